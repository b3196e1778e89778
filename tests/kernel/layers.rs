//! The kernel's folders form layers with no import cycle (`kernel/src/lib.rs`
//! lists them): `math` < `table` < `contact` < {`precomputed`,
//! `tensor_mass`} < `hybrid` < `haptic` < `link`. Code in a folder may name items of its own
//! folder or of a lower layer only; `precomputed` and `tensor_mass` are
//! peers and name neither each other. The root's own constants (`pub const`
//! in `lib.rs`) are allowed everywhere; a root re-export (`crate::Real`)
//! counts as the folder it re-exports.
//!
//! The check reads the sources: every `crate::` path (`use` statements and
//! paths in code, grouped imports included) and every `super::` path that
//! climbs to the root. Comments (doc comments with their intra-doc links
//! included: docs may point up) and string literals are skipped.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use palpate_tests::source::{code_only, is_ident, rust_files};

/// The folders, lowest first, with their rank; equal ranks are peers.
const LAYERS: [(&str, u32); 8] = [
    ("math", 0),
    ("table", 1),
    ("contact", 2),
    ("precomputed", 3),
    ("tensor_mass", 3),
    ("hybrid", 4),
    ("haptic", 5),
    ("link", 6),
];

/// What a `crate::` path's first segment names.
#[derive(Clone, Debug, PartialEq)]
enum Target {
    /// An item of a folder (by name).
    Layer(&'static str),
    /// A constant of the root, allowed everywhere.
    Root,
}

fn rank(layer: &str) -> Option<u32> {
    LAYERS.iter().find(|(l, _)| *l == layer).map(|&(_, r)| r)
}

fn layer_name(segment: &str) -> Option<&'static str> {
    LAYERS.iter().find(|(l, _)| *l == segment).map(|&(l, _)| l)
}

/// `from` may name `to`: the same folder, or a lower rank.
fn allowed(from: &str, to: &str) -> bool {
    from == to || matches!((rank(from), rank(to)), (Some(a), Some(b)) if b < a)
}

/// The identifier starting at byte `i` of `s` (may be empty).
fn ident_at(s: &str, i: usize) -> &str {
    let rest = &s[i..];
    let end = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
    &rest[..end]
}

/// The first segments of a path tail at byte `i` of `code`: one
/// identifier, or each top-level item of a `{…}` group.
fn first_segments(code: &str, i: usize) -> Vec<String> {
    let rest = code[i..].trim_start();
    if let Some(group) = rest.strip_prefix('{') {
        let mut depth = 0;
        let mut items = vec![String::new()];
        for c in group.chars() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    items.push(String::new());
                    continue;
                }
                _ => {}
            }
            if let Some(item) = items.last_mut() {
                item.push(c);
            }
        }
        items
            .iter()
            .map(|item| ident_at(item.trim_start(), 0).to_owned())
            .filter(|s| !s.is_empty())
            .collect()
    } else {
        vec![ident_at(rest, 0).to_owned()]
    }
}

/// Byte offsets where `needle` starts a path: not preceded by an
/// identifier character or `::` (so `crate::` matches, `$crate::` too).
fn path_starts(code: &str, needle: &str) -> Vec<usize> {
    code.match_indices(needle)
        .map(|(k, _)| k)
        .filter(|&k| {
            let before = &code[..k];
            !before.ends_with("::") && !before.chars().next_back().is_some_and(is_ident)
        })
        .collect()
}

/// Every root-level module a file's code names, with the line: the first
/// segments after `crate::`, and after `super::` chains that climb to the
/// root from `module` (the file's module path).
fn root_references(code: &str, module: &[String]) -> Vec<(usize, String)> {
    let line = |k: usize| code[..k].matches('\n').count() + 1;
    let mut found = Vec::new();
    for k in path_starts(code, "crate::") {
        for s in first_segments(code, k + "crate::".len()) {
            found.push((line(k), s));
        }
    }
    for k in path_starts(code, "super::") {
        let mut end = k;
        let mut ups = 0;
        while code[end..].starts_with("super::") {
            end += "super::".len();
            ups += 1;
        }
        if ups >= module.len() {
            for s in first_segments(code, end) {
                found.push((line(k), s));
            }
        }
    }
    found
}

/// The module path of a source file under `src`: `table/collision.rs` →
/// `[table, collision]`, `table/mod.rs` → `[table]`, `lib.rs` → `[]`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).expect("under src");
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// What each root-level name of `lib.rs` is: a folder's item re-exported
/// (`pub use folder::{A, B as C}` → A, C) or a root constant.
fn root_names(lib_code: &str) -> BTreeMap<String, Target> {
    let mut names = BTreeMap::new();
    for (k, _) in lib_code.match_indices("pub use ") {
        let statement = &lib_code[k + "pub use ".len()..];
        let statement = &statement[..statement.find(';').expect("use ends with ;")];
        let folder = ident_at(statement, 0);
        let layer = layer_name(folder).expect("lib.rs re-exports from a folder");
        let tail = statement.split_once('{').map_or(statement, |(_, t)| t);
        for item in tail.trim_end_matches('}').split(',') {
            let name = item.rsplit(" as ").next().unwrap_or(item);
            let name = name.rsplit("::").next().unwrap_or(name).trim();
            if !name.is_empty() {
                names.insert(name.to_owned(), Target::Layer(layer));
            }
        }
    }
    for (k, _) in lib_code.match_indices("pub const ") {
        let name = ident_at(lib_code, k + "pub const ".len());
        names.insert(name.to_owned(), Target::Root);
    }
    names
}

/// Exported macros (`#[macro_export] macro_rules! name`) live at the root
/// but belong to the folder that defines them.
fn macro_names(code: &str, layer: &'static str, names: &mut BTreeMap<String, Target>) {
    for (k, _) in code.match_indices("macro_rules!") {
        let name = ident_at(code[k + "macro_rules!".len()..].trim_start(), 0);
        names.insert(name.to_owned(), Target::Layer(layer));
    }
}

/// Every reference from a folder to a folder it may not name, as
/// `file:line: from -> to (segment)`; and the references checked per folder.
fn violations(src: &Path) -> (Vec<String>, BTreeMap<&'static str, usize>) {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let sources: Vec<(PathBuf, Vec<String>, String)> = files
        .into_iter()
        .map(|f| {
            let code = code_only(&std::fs::read_to_string(&f).expect("read source"));
            let module = module_path(src, &f);
            (f, module, code)
        })
        .collect();
    let lib = sources
        .iter()
        .find(|(_, m, _)| m.is_empty())
        .expect("lib.rs");
    let mut names = root_names(&lib.2);
    for (f, module, code) in &sources {
        let Some(first) = module.first() else {
            continue;
        };
        let layer = layer_name(first)
            .unwrap_or_else(|| panic!("{}: a folder outside the layer list", f.display()));
        macro_names(code, layer, &mut names);
    }
    let mut bad = Vec::new();
    let mut checked = BTreeMap::new();
    for (f, module, code) in &sources {
        let Some(from) = module.first().and_then(|m| layer_name(m)) else {
            continue; // lib.rs: the root may name every folder.
        };
        for (line, segment) in root_references(code, module) {
            let target = match layer_name(&segment) {
                Some(layer) => Target::Layer(layer),
                None => names.get(&segment).cloned().unwrap_or_else(|| {
                    panic!(
                        "{}:{line}: `crate::{segment}` is neither a folder nor a root item of lib.rs",
                        f.display()
                    )
                }),
            };
            *checked.entry(from).or_insert(0) += 1;
            if let Target::Layer(to) = target
                && !allowed(from, to)
            {
                bad.push(format!(
                    "{}:{line}: {from} -> {to} (crate::{segment})",
                    f.strip_prefix(src).unwrap_or(f).display()
                ));
            }
        }
    }
    (bad, checked)
}

fn kernel_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("kernel")
        .join("src")
}

#[test]
fn kernel_folders_reference_only_their_own_or_lower_layers() {
    let (bad, checked) = violations(&kernel_src());
    println!("crate-level references checked, per folder: {checked:?}");
    // Every folder names `crate::Real` at least: none found means the scan
    // is broken, not that the layering holds.
    for (layer, _) in LAYERS {
        assert!(
            checked.get(layer).is_some_and(|&n| n > 0),
            "no reference found in {layer}: is the scan broken? {checked:?}"
        );
    }
    assert!(
        bad.is_empty(),
        "references to a higher layer or a peer (the order is math < table < contact < \
         {{precomputed, tensor_mass}} < haptic):\n{}",
        bad.join("\n")
    );
}

/// The scanner itself: code paths count, comments and strings do not.
#[test]
fn scanner_sees_code_paths_only() {
    let source = r#"
//! Docs may point up: [`crate::haptic::HapticLoop`].
use crate::{Real, math::element::{lame, stiffness_block}};
use crate::haptic::HapticLoop; // crate::tensor_mass in a comment
/* crate::precomputed /* nested */ crate::precomputed */
fn f<'a>(x: &'a str) -> char {
    let _ = "crate::tensor_mass::X";
    let _ = r"crate::tensor_mass";
    let _ = '"';
    let _ = super::super::contact::Contact::default();
    crate::table::format::HEADER_LEN;
    'x'
}
"#;
    let code = code_only(source);
    let module = ["contact".to_owned(), "geometry".to_owned()];
    let segments: Vec<String> = root_references(&code, &module)
        .into_iter()
        .map(|(_, s)| s)
        .collect();
    assert_eq!(
        segments,
        ["Real", "math", "haptic", "table", "contact"],
        "code: {code}"
    );
    assert!(allowed("contact", "table") && allowed("haptic", "precomputed"));
    assert!(!allowed("contact", "haptic") && !allowed("precomputed", "tensor_mass"));
    assert!(allowed("tensor_mass", "tensor_mass"));
}
