//! The types the document's keys take, to name the key when the TOML does not fit them.
//! The toml crate reports a wrong type inside an array of tables (`[[scene.motion]]`) or an
//! enum at the table's header with no key ("invalid type: string "x", expected f64"); this
//! walk finds the key, so the message names the field, the value and the type it needs.

use toml::Value;

/// The type a key needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Number,
    Integer,
    Bool,
    Text,
    Numbers,
    IntegerOrAuto,
}

impl Kind {
    fn fits(self, v: &Value) -> bool {
        match self {
            Kind::Number => v.is_float() || v.is_integer(),
            Kind::Integer => v.as_integer().is_some_and(|i| i >= 0),
            Kind::Bool => v.is_bool(),
            Kind::Text => v.is_str(),
            Kind::Numbers => v
                .as_array()
                .is_some_and(|a| a.iter().all(|x| x.is_float() || x.is_integer())),
            Kind::IntegerOrAuto => {
                v.as_integer().is_some_and(|i| i >= 0) || v.as_str() == Some("auto")
            }
        }
    }

    fn needs(self) -> &'static str {
        match self {
            Kind::Number => "a number",
            Kind::Integer => "an integer >= 0",
            Kind::Bool => "true or false",
            Kind::Text => "a string",
            Kind::Numbers => "an array of numbers",
            Kind::IntegerOrAuto => "an integer >= 0 or \"auto\"",
        }
    }
}

/// The key's type in a table (`motion` = an entry of `[[scene.motion]]`).
fn kind(table: &str, key: &str) -> Option<Kind> {
    use Kind::*;
    Some(match (table, key) {
        ("sensor", _) => Number,
        ("scene", "depth_mm") => Number,
        ("acquisition", "duration_s") => Number,
        ("acquisition", "pulses" | "seed") => Integer,
        ("pixel", "mode") => Text,
        ("pixel", "bins" | "width") => IntegerOrAuto,
        ("pixel", "frequencies_hz") => Numbers,
        ("pixel", _) => Integer,
        ("probe", "osr" | "h_inf" | "amplitude") => Number,
        ("probe", "order" | "rom_depth") => Integer,
        ("probe", "optimised_zeros") => Bool,
        ("probe", "window" | "rom_mode" | "convention") => Text,
        ("motion", "kind") => Text,
        ("motion", "depths_mm") => Numbers,
        ("motion", "m" | "n" | "blades") => Integer,
        ("array", "rows" | "cols") => Integer,
        ("array", "pitch_um" | "mm_per_pixel" | "field_of_view_deg" | "distance_mm") => Number,
        ("motion", _) => Number,
        _ => return None,
    })
}

/// The first key of `text` (a TOML document) whose value has the wrong type, as
/// "`path` = value: expected …"; `None` when every known key has its type (or the text is
/// not TOML at all: the parser's own message says where).
pub fn wrong_type(text: &str) -> Option<String> {
    let doc: toml::Table = toml::from_str(text).ok()?;
    let report = |path: String, v: &Value, k: Kind| {
        let shown = tofprobe_io::text::clip(&v.to_string(), 60);
        format!(
            "`{path}` = {shown} has the wrong type: expected {}",
            k.needs()
        )
    };
    for (section, body) in &doc {
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
                    for (mk, mv) in m.as_table().into_iter().flatten() {
                        if let Some(k) = kind("motion", mk).filter(|k| !k.fits(mv)) {
                            return Some(report(format!("scene.motion[{i}].{mk}"), mv, k));
                        }
                    }
                }
                continue;
            }
            if let Some(k) = kind(section, key).filter(|k| !k.fits(v)) {
                return Some(report(format!("{section}.{key}"), v, k));
            }
        }
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
}
