//! The TOML configuration file. Its keys are the main command's long option names
//! (`sheet = "18x24in"`, `target-edges = 600`, `quiet = true`); every option but
//! `--config` itself is a key. Each key and value is checked here against the option's
//! own definition, so a mistake is reported at its line and column, naming the key, the
//! nearest valid key and what the value should look like.

use std::any::TypeId;
use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};

use super::layers::LayerSettings;
use super::model::ModelOptions;
use super::options::BuildOptions;
use super::sheet::parse_sheet;
use super::values::TargetEdges;
use crate::error::{Error, Result};
use crate::scheme::{OptionValues, Registry};
use crate::units::parse_length;

/// The message for a length or sheet written without quotes on the line at `offset`
/// (`size = 4ft`), which TOML cannot read as a number: the key and the quoted value.
fn unquoted_length(text: &str, offset: usize) -> Option<String> {
    let start = text[..offset.min(text.len())]
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?;
    let (key, value) = line.split_once('=')?;
    let (key, value) = (key.trim(), value.split('#').next()?.trim());
    let looks_like_text = !value.starts_with(['"', '\'', '[', '{'])
        && (parse_length(value).is_ok() || parse_sheet(value).is_ok());
    looks_like_text.then(|| {
        format!("{key} = {value}: a length or a sheet is text in TOML: write {key} = \"{value}\"")
    })
}

/// Reads a configuration file into options (every key optional); the schemes' own
/// keys are those of `registry`.
pub fn load_config(path: &Path, registry: &Registry) -> Result<BuildOptions> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Usage(format!("--config {}: cannot read it: {e}", path.display())))?;
    let at = |span: Option<Range<usize>>, what: String| {
        let place = match span {
            Some(span) => {
                let (line, column) = line_column(&text, span.start);
                format!("{}:{line}:{column}", path.display())
            }
            None => path.display().to_string(),
        };
        Error::Usage(format!("--config {place}: {what}"))
    };
    let table = DeTable::parse(&text).map_err(|e| {
        let unquoted = e.span().and_then(|span| unquoted_length(&text, span.start));
        match unquoted {
            Some(hint) => at(e.span(), hint),
            None => at(
                e.span(),
                format!("not valid TOML: {}", one_line(e.message())),
            ),
        }
    })?;
    let options = options(registry);
    let scheme_keys: Vec<String> = registry
        .options()
        .iter()
        .filter_map(|a| a.get_long().map(str::to_string))
        .collect();
    let mut scheme_values = OptionValues::default();
    // In file order, so the first mistake reported is the first in the file.
    let mut entries: Vec<_> = table.get_ref().iter().collect();
    entries.sort_by_key(|(key, _)| key.span().start);
    let mut layers = LayerSettings::default();
    for (key, value) in entries {
        let name = key.get_ref().as_ref();
        // `layers` is both the edge schemes' layer count (a number) and the table of
        // laser kinds.
        if name == "layers" && !matches!(value.get_ref(), DeValue::Integer(_)) {
            read_layers(value, &mut layers).map_err(|(span, why)| at(Some(span), why))?;
            continue;
        }
        let Some(option) = options.iter().find(|o| o.key == name) else {
            return Err(at(Some(key.span()), unknown_key(name, &options)));
        };
        check_value(option, value.get_ref()).map_err(|why| {
            at(
                Some(value.span()),
                format!("{name} = {}: {why}", shown(&text, value.span())),
            )
        })?;
        if scheme_keys.iter().any(|k| k == name) {
            let raw = text.get(value.span()).unwrap_or("").trim();
            let as_text = match value.get_ref() {
                DeValue::String(s) => s.to_string(),
                DeValue::Boolean(b) => b.to_string(),
                _ => raw.replace('_', ""),
            };
            scheme_values.set_from_file(name, &as_text);
        }
    }
    // Every key and value was checked above; what remains are errors of the
    // deserializer itself, still placed by their span.
    let build: BuildOptions =
        toml::from_str(&text).map_err(|e| at(e.span(), one_line(e.message())))?;
    let model: ModelOptions =
        toml::from_str(&text).map_err(|e| at(e.span(), one_line(e.message())))?;
    Ok(BuildOptions {
        model,
        scheme_values,
        layers,
        ..build
    })
}

/// A place in the file and what is wrong there.
type Mistake = (Range<usize>, String);

/// Reads the `[layers.KIND]` tables: each kind's `name`, `color` and `stroke-width`.
fn read_layers(
    value: &toml::Spanned<DeValue>,
    layers: &mut LayerSettings,
) -> std::result::Result<(), Mistake> {
    let kinds = LayerSettings::KEYS.join(", ");
    let DeValue::Table(table) = value.get_ref() else {
        return Err((
            value.span(),
            format!(
                "layers is a table of kinds ({kinds}): write [layers.cut] and its keys below it (or, for the edge schemes' sandwich, layers = 2)"
            ),
        ));
    };
    for (kind, fields) in table.iter() {
        let kind_name = kind.get_ref().as_ref();
        let Some(k) = LayerSettings::KEYS.iter().position(|&n| n == kind_name) else {
            return Err((
                kind.span(),
                format!("layers.{kind_name}: not a kind of laser geometry; the kinds are {kinds}"),
            ));
        };
        let DeValue::Table(fields) = fields.get_ref() else {
            return Err((
                fields.span(),
                format!("layers.{kind_name} is a table: write [layers.{kind_name}] with name, color or stroke-width below it"),
            ));
        };
        for (field, text) in fields.iter() {
            let field_name = field.get_ref().as_ref();
            let place = format!("layers.{kind_name}.{field_name}");
            let DeValue::String(text_value) = text.get_ref() else {
                return Err((
                    text.span(),
                    format!(
                        "{place}: text in quotes, like {field_name} = \"{}\"",
                        match field_name {
                            "color" => "#FF0000",
                            "stroke-width" => "0.001in",
                            _ => "CUT",
                        }
                    ),
                ));
            };
            let text_value = text_value.to_string();
            let setting = &mut layers.0[k];
            let checked = match field_name {
                "name" => super::layers::check_layer_name(&text_value)
                    .map(|()| setting.name = Some(text_value)),
                "color" => {
                    super::layers::check_layer_color(&text_value).map(|c| setting.color = Some(c))
                }
                "stroke-width" => {
                    parse_length(&text_value).map(|_| setting.stroke_width = Some(text_value))
                }
                _ => Err(
                    "not a layer setting; a layer takes name, color and stroke-width".to_string(),
                ),
            };
            checked.map_err(|why| (field.span(), format!("{place}: {why}")))?;
        }
    }
    Ok(())
}

/// What values an option takes.
#[derive(Clone, Debug, PartialEq)]
enum ValueKind {
    /// A flag: true or false.
    Switch,
    /// One of these names.
    Choice(Vec<String>),
    /// A length with a unit, as a string.
    Length,
    /// A sheet size, as a string.
    Sheet,
    /// A whole number in this range.
    Whole(i128, i128),
    /// A whole number of edges, or "auto".
    EdgeBudget,
    /// Any number.
    Number,
    /// A path or other text, as a string.
    Text,
}

/// One config key and the values it takes.
#[derive(Clone, Debug)]
struct ConfigOption {
    key: String,
    kind: ValueKind,
}

/// Every config key, read off the command line's own definitions.
fn options(registry: &Registry) -> Vec<ConfigOption> {
    let command = BuildOptions::command(registry);
    command
        .get_arguments()
        .filter_map(|arg| {
            let key = arg.get_long()?.to_string();
            let kind = if matches!(arg.get_action(), clap::ArgAction::SetTrue) {
                ValueKind::Switch
            } else if !arg.get_possible_values().is_empty() {
                ValueKind::Choice(
                    arg.get_possible_values()
                        .iter()
                        .map(|v| v.get_name().to_string())
                        .collect(),
                )
            } else {
                let id = arg.get_value_parser().type_id();
                let value_name = arg
                    .get_value_names()
                    .and_then(|names| names.first())
                    .map(|n| n.as_str())
                    .unwrap_or("");
                let whole = |lo: i128, hi: i128| Some(ValueKind::Whole(lo, hi));
                let by_type = if id == TypeId::of::<u32>() {
                    whole(0, u32::MAX.into())
                } else if id == TypeId::of::<u64>() {
                    whole(0, u64::MAX.into())
                } else if id == TypeId::of::<usize>() {
                    whole(0, usize::MAX as i128)
                } else if id == TypeId::of::<i32>() {
                    whole(i32::MIN.into(), i32::MAX.into())
                } else if id == TypeId::of::<f64>() {
                    Some(ValueKind::Number)
                } else if id == TypeId::of::<TargetEdges>() {
                    Some(ValueKind::EdgeBudget)
                } else {
                    None
                };
                by_type.unwrap_or(match value_name {
                    "LENGTH" => ValueKind::Length,
                    "SIZE" => ValueKind::Sheet,
                    _ => ValueKind::Text,
                })
            };
            Some(ConfigOption { key, kind })
        })
        .collect()
}

/// Says why `value` does not fit `option`, in the option's own terms.
fn check_value(option: &ConfigOption, value: &DeValue) -> std::result::Result<(), String> {
    let key = &option.key;
    match (&option.kind, value) {
        (ValueKind::Switch, DeValue::Boolean(_)) => Ok(()),
        (ValueKind::Switch, _) => Err(format!("a switch; write {key} = true or {key} = false")),
        (ValueKind::Choice(names), DeValue::String(s)) if names.iter().any(|n| n == s.as_ref()) => {
            Ok(())
        }
        (ValueKind::Choice(names), _) => Err(format!(
            "not one of the values it takes; write one of {} in quotes, like {key} = \"{}\"",
            names.join(", "),
            names[0]
        )),
        (ValueKind::Length, DeValue::String(s)) => parse_length(s).map(|_| ()),
        (ValueKind::Length, DeValue::Integer(_) | DeValue::Float(_)) => {
            let number = value_number(value).unwrap_or_default();
            Err(format!(
                "a length needs a unit; write it in quotes with one, like {key} = \"{number}mm\", \"{number}in\" or \"{number}ft\""
            ))
        }
        (ValueKind::Length, _) => Err(format!(
            "a length with a unit, in quotes, like {key} = \"4ft\" (mm, cm, m, in or ft)"
        )),
        (ValueKind::Sheet, DeValue::String(s)) => parse_sheet(s).map(|_| ()),
        (ValueKind::Sheet, _) => Err(format!(
            "a sheet size in quotes: WxH with a unit or a name, like {key} = \"18x24in\" or \"A2\""
        )),
        (ValueKind::Whole(lo, hi), DeValue::Integer(i)) => {
            let digits = i.as_str().replace('_', "");
            match i128::from_str_radix(&digits, i.radix()) {
                Ok(n) if (*lo..=*hi).contains(&n) => Ok(()),
                _ if *lo == 0 => Err(format!("a whole number, zero or more, like {key} = 4")),
                _ => Err(format!("a whole number between {lo} and {hi}")),
            }
        }
        (ValueKind::Whole(..), _) => Err(format!("a whole number without quotes, like {key} = 4")),
        (ValueKind::EdgeBudget, DeValue::Integer(i)) if !i.as_str().starts_with('-') => Ok(()),
        (ValueKind::EdgeBudget, DeValue::String(s)) if s.trim().eq_ignore_ascii_case("auto") => {
            Ok(())
        }
        (ValueKind::EdgeBudget, _) => Err(format!(
            "a whole number of edges without quotes, like {key} = 600, or {key} = \"auto\""
        )),
        (ValueKind::Number, DeValue::Integer(_) | DeValue::Float(_)) => Ok(()),
        (ValueKind::Number, _) => Err(format!("a number without quotes, like {key} = 0.5")),
        (ValueKind::Text, DeValue::String(_)) => Ok(()),
        (ValueKind::Text, _) => Err(format!(
            "text in quotes, like {key} = \"{}\"",
            if key == "out" {
                "build/bunny"
            } else {
                "svg,dxf"
            }
        )),
    }
}

/// A TOML number as written.
fn value_number(value: &DeValue) -> Option<String> {
    match value {
        DeValue::Integer(i) => Some(i.as_str().to_string()),
        DeValue::Float(f) => Some(f.as_str().to_string()),
        _ => None,
    }
}

/// The value as the file has it, for the message.
fn shown(text: &str, span: Range<usize>) -> String {
    let raw = text.get(span).unwrap_or("").trim();
    let raw = one_line(raw);
    if raw.chars().count() > 40 {
        format!("{}…", raw.chars().take(40).collect::<String>())
    } else {
        raw
    }
}

/// The message for a key that is not an option, with the nearest one.
fn unknown_key(name: &str, options: &[ConfigOption]) -> String {
    let wanted = name.to_ascii_lowercase().replace('_', "-");
    let nearest = options
        .iter()
        .map(|o| (edit_distance(&wanted, &o.key), &o.key))
        .min();
    let hint = match nearest {
        Some((d, key)) if d <= (key.len() / 3).max(2) => format!("; did you mean '{key}'?"),
        _ => String::new(),
    };
    format!(
        "unknown key '{name}'{hint} Keys are the long option names of unfold --help, with dashes (sheet, size, target-edges, …)"
    )
}

/// Levenshtein distance in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (above + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != cb));
            diagonal = above;
        }
    }
    row[b.len()]
}

/// 1-based line and column (in characters) of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// Joins a message's lines with "; " so it reads as one sentence.
fn one_line(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(edit_distance("target-edges", "target-edges"), 0);
        assert_eq!(edit_distance("szie", "size"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
    }

    #[test]
    fn lines_and_columns() {
        let text = "a = 1\nbb = 2\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 6), (2, 1));
        assert_eq!(line_column(text, 11), (2, 6));
    }

    #[test]
    fn every_option_is_a_key_and_kinds_follow_the_options() {
        let options = options(&Registry::default());
        let kind = |key: &str| {
            options
                .iter()
                .find(|o| o.key == key)
                .unwrap_or_else(|| panic!("no key {key}"))
                .kind
                .clone()
        };
        assert_eq!(kind("size"), ValueKind::Length);
        assert_eq!(kind("sheet"), ValueKind::Sheet);
        assert_eq!(kind("quiet"), ValueKind::Switch);
        assert_eq!(kind("json"), ValueKind::Switch);
        assert_eq!(kind("face-scale"), ValueKind::Number);
        assert_eq!(kind("target-edges"), ValueKind::EdgeBudget);
        assert_eq!(
            kind("target-faces"),
            ValueKind::Whole(0, usize::MAX as i128)
        );
        assert_eq!(
            kind("shift"),
            ValueKind::Whole(i32::MIN.into(), i32::MAX.into())
        );
        let schemes = Registry::default().names().len();
        assert!(matches!(kind("scheme"), ValueKind::Choice(v) if v.len() == schemes));
        assert_eq!(kind("out"), ValueKind::Text);
    }
}
