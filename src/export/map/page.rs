//! The assembly map's page furniture, fitted to the paper it is printed on: text is
//! measured with Arial's advance widths (Helvetica's, and Liberation Sans', are the
//! same) and a tenth to spare for wider fallback fonts, then shrunk to a readable
//! minimum and wrapped, never clipped; and the sheets' tints, chosen far apart in
//! CIELAB so that any two differ visibly.

/// Room kept for a renderer whose sans-serif is wider than Arial (DejaVu Sans).
const WIDTH_SPARE: f64 = 1.1;

/// Line spacing, in text heights.
pub const LINE: f64 = 1.25;

/// The advance width of a character in text heights (Arial's, for ASCII and the
/// degree sign); any other character is counted as wide as an `M`.
fn advance(c: char) -> f64 {
    match c {
        ' ' | '!' | ',' | '.' | '/' | ':' | ';' | 'I' | 'f' | 't' => 0.278,
        '\'' => 0.191,
        '"' => 0.355,
        '(' | ')' | '-' | 'r' => 0.333,
        '*' => 0.389,
        '°' => 0.4,
        'J' | 'c' | 'k' | 's' | 'v' | 'x' | 'y' | 'z' => 0.5,
        'i' | 'j' | 'l' => 0.222,
        '+' | '<' | '=' | '>' => 0.584,
        'F' | 'T' | 'Z' => 0.611,
        'A' | 'B' | 'E' | 'K' | 'P' | 'S' | 'V' | 'X' | 'Y' | '&' => 0.667,
        'C' | 'D' | 'H' | 'N' | 'R' | 'U' | 'w' => 0.722,
        'G' | 'O' | 'Q' => 0.778,
        'M' | 'm' => 0.833,
        '%' => 0.889,
        'W' => 0.944,
        _ if c.is_ascii_alphanumeric() || "#$?_L".contains(c) => 0.556,
        _ => 0.833,
    }
}

/// The width (mm) of `text` set `size` mm high, with room for a wider font.
pub fn text_width(text: &str, size: f64) -> f64 {
    WIDTH_SPARE * size * text.chars().map(advance).sum::<f64>()
}

/// Text set in lines at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct Lines {
    /// Text height (mm).
    pub size: f64,
    pub lines: Vec<String>,
}

impl Lines {
    /// The height the lines take (mm).
    pub fn height(&self) -> f64 {
        self.lines.len() as f64 * LINE * self.size
    }
}

/// `text` at the largest size, from `largest` down to `smallest` by tenths, at which
/// it breaks (at spaces) into at most `most` lines of at most `width` mm; below that,
/// at `smallest` in as many lines as it takes, a word wider than the width broken
/// between characters.
pub fn fit(text: &str, width: f64, largest: f64, smallest: f64, most: usize) -> Lines {
    let mut size = largest;
    while size >= smallest {
        let lines = wrap(text, width, size);
        if lines.len() <= most.max(1) {
            return Lines { size, lines };
        }
        size *= 0.9;
    }
    Lines {
        size: smallest,
        lines: wrap(text, width, smallest),
    }
}

/// `text` broken greedily at spaces into lines of at most `width` mm at `size`; a
/// word wider than that is broken between characters.
pub fn wrap(text: &str, width: f64, size: f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let joined = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if text_width(&joined, size) <= width {
            line = joined;
            continue;
        }
        if !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        for c in word.chars() {
            let mut longer = line.clone();
            longer.push(c);
            if !line.is_empty() && text_width(&longer, size) > width {
                lines.push(std::mem::take(&mut line));
                longer = c.to_string();
            }
            line = longer;
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// The sheets' tints: light colours (CIELAB, D65) picked one by one, each the
/// candidate farthest (ΔE*ab) from every tint picked before it, so that neighbouring
/// sheet numbers and any two sheets differ as much as the light gamut allows.
pub struct Palette {
    labs: Vec<[f64; 3]>,
}

/// Lightness of the candidate tints: light enough for black text over them.
const LIGHTNESS: [f64; 3] = [68.0, 78.0, 88.0];

/// How much darker (L*) a patch seen edge-on is than one facing the viewer.
const SHADE: f64 = 14.0;

impl Palette {
    /// Tints for `sheets` sheets.
    pub fn new(sheets: usize) -> Palette {
        let candidates: Vec<[f64; 3]> = LIGHTNESS
            .iter()
            .flat_map(|&l| {
                (-12..=12)
                    .flat_map(move |a| (-12..=14).map(move |b| [l, 5.0 * a as f64, 5.0 * b as f64]))
            })
            .filter(|&lab| lab_to_srgb(lab).is_some() && lab_to_srgb(shaded(lab, 0.0)).is_some())
            .collect();
        // The first: a clear light blue, then each the farthest from those picked.
        let first = [78.0, -10.0, -30.0];
        let mut nearest: Vec<f64> = candidates.iter().map(|&c| delta_e(c, first)).collect();
        let mut labs = vec![first];
        while labs.len() < sheets && !candidates.is_empty() {
            let (k, _) =
                nearest
                    .iter()
                    .enumerate()
                    .fold((0, f64::NEG_INFINITY), |best, (k, &d)| {
                        if d > best.1 {
                            (k, d)
                        } else {
                            best
                        }
                    });
            let pick = candidates[k];
            for (d, &c) in nearest.iter_mut().zip(&candidates) {
                *d = d.min(delta_e(c, pick));
            }
            labs.push(pick);
        }
        Palette { labs }
    }

    /// The tint of `sheet` (0-based) as `#RRGGBB`, shaded by how squarely the patch
    /// faces the viewer (`facing`, 0 to 1).
    pub fn colour(&self, sheet: usize, facing: f64) -> String {
        let lab = self.labs[sheet % self.labs.len().max(1)];
        let [r, g, b] = lab_to_srgb(shaded(lab, facing)).unwrap_or([255, 255, 255]);
        format!("#{r:02X}{g:02X}{b:02X}")
    }
}

fn shaded([l, a, b]: [f64; 3], facing: f64) -> [f64; 3] {
    [l - SHADE * (1.0 - facing.abs().clamp(0.0, 1.0)), a, b]
}

/// The CIE76 colour difference.
fn delta_e(p: [f64; 3], q: [f64; 3]) -> f64 {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

/// sRGB (8 bits) of a CIELAB colour under D65; `None` outside the sRGB gamut.
fn lab_to_srgb([l, a, b]: [f64; 3]) -> Option<[u8; 3]> {
    let fy = (l + 16.0) / 116.0;
    let (fx, fz) = (fy + a / 500.0, fy - b / 200.0);
    let inverse = |t: f64| {
        if t.powi(3) > 216.0 / 24389.0 {
            t.powi(3)
        } else {
            (116.0 * t - 16.0) * 27.0 / 24389.0
        }
    };
    let (x, y, z) = (0.95047 * inverse(fx), inverse(fy), 1.08883 * inverse(fz));
    let linear = [
        3.2406 * x - 1.5372 * y - 0.4986 * z,
        -0.9689 * x + 1.8758 * y + 0.0415 * z,
        0.0557 * x - 0.2040 * y + 1.0570 * z,
    ];
    if linear.iter().any(|&c| !(-1e-3..=1.0 + 1e-3).contains(&c)) {
        return None;
    }
    Some(linear.map(|c| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_measured_with_arial_widths_and_wraps_at_spaces() {
        // "E12" in Arial: 0.667 + 2 × 0.556 em.
        assert!((text_width("E12", 10.0) - 1.1 * 17.79).abs() < 1e-9);
        let lines = fit(
            "front (from +Z, turned 20° toward +X and +Y)",
            60.0,
            4.5,
            2.5,
            2,
        );
        assert_eq!(lines.lines.len(), 2, "{lines:?}");
        assert!(lines
            .lines
            .iter()
            .all(|l| text_width(l, lines.size) <= 60.0));
        assert_eq!(
            lines.lines.join(" "),
            "front (from +Z, turned 20° toward +X and +Y)"
        );
        // Too long for two lines even at the smallest size: more lines, never wider.
        let long = fit(&"word ".repeat(40), 30.0, 4.5, 2.5, 2);
        assert_eq!(long.size, 2.5);
        assert!(long.lines.len() > 2);
        assert!(long.lines.iter().all(|l| text_width(l, 2.5) <= 30.0));
        // A word wider than the width is broken between its characters.
        let word = fit("stanford-bunny-with-a-long-name", 20.0, 3.0, 3.0, 1);
        assert!(word.lines.len() > 1);
        assert!(word.lines.iter().all(|l| text_width(l, 3.0) <= 20.0));
        assert_eq!(word.lines.concat(), "stanford-bunny-with-a-long-name");
    }

    #[test]
    fn white_converts_exactly_and_every_sheet_has_a_colour_at_any_facing() {
        let white = lab_to_srgb([100.0, 0.0, 0.0]).unwrap();
        assert_eq!(white, [255, 255, 255]);
        let palette = Palette::new(40);
        assert_eq!(palette.labs.len(), 40);
        for sheet in 0..40 {
            for facing in [0.0, 0.5, 1.0] {
                assert!(palette.colour(sheet, facing).starts_with('#'));
            }
        }
    }
}
