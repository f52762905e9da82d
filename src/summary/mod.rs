//! Summaries of a results folder: `contact-sweep summarize DIR` turns `DIR/runs` into the
//! tables of a paper under `DIR/summary/` (contract §8, issue 4). The impacts come from the runs'
//! own contact-phase lists; `DIR/series` is read only for rows of older versions without them.
//!
//! # Groups and refinement paths
//! Runs are grouped by every parameter column except the refinement axes (h/elements,
//! dt/courant) and the ensemble sample index (the members of a round-off ensemble are one
//! method; [`ensemble`] summarises their spread, and a refinement path takes the ok member of
//! lowest index per level); `label` is derived from the parameters and carried, not grouped by. Columns
//! this version does not know are ignored. Inside a group a *refinement path* holds one axis
//! fixed — the Courant number (h refined, τ ∝ h), dt (h refined) or h (dt refined) — and needs
//! ≥ 2 distinct levels; levels are ordered coarse → fine by the refined value x (h or dt).
//!
//! # Observed rates
//! For consecutive usable levels (x_i, e_i), (x_j, e_j) of a path (j the next usable level
//! after i, so a failed level in between is spanned),
//!
//! ```text
//!     p_ij = log(e_i / e_j) / log(x_i / x_j)
//! ```
//!
//! from the *actual* ratio x_i/x_j — never log 2: ladders like h = 1/4, 1/12, 1/24 have ratios
//! 3 and 2, and a halving assumption would misreport the first rate by a factor log 3/log 2.
//! If e ≈ C x^p, every p_ij equals p.
//!
//! # Least-squares slopes
//! The slope p of the straight line log e = log C + p log x fitted to all usable levels,
//!
//! ```text
//!     p = Σ (ξ_k − ξ̄)(η_k − η̄) / Σ (ξ_k − ξ̄)²,   ξ = log x, η = log e,
//! ```
//!
//! and the same over the finest (up to) three usable levels. A pair rate hangs on two errors
//! and is noisy; the fit over all levels summarises the ladder, the fit over the finest three
//! is the best estimate of the *asymptotic* order (coarse levels may be pre-asymptotic).
//!
//! # Flags (thresholds in [`convergence`])
//! - pre-asymptotic: the pair rates spread (max − min) by more than 0.3;
//! - stagnating: the finest-three slope is below 0.1 (includes errors growing, slope < 0);
//! - round-off floor: the finest usable error is ≤ 1e-12 × the coarsest, or below 1e-13
//!   absolutely, or an ok level has error exactly 0 — refinement then measures rounding;
//! - failed levels: status ≠ ok. Such levels stay in the tables, marked, and are excluded from
//!   rates and fits (as are ok levels without a finite positive error), because a diverged
//!   run's "error" is where it stopped, not a discretisation error.
//!
//! # Energy, speed against error
//! See [`energy`] (drift, the energy class of each run judged by its scheme's functional,
//! energy lost per impact from the runs' contact phases), [`ensemble`] (round-off spread) and [`work`] (Pareto front in (error, wall time) and (error,
//! steps × dofs); cost to reach ε by log-log interpolation between consecutive levels, the
//! same power-law model as the rates).
//!
//! # Files (all written atomically: temporary dot-file, fsync, rename)
//! `convergence.{parquet,csv,md,tex}`, `convergence_doc.tex` (the LaTeX tables as a complete
//! document, see [`latex`]), `energy.{parquet,csv,md}`, `energy_groups.{parquet,csv}`,
//! `impacts.{parquet,csv}`, `ensemble.{parquet,csv,md}`, `stability_map.{parquet,csv,md}`
//! ([`stability`]: per method and pair of swept axes, the state of every cell),
//! `search.{parquet,csv,md}` (the boundaries of a `[search]`),
//! `work_precision.{parquet,csv,md}`, `cost_to_error.{parquet,csv}`, and where the folder has
//! runs of the contact patch test, `patch_test.{parquet,csv,md}` ([`patch`]).

use std::path::{Path, PathBuf};

use anyhow::Context as _;

mod columns;
pub mod convergence;
pub mod energy;
pub mod ensemble;
mod latex;
pub mod methods;
pub mod patch;
/// The column choice of the text tables: plain data, one layer down ([`crate::model`]) so the
/// planner can parse it without importing the summaries.
pub use crate::model::summary_options as options;
mod rates;
pub(crate) mod runs;
mod search;
pub mod stability;
pub(crate) mod table;
pub mod work;

pub use convergence::{NO_REFINEMENT, lsq_slope, observed_rate};
pub use options::{DEFAULT_ERRORS, ERROR_COLUMNS, SummaryOptions, parse_errors};
pub use table::eng;
pub use work::{loglog_cost, pareto_front};

/// What `summarize` produced.
#[derive(Debug, Clone)]
pub struct Summary {
    /// The compact report for the terminal.
    pub terminal: String,
    /// `DIR/summary`.
    pub dir: PathBuf,
    /// Every file written, in order.
    pub files: Vec<PathBuf>,
    /// Runs read (after dropping duplicate run ids).
    pub runs: usize,
    /// Method groups (runs equal in every parameter except the refinement axes).
    pub groups: usize,
    /// Refinement paths found (0: no refinement axis).
    pub refinement_paths: usize,
    /// Columns of `DIR/runs` this version does not know (ignored).
    pub ignored_columns: Vec<String>,
    /// Parts that could not be read and were skipped ([`crate::sink::Damaged::warning`]).
    pub warnings: Vec<String>,
}

/// The column choice stored with DIR: the `[summary]` table of the sweep file of DIR's latest
/// session (its text is in `DIR/manifest.json`); the default for a folder without one.
///
/// Errors: an unreadable manifest, or a `[summary]` table this version refuses (a
/// [`crate::sweep::SweepError`] naming the manifest, the key and the line in the stored text).
pub fn stored_options(dir: &Path) -> anyhow::Result<SummaryOptions> {
    let stored = match crate::sink::Manifest::latest_sweep(dir) {
        Ok(t) => t,
        // A damaged manifest does not stop the summary: the default columns, and a warning.
        Err(e @ crate::sink::SinkError::Manifest { .. }) => {
            eprintln!("warning: {e}; the summary uses the default columns");
            None
        }
        Err(e) => return Err(e.into()),
    };
    match stored {
        None => Ok(SummaryOptions::default()),
        Some((text, sets)) => {
            let name = PathBuf::from(format!(
                "{} (the sweep file stored in it)",
                dir.join("manifest.json").display()
            ));
            Ok(crate::sweep::summary_options(&name, &text, &sets)?)
        }
    }
}

/// Summarize DIR with the column choice stored with it ([`stored_options`]).
pub fn summarize(dir: &Path) -> anyhow::Result<Summary> {
    let opts = stored_options(dir)?;
    summarize_with(dir, &opts)
}

/// Summarize DIR: read `DIR/runs` (and `DIR/series` for rows without online contact phases),
/// write the tables under `DIR/summary/`; `opts` chooses the error columns of the Markdown and
/// LaTeX tables.
///
/// Errors: DIR missing or without runs (the message names the folder), or an I/O failure.
/// A folder without a refinement axis is not an error: the convergence section says so.
pub fn summarize_with(dir: &Path, opts: &SummaryOptions) -> anyhow::Result<Summary> {
    let sections = Sections::compute(dir, opts)?;
    sections.write(dir)
}

/// One file (or table: Parquet + CSV) of `DIR/summary/`.
enum Output<'a> {
    Table(&'static str, &'a table::Table),
    Text(&'static str, &'a str),
}

impl Output<'_> {
    fn write(self, out: &Path) -> anyhow::Result<Vec<PathBuf>> {
        match self {
            Output::Table(stem, t) => table::write_table(out, stem, t),
            Output::Text(name, body) => Ok(vec![table::write_text(out, name, body)?]),
        }
    }
}

/// Every section of a folder's summary, computed once: [`Sections::write`] writes the tables,
/// and the report draws from the same values (`contact-sweep run` computes them once for
/// both, issue 12).
pub(crate) struct Sections {
    pub(crate) runs: runs::Runs,
    pub(crate) title: String,
    pub(crate) conv: convergence::Section,
    pub(crate) en: energy::Section,
    pub(crate) ens: ensemble::Section,
    pub(crate) st: stability::Section,
    pub(crate) se: search::Section,
    pub(crate) wp: work::Section,
    pub(crate) methods: methods::Section,
    pub(crate) patch: patch::Section,
    pub(crate) warnings: Vec<String>,
}

impl Sections {
    /// Read DIR and compute every section (nothing is written).
    pub(crate) fn compute(dir: &Path, opts: &SummaryOptions) -> anyhow::Result<Sections> {
        let runs = runs::load(dir)?;
        // Unreadable parts are skipped by the readers; say which. The runs parts the loader
        // read are readable: only the others are read again, for the reason (reading them all
        // twice was a third of the sections' time on issue 12's 400-run sweep).
        let read: std::collections::HashSet<String> =
            runs.runs.iter().filter_map(|r| r.part.clone()).collect();
        let warnings: Vec<String> = crate::sink::unreadable_parts_except(dir, &read)?
            .iter()
            .map(|d| d.warning())
            .collect();
        // The folder's name heads the stand-alone LaTeX document.
        let title = dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| dir.display().to_string());
        // Two independent halves on two threads (each section only reads the runs).
        let (conv, rest) = std::thread::scope(|scope| {
            let rest = scope.spawn(|| {
                (
                    energy::section(dir, &runs),
                    ensemble::section(&runs),
                    stability::section(&runs),
                    search::section(&runs),
                    work::section(&runs),
                )
            });
            let conv = convergence::section(&runs, opts, &title);
            (conv, rest.join())
        });
        let (en, ens, st, se, wp) =
            rest.map_err(|_| anyhow::anyhow!("a summary section panicked"))?;
        let en = en?;
        let methods = methods::section(&runs);
        let patch = patch::section(&runs);
        Ok(Sections {
            runs,
            title,
            conv,
            en,
            ens,
            st,
            se,
            wp,
            methods,
            patch,
            warnings,
        })
    }

    /// Write the tables under `DIR/summary/` and compose the terminal report.
    pub(crate) fn write(&self, dir: &Path) -> anyhow::Result<Summary> {
        let (runs, conv, en, ens) = (&self.runs, &self.conv, &self.en, &self.ens);
        let (st, se, wp, methods) = (&self.st, &self.se, &self.wp, &self.methods);
        let out = dir.join("summary");
        std::fs::create_dir_all(&out)
            .with_context(|| format!("{}: cannot create", out.display()))?;
        // The tables are encoded concurrently (one scoped thread each; Parquet and CSV
        // encoding is CPU-bound and the sweep's workers are done by now), the files listed in
        // a fixed order whatever finishes first.
        let mut jobs = vec![
            Output::Table("convergence", &conv.table),
            Output::Text("convergence.md", &conv.markdown),
            Output::Text("convergence.tex", &conv.latex),
            Output::Text("convergence_doc.tex", &conv.latex_doc),
            Output::Table("energy", &en.runs),
            Output::Table("energy_groups", &en.groups),
            Output::Table("impacts", &en.impacts),
            Output::Text("energy.md", &en.markdown),
            Output::Table("ensemble", &ens.table),
            Output::Text("ensemble.md", &ens.markdown),
            Output::Table("stability_map", &st.table),
            Output::Text("stability_map.md", &st.markdown),
            Output::Table("search", &se.table),
            Output::Text("search.md", &se.markdown),
            Output::Table("work_precision", &wp.table),
            Output::Table("cost_to_error", &wp.cost),
            Output::Text("work_precision.md", &wp.markdown),
            Output::Table("methods", &methods.table),
            Output::Text("methods.md", &methods.markdown),
            Output::Text("methods.tex", &methods.latex),
        ];
        // The patch-test table only where the folder has patch-test runs: the other folders'
        // summaries keep their files.
        let patch = &self.patch;
        if !patch.is_empty() {
            jobs.push(Output::Table("patch_test", &patch.table));
            jobs.push(Output::Text("patch_test.md", &patch.markdown));
        }
        let out_dir: &Path = &out;
        let results: Vec<anyhow::Result<Vec<PathBuf>>> = std::thread::scope(|scope| {
            let handles: Vec<_> = jobs
                .into_iter()
                .map(|job| scope.spawn(move || job.write(out_dir)))
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err(anyhow::anyhow!("a table writer panicked")))
                })
                .collect()
        });
        let mut files = Vec::new();
        for r in results {
            files.extend(r?);
        }

        let mut terminal = format!(
            "{} runs ({} ok) in {} groups from {}\n",
            runs.runs.len(),
            runs.runs.iter().filter(|r| r.ok()).count(),
            runs.groups.len(),
            dir.display()
        );
        if runs.duplicates > 0 {
            terminal.push_str(&format!(
                "  ({} duplicate rows of the same run_id dropped)\n",
                runs.duplicates
            ));
        }
        if !runs.ignored.is_empty() {
            terminal.push_str(&format!(
                "  (columns not known to this version, ignored: {})\n",
                runs.ignored.join(", ")
            ));
        }
        if runs.status_assumed {
            terminal.push_str("  (no status column: every run counted as ok)\n");
        }
        terminal.push_str(&conv.terminal);
        terminal.push_str(&en.terminal);
        terminal.push_str(&methods.terminal);
        terminal.push_str(&patch.terminal);
        terminal.push_str(&ens.terminal);
        terminal.push_str(&st.terminal);
        terminal.push_str(&se.terminal);
        terminal.push_str(&wp.terminal);
        terminal.push_str(&format!(
            "tables: {} (convergence, energy, impacts, ensemble, stability_map, search, work_precision, cost_to_error, methods{} as .parquet/.csv; .md; convergence.tex, convergence_doc.tex, methods.tex)\n",
            out.display(),
            if patch.is_empty() { "" } else { ", patch_test" }
        ));
        if !conv.groups.hints.is_empty() {
            terminal.push_str("look at:\n");
            for h in &conv.groups.hints {
                terminal.push_str(&format!("  - {h}\n"));
            }
        }
        Ok(Summary {
            terminal,
            dir: out,
            files,
            runs: runs.runs.len(),
            groups: runs.groups.len(),
            refinement_paths: runs.paths.len(),
            ignored_columns: runs.ignored.clone(),
            warnings: self.warnings.clone(),
        })
    }
}
