//! LaTeX convergence tables that compile as they are: the fragment `convergence.tex` for
//! `\input` in a paper, and the stand-alone `convergence_doc.tex` beside it (issue 14).
//!
//! # Why this layout
//! One LaTeX float per refinement path sank the quickstart (66 floats: LaTeX holds at most 18
//! unplaced floats, "Too many unprocessed floats"), and every error norm with its rate made 17
//! columns, wider than a landscape page. So:
//! - one table per method group, its refinement paths stacked (a heading row per path, then its
//!   levels, its LSQ slopes and its flags);
//! - the group tables are `table` floats only when there are at most [`MAX_FLOATS`] of them and
//!   each has at most [`FLOAT_MAX_ROWS`] rows (a float must fit on one page); otherwise every
//!   group is a `longtable`, which is not a float, breaks across pages and repeats its header.
//!   Never a mix: a float may drift past a later longtable and be numbered out of order;
//! - only the error columns chosen by [`SummaryOptions`] (four by default), in `\small`, with
//!   four significant digits (`$1.235\cdot10^{-2}$`) and refinement values as `$1/n$` when they
//!   are reciprocals of integers (the papers' h = 1/4 … 1/256). The stand-alone document is
//!   landscape A4 with 2 cm margins (728 pt of text). Tables of more than [`COMPACT_COLUMNS`]
//!   columns (six or seven error columns with rates) are set in `\footnotesize` with 4 pt
//!   column gaps, so that even all seven fit (tests/latex.rs compiles the document with
//!   pdflatex and fails on any overfull box).
//!
//! # Packages
//! The fragment needs `booktabs`, and `longtable` when it uses it (its first lines say which);
//! the stand-alone document adds `geometry` for the page. All three are in Debian's
//! texlive-latex-base and texlive-latex-recommended. The text is ASCII: the labels' Greek
//! letters and symbols become math ([`table::tex`]).
//!
//! # Flags
//! Letters, so that the flags row is no wider than the numbers above it: P pre-asymptotic,
//! S stagnating, R round-off floor, F failed levels, N fewer than two usable levels (no fit);
//! the caption says what each means.

use std::fmt::Write as _;

use super::rates::{Fit, LevelMarks, PRE_ASYMPTOTIC_SPREAD, STAGNATION_SLOPE};
use super::runs::{Fixed, RefPath, Runs};
use super::table;
use crate::model::SummaryOptions;

/// The LaTeX tables' marks: an excluded level's value in parentheses alone (the caption says
/// why), a rate against a level further back with a dagger.
const LATEX_MARKS: LevelMarks = LevelMarks {
    excluded: "",
    skipped: "$^\\dagger$",
};

/// At most this many group tables are floats. LaTeX keeps 18 floats waiting at most; a paper
/// has its own figures and tables in that queue, so the summary takes fewer than its share.
pub(crate) const MAX_FLOATS: usize = 12;
/// A group table of more rows is a `longtable`: at `\small` (11 pt lines) 30 rows, the header
/// and a caption of four lines take ≈ 400 pt, within the 483 pt of text height of a landscape
/// A4 page with 2 cm margins, so a float of that size always finds a page.
pub(crate) const FLOAT_MAX_ROWS: usize = 30;

/// Tables of more LaTeX columns than this are set smaller (see [`group_table`]).
pub(crate) const COMPACT_COLUMNS: usize = 11;

/// The fits of one refinement path, restricted to the chosen error columns (indices into
/// [`Runs::errors`]) in the chosen order.
pub(crate) struct PathTex<'a> {
    /// The path's number in the other tables (0-based).
    pub index: usize,
    pub path: &'a RefPath,
    pub fits: Vec<(usize, Fit)>,
}

/// The fragment and the stand-alone document.
pub(crate) struct Latex {
    pub fragment: String,
    pub document: String,
}

/// A refinement value (h or τ) in math mode, without the dollars: `1/8` when 1/x is an
/// integer (to 1e-9 relative: h = L/m and τ = ν h/c0 are computed in floating point), the
/// shortest decimal when it has at most five significant digits (τ = 0.015), else four
/// significant digits.
fn level_math(x: f64) -> String {
    if x > 0.0 && x < 1.0 {
        let n = (1.0 / x).round();
        if n >= 2.0 && ((1.0 / x) - n).abs() <= 1e-9 * n {
            return format!("1/{n:.0}");
        }
    }
    let short = format!("{x}");
    let digits = short.chars().filter(|c| c.is_ascii_digit()).count();
    let lead_zeros = short
        .trim_start_matches('-')
        .chars()
        .take_while(|c| *c == '0' || *c == '.')
        .filter(|c| *c == '0')
        .count();
    if !short.contains('e') && digits - lead_zeros <= 5 && short.len() <= 8 {
        return short;
    }
    sci_math(x)
}

/// Four significant digits in math mode without the dollars: `1.235\cdot10^{-2}`.
fn sci_math(x: f64) -> String {
    let s = format!("{x:.3e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    if e == "0" {
        m.to_string()
    } else {
        format!("{m}\\cdot10^{{{e}}}")
    }
}

/// An error value: `$1.235\cdot10^{-2}$`, empty when missing.
fn value(x: Option<f64>) -> String {
    match x {
        Some(0.0) => "$0$".into(),
        Some(x) if x.is_finite() => format!("${}$", sci_math(x)),
        Some(x) => table::tex(&format!("{x}")),
        None => String::new(),
    }
}

fn level(x: Option<f64>) -> String {
    match x {
        Some(x) if x.is_finite() => format!("${}$", level_math(x)),
        _ => String::new(),
    }
}

/// What a path holds fixed and what it refines.
fn describe(f: &Fixed) -> String {
    match *f {
        Fixed::Courant(x) => format!("$\\nu = {}$ fixed, $h$ refined", level_math(x)),
        Fixed::Ratio(x) => format!("$\\tau/h = {}$ fixed, $h$ refined", level_math(x)),
        Fixed::Dt(x) => format!("$\\tau = {}$ fixed, $h$ refined", level_math(x)),
        Fixed::H(x) => format!("$h = {}$ fixed, $\\tau$ refined", level_math(x)),
    }
}

/// The flags as letters (legend in the caption); `--` when none.
fn flag_letters(f: &Fit) -> String {
    let mut s = Vec::new();
    if f.used < 2 {
        s.push("N");
    }
    if f.pre_asymptotic {
        s.push("P");
    }
    if f.stagnating {
        s.push("S");
    }
    if f.roundoff {
        s.push("R");
    }
    if f.failed > 0 {
        s.push("F");
    }
    if s.is_empty() {
        "--".into()
    } else {
        s.join(",")
    }
}

/// Column head of an error column.
fn error_head(name: &str) -> &'static str {
    match name {
        "err_u_l2l2" => "$u$: $l^2(\\tau;L^2)$",
        "err_u_l2h1" => "$u$: $l^2(\\tau;H^1)$",
        "err_u_linfl2" => "$u$: $l^\\infty(L^2)$",
        "err_sigma_l2" => "$\\sigma_C^n$: $l^2(\\tau)$",
        "err_sigma_mid_l2" => "$\\sigma_C^{n-1/2}$: $l^2(\\tau)$",
        "err_energy_l2" => "$E$: $l^2(\\tau)$",
        "err_u_contact_max" => "$u_C$: max",
        _ => "error",
    }
}

/// The LSQ slope rows of a path of `levels` levels: none for two levels (the slope is the one
/// rate), only the slope over all levels for three (the finest three are all of them).
fn slope_rows(opts: &SummaryOptions, levels: usize) -> usize {
    match (opts.slopes, levels) {
        (false, _) | (_, 0..=2) => 0,
        (_, 3) => 1,
        _ => 2,
    }
}

/// One group's table.
struct GroupTex<'p, 'a> {
    group: usize,
    paths: Vec<&'p PathTex<'a>>,
    /// Error columns shown (indices into `Runs::errors`), in the chosen order.
    cols: Vec<usize>,
    status: bool,
}

impl GroupTex<'_, '_> {
    fn lead(&self) -> usize {
        2 + usize::from(self.status)
    }

    fn ncols(&self, opts: &SummaryOptions) -> usize {
        self.lead() + self.cols.len() * if opts.rates { 2 } else { 1 }
    }

    /// Rows as LaTeX counts them for the page: header and body.
    fn rows(&self, opts: &SummaryOptions) -> usize {
        let header = if opts.rates { 2 } else { 1 };
        header
            + self
                .paths
                .iter()
                .map(|p| {
                    let n = p.path.levels.len();
                    1 + n + slope_rows(opts, n) + usize::from(opts.flags)
                })
                .sum::<usize>()
    }
}

/// Write the tables. `display` are the chosen error columns present in the folder (indices
/// into [`Runs::errors`], chosen order); `notes` are sentences about what is not shown; `title`
/// heads the stand-alone document.
pub(crate) fn render(
    runs: &Runs,
    opts: &SummaryOptions,
    display: &[usize],
    paths: &[PathTex],
    notes: &[String],
    title: &str,
) -> Latex {
    let mut groups: Vec<GroupTex> = Vec::new();
    for p in paths {
        let g = p.path.group;
        let gi = match groups.iter().position(|x| x.group == g) {
            Some(i) => i,
            None => {
                groups.push(GroupTex {
                    group: g,
                    paths: Vec::new(),
                    cols: Vec::new(),
                    status: false,
                });
                groups.len() - 1
            }
        };
        let gt = &mut groups[gi];
        gt.paths.push(p);
        gt.status |= p.path.levels.iter().any(|&(_, i)| !runs.runs[i].ok());
    }
    for gt in &mut groups {
        gt.cols = display
            .iter()
            .copied()
            .filter(|e| gt.paths.iter().any(|p| p.fits.iter().any(|(x, _)| x == e)))
            .collect();
    }
    groups.sort_by_key(|g| g.group);
    let long = groups.len() > MAX_FLOATS || groups.iter().any(|g| g.rows(opts) > FLOAT_MAX_ROWS);

    let mut body = String::new();
    for gt in &groups {
        body.push_str(&group_table(runs, opts, gt, long));
        body.push('\n');
    }

    let mut head = String::from(
        "% Convergence tables written by `contact-sweep summarize`: one table per method group,\n\
         % its refinement paths stacked. Every level, error column and statistic is in\n\
         % convergence.parquet / convergence.csv; convergence_doc.tex is this file as a complete\n\
         % document (pdflatex convergence_doc.tex).\n",
    );
    let chosen: Vec<&str> = display.iter().map(|&e| runs.errors[e]).collect();
    let _ = writeln!(
        head,
        "% Error columns: {} ({}); choose with [summary] errors = [...] in the sweep file or\n\
         % `contact-sweep summarize DIR --errors a,b,c`.",
        if chosen.is_empty() {
            "none".to_string()
        } else {
            chosen.join(", ")
        },
        if opts.errors.is_some() {
            "chosen"
        } else {
            "the default"
        }
    );
    if groups.is_empty() {
        head.push_str("% Needs no package: there is no table.\n");
    } else if long {
        let _ = writeln!(
            head,
            "% Needs \\usepackage{{booktabs}} and \\usepackage{{longtable}} ({} group tables{}: longtables, which break across pages; not floats).",
            groups.len(),
            if groups.len() > MAX_FLOATS {
                format!(", more than {MAX_FLOATS}")
            } else {
                format!(", one longer than {FLOAT_MAX_ROWS} rows")
            }
        );
    } else {
        let _ = writeln!(
            head,
            "% Needs \\usepackage{{booktabs}} ({} table floats).",
            groups.len()
        );
    }
    for n in notes {
        let _ = writeln!(head, "% {n}");
    }
    let fragment = format!("{head}\n{body}");

    let mut doc = String::from(
        "% Stand-alone document of the convergence tables (contact-sweep summarize); compile with\n\
         % pdflatex convergence_doc.tex. The tables are those of convergence.tex.\n\
         \\documentclass[10pt]{article}\n\
         \\usepackage[a4paper,landscape,margin=2cm]{geometry}\n\
         \\usepackage{booktabs}\n",
    );
    if long {
        doc.push_str("\\usepackage{longtable}\n");
    }
    doc.push_str("\\begin{document}\n");
    let _ = writeln!(doc, "\\section*{{Convergence: {}}}", table::tex(title));
    let _ = writeln!(
        doc,
        "Error columns: {}{}.",
        if chosen.is_empty() {
            "none".to_string()
        } else {
            chosen
                .iter()
                .map(|c| format!("\\texttt{{{}}}", table::tex(c)))
                .collect::<Vec<_>>()
                .join(", ")
        },
        if opts.errors.is_some() {
            ""
        } else {
            " (the default)"
        }
    );
    for n in notes {
        let _ = writeln!(doc, "\n{}", table::tex(n));
    }
    doc.push('\n');
    doc.push_str(&body);
    doc.push_str("\\end{document}\n");
    Latex {
        fragment,
        document: doc,
    }
}

/// The caption's explanation of the columns, rows and marks.
fn legend(opts: &SummaryOptions, excluded: bool, skipped: bool) -> String {
    let mut s = String::from("Errors per level");
    if opts.rates {
        s.push_str(
            " and observed rates $\\log(e_{i-1}/e_i)/\\log(x_{i-1}/x_i)$ between consecutive \
             usable levels, $x$ the refined $h$ or $\\tau$",
        );
    }
    s.push('.');
    if opts.slopes {
        s.push_str(
            " LSQ slopes of $\\log e$ against $\\log x$ over all usable levels and the finest \
             three (paths of more than two levels).",
        );
    }
    if opts.flags {
        let _ = write!(
            s,
            " Flags: P pre-asymptotic (rates spread by more than ${PRE_ASYMPTOTIC_SPREAD}$), \
             S stagnating (finest-three slope below ${STAGNATION_SLOPE}$), R round-off floor, \
             F failed levels, N fewer than two usable levels."
        );
    }
    if excluded {
        s.push_str(" In parentheses: excluded from rates and fits.");
    }
    if skipped && opts.rates {
        s.push_str(" $^\\dagger$: rate across an excluded level.");
    }
    s
}

/// The booktabs rows of one path: heading, levels, slopes, flags. Returns (rows, excluded
/// values shown, skipped-level rates shown).
fn path_rows(
    runs: &Runs,
    opts: &SummaryOptions,
    gt: &GroupTex,
    p: &PathTex,
) -> (String, bool, bool) {
    let mut out = String::new();
    let (mut excluded, mut skipped) = (false, false);
    let fit_of = |e: usize| p.fits.iter().find(|(x, _)| *x == e).map(|(_, f)| f);
    let _ = writeln!(
        out,
        "    \\multicolumn{{{}}}{{@{{}}l}}{{\\textit{{path {}}}: {}}} \\\\*",
        gt.ncols(opts),
        p.index + 1,
        describe(&p.path.fixed)
    );
    for (li, &(_, ri)) in p.path.levels.iter().enumerate() {
        let r = &runs.runs[ri];
        let mut row = vec![level(r.h), level(r.dt)];
        if gt.status {
            row.push(table::tex(&r.status));
        }
        for &e in &gt.cols {
            let Some(f) = fit_of(e) else {
                row.push(String::new());
                if opts.rates {
                    row.push(String::new());
                }
                continue;
            };
            let lf = &f.levels[li];
            let cells = lf.cells(
                li,
                value(r.errors[e]),
                table::tex_rate(lf.rate),
                &LATEX_MARKS,
            );
            excluded |= cells.excluded;
            row.push(cells.value);
            if opts.rates {
                skipped |= cells.skipped;
                row.push(cells.rate);
            }
        }
        let _ = writeln!(out, "    {} \\\\", row.join(" & "));
    }
    let stat_row = |name: &str, cell: &dyn Fn(&Fit) -> String| -> String {
        let mut row = vec![format!(
            "\\multicolumn{{{}}}{{@{{}}l}}{{{name}}}",
            gt.lead()
        )];
        for &e in &gt.cols {
            let c = fit_of(e).map(cell).unwrap_or_default();
            if opts.rates {
                row.push(String::new());
            }
            row.push(c);
        }
        format!("    {} \\\\\n", row.join(" & "))
    };
    let slopes = slope_rows(opts, p.path.levels.len());
    if slopes > 0 || opts.flags {
        out.push_str("    \\addlinespace[2pt]\n");
    }
    if slopes > 0 {
        out.push_str(&stat_row("LSQ slope, all", &|f| {
            table::tex_rate(f.slope_all)
        }));
    }
    if slopes > 1 {
        out.push_str(&stat_row("LSQ slope, finest 3", &|f| {
            table::tex_rate(f.slope_fine3)
        }));
    }
    if opts.flags {
        let mut row = vec![format!("\\multicolumn{{{}}}{{@{{}}l}}{{flags}}", gt.lead())];
        for &e in &gt.cols {
            let c = fit_of(e).map(flag_letters).unwrap_or_default();
            row.push(if opts.rates {
                format!("\\multicolumn{{2}}{{c}}{{{c}}}")
            } else {
                c
            });
        }
        let _ = writeln!(out, "    {} \\\\", row.join(" & "));
    }
    (out, excluded, skipped)
}

/// One group's table: a float or a longtable.
fn group_table(runs: &Runs, opts: &SummaryOptions, gt: &GroupTex, long: bool) -> String {
    let g = gt.group;
    let ncols = gt.ncols(opts);
    let mut spec = String::from("rr");
    if gt.status {
        spec.push('l');
    }
    for _ in &gt.cols {
        spec.push_str(if opts.rates { "rr" } else { "r" });
    }

    // Header rows.
    let mut header = String::new();
    let lead_cells = {
        let mut c = vec!["$h$".to_string(), "$\\tau$".to_string()];
        if gt.status {
            c.push("status".into());
        }
        c
    };
    if opts.rates {
        let mut top = vec![format!("\\multicolumn{{{}}}{{c}}{{}}", gt.lead())];
        let mut rules = String::new();
        let mut sub = lead_cells.clone();
        for (k, &e) in gt.cols.iter().enumerate() {
            top.push(format!(
                "\\multicolumn{{2}}{{c}}{{{}}}",
                error_head(runs.errors[e])
            ));
            let a = gt.lead() + 2 * k + 1;
            let _ = write!(rules, "\\cmidrule(lr){{{a}-{}}}", a + 1);
            sub.push("error".into());
            sub.push("rate".into());
        }
        let _ = writeln!(header, "    {} \\\\", top.join(" & "));
        let _ = writeln!(header, "    {rules}");
        let _ = writeln!(header, "    {} \\\\", sub.join(" & "));
    } else {
        let mut cells = lead_cells;
        cells.extend(
            gt.cols
                .iter()
                .map(|&e| error_head(runs.errors[e]).to_string()),
        );
        let _ = writeln!(header, "    {} \\\\", cells.join(" & "));
    }

    // Body: the paths, stacked.
    let mut rows = String::new();
    let (mut excluded, mut skipped) = (false, false);
    for (k, p) in gt.paths.iter().enumerate() {
        if k > 0 {
            rows.push_str("    \\midrule\n");
        }
        let (r, ex, sk) = path_rows(runs, opts, gt, p);
        rows.push_str(&r);
        excluded |= ex;
        skipped |= sk;
    }

    // More than five error columns with their rates (12 LaTeX columns and up) need more than
    // `\small` allows on a landscape page: all seven measured 741 pt against 728 pt of text.
    // `\footnotesize` and 4 pt column gaps bring them to ≈ 620 pt, room for a status column.
    let size = if ncols > COMPACT_COLUMNS {
        "\\footnotesize\\setlength{\\tabcolsep}{4pt}"
    } else {
        "\\small"
    };
    let title = table::tex(&runs.groups[g].title);
    let short = format!("Convergence, group {}: {title}", g + 1);
    let caption = format!("{short}. {}", legend(opts, excluded, skipped));
    let label = format!("tab:convergence-group-{}", g + 1);
    let mut out = String::new();
    if long {
        // The caption as wide as a float's (longtable's default is 4 in), in this group only.
        let _ = writeln!(
            out,
            "\\begingroup{size}\\setlength{{\\LTcapwidth}}{{\\linewidth}}"
        );
        let _ = writeln!(out, "\\begin{{longtable}}{{{spec}}}");
        let _ = writeln!(
            out,
            "  \\caption[{short}]{{{caption}}}\\label{{{label}}} \\\\"
        );
        // The head on the first page, then again under a "continued" caption on the others.
        let head = |out: &mut String, end: &str| {
            let _ = writeln!(out, "    \\toprule");
            out.push_str(&header);
            let _ = writeln!(out, "    \\midrule\n  \\{end}");
        };
        head(&mut out, "endfirsthead");
        let _ = writeln!(out, "  \\caption[]{{{short} (continued)}} \\\\");
        head(&mut out, "endhead");
        let _ = writeln!(
            out,
            "    \\midrule\n    \\multicolumn{{{ncols}}}{{r}}{{\\textit{{continued on the next page}}}} \\\\\n  \\endfoot"
        );
        let _ = writeln!(out, "    \\bottomrule\n  \\endlastfoot");
        out.push_str(&rows);
        let _ = writeln!(out, "\\end{{longtable}}\n\\endgroup");
    } else {
        let _ = writeln!(out, "\\begin{{table}}[htbp]\n  \\centering{size}");
        // The standard classes put no space below a caption: a caption above a table needs it.
        let _ = writeln!(
            out,
            "  \\caption[{short}]{{{caption}}}\\label{{{label}}}\\smallskip"
        );
        let _ = writeln!(out, "  \\begin{{tabular}}{{{spec}}}");
        let _ = writeln!(out, "    \\toprule");
        out.push_str(&header);
        let _ = writeln!(out, "    \\midrule");
        out.push_str(&rows);
        let _ = writeln!(out, "    \\bottomrule\n  \\end{{tabular}}\n\\end{{table}}");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refinement_values_print_as_the_papers_write_them() {
        assert_eq!(level_math(0.25), "1/4");
        assert_eq!(level_math(1.0 / 4096.0), "1/4096");
        // τ = ν h / c0 computed in floating point: still 1/256.
        assert_eq!(level_math(0.5 * 0.0078125 / 1.0000000000000002), "1/256");
        assert_eq!(level_math(0.015), "0.015");
        assert_eq!(level_math(1.0), "1");
        assert_eq!(level_math(0.3), "0.3");
        assert_eq!(level_math(0.123456789), "1.235\\cdot10^{-1}");
        assert_eq!(value(Some(0.7243)), "$7.243\\cdot10^{-1}$");
        assert_eq!(value(Some(2.373)), "$2.373$");
        assert_eq!(value(Some(0.0)), "$0$");
        assert_eq!(value(None), "");
    }
}
