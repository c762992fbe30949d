//! Verilator's run-time library objects (`verilated.o`, `verilated_threads.o`,
//! `verilated_dpi.o`, and `verilated_vcd_c.o` / `verilated_cov.o` when tracing or
//! covering), compiled once per compile command and shared by every harness build.
//!
//! Why: every `verilator --build` compiles those library sources again, and for the small
//! pixels the tests co-simulate they are most of the C++ compile (≈ 4.5 of ≈ 7 CPU-s per
//! build on this machine; CI makes 100+ builds). The objects depend only on the command
//! that compiles them — compiler, flags, `-D` switches of tracing and coverage — never on
//! the design, so a build of another design with the same command links the same bytes.
//!
//! How: the harness build runs Verilator without `--build`, then [`seed`] reads the
//! library objects the generated makefile wants (`VM_GLOBAL_FAST`/`VM_GLOBAL_SLOW` of
//! `Vtop_classes.mk`) and the exact commands that would compile them (`make -n`, the build
//! directory's path replaced by a placeholder), keys an entry of the cache root by those
//! commands, the Verilator version and the compiler's version, and copies the entry's
//! objects into the build directory. Copied after Verilator wrote `Vtop.mk`, they are newer
//! than every prerequisite make checks (the `.cpp` and `Vtop.mk`), so make links them as
//! they are; the executable is byte-identical to a build that compiled them (tested). A
//! build that found no entry publishes its objects after linking ([`Seeded::publish`]):
//! a directory of the objects and a manifest of their sizes and checksums, renamed into
//! place whole; an entry whose files do not match its manifest is not used. Sharing is an
//! optimisation: any failure here leaves make to compile the objects as before.

use std::path::{Path, PathBuf};
use std::process::Command;
use tofprobe_io::fnv1a64;
use tofprobe_io::stale::pid_tagged;

/// A per-process counter: two threads of one process (parallel tests) building the same
/// RTL must not share a temporary directory (the first to finish publishes, the other's
/// copy is dropped).
pub(crate) fn next_build_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// The manifest of an entry: one `NAME SIZE FNV` line per object.
const MANIFEST: &str = "objects.fnv";

/// The run-time library objects of one build, and whether they came from the cache.
#[derive(Debug)]
pub(crate) struct Seeded {
    /// The cache entry they belong to.
    entry: PathBuf,
    /// The object file names (`verilated.o`, …).
    objects: Vec<String>,
    /// Copied from the cache (nothing to publish).
    pub(crate) reused: bool,
}

/// The library objects a generated makefile links: the names listed under
/// `VM_GLOBAL_FAST +=` and `VM_GLOBAL_SLOW +=` (continuation lines ending in `\`), with `.o`.
pub(crate) fn global_objects(classes_mk: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut listing = false;
    for line in classes_mk.lines() {
        let t = line.trim();
        if t.starts_with("VM_GLOBAL_FAST +=") || t.starts_with("VM_GLOBAL_SLOW +=") {
            listing = t.ends_with('\\');
            continue;
        }
        if listing {
            let name = t.trim_end_matches('\\').trim();
            if !name.is_empty() {
                out.push(format!("{name}.o"));
            }
            listing = t.ends_with('\\');
        }
    }
    out
}

/// The compile commands of `make -n` (the lines writing an object), with `dirs`'s paths
/// replaced by `<dir>` so builds in other directories of the same command share a key.
pub(crate) fn normalised_commands(make_n: &str, dirs: &[&Path]) -> String {
    let mut out = String::new();
    for line in make_n.lines().filter(|l| l.contains(" -c -o ")) {
        let mut l = line.to_string();
        for d in dirs {
            l = l.replace(&*d.to_string_lossy(), "<dir>");
        }
        out += &l;
        out.push('\n');
    }
    out
}

/// Whether entry `dir` holds every object of `names` matching its manifest.
fn entry_is_whole(dir: &Path, names: &[String]) -> bool {
    let Ok(manifest) = std::fs::read_to_string(dir.join(MANIFEST)) else {
        return false;
    };
    let listed: Vec<&str> = manifest.lines().collect();
    listed.len() == names.len()
        && names.iter().zip(&listed).all(|(name, line)| {
            std::fs::read(dir.join(name)).is_ok_and(|b| *line == manifest_line(name, &b))
        })
}

fn manifest_line(name: &str, bytes: &[u8]) -> String {
    format!("{name} {} {:016x}", bytes.len(), fnv1a64(bytes))
}

/// The entry key of the objects `obj`'s makefile would compile with `make_flags`, or `None`
/// when it cannot be read (then nothing is shared).
fn entry_key(
    verilator: &Path,
    obj: &Path,
    tmp: &Path,
    make_flags: &[&str],
) -> Option<(String, Vec<String>)> {
    let classes = std::fs::read_to_string(obj.join("Vtop_classes.mk")).ok()?;
    let objects = global_objects(&classes);
    if objects.is_empty() {
        return None;
    }
    let dry = Command::new(crate::tools::require("make").ok()?)
        .arg("-n")
        .arg("-C")
        .arg(obj)
        .args(["-f", "Vtop.mk"])
        .args(make_flags)
        .args(&objects)
        .output()
        .ok()?;
    let commands = normalised_commands(&String::from_utf8_lossy(&dry.stdout), &[obj, tmp]);
    // One command per object, else the dry run did not say how each is compiled.
    if !dry.status.success() || commands.lines().count() != objects.len() {
        return None;
    }
    let compiler = commands.split_whitespace().next()?.to_string();
    let compiler_version = Command::new(&compiler).arg("--version").output().ok()?;
    let verilator_version = crate::tools::version(verilator).ok()?;
    let mut key = b"tofprobe-verilator-runtime-v1\n".to_vec();
    key.extend_from_slice(&verilator_version);
    key.extend_from_slice(&compiler_version.stdout);
    key.extend_from_slice(commands.as_bytes());
    Some((format!("runtime-{:016x}", fnv1a64(&key)), objects))
}

/// Before make: finds the run-time objects of the build in `obj` (verilated, not built;
/// `tmp` its temporary directory) in the cache `root` and copies them in. `None` when the
/// objects cannot be keyed (make then compiles them, nothing is published).
pub(crate) fn seed(
    root: &Path,
    verilator: &Path,
    obj: &Path,
    tmp: &Path,
    make_flags: &[&str],
) -> Option<Seeded> {
    let (hash, objects) = entry_key(verilator, obj, tmp, make_flags)?;
    let entry = root.join(hash);
    let reused = entry_is_whole(&entry, &objects)
        && objects
            .iter()
            .all(|o| std::fs::copy(entry.join(o), obj.join(o)).is_ok());
    if !reused {
        // A partial copy must not be linked: make compiles what is absent.
        for o in &objects {
            let _ = std::fs::remove_file(obj.join(o));
        }
    }
    Some(Seeded {
        entry,
        objects,
        reused,
    })
}

impl Seeded {
    /// After a successful make that compiled the objects: publishes them as the entry (a
    /// temporary directory renamed into place; if another build published first, its entry
    /// stays and this copy is dropped). Errors are ignored: the build has succeeded.
    pub(crate) fn publish(&self, obj: &Path) {
        if self.reused || entry_is_whole(&self.entry, &self.objects) {
            return;
        }
        let (Some(root), Some(name)) = (self.entry.parent(), self.entry.file_name()) else {
            return;
        };
        let id = next_build_id().to_string();
        let tmp = root.join(pid_tagged(&name.to_string_lossy(), &id));
        let copied = (|| -> std::io::Result<()> {
            std::fs::create_dir_all(&tmp)?;
            let mut manifest = String::new();
            for o in &self.objects {
                let bytes = std::fs::read(obj.join(o))?;
                std::fs::write(tmp.join(o), &bytes)?;
                manifest += &manifest_line(o, &bytes);
                manifest.push('\n');
            }
            std::fs::write(tmp.join(MANIFEST), manifest)?;
            let _ = std::fs::remove_dir_all(&self.entry);
            std::fs::rename(&tmp, &self.entry)
        })();
        if copied.is_err() {
            let _ = std::fs::remove_dir_all(&tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Vtop_classes.mk` as Verilator 5.006 writes it for a traced build.
    const CLASSES: &str = "# Verilated -*- Makefile -*-\n\
        VM_TRACE = 1\n\
        VM_GLOBAL_FAST += \\\n\tverilated \\\n\tverilated_dpi \\\n\tverilated_vcd_c \\\n\tverilated_threads \\\n\n\
        VM_GLOBAL_SLOW += \\\n\n\
        VM_CLASSES_FAST += \\\n\tVtop \\\n";

    #[test]
    fn the_library_objects_are_read_from_the_makefile() {
        assert_eq!(
            global_objects(CLASSES),
            [
                "verilated.o",
                "verilated_dpi.o",
                "verilated_vcd_c.o",
                "verilated_threads.o"
            ]
        );
        assert!(global_objects("VM_CLASSES_FAST += \\\n\tVtop \\\n").is_empty());
    }

    #[test]
    fn the_key_ignores_the_build_directory_but_not_the_flags() {
        let dry = |dir: &str, trace: u8| {
            format!(
                "make: Entering directory '{dir}/obj'\n\
                 g++ -I. -DVM_TRACE={trace} -O1 -I{dir} -c -o verilated.o /usr/share/verilator/include/verilated.cpp\n\
                 make: Leaving directory '{dir}/obj'\n"
            )
        };
        let a = Path::new("/cache/.x.tofprobe-1.0");
        let b = Path::new("/cache/.x.tofprobe-2.7");
        let norm = |text: &str, d: &Path| normalised_commands(text, &[&d.join("obj"), d]);
        let ka = norm(&dry(&a.to_string_lossy(), 1), a);
        assert_eq!(ka, norm(&dry(&b.to_string_lossy(), 1), b));
        assert_eq!(ka.lines().count(), 1, "{ka}");
        assert!(
            !ka.contains("Entering") && ka.contains("-I<dir> -c -o verilated.o"),
            "{ka}"
        );
        assert_ne!(ka, norm(&dry(&a.to_string_lossy(), 0), a));
    }

    /// An entry is used only when every object matches the manifest: a truncated object
    /// (an interrupted copy) or a missing manifest line makes it absent.
    #[test]
    fn a_damaged_entry_is_not_used() {
        let dir = std::env::temp_dir().join(format!("tofprobe-vrt-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let names = vec!["verilated.o".to_string(), "verilated_dpi.o".to_string()];
        let mut manifest = String::new();
        for (n, body) in names.iter().zip([&b"object one"[..], b"two"]) {
            std::fs::write(dir.join(n), body).unwrap();
            manifest += &manifest_line(n, body);
            manifest.push('\n');
        }
        std::fs::write(dir.join(MANIFEST), &manifest).unwrap();
        assert!(entry_is_whole(&dir, &names));
        assert!(
            !entry_is_whole(&dir, &names[..1]),
            "a different object list"
        );
        std::fs::write(dir.join("verilated.o"), b"object o").unwrap();
        assert!(!entry_is_whole(&dir, &names), "truncated object");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
