//! The method-class table (issue 20): one row per method group, its behaviour in four words.
//!
//! - energy: `conserving`, `dissipative with friction accounted` (frictional runs whose
//!   E + W_f holds while E falls by the friction's work), `dissipative` or `growing` — the
//!   worst energy class
//!   ([`super::energy::classify`], the scheme's own functional, δ = max(1, ν)·h/L) over the
//!   group's ok runs (growing beats dissipative beats conserving: one growing run is enough to
//!   show the method can gain energy);
//! - pressure: `smooth` if the largest `pressure_oscillation` of the group's runs is at most
//!   [`SMOOTH_PRESSURE`] (a pressure rising once and falling once reads 1; the methods of contract
//!   §3.2 without step-to-step alternation read about 3 at ν = 1.5, kane's alternation 11.3),
//!   `oscillating` above, `no contact` without a contact phase;
//! - penetration: `none` if the largest `max_penetration` is at most [`NO_PENETRATION`] of the
//!   body's length scale (round-off of a node put on the obstacle), `O(τ)` above;
//! - convergence: least-squares slopes of err_u_l2l2 and err_u_l2h1 against h along the group's
//!   longest refinement path with τ ∝ h (the convergence section's fit, ok levels only).
//!
//! Written as `methods.{parquet,csv,md,tex}`; the legend states the thresholds.

use super::columns::{Kind, columns};
use super::energy::{FRICTION_ACCOUNTED, classify, frictional};
use super::rates::lsq_slope;
use super::runs::{Fixed, Runs};
use super::table::{self, Table, TextTable, text_columns};

/// Largest `pressure_oscillation` read as a smooth pressure.
pub const SMOOTH_PRESSURE: f64 = 5.0;
/// Largest `max_penetration`, relative to the length scale, read as no penetration.
pub const NO_PENETRATION: f64 = 1e-12;

/// The method-class table.
pub(crate) struct Section {
    pub table: Table,
    pub markdown: String,
    pub latex: String,
    /// The terminal's lines (one per group, aligned) and the rows the report draws.
    pub terminal: String,
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
    pub legend: String,
}

/// One row per method group.
pub(crate) fn section(runs: &Runs) -> Section {
    let cols: Vec<(String, Kind)> = table::owned(&columns![
        method: Str, runs: I64, energy: Str, pressure: Str, pressure_oscillation_max: F64,
        penetration: Str, max_penetration_rel: F64, rate_l2: F64, rate_h1: F64,
    ]);
    let mut t = Table::new(&cols);
    let mut rows: Vec<Vec<String>> = Vec::new();
    let err_index = |name: &str| runs.errors.iter().position(|e| *e == name);
    let (l2, h1) = (err_index("err_u_l2l2"), err_index("err_u_l2h1"));
    for (g, group) in runs.groups.iter().enumerate() {
        let ok: Vec<&super::runs::Run> = group
            .runs
            .iter()
            .map(|&i| &runs.runs[i])
            .filter(|r| r.ok())
            .collect();
        let classes: Vec<String> = ok.iter().filter_map(|r| classify(runs, r).class).collect();
        // A frictional run whose E + W_f holds while E falls ranks between: it loses energy,
        // but only the friction's work (energy.rs).
        let energy = ["growing", "dissipative", FRICTION_ACCOUNTED, "conservative"]
            .into_iter()
            .find(|c| classes.iter().any(|x| x == c))
            .map(|c| if c == "conservative" { "conserving" } else { c });
        let osc = ok
            .iter()
            .filter_map(|r| r.pressure_oscillation)
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        let pressure = match osc {
            None if ok.is_empty() => None,
            None => Some("no contact"),
            Some(x) if x <= SMOOTH_PRESSURE => Some("smooth"),
            Some(_) => Some("oscillating"),
        };
        let pen = ok
            .iter()
            .filter_map(|r| Some(r.max_penetration? / r.length_scale.unwrap_or(1.0)))
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        let penetration = pen.map(|p| if p <= NO_PENETRATION { "none" } else { "O(τ)" });
        // The longest h-refinement path with τ ∝ h.
        let path = runs
            .paths
            .iter()
            .filter(|p| p.group == g && matches!(p.fixed, Fixed::Courant(_) | Fixed::Ratio(_)))
            .max_by_key(|p| p.levels.len());
        let slope = |k: Option<usize>| -> Option<f64> {
            let (k, p) = (k?, path?);
            let (x, e): (Vec<f64>, Vec<f64>) = p
                .levels
                .iter()
                .filter_map(|&(x, i)| {
                    let r = &runs.runs[i];
                    let e = r.errors[k]?;
                    (r.ok() && e.is_finite() && e > 0.0).then_some((x, e))
                })
                .unzip();
            lsq_slope(&x, &e)
        };
        let (r2, r1) = (slope(l2), slope(h1));
        let label = group.title.clone();
        t.str("method", Some(&label));
        t.i64("runs", Some(group.runs.len() as i64));
        t.str("energy", energy);
        t.str("pressure", pressure);
        t.f64("pressure_oscillation_max", osc);
        t.str("penetration", penetration);
        t.f64("max_penetration_rel", pen);
        t.f64("rate_l2", r2);
        t.f64("rate_h1", r1);
        t.end_row();
        rows.push(vec![
            label,
            energy.unwrap_or("—").into(),
            pressure.unwrap_or("—").into(),
            penetration.unwrap_or("—").into(),
            table::rate(r2),
            table::rate(r1),
        ]);
    }
    let text = TextTable::new(text_columns![
        "method" => Left, "energy" => Left, "pressure" => Left, "penetration" => Left,
        "L2 rate" => Right, "H1 rate" => Right,
    ])
    .with_rows(rows.clone());
    let legend = format!(
        "energy: the worst energy class of the group's ok runs (see energy.md: scheme's functional, δ = max(1, ν)·h/L); pressure: smooth if max pressure_oscillation ≤ {SMOOTH_PRESSURE} (1 = one rise and one fall), oscillating above; penetration: none if max_penetration ≤ {NO_PENETRATION:e}·L, O(τ) above; rates: least-squares slopes of err_u_l2l2 and err_u_l2h1 against h along the group's longest path with τ ∝ h (ok levels)."
    );
    // The frictional sentence only where frictional runs are: the frictionless legend keeps
    // its bytes.
    let legend = if runs.runs.iter().any(|r| frictional(runs, r)) {
        format!(
            "{legend} Frictional runs are judged by E + W_f (W_f the frictional work): {FRICTION_ACCOUNTED} when E + W_f stays within δ while E falls by more than δ (ranked between dissipative and conserving)."
        )
    } else {
        legend
    };
    let markdown = format!("# Method classes\n\n{legend}\n\n{}", text.markdown());
    let mut latex = String::from(
        "% Method classes (contact-sweep summary)\n\\begin{tabular}{llllrr}\n\\hline\nmethod & energy & pressure & penetration & L2 rate & H1 rate \\\\\n\\hline\n",
    );
    for r in &rows {
        let cells: Vec<String> = r.iter().map(|c| table::tex(c)).collect();
        latex.push_str(&cells.join(" & "));
        latex.push_str(" \\\\\n");
    }
    latex.push_str("\\hline\n\\end{tabular}\n");
    latex.push_str(&format!("% {}\n", table::tex(&legend)));
    let mut terminal = String::new();
    if !rows.is_empty() {
        terminal.push_str(
            "method classes (energy · pressure · penetration · L2, H1 rates; thresholds in methods.md):\n",
        );
        let width = rows.iter().map(|r| r[0].chars().count()).max().unwrap_or(0);
        let dash = |c: &String| {
            if c.is_empty() {
                "—".to_string()
            } else {
                c.clone()
            }
        };
        for r in &rows {
            let r: Vec<String> = r.iter().map(dash).collect();
            let pad = width - r[0].chars().count();
            terminal.push_str(&format!(
                "  {}{}  {} · {} · {} · {}, {}\n",
                r[0],
                " ".repeat(pad),
                r[1],
                r[2],
                r[3],
                r[4],
                r[5]
            ));
        }
    }
    Section {
        table: t,
        markdown,
        latex,
        terminal,
        header: text.header().to_vec(),
        rows,
        legend,
    }
}
