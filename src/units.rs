//! Lengths with units, and numbers as reports print them. The lowest layer of the
//! options: the scheme files and the configuration both read lengths through it.

use serde::Deserialize;

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// A unit of length.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches.
    In,
    /// Feet.
    Ft,
}

impl LengthUnit {
    /// Millimetres in one unit.
    pub fn mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::Cm => 10.0,
            LengthUnit::M => 1000.0,
            LengthUnit::In => MM_PER_INCH,
            LengthUnit::Ft => 12.0 * MM_PER_INCH,
        }
    }

    pub(crate) fn parse_suffix(s: &str) -> Option<LengthUnit> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mm" => Some(LengthUnit::Mm),
            "cm" => Some(LengthUnit::Cm),
            "m" => Some(LengthUnit::M),
            "in" | "inch" | "inches" | "\"" => Some(LengthUnit::In),
            "ft" | "foot" | "feet" | "'" => Some(LengthUnit::Ft),
            _ => None,
        }
    }
}

/// Splits "4.5ft" into (4.5, "ft").
pub(crate) fn split_number(s: &str) -> (&str, &str) {
    let s = s.trim();
    let end = s
        .char_indices()
        .find(|&(_, c)| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+' || c == 'e'))
        .map_or(s.len(), |(i, _)| i);
    // "1e" would swallow the 'e' of nothing; numbers here never need exponents
    // followed by a unit starting with 'e', so trim a trailing 'e'.
    let end = if s[..end].ends_with('e') {
        end - 1
    } else {
        end
    };
    (&s[..end], &s[end..])
}

/// The longest length (mm) any option takes: 1 km. Far beyond any sheet or build, and
/// small enough that areas and offsets of such lengths stay finite in f32 collision
/// geometry.
pub const MAX_LENGTH_MM: f64 = 1e6;

/// Parses a length with its unit ("4ft", "1.2m", "48in", "0.25 in", "600mm") into
/// millimetres. A unit is required: a bare "4" could mean feet or millimetres. Lengths
/// beyond [`MAX_LENGTH_MM`] either way are refused.
pub fn parse_length(text: &str) -> std::result::Result<f64, String> {
    let mm = parse_length_unbounded(text)?;
    if mm.abs() > MAX_LENGTH_MM {
        return Err(format!(
            "'{text}' is longer than 1 km, the longest length unfold takes"
        ));
    }
    Ok(mm)
}

pub(crate) fn parse_length_unbounded(text: &str) -> std::result::Result<f64, String> {
    let (number, unit) = split_number(text);
    let value: f64 = number.parse().map_err(|_| {
        format!(
            "'{text}' is not a length; write a number and a unit, like 4ft, 1.2m, 48in or 600mm"
        )
    })?;
    if unit.trim().is_empty() {
        return Err(format!(
            "'{text}' has no unit; write it with one, like {text}mm, {text}in or {text}ft"
        ));
    }
    let unit = LengthUnit::parse_suffix(unit).ok_or_else(|| {
        format!(
            "'{text}' has an unknown unit '{}'; use mm, cm, m, in or ft",
            unit.trim()
        )
    })?;
    if !value.is_finite() {
        return Err(format!("'{text}' is not a finite length"));
    }
    Ok(value * unit.mm())
}

/// A positive length option (`--tab-height`): `text` or else `default`, in mm.
pub fn positive_length(option: &str, text: Option<&str>, default: &str) -> Result<f64, String> {
    let text = text.unwrap_or(default);
    match parse_length(text) {
        Ok(mm) if mm > 0.0 => Ok(mm),
        Ok(_) => Err(format!("--{option}: '{text}' must be positive")),
        Err(e) => Err(format!("--{option}: {e}")),
    }
}

/// A fraction option in (0, 1]: `value` or else `default`.
pub fn fraction(option: &str, value: Option<f64>, default: f64) -> Result<f64, String> {
    let x = value.unwrap_or(default);
    if x > 0.0 && x <= 1.0 {
        Ok(x)
    } else {
        Err(format!(
            "--{option}: {x} must be greater than 0 and at most 1"
        ))
    }
}

/// A number for a message: [`fmt_num`] when moderate, exponent form when huge or tiny
/// (f64's `{}` would print 1e300 with 301 digits).
pub(crate) fn short_number(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.3e}")
    } else {
        fmt_num(x)
    }
}

/// A path length for a report: whole millimetres below a metre, else metres with one
/// decimal ("472 mm", "12.7 m").
pub(crate) fn fmt_path_length(mm: f64) -> String {
    // An empty sum is -0.0; written, it would read "-0 mm".
    let mm = mm + 0.0;
    if mm < 1000.0 {
        format!("{mm:.0} mm")
    } else {
        format!("{:.1} m", mm / 1000.0)
    }
}

/// A count with its noun, singular for one ("1 sheet", "2 sheets").
pub(crate) fn count_of(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A number with at most 4 decimals, trailing zeros trimmed (for reports).
pub(crate) fn fmt_num(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}
