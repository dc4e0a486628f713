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
