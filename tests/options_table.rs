//! README's option tables against the tool's own defaults: every row
//! `` | `--name …` | default | meaning | `` names options the tool has, every option of
//! the command (`unfold --help`, `unfold inspect --help` and every registered scheme's)
//! has a row, and each row's default column says what the code does.
//!
//! The code's default of an option is read from one place: for the options every run
//! takes, [`unfold::config::defaults::option_defaults`]; for a scheme's own option, the
//! `[default: …]` its help ends with (or clap's default value, if it has one). The
//! README cell is compared by this rule:
//!
//! * A default that is one value (`0.25in`, `32`, `true-shape`; for a scheme's option, a
//!   `[default: …]` whose text before any comma is one word): the cell is exactly that
//!   value in backticks. Words after the value in `--help` (`0mm, nominal geometry`)
//!   say what it means and are not compared.
//! * A switch: the cell is `off`.
//! * A default per scheme (`--face-scale`, `--holes`): the cell lists values in backticks,
//!   each followed by the schemes it holds for in parentheses. The values are exactly
//!   the schemes' distinct values, and every registered scheme named in a parenthesis has
//!   that value; words there that name no scheme ("edge schemes", "others") are not
//!   checked.
//! * A default that is words, not one value (`none`, `no limit`, `half the
//!   --hole-diameter`, `the model's own size in --units`): the cell must not be a value,
//!   so every fragment it has in backticks appears in the code's words (`./NAME` and
//!   `--units` do) and a cell without backticks passes, since words cannot be compared
//!   exactly.

use std::collections::BTreeSet;
use std::process::Command;

use unfold::config::defaults::{option_defaults, Stated};
use unfold::scheme::Registry;
use unfold::BuildOptions;

/// One option row of README.
struct Row {
    /// Its line number, for messages.
    line: usize,
    /// The long names in its first cell (`--json`, `--quiet` share a row).
    options: Vec<String>,
    /// Its default cell, trimmed.
    default: String,
}

/// What the code says an option's default is.
#[derive(Debug)]
enum CodeDefault {
    /// One value.
    Value(String),
    /// A switch: off unless given.
    Switch,
    /// Each scheme's value.
    PerScheme(Vec<(String, String)>),
    /// Words, not one value.
    Words(String),
}

/// The option rows of README.
fn readme_rows() -> Vec<Row> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/README.md");
    let text = std::fs::read_to_string(path).expect("README.md reads");
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("| `--"))
        .map(|(i, l)| {
            let cells: Vec<&str> = l.split(" | ").collect();
            assert!(
                cells.len() >= 3,
                "README.md:{}: not three cells: {l}",
                i + 1
            );
            Row {
                line: i + 1,
                options: longs_in(cells[0]),
                default: cells[1].trim().to_string(),
            }
        })
        .collect()
}

/// The long names (`--name`, without dashes) in `text`.
fn longs_in(text: &str) -> Vec<String> {
    text.match_indices("--")
        .map(|(at, _)| {
            text[at + 2..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect::<String>()
        })
        .filter(|name| !name.is_empty())
        .collect()
}

/// The fragments of `cell` in backticks.
fn backticked(cell: &str) -> Vec<&str> {
    cell.split('`').skip(1).step_by(2).collect()
}

/// Every option's default as the code states it, by long name.
fn code_defaults(registry: &Registry) -> Vec<(String, CodeDefault)> {
    let command = BuildOptions::command(registry);
    let is_switch = |long: &str| {
        command
            .get_arguments()
            .chain(registry.options().iter())
            .any(|a| a.get_long() == Some(long) && !a.get_action().takes_values())
    };
    let mut defaults: Vec<(String, CodeDefault)> = option_defaults(registry)
        .into_iter()
        .map(|d| {
            let code = match d.stated {
                _ if is_switch(d.long) => CodeDefault::Switch,
                Stated::Value { text, .. } => CodeDefault::Value(text),
                Stated::PerScheme { values, .. } => CodeDefault::PerScheme(
                    values
                        .into_iter()
                        .map(|(scheme, v)| (scheme.to_string(), v))
                        .collect(),
                ),
                Stated::Words(words) => CodeDefault::Words(words.to_string()),
            };
            (d.long.to_string(), code)
        })
        .collect();
    for arg in registry.options() {
        let long = arg.get_long().expect("scheme options are long").to_string();
        let code = if !arg.get_action().takes_values() {
            CodeDefault::Switch
        } else {
            scheme_option_default(&arg)
        };
        defaults.push((long, code));
    }
    defaults
}

/// A scheme option's default: clap's default value, or the `[default: …]` its help
/// ends with.
fn scheme_option_default(arg: &clap::Arg) -> CodeDefault {
    if let Some(value) = arg.get_default_values().first() {
        return CodeDefault::Value(value.to_string_lossy().into_owned());
    }
    let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
    let long = arg.get_long().unwrap_or("");
    let start = help
        .rfind("[default: ")
        .unwrap_or_else(|| panic!("--{long}: its help states no default: {help}"));
    let stated = help[start + "[default: ".len()..].trim_end_matches(']');
    let head = stated.split(", ").next().unwrap_or(stated);
    if head.contains(char::is_whitespace) {
        CodeDefault::Words(stated.to_string())
    } else {
        CodeDefault::Value(head.to_string())
    }
}

/// Says why `cell` does not state `code`, if it does not.
fn disagreement(cell: &str, code: &CodeDefault) -> Option<String> {
    match code {
        CodeDefault::Value(v) if cell != format!("`{v}`") => Some(format!("the code's is `{v}`")),
        CodeDefault::Switch if cell != "off" => Some("a switch is off".to_string()),
        CodeDefault::Words(words) => backticked(cell)
            .into_iter()
            .find(|fragment| !words.contains(fragment))
            .map(|fragment| format!("`{fragment}` is not in the code's default \"{words}\"")),
        CodeDefault::PerScheme(values) => per_scheme_disagreement(cell, values),
        _ => None,
    }
}

/// Says why `cell` (`` `1` (half-edge, net), `0.5` (edge schemes) ``) does not state
/// the schemes' `values`, if it does not.
fn per_scheme_disagreement(cell: &str, values: &[(String, String)]) -> Option<String> {
    let code: BTreeSet<&str> = values.iter().map(|(_, v)| v.as_str()).collect();
    let mut readme = BTreeSet::new();
    let parts: Vec<&str> = cell.split('`').collect();
    for pair in parts[1..].chunks(2) {
        let value = pair[0];
        readme.insert(value);
        let after = pair.get(1).copied().unwrap_or("");
        let names = after
            .split_once('(')
            .and_then(|(_, rest)| rest.split_once(')'))
            .map_or("", |(inside, _)| inside);
        for name in names.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')) {
            if let Some((scheme, v)) = values.iter().find(|(s, _)| s == name) {
                if v != value {
                    return Some(format!("{scheme}'s is `{v}`, not `{value}`"));
                }
            }
        }
    }
    (readme != code).then(|| format!("the schemes' values are {code:?}"))
}

/// The long options `unfold ARGS` lists (help and version aside).
fn listed_options(args: &[&str]) -> BTreeSet<String> {
    let output = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(args)
        .output()
        .expect("the unfold binary runs");
    let help = String::from_utf8_lossy(&output.stdout);
    help.lines()
        .filter(|l| l.trim_start().starts_with("--"))
        .flat_map(|l| longs_in(l).into_iter().take(1))
        .filter(|name| name != "help" && name != "version")
        .collect()
}

#[test]
fn every_readme_default_is_the_codes() {
    let registry = Registry::default();
    let code = code_defaults(&registry);
    let mut mistakes = Vec::new();
    for row in readme_rows() {
        for option in &row.options {
            match code.iter().find(|(long, _)| long == option) {
                None => mistakes.push(format!(
                    "README.md:{}: --{option} is not an option of unfold",
                    row.line
                )),
                Some((_, default)) => {
                    if let Some(why) = disagreement(&row.default, default) {
                        mistakes.push(format!(
                            "README.md:{}: --{option}: README says {}, but {why}",
                            row.line, row.default
                        ));
                    }
                }
            }
        }
    }
    assert!(mistakes.is_empty(), "{}", mistakes.join("\n"));
}

#[test]
fn every_option_has_a_readme_row_and_a_default() {
    let registry = Registry::default();
    let code = code_defaults(&registry);
    let in_readme: BTreeSet<String> = readme_rows().into_iter().flat_map(|r| r.options).collect();
    let missing: Vec<&String> = code
        .iter()
        .map(|(long, _)| long)
        .filter(|long| !in_readme.contains(*long))
        .collect();
    assert!(
        missing.is_empty(),
        "options without a README row: {missing:?}"
    );
    let mut listed = listed_options(&["--help"]);
    listed.extend(listed_options(&["inspect", "--help"]));
    assert!(
        listed.len() >= 40,
        "only {} options read off --help",
        listed.len()
    );
    let without_default: Vec<&String> = listed
        .iter()
        .filter(|long| !code.iter().any(|(l, _)| l == *long))
        .collect();
    assert!(
        without_default.is_empty(),
        "options of --help the defaults table does not know: {without_default:?}"
    );
}

#[test]
fn the_rule_refuses_a_readme_that_disagrees() {
    let value = CodeDefault::Value("0.25in".to_string());
    assert!(disagreement("`0.25in`", &value).is_none());
    assert!(disagreement("`0.5in`", &value).is_some());
    assert!(disagreement("none", &value).is_some());
    assert!(disagreement("off", &CodeDefault::Switch).is_none());
    assert!(disagreement("`0`", &CodeDefault::Switch).is_some());
    let words = CodeDefault::Words("the model's own size in --units".to_string());
    assert!(disagreement("model size × `--units`", &words).is_none());
    assert!(disagreement("`1`", &words).is_some());
    let per_scheme = CodeDefault::PerScheme(vec![
        ("half-edge".to_string(), "1".to_string()),
        ("net".to_string(), "1".to_string()),
        ("woven".to_string(), "0.8".to_string()),
    ]);
    assert!(disagreement("`1` (half-edge, net), `0.8` (woven)", &per_scheme).is_none());
    assert!(disagreement("`1` (half-edge), `0.8` (others)", &per_scheme).is_none());
    assert!(disagreement("`1` (half-edge, woven), `0.8` (net)", &per_scheme).is_some());
    assert!(disagreement("`1` (half-edge)", &per_scheme).is_some());
}
