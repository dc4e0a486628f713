//! The sheets' layers as the configuration file gives them (`[layers.cut]`: a name, a
//! colour and a stroke width per kind of line), each value checked, and resolved over
//! the standard layers.

use crate::error::{Error, Result};
use crate::export::{Kind, Layers};
use crate::units::parse_length;

/// One kind's layer as a config file gives it (`[layers.score-valley]`), each field
/// optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerSetting {
    /// Layer name.
    pub name: Option<String>,
    /// Colour, `#RRGGBB`.
    pub color: Option<String>,
    /// Stroke width, a length with a unit.
    pub stroke_width: Option<String>,
}

/// Every kind's layer settings, in [`Kind::ALL`] order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerSettings(pub [LayerSetting; 4]);

impl LayerSettings {
    /// The config keys of the kinds, in [`Kind::ALL`] order.
    pub const KEYS: [&'static str; 4] = ["engrave", "score", "score-valley", "cut"];

    /// These settings, with `other`'s where a field is missing.
    pub(super) fn or(self, other: LayerSettings) -> LayerSettings {
        let LayerSettings(mut mine) = self;
        for (m, o) in mine.iter_mut().zip(other.0) {
            m.name = m.name.take().or(o.name);
            m.color = m.color.take().or(o.color);
            m.stroke_width = m.stroke_width.take().or(o.stroke_width);
        }
        LayerSettings(mine)
    }

    /// The layers drawn: LASER.md's, every stroke `stroke_width` mm, with these
    /// settings applied.
    pub(super) fn resolve(&self, stroke_width: f64) -> Result<Layers> {
        let mut layers = Layers::standard(stroke_width);
        for ((setting, kind), key) in self.0.iter().zip(Kind::ALL).zip(Self::KEYS) {
            let style = layers.of_mut(kind);
            if let Some(name) = &setting.name {
                check_layer_name(name)
                    .map_err(|why| Error::Usage(format!("layers.{key}.name: {why}")))?;
                style.name = name.clone();
            }
            if let Some(color) = &setting.color {
                style.color = check_layer_color(color)
                    .map_err(|why| Error::Usage(format!("layers.{key}.color: {why}")))?;
            }
            if let Some(width) = &setting.stroke_width {
                style.stroke_width = parse_length(width)
                    .map_err(|why| Error::Usage(format!("layers.{key}.stroke-width: {why}")))?;
            }
        }
        for (i, a) in layers.0.iter().enumerate() {
            if layers.0[..i].iter().any(|b| b.name == a.name) {
                return Err(Error::Usage(format!(
                    "layers: two kinds are both named {}; give each kind its own layer name",
                    a.name
                )));
            }
        }
        Ok(layers)
    }
}

/// Says why `name` cannot be a layer name (DXF R12: letters, digits, `-`, `_`, `$`, at
/// most 31).
pub fn check_layer_name(name: &str) -> std::result::Result<(), String> {
    let fine = !name.is_empty()
        && name.len() <= 31
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '$'));
    if fine {
        Ok(())
    } else {
        Err(format!(
            "\"{name}\" is not a layer name DXF R12 takes: use 1 to 31 letters, digits, -, _ or $, like \"CUT\""
        ))
    }
}

/// The colour `text` names, as `#RRGGBB` in capitals, or why it names none.
pub fn check_layer_color(text: &str) -> std::result::Result<String, String> {
    let hex = text.strip_prefix('#').unwrap_or("");
    if hex.len() == 6 && hex.chars().all(|c| c.is_ascii_hexdigit()) {
        Ok(format!("#{}", hex.to_ascii_uppercase()))
    } else {
        Err(format!(
            "\"{text}\" is not a colour: write it as pure RGB, like \"#FF0000\" (drivers match colours exactly)"
        ))
    }
}
