//! The house's import rules, read from the library's sources: no import circles, and no
//! import from a lower layer back up (STYLE.md, "Data flows one way"; ARCHITECTURE.md).
//!
//! Every `use crate::...`, `use super::...` and inline `crate::a::b` path of a library file
//! (`src/**/*.rs` but the binary's `main.rs` and `cli/`; `#[cfg(test)]` blocks left out) is
//! resolved to the file of the deepest module it names, following `pub use` re-exports of
//! a module's own children. That gives a graph of files. Two things are checked:
//!
//! - **Circles**: strongly connected components of more than one file (Tarjan), leaving out
//!   a file's use of its own ancestors (a child reading its parent's types) and a parent's
//!   use of its own descendants (a `mod.rs` re-exporting or calling its children): those
//!   are how Rust modules nest, not circles. Circles between top-level modules (all the
//!   files of `mesh` against all of `las`) are checked on the graph collapsed to them.
//! - **Layers**: each top-level module has a rank in [`LAYERS`]; a module may use modules
//!   of its own rank or below, never above.
//!
//! `cargo test --release --test module_graph -- --nocapture` prints the graph's circles
//! and layer breaches without failing on the allowed ones.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom up: a module may import modules of its own layer or lower ones.
/// The flow of ARCHITECTURE.md: files are read, become a BVH over boxes and primitive
/// sets that own one, are evaluated, traced through a camera onto film; scenes configure
/// it; reports, the API and the server sit on top and call the same library.
const LAYERS: &[(&str, &[&str])] = &[
    (
        "foundations",
        &["limits", "geometry", "output", "rgb", "font"],
    ),
    ("readers", &["mesh", "las", "procedural"]),
    ("bvh", &["bvh"]),
    ("primitives", &["primitives"]),
    ("loader", &["load"]),
    ("colour from the data", &["colour"]),
    ("evaluation", &["eval", "winding", "field"]),
    ("camera and film", &["camera", "matcap", "film", "framing"]),
    ("scenes", &["scene"]),
    ("render", &["render"]),
    ("callers", &["api", "reports", "serve"]),
];

/// Circles known to be under repair elsewhere, as sorted file lists (empty when none).
const KNOWN_CIRCLES: &[&[&str]] = &[];

struct Crate {
    root: PathBuf,
    /// Module path (`["mesh", "obj"]`) -> file (relative to the crate root).
    files: BTreeMap<Vec<String>, PathBuf>,
    /// (module, name) -> child module a `pub use child::name` in that module re-exports.
    reexports: BTreeMap<(Vec<String>, String), Vec<String>>,
}

fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .skip(1) // "src"
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs").to_string();
    if stem != "mod" && stem != "lib" {
        parts.push(stem);
    }
    parts
}

fn collect(dir: &Path, root: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        let rel = p.strip_prefix(root).unwrap().to_path_buf();
        if p.is_dir() {
            if rel != Path::new("src/cli") {
                collect(&p, root, out);
            }
        } else if p.extension().is_some_and(|e| e == "rs") && rel != Path::new("src/main.rs") {
            out.push(rel);
        }
    }
}

/// The source without comments, string literals' contents and `#[cfg(test)]` blocks.
fn code_of(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
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
        } else if b[i] == b'"' {
            out.push('"');
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            out.push('"');
            i += 1;
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            // A char literal such as '{' must not count as a brace.
            out.push_str("' '");
            i += 3;
        } else if b[i] == b'\'' && b.get(i + 1) == Some(&b'\\') {
            out.push_str("' '");
            i += 2;
            while i < b.len() && b[i] != b'\'' {
                i += 1;
            }
            i += 1;
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    strip_test_blocks(&out)
}

fn strip_test_blocks(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let after = &rest[at..];
        // The item that follows: up to its `;` or its balanced `{ ... }`.
        let semi = after.find(';').unwrap_or(after.len());
        let open = after.find('{').unwrap_or(after.len());
        if semi < open {
            rest = &after[semi + 1..];
            continue;
        }
        let mut depth = 0;
        let mut end = after.len();
        for (k, c) in after.char_indices().skip(open) {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Expands a use tree (`crate::a::{b, c::{d, e}}`) into its paths.
fn expand(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else {
        return vec![tree];
    };
    let prefix = &tree[..open];
    let close = tree.rfind('}').unwrap();
    let inner = &tree[open + 1..close];
    let mut parts = Vec::new();
    let mut depth = 0;
    let mut start = 0;
    for (k, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..k]);
                start = k + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.is_empty())
        .flat_map(|p| expand(&format!("{prefix}{p}")))
        .collect()
}

/// The `use` trees of `code` (with whether each is `pub`), and the code with them removed.
fn use_items(code: &str) -> (Vec<(bool, String)>, String) {
    let mut items = Vec::new();
    let mut rest_code = String::new();
    let mut i = 0;
    while i < code.len() {
        let starts_word = i == 0 || !is_ident(code[..i].chars().next_back().unwrap());
        if starts_word && code[i..].starts_with("use ") {
            let end = i + code[i..].find(';').unwrap();
            let before = code[..i].trim_end();
            let public =
                before.ends_with("pub") || (before.ends_with(')') && before.contains("pub("));
            for p in expand(&code[i + 4..end]) {
                items.push((public, p));
            }
            i = end + 1;
        } else {
            let c = code[i..].chars().next().unwrap();
            rest_code.push(c);
            i += c.len_utf8();
        }
    }
    (items, rest_code)
}

/// Inline paths rooted at `crate`, `super` or `self` outside `use` items.
fn inline_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for root in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(root) {
            let at = from + k;
            from = at + root.len();
            if at > 0 && is_ident(code[..at].chars().next_back().unwrap()) {
                continue;
            }
            let tail: String = code[at..]
                .chars()
                .take_while(|&c| is_ident(c) || c == ':')
                .collect();
            out.push(tail.trim_end_matches(':').to_string());
        }
    }
    out
}

impl Crate {
    fn load(root: &Path) -> Crate {
        let mut rels = Vec::new();
        collect(&root.join("src"), root, &mut rels);
        let mut files = BTreeMap::new();
        for rel in &rels {
            files.insert(module_path(rel), rel.clone());
        }
        let mut c = Crate {
            root: root.to_path_buf(),
            files,
            reexports: BTreeMap::new(),
        };
        for (module, rel) in c.files.clone() {
            let (items, _) = use_items(&c.code(&rel));
            for (public, path) in items {
                let segs: Vec<&str> = path.split("::").collect();
                // `pub use child::name` (or `self::child::name`) in the module itself.
                let segs: Vec<&str> = segs.into_iter().filter(|s| *s != "self").collect();
                if public && segs.len() >= 2 {
                    let mut child = module.clone();
                    child.push(segs[0].to_string());
                    if c.files.contains_key(&child) {
                        let name = segs.last().unwrap();
                        let name = name.split(" as ").next().unwrap().to_string();
                        c.reexports.insert((module.clone(), name), child);
                    }
                }
            }
        }
        c
    }

    fn code(&self, rel: &Path) -> String {
        code_of(&std::fs::read_to_string(self.root.join(rel)).unwrap())
    }

    /// The file of the deepest module `path` names, seen from module `here`.
    fn resolve(&self, here: &[String], path: &str) -> Option<Vec<String>> {
        let mut segs = path
            .split("::")
            .map(|s| s.split(" as ").next().unwrap().to_string());
        let mut cur: Vec<String> = match segs.next()?.as_str() {
            "crate" => Vec::new(),
            "self" => here.to_vec(),
            "super" => here[..here.len().checked_sub(1)?].to_vec(),
            _ => return None,
        };
        for s in segs {
            if s == "super" {
                cur.pop();
                continue;
            }
            if s == "self" || s == "*" {
                continue;
            }
            let mut next = cur.clone();
            next.push(s.clone());
            if self.files.contains_key(&next) {
                cur = next;
            } else if let Some(child) = self.reexports.get(&(cur.clone(), s.clone())) {
                cur = child.clone();
            } else {
                break;
            }
        }
        Some(cur)
    }

    /// File -> the modules it uses (ancestors and descendants left out).
    fn edges(&self) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
        let mut out = BTreeMap::new();
        for (module, rel) in &self.files {
            let (items, rest) = use_items(&self.code(rel));
            let paths = items.into_iter().map(|(_, p)| p).chain(inline_paths(&rest));
            let mut to = BTreeSet::new();
            for p in paths {
                if let Some(t) = self.resolve(module, &p) {
                    let related = t.starts_with(module) || module.starts_with(&t);
                    if !related {
                        to.insert(t);
                    }
                }
            }
            out.insert(module.clone(), to);
        }
        out
    }

    fn file(&self, m: &[String]) -> String {
        self.files[m].display().to_string()
    }
}

/// Strongly connected components of more than one node (Tarjan).
fn circles<N: Ord + Clone>(graph: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    struct T<'a, N> {
        g: &'a BTreeMap<N, BTreeSet<N>>,
        index: BTreeMap<N, usize>,
        low: BTreeMap<N, usize>,
        stack: Vec<N>,
        on: BTreeSet<N>,
        out: Vec<Vec<N>>,
    }
    fn visit<N: Ord + Clone>(t: &mut T<N>, v: &N) {
        let i = t.index.len();
        t.index.insert(v.clone(), i);
        t.low.insert(v.clone(), i);
        t.stack.push(v.clone());
        t.on.insert(v.clone());
        let nexts: Vec<N> =
            t.g.get(v)
                .map(|s| s.iter().cloned().collect())
                .unwrap_or_default();
        for w in &nexts {
            if !t.index.contains_key(w) {
                visit(t, w);
                let l = t.low[v].min(t.low[w]);
                t.low.insert(v.clone(), l);
            } else if t.on.contains(w) {
                let l = t.low[v].min(t.index[w]);
                t.low.insert(v.clone(), l);
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(&w);
                comp.push(w.clone());
                if &w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out
}

fn the_crate() -> Crate {
    Crate::load(Path::new(env!("CARGO_MANIFEST_DIR")))
}

fn layer(module: &str) -> usize {
    LAYERS
        .iter()
        .position(|(_, ms)| ms.contains(&module))
        .unwrap_or_else(|| panic!("top-level module `{module}` has no layer in LAYERS"))
}

#[test]
fn no_import_circles_between_files() {
    let c = the_crate();
    let graph = c.edges();
    let mut found = Vec::new();
    for comp in circles(&graph) {
        let files: Vec<String> = comp.iter().map(|m| c.file(m)).collect();
        let known = KNOWN_CIRCLES
            .iter()
            .any(|k| k.iter().map(|s| s.to_string()).collect::<Vec<_>>() == files);
        let inside: Vec<String> = comp
            .iter()
            .flat_map(|m| {
                graph[m]
                    .iter()
                    .filter(|t| comp.contains(t))
                    .map(|t| format!("{} -> {}", c.file(m), c.file(t)))
                    .collect::<Vec<_>>()
            })
            .collect();
        eprintln!(
            "circle{}: {}",
            if known { " (known, under repair)" } else { "" },
            inside.join(", ")
        );
        if !known {
            found.push(inside.join(", "));
        }
    }
    assert!(
        found.is_empty(),
        "import circles between files:\n{}",
        found.join("\n")
    );
}

#[test]
fn no_import_circles_between_top_level_modules() {
    let c = the_crate();
    let mut top: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (from, tos) in c.edges() {
        let Some(a) = from.first() else { continue };
        let entry = top.entry(a.clone()).or_default();
        for t in tos {
            if let Some(b) = t.first().filter(|b| *b != a) {
                entry.insert(b.clone());
            }
        }
    }
    let found = circles(&top);
    assert!(
        found.is_empty(),
        "circles between top-level modules: {found:?}"
    );
}

#[test]
fn no_import_from_a_lower_layer_back_up() {
    let c = the_crate();
    let mut breaches = Vec::new();
    for (from, tos) in c.edges() {
        let Some(a) = from.first() else { continue };
        for t in tos {
            let Some(b) = t.first() else { continue };
            if layer(b) > layer(a) {
                breaches.push(format!(
                    "{} ({}) -> {} ({})",
                    c.file(&from),
                    LAYERS[layer(a)].0,
                    c.file(&t),
                    LAYERS[layer(b)].0
                ));
            }
        }
    }
    for b in &breaches {
        eprintln!("breach: {b}");
    }
    assert!(
        breaches.is_empty(),
        "imports back up a layer:\n{}",
        breaches.join("\n")
    );
}

/// The reader itself: a circle through a re-export, a child's use of its parent (not a
/// circle), and a test block (left out).
#[test]
fn the_reader_finds_a_circle_through_a_reexport() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("m")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod m;\npub mod n;\n").unwrap();
    std::fs::write(
        src.join("m/mod.rs"),
        "mod a;\nmod b;\npub use a::{A, helper as h};\npub struct M;\n",
    )
    .unwrap();
    std::fs::write(
        src.join("m/a.rs"),
        "use super::M; // the parent: allowed\npub struct A;\npub fn helper() { super::b::f(); }\n",
    )
    .unwrap();
    std::fs::write(
        src.join("m/b.rs"),
        "pub fn f() { let _ = crate::m::A; }\n#[cfg(test)]\nmod tests { use crate::n::N; }\n",
    )
    .unwrap();
    std::fs::write(src.join("n.rs"), "/* crate::m::b */ pub struct N;\n").unwrap();
    let c = Crate::load(dir.path());
    let g = c.edges();
    let m = |s: &str| s.split('/').map(String::from).collect::<Vec<_>>();
    assert_eq!(g[&m("m/a")], BTreeSet::from([m("m/b")]));
    assert_eq!(g[&m("m/b")], BTreeSet::from([m("m/a")]));
    assert!(g[&m("n")].is_empty(), "{:?}", g[&m("n")]);
    assert_eq!(circles(&g), vec![vec![m("m/a"), m("m/b")]]);
}

#[test]
#[ignore]
fn print_top_level_edges() {
    let c = the_crate();
    for (from, tos) in c.edges() {
        for t in tos {
            if from.first() != t.first() {
                eprintln!("{} -> {}", c.file(&from), c.file(&t));
            }
        }
    }
}
