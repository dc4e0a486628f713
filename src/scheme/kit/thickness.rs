//! The material thickness option of the schemes that take one (`--thickness`): its
//! default as `--help` states it, and the check of a value given.

use crate::scheme::PanelOptions;

/// `--thickness` as `--help` states its default (the schemes that take it differ).
pub(in crate::scheme) fn thickness_default() -> crate::option_default::OptionDefault {
    crate::option_default::OptionDefault::words(
        "thickness",
        "0mm for half-edge, net, quad-edge and winged-edge, 0.1in for woven",
    )
}

/// A material thickness as given (`text`, else `default`), in mm: zero or more, and
/// below the usable sheet's shorter side.
pub(in crate::scheme) fn thickness(
    long: &str,
    text: Option<&str>,
    default: &str,
    panel: &PanelOptions,
) -> Result<f64, String> {
    let text = text.unwrap_or(default);
    let thickness = crate::units::parse_length(text).map_err(|e| format!("--{long}: {e}"))?;
    if !(thickness >= 0.0 && thickness.is_finite()) {
        return Err(format!("--{long}: '{text}' must be zero or positive"));
    }
    // Material thicker than the sheet is wide is a typo (1e300mm would also overflow
    // the geometry).
    if let Some(limit) = panel.panel_limit {
        let widest = limit.width.min(limit.height);
        if thickness >= widest {
            return Err(format!(
                "--{long}: '{text}' is not below the usable sheet's shorter side ({widest:.1} mm); it is the material's thickness"
            ));
        }
    }
    Ok(thickness)
}
