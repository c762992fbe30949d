//! Every key a document can hold, each with values of its real type, read from the
//! document's own serde types (the one schema, [`super::schema`]): the sections and keys
//! serde lists when asked for an unknown one, the motion kinds it lists for a wrong kind,
//! and a key's values as the samples that fit it alone (numbers, integers, `true`/`false`,
//! every name of a choice, `"auto"`, strings, lists, each variant of a tagged table). The
//! fuzzers (crates/design/tests/it/mutations.rs and the binary's) draw from [`keys`], so a
//! new key is fuzzed with its type without a list to edit.

use serde::de::DeserializeOwned;
use toml::{Table, Value};

use super::schema::{default_value, misfit_of, unknown_of};
use crate::Document;

/// One key of a document.
#[derive(Debug, Clone, PartialEq)]
pub struct Key {
    /// The section (`sensor`, …, `array`); `scene.motion` for a motion entry's keys.
    pub section: String,
    pub key: String,
    /// The motion kind whose entry holds the key (`scene.motion` only).
    pub kind: Option<String>,
    /// Values of the key's type that fit it alone.
    pub values: Vec<Value>,
}

/// A name nothing is called: serde names what it expected instead.
const NOBODY: &str = "\u{1}";

/// The backquoted names after "expected" in serde's message `m`.
fn expected_names(m: &str) -> Vec<String> {
    let Some((_, list)) = m.split_once("expected") else {
        return Vec::new();
    };
    quoted(list, '`')
}

/// The pieces of `text` between pairs of `q`.
fn quoted(text: &str, q: char) -> Vec<String> {
    text.split(q)
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The samples a key is tried with: every TOML type, at values a knob commonly takes.
fn samples() -> Vec<Value> {
    let mut v: Vec<Value> = [0, 1, 2, 3, 4, 7, 16, 64, 4096, -1]
        .into_iter()
        .map(Value::Integer)
        .collect();
    v.extend([0.0, 0.5, 1.5, 30.0, 1000.0, 1e-9, -1.0].map(Value::Float));
    v.extend([true, false].map(Value::Boolean));
    v.extend(["auto", "x", "", "/nonexistent/x.lib"].map(|s| Value::String(s.into())));
    v.push(Value::Array(vec![Value::Float(1.0), Value::Float(2.0)]));
    v.push(Value::Array(Vec::new()));
    v
}

/// The values of `D`'s key `section.key` (a motion entry's: `entry` its kind).
fn values_of<D: DeserializeOwned>(
    section: &str,
    key: &str,
    entry: Option<&Value>,
    defaults: bool,
) -> Vec<Value> {
    let fits = |v: &Value| misfit_of::<D>(section, key, v, entry).is_none();
    let mut out: Vec<Value> = samples().into_iter().filter(|v| fits(v)).collect();
    let odd = Value::String(NOBODY.into());
    // The names serde lists (`a`, `b`), or a refusal of the key's own lists ("a" or "b").
    let mut names = misfit_of::<D>(section, key, &odd, entry)
        .map(|m| [expected_names(&m), quoted(&m, '"')].concat())
        .unwrap_or_default();
    if defaults && let Some(Value::String(d)) = default_value(section, key, entry) {
        names.push(d);
    }
    // A tagged table (`{ kind = "…", … }`): each of its kinds.
    let mut tagged = Table::new();
    tagged.insert("kind".into(), odd);
    if let Some(m) = misfit_of::<D>(section, key, &Value::Table(tagged), entry) {
        for kind in expected_names(&m)
            .into_iter()
            .filter(|_| m.contains("variant"))
        {
            let mut t = Table::new();
            t.insert("kind".into(), Value::String(kind));
            out.push(Value::Table(t));
        }
    }
    for n in names {
        let v = Value::String(n);
        if fits(&v) && !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

/// Every key of `D` (a document type: sections of keys, `scene.motion` a list of tagged
/// entries), in serde's order.
pub fn keys_of<D: DeserializeOwned>() -> Vec<Key> {
    collect::<D>(false)
}

/// [`keys_of`]; `defaults`: a name-valued key's values include the embedded default
/// document's (an untagged choice's names are not listed by serde).
fn collect<D: DeserializeOwned>(defaults: bool) -> Vec<Key> {
    let mut out = Vec::new();
    let sections = unknown_of::<D>(NOBODY, None, None).map_or(Vec::new(), |m| expected_names(&m));
    for section in sections {
        let names = unknown_of::<D>(&section, Some(NOBODY), None)
            .map_or(Vec::new(), |m| expected_names(&m));
        for key in names {
            if section == "scene" && key == "motion" {
                out.extend(motion_keys::<D>(defaults));
                continue;
            }
            let values = values_of::<D>(&section, &key, None, defaults);
            out.push(Key {
                section: section.clone(),
                key,
                kind: None,
                values,
            });
        }
    }
    out
}

/// The keys of each kind of `[[scene.motion]]` entry.
fn motion_keys<D: DeserializeOwned>(defaults: bool) -> Vec<Key> {
    let wrong = Value::String(NOBODY.into());
    let kinds = misfit_of::<D>("scene", "kind", &wrong, Some(&wrong))
        .map_or(Vec::new(), |m| expected_names(&m));
    let mut out = Vec::new();
    for kind in kinds {
        let entry = Value::String(kind.clone());
        // The tag, then the keys serde lists for the kind.
        let names = unknown_of::<D>("scene", Some(NOBODY), Some(&entry))
            .map_or(Vec::new(), |m| expected_names(&m));
        for key in std::iter::once("kind".to_string()).chain(names) {
            let values = if key == "kind" {
                vec![entry.clone()]
            } else {
                values_of::<D>("scene", &key, Some(&entry), defaults)
            };
            out.push(Key {
                section: "scene.motion".into(),
                key,
                kind: Some(kind.clone()),
                values,
            });
        }
    }
    out
}

/// Every key of the configuration document ([`Document`]).
pub fn keys() -> Vec<Key> {
    collect::<Document>(true)
}

/// The keys a mutation of the embedded default may touch: every key of [`keys`], a
/// motion's only those of the default's own motion kind (`scene.motion[0]`) — what both
/// fuzzers (the library's and the binary's) draw from.
pub fn keys_of_the_default() -> Vec<Key> {
    let doc: Option<toml::Table> = toml::from_str(crate::DEFAULT_TOML).ok();
    let kind = doc
        .as_ref()
        .and_then(|d| d.get("scene")?.get("motion")?.get(0)?.get("kind")?.as_str())
        .map(str::to_string);
    keys()
        .into_iter()
        .filter(|k| k.kind.is_none() || k.kind == kind)
        .collect()
}
