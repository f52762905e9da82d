//! Stability and sensitivity as results (issue 10), through the real binary and `summarize`:
//! round-off ensembles flagged sensitive or not, the energy class of every method of the
//! quickstart.

mod common;

use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};

use common::cli;
use polars::prelude::*;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Run a sweep file of the repository into `dir` (summary included); returns the stdout.
fn run_sweep(sweep: &str, dir: &Path) -> String {
    let o = cli(
        repo(),
        &[
            "run",
            sweep,
            "--out",
            dir.to_str().unwrap(),
            "--threads",
            "2",
        ],
    );
    assert!(
        o.status.success(),
        "{sweep}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn read(path: PathBuf) -> DataFrame {
    ParquetReader::new(File::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .finish()
        .unwrap()
}

fn strs(df: &DataFrame, c: &str) -> Vec<String> {
    df.column(c)
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|s| s.unwrap_or("").to_string())
        .collect()
}

fn f64s(df: &DataFrame, c: &str) -> Vec<Option<f64>> {
    df.column(c).unwrap().f64().unwrap().iter().collect()
}

#[test]
fn ensemble_flags_the_ill_posed_cn_methods_of_003_fig3_and_not_the_stable_ones() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("fig3");
    let stdout = run_sweep("sweeps/003_fig3_mixed_nitsche_hybrid.toml", &dir);
    let e = read(dir.join("summary/ensemble.parquet"));
    // Four methods at one level, 8 members each: four ensembles, not 32 groups.
    assert_eq!(e.height(), 4, "{e}");
    let labels = strs(&e, "label");
    let sensitive: Vec<bool> = e
        .column("sensitive")
        .unwrap()
        .bool()
        .unwrap()
        .iter()
        .map(|b| b.unwrap())
        .collect();
    let spread = f64s(&e, "energy_ratio_spread");
    let members: Vec<i64> = e
        .column("members")
        .unwrap()
        .i64()
        .unwrap()
        .iter()
        .map(|x| x.unwrap())
        .collect();
    let mut seen = BTreeMap::new();
    for i in 0..e.height() {
        assert_eq!(members[i], 8, "{}", labels[i]);
        let s = spread[i].unwrap();
        if labels[i].contains("consistent · crank-nicolson") {
            // contract §6: round-off moves E(T)/E⁰ anywhere in ≈ 1.07–3.9; eight members spread it
            // by far more than 10 % of the median (measured 0.78 and 0.70).
            assert!(sensitive[i], "{} must be sensitive", labels[i]);
            assert!(s > 0.3, "{}: spread of E(T)/E⁰ {s}", labels[i]);
        } else {
            // Nitsche-Hybrid and mod3 + CN are well-posed: measured spreads ≤ 1.3e-13 for
            // E(T)/E⁰ and ≤ 1.4e-11 for every error; the flag's threshold is 1e-6.
            assert!(!sensitive[i], "{} must not be sensitive", labels[i]);
            assert!(s < 1e-9, "{}: spread {s}", labels[i]);
        }
        seen.insert(labels[i].clone(), sensitive[i]);
    }
    for l in [
        "mixed · consistent · crank-nicolson",
        "nitsche(Θ=1, γ0=1e-6) · consistent · crank-nicolson",
        "nitsche(Θ=1, γ0=1e-6) · consistent · hybrid",
        "mixed · mod3 · crank-nicolson",
    ] {
        assert!(seen.contains_key(l), "{l} missing from {seen:?}");
    }
    // min ≤ median ≤ max for every column.
    for c in ["energy_ratio", "err_u_l2h1", "err_u_l2l2", "err_sigma_l2"] {
        let (lo, med, hi) = (
            f64s(&e, &format!("{c}_min")),
            f64s(&e, &format!("{c}_median")),
            f64s(&e, &format!("{c}_max")),
        );
        for i in 0..e.height() {
            assert!(lo[i] <= med[i] && med[i] <= hi[i], "{c} row {i}");
        }
    }
    // Terminal and Markdown say it too.
    assert!(
        stdout.contains("ensembles: 2 of 4 sensitive to round-off"),
        "{stdout}"
    );
    let md = std::fs::read_to_string(dir.join("summary/ensemble.md")).unwrap();
    assert_eq!(md.matches("**sensitive**").count(), 2, "{md}");

    // Energy classes of the same runs: consistent mass + CN at ν = 1.5 grows in every member
    // (E(T)/E⁰ ≥ 1.4 against δ = 1.5·h = 0.015), mixed and Nitsche alike; the hybrid and
    // mod3 + CN never do.
    let en = read(dir.join("summary/energy.parquet"));
    for (label, class) in strs(&en, "label").iter().zip(strs(&en, "energy_class")) {
        if label.contains("consistent · crank-nicolson") {
            assert_eq!(class, "growing", "{label}");
        } else {
            assert_eq!(class, "conservative", "{label}");
        }
    }
}

#[test]
fn energy_class_of_every_quickstart_method() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("qs");
    let stdout = run_sweep("sweeps/quickstart.toml", &dir);
    // δ = max(1, ν)·h/L ranges over 1/128 … 1/8 here. The ill-posed pair gains 15 % … 1100 %
    // (≥ 2.4 δ at every level); every other method stays within δ (mod3 + CN at most 0.31 δ:
    // +3.9 % at h = 1/8, ν = 1; the hybrids lose at most 0.6 δ).
    let expected = [
        ("mixed · consistent · crank-nicolson", "10 growing"),
        ("mixed · mod3 · crank-nicolson", "10 conservative"),
        ("mixed · mod3 · hybrid", "10 conservative"),
        ("mixed · zero-contact · crank-nicolson", "10 conservative"),
        (
            "nitsche(Θ=1, γ0=1e-6) · consistent · crank-nicolson",
            "10 growing",
        ),
        (
            "nitsche(Θ=1, γ0=1e-6) · consistent · hybrid",
            "10 conservative",
        ),
    ];
    let g = read(dir.join("summary/energy_groups.parquet"));
    let got: BTreeMap<String, String> = strs(&g, "label")
        .into_iter()
        .zip(strs(&g, "energy_classes"))
        .collect();
    for (label, classes) in expected {
        assert_eq!(got.get(label).map(String::as_str), Some(classes), "{label}");
        // Printed in the terminal summary, one line per method.
        assert!(
            stdout
                .lines()
                .any(|l| l.trim_start().starts_with(label) && l.trim_end().ends_with(classes)),
            "{label}: {classes} not printed:\n{stdout}"
        );
    }
    // The stability map of each method over the two swept axes (h × ν): 10 cells, every one
    // `growing` for the two ill-posed methods and `stable` for the others.
    let m = read(dir.join("summary/stability_map.parquet"));
    let mut cells: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for ((method, state), (xa, ya)) in strs(&m, "method")
        .into_iter()
        .zip(strs(&m, "state"))
        .zip(strs(&m, "x_axis").into_iter().zip(strs(&m, "y_axis")))
    {
        assert_eq!((xa.as_str(), ya.as_str()), ("courant", "h"), "{method}");
        cells.entry(method).or_default().push(state);
    }
    assert_eq!(cells.len(), 6, "{cells:?}");
    for (method, states) in &cells {
        assert_eq!(states.len(), 10, "{method}");
        let want = if method.ends_with("consistent · crank-nicolson") {
            "growing"
        } else {
            "stable"
        };
        assert!(states.iter().all(|s| s == want), "{method}: {states:?}");
    }
    // The functional each is judged by: E_Θ for Nitsche, E^h for the mixed methods.
    let en = read(dir.join("summary/energy.parquet"));
    for (label, f) in strs(&en, "label")
        .iter()
        .zip(strs(&en, "energy_functional"))
    {
        let want = if label.starts_with("nitsche") {
            "E_Θ"
        } else {
            "E^h"
        };
        assert_eq!(f, want, "{label}");
    }
}

/// The search table of a folder, one row per searched method: (method, state, last holding,
/// first failing, failing status).
fn boundaries(dir: &Path) -> Vec<(String, String, f64, f64, String)> {
    let s = read(dir.join("summary/search.parquet"));
    let (m, st, fs) = (
        strs(&s, "method"),
        strs(&s, "state"),
        strs(&s, "failing_status"),
    );
    let (a, b) = (f64s(&s, "last_holding"), f64s(&s, "first_failing"));
    (0..s.height())
        .map(|i| {
            (
                m[i].clone(),
                st[i].clone(),
                a[i].unwrap_or(f64::NAN),
                b[i].unwrap_or(f64::NAN),
                fs[i].clone(),
            )
        })
        .collect()
}

#[test]
fn cfl_search_finds_the_planners_central_difference_limit() {
    use contact_sweep::sweep::{Key, SweepFile, expand};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("cfl");
    let sweep = "sweeps/search_cfl_bar1d.toml";
    run_sweep(sweep, &dir);
    // The planner's limit for each method, from the assembled operators: the same methods at
    // ν = 1 with allow_unstable (so the plan is not refused), ν_max = ν · dt_max / dt.
    let text = std::fs::read_to_string(repo().join(sweep)).unwrap();
    let text = text
        .replace(
            "series_every = 0",
            "series_every = 0\nallow_unstable = true",
        )
        .split("[search]")
        .next()
        .unwrap()
        .to_string()
        + &text[text.find("[fixed]").unwrap()..].replace("T = 40.0", "T = 40.0\ncourant = 1.0");
    let plan = expand(&SweepFile::parse(Path::new("limits.toml"), &text).unwrap()).unwrap();
    let mut limits = BTreeMap::new();
    for r in &plan.runs {
        let dt = r.params[&Key::Dt].as_f64().unwrap();
        let nu = r.params[&Key::Courant].as_f64().unwrap();
        let dt_max = r.config.explicit_dt_limit().unwrap().unwrap();
        limits.insert(r.label.clone(), nu * dt_max / dt);
    }
    let found = boundaries(&dir);
    assert_eq!(found.len(), 4, "{found:?}");
    for (method, state, holding, failing, status) in &found {
        // Same mass and contact treatment (Θ for Nitsche; γ0 prints differently: 100 / 1e2).
        let same = |label: &str| {
            let part = |s: &str, i: usize| s.split(" · ").nth(i).unwrap_or("").to_string();
            let theta = |s: &str| s.find("Θ=").map(|k| s[k..k + 4].to_string());
            part(label, 1) == part(method, 1)
                && part(label, 0)[..5] == part(method, 0)[..5]
                && theta(label) == theta(method)
        };
        let limit = limits
            .iter()
            .find(|(l, _)| same(l))
            .map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("{method}: no limit in {limits:?}"));
        assert_eq!(state, "found", "{method}");
        assert_eq!(status, "diverged", "{method}: the probe above the limit");
        assert!((failing - holding) / failing <= 1e-3, "{method}");
        if method.contains("Θ=0") {
            // Nitsche Θ = 0: the planner's limit (0.116) is far below the measured one (1.0):
            // it models the contact term as the symmetric k·p·pᵀ, exact for Θ = 1 only, and
            // is conservative otherwise. A finding of the search, kept visible here.
            assert!(
                limit < 0.2 && *holding >= 1.0 - 1e-3,
                "{method}: {limit} vs {holding}"
            );
            continue;
        }
        // The search brackets the limit by adjacent probes (b − a)/b ≤ rel_tol = 1e-3, and the
        // limit lies in the bracket: a run at most 1e-3 above the limit still diverges within
        // T = 40 (growth ≈ e^{0.09} per step over 2000+ steps), one below it never does.
        assert!(
            *holding <= limit * (1.0 + 1e-9) && limit <= *failing,
            "{method}: limit ν = {limit} outside [{holding}, {failing}]"
        );
    }
    // Lumped mass: ν_max ≈ 1 (ω_max = 2c0/h for the free bar; the Θ = 1, γ0 = 1 contact term
    // moves it by 5e-4); a massless contact node raises the largest frequency and lowers the
    // limit to 0.578.
    let max = limits.values().cloned().fold(0.0, f64::max);
    assert!((max - 1.0).abs() < 1e-3, "{limits:?}");
}

#[test]
fn gamma0_search_for_theta_one_brackets_the_spec_threshold() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("g0");
    run_sweep("sweeps/search_gamma0_theta1.toml", &dir);
    let found = boundaries(&dir);
    assert_eq!(found.len(), 2, "{found:?}");
    for (method, state, holding, failing, _) in &found {
        // contract §6: γ0 = 1 runs to the end, γ0 ≥ 3 blows up — the threshold lies in [1, 3]; the
        // search puts it at γ0 = 1 to its tolerance (1e-3): every γ0 above 1 fails.
        assert_eq!(state, "found", "{method}");
        assert!(
            *holding >= 1.0 - 1e-3 && *failing <= 3.0,
            "{method}: [{holding}, {failing}]"
        );
        assert!((failing - holding) / failing <= 1e-3, "{method}");
    }
    // Every probe is an ordinary row tagged with its search.
    let runs = contact_sweep::sink::read_runs(&dir).unwrap();
    let tags = runs.column("search").unwrap().str().unwrap();
    assert!(
        tags.iter()
            .all(|t| t.is_some_and(|t| t.contains("key=nitsche_gamma0")))
    );
    assert!(runs.height() >= 2 * 12, "{} probes", runs.height());
    // Resumable: the same command again finds every probe committed and runs none.
    run_sweep("sweeps/search_gamma0_theta1.toml", &dir);
    let again = contact_sweep::sink::read_runs(&dir).unwrap();
    assert_eq!(
        again.height(),
        runs.height(),
        "a resumed search re-ran probes"
    );
    assert_eq!(boundaries(&dir), found);
}

#[test]
fn spec_6_nitsche_behaviours_hold_through_the_theta_gamma0_stability_map() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("f48");
    run_sweep("sweeps/003_figs4-8_nitsche_parameters.toml", &dir);
    let m = read(dir.join("summary/stability_map.parquet"));
    let (method, xa, ya, state) = (
        strs(&m, "method"),
        strs(&m, "x_axis"),
        strs(&m, "y_axis"),
        strs(&m, "state"),
    );
    let (x, y) = (f64s(&m, "x"), f64s(&m, "y"));
    let steps: Vec<i64> = m
        .column("steps")
        .unwrap()
        .i64()
        .unwrap()
        .iter()
        .map(|s| s.unwrap())
        .collect();
    // (scheme, Θ, γ0) → (state, time the worst run of the cell reached).
    let mut cell = BTreeMap::new();
    for i in 0..m.height() {
        assert_eq!(
            (xa[i].as_str(), ya[i].as_str()),
            ("nitsche_theta", "nitsche_gamma0")
        );
        let scheme = method[i].rsplit(" · ").next().unwrap().to_string();
        let key = (scheme, x[i].unwrap().to_string(), y[i].unwrap().to_string());
        cell.insert(key, (state[i].clone(), steps[i] as f64 * 0.015));
    }
    assert_eq!(cell.len(), 2 * 3 * 7);
    let get = |s: &str, th: f64, g: f64| {
        cell.iter()
            .find(|((sc, t, y), _)| sc == s && *t == th.to_string() && *y == g.to_string())
            .map(|(_, v)| v.clone())
            .unwrap_or_else(|| panic!("no cell {s} Θ={th} γ0={g}"))
    };
    // The first impact is at t = 1 (contract §1.1).
    for s in ["crank-nicolson", "hybrid"] {
        for g in [3.0, 10.0, 100.0, 1e4] {
            // Θ = 1, γ0 ≥ 3: A_Θγ indefinite, blows up before any contact.
            let (st, t) = get(s, 1.0, g);
            assert!(
                st == "diverged" && t < 1.0,
                "{s} Θ=1 γ0={g}: {st} at t = {t}"
            );
        }
        // Θ = 1, γ0 = 1: finite (unphysical: see the energy check below).
        assert!(!["diverged", "solver-failed"].contains(&get(s, 1.0, 1.0).0.as_str()));
        // Θ = 0 stays finite up to γ0 = 1e4.
        for g in [1e-6, 0.1, 1.0, 3.0, 10.0, 100.0, 1e4] {
            let (st, _) = get(s, 0.0, g);
            assert!(st == "stable" || st == "growing", "{s} Θ=0 γ0={g}: {st}");
        }
    }
    // Nitsche-Hybrid, Θ = −1: every γ0 ≥ 3 diverges; for γ0 = 3 and 10 after the first impact
    // as contract §6 says. (Measured, not in the contract: for γ0 = 100 and 1e4 the hybrid blows up before
    // the first impact, at t = 0.42 and 0.03.)
    for g in [3.0, 10.0, 100.0, 1e4] {
        let (st, t) = get("hybrid", -1.0, g);
        assert_eq!(st, "diverged", "hybrid Θ=−1 γ0={g}");
        if g <= 10.0 {
            assert!(
                t > 1.0,
                "hybrid Θ=−1 γ0={g}: diverged at t = {t}, before the impact"
            );
        }
    }
    // Θ = −1 with CN stays finite (the contract: E(T)/E⁰ 4.97 at γ0 = 10, 6.02 at 100).
    assert_ne!(get("crank-nicolson", -1.0, 100.0).0, "diverged");
    // Θ = 1, γ0 = 1 is unphysical: E^h strays by more than 100 E⁰ (the contract: peaks ≈ 231 E⁰)
    // while the run ends ok.
    let runs = contact_sweep::sink::read_runs(&dir).unwrap();
    let unphys = runs
        .lazy()
        .filter(
            col("nitsche_theta")
                .eq(lit(1.0))
                .and(col("nitsche_gamma0").eq(lit(1.0))),
        )
        .collect()
        .unwrap();
    assert_eq!(unphys.height(), 2);
    for (st, dev) in strs(&unphys, "status")
        .iter()
        .zip(f64s(&unphys, "energy_max_dev"))
    {
        assert_eq!(st, "ok");
        assert!(dev.unwrap() > 100.0, "max |E^h − E⁰|/E⁰ = {dev:?}");
    }
}

#[test]
fn hard_cases_every_run_ends_with_a_status_and_a_message() {
    use contact_sweep::sweep::{Key, SweepFile, expand};
    // The file plans, and its plan reaches every edge the issue names: ν 0.1 … 100, γ0
    // 1e-10 … 1e4 (Nitsche and penalty), Θ ∈ {−1, 0, 1}, T = 300 (100 impacts), h = 1/4096,
    // every scheme of contract §3 — without the full product (h = 1/4096 only with T = 1.5).
    let path = repo().join("sweeps/hard_cases.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let plan = expand(&SweepFile::parse(&path, &text).unwrap()).unwrap();
    assert_eq!(plan.runs.len(), 904);
    let values = |k: Key| -> Vec<f64> {
        let mut v: Vec<f64> = plan
            .runs
            .iter()
            .filter_map(|r| r.params.get(&k).and_then(|x| x.as_f64()))
            .collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    assert_eq!(values(Key::Courant), [0.1, 1.0, 1.5, 10.0, 100.0]);
    assert_eq!(values(Key::NitscheTheta), [-1.0, 0.0, 1.0]);
    assert_eq!(values(Key::NitscheGamma0), [1e-10, 1e-6, 1.0, 3.0, 1e4]);
    assert_eq!(values(Key::PenaltyGamma0), [1e-10, 1.0, 1e4]);
    assert_eq!(values(Key::H), [1.0 / 4096.0, 0.01, 0.0625]);
    assert_eq!(values(Key::T), [1.5, 12.0, 300.0]);
    for r in &plan.runs {
        let (h, t) = (r.params[&Key::H].as_f64(), r.params[&Key::T].as_f64());
        if h == Some(1.0 / 4096.0) {
            assert_eq!(t, Some(1.5), "h = 1/4096 only through the first impact");
        }
    }
    for scheme in [
        "crank-nicolson",
        "newmark(",
        "newmark-dissipative",
        "central-difference",
        "theta(",
        "backward-euler",
        "paoli-schatzman",
        "hybrid",
    ] {
        assert!(
            plan.runs.iter().any(|r| r.label.contains(scheme)),
            "no {scheme} run"
        );
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("hard");
    // A generous per-run budget: the slowest run takes about 1 s; a hang would end `timeout`.
    let o = cli(
        repo(),
        &[
            "run",
            "sweeps/hard_cases.toml",
            "--out",
            dir.to_str().unwrap(),
            "--threads",
            "2",
            "--run-timeout",
            "120",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let runs = contact_sweep::sink::read_runs(&dir).unwrap();
    assert_eq!(runs.height(), 904, "every run of the plan has its row");
    let status = strs(&runs, "status");
    let message: Vec<Option<String>> = runs
        .column("message")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|m| m.map(String::from))
        .collect();
    for (st, msg) in status.iter().zip(&message) {
        assert!(
            ["ok", "diverged", "solver-failed"].contains(&st.as_str()),
            "status {st}: {msg:?}"
        );
        if st != "ok" {
            let m = msg.as_deref().unwrap_or("");
            assert!(!m.is_empty(), "a {st} run without a message");
            assert!(!m.contains("panic"), "{m}");
        }
    }
    // Through the map (h × ν, worst over Θ and γ0): central differences diverge beyond the
    // CFL limit (ν ≥ 1 with the massless contact node of mod3, whose limit is 0.578), the
    // 000 §5 hybrid and the dissipative schemes are stable in every cell.
    let m = read(dir.join("summary/stability_map.parquet"));
    let hc = m
        .lazy()
        .filter(
            col("x_axis")
                .eq(lit("courant"))
                .and(col("y_axis").eq(lit("h"))),
        )
        .collect()
        .unwrap();
    let (meth, x, st) = (strs(&hc, "method"), f64s(&hc, "x"), strs(&hc, "state"));
    let mut seen = 0;
    for i in 0..hc.height() {
        let nu = x[i].unwrap();
        match meth[i].as_str() {
            "mixed · mod3 · central-difference" if nu >= 1.0 => {
                assert_eq!(st[i], "diverged", "CD at ν = {nu}")
            }
            "mixed · mod3 · hybrid"
            | "mixed · zero-contact · backward-euler"
            | "mixed · consistent · newmark-dissipative"
            | "penalty · consistent · hybrid" => {
                assert_eq!(st[i], "stable", "{} at ν = {nu}", meth[i])
            }
            _ => continue,
        }
        seen += 1;
    }
    assert_eq!(seen, 4 * 14 + 4 * 3, "cells checked");
    // docs/methods.md's map is this one condensed: one row per method, each ν cell the states at
    // h = 1/16, 0.01, 1/4096 in that order (· where not run). Every row must be there verbatim.
    let sym = |s: &str| match s {
        "stable" => '✓',
        "growing" => '↑',
        "diverged" => '✗',
        "solver-failed" => '!',
        "timeout" => '⌛',
        _ => '?',
    };
    let mut state: BTreeMap<(String, String, String), char> = BTreeMap::new();
    for i in 0..hc.height() {
        let key = |v: Option<f64>| format!("{:e}", v.unwrap());
        state.insert(
            (meth[i].clone(), key(x[i]), key(f64s(&hc, "y")[i])),
            sym(&st[i]),
        );
    }
    let readme = std::fs::read_to_string(repo().join("docs/methods.md")).unwrap();
    let methods: std::collections::BTreeSet<&String> = meth.iter().collect();
    assert_eq!(methods.len(), 17, "{methods:?}");
    for method in methods {
        let cells: Vec<String> = [0.1, 1.0, 1.5, 10.0, 100.0]
            .iter()
            .map(|nu| {
                [0.0625, 0.01, 1.0 / 4096.0]
                    .iter()
                    .map(|h| {
                        let k = (method.clone(), format!("{nu:e}"), format!("{h:e}"));
                        state.get(&k).copied().unwrap_or('·')
                    })
                    .collect()
            })
            .collect();
        let row = format!("| {method} | {} |", cells.join(" | "));
        assert!(
            readme.contains(&row),
            "docs/methods.md lacks the map row\n{row}"
        );
    }
}
