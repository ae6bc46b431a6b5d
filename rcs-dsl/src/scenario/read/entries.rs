//! The YAML shapes the scenario readers share (this one and
//! `scenario::system_read`): name-to-value mappings read with the line
//! of each key, the line of a value, and the names of a `silent:` list.

use crate::scenario::{err, ScenarioError};
use crate::yaml::Spanned;
use serde::Deserialize;
use serde_json::Value as Json;

/// A YAML mapping of names to values (`reads:`, `hooks:`, `sent:` …), in
/// file order, each entry with the line of its key, so that a name the
/// plans lack is reported on its own line.
#[derive(Default)]
pub(in crate::scenario) struct Entries(pub(in crate::scenario) Vec<Entry>);

pub(in crate::scenario) struct Entry {
    pub(in crate::scenario) line: usize,
    pub(in crate::scenario) name: String,
    pub(in crate::scenario) value: Json,
}

impl<'de> Deserialize<'de> for Entries {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = Entries;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a mapping of names to values")
            }
            fn visit_unit<E>(self) -> Result<Entries, E> {
                Ok(Entries::default())
            }
            fn visit_none<E>(self) -> Result<Entries, E> {
                Ok(Entries::default())
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Entries, A::Error> {
                let mut out = Vec::new();
                // Duplicate keys are refused by the YAML reader itself.
                while let Some(key) = m.next_key::<Spanned<String>>()? {
                    out.push(Entry {
                        line: line_of(&key),
                        name: key.value,
                        value: m.next_value()?,
                    });
                }
                Ok(Entries(out))
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// The line a scenario value was written on.
pub(in crate::scenario) fn line_of<T>(s: &Spanned<T>) -> usize {
    s.referenced.line() as usize
}

/// The entries of an optional mapping: (line of the key, name, value).
pub(in crate::scenario) fn entries(
    e: &Option<Entries>,
) -> impl Iterator<Item = (usize, &str, &Json)> {
    e.as_ref()
        .map_or(&[][..], |e| &e.0)
        .iter()
        .map(|e| (e.line, e.name.as_str(), &e.value))
}

/// The names of a `silent:` list (or one name alone), each a string; else
/// an error at the key's line saying it holds a list of `what`.
pub(in crate::scenario) fn silent_names<'a>(
    v: &'a Spanned<Json>,
    what: &str,
) -> Result<Vec<&'a str>, ScenarioError> {
    let shape = || {
        err(
            line_of(v),
            format!("`silent` is a list of {what} held unwritten: `silent: [io]`"),
        )
    };
    match &v.value {
        Json::Array(xs) => xs.iter().map(|x| x.as_str().ok_or_else(shape)).collect(),
        Json::String(s) => Ok(vec![s.as_str()]),
        _ => Err(shape()),
    }
}
