//! Records for the manifest: named values in the order they are written, and the
//! rounding of lengths. Below both the schemes (which describe their options and extra
//! results this way) and the export layer (which writes them).

/// Named values in the order they are written (the manifest's `scheme.params`, a
/// scheme's extra manifest sections).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Params(pub Vec<(String, Field)>);

/// One value of [`Params`].
#[derive(Clone, Debug, PartialEq)]
pub enum Field {
    /// A number, text, flag or plain list.
    Value(serde_json::Value),
    /// A list of records, each written in its own order.
    Records(Vec<Params>),
}

impl Params {
    /// Appends `name: value`.
    pub fn push(&mut self, name: &str, value: impl Into<serde_json::Value>) {
        self.0.push((name.to_string(), Field::Value(value.into())));
    }

    /// Appends `name: [record, …]`.
    pub fn push_records(&mut self, name: &str, records: Vec<Params>) {
        self.0.push((name.to_string(), Field::Records(records)));
    }

    /// Appends every entry of `other`.
    pub fn extend(&mut self, other: Params) {
        self.0.extend(other.0);
    }
}

impl serde::Serialize for Params {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (name, value) in &self.0 {
            match value {
                Field::Value(v) => map.serialize_entry(name, v)?,
                Field::Records(r) => map.serialize_entry(name, r)?,
            }
        }
        map.end()
    }
}

/// Rounds a length to 4 decimals for the manifest (a tenth of a micron).
pub fn round4(x: f64) -> f64 {
    let r = (x * 1e4).round() / 1e4;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}
