//! A configuration document from values instead of TOML text (a Python dict), and a
//! document changed key by key (`pixel.bins = 4`): both judged by the document's own serde
//! types, as a file is, before the one resolution ([`crate::resolve()`]) runs. There is no
//! text, so an error names the key's whole dotted path (and what the section takes), never
//! a line of a text the user did not write.

use serde::Deserialize;
use toml::{Table, Value};

use crate::document::Document;
use crate::error::DesignError;
use crate::schema;

impl Document {
    /// The document a table of sections holds (`{"sensor": {…}, "pixel": {…}}`); `origin`
    /// names it in errors. An unknown section or key and a value of the wrong type are
    /// named by their dotted path.
    pub fn from_table(table: Table, origin: &str) -> Result<Document, DesignError> {
        let err = |message: String| DesignError::Toml {
            origin: origin.to_string(),
            message,
        };
        if let Some(m) = schema::unknown_key(&table) {
            return Err(err(m));
        }
        if let Some(m) = schema::wrong_type_in(&table) {
            return Err(err(m));
        }
        Document::deserialize(Value::Table(table))
            .map_err(|e| err(schema::clip_message(e.message().trim())))
    }

    /// This document with each dotted key of `overrides` set to its value, or removed
    /// (back to its default) for `None`: `("pixel.bins", Some(4))`,
    /// `("pixel.frame_pulses", None)`. Keys apply in order; a table on the way is created
    /// when absent (`array.rows` on a single-pixel document). The result is checked as
    /// [`Document::from_table`] checks a table; `origin` names it in errors.
    pub fn with_overrides(
        &self,
        overrides: &[(String, Option<Value>)],
        origin: &str,
    ) -> Result<Document, DesignError> {
        let err = |message: String| DesignError::Toml {
            origin: origin.to_string(),
            message,
        };
        let mut table = match Value::try_from(self) {
            Ok(Value::Table(t)) => t,
            Ok(_) => return Err(err("the document is not a table".into())),
            Err(e) => return Err(err(e.to_string())),
        };
        for (key, value) in overrides {
            let parts: Vec<&str> = key.split('.').collect();
            let Some((last, parents)) = parts
                .split_last()
                .filter(|(l, p)| !p.is_empty() && !l.is_empty() && p.iter().all(|s| !s.is_empty()))
            else {
                return Err(err(format!(
                    "override `{key}`: name a key by its section, as `section.key` (e.g. \
                     `pixel.bins`)"
                )));
            };
            let mut at = &mut table;
            for (i, p) in parents.iter().enumerate() {
                let entry = at
                    .entry((*p).to_string())
                    .or_insert_with(|| Value::Table(Table::new()));
                at = match entry {
                    Value::Table(t) => t,
                    other => {
                        return Err(err(format!(
                            "override `{key}`: `{}` is {}, not a table: override it whole",
                            parts[..=i].join("."),
                            other.type_str()
                        )));
                    }
                };
            }
            match value {
                Some(v) => at.insert((*last).to_string(), v.clone()),
                None => at.remove(*last),
            };
        }
        Document::from_table(table, origin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DEFAULT_ORIGIN, DEFAULT_TOML};

    fn default() -> Document {
        Document::from_toml_str(DEFAULT_TOML, DEFAULT_ORIGIN).unwrap()
    }

    fn set(key: &str, v: Option<Value>) -> Vec<(String, Option<Value>)> {
        vec![(key.to_string(), v)]
    }

    #[test]
    fn an_override_changes_one_key_and_keeps_the_rest() {
        let d = default();
        let o = d
            .with_overrides(&set("pixel.bins", Some(Value::Integer(4))), "t")
            .unwrap();
        assert_ne!(o.pixel.bins, d.pixel.bins);
        let mut back = o.clone();
        back.pixel.bins = d.pixel.bins;
        assert_eq!(back, d, "only pixel.bins changed");
        // Removing a key restores its default; the override of a whole file agrees.
        let text = DEFAULT_TOML.replace("bins = 16", "bins = 4");
        assert_eq!(o, Document::from_toml_str(&text, "t").unwrap());
    }

    #[test]
    fn unknown_keys_and_wrong_types_name_the_dotted_key_and_no_line() {
        let d = default();
        for (key, v, want) in [
            (
                "pixel.binz",
                Value::Integer(4),
                "`pixel.binz` is not a key of [pixel]",
            ),
            ("pixle.bins", Value::Integer(4), "`pixle` is not a section"),
            (
                "pixel.bins",
                Value::String("many".into()),
                "`pixel.bins` = \"many\" has the wrong type",
            ),
            ("bins", Value::Integer(4), "as `section.key`"),
            (
                "sensor.jitter_ps.x",
                Value::Integer(4),
                "`sensor.jitter_ps` is float",
            ),
        ] {
            let e = d
                .with_overrides(&set(key, Some(v)), "o")
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{key}: {e}");
            assert!(!e.contains("line "), "{key}: {e}");
        }
        let e = d
            .with_overrides(&set("pixel.binz", Some(Value::Integer(4))), "o")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`bins`"), "the keys there are listed: {e}");
    }

    #[test]
    fn a_table_with_an_unknown_motion_key_names_its_entry() {
        let mut t: Table = toml::from_str(DEFAULT_TOML).unwrap();
        let scene = t.get_mut("scene").unwrap().as_table_mut().unwrap();
        let motion = scene.get_mut("motion").unwrap().as_array_mut().unwrap();
        motion[0]
            .as_table_mut()
            .unwrap()
            .insert("colour".into(), Value::Integer(1));
        let e = Document::from_table(t, "<dict>").unwrap_err().to_string();
        assert!(e.contains("`scene.motion[0].colour`"), "{e}");
        assert!(!e.contains("line "), "{e}");
    }
}
