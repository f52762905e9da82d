//! Stability maps: for every method and every pair of swept axes (Courant × γ0, Θ × γ0, h × ν,
//! …), the state of each cell of the grid — `stable`, `growing`, `diverged`, `solver-failed`,
//! `timeout`, `invalid` — as a long table (one row per cell) and as one Markdown grid per map.
//!
//! # Method, axes, cells
//! A *method* is the contact treatment, mass and scheme (space · mass · scheme label); every
//! numeric parameter that takes ≥ 2 values among a method's runs is an *axis*. Of h, dt and
//! the Courant number only two are independent: when all three vary, the one with the most
//! distinct values (the derived one — a grid over h and ν gives n_h·n_ν values of dt) is not
//! an axis; when two vary and the third is fixed they are one axis (courant kept, else h).
//! Likewise any axis in one-to-one correspondence with an earlier one (h and T bundled in one
//! grid item) is not an axis of its own. A cell is one pair of axis values; it holds every run of the method with those
//! values (other axes, ensemble members), and its state is the worst of their states in the
//! order diverged, solver-failed, timeout, growing, invalid, stable: a cell is stable only if
//! every run in it is. `uniform` says whether its runs agreed.
//!
//! # State of a run
//! Non-ok runs by their status; an ok run is `growing` when its energy class is
//! ([`super::energy::classify`]: the scheme's functional gains more than the contact's
//! consistency error δ, or a provably monotone one gains in a step), `stable` otherwise.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use super::columns::columns;
use super::energy::classify;
use super::runs::{Run, Runs};
use super::table::{Align, Table, TextTable};

/// Cell states, worst first.
pub const STATES: [&str; 6] = [
    "diverged",
    "solver-failed",
    "timeout",
    "growing",
    "invalid",
    "stable",
];

/// Candidate axes, in the order maps put them (x before y): the levels, the method parameters
/// ([`super::runs::METHOD_PARAMS`]), the physics.
const LEVEL_AXES: &[&str] = &["courant", "h", "dt", "T"];
const PHYSICS_AXES: &[&str] = &[
    "length",
    "young",
    "density",
    "amplitude",
    "gap",
    "lame_lambda",
    "lame_mu",
    "gravity",
    "velocity",
    "point_mass",
    "stiffness",
    "force",
    "impact_law",
    "height",
    "velocity_tangential",
    "friction_force",
    "incline",
    "friction_coefficient",
    "tresca_threshold",
];

fn axes() -> impl Iterator<Item = &'static str> {
    LEVEL_AXES
        .iter()
        .chain(super::runs::METHOD_PARAMS)
        .chain(PHYSICS_AXES)
        .copied()
}

fn state(runs: &Runs, r: &Run) -> &'static str {
    match r.status.as_str() {
        "ok" => match classify(runs, r).class.as_deref() {
            Some("growing") => "growing",
            _ => "stable",
        },
        "diverged" => "diverged",
        "solver-failed" => "solver-failed",
        "timeout" => "timeout",
        _ => "invalid",
    }
}

fn axis_value(runs: &Runs, r: &Run, axis: &str) -> Option<f64> {
    match axis {
        "courant" => r.courant,
        "h" => r.h,
        "dt" => r.dt,
        other => runs.param_f64(r, other),
    }
    .filter(|x| x.is_finite())
}

/// Method of a run: space · mass · scheme label (the label without Θ, γ0).
fn method(runs: &Runs, r: &Run) -> String {
    let p = |n: &str| runs.param_str(r, n).unwrap_or("").to_string();
    let mut mass = p("mass");
    if let Some(w) = runs.param_str(r, "mass_weights") {
        mass = format!("{mass}[{w}]");
    }
    let scheme = runs
        .param_str(r, "scheme_label")
        .or(runs.param_str(r, "scheme"))
        .unwrap_or("");
    format!("{} · {mass} · {scheme}", p("space"))
}

/// Short text of a number for a grid heading.
fn num(x: f64) -> String {
    let s = format!("{x}");
    if s.len() > 8 { format!("{x:.3e}") } else { s }
}

/// The stability-map section's outputs.
pub(crate) struct Section {
    pub table: Table,
    pub markdown: String,
    pub terminal: String,
}

/// Build the stability maps.
pub(crate) fn section(runs: &Runs) -> Section {
    let mut t = Table::new(
        &columns![
            method: Str, x_axis: Str, y_axis: Str, x: F64, y: F64, state: Str, uniform: Bool,
            runs: I64, stable: I64, growing: I64, diverged: I64, solver_failed: I64, timeout: I64,
            invalid: I64, steps: I64, message: Str, run_id: Str,
        ]
        .map(|(n, k)| (n.to_string(), k)),
    );
    let mut by_method: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (i, r) in runs.runs.iter().enumerate() {
        by_method.entry(method(runs, r)).or_default().push(i);
    }
    let states: Vec<&'static str> = runs.runs.iter().map(|r| state(runs, r)).collect();
    let mut md = String::from("# Stability maps\n\n");
    let _ = writeln!(
        md,
        "Per method (space · mass · scheme) and pair of swept axes, the state of each cell: the \
         worst over its runs (diverged > solver-failed > timeout > growing > invalid > stable; \
         `*`: its runs disagree). growing = ok but the scheme's energy functional gained more \
         than δ = max(1, ν)·h/L (see energy.md).\n"
    );
    let mut maps = 0usize;
    let mut terminal_lines: Vec<(String, Vec<String>)> = Vec::new();
    for (m, idx) in &by_method {
        let axes = map_axes(runs, idx);
        for (ai, &(xa, _)) in axes.iter().enumerate() {
            for &(ya, _) in &axes[ai + 1..] {
                maps += 1;
                let cells = map_cells(&mut t, runs, &states, m, idx, (xa, ya));
                map_markdown(&mut md, m, (xa, ya), &cells);
                let summary: Vec<String> = STATES
                    .iter()
                    .filter_map(|s| cells.counts.get(s).map(|n| format!("{n} {s}")))
                    .collect();
                let key = format!("{ya} × {xa}: {}", summary.join(", "));
                match terminal_lines.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, ms)) => ms.push(m.clone()),
                    None => terminal_lines.push((key, vec![m.clone()])),
                }
            }
        }
    }
    let mut terminal = String::new();
    if maps == 0 {
        md.push_str("No method has two swept axes.\n");
    } else {
        let _ = writeln!(terminal, "stability maps ({maps}, cell states):");
        // Maps with the same axes and the same cell counts share a line.
        for (key, ms) in terminal_lines {
            let who = if ms.len() <= 2 {
                ms.join("; ")
            } else {
                format!("{} methods", ms.len())
            };
            let _ = writeln!(terminal, "  {key} — {who}");
        }
    }
    Section {
        table: t,
        markdown: md,
        terminal,
    }
}

/// The axes a method's runs `idx` are swept along (≥ 2 distinct values), with their number of
/// values, in the order of [`axes`]: of h, dt and courant only the independent ones, and of
/// axes that move together only the first.
fn map_axes(runs: &Runs, idx: &[usize]) -> Vec<(&'static str, usize)> {
    let distinct = |axis: &str| -> BTreeSet<String> {
        idx.iter()
            .filter_map(|&i| axis_value(runs, &runs.runs[i], axis))
            .map(super::runs::float_key)
            .collect()
    };
    let mut axes: Vec<(&str, usize)> = axes()
        .map(|a| (a, distinct(a).len()))
        .filter(|(_, n)| *n >= 2)
        .collect();
    let mesh: Vec<(&str, usize)> = axes
        .iter()
        .copied()
        .filter(|(a, _)| ["h", "dt", "courant"].contains(a))
        .collect();
    if mesh.len() == 3 {
        // Drop the derived one (most values; dt on a tie).
        let drop = mesh
            .iter()
            .max_by_key(|(a, n)| (*n, usize::from(*a == "dt")))
            .map(|(a, _)| *a)
            .expect("three");
        axes.retain(|(a, _)| *a != drop);
    } else if mesh.len() == 2 {
        // The third is fixed, so the two are one axis (ν = c0·dt/h): keep courant, else h.
        let keep = ["courant", "h", "dt"]
            .into_iter()
            .find(|k| mesh.iter().any(|(a, _)| a == k))
            .expect("two");
        axes.retain(|(a, _)| !["h", "dt", "courant"].contains(a) || *a == keep);
    }
    // Axes that move together (bundled in one grid item, e.g. { h, T }) are one axis: an
    // axis in one-to-one correspondence with an earlier one is dropped.
    let key_of = |i: usize, a: &str| axis_value(runs, &runs.runs[i], a).map(super::runs::float_key);
    let mut kept: Vec<(&str, usize)> = Vec::new();
    for &(b, n) in &axes {
        let tied = kept.iter().any(|&(a, _)| {
            let mut fwd: BTreeMap<Option<String>, BTreeSet<Option<String>>> = BTreeMap::new();
            let mut back: BTreeMap<Option<String>, BTreeSet<Option<String>>> = BTreeMap::new();
            for &i in idx {
                let (ka, kb) = (key_of(i, a), key_of(i, b));
                fwd.entry(ka.clone()).or_default().insert(kb.clone());
                back.entry(kb).or_default().insert(ka);
            }
            fwd.values().all(|v| v.len() == 1) && back.values().all(|v| v.len() == 1)
        });
        if !tied {
            kept.push((b, n));
        }
    }
    kept
}

/// The cells of one map: the x and y values (sorted), each cell's state text by (x, y) key,
/// and how many cells are in each state.
struct MapCells {
    xs: Vec<f64>,
    ys: Vec<f64>,
    grid: BTreeMap<(String, String), String>,
    counts: BTreeMap<&'static str, usize>,
}

/// The rows of method `m`'s map over the axes `(xa, ya)`, one per cell: the worst state of
/// its runs (`states`, per run), whether they agree, and the worst run.
fn map_cells(
    t: &mut Table,
    runs: &Runs,
    states: &[&'static str],
    m: &str,
    idx: &[usize],
    (xa, ya): (&str, &str),
) -> MapCells {
    let mut cells: BTreeMap<(String, String), (f64, f64, Vec<usize>)> = BTreeMap::new();
    for &i in idx {
        let r = &runs.runs[i];
        if let (Some(x), Some(y)) = (axis_value(runs, r, xa), axis_value(runs, r, ya)) {
            let k = (super::runs::float_key(x), super::runs::float_key(y));
            cells.entry(k).or_insert((x, y, Vec::new())).2.push(i);
        }
    }
    let mut xs: Vec<f64> = Vec::new();
    let mut ys: Vec<f64> = Vec::new();
    let mut grid: BTreeMap<(String, String), String> = BTreeMap::new();
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for (k, (x, y, members)) in &cells {
        let worst = members
            .iter()
            .min_by_key(|&&i| STATES.iter().position(|s| *s == states[i]))
            .copied()
            .expect("a cell has a run");
        let st = states[worst];
        let n = |s: &str| members.iter().filter(|&&i| states[i] == s).count() as i64;
        let uniform = members.iter().all(|&i| states[i] == st);
        t.str("method", Some(m));
        t.str("x_axis", Some(xa));
        t.str("y_axis", Some(ya));
        t.f64("x", Some(*x));
        t.f64("y", Some(*y));
        t.str("state", Some(st));
        t.bool("uniform", Some(uniform));
        t.i64("runs", Some(members.len() as i64));
        t.i64("stable", Some(n("stable")));
        t.i64("growing", Some(n("growing")));
        t.i64("diverged", Some(n("diverged")));
        t.i64("solver_failed", Some(n("solver-failed")));
        t.i64("timeout", Some(n("timeout")));
        t.i64("invalid", Some(n("invalid")));
        let w = &runs.runs[worst];
        t.i64("steps", w.steps);
        t.str("message", w.message.as_deref());
        t.str("run_id", Some(&w.run_id));
        t.end_row();
        *counts.entry(st).or_default() += 1;
        if !xs.contains(x) {
            xs.push(*x);
        }
        if !ys.contains(y) {
            ys.push(*y);
        }
        grid.insert(k.clone(), format!("{st}{}", if uniform { "" } else { "*" }));
    }
    xs.sort_by(f64::total_cmp);
    ys.sort_by(f64::total_cmp);
    MapCells {
        xs,
        ys,
        grid,
        counts,
    }
}

/// Method `m`'s map over `(xa, ya)` as a Markdown grid: y down the rows, x across.
fn map_markdown(md: &mut String, m: &str, (xa, ya): (&str, &str), cells: &MapCells) {
    let (xs, ys, grid) = (&cells.xs, &cells.ys, &cells.grid);
    let _ = writeln!(md, "## {m}: {ya} (rows) × {xa} (columns)\n");
    let mut header = vec![format!("{ya} \\ {xa}")];
    header.extend(xs.iter().map(|x| num(*x)));
    let rows: Vec<Vec<String>> = ys
        .iter()
        .map(|y| {
            let mut row = vec![num(*y)];
            row.extend(xs.iter().map(|x| {
                let k = (super::runs::float_key(*x), super::runs::float_key(*y));
                grid.get(&k).cloned().unwrap_or_else(|| "—".into())
            }));
            row
        })
        .collect();
    let map = TextTable::new(header.into_iter().map(|h| (h, Align::Right)));
    md.push_str(&map.with_rows(rows).markdown());
    md.push('\n');
}
