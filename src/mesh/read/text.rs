//! What the three readers share: text lines with their numbers, numbers and positions
//! parsed with the line they stand on, and the fixes their messages name.

use std::path::Path;

use glam::DVec3;

use crate::error::{InputError, Location};

/// The offset of the first sign of binary content in the first 8 KiB (a NUL byte or a
/// byte sequence that is not UTF-8), or `None` for text.
pub(super) fn binary_data_at(bytes: &[u8]) -> Option<usize> {
    let head = &bytes[..bytes.len().min(8192)];
    if let Some(at) = head.iter().position(|&b| b == 0) {
        return Some(at);
    }
    match std::str::from_utf8(head) {
        Ok(_) => None,
        // A character cut by the 8 KiB boundary is not an error.
        Err(e) if e.error_len().is_none() => None,
        Err(e) => Some(e.valid_up_to()),
    }
}

/// Lines of a text file with their 1-based numbers. Rejects binary data with a message
/// that says so, instead of reporting nonsense numbers further on.
pub(super) fn text_lines<'a>(
    path: &'a Path,
    bytes: &'a [u8],
    what: &'static str,
) -> impl Iterator<Item = Result<(u64, &'a str), InputError>> + 'a {
    bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(move |(i, raw)| {
            let line_no = i as u64 + 1;
            let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
            if raw.contains(&0) {
                return Err(InputError::new(
                    path,
                    Location::Line(line_no),
                    format!("binary data in a text {what} file"),
                    format!("is this really an {what} file? export it again as text"),
                ));
            }
            match std::str::from_utf8(raw) {
                Ok(s) => Ok((line_no, s)),
                Err(_) => Err(InputError::new(
                    path,
                    Location::Line(line_no),
                    "the line is not valid UTF-8 text",
                    format!("is this really an {what} file? export it again as UTF-8 text"),
                )),
            }
        })
}

/// The largest coordinate magnitude read. Squares of larger values overflow f64 in
/// areas and normals, so every face would be degenerate for a reason no message could
/// name afterwards; no real model is measured in such numbers.
pub(super) const MAX_COORDINATE: f64 = 1e15;

/// Why a coordinate this large is refused, and what to do.
pub(super) const TOO_LARGE_FIX: &str =
    "coordinates must lie within ±1e15: export the model in larger units or remove the stray vertex";

/// Parses one finite coordinate within ±[`MAX_COORDINATE`], naming the token when it
/// fails.
pub(super) fn parse_coordinate(
    path: &Path,
    line: u64,
    token: &str,
    what: &str,
) -> Result<f64, InputError> {
    match token.parse::<f64>() {
        Ok(x) if x.is_finite() && x.abs() <= MAX_COORDINATE => Ok(x),
        Ok(x) if x.is_finite() => Err(InputError::new(
            path,
            Location::Line(line),
            format!("{what} coordinate '{token}' is too large"),
            TOO_LARGE_FIX,
        )),
        Ok(_) => Err(InputError::new(
            path,
            Location::Line(line),
            format!("{what} coordinate '{token}' is not a finite number"),
            "replace NaN or infinite coordinates with real positions",
        )),
        Err(_) => Err(InputError::new(
            path,
            Location::Line(line),
            format!("'{token}' is not a number in this {what}"),
            "fix the number or export the model again",
        )),
    }
}

/// What to do when a text file stops before the data it announced.
pub(super) const TRUNCATED_FIX: &str = "the file may be truncated; export it again";

/// What to do when a face names a vertex the file does not have.
pub(super) const BAD_INDEX_FIX: &str = "fix the face or export the model again";

/// An input error at a line of a text model file.
pub(super) fn line_error(
    path: &Path,
    line: u64,
    problem: impl Into<String>,
    fix: impl Into<String>,
) -> InputError {
    InputError::new(path, Location::Line(line), problem, fix)
}

/// Reads the x, y and z of a vertex from a line's next three tokens; `fix` says how
/// the format writes a vertex when a coordinate is missing.
pub(super) fn parse_position<'t>(
    path: &Path,
    line: u64,
    tokens: &mut impl Iterator<Item = &'t str>,
    fix: &str,
) -> Result<DVec3, InputError> {
    let mut xyz = [0.0; 3];
    for (axis, slot) in xyz.iter_mut().enumerate() {
        let Some(token) = tokens.next() else {
            return Err(line_error(
                path,
                line,
                format!("vertex has {axis} coordinates; it needs x, y and z"),
                fix,
            ));
        };
        *slot = parse_coordinate(path, line, token, "vertex")?;
    }
    Ok(DVec3::from_array(xyz))
}
