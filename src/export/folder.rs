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
        let is_assembled_model = |name: &str| {
            std::fs::read(self.target.join(name))
                .is_ok_and(|bytes| bytes.starts_with(ASSEMBLED_HEADER.as_bytes()))
        };
        let listed = std::fs::read(self.target.join(MANIFEST))
            .ok()
            .and_then(|bytes| listed_files(&bytes, is_assembled_model))
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
    /// again first (it may have changed during the build). A missing folder, or one
    /// holding only an earlier run's files, is replaced whole by a swap with a staged
    /// sibling, which takes the old folder's permissions and owner. The files are moved
    /// in one by one instead, keeping the folder itself, when it holds foreign files
    /// (`--force`), holds the working directory, is a mount point or sits in a folder
    /// where no sibling can be made. Returns notes for the report.
    pub fn write(&self, files: &[(String, Vec<u8>)], model: &Path) -> Result<Vec<String>> {
        let Some(contents) = self.contents()? else {
            let parent = self.target.parent().unwrap_or(Path::new("."));
            std::fs::create_dir_all(parent).map_err(|e| fail("create", parent, e))?;
            let staging = self.fresh_dir(parent, &self.sibling_name("new"))?;
            stage(&staging, files)?;
            return self.swap_in(&staging, None);
        };
        self.check_contents(&contents, model)?;
        // Case-insensitive file systems would let `Bunny-01.svg` be overwritten by
        // `bunny-01.svg`: compare without case.
        if let Some(name) = files.iter().map(|(n, _)| n).find(|n| {
            contents.foreign.iter().any(|f| {
                f.to_str()
                    .is_some_and(|f| f.eq_ignore_ascii_case(n.as_str()))
            })
        }) {
            return Err(self.usage(format!(
                "{name} is there and was not written by unfold; this run would overwrite it. Move it or choose another --out"
            )));
        }
        let holds_cwd = std::env::current_dir()
            .ok()
            .and_then(|cwd| std::fs::canonicalize(cwd).ok())
            .is_some_and(|cwd| cwd.starts_with(&self.target));
        if contents.foreign.is_empty() && !holds_cwd && !self.is_mount_point() {
            let parent = self.target.parent().unwrap_or(Path::new("."));
            if let Ok(staging) = self.fresh_dir(parent, &self.sibling_name("new")) {
                stage(&staging, files)?;
                return self.swap_in(&staging, Some(&contents));
            }
        }
        self.write_in_place(files, &contents)
    }

    /// `.NAME.unfold-KIND-PID`, the hidden sibling folders of a swap.
    fn sibling_name(&self, kind: &str) -> String {
        let name = self
            .target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        format!(".{name}.unfold-{kind}-{}", std::process::id())
    }

    /// True when the folder is on another device than its parent (a mount point,
    /// which cannot be renamed).
    fn is_mount_point(&self) -> bool {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let parent = self.target.parent().unwrap_or(Path::new("."));
            match (std::fs::metadata(&self.target), std::fs::metadata(parent)) {
                (Ok(t), Ok(p)) => t.dev() != p.dev(),
                _ => false,
            }
        }
        #[cfg(not(unix))]
        false
    }

    /// A new folder `NAME[-N]` in `parent`.
    fn fresh_dir(&self, parent: &Path, name: &str) -> Result<PathBuf> {
        for attempt in 0..1000 {
            let suffix = if attempt == 0 {
                String::new()
            } else {
                format!("-{attempt}")
            };
            let path = parent.join(format!("{name}{suffix}"));
            match std::fs::create_dir(&path) {
                Ok(()) => return Ok(path),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(fail("create", &path, e)),
            }
        }
        Err(Error::Io {
            action: "create a staging folder in".to_string(),
            path: parent.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "a thousand names are taken",
            ),
        })
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
        keep_folder_attributes(&self.target, staging);
        let parent = self.target.parent().unwrap_or(Path::new("."));
        let old = match self.fresh_dir(parent, &self.sibling_name("old")) {
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

    /// Writes the files into the folder itself: staged in a hidden folder inside it
    /// (so every move is a rename on one device), then moved in one by one, the
    /// manifest last, and the earlier run's files that this run did not write again
    /// removed. First the manifest is replaced by one listing the earlier run's files
    /// and this run's together, so that if the run stops halfway every file of unfold's
    /// in the folder is still listed and the next run can replace it.
    fn write_in_place(
        &self,
        files: &[(String, Vec<u8>)],
        previous: &Contents,
    ) -> Result<Vec<String>> {
        let staging =
            self.fresh_dir(&self.target, &format!(".unfold-new-{}", std::process::id()))?;
        let result = self.move_from(&staging, files, previous);
        remove_listed(&staging, files.iter().map(|(n, _)| n.as_str()));
        remove_listed(&staging, [PROVISIONAL].into_iter());
        let _ = std::fs::remove_dir(&staging);
        result
    }

    fn move_from(
        &self,
        staging: &Path,
        files: &[(String, Vec<u8>)],
        previous: &Contents,
    ) -> Result<Vec<String>> {
        let names: BTreeSet<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        let mut all: BTreeSet<&str> = previous.ours.iter().map(String::as_str).collect();
        all.extend(names.iter().copied());
        let provisional = serde_json::json!({
            "tool": {"name": "unfold", "version": env!("CARGO_PKG_VERSION")},
            "incomplete": "a run writing this folder stopped before it finished; run it again",
            "files": all.iter().collect::<Vec<_>>(),
        });
        let provisional = format!("{provisional:#}\n");
        write_files(staging, files)?;
        write_files(
            staging,
            &[(PROVISIONAL.to_string(), provisional.into_bytes())],
        )?;
        let into = |from: &str, to: &str| {
            let to = self.target.join(to);
            std::fs::rename(staging.join(from), &to).map_err(|e| fail("write", &to, e))
        };
        into(PROVISIONAL, MANIFEST)?;
        for name in names.iter().filter(|n| **n != MANIFEST) {
            into(name, name)?;
        }
        if names.contains(MANIFEST) {
            into(MANIFEST, MANIFEST)?;
        }
        remove_listed(
            &self.target,
            previous
                .ours
                .iter()
                .map(String::as_str)
                .filter(|n| !names.contains(n)),
        );
        Ok(Vec::new())
    }
}

/// The staged manifest that lists an unfinished in-place write.
const PROVISIONAL: &str = "manifest.json.provisional";

/// Writes `files` into the fresh folder `staging`; on failure removes them and it.
fn stage(staging: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    write_files(staging, files).inspect_err(|_| {
        remove_listed(staging, files.iter().map(|(n, _)| n.as_str()));
        let _ = std::fs::remove_dir(staging);
    })
}

/// Gives `staged` the permissions and (where allowed) the owner and group of the
/// folder `old` it replaces, so a shared folder stays shared.
fn keep_folder_attributes(old: &Path, staged: &Path) {
    let Ok(meta) = std::fs::metadata(old) else {
        return;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = std::os::unix::fs::chown(staged, Some(meta.uid()), Some(meta.gid()));
    }
    let _ = std::fs::set_permissions(staged, meta.permissions());
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
    Error::Io {
        action: what.to_string(),
        path: path.to_path_buf(),
        source: e,
    }
}

/// The files an earlier run's manifest says it wrote, or `None` when the bytes are not
/// a manifest of unfold's. Manifests list their files under `files`. Older ones list
/// only each sheet's SVG; of what they leave out, only the assembled model is known to
/// be unfold's, by the first line it always has (`is_assembled_model` reads it): a DXF
/// beside the SVG may be the user's own, since older runs wrote none by default.
fn listed_files(
    bytes: &[u8],
    is_assembled_model: impl Fn(&str) -> bool,
) -> Option<BTreeSet<String>> {
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
                names.push(sheet.get("file")?.as_str()?.to_string());
            }
            let input = manifest.pointer("/input/path")?.as_str()?;
            if let Some(stem) = Path::new(input).file_stem() {
                let obj = format!("{}-assembled.obj", stem.to_string_lossy());
                if is_assembled_model(&obj) {
                    names.push(obj);
                }
            }
            names
        }
    };
    Some(names.into_iter().filter(|n| plain(n)).collect())
}

/// The first line of every assembled model unfold writes.
pub const ASSEMBLED_HEADER: &str = "# unfold: panels as assembled";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifests_of_other_tools_list_nothing() {
        assert_eq!(
            listed_files(b"{\"tool\": {\"name\": \"other\"}}", |_| true),
            None
        );
        assert_eq!(listed_files(b"not json", |_| true), None);
        let listed = listed_files(
            b"{\"tool\": {\"name\": \"unfold\"}, \"files\": [\"a.svg\", \"../x\", \"sub/y\"]}",
            |_| true,
        )
        .unwrap();
        assert_eq!(listed, BTreeSet::from(["a.svg".to_string()]));
    }

    #[test]
    fn older_manifests_imply_only_the_assembled_model_that_is_unfolds() {
        let older = b"{\"tool\": {\"name\": \"unfold\"}, \"input\": {\"path\": \"models/cube.obj\"}, \"sheets\": [{\"file\": \"cube-01.svg\"}]}";
        let listed = listed_files(older, |name| name == "cube-assembled.obj").unwrap();
        let want: BTreeSet<String> = ["cube-01.svg", "cube-assembled.obj"]
            .map(String::from)
            .into();
        assert_eq!(listed, want);
        let listed = listed_files(older, |_| false).unwrap();
        assert_eq!(listed, BTreeSet::from(["cube-01.svg".to_string()]));
    }
}
