//! The layering of the source tree, read from the files themselves: the schemes are
//! named only inside `src/scheme/`, and each layer imports only what lies below it; and
//! `cargo build` and `cargo test` build the dependencies with the same features.
//!
//! ```text
//! error, units, record, rng, plane, font   (leaves)
//! mesh → panel → labels, flatten, kerf
//! scheme         nest
//! export         config, sanity, run, cli, lib
//! ```

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// A file's code with its comment lines blanked (line numbers kept).
fn code(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("//") {
                ""
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The top-level modules a file names through `crate::` (`use crate::{a, b::c}`, also
/// over several lines, and paths like `crate::a::f()`), with the line of each.
fn crate_modules(path: &Path) -> Vec<(usize, String)> {
    let text = code(path);
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut found = Vec::new();
    let mut at = 0;
    while let Some(i) = text[at..].find("crate::") {
        let start = at + i;
        let line = text[..start].matches('\n').count() + 1;
        let rest = &text[start + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            found.extend(
                group[..end]
                    .split(',')
                    .map(ident)
                    .filter(|n| !n.is_empty())
                    .map(|n| (line, n)),
            );
        } else {
            found.push((line, ident(rest)));
        }
        at = start + "crate::".len();
    }
    found
}

/// The offences of the files under `src/DIR` (or of `src/DIR.rs` too) against importing
/// the modules `banned`.
fn imports_of(dir: &str, banned: &[&str]) -> Vec<String> {
    let root = src().join(dir);
    let mut files = if root.is_dir() {
        rust_files(&root)
    } else {
        Vec::new()
    };
    let single = src().join(format!("{dir}.rs"));
    if single.is_file() {
        files.push(single);
    }
    let mut offences = Vec::new();
    for file in files {
        for (line, module) in crate_modules(&file) {
            if banned.contains(&module.as_str()) {
                offences.push(format!(
                    "{}:{line} uses crate::{module}",
                    file.strip_prefix(src()).unwrap().display()
                ));
            }
        }
    }
    offences
}

#[test]
fn schemes_are_named_only_in_their_own_files() {
    let names = [
        "HalfEdge",
        "QuadEdge",
        "WingedEdge",
        "Woven",
        "NetOptions",
        "net::Net",
        "WeaveCycle",
        "trace_cycles",
    ];
    let mut offences = Vec::new();
    for file in rust_files(&src()) {
        if file.starts_with(src().join("scheme")) {
            continue;
        }
        // Comments included: the grep of the source the layout promises.
        let text = std::fs::read_to_string(&file).unwrap();
        for (i, line) in text.lines().enumerate() {
            if let Some(name) = names.iter().find(|n| line.contains(*n)) {
                offences.push(format!(
                    "{}:{}: {name}",
                    file.strip_prefix(src()).unwrap().display(),
                    i + 1
                ));
            }
        }
    }
    assert!(offences.is_empty(), "{}", offences.join("\n"));
}

#[test]
fn each_layer_imports_only_what_lies_below_it() {
    let above_mesh = [
        "scheme", "panel", "labels", "flatten", "kerf", "nest", "export", "config", "sanity",
        "run", "cli", "plane", "font",
    ];
    let above_scheme = ["nest", "export", "config", "sanity", "run", "cli"];
    let mut offences = Vec::new();
    offences.extend(imports_of("mesh", &above_mesh));
    offences.extend(imports_of("scheme", &above_scheme));
    // Panels are data: label fitting and unrolling read them, not the other way.
    offences.extend(imports_of(
        "panel",
        &[
            "labels", "flatten", "kerf", "scheme", "nest", "export", "config", "run",
        ],
    ));
    // The kerf offsets flat panels; it knows nothing of where they came from.
    offences.extend(imports_of(
        "kerf",
        &[
            "mesh", "scheme", "nest", "export", "config", "sanity", "run", "cli",
        ],
    ));
    offences.extend(imports_of(
        "nest",
        &["mesh", "scheme", "export", "config", "sanity", "run", "cli"],
    ));
    offences.extend(imports_of(
        "export",
        &["mesh", "scheme", "config", "sanity", "run", "cli"],
    ));
    assert!(offences.is_empty(), "{}", offences.join("\n"));
}

#[test]
fn the_mesh_and_the_nester_know_nothing_of_the_command_line() {
    let mut offences = Vec::new();
    for dir in ["mesh", "nest"] {
        for file in rust_files(&src().join(dir)) {
            let text = code(&file);
            for (i, line) in text.lines().enumerate() {
                if line.contains("clap::") || line.contains("use clap") {
                    offences.push(format!(
                        "{}:{}: {}",
                        file.strip_prefix(src()).unwrap().display(),
                        i + 1,
                        line.trim()
                    ));
                }
            }
        }
    }
    assert!(offences.is_empty(), "{}", offences.join("\n"));
}

#[test]
fn the_import_reader_sees_grouped_and_inline_paths() {
    let tmp = tempfile::TempDir::new().unwrap();
    let file = tmp.path().join("x.rs");
    std::fs::write(
        &file,
        "use crate::{mesh::Mesh, nest};\n// crate::config in a comment\nuse crate::{\n    plane::area,\n    units,\n};\nlet r = crate::scheme::SCHEMES;\n",
    )
    .unwrap();
    let found: Vec<String> = crate_modules(&file).into_iter().map(|(_, m)| m).collect();
    assert_eq!(found, ["mesh", "nest", "plane", "units", "scheme"]);
}

/// `cargo tree` of this package with the given edge kinds: each package and version
/// with its enabled features, once.
fn features_by_package(edges: &str) -> std::collections::BTreeMap<String, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let out = std::process::Command::new(cargo)
        .args(["tree", "--offline", "--prefix", "none", "-e", edges])
        .args(["-f", "{p}|{f}"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .filter_map(|l| l.split_once('|'))
        .map(|(package, features)| {
            let package = package
                .trim_end_matches(" (*)")
                .trim_end_matches(" (proc-macro)");
            (
                package.to_string(),
                features.trim_end_matches(" (*)").to_string(),
            )
        })
        .collect()
}

/// The crates shared with the dev-dependencies get the same features in `cargo build`
/// as in `cargo test`, so the two share one build of them and of this crate (the
/// feature list in `Cargo.toml` says why).
#[test]
fn the_build_and_the_tests_share_their_dependencies_features() {
    let built = features_by_package("normal,build");
    let tested = features_by_package("normal,build,dev");
    let differ: Vec<String> = built
        .iter()
        .filter(|(package, features)| tested.get(*package) != Some(*features))
        .map(|(package, features)| {
            format!(
                "{package}: [{features}] built, [{}] tested",
                tested[package]
            )
        })
        .collect();
    assert!(
        differ.is_empty(),
        "declare these features in Cargo.toml's [dependencies]:\n{}",
        differ.join("\n")
    );
}

/// A file's product code: its text up to its test module (`#[cfg(test)]` before a
/// `mod name {`; a `#[cfg(test)] mod name;` declaration is not one), comment lines
/// blanked.
fn product_code(path: &Path) -> String {
    let text = code(path);
    let mut at = 0;
    while let Some(i) = text[at..].find("#[cfg(test)]") {
        let start = at + i;
        let after = text[start + "#[cfg(test)]".len()..].trim_start();
        let line = after.lines().next().unwrap_or("");
        if line.starts_with("mod ") && line.contains('{') {
            return text[..start].to_string();
        }
        at = start + 1;
    }
    text
}

/// The module path of a file under `src/` (`scheme/edge/quad.rs` → `scheme::edge::quad`;
/// a `mod.rs` names its folder; `lib.rs` and `main.rs` the crate root, empty).
fn module_of(file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src()).unwrap();
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// Reads one `use` tree at the start of `s` (`a::b::{c, d::e}`) into full paths.
fn use_tree(s: &str) -> Vec<Vec<String>> {
    fn tree(s: &[u8], at: &mut usize) -> Vec<Vec<String>> {
        let mut prefix = Vec::new();
        loop {
            while *at < s.len() && s[*at].is_ascii_whitespace() {
                *at += 1;
            }
            if *at < s.len() && s[*at] == b'{' {
                *at += 1;
                let mut all = Vec::new();
                loop {
                    while *at < s.len() && (s[*at].is_ascii_whitespace() || s[*at] == b',') {
                        *at += 1;
                    }
                    if *at >= s.len() || s[*at] == b'}' {
                        *at += 1;
                        break;
                    }
                    for sub in tree(s, at) {
                        all.push(prefix.iter().cloned().chain(sub).collect());
                    }
                }
                return all;
            }
            let start = *at;
            while *at < s.len() && (s[*at].is_ascii_alphanumeric() || s[*at] == b'_') {
                *at += 1;
            }
            if *at == start {
                // `*` or the end: the prefix itself.
                if *at < s.len() && s[*at] == b'*' {
                    *at += 1;
                }
                return vec![prefix];
            }
            prefix.push(String::from_utf8_lossy(&s[start..*at]).to_string());
            if s[*at..].starts_with(b"::") {
                *at += 2;
            } else {
                return vec![prefix];
            }
        }
    }
    tree(s.as_bytes(), &mut 0)
}

/// `text` without its re-exports (`pub use …;`): they make a folder's public face, not
/// a dependency of the file.
fn without_reexports(text: &str) -> String {
    let mut skipping = false;
    let mut kept = Vec::new();
    for line in text.lines() {
        let t = line.trim_start();
        let reexport = t.starts_with("pub use ")
            || (t.starts_with("pub(")
                && t.split_once(')')
                    .is_some_and(|(_, r)| r.starts_with(" use ")));
        skipping = skipping || reexport;
        kept.push(if skipping { "" } else { line });
        if skipping && line.contains(';') {
            skipping = false;
        }
    }
    kept.join("\n")
}

/// The modules a file declares (`mod name;`).
fn child_modules(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| {
            let t = l.trim_start();
            let t = match t.strip_prefix("pub") {
                Some(r) => r.split_once("mod ").map(|(_, r)| r)?,
                None => t.strip_prefix("mod ")?,
            };
            let name = t.strip_suffix(';')?;
            name.chars()
                .all(|c| c.is_alphanumeric() || c == '_')
                .then(|| name.to_string())
        })
        .collect()
}

/// The crate paths a file's product code names through `crate::`, `super::`, `self::`
/// or a module it declares (in `use` lines and inline), as full module paths.
fn named_paths(file: &Path) -> Vec<Vec<String>> {
    named_paths_in(file, &module_of(file))
}

/// [`named_paths`] of a file read as the module `here`.
fn named_paths_in(file: &Path, here: &[String]) -> Vec<Vec<String>> {
    let text = without_reexports(&product_code(file));
    // The module that `self` names; `super` names its parent.
    let here = here.to_vec();
    let children = child_modules(&text);
    let mut paths = Vec::new();
    let bytes = text.as_bytes();
    let mut at = 0;
    while at < text.len() {
        let rest = &text[at..];
        let word_start = at == 0
            || !(bytes[at - 1].is_ascii_alphanumeric()
                || bytes[at - 1] == b'_'
                || bytes[at - 1] == b':');
        let start: Option<(Vec<String>, usize)> = if !word_start {
            None
        } else if rest.starts_with("crate::") {
            Some((Vec::new(), "crate::".len()))
        } else if rest.starts_with("self::") {
            Some((here.clone(), "self::".len()))
        } else if rest.starts_with("super::") {
            let mut base = here.clone();
            let mut i = 0;
            while rest[i..].starts_with("super::") {
                base.pop();
                i += "super::".len();
            }
            Some((base, i))
        } else {
            children
                .iter()
                .find(|c| rest.starts_with(c.as_str()) && rest[c.len()..].starts_with("::"))
                .map(|c| {
                    let base = here.iter().cloned().chain([c.clone()]).collect();
                    (base, c.len() + 2)
                })
        };
        match start {
            Some((base, skip)) => {
                for tail in use_tree(&rest[skip..]) {
                    paths.push(base.iter().cloned().chain(tail).collect());
                }
                at += skip;
            }
            None => at += rest.chars().next().map_or(1, char::len_utf8),
        }
    }
    paths
}

/// The scheme modules: each file with `impl Scheme for`, or its folder when it is a
/// `mod.rs`.
fn scheme_modules() -> Vec<Vec<String>> {
    rust_files(&src().join("scheme"))
        .into_iter()
        .filter(|f| product_code(f).contains("impl Scheme for"))
        .map(|f| module_of(&f))
        .collect()
}

/// The offences of `files` against importing a sibling scheme: a path under another
/// scheme's module than the file's own.
fn sibling_scheme_imports(files: &[PathBuf], schemes: &[Vec<String>]) -> Vec<String> {
    let mut offences = Vec::new();
    for file in files {
        let own = module_of(file);
        let Some(mine) = schemes.iter().find(|s| own.starts_with(s)) else {
            continue;
        };
        for path in named_paths(file) {
            if let Some(other) = schemes.iter().find(|s| *s != mine && path.starts_with(s)) {
                offences.push(format!(
                    "{} uses {} of the {} scheme",
                    file.strip_prefix(src()).unwrap().display(),
                    path.join("::"),
                    other.join("::")
                ));
            }
        }
    }
    offences.sort();
    offences.dedup();
    offences
}

/// Checks `found` against the offences still to be mended, `known`: a new offence
/// fails (with `fix`), and so does a known one that is gone (take it off the list).
fn ratchet(found: &[String], known: &[&str], fix: &str) {
    let new: Vec<&String> = found
        .iter()
        .filter(|f| !known.iter().any(|k| f.starts_with(k)))
        .collect();
    assert!(
        new.is_empty(),
        "{fix}:\n{}",
        new.iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
    let mended: Vec<&&str> = known
        .iter()
        .filter(|k| !found.iter().any(|f| f.starts_with(**k)))
        .collect();
    assert!(
        mended.is_empty(),
        "mended, so no longer on the list of what is still to mend: {mended:?}"
    );
}

/// Sibling-scheme imports still to be moved to a shared module: none.
const SIBLING_IMPORTS_TO_MEND: &[&str] = &[];

#[test]
fn a_scheme_never_imports_a_sibling_scheme() {
    let schemes = scheme_modules();
    assert_eq!(schemes.len(), 6, "schemes found: {schemes:?}");
    let offences = sibling_scheme_imports(&rust_files(&src().join("scheme")), &schemes);
    ratchet(
        &offences,
        SIBLING_IMPORTS_TO_MEND,
        "what two schemes share goes to scheme/kit/ or their family's folder",
    );
}

#[test]
fn a_scheme_importing_a_sibling_is_found() {
    let tmp = tempfile::TempDir::new().unwrap();
    let scheme = tmp.path().join("scheme");
    std::fs::create_dir_all(&scheme).unwrap();
    let file = scheme.join("net.rs");
    std::fs::write(
        &file,
        "use crate::scheme::half_edge::{make_tab, Tab};\nfn f() { super::woven::g(); }\n",
    )
    .unwrap();
    let paths: Vec<String> = named_paths_in(&file, &["scheme".into(), "net".into()])
        .into_iter()
        .map(|p| p.join("::"))
        .collect();
    assert_eq!(
        paths,
        [
            "scheme::half_edge::make_tab",
            "scheme::half_edge::Tab",
            "scheme::woven::g"
        ]
    );
}

/// Most lines of product code in one file (up to its `#[cfg(test)]` module).
const MOST_FILE_LINES: usize = 1000;

/// Files still over the limit, to be split by concern: none.
const LONG_FILES_TO_SPLIT: &[&str] = &[];

#[test]
fn no_file_of_product_code_is_over_a_thousand_lines() {
    let long: Vec<String> = rust_files(&src())
        .into_iter()
        .filter_map(|f| {
            let lines = product_code(&f).lines().count();
            (lines > MOST_FILE_LINES).then(|| {
                format!(
                    "{}: {lines} lines",
                    f.strip_prefix(src()).unwrap().display()
                )
            })
        })
        .collect();
    ratchet(
        &long,
        LONG_FILES_TO_SPLIT,
        &format!("split these by concern (at most {MOST_FILE_LINES} lines before the tests)"),
    );
}

/// The import graph between files: for each file, the files whose modules its
/// product code names (a path's longest prefix that is a file's module; the crate
/// root and a file's own ancestors' declarations are not edges unless named).
fn file_imports(files: &[PathBuf]) -> Vec<Vec<usize>> {
    let modules: Vec<Vec<String>> = files.iter().map(|f| module_of(f)).collect();
    files
        .iter()
        .enumerate()
        .map(|(i, file)| {
            let mut to: Vec<usize> = named_paths(file)
                .iter()
                .filter_map(|path| {
                    (1..=path.len())
                        .rev()
                        .find_map(|n| modules.iter().position(|m| m[..] == path[..n]))
                })
                .filter(|&j| j != i && !modules[j].is_empty())
                .collect();
            to.sort_unstable();
            to.dedup();
            to
        })
        .collect()
}

/// The groups of files that import each other round a circle (strongly connected
/// components of more than one file), each sorted.
fn import_circles(edges: &[Vec<usize>]) -> Vec<Vec<usize>> {
    // Kosaraju: finish order on the graph, then components on its reverse.
    let n = edges.len();
    let mut order = Vec::new();
    let mut seen = vec![false; n];
    for start in 0..n {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let mut stack = vec![(start, 0)];
        while let Some((v, k)) = stack.pop() {
            if k < edges[v].len() {
                stack.push((v, k + 1));
                let w = edges[v][k];
                if !seen[w] {
                    seen[w] = true;
                    stack.push((w, 0));
                }
            } else {
                order.push(v);
            }
        }
    }
    let mut reverse = vec![Vec::new(); n];
    for (v, to) in edges.iter().enumerate() {
        for &w in to {
            reverse[w].push(v);
        }
    }
    let mut component = vec![usize::MAX; n];
    let mut circles = Vec::new();
    for &root in order.iter().rev() {
        if component[root] != usize::MAX {
            continue;
        }
        let mut members = vec![root];
        component[root] = root;
        let mut k = 0;
        while k < members.len() {
            for &w in &reverse[members[k]] {
                if component[w] == usize::MAX {
                    component[w] = root;
                    members.push(w);
                }
            }
            k += 1;
        }
        if members.len() > 1 {
            members.sort_unstable();
            circles.push(members);
        }
    }
    circles.sort();
    circles
}

/// Import circles still to be broken: none.
const CIRCLES_TO_BREAK: &[&str] = &[];

#[test]
fn no_two_files_import_each_other_round_a_circle() {
    let files = rust_files(&src());
    let circles: Vec<String> = import_circles(&file_imports(&files))
        .into_iter()
        .map(|c| {
            c.iter()
                .map(|&i| files[i].strip_prefix(src()).unwrap().display().to_string())
                .collect::<Vec<_>>()
                .join(" ↔ ")
        })
        .collect();
    ratchet(
        &circles,
        CIRCLES_TO_BREAK,
        "move what both use into a file below them",
    );
}

#[test]
fn the_path_reader_resolves_groups() {
    let found = use_tree("scheme::{kit::tab::{Tab, make_tab}, net} as x;");
    assert_eq!(
        found,
        [
            vec!["scheme", "kit", "tab", "Tab"],
            vec!["scheme", "kit", "tab", "make_tab"],
            vec!["scheme", "net"],
        ]
    );
}

#[test]
fn the_circle_finder_finds_only_circles() {
    // 0 → 1 → 2 → 0 is a circle; 3 → 0 and 4 alone are not.
    let edges = vec![vec![1], vec![2], vec![0], vec![0], vec![]];
    assert_eq!(import_circles(&edges), [vec![0, 1, 2]]);
    assert!(import_circles(&[vec![1], vec![]]).is_empty());
}
