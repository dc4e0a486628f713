//! Wavefront OBJ: `v` positions, `f` polygons (kept as n-gons), `o`/`g` names. Texture
//! coordinates, normals, materials, lines and the rest are counted and ignored.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::Path;

use super::model::{Format, Group, RawModel};
use super::text::{line_error, parse_position, text_lines, BAD_INDEX_FIX, TRUNCATED_FIX};
use crate::error::InputError;
use crate::mesh::polygons::Polygons;

/// Parses an OBJ file held in memory.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<RawModel, InputError> {
    let mut model = ObjModel::new(path);
    let mut continued = Continued::default();
    for item in text_lines(path, bytes, "OBJ") {
        let (line_no, text) = item?;
        let text = match text.find('#') {
            Some(i) => &text[..i],
            None => text,
        };
        if let Some((statement_line, statement)) = continued.statement(line_no, text) {
            model.statement(statement_line, &statement)?;
        }
    }
    if let Some(line) = continued.unfinished() {
        return Err(line_error(
            path,
            line,
            "the file ends inside a statement continued with '\\'",
            TRUNCATED_FIX,
        ));
    }
    model.finish()
}

/// A statement continued with a trailing backslash, joined to the lines that follow.
#[derive(Default)]
struct Continued {
    /// The lines joined so far, each followed by a space; empty outside a statement.
    text: String,
    /// The line the statement starts on.
    first_line: u64,
}

impl Continued {
    /// Takes line `line_no` (comment stripped); returns the whole statement and the line
    /// it starts on once a line does not end in a backslash.
    fn statement<'t>(&mut self, line_no: u64, text: &'t str) -> Option<(u64, Cow<'t, str>)> {
        if let Some(head) = text.trim_end().strip_suffix('\\') {
            if self.text.is_empty() {
                self.first_line = line_no;
            }
            self.text.push_str(head);
            self.text.push(' ');
            return None;
        }
        if self.text.is_empty() {
            Some((line_no, Cow::Borrowed(text)))
        } else {
            self.text.push_str(text);
            Some((self.first_line, Cow::Owned(std::mem::take(&mut self.text))))
        }
    }

    /// The line of a statement the file ended inside, if any.
    fn unfinished(&self) -> Option<u64> {
        (!self.text.is_empty()).then_some(self.first_line)
    }
}

/// What an OBJ file has given so far.
struct ObjModel<'a> {
    /// The file, for messages.
    path: &'a Path,
    /// Positions and faces read.
    polys: Polygons,
    /// The line of each face.
    face_locations: Vec<u64>,
    /// Named groups, in file order.
    groups: Vec<Group>,
    /// Statements not used, by keyword, with counts.
    ignored: BTreeMap<String, usize>,
    /// The largest vertex index a face names, with its line: a face may name a vertex
    /// defined further down, so ranges are checked at the end.
    max_index: Option<(u32, u64)>,
}

impl<'a> ObjModel<'a> {
    /// Nothing read yet.
    fn new(path: &'a Path) -> Self {
        ObjModel {
            path,
            polys: Polygons::new(),
            face_locations: Vec::new(),
            groups: Vec::new(),
            ignored: BTreeMap::new(),
            max_index: None,
        }
    }

    /// Reads one statement, starting on line `line_no`.
    fn statement(&mut self, line_no: u64, statement: &str) -> Result<(), InputError> {
        let mut tokens = statement.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            return Ok(());
        };
        match keyword {
            "v" => {
                let position = parse_position(self.path, line_no, &mut tokens, "write 'v x y z'")?;
                self.polys.positions.push(position);
            }
            "f" | "fo" => self.face(line_no, tokens)?,
            "o" | "g" => self.group(statement.trim()[keyword.len()..].trim()),
            other => *self.ignored.entry(other.to_string()).or_insert(0) += 1,
        }
        Ok(())
    }

    /// Reads a face from its corner tokens (`v`, `v/vt`, `v//vn` or `v/vt/vn`).
    fn face<'t>(
        &mut self,
        line_no: u64,
        tokens: impl Iterator<Item = &'t str>,
    ) -> Result<(), InputError> {
        let defined = self.polys.positions.len() as i64;
        for token in tokens {
            let index = resolve_index(self.path, line_no, token, defined)?;
            if self.max_index.is_none_or(|(m, _)| index > m) {
                self.max_index = Some((index, line_no));
            }
            self.polys.indices.push(index);
        }
        self.polys.offsets.push(self.polys.indices.len() as u32);
        self.face_locations.push(line_no);
        Ok(())
    }

    /// Starts a named group at the next face.
    fn group(&mut self, name: &str) {
        let name = name.to_string();
        let first_face = self.face_locations.len() as u32;
        match self.groups.last_mut() {
            // A name with no faces after it yet is replaced, not kept empty.
            Some(last) if last.first_face == first_face => last.name = name,
            _ => self.groups.push(Group { name, first_face }),
        }
    }

    /// Checks that every vertex a face names was defined and returns the model.
    fn finish(self) -> Result<RawModel, InputError> {
        if let Some((index, line)) = self.max_index {
            if index as usize >= self.polys.positions.len() {
                return Err(line_error(
                    self.path,
                    line,
                    format!(
                        "face refers to vertex {} but the file defines only {} vertices",
                        index as u64 + 1,
                        self.polys.positions.len()
                    ),
                    TRUNCATED_FIX,
                ));
            }
        }
        Ok(RawModel {
            groups: self.groups,
            ignored: self.ignored.into_iter().collect(),
            ..RawModel::text(self.path, Format::Obj, self.polys, self.face_locations)
        })
    }
}

/// The 0-based vertex of a face corner token: OBJ counts from 1, and a negative index
/// counts back from the last of the `defined` vertices so far.
fn resolve_index(path: &Path, line: u64, token: &str, defined: i64) -> Result<u32, InputError> {
    let index_text = token.split('/').next().unwrap_or("");
    let index: i64 = index_text.parse().map_err(|_| {
        line_error(
            path,
            line,
            format!("'{token}' is not a vertex index"),
            "face corners are written as v, v/vt, v//vn or v/vt/vn with whole numbers",
        )
    })?;
    let resolved = match index {
        0 => {
            return Err(line_error(
                path,
                line,
                "vertex index 0 in a face",
                "OBJ vertex indices start at 1 (negative ones count back from the last vertex)",
            ))
        }
        i if i > 0 => i - 1,
        i => defined + i,
    };
    if resolved < 0 || resolved > u32::MAX as i64 - 1 {
        return Err(line_error(
            path,
            line,
            format!("vertex index {index} is out of range ({defined} vertices defined so far)"),
            BAD_INDEX_FIX,
        ));
    }
    Ok(resolved as u32)
}
