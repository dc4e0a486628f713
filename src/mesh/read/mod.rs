//! Model readers: OBJ, OFF and STL into a [`RawModel`] (a polygon soup that remembers
//! where every face is in the file, so later messages can point at a line).
//!
//! OBJ is read by our own parser rather than `tobj`: tobj reports errors without a line
//! number, renumbers positions per object (so `o`/`g` groups sharing vertices would come
//! apart at every group border) and silently drops unreferenced vertices, and this tool
//! must name lines, keep groups joined and report what it drops.

mod model;
mod obj;
mod off;
mod stl;
mod text;

pub use model::{Format, Group, RawModel};
use text::binary_data_at;

use std::path::{Path, PathBuf};

use crate::error::{InputError, Location};

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
