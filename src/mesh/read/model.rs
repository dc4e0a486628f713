//! What a reader gives: the file's format and the polygon soup read from it, which
//! remembers where every face is in the file.

use std::path::{Path, PathBuf};

use crate::error::Location;
use crate::mesh::polygons::Polygons;

/// The file formats the tool reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// Wavefront OBJ (polygons kept as they are).
    Obj,
    /// Object File Format (Geomview OFF, COFF, NOFF).
    Off,
    /// STL, ASCII or binary (triangle soup, welded by position).
    Stl,
}

impl Format {
    /// The format of a path, from its extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "off" => Some(Format::Off),
            "stl" => Some(Format::Stl),
            _ => None,
        }
    }

    /// How the format numbers vertices in messages: OBJ counts from 1, the others
    /// from 0.
    pub fn index_base(self) -> u32 {
        match self {
            Format::Obj => 1,
            Format::Off | Format::Stl => 0,
        }
    }
}

/// A named run of faces (an OBJ `o` or `g` statement).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Group {
    /// The name as written in the file.
    pub name: String,
    /// Index of the group's first face.
    pub first_face: u32,
}

/// A model as read: positions and faces exactly as the file gives them.
#[derive(Clone, Debug)]
pub struct RawModel {
    /// The file it came from.
    pub path: PathBuf,
    /// Its format.
    pub format: Format,
    /// Positions and faces, 0-based.
    pub polys: Polygons,
    /// Where each face is in the file: a 1-based line for text files, the byte offset
    /// of the facet for binary STL.
    pub face_locations: Vec<u64>,
    /// True when `face_locations` are byte offsets.
    pub binary: bool,
    /// Named groups, in file order.
    pub groups: Vec<Group>,
    /// Statements read but not used (texture coordinates, normals, materials…), with
    /// how many of each; reported so that nothing is dropped silently.
    pub ignored: Vec<(String, usize)>,
    /// For STL: how many corner copies were merged when welding the triangle soup.
    pub welded_corners: usize,
}

impl RawModel {
    /// Where face `f` is in the file.
    pub fn face_location(&self, f: usize) -> Location {
        match self.face_locations.get(f) {
            Some(&n) if self.binary => Location::Byte(n),
            Some(&n) => Location::Line(n),
            None => Location::File,
        }
    }

    /// A vertex index as the user's file writes it (1-based in OBJ).
    pub fn vertex_label(&self, v: u32) -> u64 {
        v as u64 + self.format.index_base() as u64
    }

    /// A model read from a text file, with no groups and nothing ignored.
    pub(super) fn text(
        path: &Path,
        format: Format,
        polys: Polygons,
        face_locations: Vec<u64>,
    ) -> Self {
        RawModel {
            path: path.to_path_buf(),
            format,
            polys,
            face_locations,
            binary: false,
            groups: Vec::new(),
            ignored: Vec::new(),
            welded_corners: 0,
        }
    }
}
