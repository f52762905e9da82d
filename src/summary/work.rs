//! Speed against error: every run's error against its cost (median wall time with the
//! spread over repeats, and work = steps × dofs), the Pareto front, and the cost a method
//! family needs to reach an error ε.

use std::fmt::Write as _;

use super::columns::columns;
use super::runs::{Fixed, Runs};
use super::table::{self, Align, Table, TextTable};

/// The Pareto front of (cost, error) points, both minimised: `true` where no other point is
/// at least as good in both and strictly better in one. O(n log n): sort by cost, sweep.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut front = vec![false; points.len()];
    // Smallest error among points strictly cheaper than the current cost.
    let mut best = f64::INFINITY;
    let mut i = 0;
    while i < order.len() {
        let cost = points[order[i]].0;
        let mut j = i;
        while j < order.len() && points[order[j]].0 == cost {
            j += 1;
        }
        // Equal cost: only the smallest error can survive, and only if nothing cheaper is at
        // least as accurate.
        let emin = points[order[i]].1;
        for &k in &order[i..j] {
            front[k] = points[k].1 == emin && emin < best;
        }
        best = best.min(emin);
        i = j;
    }
    front
}

/// log-log interpolation: the cost at error ε on the segment (e_a, c_a)–(e_b, c_b),
/// log c = log c_a + (log ε − log e_a)/(log e_b − log e_a) · (log c_b − log c_a).
pub fn loglog_cost(eps: f64, (e_a, c_a): (f64, f64), (e_b, c_b): (f64, f64)) -> Option<f64> {
    if !(e_a > 0.0 && e_b > 0.0 && c_a > 0.0 && c_b > 0.0 && eps > 0.0) {
        return None;
    }
    let de = e_b.ln() - e_a.ln();
    let s = if de == 0.0 {
        0.0
    } else {
        (eps.ln() - e_a.ln()) / de
    };
    Some((c_a.ln() + s * (c_b.ln() - c_a.ln())).exp())
}

/// The output of the section.
pub(crate) struct Section {
    pub table: Table,
    pub cost: Table,
    pub markdown: String,
    pub terminal: String,
}

/// An error value usable on a log scale.
fn usable(v: Option<f64>) -> Option<f64> {
    v.filter(|v| v.is_finite() && *v > 0.0)
}

fn work_of(steps: Option<i64>, dofs: Option<i64>) -> Option<i64> {
    steps?.checked_mul(dofs?).filter(|w| *w > 0)
}

/// A crossing of ε along one refinement path.
#[derive(Debug, Clone)]
struct Crossing {
    path: usize,
    fixed: Fixed,
    coarse: usize,
    fine: usize,
    wall: Option<f64>,
    work: Option<f64>,
}

/// Build the speed-against-error section.
pub(crate) fn section(runs: &Runs) -> Section {
    let mut out = Section {
        table: Table::new(&table::with_params(
            &columns![
                family: I64, family_title: Str, run_id: Str, label: Str, status: Str, h: F64,
                dt: F64, courant: F64, steps: I64, dofs: I64, work: I64, wall_time_s: F64,
                wall_time_min_s: F64, wall_time_max_s: F64, repeats: I64, error: Str,
                value: F64, pareto_wall: Bool, pareto_work: Bool,
            ],
            runs,
        )),
        cost: Table::new(&table::with_params(
            &columns![
                family: I64, family_title: Str, label: Str, error: Str, epsilon: F64,
                reached: Str, wall_time_s: F64, work: F64, cost_is_upper_bound: Bool, path: I64,
                fixed: Str, fixed_value: F64, run_coarse: Str, run_fine: Str, value_coarse: F64,
                value_fine: F64,
            ],
            runs,
        )),
        markdown: String::from("# Speed against error\n\n"),
        terminal: String::new(),
    };
    let _ = writeln!(
        out.markdown,
        "Cost: wall_time_s is the median over the run's timing repeats ([min, max] shown); work = \
         steps × dofs. Pareto front: ok runs not dominated in (error, wall time) — no other run \
         at most as slow and at most as inaccurate, strictly better in one. Cost to reach ε \
         (ε = the powers of ten inside the error range of the folder): log-log interpolation \
         of cost against error between consecutive usable levels of a refinement path of the \
         family, first crossing from coarse to fine, cheapest path; \"below\" = the family's \
         cheapest run is already below ε (its cost is an upper bound), \"not reached\" = no \
         level gets below ε.\n"
    );
    for (e, &ename) in runs.errors.iter().enumerate() {
        error_column(runs, e, ename, &mut out);
    }
    if runs.errors.is_empty() {
        out.markdown.push_str(
            "No error column has a value (no reference solution): nothing to plot against cost.\n",
        );
        out.terminal
            .push_str("work-precision: no error column has a value\n");
    }
    out
}

/// One error column's part of every output, in the order the files read: its rows of the
/// long table, its Pareto front, its cost to reach ε, its table of every run and (for the
/// first column only) the terminal's front.
fn error_column(runs: &Runs, e: usize, ename: &str, out: &mut Section) {
    let fronts = Fronts::of(runs, e);
    let order = by_family_then_cost(runs);
    run_rows(&mut out.table, runs, e, ename, &order, &fronts);
    let front = front_markdown(&mut out.markdown, runs, e, ename, &fronts);
    cost_to_reach(
        runs,
        e,
        ename,
        &fronts.cand,
        &mut out.cost,
        &mut out.markdown,
    );
    all_runs_markdown(&mut out.markdown, runs, e, ename, &order, &fronts);
    if out.terminal.is_empty() {
        terminal_front(
            &mut out.terminal,
            runs,
            e,
            ename,
            &front,
            fronts.wall_pts.len(),
        );
    }
}

/// The Pareto fronts of one error column: which ok runs with a usable error are on the front
/// in (wall time, error) and in (work, error) (None: not a candidate on that axis).
struct Fronts {
    /// Ok runs with a usable error.
    cand: Vec<usize>,
    /// The candidates that were timed.
    wall_pts: Vec<usize>,
    /// Per run: on the (wall time, error) front.
    on_wall: Vec<Option<bool>>,
    /// Per run: on the (work, error) front.
    on_work: Vec<Option<bool>>,
}

impl Fronts {
    fn of(runs: &Runs, e: usize) -> Fronts {
        let n = runs.runs.len();
        // Candidates: ok runs with a usable error.
        let cand: Vec<usize> = (0..n)
            .filter(|&i| runs.runs[i].ok() && usable(runs.runs[i].errors[e]).is_some())
            .collect();
        let wall_pts: Vec<usize> = cand
            .iter()
            .copied()
            .filter(|&i| runs.runs[i].wall_time_s.is_some())
            .collect();
        let work_pts: Vec<usize> = cand
            .iter()
            .copied()
            .filter(|&i| work_of(runs.runs[i].steps, runs.runs[i].dofs).is_some())
            .collect();
        let mut on_wall: Vec<Option<bool>> = vec![None; n];
        let mut on_work: Vec<Option<bool>> = vec![None; n];
        let pts: Vec<(f64, f64)> = wall_pts
            .iter()
            .map(|&i| {
                let r = &runs.runs[i];
                (
                    r.wall_time_s.unwrap_or(f64::NAN),
                    r.errors[e].unwrap_or(f64::NAN),
                )
            })
            .collect();
        for (k, f) in pareto_front(&pts).into_iter().enumerate() {
            on_wall[wall_pts[k]] = Some(f);
        }
        let pts: Vec<(f64, f64)> = work_pts
            .iter()
            .map(|&i| {
                let r = &runs.runs[i];
                (
                    work_of(r.steps, r.dofs).unwrap_or(0) as f64,
                    r.errors[e].unwrap_or(f64::NAN),
                )
            })
            .collect();
        for (k, f) in pareto_front(&pts).into_iter().enumerate() {
            on_work[work_pts[k]] = Some(f);
        }
        Fronts {
            cand,
            wall_pts,
            on_wall,
            on_work,
        }
    }
}

/// Every run, ordered by family, then coarse → fine (h, then dt).
fn by_family_then_cost(runs: &Runs) -> Vec<usize> {
    let family = |i: usize| runs.runs[i].group;
    let mut order: Vec<usize> = (0..runs.runs.len()).collect();
    order.sort_by(|&a, &b| {
        family(a).cmp(&family(b)).then(
            runs.runs[b]
                .h
                .unwrap_or(0.0)
                .total_cmp(&runs.runs[a].h.unwrap_or(0.0))
                .then(
                    runs.runs[b]
                        .dt
                        .unwrap_or(0.0)
                        .total_cmp(&runs.runs[a].dt.unwrap_or(0.0)),
                ),
        )
    });
    order
}

/// The long table's rows of one error column: every run (failed ones too, with pareto null).
fn run_rows(t: &mut Table, runs: &Runs, e: usize, ename: &str, order: &[usize], fronts: &Fronts) {
    for &i in order {
        let r = &runs.runs[i];
        t.i64("family", Some(r.group as i64 + 1));
        t.str("family_title", Some(&runs.groups[r.group].title));
        t.run_identity(r);
        t.run_level(r);
        t.i64("steps", r.steps);
        t.i64("dofs", r.dofs);
        t.i64("work", work_of(r.steps, r.dofs));
        t.f64("wall_time_s", r.wall_time_s);
        t.f64("wall_time_min_s", r.wall_time_min_s);
        t.f64("wall_time_max_s", r.wall_time_max_s);
        t.i64("repeats", r.repeats);
        t.str("error", Some(ename));
        t.f64("value", r.errors[e]);
        t.bool("pareto_wall", fronts.on_wall[i]);
        t.bool("pareto_work", fronts.on_work[i]);
        for ((nm, _), c) in runs.params.iter().zip(&r.params) {
            t.cell(nm, c);
        }
        t.end_row();
    }
}

/// The Markdown of the Pareto front in (error, wall time); returns the front, cheapest first.
fn front_markdown(
    md: &mut String,
    runs: &Runs,
    e: usize,
    ename: &str,
    fronts: &Fronts,
) -> Vec<usize> {
    let _ = writeln!(
        md,
        "## {ename}\n\n### Pareto front (error against wall time)\n"
    );
    let mut front: Vec<usize> = fronts
        .wall_pts
        .iter()
        .copied()
        .filter(|&i| fronts.on_wall[i] == Some(true))
        .collect();
    front.sort_by(|&a, &b| {
        runs.runs[a]
            .wall_time_s
            .unwrap_or(0.0)
            .total_cmp(&runs.runs[b].wall_time_s.unwrap_or(0.0))
    });
    let mut front_table = run_table("family", false, ename, ("repeats", Align::Right));
    for &i in &front {
        let r = &runs.runs[i];
        let repeats = r.repeats.map(|x| x.to_string()).unwrap_or_default();
        front_table.row(run_cells(
            runs,
            i,
            e,
            runs.groups[r.group].title.clone(),
            false,
            repeats,
        ));
    }
    if front_table.is_empty() {
        md.push_str("No ok run with a timed, positive error.\n\n");
    } else {
        md.push_str(&front_table.markdown());
        md.push('\n');
    }
    front
}

/// The powers of ten inside the range of the candidates' errors, largest first (at most 40).
fn decades(runs: &Runs, e: usize, cand: &[usize]) -> Vec<f64> {
    let values: Vec<f64> = cand
        .iter()
        .filter_map(|&i| usable(runs.runs[i].errors[e]))
        .collect();
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if values.is_empty() {
        Vec::new()
    } else {
        let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
        (a..=b)
            .rev()
            .take(40)
            // Parsed from its decimal form: exactly the double a reader writes as 1e-2.
            .map(|k| format!("1e{k}").parse::<f64>().unwrap_or(f64::NAN))
            .collect()
    }
}

/// The cost to reach ε of every family, for each power of ten ε inside the error range: the
/// rows of `cost_to_error` and the Markdown table (one row per family, one column per ε).
fn cost_to_reach(
    runs: &Runs,
    e: usize,
    ename: &str,
    cand: &[usize],
    cost: &mut Table,
    md: &mut String,
) {
    let decades = decades(runs, e, cand);
    let _ = writeln!(
        md,
        "### Cost to reach ε (wall time in s; work in steps × dofs)\n"
    );
    if decades.is_empty() {
        md.push_str("The errors span less than a decade: no power of ten inside their range.\n\n");
    }
    let mut cost_rows: Vec<Vec<String>> = Vec::new();
    for (gi, g) in runs.groups.iter().enumerate() {
        let fam_vals: Vec<(usize, f64)> = g
            .runs
            .iter()
            .filter(|&&i| runs.runs[i].ok())
            .filter_map(|&i| usable(runs.runs[i].errors[e]).map(|v| (i, v)))
            .collect();
        if fam_vals.is_empty() || decades.is_empty() {
            continue;
        }
        let mut md_row = vec![(gi + 1).to_string(), g.title.clone()];
        for &eps in &decades {
            let best = cheapest_crossing(runs, gi, e, eps);
            md_row.push(cost_row(cost, runs, gi, e, ename, eps, best, &fam_vals));
        }
        cost_rows.push(md_row);
    }
    if !decades.is_empty() && !cost_rows.is_empty() {
        let cols = [
            ("#".to_string(), Align::Right),
            ("family".into(), Align::Left),
        ]
        .into_iter()
        .chain(
            decades
                .iter()
                .map(|d| (format!("ε = {d:.0e}"), Align::Right)),
        );
        md.push_str(&TextTable::new(cols).with_rows(cost_rows).markdown());
        md.push('\n');
    }
}

/// The cheapest first crossing of ε over the refinement paths of family `gi`: along each
/// path the first pair of consecutive usable levels whose errors bracket ε, its cost by
/// log-log interpolation; the cheapest by wall time (by work when untimed).
fn cheapest_crossing(runs: &Runs, gi: usize, e: usize, eps: f64) -> Option<Crossing> {
    let mut best: Option<Crossing> = None;
    for (pi, p) in runs.paths.iter().enumerate().filter(|(_, p)| p.group == gi) {
        let used: Vec<usize> = p
            .levels
            .iter()
            .map(|&(_, i)| i)
            .filter(|&i| runs.runs[i].ok() && usable(runs.runs[i].errors[e]).is_some())
            .collect();
        for w in used.windows(2) {
            let (a, b) = (&runs.runs[w[0]], &runs.runs[w[1]]);
            let (ea, eb) = (a.errors[e].unwrap_or(0.0), b.errors[e].unwrap_or(0.0));
            if (ea - eps) * (eb - eps) > 0.0 {
                continue;
            }
            let wall = match (a.wall_time_s, b.wall_time_s) {
                (Some(ca), Some(cb)) => loglog_cost(eps, (ea, ca), (eb, cb)),
                _ => None,
            };
            let work = match (work_of(a.steps, a.dofs), work_of(b.steps, b.dofs)) {
                (Some(ca), Some(cb)) => loglog_cost(eps, (ea, ca as f64), (eb, cb as f64)),
                _ => None,
            };
            let c = Crossing {
                path: pi,
                fixed: p.fixed,
                coarse: w[0],
                fine: w[1],
                wall,
                work,
            };
            // Cheapest path: by wall time, by work when untimed.
            let key = |c: &Crossing| c.wall.or(c.work).unwrap_or(f64::INFINITY);
            if best.as_ref().is_none_or(|b| key(&c) < key(b)) {
                best = Some(c);
            }
            // First crossing along this path only.
            break;
        }
    }
    best
}

/// Family `gi`'s row of `cost_to_error` at ε (interpolated, below, not reached or no path);
/// returns its Markdown cell. `fam_vals` are the family's ok runs with their usable errors.
#[allow(clippy::too_many_arguments)]
fn cost_row(
    cost: &mut Table,
    runs: &Runs,
    gi: usize,
    e: usize,
    ename: &str,
    eps: f64,
    best: Option<Crossing>,
    fam_vals: &[(usize, f64)],
) -> String {
    let g = &runs.groups[gi];
    let first = &runs.runs[g.runs[0]];
    cost.i64("family", Some(gi as i64 + 1));
    cost.str("family_title", Some(&g.title));
    cost.str("label", Some(&first.label));
    cost.str("error", Some(ename));
    cost.f64("epsilon", Some(eps));
    let cell = if let Some(c) = &best {
        cost.str("reached", Some("interpolated"));
        cost.f64("wall_time_s", c.wall);
        cost.f64("work", c.work);
        cost.bool("cost_is_upper_bound", Some(false));
        cost.i64("path", Some(c.path as i64 + 1));
        cost.str("fixed", Some(c.fixed.name()));
        cost.f64("fixed_value", Some(c.fixed.value()));
        cost.str("run_coarse", Some(&runs.runs[c.coarse].run_id));
        cost.str("run_fine", Some(&runs.runs[c.fine].run_id));
        cost.f64("value_coarse", runs.runs[c.coarse].errors[e]);
        cost.f64("value_fine", runs.runs[c.fine].errors[e]);
        match (c.wall, c.work) {
            (Some(w), Some(k)) => format!("{} s / {:.3e}", table::sci(Some(w)), k),
            (Some(w), None) => format!("{} s", table::sci(Some(w))),
            (None, Some(k)) => format!("{k:.3e}"),
            _ => "?".into(),
        }
    } else if fam_vals.iter().all(|&(_, v)| v <= eps) {
        // Already below ε at the family's cheapest run.
        let cheapest = fam_vals
            .iter()
            .map(|&(i, _)| i)
            .min_by(|&a, &b| {
                let k = |i: usize| {
                    let r = &runs.runs[i];
                    r.wall_time_s
                        .or(work_of(r.steps, r.dofs).map(|w| w as f64))
                        .unwrap_or(f64::INFINITY)
                };
                k(a).total_cmp(&k(b))
            })
            .expect("non-empty");
        let r = &runs.runs[cheapest];
        cost.str("reached", Some("below"));
        cost.f64("wall_time_s", r.wall_time_s);
        cost.f64("work", work_of(r.steps, r.dofs).map(|w| w as f64));
        cost.bool("cost_is_upper_bound", Some(true));
        cost.str("run_fine", Some(&r.run_id));
        cost.f64("value_fine", r.errors[e]);
        format!("≤ {} s", table::sci(r.wall_time_s))
    } else if fam_vals.iter().all(|&(_, v)| v > eps) {
        cost.str("reached", Some("not reached"));
        "not reached".into()
    } else {
        // Values on both sides of ε but no refinement path joins them.
        cost.str("reached", Some("no path"));
        "no path".into()
    };
    for ((nm, _), c) in runs.params.iter().zip(&first.params) {
        cost.cell(nm, c);
    }
    cost.end_row();
    cell
}

/// The Markdown table of every run of one error column (error against cost), by family.
fn all_runs_markdown(
    md: &mut String,
    runs: &Runs,
    e: usize,
    ename: &str,
    order: &[usize],
    fronts: &Fronts,
) {
    let _ = writeln!(md, "### All runs\n");
    let mut all = run_table("label", true, ename, ("front", Align::Left));
    for &i in order {
        let front = match (fronts.on_wall[i], fronts.on_work[i]) {
            (Some(true), Some(true)) => "wall, work",
            (Some(true), _) => "wall",
            (_, Some(true)) => "work",
            _ => "",
        };
        let label = runs.runs[i].label.clone();
        all.row(run_cells(runs, i, e, label, true, front.to_string()));
    }
    md.push_str(&all.markdown());
    md.push('\n');
}

/// The terminal's lines: the size of the front of error column `e` (of `timed` timed runs)
/// and its cheapest and most accurate ends.
fn terminal_front(
    terminal: &mut String,
    runs: &Runs,
    e: usize,
    ename: &str,
    front: &[usize],
    timed: usize,
) {
    let _ = writeln!(
        terminal,
        "work-precision ({ename} against wall time): {} runs on the Pareto front of {}",
        front.len(),
        timed
    );
    // The cheapest and the most accurate ends of the front; the rest is in the files.
    const SHOWN: usize = 4;
    let ends: Vec<usize> = if front.len() <= SHOWN {
        front.to_vec()
    } else {
        front[..SHOWN / 2]
            .iter()
            .chain(&front[front.len() - SHOWN / 2..])
            .copied()
            .collect()
    };
    for (k, &i) in ends.iter().enumerate() {
        if k == SHOWN / 2 && front.len() > SHOWN {
            let _ = writeln!(
                terminal,
                "  … {} more in work_precision.md",
                front.len() - SHOWN
            );
        }
        let r = &runs.runs[i];
        let _ = writeln!(
            terminal,
            "  {:>9} s  e = {:<9}  {} (h = {}, dt = {})",
            table::eng_opt(r.wall_time_s),
            table::eng_opt(r.errors[e]),
            runs.groups[r.group].title,
            table::eng_opt(r.h),
            table::eng_opt(r.dt)
        );
    }
}

/// The columns of a metric's two run tables (the Pareto front, every run): `#`, the run's
/// `first` (its family or label), h, dt, the status if `status`, the error `ename`, the wall
/// time with its spread, the work, and the table's `last` column.
fn run_table(first: &str, status: bool, ename: &str, last: (&str, Align)) -> TextTable {
    let mut cols = vec![
        ("#", Align::Right),
        (first, Align::Left),
        ("h", Align::Right),
        ("dt", Align::Right),
    ];
    if status {
        cols.push(("status", Align::Left));
    }
    cols.extend([
        (ename, Align::Right),
        ("wall time [min, max] s", Align::Right),
        ("work", Align::Right),
        last,
    ]);
    TextTable::new(cols)
}

/// A row of [`run_table`]: run `i`'s cells for error column `e`.
fn run_cells(
    runs: &Runs,
    i: usize,
    e: usize,
    first: String,
    status: bool,
    last: String,
) -> Vec<String> {
    let r = &runs.runs[i];
    let mut cells = vec![
        (r.group + 1).to_string(),
        first,
        table::sci(r.h),
        table::sci(r.dt),
    ];
    if status {
        cells.push(r.status.clone());
    }
    cells.extend([
        table::sci(r.errors[e]),
        format!(
            "{} [{}, {}]",
            table::sci(r.wall_time_s),
            table::sci(r.wall_time_min_s),
            table::sci(r.wall_time_max_s)
        ),
        work_of(r.steps, r.dofs)
            .map(|w| w.to_string())
            .unwrap_or_default(),
        last,
    ]);
    cells
}
