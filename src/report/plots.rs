//! The report's figure sections: convergence, work-precision, time series, the frictional
//! runs' energy balance and slip velocity, and the two-body runs' contact faces and momentum —
//! what each figure shows of the summary's computations (the same groups, main refinement paths, least-squares slopes and Pareto
//! fronts as `DIR/summary/`), the caption above it and the legend of its method groups.
//! [`super::figures`] draws them.
//!
//! Every method group is drawn in every figure: its colour and marker ([`super::style`]) tell
//! up to 60 groups apart, and the HTML legend above each figure block names them.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::summary::Sections;
use crate::summary::convergence::lsq_slope;
use crate::summary::runs::{self, Runs};
use crate::summary::table as stable;

use super::figures::{self, Curve};
use super::html::{Page, esc};
use super::series::{RunSeries, read_series};
use super::style;

/// The legend of the method groups, shared by every figure (a group has one colour and one
/// marker): the marker on a line of the colour, the group's number and title.
fn legend(runs: &Runs, groups: &[usize], note: &str) -> String {
    let mut out = String::from("<div class=\"legend\">");
    for &g in groups {
        let c = style::color(g);
        let _ = write!(
            out,
            "<span><i style=\"background:rgb({},{},{});color:rgb({},{},{})\">{}</i>{} {}</span>",
            c.0,
            c.1,
            c.2,
            c.0,
            c.1,
            c.2,
            style::marker(g).glyph(),
            g + 1,
            esc(&runs.groups[g].title)
        );
    }
    if !note.is_empty() {
        let _ = write!(out, "<span>{}</span>", note);
    }
    out.push_str("</div>\n");
    out
}

/// Usable (x, e) points of a path for error column `e`: ok runs with a finite positive error —
/// the levels the summary's fits use.
fn path_points(runs: &Runs, path: usize, e: usize) -> Vec<(f64, f64)> {
    runs.paths[path]
        .levels
        .iter()
        .filter_map(|&(x, i)| {
            let r = &runs.runs[i];
            let v = r.errors[e]?;
            (r.ok() && v.is_finite() && v > 0.0 && x > 0.0).then_some((x, v))
        })
        .collect()
}

/// The least-squares line log e = c + p log x of the points: (p, c).
fn fit_line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let xs: Vec<f64> = points.iter().map(|p| p.0).collect();
    let es: Vec<f64> = points.iter().map(|p| p.1).collect();
    let p = lsq_slope(&xs, &es)?;
    let n = xs.len() as f64;
    let mx = xs.iter().map(|x| x.ln()).sum::<f64>() / n;
    let me = es.iter().map(|e| e.ln()).sum::<f64>() / n;
    Some((p, me - p * mx))
}

/// Convergence: a figure per displayed error column, a curve per group's main path.
pub(super) fn convergence(page: &mut Page, s: &Sections) {
    let Sections { runs, conv, .. } = s;
    let body = &mut page.body;
    body.push_str("<h2 id=\"convergence\">Convergence</h2>\n");
    let mains: Vec<(usize, usize)> = conv
        .groups
        .main_paths
        .iter()
        .enumerate()
        .filter_map(|(g, p)| p.map(|p| (g, p)))
        .collect();
    if mains.is_empty() || conv.display.is_empty() {
        body.push_str("<p class=\"note\">No refinement path with errors: nothing to plot.</p>\n");
        return;
    }
    let refined = runs.paths[mains[0].1].fixed.refined();
    let _ = writeln!(
        body,
        "<p class=\"note\">Each curve is a method group's longest refinement path ({}); the triangles have the least-squares slope of the curve (the number next to each). Only ok runs with a positive error are drawn — the levels the fits use.</p>",
        esc(&conv.groups.caption)
    );
    let gs: Vec<usize> = mains.iter().map(|&(g, _)| g).collect();
    body.push_str(&legend(runs, &gs, ""));
    body.push_str("<div class=\"figs\">\n");
    for &e in &conv.display {
        let (abbr, what) = stable::error_abbrev(runs.errors[e]);
        let mut curves = Vec::new();
        let mut slopes = Vec::new();
        for &(g, p) in &mains {
            let pts = path_points(runs, p, e);
            slopes.push(fit_line(&pts));
            curves.push(Curve {
                name: format!("{} · {}", runs.groups[g].title, runs.paths[p].fixed.short()),
                points: pts,
                group: g,
            });
        }
        let t = format!("{abbr}: {what}");
        page.figure(figures::convergence(
            &t,
            refined,
            runs.errors[e],
            &curves,
            &slopes,
        ));
    }
    page.body.push_str("</div>\n");
}

/// Work-precision: the first displayed column against wall time, every ok run, and the
/// Pareto front.
pub(super) fn work_precision(page: &mut Page, s: &Sections) {
    let Sections { runs, conv, .. } = s;
    let body = &mut page.body;
    body.push_str("<h2 id=\"work\">Work-precision</h2>\n");
    let Some(&e) = conv.display.first() else {
        body.push_str("<p class=\"note\">No error column: nothing to plot.</p>\n");
        return;
    };
    let mut groups: Vec<Curve> = runs
        .groups
        .iter()
        .enumerate()
        .map(|(k, g)| Curve {
            name: g.title.clone(),
            points: Vec::new(),
            group: k,
        })
        .collect();
    let mut all = Vec::new();
    for r in runs.runs.iter().filter(|r| r.ok()) {
        if let (Some(t), Some(v)) = (r.wall_time_s, r.errors[e])
            && t > 0.0
            && v > 0.0
            && t.is_finite()
            && v.is_finite()
        {
            groups[r.group].points.push((t, v));
            all.push((t, v));
        }
    }
    let front: Vec<(f64, f64)> = crate::summary::pareto_front(&all)
        .into_iter()
        .zip(&all)
        .filter_map(|(f, p)| f.then_some(*p))
        .collect();
    let _ = writeln!(
        body,
        "<p class=\"note\">{} against the run's wall time (median over its repeats); circled: the {} runs of the Pareto front (no other run both faster and more accurate). Tables: <code>summary/work_precision.md</code>, cost to reach ε: <code>summary/cost_to_error.csv</code>.</p>",
        esc(runs.errors[e]),
        front.len()
    );
    let t = format!(
        "{}: error against wall time",
        stable::error_abbrev(runs.errors[e]).0
    );
    let gs: Vec<usize> = (0..runs.groups.len())
        .filter(|&g| !groups[g].points.is_empty())
        .collect();
    body.push_str(&legend(runs, &gs, "○ black: Pareto front"));
    page.figure_alone(figures::work_precision(&t, runs.errors[e], &groups, &front));
}

/// The run each method group shows in the time series: the finest ok level of its main path,
/// or its first ok run; (group, run) for every group with an ok run.
fn series_runs(s: &Sections) -> Vec<(usize, usize)> {
    let Sections { runs, conv, .. } = s;
    runs.groups
        .iter()
        .enumerate()
        .filter_map(|(g, grp)| {
            let from_path = conv.groups.main_paths[g].and_then(|p| {
                runs.paths[p]
                    .levels
                    .iter()
                    .rev()
                    .map(|&(_, i)| i)
                    .find(|&i| runs.runs[i].ok())
            });
            from_path
                .or_else(|| grp.runs.iter().copied().find(|&i| runs.runs[i].ok()))
                .map(|i| (g, i))
        })
        .collect()
}

/// The curves of the three time-series panels: u_C, σ_C and E/energy_scale per chosen run,
/// and the exact u_C and σ_C.
#[derive(Default)]
struct TimeCurves {
    u: Vec<Curve>,
    s: Vec<Curve>,
    en: Vec<Curve>,
    exact_u: Option<Curve>,
    exact_s: Option<Curve>,
}

fn time_curves(
    runs: &Runs,
    chosen: &[(usize, usize)],
    series: &HashMap<String, RunSeries>,
) -> TimeCurves {
    let mut c = TimeCurves::default();
    for &(g, i) in chosen {
        let r = &runs.runs[i];
        let Some(rs) = series.get(&r.run_id) else {
            continue;
        };
        let name = format!(
            "{} (h = {}, dt = {})",
            runs.groups[g].title,
            stable::eng_opt(r.h),
            stable::eng_opt(r.dt)
        );
        c.u.push(Curve {
            name: name.clone(),
            points: figures::decimate(&rs.u, 1500),
            group: g,
        });
        c.s.push(Curve {
            name: name.clone(),
            points: figures::decimate(&rs.sigma, 1500),
            group: g,
        });
        // In units of the run's energy_scale, the unit of its `energy_drift` (E⁰ for the
        // bars: the curve E/E⁰; m·g·gap under gravity, where E⁰ = 0). Older folders without
        // the column: E⁰ when it is not zero.
        let scale = r
            .energy_scale
            .or_else(|| rs.energy.first().map(|p| p.1).filter(|e| *e != 0.0));
        if let Some(scale) = scale {
            let rel: Vec<(f64, f64)> = rs.energy.iter().map(|&(t, e)| (t, e / scale)).collect();
            c.en.push(Curve {
                name,
                points: figures::decimate(&rel, 1500),
                group: g,
            });
        }
        // The exact solution of the longest run (the finest time resolution).
        if rs.u_exact.len() > c.exact_u.as_ref().map_or(0, |c| c.points.len()) {
            c.exact_u = Some(Curve {
                name: "exact".into(),
                points: figures::decimate(&rs.u_exact, 1500),
                group: 0,
            });
        }
        if rs.sigma_exact.len() > c.exact_s.as_ref().map_or(0, |c| c.points.len()) {
            c.exact_s = Some(Curve {
                name: "exact".into(),
                points: figures::decimate(&rs.sigma_exact, 1500),
                group: 0,
            });
        }
    }
    c
}

/// Time series: one run per group (every group), contact displacement, pressure and energy
/// against time with the exact solution, then the frictional runs' figures.
pub(super) fn time_series(page: &mut Page, dir: &Path, s: &Sections) -> anyhow::Result<()> {
    let runs = &s.runs;
    page.body.push_str(
        "<h2 id=\"series\">Contact displacement, pressure and energy against time</h2>\n",
    );
    let chosen = series_runs(s);
    let picked: Vec<&runs::Run> = chosen.iter().map(|&(_, i)| &runs.runs[i]).collect();
    let series = read_series(dir, &picked)?;
    if series.is_empty() {
        page.body.push_str("<p class=\"note\">No time series in <code>series/</code> (series_every = 0?): nothing to plot.</p>\n");
        return Ok(());
    }
    let _ = writeln!(
        page.body,
        "<p class=\"note\">One run per method group: the finest ok level of its main refinement path. Black dashes: the exact solution (closed form; for 2D/3D scenes the reference run). Energy in units of the run's <code>energy_scale</code> (E⁰ for the bars, so E/E⁰; m·g·gap under gravity, where E⁰ = 0).</p>",
    );
    let c = time_curves(runs, &chosen, &series);
    let gs: Vec<usize> = chosen.iter().map(|&(g, _)| g).collect();
    page.body
        .push_str(&legend(runs, &gs, "black dashes: exact"));
    page.body.push_str("<div class=\"figs\">\n");
    for (t, y, curves, exact) in [
        (
            "contact displacement u_C(t)",
            "u_C",
            &c.u,
            c.exact_u.as_ref(),
        ),
        ("contact pressure σ_C(t)", "σ_C", &c.s, c.exact_s.as_ref()),
        ("energy E(t)/energy_scale", "E/E_s", &c.en, None),
    ] {
        if curves.is_empty() {
            continue;
        }
        page.figure(figures::series(t, y, curves, exact));
    }
    page.body.push_str("</div>\n");
    frictional_figures(page, runs, &chosen, &series);
    two_body_figures(page, runs, &chosen, &series);
    Ok(())
}

/// The two-body runs' figures (only when some chosen run recorded B's contact displacement or
/// the momentum): u_C^a and u_C^b against t in one panel — the bodies' faces move together
/// while in contact and part at release — and the total momentum's departure Pⁿ − P⁰, the
/// invariant every scheme keeps with free bodies (contract §2.6), so a curve off round-off is a
/// force that is not action = reaction (or a load or clamp, which `momentum_drift` marks null).
fn two_body_figures(
    page: &mut Page,
    runs: &Runs,
    chosen: &[(usize, usize)],
    series: &HashMap<String, RunSeries>,
) {
    let (mut ua, mut ub, mut p) = (Vec::new(), Vec::new(), Vec::new());
    let mut groups = Vec::new();
    for &(g, i) in chosen {
        let r = &runs.runs[i];
        let Some(rs) = series.get(&r.run_id) else {
            continue;
        };
        if rs.u_b.is_empty() && rs.momentum.is_empty() {
            continue;
        }
        let curve = |points: &[(f64, f64)]| Curve {
            name: runs.groups[g].title.clone(),
            points: figures::decimate(points, 1500),
            group: g,
        };
        if !rs.u_b.is_empty() {
            ua.push(curve(&rs.u));
            ub.push(curve(&rs.u_b));
        }
        if let Some(&(_, p0)) = rs.momentum.first() {
            let dev: Vec<(f64, f64)> = rs.momentum.iter().map(|&(t, x)| (t, x - p0)).collect();
            p.push(curve(&dev));
        }
        groups.push(g);
    }
    if groups.is_empty() {
        return;
    }
    let body = &mut page.body;
    body.push_str("<h3 id=\"two-body\">Two bodies: both contact faces and the momentum</h3>\n");
    body.push_str("<p class=\"note\">Same runs as above, those with two bodies. Contact displacements: solid u_C^a (A's contact end or face node), faded u_C^b (B's) — equal while the faces touch (with the gap subtracted), apart after release. Momentum: Pⁿ − P⁰ of the whole system, round-off for free bodies with no load (contract §2.6); a load adds its impulse.</p>\n");
    body.push_str(&legend(runs, &groups, "solid A, faded B"));
    body.push_str("<div class=\"figs\">\n");
    let mut drawn = Vec::new();
    if !ub.is_empty() {
        drawn.push(figures::layered(
            "contact displacements u_C^a, u_C^b (t)",
            "u_C",
            &[(&ub, 3, true), (&ua, 1, false)],
        ));
    }
    if !p.is_empty() {
        drawn.push(figures::series("total momentum Pⁿ − P⁰", "ΔP", &p, None));
    }
    for fig in drawn {
        page.figure(fig);
    }
    page.body.push_str("</div>\n");
}

/// The frictional runs' figures (only when some chosen run has a friction law and recorded its
/// work): E, W_f and E + W_f against t in one panel — E + W_f flat while E falls is a scheme
/// that lost only the friction's work, the class the energy table calls "dissipative with
/// friction accounted" — and the slip velocity v_t of the contact node.
fn frictional_figures(
    page: &mut Page,
    runs: &Runs,
    chosen: &[(usize, usize)],
    series: &HashMap<String, RunSeries>,
) {
    let (mut e, mut w, mut total, mut slip) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut groups = Vec::new();
    for &(g, i) in chosen {
        let r = &runs.runs[i];
        if !crate::summary::energy::frictional(runs, r) {
            continue;
        }
        let Some(rs) = series.get(&r.run_id) else {
            continue;
        };
        // The unit of `energy_balance_drift` (E⁰ for the layer), so that a flat E + W_f reads 1.
        let scale = r
            .energy_scale
            .or_else(|| rs.balance.first().map(|p| p.1).filter(|x| *x != 0.0));
        let name = runs.groups[g].title.clone();
        let mut drawn = false;
        if let Some(scale) = scale.filter(|_| !rs.balance.is_empty()) {
            let pick = |f: &dyn Fn(&(f64, f64, f64)) -> f64| -> Vec<(f64, f64)> {
                let p: Vec<(f64, f64)> = rs.balance.iter().map(|b| (b.0, f(b) / scale)).collect();
                figures::decimate(&p, 1500)
            };
            for (list, points) in [
                (&mut e, pick(&|b| b.1)),
                (&mut w, pick(&|b| b.2)),
                (&mut total, pick(&|b| b.1 + b.2)),
            ] {
                list.push(Curve {
                    name: name.clone(),
                    points,
                    group: g,
                });
            }
            drawn = true;
        }
        if !rs.v_t.is_empty() {
            slip.push(Curve {
                name: name.clone(),
                points: figures::decimate(&rs.v_t, 1500),
                group: g,
            });
            drawn = true;
        }
        if drawn {
            groups.push(g);
        }
    }
    if groups.is_empty() {
        return;
    }
    let body = &mut page.body;
    body.push_str("<h3 id=\"friction\">Frictional runs: energy balance and slip velocity</h3>\n");
    body.push_str("<p class=\"note\">Same runs as above, those with a friction law. Energy balance in units of the run's <code>energy_scale</code>: thin E, faded W_f (the frictional work), thick E + W_f — flat when the scheme loses only the friction's work. Slip velocity: the contact node's tangential velocity v_t.</p>\n");
    body.push_str(&legend(runs, &groups, "thin E, faded W_f, thick E + W_f"));
    body.push_str("<div class=\"figs\">\n");
    let mut drawn = Vec::new();
    if !total.is_empty() {
        drawn.push(figures::balance(
            "energy balance E, W_f, E + W_f (t)",
            &e,
            &w,
            &total,
        ));
    }
    if !slip.is_empty() {
        drawn.push(figures::series("slip velocity v_t(t)", "v_t", &slip, None));
    }
    for fig in drawn {
        page.figure(fig);
    }
    page.body.push_str("</div>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fitted_line_recovers_a_power_law() {
        // e = 3 x^2: slope 2, intercept ln 3 (exact up to rounding of the logarithms).
        let pts: Vec<(f64, f64)> = [0.1, 0.05, 0.025]
            .iter()
            .map(|&x| (x, 3.0 * x * x))
            .collect();
        let (p, c) = fit_line(&pts).unwrap();
        assert!((p - 2.0).abs() < 1e-12 && (c - 3f64.ln()).abs() < 1e-12);
    }
}
