//! How an option's default is stated in its help: `[default: …]` at the end of its
//! text, written from the same constant that resolution falls back on, so a default
//! is written once. The command line's options ([`crate::config::defaults`]) and each
//! scheme's own options state theirs this way.

use std::fmt::Display;

/// What an option's `[default: …]` states.
#[derive(Clone, Debug, PartialEq)]
pub enum Stated {
    /// One value the option takes, written as on the command line (`0.25in`, `32`),
    /// and words on what that value means, if any (`nominal geometry`).
    Value {
        /// The value.
        text: String,
        /// What the value means.
        note: Option<&'static str>,
    },
    /// A value per scheme: `(scheme, value)` in the registry's order, and the
    /// sentence `--help` shows for them.
    PerScheme {
        /// Each scheme's value.
        values: Vec<(&'static str, String)>,
        /// "1 for half-edge and net, 0.5 for …".
        sentence: String,
    },
    /// Words for a default that is no single value (`off`, `none`, `the model's own
    /// size in --units`).
    Words(&'static str),
}

/// One option's default, by the option's long name.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionDefault {
    /// The long name, without dashes.
    pub long: &'static str,
    /// What its default is.
    pub stated: Stated,
}

impl OptionDefault {
    /// An option whose default is `value`.
    pub fn value(long: &'static str, value: impl Display) -> OptionDefault {
        OptionDefault {
            long,
            stated: Stated::Value {
                text: value.to_string(),
                note: None,
            },
        }
    }

    /// An option whose default is `value`, meaning `note`.
    pub fn noted(long: &'static str, value: impl Display, note: &'static str) -> OptionDefault {
        OptionDefault {
            long,
            stated: Stated::Value {
                text: value.to_string(),
                note: Some(note),
            },
        }
    }

    /// An option whose default is described by `words`.
    pub fn words(long: &'static str, words: &'static str) -> OptionDefault {
        OptionDefault {
            long,
            stated: Stated::Words(words),
        }
    }

    /// The text between `[default: ` and `]`.
    pub fn shown(&self) -> String {
        match &self.stated {
            Stated::Value { text, note: None } => text.clone(),
            Stated::Value {
                text,
                note: Some(note),
            } => format!("{text}, {note}"),
            Stated::PerScheme { sentence, .. } => sentence.clone(),
            Stated::Words(words) => words.to_string(),
        }
    }

    /// `arg` with its help ending in this default (a sentence of its own).
    pub fn state_in(&self, arg: clap::Arg) -> clap::Arg {
        let suffix = format!("[default: {}]", self.shown());
        let with_suffix = |text: String| {
            // The derive drops a one-sentence doc comment's final period; the default
            // follows as a sentence of its own.
            if text.is_empty() || text.ends_with('.') {
                format!("{text} {suffix}").trim_start().to_string()
            } else {
                format!("{text}. {suffix}")
            }
        };
        let help = with_suffix(arg.get_help().map(|h| h.to_string()).unwrap_or_default());
        let long_help = arg.get_long_help().map(|h| with_suffix(h.to_string()));
        let arg = arg.help(help);
        match long_help {
            Some(text) => arg.long_help(text),
            None => arg,
        }
    }
}

/// `args` with the help of each one `defaults` names ending in its default.
pub fn state_defaults(args: Vec<clap::Arg>, defaults: &[OptionDefault]) -> Vec<clap::Arg> {
    args.into_iter()
        .map(|arg| match find_default(defaults, arg.get_long()) {
            Some(default) => default.state_in(arg),
            None => arg,
        })
        .collect()
}

/// `command` (and its subcommands) with the help of each option `defaults` names
/// ending in its default.
pub fn state_defaults_in(command: clap::Command, defaults: &[OptionDefault]) -> clap::Command {
    command
        .mut_args(|arg| match find_default(defaults, arg.get_long()) {
            Some(default) => default.state_in(arg),
            None => arg,
        })
        .mut_subcommands(|sub| state_defaults_in(sub, defaults))
}

/// The entry of `defaults` for the option called `long`.
pub fn find_default<'a>(
    defaults: &'a [OptionDefault],
    long: Option<&str>,
) -> Option<&'a OptionDefault> {
    let long = long?;
    defaults.iter().find(|d| d.long == long)
}
