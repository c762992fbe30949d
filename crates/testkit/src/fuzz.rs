//! What the configuration fuzzers (the library's, crates/design/tests/it/mutations.rs, and
//! the binary's, crates/cli/tests/it/fuzz_binary.rs) accept as naming a mutated key: the
//! forms its value may take in a message, and the dotted path of every key of a document.

/// The forms a value may take in a message (as written, or as Rust prints the number).
pub fn value_forms(lit: &str) -> Vec<String> {
    let mut f = vec![lit.trim_matches('"').to_string()];
    if let Ok(x) = lit.parse::<f64>() {
        f.extend([
            format!("{x}"),
            format!("{x:?}"),
            format!("{x:e}"),
            tofprobe_io::text::number(x),
        ]);
    }
    if lit == "nan" {
        f.push("NaN".into());
    }
    f
}

/// `section.key` of every key of `doc` (`scene.motion[i].key` for the motions).
pub fn dotted_paths(doc: &toml::Table) -> Vec<String> {
    let mut v = Vec::new();
    for (section, body) in doc {
        for (key, value) in body.as_table().into_iter().flatten() {
            if let Some(list) = value.as_array().filter(|_| key == "motion") {
                for (i, m) in list.iter().enumerate() {
                    for k in m.as_table().into_iter().flatten().map(|(k, _)| k) {
                        v.push(format!("scene.motion[{i}].{k}"));
                    }
                }
            }
            v.push(format!("{section}.{key}"));
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_is_named_in_every_spelling_and_motions_by_index() {
        let f = value_forms("1e3");
        assert!(
            f.contains(&"1e3".to_string()) && f.contains(&"1000".to_string()),
            "{f:?}"
        );
        assert_eq!(value_forms("\"auto\""), ["auto"]);
        let doc: toml::Table =
            toml::from_str("[pixel]\nbins = 4\n[scene]\nmotion = [{ kind = \"tone\" }]\n").unwrap();
        let p = dotted_paths(&doc);
        assert!(p.contains(&"pixel.bins".to_string()), "{p:?}");
        assert!(p.contains(&"scene.motion[0].kind".to_string()), "{p:?}");
    }
}
