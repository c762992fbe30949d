//! The checkout is self-contained (issue 44): everything the code, the tests, the scripts
//! and the examples read is inside the repository (the real records and the sky130 PDK are
//! vendored under `third_party/`), so a fresh clone with nothing beside it passes. Two
//! checks: every data look-up is resolved (symlinks too) and must land inside the
//! workspace, and no source names a path that leaves it (a relative path resolved from
//! where it is read, or a folder beside the checkout named in a document).

use std::path::{Component, Path, PathBuf};

use tofprobe_eda::pdk::{self, Sky130Pdk};
use tofprobe_testkit::data;

fn root() -> PathBuf {
    data::workspace_root()
        .canonicalize()
        .expect("the workspace root")
}

/// `p` with `.` and `..` folded away (no file-system access: the path may not exist).
fn normalise(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// Where `p` really is, or why it is not there.
fn inside(root: &Path, what: &str, p: &Path) -> Option<String> {
    match p.canonicalize() {
        Ok(c) if c.starts_with(root) => None,
        Ok(c) => Some(format!(
            "{what}: {} is outside the repository {}",
            c.display(),
            root.display()
        )),
        Err(e) => Some(format!("{what}: {}: {e}", p.display())),
    }
}

/// Every data look-up the tests and the library make resolves inside the checkout, to a
/// file that is there: the records, the PDK's search path, and what the PDK look-up finds
/// (each corner's liberty, the cell models, the UDPs, the layout's files).
#[test]
fn every_data_lookup_resolves_inside_the_repository() {
    let root = root();
    let mut bad = Vec::new();
    let mut check = |what: String, p: &Path| bad.extend(inside(&root, &what, p));
    for name in data::TTTR_RECORDS {
        check(format!("tttr_record({name})"), &data::tttr_record(name));
    }
    check("tofprobe_eda::pdk::vendored()".into(), &pdk::vendored());
    check(
        "tofprobe_eda::pdk::search_path()[0]".into(),
        &pdk::search_path()[0],
    );
    let found = Sky130Pdk::at(&pdk::vendored()).expect("the vendored PDK is a PDK directory");
    assert_eq!(found.corner_names(), pdk::CORNERS, "every corner vendored");
    for c in &found.corners {
        check(format!("corner {}", c.name), &c.source);
    }
    let models = found.cell_models.clone().unwrap_or_default();
    let udps = found.primitives.clone().unwrap_or_default();
    check("the cell models (sky130_fd_sc_hd.v.gz)".into(), &models);
    check("the UDPs (primitives.v)".into(), &udps);
    // The files `tofprobe_layout::tech::TechFiles::sky130` assembles qflow's setup from.
    for stem in [
        "sky130_fd_sc_hd_merged.lef.gz",
        "sky130_fd_sc.tlef",
        "sky130_fd_sc_hd.gds.gz",
        "sky130_fd_sc_hd.cdl.gz",
        "sky130A.tech.gz",
        "lvs_setup.tcl",
        "LICENSE",
        "README.md",
    ] {
        check(format!("layout file {stem}"), &pdk::vendored().join(stem));
    }
    // Without an override the look-up the commands make finds the vendored PDK, not
    // whatever lies beside the checkout (CI lays a folder there).
    if std::env::var_os(pdk::PDK_ENV).is_none() {
        let d = Sky130Pdk::discover(None)
            .expect("discover")
            .expect("the vendored PDK");
        check("Sky130Pdk::discover(None)".into(), &d.dir);
        assert_eq!(
            d.dir.canonicalize().unwrap(),
            pdk::vendored().canonicalize().unwrap()
        );
    }
    for dir in [data::TTTR_DIR, pdk::VENDORED] {
        check(format!("{dir}/LICENSE"), &root.join(dir).join("LICENSE"));
        check(
            format!("{dir}/README.md"),
            &root.join(dir).join("README.md"),
        );
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The relative paths a source line holds: every token starting with `../` (or `/../`
/// right after a quote, the `concat!(env!("CARGO_MANIFEST_DIR"), "/../…")` form).
fn relative_paths(line: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let bytes = line.as_bytes();
    let mut i = 0;
    while let Some(at) = line[i..].find("../") {
        let start = i + at;
        let before = if start == 0 { b' ' } else { bytes[start - 1] };
        let opens = matches!(before, b'"' | b'\'' | b' ' | b'(' | b'=' | b'`')
            || (before == b'/' && start >= 2 && bytes[start - 2] == b'"');
        let end = line[start..]
            .find(['"', '\'', ' ', ')', '`', ',', ';'])
            .map_or(line.len(), |e| start + e);
        if opens {
            out.push(line[start..end].trim_start_matches('/'));
        }
        i = end.max(start + 3);
    }
    out
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name();
        let name = name.to_string_lossy();
        if p.is_dir() {
            if !matches!(name.as_ref(), "target" | "__pycache__" | ".git") {
                walk(&p, out);
            }
        } else {
            out.push(p);
        }
    }
}

/// No source names a path outside the checkout. Code (Rust, shell, Python, TOML, Verilog,
/// C++): each relative path is resolved from where it is read — an `include_str!` from
/// the file's folder, any other Rust path from its crate (`CARGO_MANIFEST_DIR`), a script's
/// from the project root it changes to, a crate's TOML from its crate — and must stay
/// inside. Documents (Markdown): no
/// folder beside the checkout (the data folder CI lays beside it) and no absolute path of this machine's.
#[test]
fn no_source_names_a_path_outside_the_repository() {
    let root = root();
    let beside = ["..", "/shared"].concat();
    let machine = ["/wo", "rk/"].concat();
    let mut files = Vec::new();
    for top in [
        "crates",
        "scripts",
        "testbench",
        "examples",
        "templates",
        "scenes",
        "docs",
        ".ci",
    ] {
        walk(&root.join(top), &mut files);
    }
    files.push(root.join("README.md"));
    files.push(root.join("Cargo.toml"));
    let mut bad = Vec::new();
    let mut scanned = 0;
    for f in &files {
        let ext = f.extension().and_then(|e| e.to_str()).unwrap_or("");
        let code = matches!(ext, "rs" | "sh" | "py" | "toml" | "v" | "cpp" | "tcl")
            || f.parent().and_then(Path::file_name) == Some(".ci".as_ref());
        if !code && ext != "md" {
            continue;
        }
        // This file spells the paths it looks for (its own examples are checked below).
        let Ok(text) = std::fs::read_to_string(f).map(|t| {
            if f.ends_with("cli/tests/it/self_contained.rs") {
                String::new()
            } else {
                t
            }
        }) else {
            continue;
        };
        scanned += 1;
        let rel = f.strip_prefix(&root).unwrap_or(f).display().to_string();
        let crate_dir = f
            .strip_prefix(&root)
            .ok()
            .filter(|r| r.starts_with("crates"))
            .and_then(|r| r.components().nth(1))
            .map(|c| root.join("crates").join(c));
        for (n, line) in text.lines().enumerate() {
            if line.contains(&beside) || line.contains(&machine) {
                bad.push(format!("{rel}:{}: {}", n + 1, line.trim()));
                continue;
            }
            if !code {
                continue;
            }
            for p in relative_paths(line) {
                let base = match &crate_dir {
                    Some(_) if ext == "rs" && line.contains("include_") => {
                        f.parent().unwrap().into()
                    }
                    Some(c) => c.clone(),
                    None => root.clone(),
                };
                if !normalise(&base.join(p)).starts_with(&root) {
                    bad.push(format!("{rel}:{}: {p} leaves the repository", n + 1));
                }
            }
        }
    }
    assert!(scanned > 300, "scanned only {scanned} files");
    assert!(
        bad.is_empty(),
        "paths outside the repository:\n{}",
        bad.join("\n")
    );
}

/// The scan can fail: a crate-relative path three levels up (the old
/// `CARGO_MANIFEST_DIR` followed by three `..` and a folder name) leaves the repository, an `include_str!` four
/// levels up from a test file does not.
#[test]
fn the_path_scan_rejects_a_path_beside_the_checkout() {
    let root = root();
    let krate = root.join("crates/cli");
    let line = r#"    .join("../../../elsewhere/data/tttr")"#;
    let [p] = relative_paths(line)[..] else {
        panic!("{:?}", relative_paths(line));
    };
    assert!(!normalise(&krate.join(p)).starts_with(&root));
    let line = r#"concat!(env!("CARGO_MANIFEST_DIR"), "/../../../elsewhere/pdk")"#;
    assert_eq!(relative_paths(line), ["../../../elsewhere/pdk"]);
    let line = r#"include_str!("../../../../scenes/default.toml")"#;
    let [p] = relative_paths(line)[..] else {
        panic!()
    };
    assert!(normalise(&krate.join("tests/it").join(p)).starts_with(&root));
    assert!(relative_paths(r#"cd "$(dirname "$0")/..""#).is_empty());
}
