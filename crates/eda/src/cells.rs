//! A liberty's cells as the hand-mapped registers pick them (`crate::clock_gate`,
//! `crate::latch`): which cells synthesis may use, pins and functions read plainly, the
//! smallest cell of a kind, the smallest inverter.

use crate::liberty::{LibCell, Liberty, NOT_FOR_SYNTHESIS};

/// Whether synthesis may use the cell (not `dont_use`, not one of [`NOT_FOR_SYNTHESIS`]).
pub(crate) fn usable(name: &str, c: &LibCell) -> bool {
    !c.dont_use && !NOT_FOR_SYNTHESIS.iter().any(|p| name.contains(p))
}

/// The function without parentheses and blanks.
pub(crate) fn bare(function: &str) -> String {
    function
        .chars()
        .filter(|c| !c.is_whitespace() && *c != '(' && *c != ')')
        .collect()
}

/// Input pins.
pub(crate) fn inputs(c: &LibCell) -> Vec<&str> {
    c.pins
        .iter()
        .filter(|p| p.direction == "input")
        .map(|p| p.name.as_str())
        .collect()
}

/// Output pins with their functions (their raw text: `crate::clock_gate`'s AND test reads it).
pub(crate) fn outputs(c: &LibCell) -> Vec<(&str, String)> {
    c.pins
        .iter()
        .filter(|p| p.direction == "output")
        .map(|p| (p.name.as_str(), p.function.clone()))
        .collect()
}

/// The smallest usable cell `pick` accepts (what it returns for it).
pub(crate) fn smallest<'a, T>(
    lib: &'a Liberty,
    pick: impl Fn(&'a String, &'a LibCell) -> Option<T>,
) -> Option<T> {
    lib.cells
        .iter()
        .filter(|(n, c)| usable(n, c))
        .filter_map(|(n, c)| pick(n, c).map(|t| (c.area, t)))
        // The first by name among equals (BTreeMap order; `min_by` keeps the first).
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, t)| t)
}

/// The liberty's smallest inverter: (cell, input pin, output pin).
pub fn smallest_inverter(lib: &Liberty) -> Option<(String, String, String)> {
    smallest(lib, |n, c| {
        let ins = inputs(c);
        let outs = outputs(c);
        if c.sequential || ins.len() != 1 || outs.len() != 1 {
            return None;
        }
        let a = ins[0];
        [format!("!{a}"), format!("{a}'")]
            .contains(&bare(&outs[0].1))
            .then(|| (n.clone(), a.to_string(), outs[0].0.to_string()))
    })
}
