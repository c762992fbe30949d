//! What one source file says about modules: the modules it declares (`mod x;`, with a
//! `#[path]`, and inline `mod x { … }`), its `use` declarations (each path of a use tree
//! apart), the paths its code names (`crate::…`, `super::…`, `self::…`, `child::…`) and
//! the items it defines, each with the module it is written in.

use super::lex::Tok;

/// A module's path from the crate root (`[]` is the root).
pub type ModPath = Vec<String>;

/// One path of a `use` tree.
#[derive(Debug, Clone)]
pub struct Use {
    /// The module the declaration is written in.
    pub module: ModPath,
    /// The path as written (`self` of a group folded into its parent).
    pub segs: Vec<String>,
    /// `…::*`.
    pub glob: bool,
    /// The name it brings into scope (`None` for `as _` and globs).
    pub alias: Option<String>,
    /// `pub use` (any visibility): a re-export, not a use of the file's own.
    pub public: bool,
}

/// What [`scan`] finds in a file.
#[derive(Debug, Default)]
pub struct FileScan {
    /// `mod x;` declarations: the child's module path, its `#[path]`, if any, and
    /// whether it is compiled for tests only (`#[cfg(test)]`).
    pub child_files: Vec<(ModPath, Option<String>, bool)>,
    /// Inline modules (`mod x { … }`).
    pub inline_mods: Vec<ModPath>,
    pub uses: Vec<Use>,
    /// Paths named in code: (module written in, segments).
    pub paths: Vec<(ModPath, Vec<String>)>,
    /// Items defined: (module, name).
    pub defs: Vec<(ModPath, String)>,
}

const DEF_KEYWORDS: [&str; 8] = [
    "fn", "struct", "enum", "const", "static", "type", "trait", "union",
];

/// Scans the tokens of the file of module `module`.
pub fn scan(t: &[Tok], module: &[String]) -> FileScan {
    let mut out = FileScan::default();
    // (module, the brace depth inside its body, compiled for tests only)
    let mut stack: Vec<(ModPath, usize, bool)> = vec![(module.to_vec(), 0, false)];
    let mut depth = 0usize;
    let mut path_attr: Option<String> = None;
    let mut cfg_test = false;
    let mut i = 0;
    while i < t.len() {
        let (here, _, in_test) = stack.last().expect("the file's module").clone();
        let skip = in_test || cfg_test;
        match &t[i] {
            Tok::Punct('{') => depth += 1,
            Tok::Punct('}') => {
                if stack.len() > 1 && stack.last().is_some_and(|s| s.1 == depth) {
                    stack.pop();
                }
                depth = depth.saturating_sub(1);
            }
            Tok::Punct('#') if attr_path(&t[i..]).is_some() => path_attr = attr_path(&t[i..]),
            Tok::Punct('#') if is_cfg_test(&t[i..]) => {
                cfg_test = true;
                i += 6;
                continue;
            }
            Tok::Punct(';') => cfg_test = false,
            Tok::Ident(k) if k == "mod" => {
                if let Some(name) = t.get(i + 1).and_then(Tok::ident) {
                    let mut child = here.clone();
                    child.push(name.to_string());
                    if t.get(i + 2).is_some_and(|x| x.is_punct('{')) {
                        out.inline_mods.push(child.clone());
                        depth += 1;
                        stack.push((child, depth, skip));
                        cfg_test = false;
                        i += 3;
                        continue;
                    }
                    out.child_files.push((child, path_attr.take(), skip));
                    cfg_test = false;
                }
            }
            Tok::Ident(k) if k == "use" => {
                let public = public_before(t, i);
                let mut pos = i + 1;
                let mut found = Vec::new();
                use_tree(t, &mut pos, Vec::new(), &mut found);
                cfg_test = false;
                for (segs, glob, alias) in found.into_iter().filter(|_| !skip) {
                    out.uses.push(Use {
                        module: here.clone(),
                        segs,
                        glob,
                        alias,
                        public,
                    });
                }
                i = pos;
                continue;
            }
            Tok::Ident(k) if DEF_KEYWORDS.contains(&k.as_str()) || k == "macro_rules" => {
                let mut j = i + 1;
                while t.get(j).is_some_and(|x| x.is("fn") || x.is_punct('!')) {
                    j += 1;
                }
                if let Some(name) = t.get(j).and_then(Tok::ident) {
                    out.defs.push((here.clone(), name.to_string()));
                }
            }
            Tok::Ident(first)
                if t.get(i + 1) == Some(&Tok::PathSep) && (i == 0 || t[i - 1] != Tok::PathSep) =>
            {
                let mut segs = vec![first.clone()];
                let mut j = i + 1;
                while t.get(j) == Some(&Tok::PathSep) {
                    match t.get(j + 1).and_then(Tok::ident) {
                        Some(s) => segs.push(s.to_string()),
                        None => break,
                    }
                    j += 2;
                }
                if !skip {
                    out.paths.push((here, segs));
                }
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// The string of a `#[path = "…"]` attribute starting at `t[0]`.
fn attr_path(t: &[Tok]) -> Option<String> {
    match t {
        [
            Tok::Punct('#'),
            Tok::Punct('['),
            p,
            Tok::Punct('='),
            Tok::Str(s),
            ..,
        ] if p.is("path") => Some(s.clone()),
        _ => None,
    }
}

/// Whether `t` opens with `#[cfg(test)]`.
fn is_cfg_test(t: &[Tok]) -> bool {
    matches!(
        t,
        [Tok::Punct('#'), Tok::Punct('['), c, Tok::Punct('('), x, Tok::Punct(')'), ..]
            if c.is("cfg") && x.is("test")
    )
}

/// Whether the `use` at `t[i]` carries a visibility (`pub`, `pub(crate)`, `pub(super)`, …).
fn public_before(t: &[Tok], i: usize) -> bool {
    if i >= 1 && t[i - 1].is("pub") {
        return true;
    }
    // `pub ( crate )` / `pub ( in a :: b )`: a `pub` before the closing parenthesis.
    if i >= 1 && t[i - 1].is_punct(')') {
        let open = t[..i].iter().rposition(|x| x.is_punct('('));
        return open.is_some_and(|o| o >= 1 && t[o - 1].is("pub"));
    }
    false
}

/// Parses the use tree at `t[*pos]` under `prefix` into (segments, glob, alias), leaving
/// `*pos` after its end (`;`, `,` or `}` of the enclosing group).
fn use_tree(
    t: &[Tok],
    pos: &mut usize,
    mut prefix: Vec<String>,
    found: &mut Vec<(Vec<String>, bool, Option<String>)>,
) {
    if t.get(*pos) == Some(&Tok::PathSep) {
        *pos += 1;
    }
    loop {
        match t.get(*pos) {
            Some(Tok::Punct('*')) => {
                *pos += 1;
                found.push((prefix, true, None));
                break;
            }
            Some(Tok::Punct('{')) => {
                *pos += 1;
                while t.get(*pos).is_some_and(|x| !x.is_punct('}')) {
                    use_tree(t, pos, prefix.clone(), found);
                    if t.get(*pos).is_some_and(|x| x.is_punct(',')) {
                        *pos += 1;
                    }
                }
                *pos += 1;
                break;
            }
            Some(Tok::Ident(s)) => {
                *pos += 1;
                if s != "self" || prefix.is_empty() {
                    prefix.push(s.clone());
                }
                if t.get(*pos) == Some(&Tok::PathSep) {
                    *pos += 1;
                    continue;
                }
                let mut alias = prefix.last().cloned();
                if t.get(*pos).is_some_and(|x| x.is("as")) {
                    alias = t
                        .get(*pos + 1)
                        .and_then(Tok::ident)
                        .filter(|a| *a != "_")
                        .map(str::to_string);
                    *pos += 2;
                }
                found.push((prefix, false, alias));
                break;
            }
            _ => break,
        }
    }
    if t.get(*pos).is_some_and(|x| x.is_punct(';')) {
        *pos += 1;
    }
}
