//! The circle check on tiny crates written here (a circle must be found and named, its
//! absence must pass), then on every crate of the workspace.

use super::*;

fn tree(files: &[(&str, &str)]) -> Sources {
    files
        .iter()
        .map(|(f, t)| (f.to_string(), t.to_string()))
        .collect()
}

/// Two files that take a name from each other, one through a parent's re-export and one
/// written inline: one circle of both, with the names that tie it.
#[test]
fn a_circle_is_found_and_named() {
    let t = tree(&[
        ("lib.rs", "mod a;\nmod b;\npub use b::Bee;\n"),
        ("a.rs", "use crate::Bee;\npub struct Ay;\nfn f(_: Bee) {}\n"),
        (
            "b.rs",
            "pub struct Bee;\nfn g() -> crate::a::Ay { crate::a::Ay }\n",
        ),
    ]);
    let c = circles(&t);
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].files, ["a.rs", "b.rs"]);
    let shown = c[0].to_string();
    assert!(shown.contains("a.rs -> b.rs: Bee"), "{shown}");
    assert!(shown.contains("b.rs -> a.rs: Ay"), "{shown}");
}

/// Three files in a ring through `super::`, a child module's path and a glob.
#[test]
fn a_ring_of_three_through_super_and_globs_is_one_circle() {
    let t = tree(&[
        ("lib.rs", "pub mod sd;\n"),
        ("sd/mod.rs", "mod isa;\nmod pairs;\nmod lanes;\n"),
        ("sd/isa.rs", "use super::pairs::*;\npub enum Path { A }\n"),
        ("sd/pairs.rs", "pub const N: usize = super::lanes::L;\n"),
        (
            "sd/lanes.rs",
            "pub const L: usize = 1;\nfn f() -> super::isa::Path { todo!() }\n",
        ),
    ]);
    let c = circles(&t);
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].files, ["sd/isa.rs", "sd/lanes.rs", "sd/pairs.rs"]);
}

/// The same crate with the shared type moved to the parent both use: no circle. A parent
/// that declares and re-exports its children, a child using the parent's items, a test
/// module's `use super::*`, a `#[path]` test file, comments and strings naming paths, and
/// another crate's paths are not circles either.
#[test]
fn shared_types_in_the_parent_leave_no_circle() {
    let t = tree(&[
        (
            "lib.rs",
            "pub mod sd;\npub use sd::isa::Path;\npub struct Error;\n",
        ),
        (
            "sd/mod.rs",
            "mod isa;\nmod pairs;\nmod lanes;\npub use pairs::N;\npub enum Path { A }\nfn g() -> usize { lanes::L + pairs::N }\n#[cfg(test)]\n#[path = \"mod_tests.rs\"]\nmod tests;\n",
        ),
        (
            "sd/mod_tests.rs",
            "use super::*;\nuse crate::sd::lanes::L;\n",
        ),
        (
            "sd/isa.rs",
            "use super::Path;\nuse crate::Error;\n// crate::sd::lanes::L\n",
        ),
        (
            "sd/pairs.rs",
            "pub const N: usize = super::lanes::L;\nconst S: &str = \"crate::sd::isa::x\";\n",
        ),
        (
            "sd/lanes.rs",
            "pub const L: usize = 1;\nfn f() -> super::Path { std::process::exit(0) }\n#[cfg(test)]\nmod tests { use super::*; use crate::sd::pairs::N; }\n",
        ),
    ]);
    let c = circles(&t);
    assert!(c.is_empty(), "{c:?}");
    let g = import_graph(&t);
    assert!(g.contains_key(&("sd/pairs.rs".into(), "sd/lanes.rs".into())));
    assert!(g.contains_key(&("sd/isa.rs".into(), "sd/mod.rs".into())));
    assert!(g.contains_key(&("sd/isa.rs".into(), "lib.rs".into())));
    assert!(
        !g.keys().any(|(a, _)| a == "lib.rs" || a == "sd/mod.rs"),
        "{g:?}"
    );
}

/// Every crate of the workspace: no file of a crate's `src` is in an import circle.
#[test]
fn no_crate_of_the_workspace_has_an_import_circle() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut dirs: Vec<_> = std::fs::read_dir(&crates)
        .unwrap()
        .map(|e| e.unwrap().path().join("src"))
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    assert!(dirs.len() > 10, "the workspace's crates under {crates:?}");
    let mut found = Vec::new();
    for src in dirs {
        let name = src.parent().unwrap().file_name().unwrap();
        let name = name.to_string_lossy().to_string();
        for c in circles(&read_sources(&src).unwrap()) {
            found.push(format!("crates/{name}/src: {c}"));
        }
    }
    assert!(
        found.is_empty(),
        "{} import circles between the files of a crate (move what both files use to a module \
         both may use, e.g. their parent):\n{}",
        found.len(),
        found.join("")
    );
}
