//! Model readers: OBJ, OFF and STL into a [`RawModel`] (a polygon soup that remembers
//! where every face is in the file, so later messages can point at a line).
//!
//! OBJ is read by our own parser rather than `tobj`: tobj reports errors without a line
//! number, renumbers positions per object (so `o`/`g` groups sharing vertices would come
//! apart at every group border) and silently drops unreferenced vertices, and this tool
//! must name lines, keep groups joined and report what it drops.

mod obj;
mod off;
mod stl;

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::error::{InputError, Location};

use super::polygons::Polygons;

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
    fn text(path: &Path, format: Format, polys: Polygons, face_locations: Vec<u64>) -> Self {
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

/// Reads a model file. The format comes from the extension.
pub fn read_model(path: &Path) -> Result<RawModel, InputError> {
    let format = model_format(path)?;
    let bytes = std::fs::read(path).map_err(|e| {
        let problem = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
            _ => format!("cannot read the file: {e}"),
        };
        InputError::new(
            path,
            Location::File,
            problem,
            "check the path and permissions",
        )
    })?;
    parse_model(path, format, &bytes)
}

/// The format of the model at `path`, from its extension, refusing a folder given as
/// the model. Cheap: a run checks it before anything else.
pub fn model_format(path: &Path) -> Result<Format, InputError> {
    if path.is_dir() {
        return Err(InputError::new(
            path,
            Location::File,
            "is a directory, not a model file",
            folder_hint(path),
        ));
    }
    let Some(format) = Format::from_path(path) else {
        return Err(InputError::new(
            path,
            Location::File,
            "unknown model format",
            "give a .obj, .off or .stl file",
        ));
    };
    Ok(format)
}

/// What to give instead of a folder: a few of the models in it, by name.
fn folder_hint(folder: &Path) -> String {
    let mut models: Vec<PathBuf> = std::fs::read_dir(folder)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file() && Format::from_path(p).is_some())
        .collect();
    models.sort();
    match models.len() {
        0 => "give the path of a .obj, .off or .stl file".to_string(),
        n => {
            let shown: Vec<String> = models
                .iter()
                .take(3)
                .map(|p| p.display().to_string())
                .collect();
            let more = if n > 3 {
                format!("; {} more are there", n - 3)
            } else {
                String::new()
            };
            format!("give one model file in it, like {}{more}", shown.join(", "))
        }
    }
}

/// Parses a model file's bytes (already read from `path`, which only names the file in
/// messages). Separate from [`read_model`] so the fuzz targets can feed it bytes.
pub fn parse_model(path: &Path, format: Format, bytes: &[u8]) -> Result<RawModel, InputError> {
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(InputError::new(
            path,
            Location::File,
            "the file is empty",
            "export the model again",
        ));
    }
    if format != Format::Stl {
        if let Some(at) = binary_data_at(bytes) {
            let what = if format == Format::Obj { "OBJ" } else { "OFF" };
            return Err(InputError::new(
                path,
                Location::Byte(at as u64),
                format!("binary data: this is not a text {what} file"),
                format!("check the file; export the model again as {what}"),
            ));
        }
    }
    let model = match format {
        Format::Obj => obj::parse(path, bytes)?,
        Format::Off => off::parse(path, bytes)?,
        Format::Stl => stl::parse(path, bytes)?,
    };
    if model.polys.face_count() == 0 {
        return Err(InputError::new(
            path,
            Location::File,
            "the file has no faces",
            "a model for unfolding needs polygon faces; export faces, not only points or lines",
        ));
    }
    Ok(model)
}

/// The offset of the first sign of binary content in the first 8 KiB (a NUL byte or a
/// byte sequence that is not UTF-8), or `None` for text.
pub(crate) fn binary_data_at(bytes: &[u8]) -> Option<usize> {
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
pub(crate) fn text_lines<'a>(
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
pub(crate) const MAX_COORDINATE: f64 = 1e15;

/// Why a coordinate this large is refused, and what to do.
pub(crate) const TOO_LARGE_FIX: &str =
    "coordinates must lie within ±1e15: export the model in larger units or remove the stray vertex";

/// Parses one finite coordinate within ±[`MAX_COORDINATE`], naming the token when it
/// fails.
pub(crate) fn parse_coordinate(
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
const TRUNCATED_FIX: &str = "the file may be truncated; export it again";

/// What to do when a face names a vertex the file does not have.
const BAD_INDEX_FIX: &str = "fix the face or export the model again";

/// An input error at a line of a text model file.
fn line_error(
    path: &Path,
    line: u64,
    problem: impl Into<String>,
    fix: impl Into<String>,
) -> InputError {
    InputError::new(path, Location::Line(line), problem, fix)
}

/// Reads the x, y and z of a vertex from a line's next three tokens; `fix` says how
/// the format writes a vertex when a coordinate is missing.
fn parse_position<'t>(
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
