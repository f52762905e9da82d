//! `contact-sweep report DIR`: one self-contained HTML file to send a colleague — no network,
//! no Python, no script: inline CSS and inline SVG figures ([`figures`], drawn with plotters).
//!
//! Everything in it comes from the computations of [`crate::summary`] (the same groups,
//! refinement paths, fits, flags, energy behaviour and Pareto fronts as `DIR/summary/`), so the
//! report and the tables can never disagree:
//!
//! 1. the sweep (name, description, what ran, the "what to look at" hints);
//! 2. figures: convergence of every displayed error column with slope triangles (the group's
//!    main refinement path and its least-squares slope), work-precision with the Pareto front,
//!    contact displacement / pressure / energy against time with the exact solution;
//! 3. the method table (one line per group with its rates, as on the terminal, with its legend),
//!    the method classes and, for a folder with patch-test runs, the contact patch test;
//! 4. the energy behaviour, the stability map when the sweep has one, the convergence and
//!    work-precision tables (the summary's Markdown, rendered);
//! 5. the sweep file as run (with its `--set` overrides) and its plan.
//!
//! The files import one way (mod.rs calls into them, none calls back): `text` (sections 1, 3–5) and `plots` (the
//! figure sections of 2) write into a `html::Page`; `plots` reads the time series (`series`)
//! and draws with [`figures`], which takes each method group's colour and marker from `style`
//! and its log axes' ticks from `ticks`; `session` reads the manifest.

pub mod figures;
mod html;
mod plots;
mod series;
mod session;
mod style;
mod text;
mod ticks;

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use crate::summary::Sections;
use html::{CSS, Page, esc};
use session::session;

/// What `report` wrote.
#[derive(Debug, Clone)]
pub struct Report {
    pub path: PathBuf,
    pub bytes: usize,
    /// Figures drawn (inline SVG elements).
    pub figures: usize,
    /// Figures that could not be drawn, with the reason (shown in the report too).
    pub skipped: Vec<String>,
}

/// Write the report of DIR to `out` (default `DIR/report.html`).
///
/// Errors: DIR without runs (the message names it), an unreadable manifest, an I/O failure.
/// A figure that cannot be drawn (no positive errors, no series) is noted in the report, not an
/// error.
pub fn write(dir: &Path, out: Option<&Path>) -> anyhow::Result<Report> {
    let opts = crate::summary::stored_options(dir)?;
    let sections = Sections::compute(dir, &opts)?;
    write_with(dir, out, &sections)
}

/// [`write`] from sections already computed (`contact-sweep run` computes them once for the
/// tables and the report).
pub(crate) fn write_with(
    dir: &Path,
    out: Option<&Path>,
    sections: &Sections,
) -> anyhow::Result<Report> {
    let html = render(dir, sections)?;
    let path = out
        .map(Path::to_path_buf)
        .unwrap_or_else(|| dir.join("report.html"));
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("{}: cannot create", parent.display()))?;
    }
    crate::sink::write_derived(&path, html.text.as_bytes())?;
    Ok(Report {
        path,
        bytes: html.text.len(),
        figures: html.figures,
        skipped: html.skipped,
    })
}

/// The report's text, with what [`Report`] says of its figures.
struct Html {
    text: String,
    figures: usize,
    skipped: Vec<String>,
}

/// The report's HTML: its sections in the order of the module's header.
fn render(dir: &Path, sections: &Sections) -> anyhow::Result<Html> {
    let ses = session(dir)?;
    let name = ses.sweep.clone().unwrap_or_else(|| sections.title.clone());
    let mut page = Page::default();
    // 1. The sweep.
    text::sweep(&mut page.body, dir, &ses, &name, sections);
    // 2. The figures.
    plots::convergence(&mut page, sections);
    plots::work_precision(&mut page, sections);
    plots::time_series(&mut page, dir, sections)?;
    // 3. The method table and classes.
    text::methods(&mut page.body, sections);
    text::patch(&mut page.body, sections);
    // 4. Energy and the full tables.
    text::tables(&mut page.body, sections);
    // 5. The sweep file and the plan.
    text::sweep_file(&mut page.body, &ses);
    let Page {
        mut body,
        figures,
        skipped,
    } = page;
    text::not_drawn(&mut body, &skipped);
    let text = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>contact-sweep report: {}</title><style>{CSS}</style></head>\n<body>\n{body}</body></html>\n",
        esc(&name)
    );
    Ok(Html {
        text,
        figures,
        skipped,
    })
}
