//! The output folder. A run's files are written whole into a hidden sibling folder and
//! swapped in, so a folder is never half-written; but only a folder that is empty or
//! holds nothing but an earlier run's output (its `manifest.json` names unfold and lists
//! every file there) is ever replaced. Anything else is refused before the build starts,
//! naming a file that would be lost. With `--force` the run writes into such a folder
//! file by file, replacing only what the earlier manifest lists and keeping every other
//! file. Nothing is ever removed by walking a tree: old files go by name, folders only
//! when empty.

use std::collections::BTreeSet;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// The manifest's file name; it lists every other file of the run.
pub const MANIFEST: &str = "manifest.json";

/// How a run will write its output folder, decided by [`check_output_folder`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutputFolder {
    /// `--out` as the user gave it (for messages).
    given: PathBuf,
    /// The folder itself: `--out` with `~` expanded and, when it exists, symbolic links
    /// resolved.
    target: PathBuf,
    /// `--force`.
    force: bool,
}

/// What is in an existing output folder.
struct Contents {
    /// Plain files an earlier run of unfold wrote (its manifest lists them).
    ours: BTreeSet<String>,
    /// Entries unfold did not write, in name order.
    foreign: Vec<OsString>,
}

/// Expands a leading `~` (alone or before a `/`) to `$HOME`, as a shell would: a config
/// file's `out = "~/build"` means the home folder, never a folder named `~`.
pub fn expand_home(path: &Path) -> PathBuf {
    let Ok(rest) = path.strip_prefix("~") else {
        return path.to_path_buf();
    };
    match std::env::var_os("HOME") {
        Some(home) if !home.is_empty() => PathBuf::from(home).join(rest),
        _ => path.to_path_buf(),
    }
}

/// Checks that the run may write `out` and says how. `model` is the input model, which
/// is never replaced. Refusals are usage errors (exit 2) naming a file that would be
/// lost and how to proceed; nothing is created here.
pub fn check_output_folder(out: &Path, model: &Path, force: bool) -> Result<OutputFolder> {
    let given = out.to_path_buf();
    let expanded = expand_home(out);
    let usage = |what: String| Error::Usage(format!("--out {}: {what}", given.display()));
    let target = match std::fs::symlink_metadata(&expanded) {
        Ok(_) => {
            let resolved = std::fs::canonicalize(&expanded).map_err(|e| {
                usage(format!(
                    "cannot resolve it: {e}; choose another --out folder"
                ))
            })?;
            if !resolved.is_dir() {
                return Err(usage(
                    "a file of that name is in the way (it is not a folder); choose another --out or move the file".to_string(),
                ));
            }
            resolved
        }
        Err(_) => {
            // A missing folder is created with its parents; a file among them would
            // only show up as a failing mkdir.
            if let Some(blocker) = expanded
                .ancestors()
                .skip(1)
                .find(|a| !a.as_os_str().is_empty() && a.exists() && !a.is_dir())
            {
                return Err(usage(format!(
                    "{} is a file, not a folder, so the folder cannot be made there; choose another --out",
                    blocker.display()
                )));
            }
            expanded
        }
    };
    if target.file_name().is_none() || target.parent().is_none() {
        return Err(usage(
            "not a folder unfold can write (give a folder with a name, like --out build/bunny)"
                .to_string(),
        ));
    }
    let folder = OutputFolder {
        given,
        target,
        force,
    };
    if let Some(contents) = folder.contents()? {
        folder.check_contents(&contents, model)?;
    }
    Ok(folder)
}

impl OutputFolder {
    /// The folder the files go to.
    pub fn path(&self) -> &Path {
        &self.target
    }

    fn usage(&self, what: String) -> Error {
        Error::Usage(format!("--out {}: {what}", self.given.display()))
    }

    /// Reads what the folder holds now, or `None` when it does not exist.
    fn contents(&self) -> Result<Option<Contents>> {
        if !self.target.is_dir() {
            return Ok(None);
        }
        let read = std::fs::read_dir(&self.target)
            .map_err(|e| self.usage(format!("cannot read it: {e}; choose another --out")))?;
        let mut entries = Vec::new();
        let mut plain_files = BTreeSet::new();
        for entry in read {
            let entry = entry
                .map_err(|e| self.usage(format!("cannot read it: {e}; choose another --out")))?;
            let name = entry.file_name();
            // A symbolic link or subfolder is never ours, even under a listed name.
            if entry.file_type().is_ok_and(|t| t.is_file()) {
                if let Some(name) = name.to_str() {
                    plain_files.insert(name.to_string());
                }
            }
            entries.push(name);
        }
        entries.sort();
        let listed = std::fs::read(self.target.join(MANIFEST))
            .ok()
            .and_then(|bytes| listed_files(&bytes))
            .filter(|_| plain_files.contains(MANIFEST));
        let ours: BTreeSet<String> = match listed {
            Some(listed) => listed
                .into_iter()
                .chain([MANIFEST.to_string()])
                .filter(|name| plain_files.contains(name))
                .collect(),
            None => BTreeSet::new(),
        };
        let foreign = entries
            .iter()
            .filter(|name| name.to_str().is_none_or(|n| !ours.contains(n)))
            .cloned()
            .collect();
        Ok(Some(Contents { ours, foreign }))
    }

    /// Refuses a folder holding files unfold did not write (unless `--force`), and a
    /// model that is one of the files this run would replace.
    fn check_contents(&self, contents: &Contents, model: &Path) -> Result<()> {
        if let Ok(model) = std::fs::canonicalize(model) {
            let inside = model.parent() == Some(self.target.as_path());
            let name = model.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if inside && contents.ours.contains(name) {
                return Err(self.usage(format!(
                    "the model {name} is an earlier run's output in this folder, which this run replaces; copy the model elsewhere or choose another --out"
                )));
            }
        }
        if contents.foreign.is_empty() {
            return Ok(());
        }
        if !self.force {
            let shown: Vec<String> = contents
                .foreign
                .iter()
                .take(3)
                .map(|n| Path::new(n).display().to_string())
                .collect();
            let more = match contents.foreign.len().saturating_sub(3) {
                0 => String::new(),
                n => format!(" and {n} more"),
            };
            let earlier = if contents.ours.is_empty() {
                "it is not the output of an earlier run"
            } else {
                "they are not part of the earlier run's output there"
            };
            return Err(self.usage(format!(
                "the folder holds {}{more} that unfold did not write ({earlier}); replacing the folder would delete them. Choose another --out (a new or empty folder), or add --force to write into it, replacing only unfold's own earlier output and keeping every other file",
                shown.join(", ")
            )));
        }
        if contents.foreign.iter().any(|n| n == MANIFEST) {
            return Err(self.usage(format!(
                "{MANIFEST} there was not written by unfold and would be overwritten, even with --force; move it or choose another --out"
            )));
        }
        Ok(())
    }

    /// Writes `files` (name, bytes) as the folder's new contents. Checks the folder
    /// again first (it may have changed during the build). Without foreign files the
    /// folder is replaced whole by a swap; with them (`--force`), or when the folder
    /// holds the working directory, the files are moved in one by one and only the
    /// earlier run's files that this run does not write again are removed. Returns
    /// notes for the report.
    pub fn write(&self, files: &[(String, Vec<u8>)], model: &Path) -> Result<Vec<String>> {
        let contents = self.contents()?;
        if let Some(contents) = &contents {
            self.check_contents(contents, model)?;
            if let Some(name) = files.iter().map(|(n, _)| n).find(|n| {
                contents
                    .foreign
                    .iter()
                    .any(|f| f.to_str() == Some(n.as_str()))
            }) {
                return Err(self.usage(format!(
                    "{name} is there and was not written by unfold; this run would overwrite it. Move it or choose another --out"
                )));
            }
        }
        let parent = self.target.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).map_err(|e| fail("create", parent, e))?;
        let staging = self.fresh_sibling("new")?;
        if let Err(e) = write_files(&staging, files) {
            remove_listed(&staging, files.iter().map(|(n, _)| n.as_str()));
            let _ = std::fs::remove_dir(&staging);
            return Err(e);
        }
        let holds_cwd = std::env::current_dir()
            .ok()
            .and_then(|cwd| std::fs::canonicalize(cwd).ok())
            .is_some_and(|cwd| cwd.starts_with(&self.target));
        match contents {
            None => self.swap_in(&staging, None),
            Some(c) if c.foreign.is_empty() && !holds_cwd => self.swap_in(&staging, Some(&c)),
            Some(c) => self.move_in(&staging, files, &c),
        }
    }

    /// A new hidden folder beside the target, `.NAME.unfold-KIND-PID[-N]`.
    fn fresh_sibling(&self, kind: &str) -> Result<PathBuf> {
        let parent = self.target.parent().unwrap_or(Path::new("."));
        let name = self
            .target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let pid = std::process::id();
        for attempt in 0..1000 {
            let suffix = if attempt == 0 {
                String::new()
            } else {
                format!("-{attempt}")
            };
            let path = parent.join(format!(".{name}.unfold-{kind}-{pid}{suffix}"));
            match std::fs::create_dir(&path) {
                Ok(()) => return Ok(path),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(fail("create", &path, e)),
            }
        }
        Err(Error::Runtime(format!(
            "cannot create a staging folder beside {}: a thousand names are taken",
            self.target.display()
        )))
    }

    /// Replaces the folder whole: the old one (empty or only an earlier run's files)
    /// moves aside, the staged one takes its name, the old files are removed by name.
    fn swap_in(&self, staging: &Path, previous: Option<&Contents>) -> Result<Vec<String>> {
        let cleanup_staging = || {
            if let Ok(read) = std::fs::read_dir(staging) {
                for entry in read.flatten() {
                    let _ = std::fs::remove_file(entry.path());
                }
            }
            let _ = std::fs::remove_dir(staging);
        };
        let Some(previous) = previous else {
            if let Err(e) = std::fs::rename(staging, &self.target) {
                cleanup_staging();
                return Err(fail("create", &self.target, e));
            }
            return Ok(Vec::new());
        };
        let old = match self.fresh_sibling("old") {
            Ok(old) => old,
            Err(e) => {
                cleanup_staging();
                return Err(e);
            }
        };
        // rename() onto an existing folder needs it empty: the fresh sibling is.
        if let Err(e) = std::fs::rename(&self.target, &old) {
            let _ = std::fs::remove_dir(&old);
            cleanup_staging();
            return Err(fail("replace", &self.target, e));
        }
        if let Err(e) = std::fs::rename(staging, &self.target) {
            let _ = std::fs::rename(&old, &self.target);
            cleanup_staging();
            return Err(fail("replace", &self.target, e));
        }
        remove_listed(&old, previous.ours.iter().map(String::as_str));
        if std::fs::remove_dir(&old).is_err() {
            // Something appeared in the folder during the build: it is kept.
            return Ok(vec![format!(
                "files that appeared in {} during the build were kept in {}",
                self.given.display(),
                old.display()
            )]);
        }
        Ok(Vec::new())
    }

    /// Moves the staged files into the folder one by one (each replacing the earlier
    /// run's file of its name), the manifest last, then removes the earlier run's files
    /// that this run did not write again. Every other file stays.
    fn move_in(
        &self,
        staging: &Path,
        files: &[(String, Vec<u8>)],
        previous: &Contents,
    ) -> Result<Vec<String>> {
        let (manifest, rest): (Vec<&String>, Vec<&String>) =
            files.iter().map(|(n, _)| n).partition(|n| *n == MANIFEST);
        for name in rest.into_iter().chain(manifest) {
            let to = self.target.join(name);
            if let Err(e) = std::fs::rename(staging.join(name), &to) {
                remove_listed(staging, files.iter().map(|(n, _)| n.as_str()));
                let _ = std::fs::remove_dir(staging);
                return Err(fail("write", &to, e));
            }
        }
        let _ = std::fs::remove_dir(staging);
        let written: BTreeSet<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        remove_listed(
            &self.target,
            previous
                .ours
                .iter()
                .map(String::as_str)
                .filter(|n| !written.contains(n)),
        );
        Ok(Vec::new())
    }
}

/// Writes every file into `dir`.
fn write_files(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    for (name, bytes) in files {
        let path = dir.join(name);
        std::fs::write(&path, bytes).map_err(|e| fail("write", &path, e))?;
    }
    Ok(())
}

/// Removes the named plain files from `dir`; missing ones are no error.
fn remove_listed<'a>(dir: &Path, names: impl Iterator<Item = &'a str>) {
    for name in names {
        let _ = std::fs::remove_file(dir.join(name));
    }
}

fn fail(what: &str, path: &Path, e: std::io::Error) -> Error {
    Error::Runtime(format!(
        "cannot {what} {}: {e} (choose a writable --out folder)",
        path.display()
    ))
}

/// The files an earlier run's manifest says it wrote, or `None` when the bytes are not
/// a manifest of unfold's. Manifests list their files under `files`; older ones list
/// only each sheet's SVG, whose DXF and the assembled OBJ are then implied.
fn listed_files(bytes: &[u8]) -> Option<BTreeSet<String>> {
    let manifest: serde_json::Value = serde_json::from_slice(bytes).ok()?;
    if manifest.pointer("/tool/name")?.as_str()? != "unfold" {
        return None;
    }
    let plain = |name: &str| {
        let path = Path::new(name);
        path.file_name().is_some_and(|n| n == path.as_os_str()) && name != "." && name != ".."
    };
    let names: Vec<String> = match manifest.get("files") {
        Some(files) => files
            .as_array()?
            .iter()
            .filter_map(|f| f.as_str().map(str::to_string))
            .collect(),
        None => {
            let mut names = Vec::new();
            for sheet in manifest.get("sheets")?.as_array()? {
                let svg = sheet.get("file")?.as_str()?;
                names.push(svg.to_string());
                if let Some(stem) = svg.strip_suffix(".svg") {
                    names.push(format!("{stem}.dxf"));
                }
            }
            let input = manifest.pointer("/input/path")?.as_str()?;
            if let Some(stem) = Path::new(input).file_stem() {
                names.push(format!("{}-assembled.obj", stem.to_string_lossy()));
            }
            names
        }
    };
    Some(names.into_iter().filter(|n| plain(n)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifests_of_other_tools_list_nothing() {
        assert_eq!(listed_files(b"{\"tool\": {\"name\": \"other\"}}"), None);
        assert_eq!(listed_files(b"not json"), None);
        let listed = listed_files(
            b"{\"tool\": {\"name\": \"unfold\"}, \"files\": [\"a.svg\", \"../x\", \"sub/y\"]}",
        )
        .unwrap();
        assert_eq!(listed, BTreeSet::from(["a.svg".to_string()]));
    }

    #[test]
    fn older_manifests_imply_the_dxf_and_the_assembled_model() {
        let listed = listed_files(
            b"{\"tool\": {\"name\": \"unfold\"}, \"input\": {\"path\": \"models/cube.obj\"}, \"sheets\": [{\"file\": \"cube-01.svg\"}]}",
        )
        .unwrap();
        let want: BTreeSet<String> = ["cube-01.svg", "cube-01.dxf", "cube-assembled.obj"]
            .map(String::from)
            .into();
        assert_eq!(listed, want);
    }
}
