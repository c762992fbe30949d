//! The one root of tofprobe's caches (syntheses under `synth/`, Verilator builds under
//! `verilator/`, the decompressed PDK under `sky130/`), so `size`, `layout`, `cosim` and the
//! tests agree where a cache is and one variable moves all of it.

use std::ffi::OsString;
use std::path::PathBuf;

/// The cache root: `$TOFPROBE_CACHE`, else `$TOFPROBE_CACHE_DIR` (the name the Verilator
/// cache read first, still honoured), else `$XDG_CACHE_HOME/tofprobe`, else
/// `~/.cache/tofprobe`, else the temporary directory's `tofprobe-cache`. An empty
/// variable counts as unset (an empty path would be the working directory).
pub fn root() -> PathBuf {
    root_from(|k| std::env::var_os(k))
}

/// [`root`] with the environment given (the tests' seam).
pub fn root_from(var: impl Fn(&str) -> Option<OsString>) -> PathBuf {
    let set = |k: &str| var(k).filter(|v| !v.is_empty());
    set("TOFPROBE_CACHE")
        .or_else(|| set("TOFPROBE_CACHE_DIR"))
        .map(PathBuf::from)
        .or_else(|| set("XDG_CACHE_HOME").map(|p| PathBuf::from(p).join("tofprobe")))
        .or_else(|| set("HOME").map(|p| PathBuf::from(p).join(".cache/tofprobe")))
        .unwrap_or_else(|| std::env::temp_dir().join("tofprobe-cache"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<OsString> + 'a {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| OsString::from(v))
        }
    }

    #[test]
    fn the_cache_root_follows_the_variables_in_order() {
        let all = [
            ("TOFPROBE_CACHE", "/a"),
            ("TOFPROBE_CACHE_DIR", "/b"),
            ("XDG_CACHE_HOME", "/x"),
            ("HOME", "/h"),
        ];
        assert_eq!(root_from(env(&all)), PathBuf::from("/a"));
        assert_eq!(root_from(env(&all[1..])), PathBuf::from("/b"));
        assert_eq!(root_from(env(&all[2..])), PathBuf::from("/x/tofprobe"));
        assert_eq!(
            root_from(env(&all[3..])),
            PathBuf::from("/h/.cache/tofprobe")
        );
        // Empty counts as unset: not the working directory.
        assert_eq!(
            root_from(env(&[("TOFPROBE_CACHE", ""), ("HOME", "/h")])),
            PathBuf::from("/h/.cache/tofprobe")
        );
        assert_eq!(
            root_from(env(&[])),
            std::env::temp_dir().join("tofprobe-cache")
        );
    }
}
