//! Import circles between the files of a crate (issue 43): file A imports file B when A's
//! code names an item that B defines — through `use crate::…`, `super::…`, `self::…` or a
//! child module's path, written in a `use` or inline —, re-exports followed to the file
//! that defines the item. A `mod` declaration or a `pub use` re-export is not an import
//! of the declaring file (a parent that only hands its children's names on does not depend
//! on them). [`circles`] returns every strongly connected component of more than one file,
//! naming its files and what ties them; the workspace test below keeps the count at zero.

mod lex;
mod scan;

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt;
use std::path::Path;

use scan::{FileScan, ModPath, Use};

/// Files (paths relative to the crate's `src`, with `/`) and their text.
pub type Sources = BTreeMap<String, String>;

/// File → file imports with the names taken.
pub type Graph = BTreeMap<(String, String), BTreeSet<String>>;

/// One circle: its files and every import between them (from, to, names).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Circle {
    pub files: Vec<String>,
    pub ties: Vec<(String, String, Vec<String>)>,
}

impl fmt::Display for Circle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} files: {}", self.files.len(), self.files.join(", "))?;
        for (from, to, names) in &self.ties {
            writeln!(f, "  {from} -> {to}: {}", names.join(", "))?;
        }
        Ok(())
    }
}

/// Every `.rs` file under `src`, by its path relative to `src`.
pub fn read_sources(src: &Path) -> std::io::Result<Sources> {
    let mut out = Sources::new();
    let mut dirs = vec![src.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir)? {
            let path = entry?.path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(src).expect("under src");
                let rel = rel.to_string_lossy().replace('\\', "/");
                out.insert(rel, std::fs::read_to_string(&path)?);
            }
        }
    }
    Ok(out)
}

/// The module path a file has by its place (`lib.rs` → root, `a/mod.rs` and `a.rs` → `a`).
fn default_module(file: &str) -> ModPath {
    let stem = file.strip_suffix(".rs").unwrap_or(file);
    let mut parts: Vec<String> = stem.split('/').map(str::to_string).collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// What the resolution knows of a crate.
struct Crate {
    /// Module → the file it is written in (inline modules: their file).
    modules: HashMap<ModPath, String>,
    defs: HashMap<ModPath, HashSet<String>>,
    uses: HashMap<ModPath, Vec<Use>>,
}

/// A path's meaning: a module, or an item of a file.
enum Target {
    Module,
    Item(String, String),
}

impl Crate {
    /// `segs` written in module `from`, made absolute; `None` for another crate's path.
    fn absolute(&self, from: &[String], segs: &[String]) -> Option<ModPath> {
        let first = segs.first()?.as_str();
        match first {
            "crate" => Some(segs[1..].to_vec()),
            "super" | "self" => {
                let ups = segs.iter().take_while(|s| *s == "super").count();
                let mut base = from[..from.len().checked_sub(ups)?].to_vec();
                let skip = if first == "self" { 1 } else { ups };
                base.extend_from_slice(&segs[skip..]);
                Some(base)
            }
            _ => {
                let mut child = from.to_vec();
                child.push(first.to_string());
                if self.modules.contains_key(&child) {
                    child.extend_from_slice(&segs[1..]);
                    return Some(child);
                }
                // A name a `use` of this module brought in (a module alias).
                let u = self.uses.get(from)?.iter().find(|u| {
                    !u.glob && u.alias.as_deref() == Some(first) && u.segs.first() != Some(&segs[0])
                })?;
                let mut base = self.absolute(&u.module, &u.segs)?;
                base.extend_from_slice(&segs[1..]);
                Some(base)
            }
        }
    }

    /// What the absolute path `abs` names; `strict`: `None` rather than the module's file
    /// when the item is not found there.
    fn target(&self, abs: &[String], strict: bool, hops: usize) -> Option<Target> {
        let k = (0..=abs.len())
            .rev()
            .find(|k| self.modules.contains_key(&abs[..*k]))?;
        if k == abs.len() {
            return Some(Target::Module);
        }
        let (module, name) = (&abs[..k], &abs[k]);
        let file = &self.modules[module];
        if self.defs.get(module).is_some_and(|d| d.contains(name)) || hops > 16 {
            return Some(Target::Item(file.clone(), name.clone()));
        }
        let uses = self.uses.get(module).map(Vec::as_slice).unwrap_or(&[]);
        if let Some(u) = uses
            .iter()
            .find(|u| !u.glob && u.alias.as_ref() == Some(name))
        {
            // A re-export (or an import the children see): followed, or another crate's.
            let mut p = self.absolute(&u.module, &u.segs)?;
            p.extend_from_slice(&abs[k + 1..]);
            return self.target(&p, strict, hops + 1);
        }
        for u in uses.iter().filter(|u| u.glob) {
            let Some(mut p) = self.absolute(&u.module, &u.segs) else {
                continue;
            };
            p.extend_from_slice(&abs[k..]);
            if let Some(t @ Target::Item(..)) = self.target(&p, true, hops + 1) {
                return Some(t);
            }
        }
        (!strict).then(|| Target::Item(file.clone(), name.clone()))
    }
}

/// Every file → file import of a crate's sources (see the module documentation).
pub fn import_graph(files: &Sources) -> Graph {
    let mut module_of: HashMap<String, ModPath> = files
        .keys()
        .map(|f| (f.clone(), default_module(f)))
        .collect();
    let mut tests_only: HashSet<ModPath> = HashSet::new();
    // `#[path = "x.rs"] mod m;`: x.rs (beside the declaring file) is module m.
    for (file, text) in files {
        let s = scan::scan(&lex::tokens(text), &module_of[file]);
        let dir = file.rsplit_once('/').map_or("", |(d, _)| d);
        for (child, attr, test) in s.child_files {
            if test {
                tests_only.insert(child.clone());
            }
            if let Some(a) = attr {
                let target = if dir.is_empty() {
                    a
                } else {
                    format!("{dir}/{a}")
                };
                module_of.insert(target, child);
            }
        }
    }
    let scans: BTreeMap<&String, FileScan> = files
        .iter()
        .map(|(f, text)| (f, scan::scan(&lex::tokens(text), &module_of[f])))
        .collect();
    let mut krate = Crate {
        modules: module_of
            .iter()
            .map(|(f, m)| (m.clone(), f.clone()))
            .collect(),
        defs: HashMap::new(),
        uses: HashMap::new(),
    };
    for (file, s) in &scans {
        for m in &s.inline_mods {
            krate.modules.insert(m.clone(), (*file).clone());
        }
        for (m, name) in &s.defs {
            krate
                .defs
                .entry(m.clone())
                .or_default()
                .insert(name.clone());
        }
        for u in &s.uses {
            krate
                .uses
                .entry(u.module.clone())
                .or_default()
                .push(u.clone());
        }
    }
    let mut graph = Graph::new();
    let module_of = &module_of;
    for (file, s) in &scans {
        let here = &module_of[*file];
        if (1..=here.len()).any(|k| tests_only.contains(&here[..k])) {
            continue;
        }
        // A module's file using its own descendants (a face composing its folder) is no
        // import of a sibling: only the descendants' uses of it count.
        let mut add = |to: String, name: String| {
            if to != **file && !module_of[&to].starts_with(here) {
                graph.entry(((*file).clone(), to)).or_default().insert(name);
            }
        };
        for u in s.uses.iter().filter(|u| !u.public) {
            let Some(abs) = krate.absolute(&u.module, &u.segs) else {
                continue;
            };
            match krate.target(&abs, false, 0) {
                Some(Target::Item(to, name)) => add(to, name),
                Some(Target::Module) if u.glob => add(krate.modules[&abs].clone(), "*".into()),
                _ => {}
            }
        }
        for (module, segs) in &s.paths {
            let abs = krate.absolute(module, segs);
            if let Some(Target::Item(to, name)) = abs.and_then(|a| krate.target(&a, false, 0)) {
                add(to, name);
            }
        }
    }
    graph
}

/// The circles of a crate's sources: every strongly connected component of its
/// [`import_graph`] with more than one file, largest first.
pub fn circles(files: &Sources) -> Vec<Circle> {
    let graph = import_graph(files);
    let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (from, to) in graph.keys() {
        next.entry(from).or_default().push(to);
    }
    let mut out: Vec<Circle> = components(files.keys().map(String::as_str), &next)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|files| {
            let ties = graph
                .iter()
                .filter(|((a, b), _)| files.contains(&a.as_str()) && files.contains(&b.as_str()))
                .map(|((a, b), names)| (a.clone(), b.clone(), names.iter().cloned().collect()))
                .collect();
            Circle {
                files: files.iter().map(|f| f.to_string()).collect(),
                ties,
            }
        })
        .collect();
    out.sort_by(|a, b| {
        b.files
            .len()
            .cmp(&a.files.len())
            .then(a.files.cmp(&b.files))
    });
    out
}

/// Tarjan's strongly connected components of the graph `next` over `nodes`, each sorted.
fn components<'a>(
    nodes: impl Iterator<Item = &'a str>,
    next: &BTreeMap<&'a str, Vec<&'a str>>,
) -> Vec<Vec<&'a str>> {
    struct State<'a> {
        index: HashMap<&'a str, usize>,
        low: HashMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: HashSet<&'a str>,
        out: Vec<Vec<&'a str>>,
    }
    fn visit<'a>(v: &'a str, next: &BTreeMap<&'a str, Vec<&'a str>>, s: &mut State<'a>) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on_stack.insert(v);
        for &w in next.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(w, next, s);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut c = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                c.push(w);
                if w == v {
                    break;
                }
            }
            c.sort_unstable();
            s.out.push(c);
        }
    }
    let mut s = State {
        index: HashMap::new(),
        low: HashMap::new(),
        stack: Vec::new(),
        on_stack: HashSet::new(),
        out: Vec::new(),
    };
    for v in nodes {
        if !s.index.contains_key(v) {
            visit(v, next, &mut s);
        }
    }
    s.out
}

#[cfg(test)]
mod tests;
