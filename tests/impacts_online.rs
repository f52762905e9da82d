//! Contact phases recorded online by the runs (the runs table's `impact_*` lists, issue 12)
//! give the summary's impacts table without reading `series/`, and the same table as the
//! series-based path of older folders whenever that path sees every step.

mod common;

use std::fs::File;
use std::path::Path;

use contact_sweep::summary;
use polars::prelude::*;

/// Two impacts per run (T = 6, two periods); Nitsche-Hybrid's pressure alternates step by step
/// in contact, so the one-step merge rule is exercised; the massless contact node of
/// zero-contact and the consistent mass chatter.
const SWEEP: &str = r#"
name = "impacts-online"
scene = "bar1d"
series_every = 1
[fixed]
T = 6.0
[grid]
courant = [0.5, 1.0]
h = [0.125, 0.0625, 0.03125]
method = [
  { space = "mixed", mass = "consistent", scheme = "crank-nicolson" },
  { space = "mixed", mass = "zero-contact", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hybrid" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1.0, scheme = "crank-nicolson" },
]
"#;

const ONLINE_COLUMNS: [&str; 9] = [
    "impact_step_first",
    "impact_step_last",
    "impact_t_first",
    "impact_t_last",
    "impact_energy_before",
    "impact_energy_after",
    "impact_energy_theta_before",
    "impact_energy_theta_after",
    "energy_theta_initial",
];

fn run(tmp: &Path, out: &str, extra: &[&str]) -> std::path::PathBuf {
    let sweep = common::write(tmp, "s.toml", SWEEP);
    let dir = tmp.join(out);
    let mut args = vec![
        "run",
        sweep.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--no-summary",
    ];
    args.extend(extra);
    let o = common::cli(tmp, &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    dir
}

fn read(path: &Path) -> DataFrame {
    ParquetReader::new(File::open(path).unwrap())
        .finish()
        .unwrap()
}

/// The impacts table of DIR, sorted by run and impact number.
fn impacts(dir: &Path) -> DataFrame {
    summary::summarize(dir).unwrap();
    read(&dir.join("summary/impacts.parquet"))
        .sort(["run_id", "impact"], SortMultipleOptions::default())
        .unwrap()
}

/// Rewrite every runs part of DIR without the online columns: the folder as an older version
/// wrote it.
fn strip_online_columns(dir: &Path) {
    for part in contact_sweep::sink::parquet_parts(&dir.join("runs")).unwrap() {
        let mut df = read(&part).drop_many(ONLINE_COLUMNS);
        let name = part.file_name().unwrap().to_str().unwrap();
        contact_sweep::sink::write_parquet_atomic(&dir.join("runs"), name, &mut df).unwrap();
    }
}

fn i64s(df: &DataFrame, c: &str) -> Vec<Option<i64>> {
    df.column(c).unwrap().i64().unwrap().iter().collect()
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &to.join(e.file_name()));
        } else {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

#[test]
fn online_phases_equal_the_series_path_and_need_no_series() {
    let tmp = tempfile::tempdir().unwrap();
    let online = run(tmp.path(), "online", &[]);
    let old = tmp.path().join("old");
    copy_dir(&online, &old);
    strip_online_columns(&old);

    let a = impacts(&online);
    let b = impacts(&old);
    // Enough phases to mean something: 24 runs × 2 impacts at least, more with chatter.
    assert!(a.height() >= 48, "{} phases", a.height());
    // Exact equality, every column (energies and losses included): both paths read the same
    // f64 values — the observer's E^n, E_Θ^n, t^n at the same steps, copied unchanged into the
    // runs' lists or into the series — and compute the losses by the same expression with
    // the same E⁰, E_Θ⁰ (the row's energy_initial / energy_theta_initial are the step-0
    // values the series holds). No arithmetic differs, so no tolerance is needed.
    assert!(a.equals_missing(&b), "online:\n{a}\nseries-based:\n{b}");
    assert_eq!(
        i64s(&a, "series_stride"),
        vec![Some(1); a.height()],
        "online phases are at stride 1"
    );
    // The per-run counts of energy.parquet agree too.
    let ea = read(&online.join("summary/energy.parquet"));
    let eb = read(&old.join("summary/energy.parquet"));
    assert!(ea.equals_missing(&eb));

    // Without series/, the runs' lists alone give the same table.
    std::fs::remove_dir_all(online.join("series")).unwrap();
    let c = impacts(&online);
    assert!(c.equals_missing(&a), "without series/:\n{c}");
    // …while the old folder without series/ has no impacts at all.
    std::fs::remove_dir_all(old.join("series")).unwrap();
    assert_eq!(impacts(&old).height(), 0);
}

#[test]
fn decimated_series_no_longer_coarsen_the_phase_ends() {
    let tmp = tempfile::tempdir().unwrap();
    let full = run(tmp.path(), "full", &[]);
    let every10 = run(tmp.path(), "every10", &["--series-every", "10"]);
    let a = impacts(&full);
    let d = impacts(&every10);
    // The same runs (series_every is not a parameter of a run): the phases found online do
    // not depend on what the series keeps — exact steps, equal to the full-series ones.
    for c in [
        "run_id",
        "step_first",
        "step_last",
        "step_before",
        "step_after",
    ] {
        assert_eq!(
            a.column(c).unwrap(),
            d.column(c).unwrap(),
            "column {c} differs with series_every = 10"
        );
    }
    assert_eq!(i64s(&d, "series_stride"), vec![Some(1); d.height()]);

    // The old path on the same decimated folder: phase ends on the recording grid only.
    strip_online_columns(&every10);
    let old = impacts(&every10);
    assert!(
        i64s(&old, "series_stride").iter().all(|s| *s == Some(10)),
        "stride of a series_every = 10 series"
    );
    // Every phase end the old path reports is a stored step: a multiple of 10, or the run's
    // last step (always stored).
    let runs = contact_sweep::sink::read_runs(&every10).unwrap();
    let last: std::collections::HashMap<String, i64> = runs
        .column("run_id")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .zip(runs.column("steps").unwrap().i64().unwrap().iter())
        .map(|(id, n)| (id.unwrap().to_string(), n.unwrap()))
        .collect();
    let ids: Vec<String> = old
        .column("run_id")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|s| s.unwrap().to_string())
        .collect();
    for c in ["step_first", "step_last"] {
        for (id, s) in ids.iter().zip(i64s(&old, c)) {
            let s = s.unwrap();
            assert!(
                s % 10 == 0 || s == last[id],
                "{c} = {s} is not a stored step"
            );
        }
    }
    let exact: Vec<i64> = ["step_first", "step_last"]
        .iter()
        .flat_map(|c| i64s(&a, c).into_iter().flatten())
        .collect();
    // The exact steps are not all on that grid: the online path resolves what the old one
    // could not.
    assert!(
        exact.iter().filter(|s| *s % 10 != 0).count() > exact.len() / 2,
        "exact phase ends mostly off the 10-step grid"
    );
}

#[test]
fn the_runs_lists_read_as_one_row_per_phase() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), "lists", &[]);
    let runs = contact_sweep::sink::read_runs(&dir).unwrap();
    for c in ["impact_step_first", "impact_step_last"] {
        assert_eq!(
            runs.column(c).unwrap().dtype(),
            &DataType::List(Box::new(DataType::Int64)),
            "{c}"
        );
    }
    for c in &ONLINE_COLUMNS[2..8] {
        assert_eq!(
            runs.column(c).unwrap().dtype(),
            &DataType::List(Box::new(DataType::Float64)),
            "{c}"
        );
    }
    let exploded = runs
        .select(["run_id", "impact_step_first", "impact_step_last"])
        .unwrap()
        .explode(
            ["impact_step_first", "impact_step_last"],
            ExplodeOptions {
                empty_as_null: false,
                keep_nulls: false,
            },
        )
        .unwrap();
    // One row per phase: the sum of the list lengths.
    let phases: usize = runs
        .column("impact_step_first")
        .unwrap()
        .list()
        .unwrap()
        .lst_lengths()
        .iter()
        .map(|n| n.unwrap_or(0) as usize)
        .sum();
    assert_eq!(exploded.height(), phases);
    assert!(phases >= 48);
    let first = i64s(&exploded, "impact_step_first");
    let last = i64s(&exploded, "impact_step_last");
    assert!(
        first
            .iter()
            .zip(&last)
            .all(|(f, l)| f.unwrap() <= l.unwrap()),
        "a phase ends at or after its start"
    );
}
