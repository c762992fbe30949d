//! The tokens of a Rust source file, as far as the import check needs them: identifiers,
//! string literals (their text, for `#[path = "…"]`), `::` and single punctuation.
//! Comments, character literals, lifetimes and numbers are dropped, so a `crate::x`
//! inside a comment or a string is not an import.

/// One token.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Tok {
    /// An identifier or keyword (a raw identifier without its `r#`).
    Ident(String),
    /// A string literal's text (escapes left as written).
    Str(String),
    /// `::`.
    PathSep,
    /// Any other punctuation character.
    Punct(char),
}

impl Tok {
    /// Whether this is the identifier (or keyword) `s`.
    pub fn is(&self, s: &str) -> bool {
        matches!(self, Tok::Ident(i) if i == s)
    }
    /// Whether this is the punctuation `c`.
    pub fn is_punct(&self, c: char) -> bool {
        *self == Tok::Punct(c)
    }
    /// The identifier's name.
    pub fn ident(&self) -> Option<&str> {
        match self {
            Tok::Ident(i) => Some(i),
            _ => None,
        }
    }
}

fn ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

fn ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The tokens of `text`.
pub fn tokens(text: &str) -> Vec<Tok> {
    let s: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        let next = s.get(i + 1).copied();
        if c.is_whitespace() {
            i += 1;
        } else if c == '/' && next == Some('/') {
            while i < s.len() && s[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            i = block_comment_end(&s, i);
        } else if c == '"' {
            let (text, end) = quoted(&s, i + 1);
            out.push(Tok::Str(text));
            i = end;
        } else if let Some((text, end)) = prefixed_string(&s, i) {
            out.push(Tok::Str(text));
            i = end;
        } else if c == '\'' {
            i = char_or_lifetime_end(&s, i);
        } else if c.is_ascii_digit() {
            while i < s.len() && (ident_char(s[i]) || (s[i] == '.' && digit_at(&s, i + 1))) {
                i += 1;
            }
        } else if ident_start(c) {
            let start = if c == 'r' && next == Some('#') {
                i + 2
            } else {
                i
            };
            let mut end = start;
            while end < s.len() && ident_char(s[end]) {
                end += 1;
            }
            out.push(Tok::Ident(s[start..end].iter().collect()));
            i = end;
        } else if c == ':' && next == Some(':') {
            out.push(Tok::PathSep);
            i += 2;
        } else {
            out.push(Tok::Punct(c));
            i += 1;
        }
    }
    out
}

fn digit_at(s: &[char], i: usize) -> bool {
    s.get(i).is_some_and(|c| c.is_ascii_digit())
}

/// The index after the (nested) block comment opening at `i`.
fn block_comment_end(s: &[char], mut i: usize) -> usize {
    let mut depth = 0usize;
    while i < s.len() {
        if s[i] == '/' && s.get(i + 1) == Some(&'*') {
            depth += 1;
            i += 2;
        } else if s[i] == '*' && s.get(i + 1) == Some(&'/') {
            depth -= 1;
            i += 2;
            if depth == 0 {
                return i;
            }
        } else {
            i += 1;
        }
    }
    i
}

/// The text of a `"…"` string whose body starts at `i`, and the index after its quote.
fn quoted(s: &[char], mut i: usize) -> (String, usize) {
    let start = i;
    while i < s.len() && s[i] != '"' {
        i += if s[i] == '\\' { 2 } else { 1 };
    }
    let end = i.min(s.len());
    (s[start..end].iter().collect(), end + 1)
}

/// A byte, C or raw string opening at `i` (`b"`, `c"`, `r"`, `r#"`, `br#"`, …).
fn prefixed_string(s: &[char], i: usize) -> Option<(String, usize)> {
    if i > 0 && ident_char(s[i - 1]) {
        return None;
    }
    let mut j = i;
    if matches!(s[j], 'b' | 'c') {
        j += 1;
    }
    let raw = s.get(j) == Some(&'r');
    if raw {
        j += 1;
    }
    if j == i {
        return None;
    }
    if !raw {
        return (s.get(j) == Some(&'"')).then(|| quoted(s, j + 1));
    }
    let hashes = s[j..].iter().take_while(|c| **c == '#').count();
    if s.get(j + hashes) != Some(&'"') {
        return None;
    }
    let body = j + hashes + 1;
    let mut k = body;
    while k < s.len() {
        if s[k] == '"'
            && s[k + 1..]
                .iter()
                .take(hashes)
                .filter(|c| **c == '#')
                .count()
                == hashes
        {
            return Some((s[body..k].iter().collect(), k + 1 + hashes));
        }
        k += 1;
    }
    Some((s[body..].iter().collect(), s.len()))
}

/// The index after a character literal (`'a'`, `'\n'`, `'\u{1F}'`) or a lifetime (`'a`)
/// opening at `i`.
fn char_or_lifetime_end(s: &[char], i: usize) -> usize {
    if s.get(i + 1) == Some(&'\\') {
        let mut k = i + 2;
        while k < s.len() && s[k] != '\'' {
            k += 1;
        }
        return k + 1;
    }
    if s.get(i + 2) == Some(&'\'') {
        return i + 3;
    }
    let mut k = i + 1;
    while k < s.len() && ident_char(s[k]) {
        k += 1;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_strings_and_lifetimes_hold_no_tokens_of_code() {
        let t = tokens(
            "// crate::a\n/* crate::b /* nested */ */ fn f<'a>(x: &'a str) -> char { let _ = \"crate::c\"; let _ = r#\"crate::d\"#; let _ = b'x'; '{' }",
        );
        assert!(!t.iter().any(|t| t.is("crate")), "{t:?}");
        assert!(t.contains(&Tok::Str("crate::c".into())));
        assert!(t.contains(&Tok::Str("crate::d".into())));
        assert_eq!(t.iter().filter(|t| t.is_punct('{')).count(), 1, "{t:?}");
        assert_eq!(
            tokens("super::x::y")[..3],
            [
                Tok::Ident("super".into()),
                Tok::PathSep,
                Tok::Ident("x".into())
            ]
        );
    }
}
