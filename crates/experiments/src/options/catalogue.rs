//! The architecture options of issue 16 as data: each a name and the `[pixel]` keys it
//! sets on the scene's configuration (applied with the tradeoff study's overrides, so an
//! option goes through the same resolution as a user's file and `width` follows it).

use serde::Serialize;

/// One architecture option: its name and the TOML keys it sets.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ArchOption {
    /// Short name (`baseline`, `nearest`, `G=2`, `clock-gated`, `latch`, combinations joined
    /// by `+`).
    pub name: String,
    /// `(dotted.key, TOML value)` pairs.
    pub overrides: Vec<(String, String)>,
}

fn opt(name: &str, overrides: &[(&str, String)]) -> ArchOption {
    ArchOption {
        name: name.to_string(),
        overrides: overrides
            .iter()
            .map(|(k, v)| ((*k).to_string(), v.clone()))
            .collect(),
    }
}

/// The register fractions G worth trying below F: F/2, 2 and 0 (distinct, < F).
pub fn fractions(frac_bits: u32) -> Vec<u32> {
    let mut g: Vec<u32> = [frac_bits / 2, 2, 0]
        .into_iter()
        .filter(|&g| g < frac_bits)
        .collect();
    g.sort_unstable_by(|a, b| b.cmp(a));
    g.dedup();
    g
}

/// The catalogue for a pixel with `frac_bits` = F and P operations per pulse: the
/// configuration as it is, each option alone (nearest rounding, each G, the clock-gated
/// register file, the latch register file, one adder shared by I and Q at C = P cycles per pulse), and the
/// combinations a recommendation picks from: a clock-gated file with each G. Nearest
/// rounding is not in the combinations: it removes a DC bias the tone bins do not see
/// (the tone moves by < 0.001 µm, docs/tradeoff.md) and costs an adder in the prefilter
/// and half of sky130's slack, so it is measured alone.
pub fn catalogue(frac_bits: u32, ops_per_pulse: usize) -> Vec<ArchOption> {
    let nearest = ("pixel.prefilter_rounding", "\"nearest\"".to_string());
    let gated = ("pixel.register_file", "\"clock_gated\"".to_string());
    let g_key = |g: u32| ("pixel.register_frac_bits", g.to_string());
    let mut v = vec![
        opt("baseline", &[]),
        opt("nearest", std::slice::from_ref(&nearest)),
    ];
    let gs = fractions(frac_bits);
    for &g in &gs {
        v.push(opt(&format!("G={g}"), &[g_key(g)]));
    }
    v.push(opt("clock-gated", std::slice::from_ref(&gated)));
    // Latch registers (issue 30 point 4): the same values at every edge as flops, so the
    // same accuracy; measured alone (its gate-level sign-off is not automated yet, so it is
    // not combined into what `flow --recommended` may build).
    v.push(opt(
        "latch",
        &[("pixel.register_file", "\"latch\"".to_string())],
    ));
    v.push(opt(
        "one-adder",
        &[
            ("pixel.adders", "1".to_string()),
            ("pixel.cycles_per_pulse", ops_per_pulse.to_string()),
        ],
    ));
    for &g in &gs {
        v.push(opt(
            &format!("G={g}+clock-gated"),
            &[g_key(g), gated.clone()],
        ));
    }
    v
}

/// The options of `catalogue` named in `only` (all when empty); an unknown name is an error
/// listing the names there are.
pub fn select(catalogue: Vec<ArchOption>, only: &[String]) -> Result<Vec<ArchOption>, String> {
    if only.is_empty() {
        return Ok(catalogue);
    }
    let names: Vec<String> = catalogue.iter().map(|o| o.name.clone()).collect();
    if let Some(bad) = only.iter().find(|o| !names.contains(o)) {
        return Err(format!(
            "{bad:?} is not an option; the options are {}",
            names.join(", ")
        ));
    }
    Ok(catalogue
        .into_iter()
        .filter(|o| only.contains(&o.name))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_of_the_default_f() {
        let c = catalogue(8, 32);
        let names: Vec<&str> = c.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "baseline",
                "nearest",
                "G=4",
                "G=2",
                "G=0",
                "clock-gated",
                "latch",
                "one-adder",
                "G=4+clock-gated",
                "G=2+clock-gated",
                "G=0+clock-gated"
            ]
        );
        // F = 1 leaves only G = 0; F = 0 no G at all.
        assert_eq!(fractions(1), [0]);
        assert!(fractions(0).is_empty());
        // One adder serves all P = 32 operations: C = 32 cycles per pulse.
        let one = c.iter().find(|o| o.name == "one-adder").unwrap();
        assert!(
            one.overrides
                .contains(&("pixel.cycles_per_pulse".into(), "32".into()))
        );
    }

    #[test]
    fn select_names_the_unknown_option() {
        let e = select(catalogue(8, 32), &["G=3".into()]).unwrap_err();
        assert!(e.contains("\"G=3\"") && e.contains("G=2"), "{e}");
        let s = select(catalogue(8, 32), &["G=2".into(), "baseline".into()]).unwrap();
        assert_eq!(s.len(), 2);
    }
}
