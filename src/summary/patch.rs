//! The contact patch test as a table (contract §1.10, §6; issue 45): for the runs of the
//! patch-test setting, one row per contact method and, per dimension × `mesh_ratio` ×
//! refinement, the two errors `patch_stress_error` and `patch_pressure_error`, with a verdict
//! per method, dimension and ratio — the textbook table (Taylor–Papadopoulos; Zavarise–De
//! Lorenzis 2009), computed.
//!
//! # Which runs
//! The runs of contract §1.10's patch test: a `pressure` p > 0, `far_end = "clamped"`, gap 0 and
//! `velocity` 0 — the static setting whose exact solution is uniform (σ = −p e_d⊗e_d, contact
//! pressure p) and which Q1/P1 represent exactly. Any other run with a pressure also reports the
//! two columns (a dynamic run under a load), but there they measure the dynamics, not a patch
//! test, and are not read here.
//!
//! # Rows and columns
//! A *method* is every parameter of the summary's groups except the scene (its dimension) and
//! `mesh_ratio`; its label spells the contact keys that apply (`space`, `pairing`,
//! `mortar_basis`, `interface_quadrature`, `nitsche_sides`, Θ) and any other parameter that
//! varies among the patch runs. A column group is one (scene, `mesh_ratio`); inside it the
//! refinements are A's elements across, n_a = round(W/h).
//!
//! # Verdicts (per method, scene and ratio)
//! - `passes`: every refinement ran and both errors are ≤ [`PATCH_TOL`] on each (contract §6's
//!   bound: the exact cases measure ≤ 4.4e-11, the failing ones ≥ 5e-4);
//! - `fails (shrinking, rate p)` / `fails (not shrinking, rate p)`: p is the least-squares slope
//!   of log e against log h, e = the larger of the two errors at each refinement; shrinking
//!   when p > [`STAGNATION_SLOPE`] (the convergence section's "stagnating" threshold). The
//!   textbook failures (node-to-segment, the `element` quadrature on non-matching faces) do
//!   not shrink: their error is a consistency error of the interface transfer, not of h;
//! - `fails (one refinement)`: too few levels to say;
//! - `fails (k runs STATUS)`: a run of the cell did not end ok — it did not solve the patch
//!   problem (its errors, where it stopped, are not the method's; the tables show its status);
//! - `incomplete (k without errors)`: an ok run without the two columns (another version).
//!
//! Written as `patch_test.{parquet,csv,md}` (only when the folder has patch-test runs, so the
//! summaries of other folders keep their files and bytes); the Parquet/CSV row is the method
//! with a column per (scene, ratio, n_a, error) and a verdict and rate per (scene, ratio).

use std::collections::BTreeMap;

use super::columns::Kind;
use super::rates::{STAGNATION_SLOPE, lsq_slope};
use super::runs::{Cell, Run, Runs};
use super::table::{Align, Table, TextTable};

/// Largest error a passing patch test may show (contract §6).
pub const PATCH_TOL: f64 = 1e-8;

/// The contact keys a method row spells, in this order (each where it applies: null elsewhere).
const METHOD_KEYS: &[&str] = &[
    "space",
    "pairing",
    "mortar_basis",
    "interface_quadrature",
    "nitsche_sides",
    "nitsche_theta",
];

/// Keys that place a run in the table's columns rather than its rows.
const COLUMN_KEYS: &[&str] = &["scene", "mesh_ratio"];

/// The patch-test table.
pub(crate) struct Section {
    pub table: Table,
    pub markdown: String,
    pub terminal: String,
    /// The verdict table (one row per method, a column per scene and ratio).
    pub verdicts: TextTable,
    /// Per (scene, ratio): its heading and its table of errors per refinement.
    pub details: Vec<(String, TextTable)>,
    pub legend: String,
}

impl Section {
    /// Whether the folder has patch-test runs (the files are written only then).
    pub(crate) fn is_empty(&self) -> bool {
        self.verdicts.is_empty()
    }
}

/// Whether run `r` is a run of the patch-test setting (module header).
fn is_patch(runs: &Runs, r: &Run) -> bool {
    let num = |k: &str| runs.param_f64(r, k);
    num("pressure").is_some_and(|p| p > 0.0)
        && runs.param_str(r, "far_end") == Some("clamped")
        && num("gap") == Some(0.0)
        && num("velocity") == Some(0.0)
}

/// A column group: the scene and the ratio (None: a scene without one, a two-body file).
#[derive(Clone, Debug, PartialEq, PartialOrd)]
struct Place {
    scene: String,
    ratio: Option<f64>,
}

impl Place {
    /// "2D", "3D" for the blocks (their dimension is what the table compares), else the scene.
    fn dim(&self) -> String {
        match self.scene.as_str() {
            "blocks2d" => "2D".into(),
            "blocks3d" => "3D".into(),
            s => s.into(),
        }
    }

    fn heading(&self) -> String {
        match self.ratio {
            Some(x) => format!("{}, mesh_ratio {}", self.dim(), ratio_label(x)),
            None => self.dim(),
        }
    }

    fn short(&self) -> String {
        match self.ratio {
            Some(x) => format!("{} {}", self.dim(), ratio_label(x)),
            None => self.dim(),
        }
    }

    /// The prefix of its Parquet columns: `blocks2d_r4_3`.
    fn stem(&self) -> String {
        match self.ratio {
            Some(x) => format!(
                "{}_r{}",
                self.scene,
                ratio_label(x).replace(['/', '.'], "_")
            ),
            None => self.scene.clone(),
        }
    }
}

/// A ratio as the sweep files write it: a fraction p/q (q ≤ 12) when it is one to 1e-9
/// (4/3, 7/5, 1), else its decimal form.
fn ratio_label(x: f64) -> String {
    for q in 1..=12u32 {
        let p = x * f64::from(q);
        if (p - p.round()).abs() <= 1e-9 * p.abs().max(1.0) {
            let p = p.round() as i64;
            return if q == 1 {
                p.to_string()
            } else {
                format!("{p}/{q}")
            };
        }
    }
    format!("{x}")
}

/// One refinement of one cell: (n_a or None, h, the run).
type Level<'a> = (Option<i64>, f64, &'a Run);

/// A method's runs by column group, each group's levels coarse → fine.
struct Row<'a> {
    label: String,
    first: &'a Run,
    cells: BTreeMap<usize, Vec<Level<'a>>>,
}

/// One refinement as the verdict reads it: h, the run's status, its two errors.
type Measured<'a> = (f64, &'a str, Option<f64>, Option<f64>);

/// The verdict of one cell (module header) and the slope it is based on.
fn verdict(levels: &[Measured]) -> (String, Option<f64>) {
    // A run that did not end ok failed to solve the patch problem: its errors are where it
    // stopped, not the method's.
    let mut not_ok: Vec<&str> = levels
        .iter()
        .filter(|(_, status, _, _)| *status != "ok")
        .map(|(_, status, _, _)| *status)
        .collect();
    if !not_ok.is_empty() {
        not_ok.sort_unstable();
        not_ok.dedup();
        let k = levels.iter().filter(|l| l.1 != "ok").count();
        let runs = if k == 1 { "run" } else { "runs" };
        return (format!("fails ({k} {runs} {})", not_ok.join(", ")), None);
    }
    let missing = levels
        .iter()
        .filter(|(_, _, s, p)| s.is_none() || p.is_none())
        .count();
    if missing > 0 {
        return (format!("incomplete ({missing} without errors)"), None);
    }
    // The larger error of each level (both are Some: checked above).
    let errs: Vec<(f64, f64)> = levels
        .iter()
        .filter_map(|&(h, _, s, p)| Some((h, s?.max(p?))))
        .collect();
    if errs.iter().all(|(_, e)| *e <= PATCH_TOL) {
        return ("passes".into(), None);
    }
    let (hs, es): (Vec<f64>, Vec<f64>) = errs.into_iter().filter(|(_, e)| *e > 0.0).unzip();
    let Some(p) = lsq_slope(&hs, &es) else {
        return ("fails (one refinement)".into(), None);
    };
    // A flat error's slope is round-off around 0: printed 0.00, not −0.00.
    let shown = if p.abs() < 5e-3 { 0.0 } else { p };
    let trend = if p > STAGNATION_SLOPE {
        "shrinking"
    } else {
        "not shrinking"
    };
    (format!("fails ({trend}, rate {shown:.2})"), Some(p))
}

/// `1.23e-13`; empty for a missing value.
fn short_sci(x: Option<f64>) -> String {
    x.map(|x| format!("{x:.2e}")).unwrap_or_default()
}

/// The method rows and the column groups of the patch-test runs.
fn collect(runs: &Runs) -> (Vec<Row<'_>>, Vec<Place>) {
    let patch: Vec<&Run> = runs.runs.iter().filter(|r| is_patch(runs, r)).collect();
    let col = |name: &str| runs.params.iter().position(|(n, _)| *n == name);
    let skip: Vec<Option<usize>> = COLUMN_KEYS
        .iter()
        .chain(&["ensemble_sample"])
        .map(|k| col(k))
        .collect();
    // The parameters (other than the spelled keys and the columns' own) that vary among the
    // patch runs: a row's label names them.
    let varying: Vec<usize> = (0..runs.params.len())
        .filter(|&j| !skip.contains(&Some(j)) && !METHOD_KEYS.contains(&runs.params[j].0))
        .filter(|&j| {
            // Two values at least (a key null where it does not apply does not vary).
            let mut keys = patch
                .iter()
                .filter(|r| r.params[j].show().is_some())
                .map(|r| r.params[j].key());
            let first = keys.next();
            keys.any(|k| Some(k) != first)
        })
        .collect();
    let mut places: Vec<Place> = Vec::new();
    let mut rows: BTreeMap<String, Row> = BTreeMap::new();
    for r in &patch {
        let place = Place {
            scene: runs.param_str(r, "scene").unwrap_or("").to_string(),
            ratio: runs.param_f64(r, "mesh_ratio"),
        };
        let pi = match places.iter().position(|p| *p == place) {
            Some(i) => i,
            None => {
                places.push(place);
                places.len() - 1
            }
        };
        let key: String = r
            .params
            .iter()
            .enumerate()
            .filter(|(j, _)| !skip.contains(&Some(*j)))
            .map(|(_, c)| c.key())
            .collect::<Vec<_>>()
            .join("|");
        let row = rows.entry(key).or_insert_with(|| Row {
            label: method_label(runs, r, &varying),
            first: r,
            cells: BTreeMap::new(),
        });
        let h = r.h.unwrap_or(f64::NAN);
        let width = runs.param_f64(r, "width").unwrap_or(1.0);
        let n_a = (runs.param_f64(r, "width").is_some() || place_is_blocks(&places[pi]))
            .then(|| (width / h).round() as i64);
        row.cells.entry(pi).or_default().push((n_a, h, r));
    }
    // Column groups by scene, then ratio; the rows' cells renumbered to match.
    let mut order: Vec<usize> = (0..places.len()).collect();
    order.sort_by(|&a, &b| {
        (&places[a].scene, places[a].ratio.unwrap_or(0.0))
            .partial_cmp(&(&places[b].scene, places[b].ratio.unwrap_or(0.0)))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let new_index = |old: usize| order.iter().position(|&o| o == old).expect("a place");
    let mut out: Vec<Row> = rows.into_values().collect();
    for row in &mut out {
        let cells = std::mem::take(&mut row.cells);
        for (pi, mut levels) in cells {
            // Coarse → fine.
            levels.sort_by(|a, b| b.1.total_cmp(&a.1));
            row.cells.insert(new_index(pi), levels);
        }
    }
    out.sort_by_cached_key(|row| (rank(runs, row.first), row.label.clone()));
    let places = order.into_iter().map(|i| places[i].clone()).collect();
    (out, places)
}

/// A row's place in the table: the textbook's order of the contact keys' values (treatment,
/// then pairing, basis, quadrature, sides, Θ = 1, 0, −1), unknown values after the known ones.
fn rank(runs: &Runs, r: &Run) -> Vec<usize> {
    const ORDER: &[(&str, &[&str])] = &[
        ("space", &["mixed", "penalty", "nitsche"]),
        ("pairing", &["node-to-node", "node-to-segment", "mortar"]),
        ("mortar_basis", &["standard", "dual"]),
        ("interface_quadrature", &["segment", "element"]),
        ("nitsche_sides", &["unbiased", "a"]),
        ("nitsche_theta", &["1", "0", "-1"]),
    ];
    ORDER
        .iter()
        .map(|(k, words)| {
            let v = applies(runs, r, k)
                .then(|| runs.param(r, k).and_then(Cell::show))
                .flatten();
            v.and_then(|v| words.iter().position(|w| *w == v))
                .unwrap_or(words.len())
        })
        .collect()
}

fn place_is_blocks(p: &Place) -> bool {
    p.scene.starts_with("blocks")
}

/// Whether contact key `k` applies to run `r` (contract §2.6): the pairing to `mixed` and
/// `penalty`, the mortar basis to the mortar pairing, the interface quadrature to the mortar
/// rows and Nitsche, the sides and Θ to Nitsche. A folder may fill a key where it does not
/// apply (a default it records): the table shows it only where it means something.
fn applies(runs: &Runs, r: &Run, k: &str) -> bool {
    let space = runs.param_str(r, "space").unwrap_or("");
    let mortar = runs.param_str(r, "pairing") == Some("mortar");
    match k {
        "pairing" => space != "nitsche",
        "mortar_basis" => space != "nitsche" && mortar,
        "interface_quadrature" => space == "nitsche" || mortar,
        "nitsche_sides" | "nitsche_theta" => space == "nitsche",
        _ => true,
    }
}

/// A row's label: the contact keys that apply, then the other parameters that vary.
fn method_label(runs: &Runs, r: &Run, varying: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    for k in METHOD_KEYS.iter().filter(|k| applies(runs, r, k)) {
        let Some(v) = runs.param(r, k).and_then(Cell::show) else {
            continue;
        };
        parts.push(match *k {
            "mortar_basis" => format!("{v} basis"),
            "nitsche_sides" => format!("sides {v}"),
            "nitsche_theta" => format!("Θ={v}"),
            _ => v,
        });
    }
    for &j in varying {
        if let Some(v) = r.params[j].show() {
            parts.push(format!("{}={v}", runs.params[j].0));
        }
    }
    parts.join(" · ")
}

/// The patch-test section of a folder (empty when it has no patch-test runs).
pub(crate) fn section(runs: &Runs) -> Section {
    let (rows, places) = collect(runs);
    // Every refinement of each column group, coarse → fine (a method may lack one).
    let levels: Vec<Vec<(Option<i64>, f64)>> = (0..places.len())
        .map(|pi| {
            let mut all: Vec<(Option<i64>, f64)> = rows
                .iter()
                .filter_map(|row| row.cells.get(&pi))
                .flatten()
                .map(|&(n, h, _)| (n, h))
                .collect();
            all.sort_by(|a, b| b.1.total_cmp(&a.1));
            all.dedup_by(|a, b| super::runs::float_key(a.1) == super::runs::float_key(b.1));
            all
        })
        .collect();
    let level_name = |(n, h): (Option<i64>, f64)| match n {
        Some(n) => format!("n{n}"),
        None => format!("h{}", super::runs::float_key(h)),
    };
    let level_head = |(n, h): (Option<i64>, f64)| match n {
        Some(n) => format!("n_a={n}"),
        None => format!("h={h}"),
    };
    let mut cols: Vec<(String, Kind)> =
        vec![("method".into(), Kind::Str), ("runs".into(), Kind::I64)];
    for k in METHOD_KEYS {
        if let Some((_, kind)) = runs.params.iter().find(|(n, _)| n == k) {
            cols.push((k.to_string(), *kind));
        }
    }
    for (pi, p) in places.iter().enumerate() {
        for &l in &levels[pi] {
            for e in ["stress", "pressure"] {
                cols.push((format!("{}_{}_{e}", p.stem(), level_name(l)), Kind::F64));
            }
        }
        cols.push((format!("{}_verdict", p.stem()), Kind::Str));
        cols.push((format!("{}_rate", p.stem()), Kind::F64));
    }
    let mut t = Table::new(&cols);
    let mut verdicts = TextTable::new(
        std::iter::once(("method".to_string(), Align::Left))
            .chain(places.iter().map(|p| (p.short(), Align::Left))),
    );
    let mut details: Vec<(String, TextTable)> = places
        .iter()
        .enumerate()
        .map(|(pi, p)| {
            let mut head = vec![("method".to_string(), Align::Left)];
            for &l in &levels[pi] {
                head.push((format!("{} stress", level_head(l)), Align::Right));
                head.push((format!("{} pressure", level_head(l)), Align::Right));
            }
            head.push(("verdict".into(), Align::Left));
            (p.heading(), TextTable::new(head))
        })
        .collect();
    for row in &rows {
        t.str("method", Some(&row.label));
        let n: usize = row.cells.values().map(Vec::len).sum();
        t.i64("runs", Some(n as i64));
        for k in METHOD_KEYS.iter().filter(|k| applies(runs, row.first, k)) {
            if let Some(c) = runs.param(row.first, k) {
                t.cell(k, c);
            }
        }
        let mut vrow = vec![row.label.clone()];
        for (pi, p) in places.iter().enumerate() {
            let Some(cell) = row.cells.get(&pi) else {
                vrow.push("—".into());
                continue;
            };
            let mut drow = vec![row.label.clone()];
            for &l in &levels[pi] {
                let run = cell
                    .iter()
                    .find(|(_, h, _)| super::runs::float_key(*h) == super::runs::float_key(l.1))
                    .map(|(_, _, r)| *r);
                let (s, pr) = (
                    run.and_then(|r| r.patch_stress_error),
                    run.and_then(|r| r.patch_pressure_error),
                );
                t.f64(&format!("{}_{}_stress", p.stem(), level_name(l)), s);
                t.f64(&format!("{}_{}_pressure", p.stem(), level_name(l)), pr);
                // A run that did not end ok shows its status: its errors are where it stopped.
                let status = |x: Option<f64>| match run {
                    None => "—".to_string(),
                    Some(r) if !r.ok() => r.status.clone(),
                    Some(_) => short_sci(x),
                };
                drow.push(status(s));
                drow.push(status(pr));
            }
            let measured: Vec<Measured> = cell
                .iter()
                .map(|(_, h, r)| {
                    (
                        *h,
                        r.status.as_str(),
                        r.patch_stress_error,
                        r.patch_pressure_error,
                    )
                })
                .collect();
            let (v, rate) = verdict(&measured);
            t.str(&format!("{}_verdict", p.stem()), Some(&v));
            t.f64(&format!("{}_rate", p.stem()), rate);
            drow.push(v.clone());
            details[pi].1.row(drow);
            vrow.push(v);
        }
        verdicts.row(vrow);
        t.end_row();
    }
    let legend = format!(
        "The contact patch test (contract §1.10): pressure p > 0 on A's top, B's base clamped, gap 0, at rest; its exact solution is uniform (σ = −p e_d⊗e_d, contact pressure p). stress: patch_stress_error = max |σ_h + p e_d⊗e_d|/p over the Gauss points of both bodies; pressure: patch_pressure_error = max |p_h − p|/p over the interface. n_a: A's elements across (W/h). passes: both errors ≤ {PATCH_TOL:e} on every refinement; fails: not, with the least-squares slope of the larger error against h (shrinking when above {STAGNATION_SLOPE}), or the runs that did not end ok (solver-failed, diverged: the step did not solve the patch problem; the tables show their status); —: not run (a combination left out)."
    );
    let mut markdown = format!(
        "# Contact patch test\n\n{legend}\n\n## Verdicts\n\n{}",
        verdicts.markdown()
    );
    for (head, d) in &details {
        markdown.push_str(&format!("\n## {head}\n\n{}", d.markdown()));
    }
    let terminal = if verdicts.is_empty() {
        String::new()
    } else {
        format!(
            "contact patch test (passes: both errors ≤ {PATCH_TOL:e} at every n_a; errors per refinement in patch_test.md):\n{}",
            verdicts.plain()
        )
    };
    Section {
        table: t,
        markdown,
        terminal,
        verdicts,
        details,
        legend,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The verdicts on hand-made levels: exact ones pass; an error constant under refinement
    /// (node-to-segment's kind, contract §6) fails without shrinking, rate 0 exactly; an
    /// error ∝ h fails shrinking at rate 1 (the LSQ slope of log e on log h, exact here to
    /// round-off: two decimals printed); a run not ok fails the cell, naming its status.
    #[test]
    fn verdicts_of_hand_made_levels() {
        let h = [1.0 / 3.0, 1.0 / 6.0, 1.0 / 12.0];
        let cell = |e: &dyn Fn(f64) -> f64| -> Vec<Measured> {
            h.iter()
                .map(|&h| (h, "ok", Some(e(h)), Some(e(h) / 2.0)))
                .collect()
        };
        assert_eq!(verdict(&cell(&|_| 5e-13)).0, "passes");
        let (v, p) = verdict(&cell(&|_| 0.15));
        assert_eq!(v, "fails (not shrinking, rate 0.00)");
        assert!(p.unwrap().abs() < 1e-12);
        let (v, p) = verdict(&cell(&|h| 0.3 * h));
        assert_eq!(v, "fails (shrinking, rate 1.00)");
        assert!((p.unwrap() - 1.0).abs() < 1e-12);
        // One error above the bound is enough to fail (here the pressure alone, at n_a = 12).
        let mut one = cell(&|_| 1e-12);
        one[2].3 = Some(2e-8);
        assert!(verdict(&one).0.starts_with("fails"));
        let mut failed = cell(&|_| 1e-12);
        failed[1] = (h[1], "solver-failed", Some(1.0), Some(1.0));
        assert_eq!(verdict(&failed).0, "fails (1 run solver-failed)");
        failed[2] = (h[2], "diverged", Some(1.0), Some(1.0));
        assert_eq!(verdict(&failed).0, "fails (2 runs diverged, solver-failed)");
        let mut missing = cell(&|_| 1e-12);
        missing[0].2 = None;
        assert_eq!(verdict(&missing).0, "incomplete (1 without errors)");
        assert_eq!(verdict(&cell(&|_| 0.1)[..1]).0, "fails (one refinement)");
    }

    #[test]
    fn ratios_print_as_the_sweep_files_write_them() {
        assert_eq!(ratio_label(1.0), "1");
        assert_eq!(ratio_label(4.0 / 3.0), "4/3");
        assert_eq!(ratio_label(1.4), "7/5");
        assert_eq!(ratio_label(1.3333333333333333), "4/3");
        assert_eq!(
            ratio_label(std::f64::consts::PI),
            format!("{}", std::f64::consts::PI)
        );
    }
}
