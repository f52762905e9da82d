//! Convergence tables: observed rates, least-squares slopes and flags per refinement path and
//! error column (the maths is in the module header of [`super`]). The Parquet/CSV long table
//! holds every error column; the Markdown and LaTeX tables show the columns chosen by
//! [`SummaryOptions`] (the LaTeX layout is in [`latex`]).

use std::fmt::Write as _;

use super::columns::{Kind, columns};
use super::latex;
use super::rates::{Fit, LevelIn, LevelMarks, fit};
use super::runs::{RefPath, Runs, group_heading};
use super::table::{self, Align, Table, TextTable};
use crate::model::SummaryOptions;

// The fits' thresholds and formulas, public here where they have always been.
pub use super::rates::{
    PRE_ASYMPTOTIC_SPREAD, ROUNDOFF_ABSOLUTE, ROUNDOFF_RELATIVE, STAGNATION_SLOPE, lsq_slope,
    observed_rate,
};

/// The Markdown tables' marks.
pub(crate) const MARKDOWN_MARKS: LevelMarks = LevelMarks {
    excluded: " ✗",
    skipped: " †",
};

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
    let shown: Vec<usize> = display.iter().copied().take(TERMINAL_ERRORS).collect();
    let main_paths: Vec<Option<usize>> = main.iter().map(|m| m.as_ref().map(|(p, _)| *p)).collect();
    if runs.groups.is_empty() {
        return GroupTable {
            main_paths,
            ..GroupTable::default()
        };
    }
    let refined = main.iter().any(Option::is_some);
    let cols = group_columns(runs, &shown, refined);
    let mut notable = Notable {
        best: vec![None; shown.len()],
        stagnating: Vec::new(),
        ratios: Vec::new(),
    };
    let rows: Vec<Vec<String>> = (0..runs.groups.len())
        .map(|g| group_row(runs, g, &main[g], &shown, refined, &mut notable))
        .collect();
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
    let legend = group_legend(runs, &shown, refined);
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
        hints: hints(runs, &shown, &notable),
        terminal: out,
        main_paths,
    }
}

/// What the hints point to, gathered while the group lines are built.
struct Notable {
    /// Per shown error column: the group of the highest LSQ slope, and the slope.
    best: Vec<Option<(usize, f64)>>,
    /// Groups with a stagnating shown column.
    stagnating: Vec<usize>,
    /// (group, E(T)/E⁰) of every group that has it.
    ratios: Vec<(usize, f64)>,
}

/// The columns of the group lines: #, method, the path and its levels (or the runs when no
/// group is refined), the `shown` error columns, E(T)/E⁰.
fn group_columns(runs: &Runs, shown: &[usize], refined: bool) -> Vec<(String, Align)> {
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
    for &e in shown {
        cols.push((
            table::error_abbrev(runs.errors[e]).0.to_string(),
            Align::Right,
        ));
    }
    cols.push(("E(T)/E⁰".into(), Align::Right));
    cols
}

/// Group `g`'s line: its main path's slopes (`main_g`), or its errors when it has none.
fn group_row(
    runs: &Runs,
    g: usize,
    main_g: &Option<MainPath>,
    shown: &[usize],
    refined: bool,
    notable: &mut Notable,
) -> Vec<String> {
    let grp = &runs.groups[g];
    let mut row = vec![(g + 1).to_string(), grp.title.clone()];
    let ratio = match main_g {
        Some((pi, fits)) => main_path_cells(runs, g, *pi, fits, shown, &mut row, notable),
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
            if r.ok() { energy_ratio(r) } else { None }
        }
    };
    if let Some(x) = ratio {
        notable.ratios.push((g, x));
    }
    row.push(table::eng_opt(ratio));
    row
}

/// The cells of group `g`'s main path `pi` (its fits `fits`): the path, its usable levels and
/// each shown column's slope with its flag letters. Returns E(T)/E⁰ at the path's finest ok
/// level.
fn main_path_cells(
    runs: &Runs,
    g: usize,
    pi: usize,
    fits: &[(usize, Fit)],
    shown: &[usize],
    row: &mut Vec<String>,
    notable: &mut Notable,
) -> Option<f64> {
    let p = &runs.paths[pi];
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
                    && notable.best[k].is_none_or(|(_, b)| r > b)
                {
                    notable.best[k] = Some((g, r));
                }
                // Letters padded so that the rates stay right-aligned.
                row.push(format!("{} {letters:<2}", table::rate(f.slope_all)));
            }
            None => row.push("—".into()),
        }
    }
    if stag {
        notable.stagnating.push(g);
    }
    p.levels
        .iter()
        .rev()
        .map(|&(_, i)| &runs.runs[i])
        .find(|r| r.ok())
        .and_then(energy_ratio)
}

/// The legend of the group lines: every abbreviation of the table, one per line for the
/// error columns.
fn group_legend(runs: &Runs, shown: &[usize], refined: bool) -> Vec<String> {
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
    legend
}

/// Hints: the best rate of the first two columns, the stagnating groups, the energy gained.
fn hints(runs: &Runs, shown: &[usize], notable: &Notable) -> Vec<String> {
    let mut hints = Vec::new();
    for (k, b) in notable.best.iter().enumerate().take(2) {
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
    let stagnating = &notable.stagnating;
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
    let gained: Vec<String> = notable
        .ratios
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
    hints
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
    let mut tex_notes: Vec<String> = Vec::new();
    let mut tex_paths: Vec<latex::PathTex> = Vec::new();
    let (display, notes) = displayed(runs, opts);
    let mut hidden = 0usize;
    // Per group: its main refinement path (index) and the fits of its error columns.
    let mut main: Vec<Option<MainPath>> = vec![None; runs.groups.len()];
    let mut md = intro_markdown(runs, opts, &display, &notes);
    tex_notes.extend(notes);
    let single = runs.groups.iter().filter(|g| g.levels < 2).count();
    let mut terminal = unfitted(runs, single, &mut md, &mut tex_notes);

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
        let fits = path_fits(runs, p, &errs);
        long_rows(&mut t, runs, pi, p, &fits);

        // Markdown: one table per path, deal.II ConvergenceTable style, with the chosen
        // columns (every one is in the long table above).
        let shown: Vec<&(usize, Fit)> = display
            .iter()
            .filter_map(|d| fits.iter().find(|(e, _)| e == d))
            .collect();
        path_markdown(&mut md, runs, opts, p, &shown);
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

/// The head of `convergence.md`: what the tables hold, the error columns shown (`display`)
/// and the `notes` about the others.
fn intro_markdown(
    runs: &Runs,
    opts: &SummaryOptions,
    display: &[usize],
    notes: &[String],
) -> String {
    let mut md = String::new();
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
        for n in notes {
            let _ = writeln!(md, "{n}\n");
        }
    }
    md
}

/// What cannot be fitted, in `md`, `tex_notes` and the returned terminal lines: no refinement
/// axis or path, no error column, the `single` groups of one level, the groups of several
/// levels without a path.
fn unfitted(runs: &Runs, single: usize, md: &mut String, tex_notes: &mut Vec<String>) -> String {
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
    terminal
}

/// The fits of the error columns `errs` along path `p`.
fn path_fits(runs: &Runs, p: &RefPath, errs: &[usize]) -> Vec<(usize, Fit)> {
    errs.iter()
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
        .collect()
}

/// The long table's rows of path `pi`: one per error column and level.
fn long_rows(t: &mut Table, runs: &Runs, pi: usize, p: &RefPath, fits: &[(usize, Fit)]) {
    let g = p.group;
    for (e, f) in fits {
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
}

/// Path `p`'s Markdown table of the `shown` fits (levels, then the statistics rows the
/// options ask for), and its notes: skipped levels, excluded levels.
fn path_markdown(
    md: &mut String,
    runs: &Runs,
    opts: &SummaryOptions,
    p: &RefPath,
    shown: &[&(usize, Fit)],
) {
    if shown.is_empty() {
        md.push_str("None of the error columns shown has a value on this path.\n\n");
    }
    let mut cols: Vec<(&str, Align)> = vec![
        ("level", Align::Right),
        ("h", Align::Right),
        ("dt", Align::Right),
        ("status", Align::Left),
    ];
    for (e, _) in shown {
        cols.push((runs.errors[*e], Align::Right));
        if opts.rates {
            cols.push(("rate", Align::Right));
        }
    }
    let (mut rows, skipped) = level_rows(runs, opts, p, shown);
    rows.extend(stat_rows(opts, shown));
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
}

/// The Markdown rows of path `p`'s levels; and whether a rate is against a level further back.
fn level_rows(
    runs: &Runs,
    opts: &SummaryOptions,
    p: &RefPath,
    shown: &[&(usize, Fit)],
) -> (Vec<Vec<String>>, bool) {
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
        for (e, f) in shown {
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
    (rows, skipped)
}

/// The statistics rows the options ask for (slopes, rate spread, flags), under a path's levels.
fn stat_rows(opts: &SummaryOptions, shown: &[&(usize, Fit)]) -> Vec<Vec<String>> {
    let mut rows: Vec<Vec<String>> = Vec::new();
    // A statistics row: its name, then one cell per shown column (two with rates: the
    // statistic sits under the rate, a note under the value).
    let stat_row = |name: &str, cell: &dyn Fn(&Fit) -> (String, String)| -> Vec<String> {
        let mut row = vec![
            name.to_string(),
            String::new(),
            String::new(),
            String::new(),
        ];
        for (_, f) in shown {
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
    rows
}
