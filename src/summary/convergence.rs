//! Convergence tables: observed rates, least-squares slopes and flags per refinement path and
//! error column (the maths is in the module header of [`super`]). The Parquet/CSV long table
//! holds every error column; the Markdown and LaTeX tables show the columns chosen by
//! [`SummaryOptions`] (the LaTeX layout is in [`latex`]).

use std::fmt::Write as _;

use super::latex;
use super::options::SummaryOptions;
use super::runs::{RefPath, Runs, group_heading};
use super::table::{self, Align, Kind, Table, TextTable, columns};

/// Pair rates spread over more than this: the errors are not yet in the asymptotic regime.
/// A clean power law gives spread 0; the converging ladders of SPEC §6 (h = 1/4 … 1/256, ratio
/// 4, l2(τ;H1)) wobble by 0.11 (Nitsche-Hybrid: 0.21, 0.28, 0.32), 0.04 (mod3 + CN) and 0.16
/// (zero-contact + CN), while the non-converging mixed + CN ladder (2.373, 1.470, 3.166,
/// 4.610) spreads by 0.9.
pub const PRE_ASYMPTOTIC_SPREAD: f64 = 0.3;
/// LSQ slope over the finest (up to) three usable levels below this: stagnating (includes
/// negative slopes, i.e. errors growing under refinement). The slowest genuine convergence the
/// papers report is ≈ 0.3 (SPEC §6), three times this.
pub const STAGNATION_SLOPE: f64 = 0.1;
/// Finest usable error at most this times the coarsest usable error: round-off floor. No
/// discretisation ladder reduces an error by twelve orders of magnitude (order 2 from h = 1/4
/// to 1/1024 gains 6.6e4); only cancellation to machine precision does.
pub const ROUNDOFF_RELATIVE: f64 = 1e-12;
/// Finest usable error below this (absolute): round-off floor. The scenes are O(1) in SI
/// units (bar: L = 1, E = ρ = 1, amplitude 0.5), so 1e-13 is ~1e-13 relative to the
/// solution — a few hundred ulps, where refinement only measures rounding. (Scaled problems
/// with tiny solutions would trip it early; the relative criterion does not depend on units.)
pub const ROUNDOFF_ABSOLUTE: f64 = 1e-13;

/// The observed rate between a coarser level (x_c, e_c) and a finer one (x_f, e_f):
/// log(e_c/e_f) / log(x_c/x_f), from the actual ratio of the refinement values.
pub fn observed_rate(e_coarse: f64, e_fine: f64, x_coarse: f64, x_fine: f64) -> f64 {
    (e_coarse / e_fine).ln() / (x_coarse / x_fine).ln()
}

/// Least-squares slope p of log e = log C + p log x over the given points:
/// p = Σ(ξ_i − ξ̄)(η_i − η̄) / Σ(ξ_i − ξ̄)², ξ = log x, η = log e. `None` with fewer than two
/// points or no spread in x.
pub fn lsq_slope(x: &[f64], e: &[f64]) -> Option<f64> {
    let n = x.len().min(e.len());
    if n < 2 {
        return None;
    }
    let xi: Vec<f64> = x[..n].iter().map(|v| v.ln()).collect();
    let eta: Vec<f64> = e[..n].iter().map(|v| v.ln()).collect();
    let mx = xi.iter().sum::<f64>() / n as f64;
    let me = eta.iter().sum::<f64>() / n as f64;
    let sxx: f64 = xi.iter().map(|a| (a - mx) * (a - mx)).sum();
    let sxe: f64 = xi.iter().zip(&eta).map(|(a, b)| (a - mx) * (b - me)).sum();
    if sxx <= 0.0 || !sxx.is_finite() {
        return None;
    }
    Some(sxe / sxx)
}

/// One level of a path as the fit sees it.
#[derive(Debug, Clone)]
pub(crate) struct LevelIn<'a> {
    pub x: f64,
    pub status: &'a str,
    pub value: Option<f64>,
}

/// The fit's verdict on one level.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelFit {
    /// Used in the rates and fits.
    pub used: bool,
    /// Why not (status, no value, zero error).
    pub excluded: Option<String>,
    /// Rate of the pair (previous used level, this level); attached to the finer level.
    pub rate: Option<f64>,
    /// Index of the coarser level of that pair (≠ level − 1 when a level was skipped).
    pub rate_from: Option<usize>,
}

/// How a format marks a level's cells: an excluded level's value (in parentheses, then the
/// format's mark) and a rate taken against a level further back than the previous one.
pub(crate) struct LevelMarks {
    pub excluded: &'static str,
    pub skipped: &'static str,
}

/// The Markdown tables' marks.
pub(crate) const MARKDOWN_MARKS: LevelMarks = LevelMarks {
    excluded: " ✗",
    skipped: " †",
};

/// A level's value and rate cells as a table prints them, and what they mark.
pub(crate) struct LevelCells {
    pub value: String,
    pub rate: String,
    /// The value is shown but excluded from the fits.
    pub excluded: bool,
    /// The rate is against a level further back (a level in between was excluded).
    pub skipped: bool,
}

impl LevelFit {
    /// The cells of level `li` from its formatted value and rate, marked as `marks` says
    /// (one rule for every format, so the Markdown and LaTeX tables mark the same levels).
    pub(crate) fn cells(
        &self,
        li: usize,
        value: String,
        rate: String,
        marks: &LevelMarks,
    ) -> LevelCells {
        let excluded = !(self.used || value.is_empty());
        let skipped = self.rate_from.is_some_and(|from| from + 1 != li);
        LevelCells {
            value: if excluded {
                format!("({value}){}", marks.excluded)
            } else {
                value
            },
            rate: if skipped { rate + marks.skipped } else { rate },
            excluded,
            skipped,
        }
    }
}

/// Rates, slopes and flags of one error column along one path.
#[derive(Debug, Clone, Default)]
pub(crate) struct Fit {
    pub levels: Vec<LevelFit>,
    pub used: usize,
    pub slope_all: Option<f64>,
    pub slope_fine3: Option<f64>,
    pub fine_levels: usize,
    pub spread: Option<f64>,
    pub pre_asymptotic: bool,
    pub stagnating: bool,
    pub roundoff: bool,
    pub failed: usize,
}

impl Fit {
    /// The flags as words ("-" when none).
    pub(crate) fn flags(&self) -> String {
        let mut f = Vec::new();
        if self.used < 2 {
            f.push("no fit (< 2 usable levels)".to_string());
        }
        if self.pre_asymptotic {
            f.push("pre-asymptotic".into());
        }
        if self.stagnating {
            f.push("stagnating".into());
        }
        if self.roundoff {
            f.push("round-off floor".into());
        }
        if self.failed > 0 {
            f.push(format!(
                "{} failed level{}",
                self.failed,
                if self.failed == 1 { "" } else { "s" }
            ));
        }
        if f.is_empty() {
            "-".into()
        } else {
            f.join(", ")
        }
    }
}

/// Fit one error column along one path, levels ordered coarse → fine.
pub(crate) fn fit(levels: &[LevelIn]) -> Fit {
    let mut out = Fit {
        levels: vec![LevelFit::default(); levels.len()],
        ..Fit::default()
    };
    let mut xs = Vec::new();
    let mut es = Vec::new();
    let mut prev: Option<usize> = None;
    let mut zero = false;
    for (i, l) in levels.iter().enumerate() {
        let lf = &mut out.levels[i];
        if l.status != "ok" {
            out.failed += 1;
            lf.excluded = Some(format!("status {}", l.status));
            continue;
        }
        match l.value {
            None => lf.excluded = Some("no value".into()),
            Some(v) if !v.is_finite() => lf.excluded = Some("non-finite".into()),
            // An exact zero has no logarithm: the error is at (or below) the floor.
            Some(v) if v <= 0.0 => {
                zero = true;
                lf.excluded = Some("zero error".into());
            }
            Some(v) => {
                lf.used = true;
                if let Some(p) = prev {
                    let (xp, ep) = (levels[p].x, levels[p].value.expect("used"));
                    lf.rate = Some(observed_rate(ep, v, xp, l.x));
                    lf.rate_from = Some(p);
                }
                prev = Some(i);
                xs.push(l.x);
                es.push(v);
            }
        }
    }
    out.used = xs.len();
    out.slope_all = lsq_slope(&xs, &es);
    let k = xs.len().min(3);
    out.fine_levels = k;
    out.slope_fine3 = lsq_slope(&xs[xs.len() - k..], &es[es.len() - k..]);
    let rates: Vec<f64> = out.levels.iter().filter_map(|l| l.rate).collect();
    if rates.len() >= 2 {
        let max = rates.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = rates.iter().copied().fold(f64::INFINITY, f64::min);
        out.spread = Some(max - min);
        out.pre_asymptotic = max - min > PRE_ASYMPTOTIC_SPREAD;
    }
    out.stagnating = out.slope_fine3.is_some_and(|s| s < STAGNATION_SLOPE);
    if let (Some(&coarse), Some(&finest)) = (es.first(), es.last()) {
        out.roundoff = finest <= ROUNDOFF_RELATIVE * coarse || finest < ROUNDOFF_ABSOLUTE;
    }
    out.roundoff |= zero;
    out
}

/// The error columns of a path: those with a value at some level.
fn path_errors(runs: &Runs, p: &RefPath) -> Vec<usize> {
    (0..runs.errors.len())
        .filter(|&e| {
            p.levels
                .iter()
                .any(|&(_, i)| runs.runs[i].errors[e].is_some_and(|v| !v.is_nan()))
        })
        .collect()
}

/// At most this many error columns on the terminal (the rest is in the files).
const TERMINAL_ERRORS: usize = 4;

/// The message when nothing can be fitted.
pub const NO_REFINEMENT: &str = "no refinement axis: every group has a single (h, dt) level";

/// The convergence section: long table, Markdown, LaTeX (fragment and stand-alone document)
/// and the terminal lines.
pub(crate) struct Section {
    pub table: Table,
    pub markdown: String,
    pub latex: String,
    pub latex_doc: String,
    pub terminal: String,
    /// One line per method group, with its legend and hints (terminal and report).
    pub groups: GroupTable,
    /// The error columns the text tables show (indices into [`Runs::errors`]).
    pub display: Vec<usize>,
}

/// The error columns the text tables show: the chosen ones that have values in the folder
/// (indices into [`Runs::errors`], in the chosen order), and sentences about the rest. When
/// none of the *default* columns has a value (a scene or version without them), every column
/// with values is shown rather than an empty table.
fn displayed(runs: &Runs, opts: &SummaryOptions) -> (Vec<usize>, Vec<String>) {
    let chosen = opts.chosen();
    let mut show: Vec<usize> = chosen
        .iter()
        .filter_map(|c| runs.errors.iter().position(|e| e == c))
        .collect();
    let missing: Vec<&str> = chosen
        .iter()
        .copied()
        .filter(|c| !runs.errors.contains(c))
        .collect();
    let mut notes = Vec::new();
    if runs.errors.is_empty() || runs.paths.is_empty() {
        return (show, notes);
    }
    if show.is_empty() && opts.errors.is_none() {
        show = (0..runs.errors.len()).collect();
        notes.push(format!(
            "None of the default error columns ({}) has a value in this folder: every column with values is shown.",
            chosen.join(", ")
        ));
    } else if !missing.is_empty() {
        notes.push(format!(
            "No value in this folder for {}.",
            missing.join(", ")
        ));
    }
    // The default selection carries the tangential errors where the folder has them (only a
    // frictional scene fills them: a frictionless folder's tables are unchanged).
    if opts.errors.is_none() {
        for c in crate::model::TANGENTIAL_ERRORS {
            if let Some(e) = runs.errors.iter().position(|e| e == c)
                && !show.contains(&e)
            {
                show.push(e);
            }
        }
    }
    let hidden: Vec<&str> = (0..runs.errors.len())
        .filter(|e| !show.contains(e))
        .map(|e| runs.errors[e])
        .collect();
    if !hidden.is_empty() {
        notes.push(format!(
            "Not shown here (in convergence.parquet and .csv): {}.",
            hidden.join(", ")
        ));
    }
    (show, notes)
}

fn columns(runs: &Runs) -> Vec<(String, Kind)> {
    table::with_params(
        &columns![
            group: I64, group_title: Str, path: I64, fixed: Str, fixed_value: F64, refined: Str,
            levels: I64, level: I64, run_id: Str, label: Str, status: Str, message: Str, h: F64,
            dt: F64, courant: F64, elements: I64, refinement: F64, error: Str, value: F64,
            used_in_fit: Bool, excluded: Str, rate: F64, rate_from_level: I64, slope_all: F64,
            fit_levels: I64, slope_finest3: F64, finest_levels: I64, rate_spread: F64,
            pre_asymptotic: Bool, stagnating: Bool, roundoff_floor: Bool, failed_levels: I64,
            flags: Str,
        ],
        runs,
    )
}

/// A group's main refinement path: its index and the fits of its error columns.
type MainPath = (usize, Vec<(usize, Fit)>);

/// The flags of a fit as letters after its rate on the terminal (explained by the legend):
/// p pre-asymptotic, s stagnating, r round-off floor, f failed levels, n no fit.
fn flag_letters(f: &Fit) -> String {
    let mut s = String::new();
    for (on, c) in [
        (f.used < 2, 'n'),
        (f.pre_asymptotic, 'p'),
        (f.stagnating, 's'),
        (f.roundoff, 'r'),
        (f.failed > 0, 'f'),
    ] {
        if on {
            s.push(c);
        }
    }
    s
}

/// E(T)/E⁰ of a run (None without the energies).
fn energy_ratio(r: &super::runs::Run) -> Option<f64> {
    r.energy_ratio()
}

/// The terminal's view of the convergence section: one line per method group with the LSQ
/// slopes of its longest refinement path (or, when no group is refined, its errors), a legend
/// for every abbreviation, and the hints of "what to look at". `main[g]` is group g's main path
/// and its fits; `hidden` the other paths; `single` the groups with one (h, dt) level.
fn group_lines(
    runs: &Runs,
    display: &[usize],
    main: &[Option<MainPath>],
    hidden: usize,
    single: usize,
) -> GroupTable {
    let mut out = String::new();
    let mut hints = Vec::new();
    let shown: Vec<usize> = display.iter().copied().take(TERMINAL_ERRORS).collect();
    let main_paths: Vec<Option<usize>> = main.iter().map(|m| m.as_ref().map(|(p, _)| *p)).collect();
    if runs.groups.is_empty() {
        return GroupTable {
            main_paths,
            ..GroupTable::default()
        };
    }
    let refined = main.iter().any(Option::is_some);
    let mut cols: Vec<(String, Align)> =
        vec![("#".into(), Align::Right), ("method".into(), Align::Left)];
    if refined {
        cols.extend([
            ("path".into(), Align::Left),
            ("levels".into(), Align::Right),
        ]);
    } else {
        cols.push(("runs".into(), Align::Right));
    }
    for &e in &shown {
        cols.push((
            table::error_abbrev(runs.errors[e]).0.to_string(),
            Align::Right,
        ));
    }
    cols.push(("E(T)/E⁰".into(), Align::Right));
    let mut rows = Vec::new();
    // (group, rate) per shown column, and (group, E(T)/E⁰) — for the hints.
    let mut best: Vec<Option<(usize, f64)>> = vec![None; shown.len()];
    let mut stagnating: Vec<usize> = Vec::new();
    let mut ratios: Vec<(usize, f64)> = Vec::new();
    for (g, grp) in runs.groups.iter().enumerate() {
        let mut row = vec![(g + 1).to_string(), grp.title.clone()];
        let ratio;
        match &main[g] {
            Some((pi, fits)) => {
                let p = &runs.paths[*pi];
                let used = shown
                    .iter()
                    .find_map(|e| fits.iter().find(|(x, _)| x == e))
                    .map(|(_, f)| f.used)
                    .unwrap_or(0);
                row.push(p.fixed.short());
                row.push(format!("{used}/{}", p.levels.len()));
                let mut stag = false;
                for (k, e) in shown.iter().enumerate() {
                    match fits.iter().find(|(x, _)| x == e) {
                        Some((_, f)) => {
                            let letters = flag_letters(f);
                            stag |= f.stagnating;
                            if let Some(r) = f.slope_all.filter(|r| r.is_finite())
                                && best[k].is_none_or(|(_, b)| r > b)
                            {
                                best[k] = Some((g, r));
                            }
                            // Letters padded so that the rates stay right-aligned.
                            row.push(format!("{} {letters:<2}", table::rate(f.slope_all)));
                        }
                        None => row.push("—".into()),
                    }
                }
                if stag {
                    stagnating.push(g);
                }
                ratio = p
                    .levels
                    .iter()
                    .rev()
                    .map(|&(_, i)| &runs.runs[i])
                    .find(|r| r.ok())
                    .and_then(energy_ratio);
            }
            None => {
                // Not refined: the errors of the group's first ok run (a single level; several
                // runs only as ensemble members or repeats).
                let r = grp
                    .runs
                    .iter()
                    .map(|&i| &runs.runs[i])
                    .find(|r| r.ok())
                    .unwrap_or(&runs.runs[grp.runs[0]]);
                if refined {
                    row.extend(["single level".into(), "1".into()]);
                    row.extend(shown.iter().map(|_| "—".to_string()));
                } else {
                    row.push(format!(
                        "{}/{}",
                        grp.runs.iter().filter(|&&i| runs.runs[i].ok()).count(),
                        grp.runs.len()
                    ));
                    row.extend(shown.iter().map(|&e| table::eng_opt(r.errors[e])));
                }
                ratio = if r.ok() { energy_ratio(r) } else { None };
            }
        }
        if let Some(x) = ratio {
            ratios.push((g, x));
        }
        row.push(table::eng_opt(ratio));
        rows.push(row);
    }
    if refined {
        let _ = writeln!(
            out,
            "convergence rates by method group (LSQ slope of log e against log h or dt over the group's longest refinement path):"
        );
    } else {
        let _ = writeln!(out, "errors by method group (no refinement path):");
    }
    let text = TextTable::new(cols).with_rows(rows);
    out.push_str(&text.plain());
    // Legend: every abbreviation of the table, one per line for the error columns.
    let mut legend: Vec<String> = Vec::new();
    if refined {
        legend.push(
            "path: the value held fixed and the axis refined (ν Courant number, h↓ h refined); levels: usable/all".into(),
        );
        legend.push(format!(
            "rate letters: p pre-asymptotic (pair rates spread > {PRE_ASYMPTOTIC_SPREAD}), s stagnating (finest-three slope < {STAGNATION_SLOPE}), r round-off floor, f failed levels, n no fit"
        ));
    }
    // Two error columns per legend line: the legend must not push the table off the screen.
    let entries: Vec<String> = shown
        .iter()
        .map(|&e| {
            let (a, what) = table::error_abbrev(runs.errors[e]);
            format!("{a}: {what} ({})", runs.errors[e])
        })
        .collect();
    for pair in entries.chunks(2) {
        legend.push(pair.join(" · "));
    }
    legend.push(if refined {
        "E(T)/E⁰: final over initial discrete energy at the path's finest ok level (1 + energy_drift: relative to m·g·gap under gravity, where E⁰ = 0)".into()
    } else {
        "E(T)/E⁰: final over initial discrete energy (1 + energy_drift: relative to m·g·gap under gravity, where E⁰ = 0)".into()
    });
    for l in &legend {
        let _ = writeln!(out, "  {l}");
    }
    if hidden > 0 || single > 0 {
        let mut parts = Vec::new();
        if hidden > 0 {
            parts.push(format!(
                "{hidden} other refinement path{} in convergence.md",
                if hidden == 1 { "" } else { "s" }
            ));
        }
        if single > 0 && refined {
            parts.push(format!(
                "{single} of {} groups with a single (h, dt) level",
                runs.groups.len()
            ));
        }
        if !parts.is_empty() {
            let _ = writeln!(out, "  ({})", parts.join("; "));
        }
    }
    // Hints: the best rate of the first two columns, the stagnating groups, the energy range.
    for (k, b) in best.iter().enumerate().take(2) {
        if let Some((g, r)) = b {
            hints.push(format!(
                "highest {} rate: {} (group {}, {})",
                table::error_abbrev(runs.errors[shown[k]]).0,
                table::rate(Some(*r)),
                g + 1,
                runs.groups[*g].title
            ));
        }
    }
    if !stagnating.is_empty() {
        hints.push(format!(
            "stagnating (s): group{} {} — refining does not reduce some error there",
            if stagnating.len() == 1 { "" } else { "s" },
            stagnating
                .iter()
                .map(|g| (g + 1).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    let gained: Vec<String> = ratios
        .iter()
        .filter(|(_, x)| *x > 1.0 + 1e-3)
        .map(|(g, _)| (g + 1).to_string())
        .collect();
    if !gained.is_empty() {
        hints.push(format!(
            "energy gained (E(T)/E⁰ > 1.001): group{} {}",
            if gained.len() == 1 { "" } else { "s" },
            gained.join(", ")
        ));
    }
    GroupTable {
        caption: if refined {
            "convergence rates by method group (LSQ slope of log e against log h or dt over the group's longest refinement path)".into()
        } else {
            "errors by method group (no refinement path)".into()
        },
        header: text.header().to_vec(),
        right: text.right(),
        rows: text.rows().to_vec(),
        legend,
        hints,
        terminal: out,
        main_paths,
    }
}

/// The table of one line per method group (terminal and report), its legend and the hints.
#[derive(Debug, Clone, Default)]
pub(crate) struct GroupTable {
    pub caption: String,
    pub header: Vec<String>,
    /// Right-aligned columns.
    pub right: Vec<bool>,
    pub rows: Vec<Vec<String>>,
    /// One line per abbreviation of the table.
    pub legend: Vec<String>,
    /// What to look at first, one sentence each.
    pub hints: Vec<String>,
    /// The table as the terminal prints it (caption, table, legend, notes).
    pub terminal: String,
    /// Per group: its main refinement path (index into [`Runs::paths`]), if refined.
    pub main_paths: Vec<Option<usize>>,
}

/// Build the convergence section; `title` heads the stand-alone LaTeX document.
pub(crate) fn section(runs: &Runs, opts: &SummaryOptions, title: &str) -> Section {
    let mut t = Table::new(&columns(runs));
    let mut md = String::new();
    let mut tex_notes: Vec<String> = Vec::new();
    let mut tex_paths: Vec<latex::PathTex> = Vec::new();
    let (display, notes) = displayed(runs, opts);
    let mut hidden = 0usize;
    // Per group: its main refinement path (index) and the fits of its error columns.
    let mut main: Vec<Option<MainPath>> = vec![None; runs.groups.len()];

    md.push_str("# Convergence\n\n");
    let _ = writeln!(
        md,
        "Runs grouped by every parameter except the refinement axes (h/elements, dt/courant); \
         within a group a refinement path holds courant, dt or h fixed and has ≥ 2 levels, \
         ordered coarse → fine. rate = log(e_prev/e)/log(x_prev/x) from the actual ratios of \
         the refined axis x (h or dt), against the previous usable level (†: a level was \
         skipped). Slopes: least squares of log e against log x over all usable levels and \
         over the finest three. Flags: pre-asymptotic (pair rates spread > {PRE_ASYMPTOTIC_SPREAD}), \
         stagnating (slope over the finest three < {STAGNATION_SLOPE}), round-off floor (finest \
         error ≤ {ROUNDOFF_RELATIVE:e}·coarsest, or < {ROUNDOFF_ABSOLUTE:e}, or exactly 0). \
         Levels whose status is not ok are kept, marked ✗, and excluded from rates and fits.\n"
    );
    if !runs.paths.is_empty() && !runs.errors.is_empty() {
        let _ = writeln!(
            md,
            "Error columns: {} ({}; choose with `[summary] errors = [...]` in the sweep file or \
             `contact-sweep summarize DIR --errors a,b,c`; every column is in convergence.parquet \
             and .csv).\n",
            display
                .iter()
                .map(|&e| runs.errors[e])
                .collect::<Vec<_>>()
                .join(", "),
            if opts.errors.is_some() {
                "chosen"
            } else {
                "the default"
            }
        );
        for n in &notes {
            let _ = writeln!(md, "{n}\n");
        }
    }
    tex_notes.extend(notes);

    let single = runs.groups.iter().filter(|g| g.levels < 2).count();
    let multi_without_path: Vec<usize> = (0..runs.groups.len())
        .filter(|&g| runs.groups[g].levels >= 2 && !runs.paths.iter().any(|p| p.group == g))
        .collect();

    let mut terminal = String::new();
    if runs.paths.is_empty() {
        if multi_without_path.is_empty() {
            let _ = writeln!(md, "**{NO_REFINEMENT}** ({} groups).\n", runs.groups.len());
            tex_notes.push(format!("{NO_REFINEMENT} ({} groups).", runs.groups.len()));
            let _ = writeln!(
                terminal,
                "convergence: {NO_REFINEMENT} ({} groups) — no rates to compute",
                runs.groups.len()
            );
        } else {
            let msg = "no refinement path: no group holds courant, dt or h fixed over ≥ 2 levels";
            let _ = writeln!(md, "**{msg}**.\n");
            tex_notes.push(format!("{msg}."));
            let _ = writeln!(terminal, "convergence: {msg}");
        }
    } else if runs.errors.is_empty() {
        let msg = "no error columns with values (no reference solution): rates cannot be computed";
        let _ = writeln!(md, "**{msg}**.\n");
        tex_notes.push(format!("{msg}."));
        let _ = writeln!(terminal, "convergence: {msg}");
    }
    if single > 0 && !runs.paths.is_empty() {
        let _ = writeln!(
            md,
            "{single} of {} groups have a single (h, dt) level and are not in these tables.\n",
            runs.groups.len()
        );
    }
    for &g in &multi_without_path {
        let _ = writeln!(
            md,
            "- {}: {} (h, dt) levels but neither courant, dt nor h is held fixed over two of them — not fitted.",
            group_heading(runs, g),
            runs.groups[g].levels
        );
    }
    if !multi_without_path.is_empty() {
        md.push('\n');
    }

    for (pi, p) in runs.paths.iter().enumerate() {
        let g = p.group;
        let errs = path_errors(runs, p);
        let heading = format!(
            "{} — {} (path {})",
            group_heading(runs, g),
            p.fixed.describe(),
            pi + 1
        );
        let _ = writeln!(md, "## {heading}\n");
        let first = &runs.runs[runs.groups[g].runs[0]];
        let params: Vec<String> = runs
            .params
            .iter()
            .zip(&first.params)
            .filter_map(|((n, _), c)| c.show().map(|v| format!("{n}={v}")))
            .collect();
        let _ = writeln!(md, "Parameters: {}\n", params.join(", "));
        if errs.is_empty() {
            md.push_str("No error column has a value on this path (no reference solution).\n\n");
            continue;
        }
        let fits: Vec<(usize, Fit)> = errs
            .iter()
            .map(|&e| {
                let lv: Vec<LevelIn> = p
                    .levels
                    .iter()
                    .map(|&(x, i)| LevelIn {
                        x,
                        status: &runs.runs[i].status,
                        value: runs.runs[i].errors[e],
                    })
                    .collect();
                (e, fit(&lv))
            })
            .collect();

        // Long table rows.
        for (e, f) in &fits {
            for (li, &(x, ri)) in p.levels.iter().enumerate() {
                let r = &runs.runs[ri];
                let lf = &f.levels[li];
                t.i64("group", Some(g as i64 + 1));
                t.str("group_title", Some(&runs.groups[g].title));
                t.i64("path", Some(pi as i64 + 1));
                t.str("fixed", Some(p.fixed.name()));
                t.f64("fixed_value", Some(p.fixed.value()));
                t.str("refined", Some(p.fixed.refined()));
                t.i64("levels", Some(p.levels.len() as i64));
                t.i64("level", Some(li as i64));
                t.run_identity(r);
                t.str("message", r.message.as_deref());
                t.run_level(r);
                t.i64("elements", r.elements);
                t.f64("refinement", Some(x));
                t.str("error", Some(runs.errors[*e]));
                t.f64("value", r.errors[*e]);
                t.bool("used_in_fit", Some(lf.used));
                t.str("excluded", lf.excluded.as_deref());
                t.f64("rate", lf.rate);
                t.i64("rate_from_level", lf.rate_from.map(|v| v as i64));
                t.f64("slope_all", f.slope_all);
                t.i64("fit_levels", Some(f.used as i64));
                t.f64("slope_finest3", f.slope_fine3);
                t.i64("finest_levels", Some(f.fine_levels as i64));
                t.f64("rate_spread", f.spread);
                t.bool("pre_asymptotic", Some(f.pre_asymptotic));
                t.bool("stagnating", Some(f.stagnating));
                t.bool("roundoff_floor", Some(f.roundoff));
                t.i64("failed_levels", Some(f.failed as i64));
                t.str("flags", Some(&f.flags()));
                for ((n, _), c) in runs.params.iter().zip(&r.params) {
                    t.cell(n, c);
                }
                t.end_row();
            }
        }

        // Markdown: one table per path, deal.II ConvergenceTable style, with the chosen
        // columns (every one is in the long table above).
        let shown: Vec<&(usize, Fit)> = display
            .iter()
            .filter_map(|d| fits.iter().find(|(e, _)| e == d))
            .collect();
        if shown.is_empty() {
            md.push_str("None of the error columns shown has a value on this path.\n\n");
        }
        let mut cols: Vec<(&str, Align)> = vec![
            ("level", Align::Right),
            ("h", Align::Right),
            ("dt", Align::Right),
            ("status", Align::Left),
        ];
        for (e, _) in &shown {
            cols.push((runs.errors[*e], Align::Right));
            if opts.rates {
                cols.push(("rate", Align::Right));
            }
        }
        let mut rows: Vec<Vec<String>> = Vec::new();
        let mut skipped = false;
        for (li, &(_, ri)) in p.levels.iter().enumerate() {
            let r = &runs.runs[ri];
            let mut row = vec![
                li.to_string(),
                table::sci(r.h),
                table::sci(r.dt),
                if r.ok() {
                    r.status.clone()
                } else {
                    format!("{} ✗", r.status)
                },
            ];
            for (e, f) in &shown {
                let lf = &f.levels[li];
                let cells = lf.cells(
                    li,
                    table::sci(r.errors[*e]),
                    table::rate(lf.rate),
                    &MARKDOWN_MARKS,
                );
                row.push(cells.value);
                if opts.rates {
                    skipped |= cells.skipped;
                    row.push(cells.rate);
                }
            }
            rows.push(row);
        }
        // A statistics row: its name, then one cell per shown column (two with rates: the
        // statistic sits under the rate, a note under the value).
        let stat_row = |name: &str, cell: &dyn Fn(&Fit) -> (String, String)| -> Vec<String> {
            let mut row = vec![
                name.to_string(),
                String::new(),
                String::new(),
                String::new(),
            ];
            for (_, f) in &shown {
                let (note, stat) = cell(f);
                if opts.rates {
                    row.extend([note, stat]);
                } else if stat.is_empty() {
                    row.push(note);
                } else {
                    row.push(stat);
                }
            }
            row
        };
        if opts.slopes {
            rows.push(stat_row("LSQ slope, all usable levels", &|f| {
                (format!("({} levels)", f.used), table::rate(f.slope_all))
            }));
            rows.push(stat_row("LSQ slope, finest 3", &|f| {
                (
                    format!("({} levels)", f.fine_levels),
                    table::rate(f.slope_fine3),
                )
            }));
        }
        if opts.rates {
            rows.push(stat_row("rate spread", &|f| {
                (String::new(), table::rate(f.spread))
            }));
        }
        if opts.flags {
            rows.push(stat_row("flags", &|f| (f.flags(), String::new())));
        }
        if !shown.is_empty() {
            md.push_str(
                &TextTable::new(cols.iter().copied())
                    .with_rows(rows)
                    .markdown(),
            );
            md.push('\n');
        }
        if skipped {
            md.push_str(
                "†: rate against the previous usable level (a level in between is excluded).\n\n",
            );
        }
        let excluded: Vec<String> = p
            .levels
            .iter()
            .enumerate()
            .filter(|(_, (_, ri))| !runs.runs[*ri].ok())
            .map(|(li, (_, ri))| {
                let r = &runs.runs[*ri];
                format!(
                    "- level {li} ({}): {}{}",
                    r.run_id,
                    r.status,
                    r.message
                        .as_ref()
                        .map(|m| format!(" — {m}"))
                        .unwrap_or_default()
                )
            })
            .collect();
        if !excluded.is_empty() {
            md.push_str("Excluded from the fits:\n");
            md.push_str(&excluded.join("\n"));
            md.push_str("\n\n");
        }

        if !shown.is_empty() {
            tex_paths.push(latex::PathTex {
                index: pi,
                path: p,
                fits: shown.iter().map(|(e, f)| (*e, f.clone())).collect(),
            });
        }

        // Terminal: one line per group, from its longest refinement path (the first of equal
        // length); a grid of h × dt also yields many two-level paths, they are in the files.
        let longest = runs
            .paths
            .iter()
            .filter(|q| q.group == g)
            .map(|q| q.levels.len())
            .max()
            .unwrap_or(0);
        if p.levels.len() < longest || main[g].is_some() {
            hidden += 1;
            continue;
        }
        main[g] = Some((pi, fits));
    }

    let groups = group_lines(runs, &display, &main, hidden, single);
    terminal.push_str(&groups.terminal);
    let tex = latex::render(runs, opts, &display, &tex_paths, &tex_notes, title);
    Section {
        table: t,
        markdown: md,
        latex: tex.fragment,
        latex_doc: tex.document,
        terminal,
        groups,
        display,
    }
}
