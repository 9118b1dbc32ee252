//! Property tests on hostile input: the project's own scene and stage files, mutated at random
//! (seeded, so every failure replays), must each either load or be refused with an error that
//! names the file (and, for a bad value, the key): never a panic, never unbounded memory.
//!
//! Mutations work on the text, the way people and scripts damage files: a number replaced by
//! an extreme one, a line deleted or repeated, a key line inserted from a vocabulary of real
//! keys with wild values, a truncation, a byte overwritten.
#![allow(clippy::unwrap_used)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use woodpile_stages::KINDS;

use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::PipelineError;
use woodpile_scene::SceneError;

/// xorshift64*: a seeded generator, enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }
}

const NUMBERS: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1e308",
    "-1e308",
    "1e-308",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "1e12",
    "1e7",
    "3.5",
    "0.5",
    "100000",
];

const KEY_LINES: &[&str] = &[
    "[[defect]]\nsite = 0\neps = 1e-300",
    "[[defect]]\nsite = 99999999\neps = 1.0",
    "[run]\nt_end = 1e12",
    "t_end = 1e9",
    "dt = 1e-300",
    "tolerance = 1e-30",
    "sample_every = 1e-12",
    "method = \"dop853\"",
    "method = \"nope\"",
    "velocity = 0",
    "p = 101",
    "kappa = { k1 = 0.0, k2 = 1e300, t0 = 1.0, tau = 1e-300 }",
    "through = 99999999",
    "n = 5000000",
    "sites = [-9223372036854775808, 9223372036854775807]",
    "region = [5, -5]",
    "inputs = [\"nope\"]",
    "inputs = [\"f4_sweep\", \"f4_sweep\"]",
    "kind = \"nope\"",
    "markdown = \"../../x.md\"",
    "markdown = \"/tmp/x.md\"",
    "eps = { from = 0.0, to = 1e12, step = 1e-6 }",
    "eps = [1.5, 1.5, 1.5, 1.5]",
    "at = -1.0",
    "x = \"$nope\"",
    "[axes]\na = { from = 0, to = 1e9, step = 1 }\nb = { from = 0, to = 1e9, step = 1 }",
];

/// One random mutation of `text`.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let i = rng.below(lines.len());
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    match rng.below(6) {
        0 => {
            // Replace one number on a line that has one.
            let numeric: Vec<usize> = (0..out.len())
                .filter(|&j| out[j].contains(|c: char| c.is_ascii_digit()))
                .collect();
            if let Some(&j) = numeric.get(rng.below(numeric.len())) {
                let line = &out[j];
                let start = line
                    .find(|c: char| c.is_ascii_digit() || c == '-')
                    .unwrap_or(0);
                let end = line[start..]
                    .find(|c: char| !(c.is_ascii_alphanumeric() || "-+.".contains(c)))
                    .map_or(line.len(), |e| start + e);
                out[j] = format!("{}{}{}", &line[..start], rng.pick(NUMBERS), &line[end..]);
            }
        }
        1 if !out.is_empty() => {
            out.remove(i);
        }
        2 if !out.is_empty() => {
            let line = out[i].clone();
            out.insert(i, line);
        }
        3 => out.insert(i.min(out.len()), rng.pick(KEY_LINES).to_string()),
        4 => {
            let joined = out.join("\n");
            let mut cut = rng.below(joined.len() + 1);
            while !joined.is_char_boundary(cut) {
                cut -= 1;
            }
            return joined[..cut].to_string();
        }
        _ => {
            let mut bytes = out.join("\n").into_bytes();
            if !bytes.is_empty() {
                let at = rng.below(bytes.len());
                bytes[at] = b"=[]{}\"'.,#$x0\n"[rng.below(14)];
            }
            return String::from_utf8_lossy(&bytes).into_owned();
        }
    }
    out.join("\n")
}

fn toml_files(dir: &Path) -> Vec<(PathBuf, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|x| x == "toml") {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(dir, &mut files);
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect()
}

fn repo(dir: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(dir)
}

/// Largest resident memory this process has had, in bytes (Linux; `None` elsewhere).
fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

const MEMORY_BOUND: u64 = 2 << 30;

#[test]
fn mutated_scene_files_load_or_are_refused_naming_file_and_key() {
    let seeds = toml_files(&repo("scenes"));
    assert!(!seeds.is_empty());
    let mut rng = Rng(0x5eed_0001);
    let (mut loaded, mut refused) = (0, 0);
    for case in 0..3000 {
        let (path, text) = &seeds[case % seeds.len()];
        let mut mutant = mutate(text, &mut rng);
        if rng.below(3) == 0 {
            mutant = mutate(&mutant, &mut rng);
        }
        let result = catch_unwind(AssertUnwindSafe(|| woodpile_scene::parse(&mutant, path)));
        let Ok(result) = result else {
            panic!("case {case}: parsing panicked on\n{mutant}");
        };
        match result {
            Ok(scene) => {
                loaded += 1;
                // A scene that loads is within the simulator's budgets.
                assert!(
                    woodpile_sim::simulation::budget::check(&scene.scenario).is_ok(),
                    "case {case}: loaded a scene beyond budget:\n{mutant}"
                );
            }
            Err(e) => {
                refused += 1;
                let message = e.to_string();
                assert!(
                    message.starts_with(&path.display().to_string()),
                    "case {case}: `{message}` does not name the file"
                );
                if let SceneError::Invalid { key, reason, .. } = &e {
                    assert!(!key.is_empty() && !reason.is_empty(), "case {case}: {e}");
                }
            }
        }
    }
    assert!(
        loaded > 100 && refused > 100,
        "{loaded} loaded, {refused} refused"
    );
    if let Some(peak) = peak_memory() {
        assert!(peak < MEMORY_BOUND, "peak memory {peak} bytes");
    }
}

#[test]
fn mutated_stage_files_load_or_are_refused_naming_file_and_key() {
    let seeds = toml_files(&repo("pipeline"));
    assert!(seeds.len() > 40);
    let mut rng = Rng(0x5eed_0002);
    let (mut loaded, mut refused) = (0, 0);
    for case in 0..2000 {
        let (path, text) = &seeds[case % seeds.len()];
        let mutant = mutate(text, &mut rng);
        let result = catch_unwind(AssertUnwindSafe(|| Stage::parse(&mutant, path, KINDS)));
        let Ok(result) = result else {
            panic!(
                "case {case}: parsing panicked on {}:\n{mutant}",
                path.display()
            );
        };
        match result {
            Ok(_) => loaded += 1,
            Err(e) => {
                refused += 1;
                let message = e.to_string();
                assert!(
                    message.contains(&path.display().to_string()),
                    "case {case}: `{message}` does not name the file"
                );
                if let PipelineError::Definition { key, reason, .. } = &e {
                    assert!(!reason.is_empty(), "case {case}: {e} (key `{key}`)");
                }
            }
        }
    }
    assert!(
        loaded > 100 && refused > 100,
        "{loaded} loaded, {refused} refused"
    );
    if let Some(peak) = peak_memory() {
        assert!(peak < MEMORY_BOUND, "peak memory {peak} bytes");
    }
}
