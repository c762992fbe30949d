//! `[array] level`: the four names resolve and round-trip, a name that does not exist is
//! refused listing all four, and `"auto"` (which runs pixels at the statistical level) is
//! refused wherever `"statistical"` is, naming `array.level` and the level that works.

use tofprobe_design::{ArrayLevel, DEFAULT_TOML, Document, resolve};

/// The default scene (a sine) on a 2 × 2 array at `level`, with `extra` TOML appended to
/// the `[array]` table.
fn text(level: &str, extra: &str) -> String {
    format!(
        "{DEFAULT_TOML}\n[array]\nrows = 2\ncols = 2\npitch_um = 30.0\nmm_per_pixel = 1.0\n\
         level = \"{level}\"\n{extra}"
    )
}

fn resolved(t: &str) -> Result<tofprobe_design::ResolvedDesign, String> {
    let d = Document::from_toml_str(t, "t.toml").map_err(|e| e.to_string())?;
    resolve(d, "t.toml").map_err(|e| e.to_string())
}

#[test]
fn every_level_resolves_under_its_name() {
    assert_eq!(ArrayLevel::ALL.len(), 4);
    for level in ArrayLevel::ALL {
        let d = resolved(&text(level.name(), "")).unwrap();
        assert_eq!(d.array.as_ref().unwrap().level, level);
        let back = tofprobe_design::ResolvedDesign::from_json(&d.to_json().unwrap()).unwrap();
        assert_eq!(back.array.unwrap().level, level);
    }
}

#[test]
fn an_unknown_level_lists_the_four_names() {
    let e = resolved(&text("fast", "")).unwrap_err();
    for want in ["level", "bit-true", "statistical", "closed-form", "auto"] {
        assert!(e.contains(want), "{e}");
    }
}

/// Background with a superpixel is outside the statistical level's validated range: the
/// statistical and the auto levels are refused with the same reason, each naming itself,
/// and bit-true runs it.
#[test]
fn auto_is_refused_where_statistical_is() {
    let extra = "superpixel = 2\nbackground_map = { kind = \"constant\", value = 0.1 }";
    let t = |level| text(level, extra).replace("rows = 2\ncols = 2", "rows = 4\ncols = 4");
    let why = |e: &str| e.split("validated range:").nth(1).map(str::to_string);
    let st = resolved(&t("statistical")).unwrap_err();
    let au = resolved(&t("auto")).unwrap_err();
    assert!(
        au.contains("array.level = \"auto\"") && au.contains("\"bit-true\""),
        "{au}"
    );
    assert!(why(&au).is_some() && why(&au) == why(&st), "{au}\n{st}");
    resolved(&t("bit-true")).unwrap();
}

/// `auto_threshold` (K of the auto level): resolved (default 0.5 when not written, and a
/// design at the default serialises without it, so older sets keep their hash), refused
/// out of 0..=10 naming the key, its value, the range and the default, and refused beside
/// any level but `"auto"` (never accepted and ignored), naming the level that takes it.
#[test]
fn the_auto_threshold_is_resolved_checked_and_only_taken_by_auto() {
    use tofprobe_design::array::AUTO_THRESHOLD;
    let k = |t: &str| resolved(t).map(|d| d.array.unwrap().auto_threshold);
    assert_eq!(k(&text("auto", "")).unwrap(), AUTO_THRESHOLD);
    assert_eq!(k(&text("auto", "auto_threshold = 2.5\n")).unwrap(), 2.5);
    assert_eq!(k(&text("auto", "auto_threshold = 0.0\n")).unwrap(), 0.0);
    let json = resolved(&text("auto", "")).unwrap().to_json().unwrap();
    assert!(!json.contains("auto_threshold"), "{json}");
    let json = resolved(&text("auto", "auto_threshold = 2.5\n"))
        .unwrap()
        .to_json()
        .unwrap();
    assert!(json.contains("auto_threshold"), "{json}");
    for bad in ["-0.1", "10.5", "1e300"] {
        let e = resolved(&text("auto", &format!("auto_threshold = {bad}\n"))).unwrap_err();
        for want in [
            "array.auto_threshold",
            "0 <= auto_threshold <= 10",
            "default 0.5",
        ] {
            assert!(e.contains(want), "{bad}: {e}");
        }
    }
    let e = resolved(&text("auto", "auto_threshold = nan\n")).unwrap_err();
    assert!(e.contains("array.auto_threshold = NaN"), "{e}");
    for level in ["bit-true", "statistical", "closed-form"] {
        let e = resolved(&text(level, "auto_threshold = 1.0\n")).unwrap_err();
        assert!(
            e.contains("array.auto_threshold = 1 applies only with array.level = \"auto\"")
                && e.contains(&format!("the level is \"{level}\"")),
            "{level}: {e}"
        );
    }
}
