//! Round-off ensembles (`ensemble = { perturbation, samples, seed }`): the members of one run —
//! equal in every parameter and level (h, dt), differing only in `ensemble_sample`, i.e. in a
//! relative perturbation ε of u⁰ — form one *ensemble*, summarised by the min / median / max of
//! every error and energy column and a `sensitive` flag.
//!
//! # Why a spread means something
//! A well-posed discrete problem is Lipschitz in its data: perturbing u⁰ by ε moves every
//! output by at most L·ε, and for the schemes contract §6 calls stable the measured moves under
//! ε = 1e-14 stay below 1e-9 relative (L ≲ 1e5 over a whole run). An ill-posed one — mixed or
//! Nitsche (γ0 → 0) with the consistent mass and Crank–Nicolson at ν = 1.5 — chooses between
//! contact branches that round-off decides, and E(T)/E⁰ lands anywhere in ≈ 1.07–3.9 (contract §6).
//!
//! # The flag
//! For a column x over the ok members, the relative spread is
//!
//! ```text
//!     s(x) = (max x − min x) / |median x|
//! ```
//!
//! and an ensemble is `sensitive` when s(E(T)/E⁰) or s(e) for any error column e exceeds
//! [`sensitive_tol`]`(ε) = max(1e-6, 1e8·ε)`: at ε = 1e-14 that is 1e-6, a thousand times the
//! largest move of a well-posed run and five decades below the spread of an ill-posed one
//! (≥ 0.1), so neither rounding nor a mild amplification can flag a stable method; for larger
//! perturbations the threshold grows with ε so that the same amplification L = 1e8 is what
//! counts as sensitive. Members that end with different statuses (one diverges, another does
//! not) are sensitive whatever the numbers. The one-step energy increases are reported but do
//! not flag: for a conservative run they are rounding noise (≈ 1e-16), whose relative spread is
//! of order one without meaning anything.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::columns::{Kind, columns};
use super::runs::{Cell, Run, Runs, float_key};
use super::table::{self, Table, TextTable, text_columns};

/// The relative spread above which an ensemble is sensitive, for perturbations of relative
/// size `eps` (see the module header).
pub fn sensitive_tol(eps: f64) -> f64 {
    1e-6_f64.max(1e8 * eps)
}

/// One measured column: its name in the tables and how to read it from a run.
struct Metric {
    name: &'static str,
    get: fn(&Run) -> Option<f64>,
    /// Whether its spread can flag the ensemble (E(T)/E⁰ and the errors).
    flags: bool,
}

/// The energy columns an ensemble summarises: E(T)/E⁰ flags (with the errors), the others are
/// shown.
fn energy_metrics() -> Vec<Metric> {
    let shown = |name, get| Metric {
        name,
        get,
        flags: false,
    };
    vec![
        Metric {
            name: "energy_ratio",
            get: Run::energy_ratio,
            flags: true,
        },
        shown("energy_max_dev", |r| r.energy_max_dev),
        shown("energy_max_increase", |r| r.energy_max_increase),
        shown("energy_theta_drift", |r| r.energy_theta_drift),
        shown("energy_theta_max_increase", |r| r.energy_theta_max_increase),
    ]
}

/// Min, median, max of the finite values (the median of an even count is the mean of the two
/// middle values).
pub(crate) fn stats(mut v: Vec<f64>) -> Option<(f64, f64, f64)> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let med = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    Some((v[0], med, v[n - 1]))
}

/// (max − min)/|median|; 0 when all values are equal (also when they are all 0).
pub(crate) fn rel_spread((lo, med, hi): (f64, f64, f64)) -> f64 {
    if hi == lo {
        0.0
    } else if med == 0.0 {
        f64::INFINITY
    } else {
        (hi - lo) / med.abs()
    }
}

/// One ensemble's verdict.
#[derive(Debug, Clone)]
struct Ensemble {
    sensitive: bool,
    /// Why it is sensitive (columns whose spread exceeds the tolerance, or mixed statuses).
    reasons: Vec<String>,
}

/// The ensemble section's outputs.
pub(crate) struct Section {
    pub table: Table,
    pub markdown: String,
    pub terminal: String,
}

/// Build the ensemble section (empty tables when the folder holds no ensemble).
pub(crate) fn section(runs: &Runs) -> Section {
    let energy = energy_metrics();
    let mut t = Table::new(&ensemble_columns(runs, &energy));
    let mut out = Vec::new();
    let mut md_rows: Vec<Vec<String>> = Vec::new();
    for ((g, _, _), members) in ensembles(runs) {
        let (verdict, row) = ensemble_row(&mut t, runs, &energy, g, &members);
        md_rows.push(row);
        out.push(verdict);
    }
    let (markdown, terminal) = texts(&out, md_rows);
    Section {
        table: t,
        markdown,
        terminal,
    }
}

/// The ensemble table's columns: its own, min/median/max/spread of every energy metric and
/// error column, then the parameters.
fn ensemble_columns(runs: &Runs, energy: &[Metric]) -> Vec<(String, Kind)> {
    let mut columns: Vec<(String, Kind)> = table::owned(&columns![
        group: I64, group_title: Str, label: Str, h: F64, dt: F64, courant: F64,
        perturbation: F64, members: I64, ok_members: I64, statuses: Str, tolerance: F64,
        sensitive: Bool, sensitive_columns: Str,
    ]);
    let metric_names: Vec<&str> = energy
        .iter()
        .map(|m| m.name)
        .chain(runs.errors.iter().copied())
        .collect();
    for m in &metric_names {
        for suffix in ["min", "median", "max", "spread"] {
            columns.push((format!("{m}_{suffix}"), Kind::F64));
        }
    }
    columns.extend(runs.param_columns());
    columns
}

/// The ensembles of the folder: members of the same group (every parameter but the sample
/// index) and the same level, keyed by (group, h, dt).
fn ensembles(runs: &Runs) -> BTreeMap<(usize, String, String), Vec<usize>> {
    let mut by_key: BTreeMap<(usize, String, String), Vec<usize>> = BTreeMap::new();
    for (i, r) in runs.runs.iter().enumerate() {
        if r.ensemble_sample.is_none() {
            continue;
        }
        let k = |x: Option<f64>| x.map(float_key).unwrap_or_default();
        by_key
            .entry((r.group, k(r.h), k(r.dt)))
            .or_default()
            .push(i);
    }
    by_key
}

/// One ensemble's row of the table (group `g`, runs `members`); returns its verdict and its
/// Markdown row.
fn ensemble_row(
    t: &mut Table,
    runs: &Runs,
    energy: &[Metric],
    g: usize,
    members: &[usize],
) -> (Ensemble, Vec<String>) {
    let rs: Vec<&Run> = members.iter().map(|&i| &runs.runs[i]).collect();
    let ok: Vec<&Run> = rs.iter().copied().filter(|r| r.ok()).collect();
    let first = rs[0];
    let eps = first
        .params
        .iter()
        .zip(&runs.params)
        .find(|(_, (n, _))| *n == "ensemble_perturbation")
        .and_then(|(c, _)| match c {
            Cell::F64(x) => *x,
            _ => None,
        })
        .unwrap_or(0.0);
    let tol = sensitive_tol(eps);
    let mut statuses: BTreeMap<&str, usize> = BTreeMap::new();
    for r in &rs {
        *statuses.entry(r.status.as_str()).or_default() += 1;
    }
    let status_text = statuses
        .iter()
        .map(|(s, n)| format!("{n} {s}"))
        .collect::<Vec<_>>()
        .join(", ");
    let mut reasons = Vec::new();
    if statuses.len() > 1 {
        reasons.push(format!("statuses differ ({status_text})"));
    }
    t.i64("group", Some(g as i64 + 1));
    t.str("group_title", Some(&runs.groups[g].title));
    t.str("label", Some(&first.label));
    t.f64("h", first.h);
    t.f64("dt", first.dt);
    t.f64("courant", first.courant);
    t.f64("perturbation", Some(eps));
    t.i64("members", Some(rs.len() as i64));
    t.i64("ok_members", Some(ok.len() as i64));
    t.str("statuses", Some(&status_text));
    t.f64("tolerance", Some(tol));
    let mut ratio = None;
    let mut shown: Vec<String> = Vec::new();
    for m in energy {
        let vals = ok.iter().filter_map(|r| (m.get)(r)).collect();
        let st = record(t, m.name, vals, m.flags, tol, &mut reasons);
        if m.name == "energy_ratio" {
            ratio = st;
        }
    }
    for (j, e) in runs.errors.iter().enumerate() {
        let vals = ok.iter().filter_map(|r| r.errors[j]).collect();
        let st = record(t, e, vals, true, tol, &mut reasons);
        if *e == "err_u_l2h1" {
            shown.push(spread_text(st));
        }
    }
    let sensitive = !reasons.is_empty();
    t.bool("sensitive", Some(sensitive));
    t.str("sensitive_columns", Some(&reasons.join("; ")));
    for ((n, _), c) in runs.params.iter().zip(&first.params) {
        if *n != "ensemble_sample" {
            t.cell(n, c);
        }
    }
    t.end_row();
    let row = vec![
        (g + 1).to_string(),
        runs.groups[g].title.clone(),
        table::sci(first.h),
        table::sci(first.dt),
        format!("{}/{}", ok.len(), rs.len()),
        spread_text(ratio),
        ratio
            .map(|r| table::sci(Some(rel_spread(r))))
            .unwrap_or_default(),
        shown.pop().unwrap_or_default(),
        if sensitive { "**sensitive**" } else { "no" }.to_string(),
        reasons.join("; "),
    ];
    (Ensemble { sensitive, reasons }, row)
}

/// One column's min, median, max and spread over the ok members, into the current row of
/// `t`; a spread above `tol` of a flagging column (`flags`) adds a reason. Returns the stats.
fn record(
    t: &mut Table,
    name: &str,
    vals: Vec<f64>,
    flags: bool,
    tol: f64,
    reasons: &mut Vec<String>,
) -> Option<(f64, f64, f64)> {
    let st = stats(vals);
    let spread = st.map(rel_spread);
    if let Some((lo, med, hi)) = st {
        t.f64(&format!("{name}_min"), Some(lo));
        t.f64(&format!("{name}_median"), Some(med));
        t.f64(&format!("{name}_max"), Some(hi));
    } else {
        t.f64(&format!("{name}_min"), None);
        t.f64(&format!("{name}_median"), None);
        t.f64(&format!("{name}_max"), None);
    }
    t.f64(&format!("{name}_spread"), spread.filter(|s| s.is_finite()));
    if flags && spread.is_some_and(|s| s > tol) {
        reasons.push(format!("{name} spread {}", table::sci(spread)));
    }
    st
}

/// `ensemble.md` and the terminal's lines from the verdicts and Markdown rows of the
/// ensembles.
fn texts(out: &[Ensemble], md_rows: Vec<Vec<String>>) -> (String, String) {
    let mut md = String::from("# Round-off ensembles\n\n");
    let mut terminal = String::new();
    if out.is_empty() {
        md.push_str("No ensemble in this folder (`ensemble = { perturbation, samples, seed }`).\n");
    } else {
        let _ = writeln!(
            md,
            "Members: runs equal in every parameter and level, differing in `ensemble_sample` \
             (u⁰ perturbed by a relative ε). Per column min / median / max over the ok members \
             (ensemble.parquet holds every error and energy column); spread = (max − min)/|median|. \
             Sensitive: the spread of E(T)/E⁰ or of an error exceeds max(1e-6, 1e8·ε), or the \
             members end with different statuses — the result is decided by round-off and no \
             single digit of it means anything.\n"
        );
        let text = TextTable::new(text_columns![
            "#" => Right, "group" => Left, "h" => Right, "dt" => Right, "ok/members" => Right,
            "E(T)/E⁰ min · median · max" => Right, "spread" => Right,
            "l2(τ;H1) min · median · max" => Right, "sensitive" => Left, "why" => Left,
        ])
        .with_rows(md_rows);
        md.push_str(&text.markdown());
        let n_sens = out.iter().filter(|e| e.sensitive).count();
        let _ = writeln!(
            terminal,
            "ensembles: {} of {} sensitive to round-off",
            n_sens,
            out.len()
        );
        for (row, e) in text.rows().iter().zip(out) {
            let _ = writeln!(
                terminal,
                "  {:<9} {} (h = {}, dt = {}): E(T)/E⁰ {}{}",
                if e.sensitive { "SENSITIVE" } else { "stable" },
                row[1],
                row[2],
                row[3],
                row[5],
                if e.sensitive {
                    format!(" — {}", e.reasons.join("; "))
                } else {
                    String::new()
                }
            );
        }
    }
    (md, terminal)
}

fn spread_text(st: Option<(f64, f64, f64)>) -> String {
    match st {
        Some((lo, med, hi)) => format!("{lo:.6} · {med:.6} · {hi:.6}"),
        None => String::new(),
    }
}
