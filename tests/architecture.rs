//! The layering `ARCHITECTURE.md` states, checked against the sources: this test reads every file
//! of `radiosity-core/src` and the paths its code names (`crate::…`, `super::…`; comments, string
//! literals and test modules left out), and enforces two rules.
//!
//! - **Rule "imports point down"**: a top-level module of `radiosity-core` uses only modules of its
//!   own layer or of a layer below it, as the `layers` block of `ARCHITECTURE.md` lists them.
//! - **Rule "no circle across folders"**: within the crate root and within every folder, the
//!   modules (files and subfolders) that use each other form no circle through a folder, and the
//!   top-level modules none at all.
//!
//! Uses that break a rule today are listed in the `exceptions` block of `ARCHITECTURE.md`, each
//! with its reason. A use that breaks a rule and is not listed fails; so does a listed exception
//! that no longer occurs (the list only shrinks).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A source file: its module path (`["solve", "leaf"]` for `solve/leaf.rs` or
/// `solve/leaf/mod.rs`), whether it is a folder's `mod.rs`, and its code.
struct Source {
    module: Vec<String>,
    code: String,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("radiosity-core/src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).expect("source folder").map(|e| e.expect("entry").path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The code of a file without comments, string and character literals, and without what follows
/// its first `#[cfg(test)]` (test modules sit at the end of a file by this crate's habit).
fn code_only(text: &str) -> String {
    let text = match text.find("#[cfg(test)]") {
        Some(i) => &text[..i],
        None => text,
    };
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let mut depth = 0;
                while i < b.len() {
                    if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                        depth += 1;
                        i += 2;
                    } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                        depth -= 1;
                        i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
            }
            b'r' if b.get(i + 1) == Some(&b'#') || (b.get(i + 1) == Some(&b'"') && (i == 0 || !is_ident(b[i - 1]))) => {
                // A raw string r"…" or r#"…"#.
                let mut j = i + 1;
                let mut hashes = 0;
                while b.get(j) == Some(&b'#') {
                    hashes += 1;
                    j += 1;
                }
                if b.get(j) != Some(&b'"') {
                    out.push('r');
                    i += 1;
                    continue;
                }
                j += 1;
                let close: Vec<u8> = std::iter::once(b'"').chain(std::iter::repeat_n(b'#', hashes)).collect();
                while j < b.len() && !b[j..].starts_with(&close) {
                    j += 1;
                }
                i = j + close.len();
                out.push_str("\"\"");
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
                out.push_str("\"\"");
            }
            b'\'' if b.get(i + 2) == Some(&b'\'') || (b.get(i + 1) == Some(&b'\\')) => {
                // A character literal ('x', '\n', '\u{..}'); lifetimes ('a) have no closing quote.
                let mut j = i + 1;
                while j < b.len() && b[j] != b'\'' {
                    j += if b[j] == b'\\' { 2 } else { 1 };
                }
                i = j + 1;
                out.push_str("' '");
            }
            c => {
                out.push(c as char);
                i += 1;
            }
        }
    }
    out
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

fn sources() -> Vec<Source> {
    let root = root();
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    files
        .into_iter()
        .filter_map(|p| {
            let rel = p.strip_prefix(&root).expect("under the root");
            let mut module: Vec<String> = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
            let file = module.pop().expect("a file name");
            if file == "tests.rs" || module.iter().any(|m| m == "tests") {
                return None;
            }
            let stem = file.trim_end_matches(".rs");
            if stem != "mod" && stem != "lib" {
                module.push(stem.to_string());
            }
            let text = std::fs::read_to_string(&p).expect("readable source");
            Some(Source { module, code: code_only(&text) })
        })
        .collect()
}

/// The module paths the code of `s` names, absolute: `crate::a::b`, `super::x` (resolved from
/// the file's module), and the first level of `crate::{a, b::c}` groups.
fn named_paths(s: &Source) -> Vec<Vec<String>> {
    let b = s.code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = |kw: &str| b[i..].starts_with(kw.as_bytes()) && (i == 0 || !is_ident(b[i - 1]));
        let (mut base, mut j) = if starts("crate::") {
            (Vec::new(), i + "crate::".len())
        } else if starts("super::") {
            let mut base = s.module.clone();
            let mut j = i;
            while b[j..].starts_with(b"super::") {
                base.pop();
                j += "super::".len();
            }
            (base, j)
        } else {
            i += 1;
            continue;
        };
        // Path segments, then possibly a `{…}` group.
        loop {
            if b.get(j) == Some(&b'{') {
                let mut depth = 0;
                let mut k = j;
                let mut item_start = j + 1;
                while k < b.len() {
                    match b[k] {
                        b'{' => depth += 1,
                        b'}' | b',' if depth == 1 => {
                            let item: String =
                                s.code[item_start..k].trim().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                            if !item.is_empty() && item != "self" {
                                let mut p = base.clone();
                                p.push(item);
                                out.push(p);
                            }
                            item_start = k + 1;
                            if b[k] == b'}' {
                                break;
                            }
                        }
                        b'}' => depth -= 1,
                        _ => {}
                    }
                    k += 1;
                }
                i = k;
                break;
            }
            let seg: String = s.code[j..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if seg.is_empty() {
                i = j;
                break;
            }
            j += seg.len();
            base.push(seg);
            if b[j..].starts_with(b"::") {
                j += 2;
            } else {
                out.push(base.clone());
                i = j;
                break;
            }
        }
    }
    out
}

/// A block of `ARCHITECTURE.md` fenced as ```` ```name ````.
fn block(doc: &str, name: &str) -> Vec<String> {
    let open = format!("```{name}\n");
    let start = doc.find(&open).unwrap_or_else(|| panic!("ARCHITECTURE.md has no ```{name} block")) + open.len();
    let end = start + doc[start..].find("```").expect("the block is closed");
    doc[start..end].lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).map(String::from).collect()
}

/// Every edge between sibling modules of a folder: `(folder, from, to)`, with the file that makes it.
fn edges(sources: &[Source], dirs: &BTreeSet<Vec<String>>) -> BTreeMap<(Vec<String>, String, String), String> {
    let mut out = BTreeMap::new();
    for s in sources {
        for p in named_paths(s) {
            // The deepest folder both lie in.
            let common = s.module.iter().zip(&p).take_while(|(a, b)| a == b).count();
            if common >= s.module.len() || common >= p.len() {
                continue;
            }
            let folder = s.module[..common].to_vec();
            if !dirs.contains(&folder) {
                continue;
            }
            let (from, to) = (s.module[common].clone(), p[common].clone());
            // Only modules: a path to an item of the folder's own mod.rs is no sibling.
            let mut target = folder.clone();
            target.push(to.clone());
            if !sources.iter().any(|t| t.module == target) {
                continue;
            }
            out.entry((folder, from, to)).or_insert_with(|| s.module.join("/"));
        }
    }
    out
}

/// The circles of a graph: its strongly connected components of more than one node (Tarjan).
fn circles(nodes: &BTreeSet<String>, adj: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        adj: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        out: Vec<Vec<String>>,
    }
    fn visit(t: &mut T<'_>, v: &str) {
        let i = t.index.len();
        t.index.insert(v.to_string(), i);
        t.low.insert(v.to_string(), i);
        t.stack.push(v.to_string());
        t.on.insert(v.to_string());
        for w in t.adj.get(v).cloned().unwrap_or_default() {
            if !t.index.contains_key(&w) {
                visit(t, &w);
                let l = t.low[&w].min(t.low[v]);
                t.low.insert(v.to_string(), l);
            } else if t.on.contains(&w) {
                let l = t.index[&w].min(t.low[v]);
                t.low.insert(v.to_string(), l);
            }
        }
        if t.low[v] == t.index[v] {
            let mut c = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(&w);
                let done = w == v;
                c.push(w);
                if done {
                    break;
                }
            }
            if c.len() > 1 {
                c.sort();
                t.out.push(c);
            }
        }
    }
    let mut t = T { adj, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), on: BTreeSet::new(), out: Vec::new() };
    for n in nodes {
        if !t.index.contains_key(n) {
            visit(&mut t, n);
        }
    }
    t.out
}

#[test]
fn layers_only_point_down_and_no_circle_crosses_folders() {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let mut layer: BTreeMap<String, usize> = BTreeMap::new();
    for (i, line) in block(&doc, "layers").iter().enumerate() {
        let names = line.split_once(':').map_or(line.as_str(), |(_, n)| n);
        for m in names.split_whitespace() {
            layer.insert(m.trim_matches(',').to_string(), i);
        }
    }
    // Exceptions: `folder: from -> to  (reason)`, the folder `crate` for the top level.
    let mut allowed: BTreeSet<(String, String, String)> = BTreeSet::new();
    for line in block(&doc, "exceptions") {
        let (folder, rest) = line.split_once(':').expect("`folder: from -> to` in the exceptions block");
        let (from, rest) = rest.split_once("->").expect("`from -> to` in the exceptions block");
        let to = rest.split_whitespace().next().expect("a target module");
        allowed.insert((folder.trim().to_string(), from.trim().to_string(), to.to_string()));
    }
    let sources = sources();
    let mut dirs: BTreeSet<Vec<String>> = BTreeSet::new();
    for s in &sources {
        for k in 0..s.module.len() {
            dirs.insert(s.module[..k].to_vec());
        }
    }
    // Every top-level module has a layer, and every layer's module exists.
    let top: BTreeSet<String> = sources.iter().filter(|s| s.module.len() == 1).map(|s| s.module[0].clone()).collect();
    let unlayered: Vec<&String> = top.iter().filter(|m| !layer.contains_key(*m)).collect();
    assert!(unlayered.is_empty(), "top-level modules without a layer in ARCHITECTURE.md: {unlayered:?}");
    let unknown: Vec<&String> = layer.keys().filter(|m| !top.contains(*m)).collect();
    assert!(unknown.is_empty(), "ARCHITECTURE.md's layers name modules that do not exist: {unknown:?}");

    let edges = edges(&sources, &dirs);
    let folder_name = |f: &[String]| if f.is_empty() { "crate".to_string() } else { f.join("/") };
    let mut used_exceptions = BTreeSet::new();
    let mut failures = Vec::new();
    let mut kept: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for ((folder, from, to), file) in &edges {
        let key = (folder_name(folder), from.clone(), to.clone());
        if allowed.contains(&key) {
            used_exceptions.insert(key);
            continue;
        }
        if folder.is_empty() && layer[to] > layer[from] {
            failures.push(format!(
                "imports point down: `{from}` (layer {}) uses `{to}` (layer {}), in module `{file}`",
                layer[from], layer[to]
            ));
        }
        kept.entry(folder.clone()).or_default().entry(from.clone()).or_default().insert(to.clone());
    }
    for (folder, adj) in &kept {
        let nodes: BTreeSet<String> = adj.iter().flat_map(|(a, bs)| std::iter::once(a.clone()).chain(bs.iter().cloned())).collect();
        for c in circles(&nodes, adj) {
            let through_folder = c.iter().any(|m| {
                let mut p = folder.clone();
                p.push(m.clone());
                dirs.contains(&p)
            });
            if folder.is_empty() || through_folder {
                failures.push(format!("no circle across folders: in `{}`, {} use each other", folder_name(folder), c.join(", ")));
            }
        }
    }
    for e in allowed.difference(&used_exceptions) {
        failures.push(format!(
            "ARCHITECTURE.md lists `{}: {} -> {}` as an exception, but no code makes that use any more: remove it",
            e.0, e.1, e.2
        ));
    }
    assert!(failures.is_empty(), "{} broken rule(s) (see ARCHITECTURE.md):\n{}", failures.len(), failures.join("\n"));
}

/// The reader this test relies on: comments, strings and test modules are not code; grouped and
/// relative paths resolve to absolute module paths.
#[test]
fn the_source_reader_finds_what_code_names_and_nothing_else() {
    let text = r##"
use crate::{geom::DVec3, hierarchy::{Hierarchy, NONE}, self};
use super::super::solve::Link; // crate::output in a comment
/// [`crate::pipeline::run`] in a doc comment
fn f() { let s = "crate::luminaire"; let r = r#"crate::daylight"#; let c = '"'; crate::visibility::RayCaster::new(); }
#[cfg(test)]
mod tests { use crate::instancing::load; }
"##;
    let s = Source { module: vec!["refine".into(), "driver".into()], code: code_only(text) };
    let mut paths = named_paths(&s);
    paths.sort();
    let expected: Vec<Vec<String>> = [vec!["geom"], vec!["hierarchy"], vec!["solve", "Link"], vec!["visibility", "RayCaster", "new"]]
        .iter()
        .map(|p| p.iter().map(|x| x.to_string()).collect())
        .collect();
    assert_eq!(paths, expected, "code read as {:?}", s.code);
}
