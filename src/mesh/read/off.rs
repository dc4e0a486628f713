//! Object File Format: `OFF` header (optionally with `C`, `N`, `ST` prefixes for colours,
//! normals and texture coordinates, which are ignored), counts, vertex lines, face lines
//! `n i0 … i(n−1) [colour]`. Indices are 0-based.

use std::path::Path;

use glam::DVec3;

use super::{parse_coordinate, text_lines, Format, RawModel};
use crate::error::{InputError, Location};
use crate::mesh::polygons::Polygons;

/// Parses an OFF file held in memory.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<RawModel, InputError> {
    // Data lines: comments stripped, blank lines skipped, each with its line number.
    let mut lines = text_lines(path, bytes, "OFF").filter_map(|item| match item {
        Ok((n, text)) => {
            let text = text.split('#').next().unwrap_or("").trim();
            (!text.is_empty()).then_some(Ok((n, text)))
        }
        Err(e) => Some(Err(e)),
    });
    let err = |line: u64, problem: String, fix: &str| {
        InputError::new(path, Location::Line(line), problem, fix.to_string())
    };

    let (header_line, header) = lines.next().transpose()?.ok_or_else(|| {
        InputError::new(path, Location::File, "the file is empty", "export it again")
    })?;
    let mut header_tokens = header.split_ascii_whitespace();
    let keyword = header_tokens.next().unwrap_or("");
    let known = keyword
        .strip_suffix("OFF")
        .is_some_and(|prefix| prefix.chars().all(|c| matches!(c, 'S' | 'T' | 'C' | 'N')));
    if !known {
        return Err(err(
            header_line,
            format!("expected an 'OFF' header, found '{keyword}'"),
            "this does not look like an OFF file; check the file or its extension",
        ));
    }
    // The counts may follow the keyword on the same line or stand on the next one.
    let rest: Vec<&str> = header_tokens.collect();
    if rest.first() == Some(&"BINARY") {
        return Err(err(
            header_line,
            "binary OFF is not supported".into(),
            "export the model as ASCII OFF, OBJ or STL",
        ));
    }
    let (counts_line, counts): (u64, Vec<&str>) = if rest.is_empty() {
        let (n, text) = lines.next().transpose()?.ok_or_else(|| {
            err(
                header_line,
                "the file ends after the header".into(),
                "the file may be truncated; export it again",
            )
        })?;
        (n, text.split_ascii_whitespace().collect())
    } else {
        (header_line, rest)
    };
    let count = |k: usize, what: &str| -> Result<usize, InputError> {
        let token = counts.get(k).copied().unwrap_or("");
        token.parse::<usize>().map_err(|_| {
            err(
                counts_line,
                format!("expected the number of {what}, found '{token}'"),
                "the counts line is 'vertices faces edges'",
            )
        })
    };
    let vertex_count = count(0, "vertices")?;
    let face_count = count(1, "faces")?;

    let mut polys = Polygons::new();
    // Counts come from the file: never trust them for allocation beyond a sane cap.
    polys.positions.reserve(vertex_count.min(1 << 24));
    let mut last_line = counts_line;
    for k in 0..vertex_count {
        let Some(item) = lines.next() else {
            return Err(err(
                last_line,
                format!("the file ends after {k} of {vertex_count} vertices"),
                "the file may be truncated; export it again",
            ));
        };
        let (n, text) = item?;
        last_line = n;
        let mut tokens = text.split_ascii_whitespace();
        let mut xyz = [0.0; 3];
        for (axis, slot) in xyz.iter_mut().enumerate() {
            let token = tokens.next().ok_or_else(|| {
                err(
                    n,
                    format!("vertex has {axis} coordinates; it needs x, y and z"),
                    "write 'x y z' on each vertex line",
                )
            })?;
            *slot = parse_coordinate(path, n, token, "vertex")?;
        }
        polys.positions.push(DVec3::from_array(xyz));
    }

    let mut face_locations = Vec::with_capacity(face_count.min(1 << 24));
    for k in 0..face_count {
        let Some(item) = lines.next() else {
            return Err(err(
                last_line,
                format!("the file ends after {k} of {face_count} faces"),
                "the file may be truncated; export it again",
            ));
        };
        let (n, text) = item?;
        last_line = n;
        let mut tokens = text.split_ascii_whitespace();
        let size_token = tokens.next().unwrap_or("");
        let size: usize = size_token.parse().map_err(|_| {
            err(
                n,
                format!("expected the number of corners of face {k}, found '{size_token}'"),
                "face lines are 'n i0 i1 … i(n-1)'",
            )
        })?;
        for corner in 0..size {
            let token = tokens.next().ok_or_else(|| {
                err(
                    n,
                    format!("face {k} declares {size} corners but lists {corner}"),
                    "face lines are 'n i0 i1 … i(n-1)'",
                )
            })?;
            let index: u32 = token.parse().map_err(|_| {
                err(
                    n,
                    format!("'{token}' is not a vertex index in face {k}"),
                    "OFF vertex indices are whole numbers from 0",
                )
            })?;
            if index as usize >= vertex_count {
                return Err(err(
                    n,
                    format!(
                        "face {k} refers to vertex {index} but the file has {vertex_count} vertices (numbered from 0)"
                    ),
                    "fix the face or export the model again",
                ));
            }
            polys.indices.push(index);
        }
        polys.offsets.push(polys.indices.len() as u32);
        face_locations.push(n);
    }
    Ok(RawModel {
        path: path.to_path_buf(),
        format: Format::Off,
        polys,
        face_locations,
        binary: false,
        groups: Vec::new(),
        ignored: Vec::new(),
        welded_corners: 0,
    })
}
