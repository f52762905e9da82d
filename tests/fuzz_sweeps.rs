//! Fuzzed sweep files through parse and plan (proptest, fixed seed): mutated copies of the
//! sweeps in `sweeps/` (lines dropped, duplicated, cut, values replaced), and files built from
//! random keys, types and values — huge and empty lists, deep bundles, unicode keys and
//! strings, NaN and infinities. Every file must be accepted or rejected within a second, never
//! panic, and every rejection must name a key (the `file:line: key `…`: reason` form).
//!
//! 2000 files per run (about 10 s here); `CONTACT_SWEEP_FUZZ_CASES=10000` raises the count,
//! `CONTACT_SWEEP_FUZZ_SEED` changes the seed. The counts are printed (`--nocapture`).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::time::{Duration, Instant};

use contact_sweep::sweep::{Key, PlanLimits, SweepError, SweepFile, expand_with};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

const STRINGS: &[&str] = &[
    "mixed",
    "nitsche",
    "penalty",
    "consistent",
    "lumped",
    "mod1",
    "mod3",
    "weights",
    "zero-contact",
    "crank-nicolson",
    "central-difference",
    "backward-euler",
    "newmark",
    "theta",
    "paoli-schatzman",
    "hybrid",
    "bar1d",
    "bar2d",
    "bar3d",
    "disc2d",
    "interpolant",
    "",
    "é∂ƒ©",
    "🦀",
];

const NUMBERS: &[&str] = &[
    "0",
    "1",
    "-1",
    "2",
    "0.5",
    "0.25",
    "0.1",
    "0.05",
    "0.01",
    "1e-6",
    "1e-300",
    "1e300",
    "-0.0",
    "nan",
    "inf",
    "-inf",
    "12",
    "3",
    "64",
    "100000000",
    "1000000000000",
    "9223372036854775807",
    "-9223372036854775808",
    "0.0625",
    "0.015625",
    "1.5",
    "3.0",
];

fn keys() -> Vec<String> {
    let mut k: Vec<String> = Key::ALL.iter().map(|k| k.name().to_string()).collect();
    k.extend(
        [
            "name",
            "scene",
            "description",
            "exclude",
            "repeats",
            "ensemble",
            "series_every",
            "reference",
            "summary",
            "method",
            "perturbation",
            "samples",
            "seed",
            "errors",
            "rates",
        ]
        .map(String::from),
    );
    k
}

fn toml_string(s: &str) -> String {
    format!("{s:?}") // Rust's debug escaping is valid TOML basic-string escaping for these
}

/// A key: a known one, or a random (quoted, possibly unicode) one.
fn key() -> impl Strategy<Value = String> {
    prop_oneof![
        8 => prop::sample::select(keys()),
        1 => "\\PC{1,8}".prop_map(|s| toml_string(&s)),
    ]
}

/// A value of any type, nested up to 6 deep.
fn value() -> BoxedStrategy<String> {
    let leaf = prop_oneof![
        3 => prop::sample::select(NUMBERS).prop_map(String::from),
        2 => any::<i64>().prop_map(|i| i.to_string()),
        2 => any::<f64>().prop_map(|x| if x.is_finite() { format!("{x:e}") } else { "nan".into() }),
        3 => prop::sample::select(STRINGS).prop_map(toml_string),
        1 => "\\PC{0,16}".prop_map(|s| toml_string(&s)),
        1 => any::<bool>().prop_map(|b| b.to_string()),
    ];
    leaf.prop_recursive(6, 48, 6, |inner| {
        prop_oneof![
            vec(inner.clone(), 0..6).prop_map(|v| format!("[{}]", v.join(", "))),
            vec((key(), inner), 0..4).prop_map(|kv| {
                let mut seen = std::collections::HashSet::new();
                let body: Vec<String> = kv
                    .into_iter()
                    .filter(|(k, _)| seen.insert(k.clone()))
                    .map(|(k, v)| format!("{k} = {v}"))
                    .collect();
                format!("{{ {} }}", body.join(", "))
            }),
        ]
    })
    .boxed()
}

use prop::collection::vec;

/// A table's entries, each key once (TOML refuses duplicates: that path is the syntax error,
/// covered by the mutations).
fn entries(max: usize) -> impl Strategy<Value = String> {
    vec((key(), value()), 0..max).prop_map(|kv| {
        let mut seen = std::collections::HashSet::new();
        kv.into_iter()
            .filter(|(k, _)| seen.insert(k.clone()))
            .map(|(k, v)| format!("{k} = {v}\n"))
            .collect()
    })
}

/// A list of `n` numbers (huge lists: up to 20 000 items).
fn number_list() -> impl Strategy<Value = String> {
    (0usize..20_000, prop::sample::select(NUMBERS)).prop_map(|(n, x)| {
        let items: Vec<String> = (0..n)
            .map(|i| {
                if i % 2 == 0 {
                    x.to_string()
                } else {
                    format!("{}", 0.001 * (i + 1) as f64)
                }
            })
            .collect();
        format!("[{}]", items.join(", "))
    })
}

/// A file built from random parts.
fn random_file() -> impl Strategy<Value = String> {
    (
        prop::option::of(prop::sample::select(STRINGS)),
        prop::option::of(prop::sample::select(STRINGS)),
        entries(3),
        entries(8),
        entries(6),
        prop::option::of((prop::sample::select(keys()), number_list())),
        entries(3),
    )
        .prop_map(|(name, scene, top, fixed, grid, huge, zip)| {
            let mut s = String::new();
            if let Some(n) = name {
                s += &format!("name = {}\n", toml_string(n));
            }
            if let Some(sc) = scene {
                s += &format!("scene = {}\n", toml_string(sc));
            }
            s += &top;
            s += "[fixed]\n";
            s += &fixed;
            s += "[grid]\n";
            s += &grid;
            if let Some((k, list)) = huge
                && !grid.contains(&format!("{k} ="))
            {
                s += &format!("{k} = {list}\n");
            }
            s += "[zip]\n";
            s += &zip;
            s
        })
}

/// The limits of the fuzz: as the CLI sets them, scaled so that no accepted plan takes a
/// second — 20 000 combinations, 64 MiB per run (the plan-time CFL check of an explicit
/// scheme assembles the operators).
fn limits() -> PlanLimits {
    PlanLimits {
        max_runs: 20_000,
        max_run_bytes: Some(64.0 * 1024.0 * 1024.0),
        series_every: None,
        max_plan_bytes: Some(1024.0 * 1024.0 * 1024.0),
    }
}

/// The sweeps of the repository, each a starting point for mutations — those whose own plan
/// takes under half a second: `hard_cases.toml` (4050 combinations, each explicit scheme's CFL
/// limit computed from its operators) takes 1.5 s as written, so its mutations would measure
/// the campaign's size, not a hang.
fn corpus() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut files = Vec::new();
    for p in paths {
        let text = std::fs::read_to_string(&p).unwrap();
        let t0 = Instant::now();
        let _ = SweepFile::parse(&p, &text).map(|s| expand_with(&s, &limits()));
        if t0.elapsed() < Duration::from_millis(500) {
            files.push(text);
        } else {
            println!(
                "corpus: {} left out (its plan takes {:?})",
                p.display(),
                t0.elapsed()
            );
        }
    }
    files
}

#[derive(Debug, Clone)]
enum Mutation {
    DropLine(usize),
    DuplicateLine(usize),
    ReplaceValue(usize, String),
    Cut(usize),
    Insert(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        1 => any::<usize>().prop_map(Mutation::DropLine),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
        3 => (any::<usize>(), value()).prop_map(|(i, v)| Mutation::ReplaceValue(i, v)),
        1 => any::<usize>().prop_map(Mutation::Cut),
        1 => (any::<usize>(), "\\PC{0,6}").prop_map(|(i, s)| Mutation::Insert(i, s)),
    ]
}

fn mutate(text: &str, ms: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for m in ms {
        if lines.is_empty() {
            break;
        }
        let n = lines.len();
        match m {
            Mutation::DropLine(i) => {
                lines.remove(i % n);
            }
            Mutation::DuplicateLine(i) => {
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
            Mutation::ReplaceValue(i, v) => {
                let l = &mut lines[i % n];
                if let Some((k, _)) = l.split_once('=') {
                    *l = format!("{k}= {v}");
                }
            }
            Mutation::Cut(i) => {
                let l = &mut lines[i % n];
                let cut = l.char_indices().map(|(j, _)| j).nth(i % (l.len() + 1));
                if let Some(c) = cut {
                    l.truncate(c);
                }
            }
            Mutation::Insert(i, s) => {
                let l = &mut lines[i % n];
                let at = l
                    .char_indices()
                    .map(|(j, _)| j)
                    .nth(i % (l.chars().count() + 1))
                    .unwrap_or(l.len());
                l.insert_str(at, s);
            }
        }
    }
    lines.join("\n") + "\n"
}

fn sweep_file() -> impl Strategy<Value = String> {
    let corpus = corpus();
    let n = corpus.len();
    prop_oneof![
        (0..n, vec(mutation(), 1..6)).prop_map(move |(i, ms)| mutate(&corpus[i], &ms)),
        random_file(),
    ]
}

#[derive(Debug, Default)]
struct Counts {
    accepted: usize,
    rejected: usize,
    panics: usize,
    slowest: Duration,
}

/// Parse and plan one file; the outcome, or a message on a broken property.
fn check(text: &str, counts: &mut Counts) -> Result<(), String> {
    let limits = limits();
    let t0 = Instant::now();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        SweepFile::parse(Path::new("fuzz.toml"), text).and_then(|s| {
            let plan = expand_with(&s, &limits)?;
            // What `plan` prints must not panic either.
            let _ = (plan.summary(), plan.varying_keys());
            Ok(plan.runs.len())
        })
    }));
    let took = t0.elapsed();
    counts.slowest = counts.slowest.max(took);
    let result = match outcome {
        Ok(r) => r,
        Err(p) => {
            counts.panics += 1;
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            return Err(format!("panic: {what}"));
        }
    };
    if took > Duration::from_secs(1) {
        return Err(format!("took {took:?}"));
    }
    match result {
        Ok(_) => counts.accepted += 1,
        Err(SweepError::Invalid { issues, .. }) => {
            counts.rejected += 1;
            if issues.is_empty() {
                return Err("rejected without an issue".into());
            }
            for is in &issues {
                if is.key.trim().is_empty() || is.reason.trim().is_empty() {
                    return Err(format!("an issue without key or reason: {is:?}"));
                }
            }
            let msg = SweepError::Invalid {
                file: "fuzz.toml".into(),
                issues,
                sets: Vec::new(),
            }
            .to_string();
            if !msg
                .lines()
                .all(|l| l.starts_with("fuzz.toml") && l.contains(": key `"))
            {
                return Err(format!("a message line names no key: {msg}"));
            }
        }
        Err(e) => return Err(format!("unexpected error kind: {e}")),
    }
    Ok(())
}

#[test]
fn fuzzed_sweep_files_are_accepted_or_rejected_naming_a_key_quickly_and_never_panic() {
    let cases: usize = std::env::var("CONTACT_SWEEP_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let seed: u64 = std::env::var("CONTACT_SWEEP_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20261123);
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );
    let strategy = sweep_file();
    let mut counts = Counts::default();
    let mut failures: Vec<(String, String)> = Vec::new();
    // Panics are counted and reported with their file, not printed by the default hook.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let t0 = Instant::now();
    for _ in 0..cases {
        let text = strategy.new_tree(&mut runner).unwrap().current();
        if let Err(why) = check(&text, &mut counts)
            && failures.len() < 5
        {
            failures.push((why, text));
        }
    }
    std::panic::set_hook(hook);
    println!(
        "fuzz (seed {seed}): {cases} files in {:.1} s: {} accepted, {} rejected, {} panics; slowest {:?}",
        t0.elapsed().as_secs_f64(),
        counts.accepted,
        counts.rejected,
        counts.panics,
        counts.slowest
    );
    assert!(
        failures.is_empty(),
        "{} broken: {:#?}",
        failures.len(),
        failures
            .iter()
            .map(|(w, t)| format!(
                "{w}\n--- file:\n{}",
                t.chars().take(2000).collect::<String>()
            ))
            .collect::<Vec<_>>()
    );
    // The generator must exercise both sides (a fuzzer that only produces syntax errors
    // tests nothing past the TOML parser).
    assert!(counts.accepted >= cases / 50, "{counts:?}");
    assert!(counts.rejected >= cases / 4, "{counts:?}");
}
