//! The documents a newcomer walks through: every relative link in
//! `README.md`, `ARCHITECTURE.md`, `CHANGELOG.md`, `tools/README.md` and
//! `docs/` resolves to a file of the repository, and a `#anchor` into a
//! markdown file to one of its headings (named as GitHub names them);
//! `ARCHITECTURE.md` names every source folder by its path, and every
//! repository path and file name it gives exists.
//!
//! The truth is the file tree itself. The scanner is plain string work
//! (fenced code blocks and inline code spans are not links); its own tests
//! feed it a document with known good and broken links.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The documents checked: the top-level ones and every markdown file under
/// `docs/`, sorted.
fn documents() -> Vec<PathBuf> {
    let root = repository();
    let mut docs: Vec<PathBuf> = [
        "README.md",
        "ARCHITECTURE.md",
        "CHANGELOG.md",
        "tools/README.md",
    ]
    .iter()
    .map(|name| root.join(name))
    .collect();
    let mut markdown = Vec::new();
    files_under(&root.join("docs"), &mut markdown);
    markdown.retain(|path| path.extension().is_some_and(|ext| ext == "md"));
    markdown.sort();
    docs.extend(markdown);
    docs
}

/// Every file under `dir`, recursively, without build outputs (`target`).
fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.file_name().is_some_and(|n| n == "target") {
            continue;
        }
        if path.is_dir() {
            files_under(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// The sub-folders of `dir` (recursively when `deep`), as paths relative
/// to the repository with `/` separators, without hidden folders and
/// build outputs (`target`).
fn folders_under(dir: &str, deep: bool, out: &mut Vec<String>) {
    let root = repository();
    for entry in fs::read_dir(root.join(dir)).unwrap_or_else(|e| panic!("{dir}: {e}")) {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().into_owned();
        if !entry.path().is_dir() || name.starts_with('.') || name == "target" {
            continue;
        }
        let path = format!("{dir}/{name}");
        if deep {
            folders_under(&path, deep, out);
        }
        out.push(path);
    }
}

/// The lines of a markdown document outside fenced code blocks, grouped by
/// paragraph (a code span never crosses a blank line), each with its
/// 1-based line number.
fn paragraphs(text: &str) -> Vec<Vec<(usize, &str)>> {
    let mut out = Vec::new();
    let mut current = Vec::new();
    let mut fence: Option<&str> = None;
    for (index, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let marker = if trimmed.starts_with("```") {
            Some("```")
        } else if trimmed.starts_with("~~~") {
            Some("~~~")
        } else {
            None
        };
        match (fence, marker) {
            (None, Some(m)) => {
                fence = Some(m);
                out.push(core::mem::take(&mut current));
            }
            (Some(open), Some(m)) if open == m => fence = None,
            (Some(_), _) => {}
            (None, None) if trimmed.is_empty() => out.push(core::mem::take(&mut current)),
            (None, None) => current.push((index + 1, line)),
        }
    }
    out.push(current);
    out.retain(|p| !p.is_empty());
    out
}

/// The link targets of one paragraph, with their line: `[text](target)`,
/// `![alt](target)` and `[label]: target` definitions, outside inline code
/// spans (a run of `n` backticks up to the next run of exactly `n`).
fn link_targets(paragraph: &[(usize, &str)]) -> Vec<(usize, String)> {
    // The paragraph's characters, each with its line.
    let chars: Vec<(usize, char)> = paragraph
        .iter()
        .flat_map(|&(line, text)| text.chars().chain(['\n']).map(move |c| (line, c)))
        .collect();
    let run_at = |i: usize| chars[i..].iter().take_while(|&&(_, c)| c == '`').count();
    let mut targets = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let (line, c) = chars[i];
        if c == '`' {
            let n = run_at(i);
            // The closing run of exactly n backticks, if any.
            let mut j = i + n;
            let mut close = None;
            while j < chars.len() {
                if chars[j].1 == '`' {
                    let m = run_at(j);
                    if m == n {
                        close = Some(j + m);
                        break;
                    }
                    j += m;
                } else {
                    j += 1;
                }
            }
            i = close.unwrap_or(i + n);
            continue;
        }
        let target_from = if c == ']' && chars.get(i + 1).map(|&(_, c)| c) == Some('(') {
            Some((i + 2, ')'))
        } else if c == ']'
            && chars.get(i + 1).map(|&(_, c)| c) == Some(':')
            && definition_starts(&chars, i)
        {
            Some((i + 2, '\n'))
        } else {
            None
        };
        if let Some((start, end)) = target_from {
            let mut depth = 0usize;
            let mut j = start;
            let mut target = String::new();
            while let Some(&(_, d)) = chars.get(j) {
                if d == end && depth == 0 || d == '\n' {
                    break;
                }
                if d == '(' {
                    depth += 1;
                } else if d == ')' {
                    depth = depth.saturating_sub(1);
                }
                target.push(d);
                j += 1;
            }
            // A title (`(path "title")`) follows the target after a space.
            let target = target.split_whitespace().next().unwrap_or("").to_string();
            let target = target.trim_matches(['<', '>']).to_string();
            if !target.is_empty() {
                targets.push((line, target));
            }
            i = j;
            continue;
        }
        i += 1;
    }
    targets
}

/// Whether the `]` at `close` ends a `[label]` that starts its line (a
/// reference definition `[label]: target`).
fn definition_starts(chars: &[(usize, char)], close: usize) -> bool {
    let line_start = chars[..close]
        .iter()
        .rposition(|&(_, c)| c == '\n')
        .map_or(0, |p| p + 1);
    let before: String = chars[line_start..close].iter().map(|&(_, c)| c).collect();
    let before = before.trim_start();
    before.starts_with('[') && !before.contains(']')
}

/// The anchor GitHub gives a heading: lower case, every character other
/// than a letter, digit, `_`, `-` or space dropped, spaces turned into `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            '_' | '-' => Some(c),
            c if c.is_alphanumeric() => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a markdown document's headings (outside fenced code), a
/// repeated heading's `-1`, `-2`, … as GitHub numbers them.
fn anchors(text: &str) -> Vec<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = Vec::new();
    for paragraph in paragraphs(text) {
        for &(_, line) in &paragraph {
            let hashes = line.chars().take_while(|&c| c == '#').count();
            let Some(rest) = line.get(hashes..) else {
                continue;
            };
            if !(1..=6).contains(&hashes) || !rest.starts_with(' ') {
                continue;
            }
            let base = slug(rest.trim().trim_end_matches('#'));
            let count = seen.entry(base.clone()).or_insert(0);
            out.push(if *count == 0 {
                base.clone()
            } else {
                format!("{base}-{count}")
            });
            *count += 1;
        }
    }
    out
}

/// The broken relative links of the document `doc` whose text is `text`,
/// each as `doc:line: target (why)`. Absolute URLs are not followed.
fn broken_links(doc: &Path, text: &str) -> Vec<String> {
    let dir = doc.parent().unwrap();
    let name = doc
        .strip_prefix(repository())
        .unwrap_or(doc)
        .display()
        .to_string();
    let mut broken = Vec::new();
    for paragraph in paragraphs(text) {
        for (line, target) in link_targets(&paragraph) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((path, anchor)) => (path, Some(anchor)),
                None => (target.as_str(), None),
            };
            let file = if path.is_empty() {
                doc.to_path_buf()
            } else {
                dir.join(path)
            };
            if !file.exists() {
                broken.push(format!("{name}:{line}: {target} (no such file)"));
                continue;
            }
            let Some(anchor) = anchor else { continue };
            if file.extension().is_none_or(|ext| ext != "md") {
                continue;
            }
            let target_text = fs::read_to_string(&file).unwrap();
            if !anchors(&target_text).iter().any(|a| a == anchor) {
                broken.push(format!("{name}:{line}: {target} (no such heading)"));
            }
        }
    }
    broken
}

#[test]
fn every_relative_link_resolves() {
    let docs = documents();
    // The index and at least the topic pages the README links to are there.
    assert!(docs.len() >= 10, "too few documents found: {docs:?}");
    let mut broken = Vec::new();
    let mut links = 0;
    for doc in &docs {
        let text = fs::read_to_string(doc).unwrap_or_else(|e| panic!("{}: {e}", doc.display()));
        links += paragraphs(&text)
            .iter()
            .map(|p| link_targets(p).len())
            .sum::<usize>();
        broken.extend(broken_links(doc, &text));
    }
    // The README alone links every page of docs/: a scan that finds no
    // link has stopped reading.
    assert!(links >= 40, "only {links} links found");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_scanner_finds_broken_links_and_skips_code() {
    let doc = repository().join("README.md");
    let text = "See [the map](ARCHITECTURE.md#invariants-worth-knowing) and ![a chart](docs/chart/volume.png).\n\
        A [gone file](no-such-file.md), `[in code](nope.md)` and a span\n\
        ``with ` inside [x](nope2.md)`` then [a bad heading](ARCHITECTURE.md#no-such-heading).\n\
        \n\
        ```text\n\
        [in a fence](nope3.md)\n\
        ```\n\
        [web](https://example.com/x.md) [here](#a-ten-minute-tour) [nowhere](#no-such-anchor)\n\
        \n\
        [label]: also-missing.md\n";
    let broken = broken_links(&doc, text);
    assert_eq!(
        broken,
        [
            "README.md:2: no-such-file.md (no such file)",
            "README.md:3: ARCHITECTURE.md#no-such-heading (no such heading)",
            "README.md:8: #no-such-anchor (no such heading)",
            "README.md:10: also-missing.md (no such file)",
        ]
    );
}

#[test]
fn headings_get_githubs_anchors() {
    // Anchors as github.com renders them for these headings of the docs.
    assert_eq!(
        slug("The hybrid model (MODELS.md §5; RR-3510 §6.2)"),
        "the-hybrid-model-modelsmd-5-rr-3510-62"
    );
    assert_eq!(
        slug("Scenes that model no more than they need: `palpate scene plan`"),
        "scenes-that-model-no-more-than-they-need-palpate-scene-plan"
    );
    assert_eq!(slug("snake_case and `C_nk`"), "snake_case-and-c_nk");
    assert_eq!(
        anchors("# A\n## B\n```\n# not a heading\n```\n## B\n#no\n"),
        ["a", "b", "b-1"]
    );
}

#[test]
fn architecture_names_every_source_folder() {
    let text = fs::read_to_string(repository().join("ARCHITECTURE.md")).unwrap();
    let mut folders = Vec::new();
    for root in ["kernel/src", "host-harness/src", "ffi/src"] {
        folders_under(root, true, &mut folders);
    }
    folders_under("tools", false, &mut folders);
    // Non-vacuous: the kernel's layers and the tools' crates were found.
    for known in [
        "kernel/src/haptic",
        "host-harness/src/chart",
        "tools/cycles",
    ] {
        assert!(folders.iter().any(|f| f == known), "{known} not found");
    }
    let missing: Vec<&String> = folders
        .iter()
        .filter(|folder| !text.contains(&format!("{folder}/")))
        .collect();
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md does not name these folders: {missing:?}"
    );
}

/// The paths `ARCHITECTURE.md` gives, and the file names a table row lists
/// for its one folder, exist (a renamed file is not left on the map).
#[test]
fn architecture_names_only_what_exists() {
    let root = repository();
    let text = fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let roots = [
        "kernel/",
        "host-harness/",
        "ffi/",
        "tools/",
        "tests/",
        "benches/",
        "fuzz/",
        "docs/",
    ];
    let mut missing = Vec::new();
    // Whole paths anywhere (the diagrams, the table, the prose).
    for token in text.split(|c: char| c.is_whitespace() || "`()[],;|".contains(c)) {
        let token = token.trim_end_matches(['.', ':']);
        if roots.iter().any(|r| token.starts_with(r))
            && !token.contains(['{', '*', '…', '<'])
            && !root.join(token).exists()
        {
            missing.push(token.to_string());
        }
    }
    // File names in a row of the table whose first cell is one folder: each
    // is somewhere under that folder.
    let mut rows = 0;
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').collect();
        let (Some(first), Some(rest)) = (cells.get(1), cells.get(2)) else {
            continue;
        };
        let first = first.trim();
        let Some(folder) = first
            .strip_prefix('`')
            .and_then(|f| f.strip_suffix("/`"))
            .filter(|f| !f.contains(['`', ',', '*']))
        else {
            continue;
        };
        let mut files = Vec::new();
        files_under(&root.join(folder), &mut files);
        rows += 1;
        for name in rest.split('`').skip(1).step_by(2) {
            let is_file = [".rs", ".c", ".h", ".toml", ".sh", ".py", ".ld", ".S"]
                .iter()
                .any(|ext| name.ends_with(ext));
            if !is_file || name.contains(['/', ' ', '*']) {
                continue;
            }
            if !files
                .iter()
                .any(|f| f.file_name().is_some_and(|n| n == name))
            {
                missing.push(format!("{folder}/…/{name}"));
            }
        }
    }
    assert!(rows >= 15, "only {rows} folder rows read");
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md names what does not exist: {missing:?}"
    );
}
