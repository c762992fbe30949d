//! Naming the key whose value does not fit the document's schema. The toml crate reports a
//! wrong type inside an array of tables (`[[scene.motion]]`) or an enum at the table's
//! header with no key ("invalid type: string "x", expected f64"); this walk finds the key,
//! so the message names the field, the value and the type it needs. The types are not
//! listed here: each key is tried alone against the document's own serde types
//! ([`Document`]), so every key — a new one included — is judged by the one schema.

use serde::de::DeserializeOwned;
use toml::{Table, Value};

use crate::Document;

/// Whether `value` fits key `key` of section `section` (`scene.motion` entries: `entry`
/// holds the entry's `kind`): the document's own serde types are asked, with a document
/// holding only this one key. A wrong type or value fails there at the key, before serde
/// notices the keys that are missing, so "missing field" means the key fits; an unknown key
/// is the parser's to report (with its line). `Some(serde's message)` when it does not fit.
fn misfit(section: &str, key: &str, value: &Value, entry: Option<&Value>) -> Option<String> {
    misfit_of::<Document>(section, key, value, entry)
}

/// [`misfit`] against the serde types of `D` (the document, or a test's own).
pub(crate) fn misfit_of<D: DeserializeOwned>(
    section: &str,
    key: &str,
    value: &Value,
    entry: Option<&Value>,
) -> Option<String> {
    let mut body = Table::new();
    body.insert(key.to_string(), value.clone());
    let body = match entry {
        None => body,
        Some(kind) => {
            if key != "kind" {
                body.insert("kind".into(), kind.clone());
            }
            let mut scene = Table::new();
            scene.insert("motion".into(), Value::Array(vec![Value::Table(body)]));
            scene
        }
    };
    let mut doc = Table::new();
    doc.insert(section.to_string(), Value::Table(body));
    let e = D::deserialize(Value::Table(doc)).err()?;
    let m = e.message().trim();
    (!(m.starts_with("missing field") || m.starts_with("unknown field"))).then(|| m.to_string())
}

/// What key `key` takes, in the document's words ("a number", "an integer >= 0 or
/// \"auto\"", "one of `flops`, `clock_gated`"), found by trying a sample of each TOML type
/// against the schema ([`misfit`]); a name-valued key whose names serde does not list (an
/// untagged choice) is shown by its default value.
fn describe(section: &str, key: &str, entry: Option<&Value>) -> String {
    describe_by(&|v| misfit(section, key, v, entry), || {
        default_value(section, key, entry)
    })
}

/// [`describe`] of a key judged by `try_value` (serde's message when a value does not
/// fit), its default value from `default` for a name-valued key.
fn describe_by(
    try_value: &dyn Fn(&Value) -> Option<String>,
    default: impl Fn() -> Option<Value>,
) -> String {
    let fits = |v: Value| try_value(&v).is_none();
    let mut kinds = Vec::new();
    if fits(Value::Float(1.5)) {
        kinds.push("a number".to_string());
    } else if fits(Value::Integer(1)) {
        kinds.push(
            if fits(Value::Integer(-1)) {
                "an integer"
            } else {
                "an integer >= 0"
            }
            .into(),
        );
    }
    if fits(Value::Boolean(true)) {
        kinds.push("true or false".into());
    }
    let odd = Value::String("\u{1}".into());
    if fits(odd.clone()) {
        kinds.push("a string".into());
    } else {
        let names = try_value(&odd)
            .and_then(|m| {
                m.split_once(", expected ")
                    .map(|(_, n)| n.trim().to_string())
            })
            .filter(|n| n.contains('`'));
        match names {
            Some(n) => kinds.push(if n.starts_with("one of") {
                n
            } else {
                format!("one of {n}")
            }),
            None => {
                if let Some(Value::String(d)) = default()
                    && d != "auto"
                {
                    kinds.push(format!("a name such as \"{d}\""));
                }
                if fits(Value::String("auto".into())) {
                    kinds.push("\"auto\"".into());
                }
            }
        }
    }
    if fits(Value::Array(vec![Value::Float(1.5)])) {
        kinds.push("an array of numbers".into());
    } else if fits(Value::Array(Vec::new())) {
        kinds.push("an array".into());
    }
    if kinds.is_empty() {
        "another value".into()
    } else {
        kinds.join(" or ")
    }
}

/// The embedded default's value of a key (absent keys at their serde defaults), for
/// [`describe`]; motions only for the default's kind.
pub(crate) fn default_value(section: &str, key: &str, entry: Option<&Value>) -> Option<Value> {
    let doc = Document::from_toml_str(crate::DEFAULT_TOML, crate::DEFAULT_ORIGIN).ok()?;
    let v = Value::try_from(doc).ok()?;
    let sec = v.get(section)?;
    match entry {
        None => sec.get(key).cloned(),
        Some(kind) => sec
            .get("motion")?
            .as_array()?
            .iter()
            .find(|m| m.get("kind") == Some(kind))?
            .get(key)
            .cloned(),
    }
}

/// The first key of `text` (a TOML document) whose value does not fit, as
/// "`path` = value has the wrong type: expected …" (or "is not accepted: …" for a value of
/// the right type that is not one of the key's values); `None` when every key fits (or the
/// text is not TOML at all: the parser's own message says where). Every key's type comes
/// from the document's serde types ([`Document`]), so a new key needs no entry here.
pub fn wrong_type(text: &str) -> Option<String> {
    let doc: Table = toml::from_str(text).ok()?;
    wrong_type_in(&doc)
}

/// [`wrong_type`] of a document already parsed (or built from values: a Python dict).
pub fn wrong_type_in(doc: &Table) -> Option<String> {
    // A wrong type (or an integer out of its type's range, or no alternative of a choice)
    // is described by what the key takes; a value of the right type that is not one of the
    // key's names keeps serde's message, which lists them.
    let report = |path: String, v: &Value, m: String, sec: &str, key: &str, e: Option<&Value>| {
        let shown = tofprobe_io::text::clip(&v.to_string(), 60);
        if m.starts_with("invalid type")
            || m.starts_with("invalid value")
            || m.starts_with("data did not match")
        {
            format!(
                "`{path}` = {shown} has the wrong type: expected {}",
                describe(sec, key, e)
            )
        } else {
            format!(
                "`{path}` = {shown} is not accepted: {}",
                tofprobe_io::text::clip(&m, 200)
            )
        }
    };
    for (section, body) in doc {
        let Some(t) = body.as_table() else {
            continue;
        };
        for (key, v) in t {
            if section == "scene" && key == "motion" {
                let Some(list) = v.as_array() else {
                    return Some(
                        "`scene.motion` has the wrong type: expected [[scene.motion]] tables"
                            .to_string(),
                    );
                };
                for (i, m) in list.iter().enumerate() {
                    let Some(m) = m.as_table() else {
                        return Some(format!(
                            "`scene.motion[{i}]` has the wrong type: expected a table"
                        ));
                    };
                    let kind = m
                        .get("kind")
                        .cloned()
                        .unwrap_or(Value::String(String::new()));
                    // The kind first: every other key is judged against it.
                    let keys = m
                        .iter()
                        .filter(|(k, _)| *k == "kind")
                        .chain(m.iter().filter(|(k, _)| *k != "kind"));
                    for (mk, mv) in keys {
                        if let Some(e) = misfit("scene", mk, mv, Some(&kind)) {
                            let path = format!("scene.motion[{i}].{mk}");
                            return Some(report(path, mv, e, "scene", mk, Some(&kind)));
                        }
                    }
                }
                continue;
            }
            if let Some(e) = misfit(section, key, v, None) {
                if let Some(inner) = v.as_table().and_then(|t| nested_misfit(section, key, t)) {
                    return Some(inner);
                }
                return Some(report(format!("{section}.{key}"), v, e, section, key, None));
            }
        }
    }
    None
}

/// serde's refusal of the one key `key` of `section` (a motion entry: `entry` its kind)
/// when it is not a key there: "unknown field `x`, expected one of …"; `None` when the
/// schema knows the key (whatever its value).
fn unknown(section: &str, key: Option<&str>, entry: Option<&Value>) -> Option<String> {
    unknown_of::<Document>(section, key, entry)
}

/// [`unknown`] against the serde types of `D`.
pub(crate) fn unknown_of<D: DeserializeOwned>(
    section: &str,
    key: Option<&str>,
    entry: Option<&Value>,
) -> Option<String> {
    let mut body = Table::new();
    if let Some(k) = key {
        // A value that fits no key's type: the key's own name is what serde judges first.
        body.insert(k.to_string(), Value::Table(Table::new()));
    }
    let body = match entry {
        None => body,
        Some(kind) => {
            let mut m = Table::new();
            m.insert("kind".into(), kind.clone());
            m.extend(body);
            let mut scene = Table::new();
            scene.insert("motion".into(), Value::Array(vec![Value::Table(m)]));
            scene
        }
    };
    let mut doc = Table::new();
    doc.insert(section.to_string(), Value::Table(body));
    let e = D::deserialize(Value::Table(doc)).err()?;
    let m = e.message().trim();
    m.starts_with("unknown field").then(|| m.to_string())
}

/// The first section or key of `doc` the document does not have, named by its dotted path
/// with the keys that are there ("`pixel.binz` is not a key of \[pixel\]: expected one of
/// `bins`, …"): a document built from values (a dict, overrides) has no line to cite, so
/// the path is the whole address. `None` when every name is known.
pub fn unknown_key(doc: &Table) -> Option<String> {
    let expected = |m: String| {
        m.split_once(", expected ")
            .map_or(m.clone(), |(_, e)| format!("expected {e}"))
    };
    for (section, body) in doc {
        if let Some(m) = unknown(section, None, None) {
            return Some(format!(
                "`{section}` is not a section of the document: {}",
                expected(m)
            ));
        }
        let Some(t) = body.as_table() else {
            continue;
        };
        for (key, v) in t {
            if let Some(m) = unknown(section, Some(key), None) {
                return Some(format!(
                    "`{section}.{key}` is not a key of [{section}]: {}",
                    expected(m)
                ));
            }
            if section == "scene" && key == "motion" {
                for (i, entry) in v.as_array().into_iter().flatten().enumerate() {
                    let Some(e) = entry.as_table() else {
                        continue;
                    };
                    let kind = e
                        .get("kind")
                        .cloned()
                        .unwrap_or(Value::String(String::new()));
                    for mk in e.keys().filter(|k| *k != "kind") {
                        if let Some(m) = unknown(section, Some(mk), Some(&kind)) {
                            return Some(format!(
                                "`scene.motion[{i}].{mk}` is not a key of a {kind} motion: {}",
                                expected(m)
                            ));
                        }
                    }
                }
            }
        }
    }
    None
}

/// The key inside the table `t` of `section.key` (a tagged table such as
/// `array.signal_map = { kind = "constant", value = "x" }`) whose value does not fit, each
/// tried alone beside the table's `kind`, as "`section.key.inner` = value has the wrong
/// type: expected …"; `None` when none does alone.
fn nested_misfit(section: &str, key: &str, t: &Table) -> Option<String> {
    let kind = t.get("kind");
    let try_inner = |inner: &str, v: &Value| {
        let mut sub = Table::new();
        if let Some(k) = kind
            && inner != "kind"
        {
            sub.insert("kind".into(), k.clone());
        }
        sub.insert(inner.to_string(), v.clone());
        misfit(section, key, &Value::Table(sub), None)
    };
    let keys = t
        .iter()
        .filter(|(k, _)| *k == "kind")
        .chain(t.iter().filter(|(k, _)| *k != "kind"));
    for (inner, v) in keys {
        let Some(m) = try_inner(inner, v) else {
            continue;
        };
        let shown = tofprobe_io::text::clip(&v.to_string(), 60);
        let path = format!("{section}.{key}.{inner}");
        return Some(
            if m.starts_with("invalid type") || m.starts_with("invalid value") {
                format!(
                    "`{path}` = {shown} has the wrong type: expected {}",
                    describe_by(&|x| try_inner(inner, x), || None)
                )
            } else {
                format!(
                    "`{path}` = {shown} is not accepted: {}",
                    tofprobe_io::text::clip(&m, 200)
                )
            },
        );
    }
    None
}

/// The toml crate's message with every line cut to a readable length: a megabyte string in
/// the document is not echoed back whole.
pub fn clip_message(message: &str) -> String {
    message
        .lines()
        .map(|l| tofprobe_io::text::clip(l, 200))
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_key_of_a_wrong_type_is_named() {
        let t =
            "[scene]\ndepth_mm = 30.0\n[[scene.motion]]\nkind = \"sine\"\namplitude_mm = \"x\"\n";
        let m = wrong_type(t).unwrap();
        assert!(m.contains("`scene.motion[0].amplitude_mm` = \"x\""), "{m}");
        assert!(wrong_type("[probe]\nosr = 32\n").is_none());
        assert!(
            wrong_type("[probe]\nosr = {}\n")
                .unwrap()
                .contains("probe.osr")
        );
        assert_eq!(clip_message(&"y".repeat(10_000)).len(), 200);
    }

    /// Every key's type comes from the schema: string keys are strings or names, choices
    /// take an integer or "auto", and a valid `adders = "auto"` is not blamed for a wrong
    /// `jitter_ps` elsewhere (the old table took every unlisted `[pixel]` key for an integer).
    #[test]
    fn each_key_is_judged_by_the_schema() {
        let cases = [
            (
                "[sensor]\njitter_ps = \"50\"\n[pixel]\nadders = \"auto\"\n",
                "`sensor.jitter_ps` = \"50\" has the wrong type: expected a number",
            ),
            (
                "[pixel]\nregister_file = 3\n",
                "`pixel.register_file` = 3 has the wrong type: expected one of `flops`, `clock_gated`, `latch`",
            ),
            (
                "[pixel]\nregister_file = \"sram\"\n",
                "`pixel.register_file` = \"sram\" is not accepted: unknown variant `sram`, expected one of `flops`, `clock_gated`, `latch`",
            ),
            (
                "[pixel]\nprefilter_rounding = 1.5\n",
                "`pixel.prefilter_rounding` = 1.5 has the wrong type: expected one of `floor` or `nearest`",
            ),
            (
                "[pixel]\ntiming_liberty = 3\n",
                "`pixel.timing_liberty` = 3 has the wrong type: expected a string",
            ),
            (
                "[pixel]\nadders = \"Auto\"\n",
                "`pixel.adders` = \"Auto\" has the wrong type: expected an integer >= 0 or \"auto\"",
            ),
            (
                "[pixel]\nmode = 1\n",
                "`pixel.mode` = 1 has the wrong type: expected a name such as \"fourier\" or \"auto\"",
            ),
            (
                "[pixel]\nfrequencies_hz = [\"a\"]\n",
                "`pixel.frequencies_hz` = [\"a\"] has the wrong type: expected an array of numbers",
            ),
            (
                "[probe]\noptimised_zeros = 1\n",
                "`probe.optimised_zeros` = 1 has the wrong type: expected true or false",
            ),
            (
                "[acquisition]\npulses = -5\n",
                "`acquisition.pulses` = -5 has the wrong type: expected an integer >= 0",
            ),
            (
                "[array]\nrows = \"x\"\n",
                "`array.rows` = \"x\" has the wrong type: expected an integer >= 0",
            ),
            (
                "[array]\nsignal_map = { kind = \"constant\", value = \"x\" }\n",
                "`array.signal_map.value` = \"x\" has the wrong type: expected a number",
            ),
            (
                "[array]\nsignal_map = { kind = \"gradient\", from = 0.1, to = [1] }\n",
                "`array.signal_map.to` = [1] has the wrong type: expected a number",
            ),
            (
                "[array]\nbackground_map = { kind = \"image\", path = 3 }\n",
                "`array.background_map.path` = 3 has the wrong type: expected a string",
            ),
            (
                "[[scene.motion]]\nkind = 3\n",
                "`scene.motion[0].kind` = 3 has the wrong type: expected one of `sine`, `square`, `disk`, `step`, `ramp`, `impulse`, `plate_mode`, `rotor`, `edge`",
            ),
        ];
        for (text, want) in cases {
            assert_eq!(wrong_type(text).as_deref(), Some(want), "{text:?}");
        }
        for fine in [
            "[pixel]\nadders = \"auto\"\nregister_file = \"clock_gated\"\ntiming_liberty = \"sky130\"\n",
            "[pixel]\nprefilter_rounding = \"nearest\"\nmode = \"haar\"\nbins = 4\n",
        ] {
            assert_eq!(wrong_type(fine), None, "{fine:?}");
        }
    }
}
