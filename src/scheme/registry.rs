//! The registry: the built-in schemes and the [`Registry`] a run chooses its scheme
//! from. The one file that names every scheme; the schemes know only the trait.

use std::fmt;

use super::{edge, half_edge, net, strip, woven, PanelDefaults, Scheme};

/// The built-in schemes, in the order `--help` lists them; the first is the default.
pub static SCHEMES: [&dyn Scheme; 6] = [
    &half_edge::HalfEdge,
    &edge::quad::QuadEdge,
    &edge::winged::WingedEdge,
    &woven::Woven,
    &net::Net,
    &strip::Strips,
];

/// The schemes a run can choose from: the built-in ones, and any a program embedding
/// the library adds with [`Registry::with`].
#[derive(Clone)]
pub struct Registry {
    schemes: Vec<&'static dyn Scheme>,
}

impl Default for Registry {
    fn default() -> Self {
        Registry {
            schemes: SCHEMES.to_vec(),
        }
    }
}

impl fmt::Debug for Registry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.names()).finish()
    }
}

impl Registry {
    /// The built-in schemes plus `scheme`.
    pub fn with(mut self, scheme: &'static dyn Scheme) -> Registry {
        self.schemes.push(scheme);
        self
    }

    /// Scheme names, in order.
    pub fn names(&self) -> Vec<&'static str> {
        self.schemes.iter().map(|s| s.name()).collect()
    }

    /// The schemes, in order.
    pub fn schemes(&self) -> &[&'static dyn Scheme] {
        &self.schemes
    }

    /// The scheme called `name`.
    pub fn get(&self, name: &str) -> Option<&'static dyn Scheme> {
        self.schemes.iter().copied().find(|s| s.name() == name)
    }

    /// The scheme used when none is given.
    pub fn default_scheme(&self) -> &'static dyn Scheme {
        self.schemes[0]
    }

    /// Every scheme's own options, each once (schemes that share one share its
    /// definition), headed in `--help` by the schemes that take it.
    pub fn options(&self) -> Vec<clap::Arg> {
        let mut options: Vec<(clap::Arg, Vec<&str>)> = Vec::new();
        for scheme in &self.schemes {
            for arg in scheme.options() {
                match options.iter_mut().find(|(a, _)| a.get_id() == arg.get_id()) {
                    Some((_, takers)) => takers.push(scheme.name()),
                    None => options.push((arg, vec![scheme.name()])),
                }
            }
        }
        options
            .into_iter()
            .map(|(arg, takers)| arg.help_heading(format!("Options of {}", name_list(&takers))))
            .collect()
    }

    /// "1 for half-edge, 0.5 for quad-edge and winged-edge": a per-scheme default as
    /// `--help` states it.
    pub fn describe_defaults<T: PartialEq + fmt::Display>(
        &self,
        value: impl Fn(&PanelDefaults) -> T,
    ) -> String {
        let mut groups: Vec<(T, Vec<&str>)> = Vec::new();
        for scheme in &self.schemes {
            let v = value(&scheme.info().defaults);
            match groups.iter_mut().find(|(g, _)| *g == v) {
                Some((_, names)) => names.push(scheme.name()),
                None => groups.push((v, vec![scheme.name()])),
            }
        }
        groups
            .iter()
            .map(|(v, names)| format!("{v} for {}", name_list(names)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// "a", "a and b", "a, b and c".
fn name_list(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}
