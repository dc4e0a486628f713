//! Wavefront OBJ: `v` positions, `f` polygons (kept as n-gons), `o`/`g` names. Texture
//! coordinates, normals, materials, lines and the rest are counted and ignored.

use std::collections::BTreeMap;
use std::path::Path;

use glam::DVec3;

use super::{parse_coordinate, text_lines, Format, Group, RawModel};
use crate::error::{InputError, Location};
use crate::mesh::polygons::Polygons;

/// Parses an OBJ file held in memory.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<RawModel, InputError> {
    let mut polys = Polygons::new();
    let mut face_locations = Vec::new();
    let mut groups: Vec<Group> = Vec::new();
    let mut ignored: BTreeMap<String, usize> = BTreeMap::new();
    // A face may name a vertex defined further down; ranges are checked at the end.
    let mut max_index: Option<(u32, u64)> = None;
    // A statement continued with a trailing backslash is joined to the next line.
    let mut pending = String::new();
    let mut pending_line = 0u64;

    for item in text_lines(path, bytes, "OBJ") {
        let (line_no, text) = item?;
        let text = match text.find('#') {
            Some(i) => &text[..i],
            None => text,
        };
        if let Some(head) = text.trim_end().strip_suffix('\\') {
            if pending.is_empty() {
                pending_line = line_no;
            }
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        let (statement_line, joined);
        let statement = if pending.is_empty() {
            statement_line = line_no;
            text
        } else {
            statement_line = pending_line;
            pending.push_str(text);
            joined = std::mem::take(&mut pending);
            joined.as_str()
        };
        let line_no = statement_line;
        let mut tokens = statement.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut xyz = [0.0; 3];
                for (k, slot) in xyz.iter_mut().enumerate() {
                    let Some(token) = tokens.next() else {
                        return Err(InputError::new(
                            path,
                            Location::Line(line_no),
                            format!("vertex has {k} coordinates; it needs x, y and z"),
                            "write 'v x y z'",
                        ));
                    };
                    *slot = parse_coordinate(path, line_no, token, "vertex")?;
                }
                polys.positions.push(DVec3::from_array(xyz));
            }
            "f" | "fo" => {
                let defined = polys.positions.len() as i64;
                for token in tokens {
                    let index_text = token.split('/').next().unwrap_or("");
                    let index: i64 = index_text.parse().map_err(|_| {
                        InputError::new(
                            path,
                            Location::Line(line_no),
                            format!("'{token}' is not a vertex index"),
                            "face corners are written as v, v/vt, v//vn or v/vt/vn with whole numbers",
                        )
                    })?;
                    let resolved = match index {
                        0 => {
                            return Err(InputError::new(
                                path,
                                Location::Line(line_no),
                                "vertex index 0 in a face",
                                "OBJ vertex indices start at 1 (negative ones count back from the last vertex)",
                            ))
                        }
                        i if i > 0 => i - 1,
                        i => defined + i,
                    };
                    if resolved < 0 || resolved > u32::MAX as i64 - 1 {
                        return Err(InputError::new(
                            path,
                            Location::Line(line_no),
                            format!(
                                "vertex index {index} is out of range ({defined} vertices defined so far)"
                            ),
                            "fix the face or export the model again",
                        ));
                    }
                    let resolved = resolved as u32;
                    if max_index.is_none_or(|(m, _)| resolved > m) {
                        max_index = Some((resolved, line_no));
                    }
                    polys.indices.push(resolved);
                }
                polys.offsets.push(polys.indices.len() as u32);
                face_locations.push(line_no);
            }
            "o" | "g" => {
                let name = statement.trim()[keyword.len()..].trim().to_string();
                let first_face = face_locations.len() as u32;
                match groups.last_mut() {
                    // A name with no faces after it yet is replaced, not kept empty.
                    Some(last) if last.first_face == first_face => last.name = name,
                    _ => groups.push(Group { name, first_face }),
                }
            }
            other => *ignored.entry(other.to_string()).or_insert(0) += 1,
        }
    }
    if !pending.is_empty() {
        return Err(InputError::new(
            path,
            Location::Line(pending_line),
            "the file ends inside a statement continued with '\\'",
            "the file may be truncated; export it again",
        ));
    }
    if let Some((index, line)) = max_index {
        if index as usize >= polys.positions.len() {
            return Err(InputError::new(
                path,
                Location::Line(line),
                format!(
                    "face refers to vertex {} but the file defines only {} vertices",
                    index as u64 + 1,
                    polys.positions.len()
                ),
                "the file may be truncated; export it again",
            ));
        }
    }
    Ok(RawModel {
        path: path.to_path_buf(),
        format: Format::Obj,
        polys,
        face_locations,
        binary: false,
        groups,
        ignored: ignored.into_iter().collect(),
        welded_corners: 0,
    })
}
