//! Object File Format: `OFF` header (optionally with `C`, `N`, `ST` prefixes for colours,
//! normals and texture coordinates, which are ignored), counts, vertex lines, face lines
//! `n i0 … i(n−1) [colour]`. Indices are 0-based.

use std::path::Path;

use super::model::{Format, RawModel};
use super::text::{line_error, parse_position, text_lines, BAD_INDEX_FIX, TRUNCATED_FIX};
use crate::error::{InputError, Location};
use crate::mesh::polygons::Polygons;

/// Parses an OFF file held in memory.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<RawModel, InputError> {
    let mut reader = OffReader {
        path,
        lines: data_lines(path, bytes),
        last_line: 0,
    };
    let (vertex_count, face_count) = reader.counts()?;
    let mut polys = Polygons::new();
    // Counts come from the file: never trust them for allocation beyond a sane cap.
    polys.positions.reserve(vertex_count.min(1 << 24));
    for k in 0..vertex_count {
        let (n, text) = reader.next_line(k, vertex_count, "vertices")?;
        let mut tokens = text.split_ascii_whitespace();
        let position = parse_position(path, n, &mut tokens, "write 'x y z' on each vertex line")?;
        polys.positions.push(position);
    }
    let mut face_locations = Vec::with_capacity(face_count.min(1 << 24));
    for k in 0..face_count {
        let (n, text) = reader.next_line(k, face_count, "faces")?;
        reader.face(k, n, text, &mut polys)?;
        face_locations.push(n);
    }
    Ok(RawModel::text(path, Format::Off, polys, face_locations))
}

/// Data lines of an OFF file: comments stripped, blank lines skipped, each with its
/// line number.
fn data_lines<'a>(
    path: &'a Path,
    bytes: &'a [u8],
) -> impl Iterator<Item = Result<(u64, &'a str), InputError>> + 'a {
    text_lines(path, bytes, "OFF").filter_map(|item| match item {
        Ok((n, text)) => {
            let text = text.split('#').next().unwrap_or("").trim();
            (!text.is_empty()).then_some(Ok((n, text)))
        }
        Err(e) => Some(Err(e)),
    })
}

/// An OFF file being read line by line, remembering the last line read so that a
/// file ending too early is reported where it ends.
struct OffReader<'a, I> {
    /// The file, for messages.
    path: &'a Path,
    /// The data lines not read yet.
    lines: I,
    /// The number of the last line read.
    last_line: u64,
}

impl<'a, I> OffReader<'a, I>
where
    I: Iterator<Item = Result<(u64, &'a str), InputError>>,
{
    /// Reads the header and returns its line and the tokens after the keyword.
    fn header(&mut self) -> Result<(u64, Vec<&'a str>), InputError> {
        let (header_line, header) = self.lines.next().transpose()?.ok_or_else(|| {
            InputError::new(
                self.path,
                Location::File,
                "the file is empty",
                "export it again",
            )
        })?;
        let mut header_tokens = header.split_ascii_whitespace();
        let keyword = header_tokens.next().unwrap_or("");
        let known = keyword
            .strip_suffix("OFF")
            .is_some_and(|prefix| prefix.chars().all(|c| matches!(c, 'S' | 'T' | 'C' | 'N')));
        if !known {
            return Err(line_error(
                self.path,
                header_line,
                format!("expected an 'OFF' header, found '{keyword}'"),
                "this does not look like an OFF file; check the file or its extension",
            ));
        }
        let rest: Vec<&str> = header_tokens.collect();
        if rest.first() == Some(&"BINARY") {
            return Err(line_error(
                self.path,
                header_line,
                "binary OFF is not supported",
                "export the model as ASCII OFF, OBJ or STL",
            ));
        }
        Ok((header_line, rest))
    }

    /// Reads the header and the counts, and returns the numbers of vertices and faces.
    fn counts(&mut self) -> Result<(usize, usize), InputError> {
        let (header_line, rest) = self.header()?;
        // The counts may follow the keyword on the same line or stand on the next one.
        let (counts_line, counts): (u64, Vec<&str>) = if rest.is_empty() {
            let (n, text) = self.lines.next().transpose()?.ok_or_else(|| {
                line_error(
                    self.path,
                    header_line,
                    "the file ends after the header",
                    TRUNCATED_FIX,
                )
            })?;
            (n, text.split_ascii_whitespace().collect())
        } else {
            (header_line, rest)
        };
        self.last_line = counts_line;
        let count = |k: usize, what: &str| -> Result<usize, InputError> {
            let token = counts.get(k).copied().unwrap_or("");
            token.parse::<usize>().map_err(|_| {
                line_error(
                    self.path,
                    counts_line,
                    format!("expected the number of {what}, found '{token}'"),
                    "the counts line is 'vertices faces edges'",
                )
            })
        };
        Ok((count(0, "vertices")?, count(1, "faces")?))
    }

    /// Reads the next data line, the `k`-th of `total` vertices or faces (`what`).
    fn next_line(
        &mut self,
        k: usize,
        total: usize,
        what: &str,
    ) -> Result<(u64, &'a str), InputError> {
        let Some(item) = self.lines.next() else {
            return Err(line_error(
                self.path,
                self.last_line,
                format!("the file ends after {k} of {total} {what}"),
                TRUNCATED_FIX,
            ));
        };
        let (n, text) = item?;
        self.last_line = n;
        Ok((n, text))
    }

    /// Reads face `k` from line `n` and appends it to `polys`, checking its corners
    /// against the vertices read.
    fn face(&self, k: usize, n: u64, text: &str, polys: &mut Polygons) -> Result<(), InputError> {
        let vertex_count = polys.positions.len();
        let mut tokens = text.split_ascii_whitespace();
        let size_token = tokens.next().unwrap_or("");
        let size: usize = size_token.parse().map_err(|_| {
            line_error(
                self.path,
                n,
                format!("expected the number of corners of face {k}, found '{size_token}'"),
                "face lines are 'n i0 i1 … i(n-1)'",
            )
        })?;
        for corner in 0..size {
            let token = tokens.next().ok_or_else(|| {
                line_error(
                    self.path,
                    n,
                    format!("face {k} declares {size} corners but lists {corner}"),
                    "face lines are 'n i0 i1 … i(n-1)'",
                )
            })?;
            let index: u32 = token.parse().map_err(|_| {
                line_error(
                    self.path,
                    n,
                    format!("'{token}' is not a vertex index in face {k}"),
                    "OFF vertex indices are whole numbers from 0",
                )
            })?;
            if index as usize >= vertex_count {
                return Err(line_error(
                    self.path,
                    n,
                    format!(
                        "face {k} refers to vertex {index} but the file has {vertex_count} vertices (numbered from 0)"
                    ),
                    BAD_INDEX_FIX,
                ));
            }
            polys.indices.push(index);
        }
        polys.offsets.push(polys.indices.len() as u32);
        Ok(())
    }
}
