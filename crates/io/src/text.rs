//! User text on its way into a generated file (a header's regeneration command, a report's
//! configuration name): reduced to a safe, canonical single line, so no newline, control
//! character, comment terminator or backtick can end the comment it sits in, and two
//! spellings of one path (`X`, `./X/`, `X//`) give the same bytes.

use std::path::{Component, Path};

/// Longest sanitised text kept (longer text ends in `...`).
pub const MAX_TEXT: usize = 200;

/// Keeps ASCII letters, digits and `. _ - / + = , : @` and spaces; every other character
/// (newlines, control characters, `*`, `$`, quotes, backticks, non-ASCII) becomes `_`.
/// At most [`MAX_TEXT`] characters.
pub fn sanitize(text: &str) -> String {
    let mut out: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || " ._-/+=,:@".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.len() > MAX_TEXT {
        out.truncate(MAX_TEXT - 3);
        out.push_str("...");
    }
    out
}

/// A path as it goes into a generated file: lexically normalised (no `.` components, no
/// repeated or trailing separators; `..` kept: resolving it would need the file system)
/// and [`sanitize`]d. `./X/` and `X` give `X`; an empty path gives `.`.
pub fn canonical_path(path: &Path) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut absolute = false;
    for c in path.components() {
        match c {
            Component::RootDir => absolute = true,
            Component::Prefix(p) => parts.push(p.as_os_str().to_string_lossy().into_owned()),
            Component::CurDir => {}
            Component::ParentDir => parts.push("..".into()),
            Component::Normal(n) => parts.push(n.to_string_lossy().into_owned()),
        }
    }
    let joined = parts.join("/");
    let text = match (absolute, joined.is_empty()) {
        (true, _) => format!("/{joined}"),
        (false, true) => ".".to_string(),
        (false, false) => joined,
    };
    sanitize(&text)
}

/// A path as the user would type it from the working directory `cwd`, for a header's
/// regeneration command: an absolute path is made relative to `cwd` (lexically: `/w/d`
/// from `/w` is `d`, `/tmp/d` from `/w/x` is `../../tmp/d`), so `--out d` and `--out
/// /w/d` give the same bytes and no machine's absolute path reaches a generated file; a
/// relative path is kept relative; then [`canonical_path`].
pub fn path_from(cwd: &Path, path: &Path) -> String {
    if !path.is_absolute() || !cwd.is_absolute() {
        return canonical_path(path);
    }
    let parts = |p: &Path| -> Vec<String> {
        let mut v: Vec<String> = Vec::new();
        for c in p.components() {
            match c {
                Component::Normal(n) => v.push(n.to_string_lossy().into_owned()),
                Component::ParentDir => {
                    v.pop();
                }
                _ => {}
            }
        }
        v
    };
    let (a, b) = (parts(cwd), parts(path));
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut rel: Vec<String> = vec!["..".to_string(); a.len() - common];
    rel.extend(b[common..].iter().cloned());
    canonical_path(Path::new(&rel.join("/")))
}

/// [`path_from`] the process's working directory (an absolute path when there is none
/// is replaced by its file name alone: still never the machine's path).
pub fn path_as_typed(path: &Path) -> String {
    match std::env::current_dir() {
        Ok(cwd) => path_from(&cwd, path),
        Err(_) if path.is_absolute() => {
            canonical_path(Path::new(path.file_name().unwrap_or_default()))
        }
        Err(_) => canonical_path(path),
    }
}

/// `text` cut to at most `max` characters (with `...` when cut): what an error message
/// echoes of a value, so a megabyte string does not become a megabyte message.
pub fn clip(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        return text.to_string();
    }
    let kept: String = text.chars().take(max.saturating_sub(3)).collect();
    format!("{kept}...")
}

/// A number as an error message shows it: plain when readable, scientific when tiny or huge
/// (`1e-300`, not 300 zeros), and `NaN`/`inf` as Rust writes them.
pub fn number(x: f64) -> String {
    let a = x.abs();
    if x.is_finite() && a != 0.0 && !(1e-4..1e9).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_can_end_a_comment_or_a_line() {
        let evil = "x\nmodule m; initial $display(\"hi\"); endmodule\r\n*/`\u{2028}\u{0}é";
        let s = sanitize(evil);
        assert!(!s.contains(['\n', '\r', '*', '$', '"', '`', '\u{2028}', '\0']));
        assert!(s.is_ascii());
        assert_eq!(sanitize("rtl/a-b_c.v"), "rtl/a-b_c.v");
        assert_eq!(sanitize(&"a".repeat(1000)).len(), MAX_TEXT);
    }

    #[test]
    fn spellings_of_one_path_agree() {
        for s in ["X", "./X/", "X//", "./X/."] {
            assert_eq!(canonical_path(Path::new(s)), "X", "{s}");
        }
        assert_eq!(canonical_path(Path::new("./")), ".");
        assert_eq!(canonical_path(Path::new("/tmp//a/./b/")), "/tmp/a/b");
        assert_eq!(canonical_path(Path::new("a/../b")), "a/../b");
        assert_eq!(canonical_path(Path::new("x\ny")), "x_y");
    }

    #[test]
    fn absolute_paths_become_what_the_user_would_type() {
        let w = Path::new("/w/x");
        assert_eq!(path_from(w, Path::new("/w/x/d")), "d");
        assert_eq!(path_from(w, Path::new("/w/x/d/")), "d");
        assert_eq!(path_from(w, Path::new("d")), "d");
        assert_eq!(path_from(w, Path::new("/tmp/d")), "../../tmp/d");
        assert_eq!(path_from(w, Path::new("/w/x")), ".");
    }

    #[test]
    fn clip_keeps_short_text_and_cuts_long_text() {
        assert_eq!(clip("abc", 10), "abc");
        assert_eq!(clip(&"a".repeat(1_000_000), 10), "aaaaaaa...");
    }
}
