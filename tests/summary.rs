//! `contact-sweep summarize` on synthetic results folders written here as Parquet: rates,
//! least-squares slopes and flags against hand-computed values (unequal refinement ratios, a
//! failed level, a level without a value, a zero error), folders of another version with
//! extra and missing columns, a folder without a refinement axis, an empty folder, the energy
//! and impact tables, and the speed-against-error tables.
//!
//! Tolerances: every expected value below is a closed-form expression or was evaluated in
//! IEEE double (Python `math.log`) from the same inputs. The summary computes the same
//! expressions with other rounding orders (sums of logarithms in the LSQ slope), so values
//! agree to a few ulps of the logarithms involved, amplified by the conditioning of a ratio of
//! logarithms: at worst 1/|log(e_i/e_j)| ≈ 30 for the near-stagnant column (e ratios ≈ 1.04).
//! That is ≲ 1e-13 absolute on rates of order 1–20; [`TOL`] = 1e-10 leaves margin and is still
//! far below the two decimals any table prints.

use std::fs::File;
use std::path::Path;

use contact_sweep::summary::{
    self, NO_REFINEMENT, loglog_cost, lsq_slope, observed_rate, pareto_front,
};
use polars::prelude::*;

const TOL: f64 = 1e-10;

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= TOL * b.abs().max(1.0),
        "{what}: got {a}, expected {b}"
    );
}

/// One synthetic run.
#[derive(Clone)]
struct R {
    label: &'static str,
    space: &'static str,
    scheme_label: &'static str,
    status: &'static str,
    h: f64,
    dt: f64,
    /// err_u_l2l2, err_u_l2h1, err_u_linfl2, err_sigma_l2
    err: [Option<f64>; 4],
    wall: f64,
    max_inc: Option<f64>,
    drift: Option<f64>,
    max_dev: Option<f64>,
}

fn run(
    label: &'static str,
    scheme_label: &'static str,
    h: f64,
    dt: f64,
    err: [Option<f64>; 4],
) -> R {
    R {
        label,
        space: "mixed",
        scheme_label,
        status: "ok",
        h,
        dt,
        err,
        // Cost ∝ (1/h)·(1/dt): a time-stepping cost model, exact for the interpolation checks.
        wall: 1e-3 / (h * dt),
        max_inc: Some(1e-16),
        drift: Some(-1e-16),
        max_dev: Some(3e-16),
    }
}

/// The runs table of the current version (contract §8 columns that the summary reads, plus the
/// ones it must tolerate). c0 = 1 (young = density = 1), so courant = dt/h.
fn runs_frame(rows: &[R]) -> DataFrame {
    let n = rows.len();
    let s = |f: &dyn Fn(&R) -> Option<String>| rows.iter().map(f).collect::<Vec<_>>();
    let f = |f: &dyn Fn(&R) -> Option<f64>| rows.iter().map(f).collect::<Vec<_>>();
    let i = |f: &dyn Fn(&R) -> Option<i64>| rows.iter().map(f).collect::<Vec<_>>();
    let cols = vec![
        Column::new(
            "run_id".into(),
            s(&|r| Some(format!("{}-{}-{}-{}", r.space, r.scheme_label, r.h, r.dt))),
        ),
        Column::new("sweep".into(), vec![Some("synthetic"); n]),
        Column::new("scene".into(), vec![Some("bar1d"); n]),
        Column::new("label".into(), s(&|r| Some(r.label.to_string()))),
        Column::new("status".into(), s(&|r| Some(r.status.to_string()))),
        Column::new(
            "message".into(),
            s(&|r| (r.status != "ok").then(|| "energy exceeded 1e6·E0".to_string())),
        ),
        Column::new("T".into(), vec![Some(1.0); n]),
        Column::new("h".into(), f(&|r| Some(r.h))),
        Column::new("elements".into(), i(&|r| Some((1.0 / r.h).round() as i64))),
        Column::new("dt".into(), f(&|r| Some(r.dt))),
        Column::new("courant".into(), f(&|r| Some(r.dt / r.h))),
        Column::new("space".into(), s(&|r| Some(r.space.to_string()))),
        Column::new("mass".into(), vec![Some("mod3"); n]),
        Column::new("scheme".into(), vec![Some("newmark"); n]),
        Column::new(
            "scheme_label".into(),
            s(&|r| Some(r.scheme_label.to_string())),
        ),
        Column::new("nitsche_theta".into(), vec![None::<f64>; n]),
        Column::new("length".into(), vec![Some(1.0); n]),
        Column::new("young".into(), vec![Some(1.0); n]),
        Column::new("density".into(), vec![Some(1.0); n]),
        Column::new("wall_time_s".into(), f(&|r| Some(r.wall))),
        Column::new("wall_time_min_s".into(), f(&|r| Some(0.9 * r.wall))),
        Column::new("wall_time_max_s".into(), f(&|r| Some(1.2 * r.wall))),
        Column::new("repeats".into(), vec![Some(3i64); n]),
        Column::new("steps".into(), i(&|r| Some((1.0 / r.dt).round() as i64))),
        Column::new("dofs".into(), i(&|r| Some((1.0 / r.h).round() as i64))),
        Column::new("energy_initial".into(), vec![Some(1.0); n]),
        Column::new("energy_drift".into(), f(&|r| r.drift)),
        Column::new("energy_max_dev".into(), f(&|r| r.max_dev)),
        Column::new("energy_max_increase".into(), f(&|r| r.max_inc)),
        Column::new("err_u_l2l2".into(), f(&|r| r.err[0])),
        Column::new("err_u_l2h1".into(), f(&|r| r.err[1])),
        Column::new("err_u_linfl2".into(), f(&|r| r.err[2])),
        Column::new("err_sigma_l2".into(), f(&|r| r.err[3])),
        // Present but all null: must not become a table column.
        Column::new("err_energy_l2".into(), vec![None::<f64>; n]),
        // err_u_contact_max absent altogether.
    ];
    DataFrame::new(n, cols).unwrap()
}

fn write_runs(dir: &Path, part: &str, df: &mut DataFrame) {
    let runs = dir.join("runs");
    std::fs::create_dir_all(&runs).unwrap();
    contact_sweep::sink::write_parquet_atomic(&runs, part, df).unwrap();
}

fn read(path: &Path) -> DataFrame {
    ParquetReader::new(File::open(path).unwrap())
        .finish()
        .unwrap()
}

/// Rows of convergence.parquet for one label and error column, ordered by level.
fn conv_rows(dir: &Path, label: &str, error: &str) -> DataFrame {
    read(&dir.join("summary/convergence.parquet"))
        .lazy()
        .filter(col("label").eq(lit(label)).and(col("error").eq(lit(error))))
        .sort(["level"], SortMultipleOptions::default())
        .collect()
        .unwrap()
}

fn f64s(df: &DataFrame, c: &str) -> Vec<Option<f64>> {
    df.column(c).unwrap().f64().unwrap().iter().collect()
}
fn i64s(df: &DataFrame, c: &str) -> Vec<Option<i64>> {
    df.column(c).unwrap().i64().unwrap().iter().collect()
}
fn bools(df: &DataFrame, c: &str) -> Vec<Option<bool>> {
    df.column(c).unwrap().bool().unwrap().iter().collect()
}
fn strs(df: &DataFrame, c: &str) -> Vec<Option<String>> {
    df.column(c)
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|s| s.map(String::from))
        .collect()
}
/// The single value of a per-path column (repeated on every level row).
fn one_f64(df: &DataFrame, c: &str) -> f64 {
    let v = f64s(df, c);
    assert!(
        v.windows(2).all(|w| w[0] == w[1]),
        "{c} differs between levels"
    );
    v[0].unwrap_or_else(|| panic!("{c} is null"))
}
fn one_bool(df: &DataFrame, c: &str) -> bool {
    bools(df, c)[0].unwrap()
}

const CN: &str = "mixed · mod3 · crank-nicolson";
const HY: &str = "mixed · mod3 · hybrid";

/// Group A (crank-nicolson): Courant 1 (dt = h), h = 1/4, 1/12, 1/24, 1/48 (diverged), 1/96 —
/// ratios 3, 2, (2, 2) = 4 across the failed level. Group B (hybrid): h = 0.1 fixed, dt = 0.1,
/// 0.05, 0.02 — ratios 2, 2.5.
fn synthetic() -> Vec<R> {
    let mut a = vec![
        run(
            CN,
            "crank-nicolson",
            0.25,
            0.25,
            [Some(0.1), Some(0.5), Some(1e2), Some(0.5)],
        ),
        run(
            CN,
            "crank-nicolson",
            1.0 / 12.0,
            1.0 / 12.0,
            [Some(0.02), Some(0.52), Some(1e-3), Some(1.0 / 6.0)],
        ),
        run(
            CN,
            "crank-nicolson",
            1.0 / 24.0,
            1.0 / 24.0,
            [Some(0.006), Some(0.49), Some(1e-8), Some(1.0 / 12.0)],
        ),
        // The failed level carries a bogus error value that must not enter any fit.
        run(
            CN,
            "crank-nicolson",
            1.0 / 48.0,
            1.0 / 48.0,
            [Some(1e3), None, None, None],
        ),
        run(
            CN,
            "crank-nicolson",
            1.0 / 96.0,
            1.0 / 96.0,
            [Some(3.75e-4), Some(0.5), Some(5e-11), Some(1.0 / 48.0)],
        ),
    ];
    a[3].status = "diverged";
    let b = vec![
        run(
            HY,
            "hybrid",
            0.1,
            0.1,
            [Some(0.3 * 0.01), Some(3e-14), Some(1e-3), Some(1.0)],
        ),
        run(
            HY,
            "hybrid",
            0.1,
            0.05,
            [Some(0.3 * 0.0025), Some(2e-14), Some(0.0), None],
        ),
        run(
            HY,
            "hybrid",
            0.1,
            0.02,
            [Some(0.3 * 0.0004), Some(5e-14), Some(2.5e-4), Some(0.2)],
        ),
    ];
    a.into_iter().chain(b).collect()
}

#[test]
fn rates_slopes_and_flags_match_hand_computed_values() {
    let tmp = tempfile::tempdir().unwrap();
    write_runs(tmp.path(), "part-0.parquet", &mut runs_frame(&synthetic()));
    let s = summary::summarize(tmp.path()).unwrap();
    assert_eq!(s.runs, 8);
    assert_eq!(s.groups, 2);
    // A: one path (Courant 1; every dt and h distinct, so no dt- or h-fixed path). B: one (h).
    assert_eq!(s.refinement_paths, 2, "{}", s.terminal);

    // --- A, err_u_l2l2: unequal ratios and a failed level in between.
    let d = conv_rows(tmp.path(), CN, "err_u_l2l2");
    assert_eq!(d.height(), 5, "the failed level stays in the table");
    assert_eq!(strs(&d, "fixed")[0].as_deref(), Some("courant"));
    assert_eq!(strs(&d, "refined")[0].as_deref(), Some("h"));
    let rate = f64s(&d, "rate");
    assert_eq!(rate[0], None);
    // log(0.1/0.02)/log((1/4)/(1/12)) = ln 5 / ln 3 — not ln 5 / ln 2.
    close(rate[1].unwrap(), 5f64.ln() / 3f64.ln(), "rate 1/4→1/12");
    close(rate[1].unwrap(), 1.4649735207179269, "rate 1/4→1/12");
    // ln(0.02/0.006)/ln 2.
    close(rate[2].unwrap(), 1.7369655941662063, "rate 1/12→1/24");
    assert_eq!(rate[3], None, "no rate at the failed level");
    // Across the failed level: ln(0.006/3.75e-4)/ln((1/24)/(1/96)) = ln 16 / ln 4 = 2.
    close(rate[4].unwrap(), 2.0, "rate 1/24→1/96");
    assert_eq!(
        i64s(&d, "rate_from_level"),
        vec![None, Some(0), Some(1), None, Some(2)]
    );
    assert_eq!(
        bools(&d, "used_in_fit"),
        vec![Some(true), Some(true), Some(true), Some(false), Some(true)]
    );
    assert_eq!(strs(&d, "excluded")[3].as_deref(), Some("status diverged"));
    assert_eq!(strs(&d, "status")[3].as_deref(), Some("diverged"));
    // The bogus value is kept (marked), not dropped.
    assert_eq!(f64s(&d, "value")[3], Some(1e3));
    // LSQ of ln e on ln h over h = 1/4, 1/12, 1/24, 1/96 (the diverged 1/48 excluded).
    close(one_f64(&d, "slope_all"), 1.7656461960639913, "LSQ all");
    assert_eq!(i64s(&d, "fit_levels")[0], Some(4));
    close(
        one_f64(&d, "slope_finest3"),
        1.9248473126189163,
        "LSQ finest 3",
    );
    // Spread 2 − ln5/ln3 = 0.535 > 0.3.
    close(
        one_f64(&d, "rate_spread"),
        2.0 - 5f64.ln() / 3f64.ln(),
        "spread",
    );
    assert!(one_bool(&d, "pre_asymptotic"));
    assert!(!one_bool(&d, "stagnating"));
    assert!(!one_bool(&d, "roundoff_floor"));
    assert_eq!(i64s(&d, "failed_levels")[0], Some(1));
    assert_eq!(
        strs(&d, "flags")[0].as_deref(),
        Some("pre-asymptotic, 1 failed level")
    );

    // --- A, err_u_l2h1: stagnating (finest-three slope 0.014 < 0.1), spread 0.12 ≤ 0.3.
    let d = conv_rows(tmp.path(), CN, "err_u_l2h1");
    close(
        one_f64(&d, "slope_all"),
        0.0041353159872802026,
        "l2h1 LSQ all",
    );
    close(
        one_f64(&d, "slope_finest3"),
        0.01408484055756812,
        "l2h1 LSQ finest 3",
    );
    close(
        one_f64(&d, "rate_spread"),
        0.12143010563427992,
        "l2h1 spread",
    );
    assert!(one_bool(&d, "stagnating"));
    assert!(!one_bool(&d, "pre_asymptotic"));
    assert!(!one_bool(&d, "roundoff_floor"));

    // --- A, err_u_linfl2: round-off floor by the relative criterion only (5e-11 ≤ 1e-12·1e2,
    // and 5e-11 is above the absolute 1e-13).
    let d = conv_rows(tmp.path(), CN, "err_u_linfl2");
    assert!(one_bool(&d, "roundoff_floor"));
    close(one_f64(&d, "slope_all"), 9.141710670626383, "linf LSQ all");
    close(
        one_f64(&d, "slope_finest3"),
        7.475560203330062,
        "linf LSQ finest 3",
    );

    // --- A, err_sigma_l2 = 2h exactly: every rate 1, no flag but the failed level.
    let d = conv_rows(tmp.path(), CN, "err_sigma_l2");
    for r in f64s(&d, "rate").into_iter().flatten() {
        close(r, 1.0, "sigma rate");
    }
    close(one_f64(&d, "slope_all"), 1.0, "sigma LSQ");
    assert!(!one_bool(&d, "pre_asymptotic"));
    assert_eq!(strs(&d, "flags")[0].as_deref(), Some("1 failed level"));

    // All-null and absent error columns produce no rows.
    let all = read(&tmp.path().join("summary/convergence.parquet"));
    let errors: std::collections::BTreeSet<String> =
        strs(&all, "error").into_iter().flatten().collect();
    assert_eq!(
        errors.into_iter().collect::<Vec<_>>(),
        ["err_sigma_l2", "err_u_l2h1", "err_u_l2l2", "err_u_linfl2"]
    );

    // --- B: h fixed, dt refined with ratios 2 and 2.5; e = 0.3 dt² → rates exactly 2.
    let d = conv_rows(tmp.path(), HY, "err_u_l2l2");
    assert_eq!(strs(&d, "fixed")[0].as_deref(), Some("h"));
    assert_eq!(strs(&d, "refined")[0].as_deref(), Some("dt"));
    close(f64s(&d, "rate")[1].unwrap(), 2.0, "dt rate 0.1→0.05");
    close(f64s(&d, "rate")[2].unwrap(), 2.0, "dt rate 0.05→0.02");
    close(one_f64(&d, "slope_all"), 2.0, "dt LSQ");
    assert_eq!(strs(&d, "flags")[0].as_deref(), Some("-"));
    // Absolute round-off floor: errors ~1e-14 (relative criterion not met: 5e-14/3e-14 > 1e-12).
    let d = conv_rows(tmp.path(), HY, "err_u_l2h1");
    assert!(one_bool(&d, "roundoff_floor"));
    assert!(one_bool(&d, "stagnating"));
    close(one_f64(&d, "slope_all"), -0.3530860792317223, "floor LSQ");
    // An exact zero at an ok level: excluded (no logarithm), flagged as floor; the rate spans
    // it: ln(1e-3/2.5e-4)/ln(0.1/0.02) = ln 4 / ln 5.
    let d = conv_rows(tmp.path(), HY, "err_u_linfl2");
    assert_eq!(strs(&d, "excluded")[1].as_deref(), Some("zero error"));
    close(
        f64s(&d, "rate")[2].unwrap(),
        4f64.ln() / 5f64.ln(),
        "rate across zero",
    );
    assert_eq!(i64s(&d, "rate_from_level")[2], Some(0));
    assert!(one_bool(&d, "roundoff_floor"));
    assert_eq!(i64s(&d, "failed_levels")[0], Some(0));
    // An ok level without a value: excluded as "no value", not counted as failed.
    let d = conv_rows(tmp.path(), HY, "err_sigma_l2");
    assert_eq!(strs(&d, "excluded")[1].as_deref(), Some("no value"));
    close(
        f64s(&d, "rate")[2].unwrap(),
        1.0,
        "rate across missing value",
    );
    assert_eq!(strs(&d, "flags")[0].as_deref(), Some("-"));

    // The Markdown and LaTeX tables exist, one per path, and show the marks.
    let md = std::fs::read_to_string(tmp.path().join("summary/convergence.md")).unwrap();
    assert_eq!(md.matches("\n## group").count(), 2);
    assert!(
        md.contains("diverged ✗") && md.contains("(1.0000e3) ✗") && md.contains("2.00 †"),
        "{md}"
    );
    assert!(md.contains("| LSQ slope, all usable levels |"));
    // The text tables show the default columns that have values, in the default order; the
    // others are named (the Parquet holds all four, checked above).
    assert!(
        md.contains("| level | h | dt | status | err_u_l2l2 | rate | err_u_l2h1 | rate |"),
        "{md}"
    );
    assert!(!md.contains("| err_u_linfl2 |") && !md.contains("| err_sigma_l2 |"));
    assert!(
        md.contains("No value in this folder for err_sigma_mid_l2, err_energy_l2.")
            && md.contains(
                "Not shown here (in convergence.parquet and .csv): err_u_linfl2, err_sigma_l2."
            ),
        "{md}"
    );
    // LaTeX: one float per method group (two groups of one short path each).
    let tex = std::fs::read_to_string(tmp.path().join("summary/convergence.tex")).unwrap();
    assert_eq!(tex.matches("\\begin{table}").count(), 2);
    assert!(tex.contains("\\toprule") && tex.contains("\\bottomrule"));
    // The failed level: its status column, its value in parentheses, the rate across it.
    assert!(
        tex.contains("$1/48$ & $1/48$ & diverged & ($1.000\\cdot10^{3}$)")
            && tex.contains("$2.00$$^\\dagger$"),
        "{tex}"
    );
    let doc = std::fs::read_to_string(tmp.path().join("summary/convergence_doc.tex")).unwrap();
    assert!(doc.starts_with("% Stand-alone") && doc.contains("\\documentclass"));
    assert!(doc.contains("\\end{document}") && !doc.contains("longtable"));
    // The terminal shows the slopes and flags.
    assert!(
        s.terminal.contains("1.77") && s.terminal.contains("pre-asym"),
        "{}",
        s.terminal
    );
    // CSV mirrors the Parquet.
    let csv = std::fs::read_to_string(tmp.path().join("summary/convergence.csv")).unwrap();
    assert_eq!(csv.lines().count(), all.height() + 1);
}

/// A manifest as `run` writes it: the sweep file's text in each session.
fn write_manifest(dir: &Path, sweep_texts: &[&str]) {
    let sessions: Vec<serde_json::Value> = sweep_texts
        .iter()
        .map(|t| serde_json::json!({ "sweep_file": "s.toml", "sweep_text": t }))
        .collect();
    let doc = serde_json::json!({ "tool": "contact-sweep", "sweep": "x", "sessions": sessions });
    std::fs::write(dir.join("manifest.json"), doc.to_string()).unwrap();
}

#[test]
fn the_summary_table_of_the_stored_sweep_file_chooses_the_columns() {
    let tmp = tempfile::tempdir().unwrap();
    write_runs(tmp.path(), "part-0.parquet", &mut runs_frame(&synthetic()));
    // Two sessions: the latest sweep file's [summary] counts.
    let base = "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n";
    write_manifest(
        tmp.path(),
        &[
            &format!("{base}[summary]\nerrors = [\"err_u_l2l2\"]\n"),
            &format!(
                "{base}[summary]\nerrors = [\"err_sigma_l2\", \"err_u_linfl2\"]\nrates = false\nslopes = false\n"
            ),
        ],
    );
    let stored = summary::stored_options(tmp.path()).unwrap();
    assert_eq!(
        stored,
        summary::SummaryOptions {
            errors: Some(vec!["err_sigma_l2", "err_u_linfl2"]),
            rates: false,
            slopes: false,
            flags: true,
        }
    );
    summary::summarize(tmp.path()).unwrap();
    let md = std::fs::read_to_string(tmp.path().join("summary/convergence.md")).unwrap();
    assert!(
        md.contains("| level | h | dt | status | err_sigma_l2 | err_u_linfl2 |\n"),
        "{md}"
    );
    assert!(!md.contains("| rate") && !md.contains("LSQ slope") && md.contains("| flags |"));
    let tex = std::fs::read_to_string(tmp.path().join("summary/convergence.tex")).unwrap();
    let (sigma, linf) = (
        tex.find("$\\sigma_C^n$: $l^2(\\tau)$")
            .expect("sigma column"),
        tex.find("$u$: $l^\\infty(L^2)$").expect("linf column"),
    );
    assert!(sigma < linf, "chosen order");
    assert!(!tex.contains("& rate") && !tex.contains("LSQ slope") && tex.contains("{flags}"));
    // The Parquet keeps every column whatever the choice.
    assert_eq!(
        read(&tmp.path().join("summary/convergence.parquet")).height(),
        4 * 5 + 4 * 3
    );

    // `summarize --errors` replaces the columns and keeps the rest of the stored choice.
    let flag = summary::SummaryOptions {
        errors: Some(summary::parse_errors(&["err_u_l2h1"]).unwrap()),
        ..stored
    };
    summary::summarize_with(tmp.path(), &flag).unwrap();
    let md = std::fs::read_to_string(tmp.path().join("summary/convergence.md")).unwrap();
    assert!(
        md.contains("| level | h | dt | status | err_u_l2h1 |\n"),
        "{md}"
    );

    // A [summary] table this version refuses: a sweep-file error naming the manifest, the key
    // and the line in the stored text (exit 2 from the CLI).
    write_manifest(
        tmp.path(),
        &[&format!(
            "{base}[summary]\nerrors = [\"err_u_l2h1\", \"nope\"]\n"
        )],
    );
    let err = summary::summarize(tmp.path()).unwrap_err();
    assert!(
        err.chain().any(|c| c
            .downcast_ref::<contact_sweep::sweep::SweepError>()
            .is_some()),
        "{err:#}"
    );
    let msg = format!("{err:#}");
    assert!(
        msg.contains("manifest.json (the sweep file stored in it):7: key `summary.errors`: unknown error column `nope`"),
        "{msg}"
    );
}

#[test]
fn rate_and_slope_functions_use_the_actual_ratios() {
    // e = C h^1.5 on h = 1/4, 1/12, 1/24: every rate and the slope are 1.5 whatever the ratios.
    let h = [0.25, 1.0 / 12.0, 1.0 / 24.0];
    let e: Vec<f64> = h.iter().map(|x: &f64| 7.0 * x.powf(1.5)).collect();
    close(observed_rate(e[0], e[1], h[0], h[1]), 1.5, "rate");
    close(observed_rate(e[1], e[2], h[1], h[2]), 1.5, "rate");
    close(lsq_slope(&h, &e).unwrap(), 1.5, "slope");
    assert_eq!(lsq_slope(&h[..1], &e[..1]), None);
    assert_eq!(lsq_slope(&[0.1, 0.1], &[1.0, 2.0]), None);
}

#[test]
fn extra_unknown_columns_and_missing_columns_from_another_version() {
    let tmp = tempfile::tempdir().unwrap();
    let rows = synthetic();
    // Part 1: this version plus columns it does not know (a float, a string, a list).
    let mut a = runs_frame(&rows[..3]);
    let n = a.height();
    a.with_column(Column::new("future_metric".into(), vec![1.5f64; n]))
        .unwrap();
    a.with_column(Column::new("solver_notes".into(), vec!["fine"; n]))
        .unwrap();
    let lists: Vec<Series> = (0..n)
        .map(|i| Series::new("".into(), [i as i64, 2]))
        .collect();
    a.with_column(Column::new("history".into(), lists)).unwrap();
    // A known column stored with another type (i32 instead of i64).
    a.with_column(Column::new("repeats".into(), vec![3i32; n]))
        .unwrap();
    write_runs(tmp.path(), "part-a.parquet", &mut a);
    // Part 2: an older version without courant, label, message, timing spread, energy
    // columns; elements stored as float; one extra boolean.
    let mut b = runs_frame(&rows[3..5]);
    b = b
        .drop_many([
            "courant",
            "label",
            "message",
            "wall_time_min_s",
            "wall_time_max_s",
            "energy_drift",
            "energy_max_dev",
        ])
        .lazy()
        .with_column(col("elements").cast(DataType::Float64))
        .collect()
        .unwrap();
    let m = b.height();
    b.with_column(Column::new("legacy_flag".into(), vec![true; m]))
        .unwrap();
    write_runs(tmp.path(), "part-b.parquet", &mut b);

    let s = summary::summarize(tmp.path()).unwrap();
    assert_eq!(s.runs, 5);
    for c in ["future_metric", "solver_notes", "history", "legacy_flag"] {
        assert!(
            s.ignored_columns.iter().any(|x| x == c),
            "{c} not reported: {:?}",
            s.ignored_columns
        );
        assert!(s.terminal.contains(c));
    }
    assert!(
        !s.ignored_columns
            .iter()
            .any(|x| x == "repeats" || x == "elements")
    );
    // The old rows (no courant) still join the Courant-1 path: dt/h = 1 is held.
    assert_eq!(s.refinement_paths, 1, "{}", s.terminal);
    let all = read(&tmp.path().join("summary/convergence.parquet"));
    let d = all
        .lazy()
        .filter(col("error").eq(lit("err_u_l2l2")))
        .sort(["level"], SortMultipleOptions::default())
        .collect()
        .unwrap();
    assert_eq!(d.height(), 5);
    assert_eq!(strs(&d, "fixed")[0].as_deref(), Some("dt/h"));
    close(
        one_f64(&d, "slope_all"),
        1.7656461960639913,
        "LSQ all across versions",
    );
    // Unknown columns never reach the outputs.
    for f in [
        "convergence",
        "energy",
        "work_precision",
        "impacts",
        "cost_to_error",
    ] {
        let df = read(&tmp.path().join(format!("summary/{f}.parquet")));
        for c in ["future_metric", "solver_notes", "history", "legacy_flag"] {
            assert!(df.column(c).is_err(), "{c} leaked into {f}");
        }
    }
    // A label is composed for rows without one.
    let e = read(&tmp.path().join("summary/energy.parquet"));
    assert!(
        strs(&e, "label")
            .iter()
            .all(|l| l.as_deref().is_some_and(|l| !l.is_empty()))
    );
}

#[test]
fn no_refinement_axis_says_so_and_still_writes_the_other_sections() {
    let tmp = tempfile::tempdir().unwrap();
    // Three methods, each at a single (h, dt).
    let mut rows = vec![
        run(
            CN,
            "crank-nicolson",
            0.1,
            0.1,
            [Some(0.01), Some(0.1), Some(0.01), Some(0.2)],
        ),
        run(
            HY,
            "hybrid",
            0.1,
            0.1,
            [Some(0.02), Some(0.2), Some(0.02), Some(0.3)],
        ),
        run(
            "nitsche · mod3 · hybrid",
            "hybrid",
            0.1,
            0.1,
            [Some(0.03), Some(0.3), Some(0.03), Some(0.4)],
        ),
    ];
    rows[2].space = "nitsche";
    write_runs(tmp.path(), "part-0.parquet", &mut runs_frame(&rows));
    let s = summary::summarize(tmp.path()).unwrap();
    assert_eq!(s.groups, 3);
    assert_eq!(s.refinement_paths, 0);
    assert!(s.terminal.contains(NO_REFINEMENT), "{}", s.terminal);
    assert_eq!(
        NO_REFINEMENT,
        "no refinement axis: every group has a single (h, dt) level"
    );
    let md = std::fs::read_to_string(tmp.path().join("summary/convergence.md")).unwrap();
    assert!(md.contains(NO_REFINEMENT), "{md}");
    assert!(!md.contains("| level |"), "no empty table");
    // The Parquet keeps its schema with no rows; the other sections are complete.
    let conv = read(&tmp.path().join("summary/convergence.parquet"));
    assert_eq!(conv.height(), 0);
    assert!(conv.column("slope_all").is_ok());
    assert_eq!(read(&tmp.path().join("summary/energy.parquet")).height(), 3);
    assert_eq!(
        read(&tmp.path().join("summary/work_precision.parquet")).height(),
        3 * 4
    );
    for f in [
        "energy.md",
        "work_precision.md",
        "energy_groups.parquet",
        "impacts.parquet",
    ] {
        assert!(tmp.path().join("summary").join(f).exists(), "{f}");
    }
}

#[test]
fn a_folder_without_runs_is_an_error_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let err = summary::summarize(tmp.path()).unwrap_err().to_string();
    assert!(
        err.contains(&tmp.path().display().to_string()) && err.contains("no runs"),
        "{err}"
    );
    // runs/ exists but holds only a temporary of an interrupted write.
    std::fs::create_dir_all(tmp.path().join("runs")).unwrap();
    std::fs::write(tmp.path().join("runs/.tmp-part-0.parquet"), b"partial").unwrap();
    let err = summary::summarize(tmp.path()).unwrap_err().to_string();
    assert!(err.contains("no runs"), "{err}");
    let missing = tmp.path().join("nowhere");
    let err = summary::summarize(&missing).unwrap_err().to_string();
    assert!(
        err.contains("nowhere") && err.contains("no such folder"),
        "{err}"
    );
    assert!(
        !tmp.path().join("summary").exists(),
        "nothing written on error"
    );
}

#[test]
fn energy_classes_and_impact_losses() {
    let tmp = tempfile::tempdir().unwrap();
    let mut rows = vec![
        run(CN, "crank-nicolson", 0.25, 0.25, [None; 4]),
        run(CN, "crank-nicolson", 0.125, 0.125, [None; 4]),
        run(HY, "hybrid", 0.25, 0.25, [None; 4]),
        run(HY, "hybrid", 0.125, 0.125, [None; 4]),
        run(CN, "crank-nicolson", 0.0625, 0.0625, [None; 4]),
    ];
    // ν = dt/h = 1 and L = 1, so δ = max(1, ν)·h/L = h.
    // growing: drift 0.3 > δ = 0.25 (CN has no monotonicity proof: one-step gains alone do not
    // count).
    (rows[0].max_inc, rows[0].drift, rows[0].max_dev) = (Some(2e-10), Some(0.3), Some(0.4));
    // dissipative: drift −0.2 < −δ = −0.125.
    (rows[1].max_inc, rows[1].drift, rows[1].max_dev) = (Some(5e-11), Some(-0.2), Some(0.2));
    // rows[2]: conservative (drift −1e-16, max one-step increase 1e-16 ≤ 1e-10).
    // rows[3]: the 000 §5 hybrid (mixed, scheme hybrid) provably never gains E^h: one step
    // raising it by 2e-10·E0 is growth although the drift (−1e-3) is inside δ = 0.125.
    (rows[3].max_inc, rows[3].drift, rows[3].max_dev) = (Some(2e-10), Some(-1e-3), Some(1e-3));
    // conservative: drift +0.05 within δ = 0.0625, and 2e-10 one-step gains do not count.
    (rows[4].max_inc, rows[4].drift, rows[4].max_dev) = (Some(2e-10), Some(0.05), Some(0.05));
    write_runs(tmp.path(), "part-0.parquet", &mut runs_frame(&rows));

    // Series of the hybrid run, decimated by 2 (steps 0, 2, …, 18): two contact phases.
    // σ_C < 0 at steps 4–6 and 12; energies before/after: 1.0 → 0.7 and 0.7 → 0.6.
    let id = "mixed-hybrid-0.25-0.25";
    let steps: Vec<i64> = (0..10).map(|k| 2 * k).collect();
    let sigma = [0.0, 0.0, -1.0, -2.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0];
    let energy = [1.0, 1.0, 0.9, 0.8, 0.7, 0.7, 0.65, 0.6, 0.6, 0.6];
    let n = steps.len();
    let mut series = DataFrame::new(
        n,
        vec![
            Column::new("run_id".into(), vec![id; n]),
            Column::new("step".into(), &steps),
            Column::new(
                "t".into(),
                steps.iter().map(|&s| s as f64 * 0.25).collect::<Vec<_>>(),
            ),
            Column::new("u_contact".into(), vec![0.0; n]),
            Column::new("sigma_contact".into(), &sigma),
            Column::new("energy".into(), &energy),
            Column::new("energy_theta".into(), vec![None::<f64>; n]),
        ],
    )
    .unwrap();
    let sdir = tmp.path().join("series");
    std::fs::create_dir_all(&sdir).unwrap();
    contact_sweep::sink::write_parquet_atomic(&sdir, "part-0.parquet", &mut series).unwrap();

    summary::summarize(tmp.path()).unwrap();
    let e = read(&tmp.path().join("summary/energy.parquet"))
        .lazy()
        .sort(
            ["label", "h"],
            SortMultipleOptions::default().with_order_descending_multi([false, true]),
        )
        .collect()
        .unwrap();
    assert_eq!(
        strs(&e, "energy_class"),
        [
            "growing",
            "dissipative",
            "conservative",
            "conservative",
            "growing"
        ]
        .map(|s| Some(s.to_string()))
        .to_vec()
    );
    assert_eq!(
        bools(&e, "energy_monotone_by_proof"),
        vec![
            Some(false),
            Some(false),
            Some(false),
            Some(true),
            Some(true)
        ]
    );
    close(f64s(&e, "energy_tolerance")[1].unwrap(), 0.125, "δ = h");
    assert_eq!(
        strs(&e, "energy_functional"),
        vec![Some("E^h".to_string()); 5]
    );
    assert_eq!(i64s(&e, "impacts"), vec![None, None, None, Some(2), None]);
    assert_eq!(bools(&e, "series_decimated")[3], Some(true));
    close(
        f64s(&e, "impact_loss_total")[3].unwrap(),
        0.4,
        "total impact loss",
    );

    let g = read(&tmp.path().join("summary/energy_groups.parquet"));
    let cn = g.lazy().filter(col("label").eq(lit(CN))).collect().unwrap();
    assert_eq!(f64s(&cn, "energy_drift_min"), vec![Some(-0.2)]);
    assert_eq!(f64s(&cn, "energy_drift_max"), vec![Some(0.3)]);
    assert_eq!(i64s(&cn, "growing_runs"), vec![Some(1)]);
    assert_eq!(i64s(&cn, "dissipative_runs"), vec![Some(1)]);
    assert_eq!(i64s(&cn, "conservative_runs"), vec![Some(1)]);
    assert_eq!(
        strs(&cn, "energy_classes"),
        vec![Some("1 conservative, 1 dissipative, 1 growing".to_string())]
    );

    let imp = read(&tmp.path().join("summary/impacts.parquet"));
    assert_eq!(imp.height(), 2);
    assert_eq!(i64s(&imp, "step_first"), vec![Some(4), Some(12)]);
    assert_eq!(i64s(&imp, "step_last"), vec![Some(6), Some(12)]);
    assert_eq!(i64s(&imp, "step_before"), vec![Some(2), Some(10)]);
    assert_eq!(i64s(&imp, "step_after"), vec![Some(8), Some(14)]);
    // (E_before − E_after)/E0 with E0 = 1: 1.0 − 0.7 and 0.7 − 0.6 (to rounding of the
    // subtraction, ≤ 1 ulp of 1).
    let loss = f64s(&imp, "energy_loss_rel");
    close(loss[0].unwrap(), 0.3, "first impact");
    close(loss[1].unwrap(), 0.1, "second impact");
    assert_eq!(
        bools(&imp, "series_decimated"),
        vec![Some(true), Some(true)]
    );
    assert_eq!(i64s(&imp, "series_stride"), vec![Some(2), Some(2)]);
    assert!(
        std::fs::read_to_string(tmp.path().join("summary/energy.md"))
            .unwrap()
            .contains("decimated")
    );
}

/// Frictional rows are judged by the balance E + W_f against δ (energy.rs's header): within δ
/// while E falls by more than δ is "dissipative with friction accounted", below −δ dissipative,
/// above δ growing; a frictionless row with the same E is judged by E as before. h = dt = 0.25,
/// L = 1: δ = 0.25, the values straddle it by at least 0.05.
#[test]
fn frictional_rows_are_judged_by_energy_plus_friction_work() {
    let tmp = tempfile::tempdir().unwrap();
    // (scheme label, friction, E drift, W_f, balance drift, expected class)
    let cases = [
        (
            "fa",
            "coulomb",
            -0.5,
            0.49,
            -0.01,
            "dissipative with friction accounted",
        ),
        ("fb", "coulomb", -0.6, 0.2, -0.4, "dissipative"),
        ("fc", "coulomb", 0.1, 0.2, 0.3, "growing"),
        ("fd", "coulomb", -0.1, 0.1, 0.0, "conservative"),
        ("fe", "none", -0.5, f64::NAN, f64::NAN, "dissipative"),
    ];
    let mut rows: Vec<R> = cases
        .iter()
        .map(|c| run(c.0, c.0, 0.25, 0.25, [None; 4]))
        .collect();
    for (r, c) in rows.iter_mut().zip(&cases) {
        r.drift = Some(c.2);
    }
    let mut df = runs_frame(&rows);
    let opt = |x: f64| (!x.is_nan()).then_some(x);
    let n = cases.len();
    for col in [
        Column::new(
            "friction".into(),
            cases.iter().map(|c| Some(c.1)).collect::<Vec<_>>(),
        ),
        Column::new(
            "friction_work".into(),
            cases.iter().map(|c| opt(c.3)).collect::<Vec<_>>(),
        ),
        Column::new(
            "energy_balance_drift".into(),
            cases.iter().map(|c| opt(c.4)).collect::<Vec<_>>(),
        ),
        Column::new(
            "energy_balance_max_increase".into(),
            cases
                .iter()
                .map(|c| opt(c.4).map(|_| 1e-3))
                .collect::<Vec<_>>(),
        ),
    ] {
        assert_eq!(col.len(), n);
        df.with_column(col).unwrap();
    }
    write_runs(tmp.path(), "part-0.parquet", &mut df);
    summary::summarize(tmp.path()).unwrap();
    let e = read(&tmp.path().join("summary/energy.parquet"));
    let (labels, classes, functional) = (
        strs(&e, "label"),
        strs(&e, "energy_class"),
        strs(&e, "energy_functional"),
    );
    let m = read(&tmp.path().join("summary/methods.parquet"));
    let (methods, energy) = (strs(&m, "method"), strs(&m, "energy"));
    for c in &cases {
        let k = labels
            .iter()
            .position(|l| l.as_deref() == Some(c.0))
            .unwrap();
        assert_eq!(classes[k].as_deref(), Some(c.5), "{}", c.0);
        let want = if c.1 == "none" { "E^h" } else { "E^h + W_f" };
        assert_eq!(functional[k].as_deref(), Some(want), "{}", c.0);
        // The method-class table's word for the same class (one run per group).
        let j = methods
            .iter()
            .position(|l| l.as_deref() == Some(c.0))
            .unwrap();
        let word = if c.5 == "conservative" {
            "conserving"
        } else {
            c.5
        };
        assert_eq!(energy[j].as_deref(), Some(word), "{}", c.0);
    }
}

#[test]
fn pareto_front_and_cost_to_reach_an_error() {
    // (cost, error): (1, 5) (2, 3) (2, 4) (3, 3) (4, 1) (4, 1): (2, 4) is beaten by (2, 3) at
    // equal cost, (3, 3) by (2, 3); the two identical (4, 1) dominate neither each other.
    let pts = [
        (1.0, 5.0),
        (2.0, 3.0),
        (2.0, 4.0),
        (3.0, 3.0),
        (4.0, 1.0),
        (4.0, 1.0),
    ];
    assert_eq!(
        pareto_front(&pts),
        vec![true, true, false, false, true, true]
    );
    // c = 2 e^-2 exactly: the log-log interpolant reproduces it between any two points.
    let c = |e: f64| 2.0 / (e * e);
    close(
        loglog_cost(0.03, (0.1, c(0.1)), (0.01, c(0.01))).unwrap(),
        c(0.03),
        "loglog",
    );

    let tmp = tempfile::tempdir().unwrap();
    write_runs(tmp.path(), "part-0.parquet", &mut runs_frame(&synthetic()));
    summary::summarize(tmp.path()).unwrap();
    let cost = read(&tmp.path().join("summary/cost_to_error.parquet"))
        .lazy()
        .filter(
            col("label")
                .eq(lit(CN))
                .and(col("error").eq(lit("err_u_l2l2")))
                .and(col("epsilon").eq(lit(1e-2))),
        )
        .collect()
        .unwrap();
    assert_eq!(strs(&cost, "reached"), vec![Some("interpolated".into())]);
    // ε = 1e-2 lies between e = 0.02 (h = 1/12, wall 1e-3·144) and 0.006 (h = 1/24, wall
    // 1e-3·576): wall = 0.144 · 4^s, s = ln(0.01/0.02)/ln(0.006/0.02).
    let s = (0.5f64).ln() / (0.3f64).ln();
    close(
        f64s(&cost, "wall_time_s")[0].unwrap(),
        0.144 * 4f64.powf(s),
        "cost to 1e-2",
    );
    // work = steps × dofs = 144 and 576 on the same levels.
    close(
        f64s(&cost, "work")[0].unwrap(),
        144.0 * 4f64.powf(s),
        "work to 1e-2",
    );
    // ε = 1e-1 equals the coarsest CN error: the crossing is at that level, so its own cost
    // (1e-3 / (1/4)² = 0.016 s).
    let first = read(&tmp.path().join("summary/cost_to_error.parquet"))
        .lazy()
        .filter(
            col("label")
                .eq(lit(CN))
                .and(col("error").eq(lit("err_u_l2l2")))
                .and(col("epsilon").eq(lit(1e-1))),
        )
        .collect()
        .unwrap();
    close(
        f64s(&first, "wall_time_s")[0].unwrap(),
        0.016,
        "cost to 1e-1",
    );
    let wp = read(&tmp.path().join("summary/work_precision.parquet"));
    let ok_l2 = wp
        .lazy()
        .filter(
            col("error")
                .eq(lit("err_u_l2l2"))
                .and(col("status").eq(lit("ok"))),
        )
        .collect()
        .unwrap();
    assert_eq!(ok_l2.height(), 7);
    // Every ok run has a Pareto verdict, the failed one none.
    assert!(bools(&ok_l2, "pareto_wall").iter().all(Option::is_some));
    let md = std::fs::read_to_string(tmp.path().join("summary/work_precision.md")).unwrap();
    assert!(
        md.contains("Pareto front") && md.contains("ε = 1e-2"),
        "{md}"
    );
}

/// The method-class table (`summary/methods.*`): one row per method group, its words computed
/// from the runs — the worst energy class, the largest pressure_oscillation against the
/// smooth threshold (5), the largest max_penetration against 1e-12·L, and the LSQ slopes of
/// err_u_l2l2 and err_u_l2h1 along the τ ∝ h path. Errors are exact power laws of h here
/// (0.1h and h^½; h² and h), so the slopes are 1, ½, 2, 1 to the rounding of the logarithms
/// ([`TOL`]).
#[test]
fn method_class_table_is_computed_from_the_runs() {
    let dir = tempfile::tempdir().unwrap();
    let hs: [f64; 3] = [0.25, 0.125, 0.0625];
    let mut rows = Vec::new();
    for &h in &hs {
        let e = [Some(0.1 * h), Some(h.sqrt()), None, None];
        rows.push(run("mixed · consistent · kane", "kane", h, h, e));
    }
    for (k, &h) in hs.iter().enumerate() {
        let e = [Some(h * h), Some(h), None, None];
        let mut r = run("mixed · consistent · moreau-jean", "moreau-jean", h, h, e);
        if k == 1 {
            // E gained 50 % > δ = h: the method can grow energy.
            r.drift = Some(0.5);
        }
        rows.push(r);
    }
    let mut df = runs_frame(&rows);
    let osc = [1.0, 3.0, 4.9, 2.0, 11.3, 3.0];
    let pen = [0.0, 1e-18, 0.0, 1e-3, 5e-4, 2.5e-4];
    df.with_column(Column::new("pressure_oscillation".into(), osc.to_vec()))
        .unwrap();
    df.with_column(Column::new("max_penetration".into(), pen.to_vec()))
        .unwrap();
    write_runs(dir.path(), "part-0.parquet", &mut df);
    summary::summarize(dir.path()).unwrap();
    let t = read(&dir.path().join("summary/methods.parquet"));
    let methods = strs(&t, "method");
    let row = |label: &str| {
        methods
            .iter()
            .position(|m| m.as_deref() == Some(label))
            .unwrap_or_else(|| panic!("{label} not in {methods:?}"))
    };
    let (a, b) = (
        row("mixed · consistent · kane"),
        row("mixed · consistent · moreau-jean"),
    );
    let (energy, pressure, penetration) = (
        strs(&t, "energy"),
        strs(&t, "pressure"),
        strs(&t, "penetration"),
    );
    assert_eq!(energy[a].as_deref(), Some("conserving"));
    assert_eq!(energy[b].as_deref(), Some("growing"));
    assert_eq!(pressure[a].as_deref(), Some("smooth"));
    assert_eq!(pressure[b].as_deref(), Some("oscillating"));
    assert_eq!(penetration[a].as_deref(), Some("none"));
    assert_eq!(penetration[b].as_deref(), Some("O(τ)"));
    assert_eq!(f64s(&t, "pressure_oscillation_max")[b], Some(11.3));
    let (l2, h1) = (f64s(&t, "rate_l2"), f64s(&t, "rate_h1"));
    close(l2[a].unwrap(), 1.0, "kane L2 rate");
    close(h1[a].unwrap(), 0.5, "kane H1 rate");
    close(l2[b].unwrap(), 2.0, "moreau-jean L2 rate");
    close(h1[b].unwrap(), 1.0, "moreau-jean H1 rate");
    let md = std::fs::read_to_string(dir.path().join("summary/methods.md")).unwrap();
    assert!(
        md.contains("smooth if max pressure_oscillation ≤ 5"),
        "{md}"
    );
    assert!(dir.path().join("summary/methods.tex").is_file());
    assert!(dir.path().join("summary/methods.csv").is_file());
}
