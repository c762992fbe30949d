//! The layout's options: the target placement density (`--density`, auto by the netlist's
//! size), the densities tried when routing fails, and qrouter's stage 3
//! (`--route-cleanup`), each checked before any tool runs.

use crate::error::{LayoutError, Result};

/// Densities below this are not tried (the macro would be mostly fill).
pub const MIN_DENSITY: f64 = 0.2;
/// Placement attempts at most (the asked density, then 0.1 lower each time).
pub const MAX_ATTEMPTS: usize = 3;
/// Above this many cells `RouteCleanup::Auto` skips qrouter's stage 3: on the default
/// pixel (9,248 cells) it re-routed 40–60 nets a minute after stages 1 and 2 had routed
/// all 9,435 nets in ≈ 47 min, i.e. hours for wirelength alone; the 2-bin pixel (2,627
/// cells) keeps it (it takes a minute there).
pub const AUTO_CLEANUP_MAX_CELLS: u64 = 5_000;

/// Whether qrouter runs its stage 3, the cleanup that rips up and re-routes every routed
/// net. Stages 1 and 2 (route, then rip up and re-route the failures) leave every net
/// routed; stage 3 shortens the wires and removes defects stage 2 can leave (the default
/// pixel's stage-2 route had 3 DRC errors and one open net, which the ECO re-route,
/// `crate::repair`, clears by re-routing two nets; docs/layout.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RouteCleanup {
    /// On up to [`AUTO_CLEANUP_MAX_CELLS`] cells, off above.
    Auto,
    /// Always (qflow's own `qrouter::standard_route`).
    On,
    /// Never (`qrouter::standard_route` with its `nocleanup` argument).
    Off,
}

impl RouteCleanup {
    /// Parses `auto`, `on` or `off` (the CLI's `--route-cleanup`).
    pub fn parse(s: &str) -> Result<RouteCleanup> {
        match s {
            "auto" => Ok(RouteCleanup::Auto),
            "on" => Ok(RouteCleanup::On),
            "off" => Ok(RouteCleanup::Off),
            _ => Err(LayoutError::Option {
                option: "route-cleanup",
                value: s.into(),
                allowed: "auto, on or off".into(),
            }),
        }
    }

    /// Whether stage 3 runs for a netlist of `cells` cells.
    pub fn runs(self, cells: u64) -> bool {
        match self {
            RouteCleanup::Auto => cells <= AUTO_CLEANUP_MAX_CELLS,
            RouteCleanup::On => true,
            RouteCleanup::Off => false,
        }
    }
}

/// The density `Density::Auto` asks for up to [`AUTO_CLEANUP_MAX_CELLS`] cells (the 2-bin
/// pixel routes clean there, stage 3 included) and above ([`AUTO_DENSITY_LARGE`]).
pub const AUTO_DENSITY_SMALL: f64 = 0.6;
/// The density `Density::Auto` asks for above [`AUTO_CLEANUP_MAX_CELLS`] cells: the default
/// pixel (9,248 cells) routes every net at 0.5 with stages 1 and 2 and is clean after the
/// ECO re-route (docs/layout.md); at 0.6 stage 2 had not finished after 34 min.
pub const AUTO_DENSITY_LARGE: f64 = 0.5;

/// The target placement density asked for: a number, or `auto` (by the netlist's size).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Density {
    /// [`AUTO_DENSITY_SMALL`] up to [`AUTO_CLEANUP_MAX_CELLS`] cells, [`AUTO_DENSITY_LARGE`] above.
    Auto,
    /// This density (cells / core), [`MIN_DENSITY`] ..= 0.95.
    Fixed(f64),
}

impl Density {
    /// Parses `auto` or a number (the CLI's `--density`); the range is checked by
    /// [`check_options`].
    pub fn parse(s: &str) -> Result<Density> {
        if s == "auto" {
            return Ok(Density::Auto);
        }
        s.trim()
            .parse::<f64>()
            .map(Density::Fixed)
            .map_err(|_| LayoutError::Option {
                option: "density",
                value: s.into(),
                allowed: format!("auto or a number {MIN_DENSITY} ..= 0.95, e.g. 0.5"),
            })
    }

    /// The density to place a netlist of `cells` cells at.
    pub fn target(self, cells: u64) -> f64 {
        match self {
            Density::Auto if cells <= AUTO_CLEANUP_MAX_CELLS => AUTO_DENSITY_SMALL,
            Density::Auto => AUTO_DENSITY_LARGE,
            Density::Fixed(d) => d,
        }
    }
}

/// Checks the request's numbers before anything runs.
pub fn check_options(density: Density, node_nm: f64) -> Result<()> {
    if let Density::Fixed(density) = density
        && !(density.is_finite() && (MIN_DENSITY..=0.95).contains(&density))
    {
        return Err(LayoutError::Option {
            option: "density",
            value: density.to_string(),
            allowed: format!(
                "auto or {MIN_DENSITY} ..= 0.95 (0.5 routes the default pixel on osu018)"
            ),
        });
    }
    if !(node_nm.is_finite() && node_nm > 0.0 && node_nm <= 1000.0) {
        return Err(LayoutError::Option {
            option: "node-nm",
            value: node_nm.to_string(),
            allowed: "0 < node ≤ 1000 (nm), e.g. 40".into(),
        });
    }
    Ok(())
}

/// The densities tried for a request of `d`.
pub fn densities(d: f64) -> Vec<f64> {
    (0..MAX_ATTEMPTS)
        .map(|i| ((d - 0.1 * i as f64) * 100.0).round() / 100.0)
        .filter(|&x| x >= MIN_DENSITY - 1e-9)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn route_cleanup_auto_keeps_stage_3_for_small_pixels_only() {
        // The 2-bin pixel (2,627 cells) keeps it, the default (9,248 cells) skips it.
        assert!(RouteCleanup::Auto.runs(2_627));
        assert!(RouteCleanup::Auto.runs(AUTO_CLEANUP_MAX_CELLS));
        assert!(!RouteCleanup::Auto.runs(9_248));
        assert!(RouteCleanup::On.runs(9_248));
        assert!(!RouteCleanup::Off.runs(10));
        assert_eq!(RouteCleanup::parse("off").unwrap(), RouteCleanup::Off);
        let e = RouteCleanup::parse("never").unwrap_err().to_string();
        assert!(
            e.contains("route-cleanup") && e.contains("auto, on or off"),
            "{e}"
        );
    }

    #[test]
    fn density_auto_follows_the_netlist_size() {
        // The 2-bin pixel (2,627 cells) at 0.6, where it routes clean with stage 3; the
        // default (9,248 cells) at 0.5, where it routes clean after the ECO re-route.
        assert_eq!(Density::Auto.target(2_627), 0.6);
        assert_eq!(Density::Auto.target(AUTO_CLEANUP_MAX_CELLS), 0.6);
        assert_eq!(Density::Auto.target(9_248), 0.5);
        assert_eq!(Density::Fixed(0.45).target(9_248), 0.45);
        assert_eq!(Density::parse("auto").unwrap(), Density::Auto);
        assert_eq!(Density::parse("0.55").unwrap(), Density::Fixed(0.55));
        let e = Density::parse("dense").unwrap_err().to_string();
        assert!(
            e.contains("--density = dense") && e.contains("auto or a number"),
            "{e}"
        );
        assert!(check_options(Density::Auto, 40.0).is_ok());
        let e = check_options(Density::Fixed(0.99), 40.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("0.5 routes the default pixel"), "{e}");
    }
}
