//! The tree as ARCHITECTURE.md describes it, checked so that it stays true: every source file
//! is named in the code map, no module imports another in a circle, functions stay short,
//! and rustdoc finds every intra-doc link. A newcomer reads the map and the module docs first;
//! these tests keep them from going stale.
#![allow(clippy::unwrap_used)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every crate's source folder, and the Python module's: (label, folder).
fn source_roots() -> Vec<(String, PathBuf)> {
    let mut roots: Vec<(String, PathBuf)> = std::fs::read_dir(repo().join("crates"))
        .unwrap()
        .flatten()
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                e.path().join("src"),
            )
        })
        .filter(|(_, src)| src.is_dir())
        .collect();
    roots.push(("woodpile-py".into(), repo().join("python/src")));
    roots.sort();
    roots
}

/// The `.rs` files below `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out.sort();
    out
}

/// A file's code, without comments and without its `#[cfg(test)]` module (tests may reach
/// anywhere).
fn code_of(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.split("#[cfg(test)]").next().unwrap_or_default();
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn every_source_file_is_in_the_code_map() {
    let map = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
    let mut missing = Vec::new();
    for (_, root) in source_roots() {
        for file in rust_files(&root) {
            let rel = file.strip_prefix(&root).unwrap();
            let parts: Vec<String> = rel
                .iter()
                .map(|p| p.to_string_lossy().into_owned())
                .collect();
            let name = parts.last().unwrap().clone();
            let mut spellings = vec![format!("`{name}`"), format!("`{}`", parts.join("/"))];
            if name == "mod.rs" {
                spellings.push(format!("`{}/`", parts[..parts.len() - 1].join("/")));
            }
            spellings.push(format!("`src/{}`", parts.join("/")));
            if !spellings.iter().any(|s| map.contains(s.as_str())) {
                missing.push(
                    file.strip_prefix(repo())
                        .unwrap_or(&file)
                        .display()
                        .to_string(),
                );
            }
        }
    }
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md's code map does not name: {missing:?}"
    );
}

/// A module's path in its crate (`report::markdown`), from its file.
fn module_of(root: &Path, file: &Path) -> Vec<String> {
    let mut parts: Vec<String> = file
        .strip_prefix(root)
        .unwrap()
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("lib" | "main" | "mod")
    ) {
        parts.pop();
    }
    parts
}

/// The modules of its crate that a module's code names (`crate::a::b`, `super::c`,
/// `use super::{d, e}`), resolved to the longest prefix that is a module file.
fn imports(
    code: &str,
    module: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    let words: Vec<&str> = code
        .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':' || c == '{' || c == ','))
        .filter(|w| w.starts_with("crate::") || w.starts_with("super::"))
        .collect();
    for word in words {
        let (base, rest) = match word.split_once("::") {
            Some(("crate", rest)) => (Vec::new(), rest),
            Some((_, rest)) => (module[..module.len().saturating_sub(1)].to_vec(), rest),
            None => continue,
        };
        let (head, group) = match rest.split_once('{') {
            Some((head, group)) => (head, Some(group)),
            None => (rest, None),
        };
        let mut path = base;
        path.extend(head.split("::").filter(|s| !s.is_empty()).map(String::from));
        let mut targets = vec![path.clone()];
        for name in group.into_iter().flat_map(|g| g.split(',')) {
            let mut with = path.clone();
            with.push(name.trim().to_string());
            targets.push(with);
        }
        for target in targets {
            if let Some(k) = (1..=target.len())
                .rev()
                .find(|&k| modules.contains(&target[..k]))
            {
                if target[..k] != *module {
                    out.insert(target[..k].to_vec());
                }
            }
        }
    }
    out
}

#[test]
fn no_module_imports_another_in_a_circle() {
    let mut cycles = Vec::new();
    for (krate, root) in source_roots() {
        let files = rust_files(&root);
        let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&root, f)).collect();
        let graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = files
            .iter()
            .map(|f| {
                let module = module_of(&root, f);
                let edges = imports(&code_of(f), &module, &modules);
                (module, edges)
            })
            .collect();
        // A module reaches itself through others: a circle.
        for start in graph.keys() {
            let mut seen = BTreeSet::new();
            let mut stack: Vec<&Vec<String>> = graph[start].iter().collect();
            while let Some(m) = stack.pop() {
                if m == start {
                    cycles.push(format!("{krate}: {}", start.join("::")));
                    break;
                }
                if seen.insert(m) {
                    stack.extend(graph.get(m).into_iter().flatten());
                }
            }
        }
    }
    assert!(
        cycles.is_empty(),
        "modules that import themselves through others: {cycles:?}"
    );
}

/// Most lines a function may run to (signature to closing brace).
const MAX_FUNCTION_LINES: usize = 80;

/// Functions longer than that when the limit came in, with their length then: each may only
/// shrink, and leaves this list once it is within the limit. Phases instead of long functions
/// is the work these name.
const LONGER_FOR_NOW: &[(&str, &str, usize)] = &[];

/// Every function of `code` as (name, lines), found by its `fn` line and the closing brace at
/// the same indent.
fn functions(code: &str) -> Vec<(String, usize)> {
    let lines: Vec<&str> = code.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let indent = line.len() - line.trim_start().len();
        let words: Vec<&str> = line.split_whitespace().collect();
        let at = words.iter().position(|w| *w == "fn");
        let is_fn = at.is_some_and(|k| {
            words[..k]
                .iter()
                .all(|w| w.starts_with("pub") || ["const", "async", "unsafe"].contains(w))
        });
        if !is_fn {
            i += 1;
            continue;
        }
        let name: String = words[at.unwrap() + 1]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let Some(open) = (i..lines.len())
            .find(|&j| lines[j].contains('{') || lines[j].trim_end().ends_with(';'))
        else {
            break;
        };
        if !lines[open].contains('{') {
            i = open + 1;
            continue;
        }
        let close = format!("{}}}", " ".repeat(indent));
        let end = (open..lines.len())
            .find(|&j| lines[j].trim_end() == close)
            .unwrap_or(lines.len() - 1);
        out.push((name, end - i + 1));
        i = end + 1;
    }
    out
}

#[test]
fn functions_stay_short() {
    let mut too_long = Vec::new();
    let mut now_short = Vec::new();
    for (krate, root) in source_roots() {
        for file in rust_files(&root) {
            let rel = file
                .strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .into_owned();
            // Functions of one name in one file (a kind's `run` and its trait's) count as
            // their longest.
            let mut longest: BTreeMap<String, usize> = BTreeMap::new();
            for (name, lines) in functions(&code_of(&file)) {
                let entry = longest.entry(name).or_default();
                *entry = (*entry).max(lines);
            }
            for (name, lines) in longest {
                let at = format!("{rel}:{name}");
                let cap = LONGER_FOR_NOW
                    .iter()
                    .find(|(k, f, _)| *k == krate && *f == at)
                    .map(|(_, _, n)| *n);
                match cap {
                    Some(cap) if lines <= MAX_FUNCTION_LINES => {
                        now_short.push(format!("{krate} {at} ({lines}, listed at {cap})"))
                    }
                    Some(cap) if lines > cap => {
                        too_long.push(format!("{krate} {at}: {lines} lines, listed at {cap}"))
                    }
                    None if lines > MAX_FUNCTION_LINES => too_long.push(format!(
                        "{krate} {at}: {lines} lines, more than {MAX_FUNCTION_LINES}"
                    )),
                    _ => {}
                }
            }
        }
    }
    assert!(too_long.is_empty(), "functions too long: {too_long:#?}");
    assert!(
        now_short.is_empty(),
        "within the limit now: take them off LONGER_FOR_NOW: {now_short:#?}"
    );
}

/// rustdoc resolves every intra-doc link of the workspace's documentation (a renamed or moved
/// item otherwise leaves the entry docs pointing at nothing). Runs `cargo doc` into a target
/// folder of its own, so it never waits on the one running this test.
#[test]
fn intra_doc_links_resolve() {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| repo().join("target"), PathBuf::from)
        .join("tidy-doc");
    let out = std::process::Command::new(cargo)
        .current_dir(repo())
        .args([
            "doc",
            "--workspace",
            "--no-deps",
            "--exclude",
            "woodpile-py",
            "--quiet",
        ])
        .arg("--target-dir")
        .arg(&target)
        .env("RUSTDOCFLAGS", "-D rustdoc::broken_intra_doc_links")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "broken intra-doc links:\n{stderr}");
}
