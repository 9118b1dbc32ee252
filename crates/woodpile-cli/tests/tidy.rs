//! The tree as ARCHITECTURE.md describes it, checked so that it stays true: every crate and
//! top-level module is named in the code map, every path it names exists, no module imports another in a circle, files and functions stay short,
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

/// ARCHITECTURE.md's section on one source root: from the `### ` heading that names it (the
/// crate's folder, or `python/` for the Python module) to the next heading.
fn section_on<'a>(map: &'a str, krate: &str) -> &'a str {
    let heading = match krate {
        "woodpile-py" => "### `python/`".to_string(),
        name => format!("### `crates/{name}`"),
    };
    let Some(start) = map.find(&heading) else {
        return "";
    };
    let body = &map[start + heading.len()..];
    let end = [body.find("\n### "), body.find("\n## ")]
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(body.len());
    &body[..end]
}

/// The top-level modules of a source root: each file's stem and each folder's name below
/// `src/` (a folder beside its `name.rs` holds that module's children), without the crate
/// root.
fn top_level_modules(root: &Path) -> BTreeSet<String> {
    std::fs::read_dir(root)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter_map(|path| {
            let stem = path.file_stem()?.to_string_lossy().into_owned();
            let module = path.is_dir() || path.extension().is_some_and(|e| e == "rs");
            (module && stem != "lib").then_some(stem)
        })
        .collect()
}

/// Every crate has its section in the code map, and names each of its top-level modules
/// there (`force.rs`, or `integrate/` for a folder): the map may leave a module's children to
/// its docs, but not a module.
#[test]
fn every_crate_and_top_level_module_is_in_the_code_map() {
    let map = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
    let mut missing = Vec::new();
    for (krate, root) in source_roots() {
        let section = section_on(&map, &krate);
        if section.is_empty() {
            missing.push(format!("{krate}: no section"));
            continue;
        }
        for module in top_level_modules(&root) {
            let named = [format!("`{module}.rs`"), format!("`{module}/`")]
                .iter()
                .any(|spelling| section.contains(spelling.as_str()));
            if !named {
                missing.push(format!("{krate}: {module}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md's code map does not name these in their crate's section: {missing:#?}"
    );
}

/// The paths a section names: every backquoted word ending in `.rs` or `/`.
fn named_paths(section: &str) -> Vec<&str> {
    section
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|word| !word.contains(' ') && (word.ends_with(".rs") || word.ends_with('/')))
        .collect()
}

/// Every path the code map names exists, in its crate's `src/` or beside it (`examples/`):
/// a renamed or deleted file cannot leave the map pointing at nothing.
#[test]
fn every_path_the_code_map_names_exists() {
    let map = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
    let mut stale = Vec::new();
    for (krate, root) in source_roots() {
        let section = section_on(&map, &krate);
        let package = root.parent().unwrap();
        for path in named_paths(section) {
            if !root.join(path).exists() && !package.join(path).exists() {
                stale.push(format!("{krate}: {path}"));
            }
        }
    }
    assert!(named_paths(section_on(&map, "woodpile-sim")).len() > 10);
    assert!(
        stale.is_empty(),
        "ARCHITECTURE.md names paths that do not exist: {stale:#?}"
    );
}

/// The crates each crate depends on, as ARCHITECTURE.md's layering table says (short names:
/// `sim` for `woodpile-sim`).
fn layering_table() -> BTreeMap<String, BTreeSet<String>> {
    let map = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
    map.lines()
        .filter_map(|line| {
            let cells: Vec<&str> = line.trim().trim_matches('|').split('|').collect();
            let krate = cells
                .first()?
                .trim()
                .strip_prefix("`woodpile-")?
                .strip_suffix('`')?;
            let deps = cells
                .get(1)?
                .split(',')
                .map(str::trim)
                .filter(|d| !d.is_empty() && *d != "—")
                .map(String::from)
                .collect();
            Some((krate.to_string(), deps))
        })
        .collect()
}

/// The workspace crates a `Cargo.toml` lists among its dependencies (not dev-dependencies).
fn workspace_dependencies(manifest: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(manifest).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let own = table["package"]["name"].as_str().unwrap().to_string();
    table
        .get("dependencies")
        .and_then(|d| d.as_table())
        .into_iter()
        .flat_map(|d| d.keys())
        .filter(|k| k.starts_with("woodpile-") && **k != own)
        .map(|k| k.trim_start_matches("woodpile-").to_string())
        .collect()
}

/// ARCHITECTURE.md's layering table is the crate graph: every crate is in it, with exactly
/// the workspace crates its `Cargo.toml` depends on.
#[test]
fn the_layering_table_is_the_crate_graph() {
    let table = layering_table();
    let mut manifests: Vec<PathBuf> = std::fs::read_dir(repo().join("crates"))
        .unwrap()
        .flatten()
        .map(|e| e.path().join("Cargo.toml"))
        .filter(|p| p.is_file())
        .collect();
    manifests.push(repo().join("python/Cargo.toml"));
    let mut wrong = Vec::new();
    let mut seen = BTreeSet::new();
    for manifest in manifests {
        let text: toml::Table = std::fs::read_to_string(&manifest).unwrap().parse().unwrap();
        let name = text["package"]["name"].as_str().unwrap();
        let short = name.trim_start_matches("woodpile-").to_string();
        seen.insert(short.clone());
        let actual = workspace_dependencies(&manifest);
        match table.get(&short) {
            Some(said) if *said == actual => {}
            said => wrong.push(format!(
                "{name}: the table says {said:?}, Cargo.toml {actual:?}"
            )),
        }
    }
    wrong.extend(
        table
            .keys()
            .filter(|k| !seen.contains(*k))
            .map(|k| format!("woodpile-{k}: in the table, but no such crate")),
    );
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The engine caches, seals, shards and diffs a results tree without linking the simulator:
/// none of the crates it reaches, directly or through another, is the simulator, the scene
/// format or the point simulation (ARCHITECTURE.md's bird's-eye view says so).
#[test]
fn the_engine_links_no_simulator() {
    let table = layering_table();
    assert!(table.contains_key("pipeline"), "the engine is in the table");
    let mut reached = BTreeSet::new();
    let mut todo = vec!["pipeline".to_string()];
    while let Some(krate) = todo.pop() {
        for dep in table.get(&krate).into_iter().flatten() {
            if reached.insert(dep.clone()) {
                todo.push(dep.clone());
            }
        }
    }
    let simulating: Vec<_> = ["sim", "scene", "points"]
        .into_iter()
        .filter(|k| reached.contains(*k))
        .collect();
    assert!(
        simulating.is_empty(),
        "the engine reaches {simulating:?} (through {reached:?})"
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
    let compact = without_space_in_groups(code);
    let words: Vec<&str> = compact
        .split(|c: char| {
            !(c.is_alphanumeric() || c == '_' || c == ':' || c == '{' || c == '}' || c == ',')
        })
        .filter(|w| w.starts_with("crate::") || w.starts_with("super::"))
        .collect();
    for word in words {
        let (base, rest) = match word.split_once("::") {
            Some(("crate", rest)) => (Vec::new(), rest),
            Some((_, rest)) => (module[..module.len().saturating_sub(1)].to_vec(), rest),
            None => continue,
        };
        let targets: Vec<Vec<String>> = expand_use(rest)
            .into_iter()
            .map(|path| {
                let mut full = base.clone();
                full.extend(path);
                full
            })
            .collect();
        for target in targets {
            if let Some(k) = (1..=target.len())
                .rev()
                .find(|&k| modules.contains(&target[..k]))
            {
                let found = &target[..k];
                let related = module.starts_with(found) || found.starts_with(module);
                if !related {
                    out.insert(found.to_vec());
                }
            }
        }
    }
    out
}

/// `code` with the white space inside `use` groups (`::{ a,\n b }`) removed, so that a group
/// reads as one word whatever its layout.
fn without_space_in_groups(code: &str) -> String {
    let mut out = String::with_capacity(code.len());
    let mut depth = 0usize;
    for c in code.chars() {
        match c {
            '{' if out.ends_with("::") || depth > 0 => depth += 1,
            '}' if depth > 0 => depth -= 1,
            c if c.is_whitespace() && depth > 0 => continue,
            _ => {}
        }
        out.push(c);
    }
    out
}

/// The paths a `use` tree names (`a::{b, c::{d, e}}` → a::b, a::c::d, a::c::e, and a
/// itself), each as its segments.
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    let tree = tree.trim_end_matches([',', ';']);
    // The first brace opens this level's group: `a::{b, c::{d}}` or, after `crate::`, `{a, b}`.
    let Some(open) = tree.find('{') else {
        let path: Vec<String> = tree
            .split("::")
            .filter(|s| !s.is_empty() && *s != "self")
            .map(String::from)
            .collect();
        return vec![path];
    };
    let head: Vec<String> = tree[..open]
        .trim_end_matches("::")
        .split("::")
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    let inner = tree[open + 1..]
        .strip_suffix('}')
        .unwrap_or(&tree[open + 1..]);
    let mut out = vec![head.clone()];
    for branch in split_top_level(inner) {
        for tail in expand_use(branch) {
            let mut path = head.clone();
            path.extend(tail);
            out.push(path);
        }
    }
    out
}

/// The `use` reader expands nested groups, after `crate::` as after a path.
#[test]
fn use_groups_are_expanded_whole() {
    let paths = |tree: &str| -> Vec<String> {
        expand_use(tree).into_iter().map(|p| p.join("::")).collect()
    };
    assert_eq!(paths("{a::{b,c},d}"), ["", "a", "a::b", "a::c", "d"]);
    assert_eq!(paths("x::{y,z::{w}}"), ["x", "x::y", "x::z", "x::z::w"]);
    assert_eq!(paths("a::b;"), ["a::b"]);
}

/// `a, b::{c, d}, e` split at its top-level commas.
fn split_top_level(list: &str) -> Vec<&str> {
    let (mut out, mut depth, mut start) = (Vec::new(), 0usize, 0);
    for (k, c) in list.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth = depth.saturating_sub(1),
            ',' if depth == 0 => {
                out.push(&list[start..k]);
                start = k + 1;
            }
            _ => {}
        }
    }
    out.push(&list[start..]);
    out.into_iter().filter(|s| !s.is_empty()).collect()
}

/// Sibling and unrelated modules never import each other in a circle. A module and its own
/// ancestor may (a child uses what its parent defines, and the parent re-exports the child):
/// that edge is not counted.
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

/// Most lines a source file may hold, tests included: past this a file does more than one job
/// (split it into a folder of modules, as `model/` and `optimize/` are).
const MAX_FILE_LINES: usize = 500;

#[test]
fn no_source_file_runs_over_500_lines() {
    let mut long = Vec::new();
    for (krate, root) in source_roots() {
        for file in rust_files(&root) {
            let lines = std::fs::read_to_string(&file).unwrap().lines().count();
            if lines > MAX_FILE_LINES {
                let rel = file.strip_prefix(&root).unwrap().display().to_string();
                long.push(format!("{krate}: {rel} ({lines} lines)"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "files over {MAX_FILE_LINES} lines: {long:#?}"
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
            "--document-private-items",
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
