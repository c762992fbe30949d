//! Formal equivalence of a mapped netlist and its RTL, with yosys's equivalence passes
//! (`equiv_make`, `equiv_simple -seq`, `equiv_induct`, `equiv_status -assert`).
//!
//! Gold: the RTL through yosys's coarse synthesis (`synth -flatten -run begin:fine`: proc,
//! const-flop removal, width reduction), so its registers have the names and widths the
//! netlist's flops carry (`equiv_make` pairs registers by name; a register the netlist
//! narrowed — `held`'s constant sign bit — would otherwise stay unpaired and break the
//! induction). What is proven is therefore the fine half of synthesis: techmap, ABC's
//! mapping, buffering and sizing, and the flop mapping — everything that turns words
//! into cells. Gate: the netlist with the cells' functions read from the liberty
//! (`read_liberty` without `-lib`: `function` and `ff` groups become logic and flops).
//! Both sides get `async2sync; dffunmap` (plain flops: `equiv_simple -seq` steps
//! through `$dff` only). `equiv_induct` then proves every register and output pair by
//! one-step induction: all pairs equal at t ⇒ equal at t + 1.
//!
//! A clock-gated register file (`register_file = "clock_gated"`): yosys's model steps every
//! flop at every step whatever drives its clock, so a gated register's update is proven
//! through the signals its clock is made of, which both sides name alike and `equiv_make`
//! pairs: each gate's latched enable (`cg_<r>.en_l`, a latch on both sides) and gated clock
//! (`gclk_<r>`), besides the flops' D logic. A gate on the wrong enable fails as an
//! unproven `cg_<r>.en_l` pair. An integrated clock-gating cell is read as the behaviour its
//! liberty declares (`latch_posedge`: latch open while CLK is low, AND with CLK), so the
//! proof covers the netlist's wiring of the cells, not the cells' transistors.
//!
//! A latch register file (`register_file = "latch"`, the RTL carries
//! [`crate::latch::MARKER`]) is proven by its own script, [`latch_equiv_script`]: SAT steps
//! `$dff`/`$ff` only, so both sides are first put on one global step — `async2sync` turns
//! each latch (`$dlatch`, and the liberty's latch cells as read) into "Q = EN ? D : Q of
//! the step before", and `clk2fflogic` each flop into "Q = D of the step before where `clk`
//! rose between the steps, else Q of the step before" — so `clk` is an input like any
//! other, its two phases are steps, and a latch open in the wrong phase or on the wrong
//! enable differs. Names are paired for state and ports only (registers, latches, the
//! clock gates' enable latches, inputs and outputs), not combinational wires: synthesis
//! may leave a wire's name on a net that carries it only where it is read (a Haar
//! pixel's `h_new` becomes `tdc` because it is read only when `valid`), which is no state
//! and would stay unproven. `equiv_induct` proves the pairs by induction over the
//! register correspondence.

use crate::error::{EdaError, Result};
use crate::fsutil::{Fnv64, write_atomic};
use crate::tools::{Tool, tail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// What to compare.
#[derive(Debug, Clone)]
pub struct EquivSpec {
    /// The RTL sources (the gold side).
    pub rtl: Vec<PathBuf>,
    /// The module both sides implement.
    pub top: String,
    /// Verilog parameter overrides of the RTL (as the netlist was synthesised with).
    pub params: Vec<(String, i64)>,
    /// The mapped netlist (`write_verilog -noattr`).
    pub netlist: PathBuf,
    /// The liberty whose cells the netlist instantiates (their functions).
    pub liberty: PathBuf,
}

/// A proven equivalence.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Equivalence {
    /// `$equiv` points (paired signal bits: registers and outputs).
    pub points: u64,
    /// All of them, proven.
    pub proven: u64,
    /// Wall time of yosys (s).
    pub seconds: f64,
    /// The yosys log.
    pub log: PathBuf,
    /// Served from the equivalence cache ([`check_equivalence_cached`]): `seconds` and
    /// `log` are those of the run that proved it.
    #[serde(default)]
    pub cached: bool,
}

/// The yosys script comparing `spec`.
pub fn equiv_script(spec: &EquivSpec) -> String {
    equiv_script_with(spec, None)
}

/// [`equiv_script`], with `icg_models` (a clock-gated register file's integrated clock
/// gates as Verilog, [`crate::clock_gate::icg_models`]) read on the gate side: a liberty
/// describes those cells by a `statetable`, which `read_liberty` cannot turn into logic.
pub fn equiv_script_with(spec: &EquivSpec, icg_models: Option<&Path>) -> String {
    let top = &spec.top;
    let mut s = read_rtl(spec);
    s += &format!(
        "synth -top {top} -flatten -run begin:fine\n\
         async2sync\n\
         dffunmap\n\
         memory_map\n\
         opt_clean\n\
         rename {top} gold\n\
         design -stash gold\n\
         read_liberty -ignore_miss_func {lib}\n\
         {icg}read_verilog {net}\n\
         prep -top {top} -flatten\n\
         async2sync\n\
         dffunmap\n\
         rename {top} gate\n\
         design -stash gate\n{tail}",
        lib = spec.liberty.display(),
        net = spec.netlist.display(),
        icg = icg_models.map_or(String::new(), |m| format!(
            "read_verilog -overwrite {}\n",
            m.display()
        )),
        tail = prove_pairs(1),
    );
    s
}

/// Reading the RTL sources with the netlist's parameter overrides (both scripts' gold side).
fn read_rtl(spec: &EquivSpec) -> String {
    let mut s = String::new();
    for src in &spec.rtl {
        s += &format!("read_verilog -sv {}\n", src.display());
    }
    s + &crate::synth::chparam(&spec.params, &spec.top)
}

/// Both scripts' end: the stashed gold and gate designs paired by name, each pair proven
/// by `equiv_simple -seq 2` and then induction over `induct_seq` steps, every pair asserted.
fn prove_pairs(induct_seq: u32) -> String {
    format!(
        "design -copy-from gold -as gold gold\n\
         design -copy-from gate -as gate gate\n\
         equiv_make gold gate equiv\n\
         hierarchy -top equiv\n\
         equiv_simple -seq 2\n\
         equiv_induct -seq {induct_seq}\n\
         equiv_status -assert\n"
    )
}

/// Which script proves a netlist: it follows the RTL's register file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Recipe {
    /// Flops, plain or clock-gated: [`equiv_script_with`].
    Flops,
    /// A latch register file: [`latch_equiv_script`].
    Latch,
}

impl Recipe {
    /// The recipe for `spec`: [`Recipe::Latch`] when one of its RTL sources is a pixel
    /// rendered with `register_file = "latch"` ([`crate::latch::in_source`], as synthesis
    /// decides to map latches).
    pub fn of(spec: &EquivSpec) -> Result<Self> {
        for src in &spec.rtl {
            let text = std::fs::read_to_string(src).map_err(|e| EdaError::io("reading", src, e))?;
            if crate::latch::in_source(&text) {
                return Ok(Self::Latch);
            }
        }
        Ok(Self::Flops)
    }

    /// The yosys script of this recipe for `spec` (`icg_models` as [`equiv_script_with`]).
    pub fn script(self, spec: &EquivSpec, icg_models: Option<&Path>) -> String {
        match self {
            Self::Flops => equiv_script_with(spec, icg_models),
            Self::Latch => latch_equiv_script(spec, icg_models),
        }
    }

    /// The cache key's tag: a latch proof never reuses a verdict cached for the other
    /// script (nor one cached before this recipe existed, which failed).
    fn cache_tag(self) -> &'static [u8] {
        match self {
            Self::Flops => b"tofprobe-equiv-v1",
            Self::Latch => b"tofprobe-equiv-latch-v1",
        }
    }
}

/// The yosys script proving a latch register file's netlist (see the module header).
///
/// Gold: the coarse RTL as in [`equiv_script_with`], with every wire that is neither a port
/// nor driven by a register's or latch's `Q` renamed private (`rename -hide`), so that
/// `equiv_make` pairs state and ports only. Gate: the netlist with the liberty's functions
/// (and `icg_models`); the wires the liberty cells' flattening adds (`<inst>.DS0000`,
/// `<inst>.A`) are renamed private likewise, so the netlist's own name of each net (`y[1]`,
/// `wd_0`) is the one pairs are made on. Then `async2sync; dffunmap; clk2fflogic` on both.
pub fn latch_equiv_script(spec: &EquivSpec, icg_models: Option<&Path>) -> String {
    let top = &spec.top;
    let mut s = read_rtl(spec);
    s += &format!(
        "synth -top {top} -flatten -run begin:fine\n\
         rename -hide w:* x:* %d t:* %co1:+[Q] w:* %i %d\n\
         async2sync\n\
         dffunmap\n\
         clk2fflogic\n\
         memory_map\n\
         opt_clean\n\
         rename {top} gold\n\
         design -stash gold\n\
         read_liberty -ignore_miss_func {lib}\n\
         {icg}read_verilog {net}\n\
         hierarchy -top {top}\n\
         setattr -set tofprobe_net 1 {top}/w:*\n\
         prep -top {top} -flatten\n\
         rename -hide w:* a:tofprobe_net %d\n\
         async2sync\n\
         dffunmap\n\
         clk2fflogic\n\
         opt_clean\n\
         rename {top} gate\n\
         design -stash gate\n{tail}",
        lib = spec.liberty.display(),
        net = spec.netlist.display(),
        icg = icg_models.map_or(String::new(), |m| format!(
            "read_verilog -overwrite {}\n",
            m.display()
        )),
        tail = prove_pairs(2),
    );
    s
}

/// Parses `equiv_status`: (points, unproven, first unproven pair).
pub fn parse_status(log: &str) -> Option<(u64, u64, String)> {
    let pos = log.rfind("Executing EQUIV_STATUS pass")?;
    let text = &log[pos..];
    let points = text
        .lines()
        .find(|l| l.trim_start().starts_with("Found") && l.contains("$equiv cells"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())?;
    // "Of those cells P are proven and U are unproven."
    let unproven = text
        .lines()
        .find(|l| l.contains("are proven and"))
        .and_then(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            let i = w.iter().position(|x| *x == "and")?;
            w.get(i + 1)?.parse().ok()
        })
        .unwrap_or(0);
    let first = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Unproven $equiv "))
        .and_then(|l| l.split_once(": "))
        .map(|(_, pair)| pair.trim().to_string())
        .unwrap_or_default();
    Some((points, unproven, first))
}

/// Where proven equivalences are cached: `equiv` beside the synthesis cache
/// ([`crate::fsutil::synth_cache_dir`]), so one cache directory holds both.
pub fn equiv_cache_dir() -> PathBuf {
    let synth = crate::fsutil::synth_cache_dir(None);
    synth
        .parent()
        .map_or_else(|| PathBuf::from("equiv"), |p| p.join("equiv"))
}

/// The cache key of `spec`: everything the proof's outcome depends on — the yosys version,
/// the script (with the files named by role, their paths do not matter), and the bytes of
/// the RTL sources, the netlist, the liberty and the clock-gate models read with it.
fn cache_key(
    spec: &EquivSpec,
    recipe: Recipe,
    yosys: &Path,
    models: Option<&str>,
) -> Result<String> {
    let mut h = Fnv64::default();
    h.feed(recipe.cache_tag())
        .feed(crate::synth::yosys_version(yosys).as_bytes());
    let roles = EquivSpec {
        rtl: (0..spec.rtl.len())
            .map(|i| PathBuf::from(format!("rtl{i}.v")))
            .collect(),
        netlist: "netlist.v".into(),
        liberty: "cells.lib".into(),
        ..spec.clone()
    };
    let models_role = Path::new("icg_models.v");
    h.feed(
        recipe
            .script(&roles, models.map(|_| models_role))
            .as_bytes(),
    );
    for path in spec.rtl.iter().chain([&spec.netlist, &spec.liberty]) {
        let bytes = std::fs::read(path).map_err(|e| EdaError::io("reading", path, e))?;
        h.feed(&bytes);
    }
    h.feed(models.unwrap_or("").as_bytes());
    Ok(h.hex())
}

/// Proves `spec`'s netlist equivalent to its RTL; `work` holds the script and the log.
/// An unproven pair is [`EdaError::NotEquivalent`], naming the netlist and the first
/// pair (`\\y[3]_gold [5] \\y[3]_gate [5]`: register 3, bit 5). A proof already made
/// of the same netlist, RTL, liberty and yosys is served from [`equiv_cache_dir`].
pub fn check_equivalence(spec: &EquivSpec, work: &Path) -> Result<Equivalence> {
    check_equivalence_cached(spec, work, Some(&equiv_cache_dir()))
}

/// [`check_equivalence`] with the cache in `cache` (`None`: no cache). Only a proof is
/// cached (a failure is re-run, so its report is fresh): the entry `cache/<key>/`
/// (`equiv.log` and `result.json` naming it) is made by `tofprobe_io::cache::entry` — built
/// in a private directory under the key's lock, sealed with its files' hashes, published
/// by a rename and checked on every read — so two runs proving one pair at once run one
/// proof, and an entry that does not read back whole is proven again and replaced.
pub fn check_equivalence_cached(
    spec: &EquivSpec,
    work: &Path,
    cache: Option<&Path>,
) -> Result<Equivalence> {
    let yosys = Tool::Yosys.locate()?;
    for src in &spec.rtl {
        if !src.is_file() {
            return Err(EdaError::RtlMissing { path: src.clone() });
        }
    }
    if !spec.netlist.is_file() {
        return Err(EdaError::RtlMissing {
            path: spec.netlist.clone(),
        });
    }
    let lib = crate::liberty::Liberty::load(&spec.liberty)?;
    let netlist = std::fs::read_to_string(&spec.netlist)
        .map_err(|e| EdaError::io("reading", &spec.netlist, e))?;
    let models = crate::clock_gate::icg_models(&lib, &netlist);
    let recipe = Recipe::of(spec)?;
    let Some(root) = cache else {
        return prove(spec, recipe, work, &yosys, models.as_deref());
    };
    let key = cache_key(spec, recipe, &yosys, models.as_deref())?;
    let dir = root.join(&key);
    let mut fresh = None;
    tofprobe_io::cache::entry(
        root,
        &key,
        |tmp| {
            let proven = prove(spec, recipe, work, &yosys, models.as_deref())?;
            store_entry(tmp, &dir, &proven)?;
            fresh = Some(proven);
            Ok(())
        },
        |p, e| EdaError::io("publishing the equivalence cache entry", p, e),
    )?;
    match fresh {
        Some(proven) => Ok(proven),
        // A whole entry that is not a proof (written by another version): prove again.
        None => match read_entry(&dir) {
            Some(hit) => Ok(hit),
            None => prove(spec, recipe, work, &yosys, models.as_deref()),
        },
    }
}

/// A whole cache entry's proof, or `None` (not a proof of every point).
fn read_entry(dir: &Path) -> Option<Equivalence> {
    let text = std::fs::read_to_string(dir.join("result.json")).ok()?;
    let e: Equivalence = serde_json::from_str(&text).ok()?;
    (e.points > 0 && e.proven == e.points && e.log.is_file())
        .then_some(Equivalence { cached: true, ..e })
}

/// Stores a proof into `tmp`, the entry published at `dir`: its log, then the result
/// naming the log at `dir`.
fn store_entry(tmp: &Path, dir: &Path, proven: &Equivalence) -> Result<()> {
    let text = std::fs::read(&proven.log).map_err(|e| EdaError::io("reading", &proven.log, e))?;
    write_atomic(&tmp.join("equiv.log"), &text)?;
    let entry = Equivalence {
        log: dir.join("equiv.log"),
        cached: false,
        ..proven.clone()
    };
    let json = serde_json::to_vec_pretty(&entry).map_err(|e| EdaError::Json {
        what: dir.join("result.json").display().to_string(),
        source: e,
    })?;
    write_atomic(&tmp.join("result.json"), &json)
}

/// Runs yosys's proof of `spec` in `work`.
fn prove(
    spec: &EquivSpec,
    recipe: Recipe,
    work: &Path,
    yosys: &Path,
    models: Option<&str>,
) -> Result<Equivalence> {
    let models_path = work.join("icg_models.v");
    if let Some(m) = models {
        write_atomic(&models_path, m.as_bytes())?;
    }
    let script = work.join("equiv.ys");
    write_atomic(
        &script,
        recipe
            .script(spec, models.map(|_| models_path.as_path()))
            .as_bytes(),
    )?;
    let log_path = work.join("equiv.log");
    let start = std::time::Instant::now();
    let out = Command::new(yosys)
        .arg("-q")
        .arg("-l")
        .arg(&log_path)
        .arg(&script)
        .output()
        .map_err(|e| EdaError::io("running", yosys, e))?;
    let seconds = start.elapsed().as_secs_f64();
    let log = std::fs::read_to_string(&log_path).unwrap_or_default();
    match parse_status(&log) {
        Some((points, 0, _)) if out.status.success() => Ok(Equivalence {
            points,
            proven: points,
            seconds,
            log: log_path,
            cached: false,
        }),
        Some((points, unproven, first)) if unproven > 0 => Err(EdaError::NotEquivalent(Box::new(
            crate::error::EquivFailure {
                netlist: spec.netlist.clone(),
                top: spec.top.clone(),
                unproven,
                total: points,
                first,
                log_tail: tail(&log, 8),
            },
        ))),
        _ => Err(EdaError::ToolFailed {
            tool: "yosys (equivalence)",
            status: out
                .status
                .code()
                .map_or("killed by a signal".into(), |c| c.to_string()),
            log_tail: tail(
                &format!("{log}{}", String::from_utf8_lossy(&out.stderr)),
                15,
            ),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_is_parsed_from_the_last_pass() {
        let log = "17. Executing EQUIV_STATUS pass.\nFound 35 $equiv cells in equiv:\n  Of those cells 24 are proven and 11 are unproven.\n  Unproven $equiv $auto$equiv_make.cc:274:find_same_wires$441: \\x_gold [6] \\x_gate [6]\n";
        assert_eq!(
            parse_status(log),
            Some((35, 11, "\\x_gold [6] \\x_gate [6]".into()))
        );
        let ok = "Executing EQUIV_STATUS pass.\nFound 39 $equiv cells in equiv:\n  Of those cells 39 are proven and 0 are unproven.\n  Equivalence successfully proven!\n";
        assert_eq!(parse_status(ok), Some((39, 0, String::new())));
        assert_eq!(parse_status("nothing"), None);
    }

    #[test]
    fn script_compares_coarse_gold_with_the_liberty_cells() {
        let s = equiv_script(&EquivSpec {
            rtl: vec!["p.v".into()],
            top: "pix".into(),
            params: vec![("B".into(), 2)],
            netlist: "n.v".into(),
            liberty: "c.lib".into(),
        });
        assert!(s.contains("chparam -set B 2 pix"));
        assert!(s.contains("synth -top pix -flatten -run begin:fine"));
        assert!(s.contains("read_liberty -ignore_miss_func c.lib\nread_verilog n.v"));
        assert!(s.ends_with("equiv_status -assert\n"));
        assert!(!s.contains("clk2fflogic"), "the flop script is unchanged");
    }

    #[test]
    fn latch_recipe_steps_both_sides_on_one_clock_and_pairs_state_only() {
        let dir = std::env::temp_dir().join(format!("tofprobe-recipe-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (flops, latch) = (dir.join("flops.v"), dir.join("latch.v"));
        std::fs::write(&flops, "// Register file: flops\nmodule pix; endmodule\n").unwrap();
        std::fs::write(
            &latch,
            format!("// {}\nmodule pix; endmodule\n", crate::latch::MARKER),
        )
        .unwrap();
        let spec = |rtl: &Path| EquivSpec {
            rtl: vec![rtl.to_path_buf()],
            top: "pix".into(),
            params: vec![],
            netlist: "n.v".into(),
            liberty: "c.lib".into(),
        };
        assert_eq!(Recipe::of(&spec(&flops)).unwrap(), Recipe::Flops);
        assert_eq!(Recipe::of(&spec(&latch)).unwrap(), Recipe::Latch);
        let s = Recipe::Latch.script(&spec(&latch), Some(Path::new("icg.v")));
        // Both sides: latches by async2sync, flops by clk2fflogic, in that order.
        assert_eq!(
            s.matches("async2sync\ndffunmap\nclk2fflogic\n").count(),
            2,
            "{s}"
        );
        // Gold keeps ports and register outputs; gate keeps the netlist's own names.
        assert!(s.contains("rename -hide w:* x:* %d t:* %co1:+[Q] w:* %i %d\n"));
        assert!(s.contains("setattr -set tofprobe_net 1 pix/w:*\nprep -top pix -flatten\n"));
        assert!(s.contains("read_verilog -overwrite icg.v\nread_verilog n.v\n"));
        assert!(s.ends_with("equiv_induct -seq 2\nequiv_status -assert\n"));
        assert_ne!(Recipe::Latch.cache_tag(), Recipe::Flops.cache_tag());
        let missing = spec(&dir.join("absent.v"));
        assert!(
            Recipe::of(&missing)
                .unwrap_err()
                .to_string()
                .contains("absent.v")
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
