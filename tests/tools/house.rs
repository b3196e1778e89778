//! The house's structure, read from the sources: files and functions that fit in a head in
//! `kernel/` and `host-harness/` ([`MAX_FILE_LINES`], [`MAX_FUNCTION_LINES`]), and no file circle
//! in any crate of the workspace
//! (two files that import each other, directly or through a cycle of files), so that every
//! folder reads from its leaves up.
//!
//! The graph: a file points at the file that defines each item it names through a `use`
//! statement or a `crate::`/`super::`/`self::` path in its code. A name re-exported by a
//! `mod.rs` or `lib.rs` (`pub use scene::Scene`) is followed to the file that defines it; the
//! re-export itself is no arrow (a folder's front door names its rooms, it does not depend on
//! them). Comments and string literals are skipped (docs may point anywhere). External crates
//! are not followed: a crate's own layering is the kernel's layer test (`kernel::layers`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use palpate_tests::source::{code_only, is_ident, rust_files};

/// Every crate root of the workspace whose files are checked: the folders holding a `lib.rs`
/// or `main.rs`, relative to the repository root.
const CRATE_SOURCES: [&str; 11] = [
    "kernel/src",
    "host-harness/src",
    "ffi/src",
    "benches/src",
    "tools/script/src",
    "tools/firmware-m4f/src",
    "tools/nopanic-check/src",
    "tools/ffi-header/src",
    "tools/cycles/src",
    "tools/cycles-m4f/src",
    "fuzz/src",
];

/// A module path from the crate root: `session/scene.rs` → `["session", "scene"]`.
type ModulePath = Vec<String>;

/// One crate's files, by module path, with their code (comments and literals blanked).
struct Crate {
    files: BTreeMap<ModulePath, (PathBuf, String)>,
}

fn repository_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The module path of `file` under `src` (`mod.rs`, `lib.rs` and `main.rs` name their folder).
fn module_path(src: &Path, file: &Path) -> ModulePath {
    let relative = file.strip_prefix(src).expect("file under its crate's src");
    let mut parts: ModulePath = relative
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

fn read_crate(src: &Path) -> Crate {
    let mut paths = Vec::new();
    rust_files(src, &mut paths);
    let files = paths
        .into_iter()
        .map(|f| {
            let source = std::fs::read_to_string(&f).expect("read source");
            // A file's unit tests (its last item, by the house's convention) may import
            // anything of the file's folder: they are not the file's dependencies.
            let source = source.split("#[cfg(test)]").next().unwrap_or_default();
            (module_path(src, &f), (f, code_only(source)))
        })
        .collect();
    Crate { files }
}

fn ident_at(s: &str) -> &str {
    let end = s.find(|c: char| !is_ident(c)).unwrap_or(s.len());
    &s[..end]
}

/// The paths of a use tree written at the start of `text` (`a::b::{C, d::E as F, self}`), each
/// as its segments and the name it binds (the last segment, or the `as` alias).
fn use_tree(text: &str) -> Vec<(Vec<String>, String)> {
    let mut out = Vec::new();
    tree_into(text.trim_start(), &mut Vec::new(), &mut out);
    out
}

fn tree_into(text: &str, prefix: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    if let Some(group) = text.strip_prefix('{') {
        let mut depth = 0;
        let mut start = 0;
        for (k, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    tree_into(group[start..k].trim_start(), prefix, out);
                    return;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    tree_into(group[start..k].trim_start(), prefix, out);
                    start = k + 1;
                }
                _ => {}
            }
        }
        return;
    }
    let segment = ident_at(text);
    if segment.is_empty() {
        return;
    }
    let rest = text[segment.len()..].trim_start();
    if segment == "self" && !prefix.is_empty() {
        let name = prefix.last().cloned().unwrap_or_default();
        out.push((prefix.clone(), alias(rest).unwrap_or(name)));
        return;
    }
    prefix.push(segment.to_owned());
    if let Some(tail) = rest.strip_prefix("::") {
        tree_into(tail.trim_start(), prefix, out);
    } else {
        out.push((prefix.clone(), alias(rest).unwrap_or(segment.to_owned())));
    }
    prefix.pop();
}

/// The name after ` as `, if the text starts with one.
fn alias(rest: &str) -> Option<String> {
    rest.strip_prefix("as ")
        .map(|a| ident_at(a.trim_start()).to_owned())
}

/// Byte offsets where `needle` starts a path (not inside an identifier or a longer path).
fn path_starts<'a>(code: &'a str, needle: &'a str) -> impl Iterator<Item = usize> + 'a {
    code.match_indices(needle).map(|(k, _)| k).filter(|&k| {
        let before = &code[..k];
        !before.ends_with("::") && !before.chars().next_back().is_some_and(is_ident)
    })
}

/// A `use` statement: whether it re-exports (`pub…`) and its text up to the `;`.
struct UseStatement<'a> {
    public: bool,
    tree: &'a str,
}

fn use_statements(code: &str) -> Vec<UseStatement<'_>> {
    path_starts(code, "use ")
        .filter_map(|k| {
            let tree = &code[k + "use ".len()..];
            let tree = &tree[..tree.find(';')?];
            let line_start = code[..k].rfind(['\n', ';', '{', '}']).map_or(0, |s| s + 1);
            let public = code[line_start..k].trim_start().starts_with("pub");
            Some(UseStatement { public, tree })
        })
        .collect()
}

impl Crate {
    /// The absolute module path a relative path's first segments name, seen from `module`
    /// (the segments after them returned too), or `None` for an external crate.
    fn absolute(&self, module: &[String], path: &[String]) -> Option<Vec<String>> {
        let (first, rest) = path.split_first()?;
        let mut base: Vec<String> = match first.as_str() {
            "crate" => Vec::new(),
            "self" => module.to_vec(),
            "super" => module[..module.len().checked_sub(1)?].to_vec(),
            child => {
                let mut m = module.to_vec();
                m.push(child.to_owned());
                if !self.files.contains_key(&m) {
                    return None;
                }
                return Some(m.into_iter().chain(rest.iter().cloned()).collect());
            }
        };
        let mut rest = rest;
        while let Some((next, tail)) = rest.split_first() {
            if next != "super" {
                break;
            }
            base.pop()?;
            rest = tail;
        }
        Some(base.into_iter().chain(rest.iter().cloned()).collect())
    }

    /// The file that defines what an absolute path names: the deepest module on the path, or,
    /// when that module re-exports the next segment, the file the re-export leads to.
    fn defining_file(&self, path: &[String], depth: usize) -> Option<ModulePath> {
        let module_len = (0..=path.len())
            .rev()
            .find(|&n| self.files.contains_key(&path[..n]))?;
        let module = path[..module_len].to_vec();
        let Some(name) = path.get(module_len) else {
            return Some(module);
        };
        if depth < 8 {
            let code = &self.files[&module].1;
            for statement in use_statements(code).iter().filter(|s| s.public) {
                for (target, bound) in use_tree(statement.tree) {
                    if &bound == name
                        && let Some(absolute) = self.absolute(&module, &target)
                    {
                        let mut full = absolute;
                        full.extend(path[module_len + 1..].iter().cloned());
                        return self.defining_file(&full, depth + 1);
                    }
                }
            }
        }
        Some(module)
    }

    /// Every file each file points at, with the names that tie them.
    fn arrows(&self) -> BTreeMap<ModulePath, BTreeMap<ModulePath, BTreeSet<String>>> {
        let mut arrows: BTreeMap<ModulePath, BTreeMap<ModulePath, BTreeSet<String>>> =
            BTreeMap::new();
        for (module, (_, code)) in &self.files {
            let mut paths: Vec<Vec<String>> = use_statements(code)
                .iter()
                .filter(|s| !s.public)
                .flat_map(|s| use_tree(s.tree).into_iter().map(|(p, _)| p))
                .collect();
            for needle in ["crate::", "super::", "self::"] {
                for k in path_starts(code, needle) {
                    let rest = &code[k..];
                    let end = rest
                        .find(|c: char| !(is_ident(c) || c == ':'))
                        .unwrap_or(rest.len());
                    if rest[..end].ends_with("::") {
                        continue; // a use group (`crate::a::{…}`), read with its statement
                    }
                    let segments: Vec<String> = rest[..end]
                        .split("::")
                        .filter(|s| !s.is_empty())
                        .map(str::to_owned)
                        .collect();
                    paths.push(segments);
                }
            }
            for path in paths {
                let Some(absolute) = self.absolute(module, &path) else {
                    continue;
                };
                let Some(target) = self.defining_file(&absolute, 0) else {
                    continue;
                };
                if &target != module && !target.is_empty() {
                    let name = path.last().cloned().unwrap_or_default();
                    arrows
                        .entry(module.clone())
                        .or_default()
                        .entry(target)
                        .or_default()
                        .insert(name);
                }
            }
        }
        arrows
    }
}

/// The strongly connected components of more than one file (Tarjan's algorithm).
fn circles(
    arrows: &BTreeMap<ModulePath, BTreeMap<ModulePath, BTreeSet<String>>>,
) -> Vec<Vec<ModulePath>> {
    struct Walk<'a> {
        arrows: &'a BTreeMap<ModulePath, BTreeMap<ModulePath, BTreeSet<String>>>,
        index: BTreeMap<&'a ModulePath, usize>,
        low: BTreeMap<&'a ModulePath, usize>,
        stack: Vec<&'a ModulePath>,
        on_stack: BTreeSet<&'a ModulePath>,
        found: Vec<Vec<ModulePath>>,
    }
    impl<'a> Walk<'a> {
        fn visit(&mut self, v: &'a ModulePath) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.arrows.get(v).into_iter().flat_map(|m| m.keys()) {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.on_stack.contains(w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.found.push(component);
                }
            }
        }
    }
    let mut walk = Walk {
        arrows,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in arrows.keys() {
        if !walk.index.contains_key(v) {
            walk.visit(v);
        }
    }
    walk.found
}

/// A circle in words: each file of it and what it takes from the others.
fn describe(
    src: &str,
    circle: &[ModulePath],
    arrows: &BTreeMap<ModulePath, BTreeMap<ModulePath, BTreeSet<String>>>,
) -> String {
    let name = |m: &ModulePath| format!("{src}/{}", m.join("/"));
    let mut lines = vec![format!(
        "circle of {} files: {}",
        circle.len(),
        circle.iter().map(name).collect::<Vec<_>>().join(", ")
    )];
    for from in circle {
        for (to, names) in arrows.get(from).into_iter().flatten() {
            if circle.contains(to) {
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                lines.push(format!(
                    "  {} -> {}: {}",
                    name(from),
                    name(to),
                    names.join(", ")
                ));
            }
        }
    }
    lines.join("\n")
}

#[test]
fn no_file_circle_in_any_crate() {
    let root = repository_root();
    let mut found = Vec::new();
    let mut arrow_count = 0;
    for src in CRATE_SOURCES {
        let krate = read_crate(&root.join(src));
        let arrows = krate.arrows();
        arrow_count += arrows.values().map(BTreeMap::len).sum::<usize>();
        for circle in circles(&arrows) {
            found.push(describe(src, &circle, &arrows));
        }
    }
    // The harness alone has hundreds of arrows: a handful means the scan is broken.
    assert!(arrow_count > 300, "only {arrow_count} arrows found");
    assert!(
        found.is_empty(),
        "files that import each other (move what they share to a file both use):\n{}",
        found.join("\n")
    );
}

/// The scanner on a small crate: arrows through `use` trees, code paths and re-exports, and a
/// circle found where there is one.
#[test]
fn the_scanner_follows_re_exports_and_finds_circles() {
    let file = |code: &str| (PathBuf::new(), code_only(code));
    let module = |m: &[&str]| m.iter().map(|s| (*s).to_owned()).collect::<ModulePath>();
    let krate = Crate {
        files: BTreeMap::from([
            (
                module(&[]),
                file("pub mod a; pub mod b; pub use a::x::Thing;"),
            ),
            (
                module(&["a"]),
                file("pub mod x; pub mod y; pub use x::Thing;"),
            ),
            (
                module(&["a", "x"]),
                file("use super::y::{Other, self as why};\npub struct Thing;"),
            ),
            (
                module(&["a", "y"]),
                file("// crate::b::Nothing\npub struct Other; fn f() { let _ = crate::Thing; }"),
            ),
            (
                module(&["b"]),
                file("use crate::a::{Thing, y::Other as O};\nconst S: &str = \"crate::a::x\";"),
            ),
        ]),
    };
    let arrows = krate.arrows();
    let targets = |m: &[&str]| -> Vec<ModulePath> {
        arrows
            .get(&module(m))
            .map(|t| t.keys().cloned().collect())
            .unwrap_or_default()
    };
    assert_eq!(targets(&["b"]), [module(&["a", "x"]), module(&["a", "y"])]);
    assert_eq!(targets(&["a", "x"]), [module(&["a", "y"])]);
    assert_eq!(targets(&["a", "y"]), [module(&["a", "x"])]);
    assert!(targets(&[]).is_empty() && targets(&["a"]).is_empty());
    assert_eq!(
        circles(&arrows),
        [vec![module(&["a", "x"]), module(&["a", "y"])]]
    );
}

/// The largest source file in `kernel/` and `host-harness/`, lines: a file longer than this holds
/// more than one responsibility (split it by responsibility, not by line count).
const MAX_FILE_LINES: usize = 800;
/// The longest function there, lines from its `fn` to its closing brace: longer, its stages
/// become named functions.
const MAX_FUNCTION_LINES: usize = 120;

/// Each function's name and length in lines (from the line of `fn` to its closing brace) in code
/// with comments and literals blanked: a `fn` followed by a body (a declaration ending in `;`, as
/// in a trait, has none).
fn function_lengths(code: &str) -> Vec<(String, usize, usize)> {
    let mut found = Vec::new();
    for k in path_starts(code, "fn ") {
        let name = ident_at(&code[k + 3..]);
        if name.is_empty() {
            continue; // `fn(` types
        }
        let rest = &code[k..];
        let Some(open) = rest.find(['{', ';']) else {
            continue;
        };
        if rest.as_bytes()[open] == b';' {
            continue;
        }
        let mut depth = 0usize;
        let mut end = open;
        for (i, c) in rest[open..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + i;
                        break;
                    }
                }
                _ => {}
            }
        }
        let first_line = code[..k].matches('\n').count() + 1;
        let lines = rest[..end].matches('\n').count() + 1;
        found.push((name.to_owned(), first_line, lines));
    }
    found
}

#[test]
fn files_and_functions_fit_in_a_head() {
    let root = repository_root();
    let mut too_long = Vec::new();
    let mut functions = 0;
    for src in ["kernel/src", "host-harness/src"] {
        let mut files = Vec::new();
        rust_files(&root.join(src), &mut files);
        for file in files {
            let source = std::fs::read_to_string(&file).expect("read source");
            let shown = file
                .strip_prefix(&root)
                .unwrap_or(&file)
                .display()
                .to_string();
            let lines = source.lines().count();
            if lines > MAX_FILE_LINES {
                too_long.push(format!("{shown}: {lines} lines (at most {MAX_FILE_LINES})"));
            }
            for (name, line, length) in function_lengths(&code_only(&source)) {
                functions += 1;
                if length > MAX_FUNCTION_LINES {
                    too_long.push(format!(
                        "{shown}:{line}: fn {name}: {length} lines (at most {MAX_FUNCTION_LINES})"
                    ));
                }
            }
        }
    }
    // The kernel and the harness hold thousands of functions: a handful means a broken scan.
    assert!(functions > 1000, "only {functions} functions found");
    assert!(too_long.is_empty(), "{}", too_long.join("\n"));
}

/// The length scan on known code: a body's lines counted, a declaration and a `fn` type skipped.
#[test]
fn function_lengths_count_bodies_only() {
    let code = code_only(
        "trait T { fn declared(&self); }\nfn short() {}\nfn long(f: fn(u8)) {\n    let _ = \"}\";\n    {\n    }\n}\n",
    );
    assert_eq!(
        function_lengths(&code),
        [("short".to_owned(), 2, 1), ("long".to_owned(), 3, 5)]
    );
}
