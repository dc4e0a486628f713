//! Sheet sizes: a width and height with a unit, or a paper's name, parsed and checked.

use crate::units::{parse_length_unbounded, split_number, MAX_LENGTH_MM, MM_PER_INCH};

/// A sheet of material.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetSize {
    /// Width in mm.
    pub width: f64,
    /// Height in mm.
    pub height: f64,
    /// As the user wrote it ("18x24in", "A2").
    pub name: String,
}

/// Parses a sheet size: `WxH` with a unit (`18x24in`, `600x400mm`, `18in x 24in`), or
/// a name: `A0`..`A5` (portrait, ISO 216), `letter` (8.5×11 in), `legal` (8.5×14 in),
/// `tabloid` (11×17 in).
pub fn parse_sheet(text: &str) -> std::result::Result<SheetSize, String> {
    let named = match text.trim().to_ascii_lowercase().as_str() {
        "a0" => Some((841.0, 1189.0)),
        "a1" => Some((594.0, 841.0)),
        "a2" => Some((420.0, 594.0)),
        "a3" => Some((297.0, 420.0)),
        "a4" => Some((210.0, 297.0)),
        "a5" => Some((148.0, 210.0)),
        "letter" => Some((8.5 * MM_PER_INCH, 11.0 * MM_PER_INCH)),
        "legal" => Some((8.5 * MM_PER_INCH, 14.0 * MM_PER_INCH)),
        "tabloid" => Some((11.0 * MM_PER_INCH, 17.0 * MM_PER_INCH)),
        _ => None,
    };
    let (width, height) = match named {
        Some(size) => size,
        None => {
            let bad = || {
                format!(
                    "'{text}' is not a sheet size; write WxH with a unit (18x24in, 600x400mm) or a name (A0..A5, letter, legal, tabloid)"
                )
            };
            let lower = text.to_ascii_lowercase();
            let (w, h) = lower.split_once('x').ok_or_else(bad)?;
            let (h_number, h_unit) = split_number(h);
            if h_number.is_empty() {
                return Err(bad());
            }
            // "18x24in": the unit after the height serves both; "18in x 24in" also works.
            let (w_number, w_unit) = split_number(w);
            let w_text = if w_unit.trim().is_empty() {
                format!("{w_number}{h_unit}")
            } else {
                w.to_string()
            };
            let width = parse_length_unbounded(&w_text).map_err(|_| bad())?;
            let height = parse_length_unbounded(h).map_err(|_| bad())?;
            (width, height)
        }
    };
    if width <= 0.0 || height <= 0.0 {
        return Err(format!(
            "sheet '{text}' must have a positive width and height"
        ));
    }
    if width > MAX_LENGTH_MM || height > MAX_LENGTH_MM {
        return Err(format!(
            "sheet '{text}' is larger than 1 km, the longest length unfold takes"
        ));
    }
    Ok(SheetSize {
        width,
        height,
        name: text.trim().to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::parse_length;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn lengths_in_every_unit() {
        for (text, mm) in [
            ("4ft", 1219.2),
            ("1.2m", 1200.0),
            ("48in", 1219.2),
            ("0.25 in", 6.35),
            ("600mm", 600.0),
            ("12.5cm", 125.0),
            ("1e3mm", 1000.0),
        ] {
            assert!(close(parse_length(text).unwrap(), mm), "{text}");
        }
        assert!(parse_length("4").unwrap_err().contains("no unit"));
        assert!(parse_length("4yd").unwrap_err().contains("unknown unit"));
        assert!(parse_length("ft").is_err());
    }

    #[test]
    fn sheet_sizes() {
        let s = parse_sheet("18x24in").unwrap();
        assert!((s.width - 457.2).abs() < 1e-9 && (s.height - 609.6).abs() < 1e-9);
        let s = parse_sheet("600x400mm").unwrap();
        assert_eq!((s.width, s.height), (600.0, 400.0));
        let s = parse_sheet("18in x 24in").unwrap();
        assert!((s.height - 609.6).abs() < 1e-9);
        assert_eq!(parse_sheet("A0").unwrap().width, 841.0);
        assert_eq!(parse_sheet("a4").unwrap().height, 297.0);
        assert!((parse_sheet("letter").unwrap().width - 215.9).abs() < 1e-9);
        assert!((parse_sheet("tabloid").unwrap().height - 431.8).abs() < 1e-9);
        assert!(parse_sheet("18x24").is_err());
        assert!(parse_sheet("0x24in").is_err());
        assert!(parse_sheet("huge").is_err());
    }
}
