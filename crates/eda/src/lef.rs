//! The cell outlines of a LEF (`MACRO name … SIZE w BY h`, µm): the layout's check that
//! every cell has a view, and the area of a cell whose liberty gives none (osu018's
//! `LATCH` has `area : 0`; its LEF outline is 5.6 × 10 µm), see
//! [`crate::liberty::Liberty::load`].

use std::collections::BTreeMap;

/// Cell outlines of a LEF: `MACRO name … SIZE w BY h` (µm).
pub fn lef_sizes(text: &str) -> BTreeMap<String, (f64, f64)> {
    let mut sizes = BTreeMap::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["MACRO", name, ..] => current = Some((*name).to_string()),
            ["SIZE", w, "BY", h, ..] => {
                if let (Some(name), Ok(w), Ok(h)) =
                    (&current, w.parse(), h.trim_end_matches(';').parse())
                {
                    sizes.insert(name.clone(), (w, h));
                }
            }
            ["END", name] if current.as_deref() == Some(*name) => current = None,
            _ => {}
        }
    }
    sizes
}
