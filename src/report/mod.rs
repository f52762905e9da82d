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
//! 3. the method table (one line per group with its rates, as on the terminal, with its legend);
//! 4. the energy behaviour, the stability map when the sweep has one, the convergence and
//!    work-precision tables (the summary's Markdown, rendered);
//! 5. the sweep file as run (with its `--set` overrides) and its plan.

pub mod figures;

use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context as _;

use crate::summary::Sections;
use crate::summary::convergence::lsq_slope;
use crate::summary::runs::{self, Runs};
use crate::summary::table as stable;
use figures::Curve;

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

/// Groups drawn in the time-series figures (one run each; more would be unreadable).
const SERIES_GROUPS: usize = 8;

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

struct Html {
    text: String,
    figures: usize,
    skipped: Vec<String>,
}

/// The manifest's facts about the latest session (absent fields: None).
#[derive(Default)]
struct Session {
    sweep: Option<String>,
    scene: Option<String>,
    file: Option<String>,
    text: Option<String>,
    sets: Vec<String>,
    version: Option<String>,
    commit: Option<String>,
    finished: Option<String>,
}

fn session(dir: &Path) -> anyhow::Result<Session> {
    let path = dir.join("manifest.json");
    if !path.exists() {
        return Ok(Session::default());
    }
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a manifest (invalid JSON)", path.display()))?;
    let s = |v: &serde_json::Value| v.as_str().map(String::from);
    let last = doc["sessions"]
        .as_array()
        .and_then(|a| a.iter().rev().find(|x| x["sweep_text"].is_string()))
        .cloned()
        .unwrap_or_default();
    Ok(Session {
        sweep: s(&doc["sweep"]),
        scene: s(&doc["scene"]),
        file: s(&last["sweep_file"]),
        text: s(&last["sweep_text"]),
        sets: last["overrides"]
            .as_array()
            .map(|a| a.iter().filter_map(s).collect())
            .unwrap_or_default(),
        version: s(&last["version"]),
        commit: s(&last["git_commit"]),
        finished: s(&last["finished"]),
    })
}

/// HTML-escape text.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            c => o.push(c),
        }
    }
    o
}

/// Inline Markdown of the summary's text: `code` spans, **bold**.
fn inline(s: &str) -> String {
    let e = esc(s);
    let mut out = String::new();
    for (i, part) in e.split('`').enumerate() {
        if i % 2 == 1 {
            let _ = write!(out, "<code>{part}</code>");
        } else {
            for (j, b) in part.split("**").enumerate() {
                if j % 2 == 1 {
                    let _ = write!(out, "<b>{b}</b>");
                } else {
                    out.push_str(b);
                }
            }
        }
    }
    out
}

/// The summary's Markdown (headings, paragraphs, lists, GitHub tables) as HTML; heading
/// levels are shifted by `shift` so that the files' `#` sit under the report's sections.
fn markdown(md: &str, shift: usize) -> String {
    let mut out = String::new();
    let lines: Vec<&str> = md.lines().collect();
    let mut i = 0;
    let cells = |l: &str| -> Vec<String> {
        let t = l.trim().trim_start_matches('|').trim_end_matches('|');
        // split at | not preceded by a backslash
        let mut v = Vec::new();
        let mut cur = String::new();
        let mut prev = ' ';
        for c in t.chars() {
            if c == '|' && prev != '\\' {
                v.push(cur.trim().replace("\\|", "|"));
                cur.clear();
            } else {
                cur.push(c);
            }
            prev = c;
        }
        v.push(cur.trim().replace("\\|", "|"));
        v
    };
    while i < lines.len() {
        let l = lines[i];
        if l.trim().is_empty() {
            i += 1;
        } else if l.starts_with('#') {
            let level = l.chars().take_while(|&c| c == '#').count();
            let h = (level + shift).min(6);
            let _ = writeln!(out, "<h{h}>{}</h{h}>", inline(l[level..].trim()));
            i += 1;
        } else if l.starts_with('|') {
            let header = cells(l);
            let right: Vec<bool> = lines
                .get(i + 1)
                .map(|a| {
                    cells(a)
                        .iter()
                        .map(|c| c.ends_with(':') && !c.starts_with(':'))
                        .collect()
                })
                .unwrap_or_default();
            out.push_str("<table><thead><tr>");
            for h in &header {
                let _ = write!(out, "<th>{}</th>", inline(h));
            }
            out.push_str("</tr></thead><tbody>\n");
            i += 2;
            while i < lines.len() && lines[i].starts_with('|') {
                out.push_str("<tr>");
                for (k, c) in cells(lines[i]).iter().enumerate() {
                    let cls = if right.get(k).copied().unwrap_or(false) {
                        " class=\"r\""
                    } else {
                        ""
                    };
                    let _ = write!(out, "<td{cls}>{}</td>", inline(c));
                }
                out.push_str("</tr>\n");
                i += 1;
            }
            out.push_str("</tbody></table>\n");
        } else if l.starts_with("- ") {
            out.push_str("<ul>");
            while i < lines.len() && lines[i].starts_with("- ") {
                let _ = write!(out, "<li>{}</li>", inline(&lines[i][2..]));
                i += 1;
            }
            out.push_str("</ul>\n");
        } else {
            let mut p = Vec::new();
            while i < lines.len()
                && !lines[i].trim().is_empty()
                && !lines[i].starts_with('#')
                && !lines[i].starts_with('|')
                && !lines[i].starts_with("- ")
            {
                p.push(lines[i]);
                i += 1;
            }
            let _ = writeln!(out, "<p>{}</p>", inline(&p.join(" ")));
        }
    }
    out
}

/// An HTML table from rows of text; `right[k]`: column k right-aligned.
fn html_table(header: &[String], right: &[bool], rows: &[Vec<String>]) -> String {
    let mut out = String::from("<table><thead><tr>");
    for h in header {
        let _ = write!(out, "<th>{}</th>", esc(h));
    }
    out.push_str("</tr></thead><tbody>\n");
    for r in rows {
        out.push_str("<tr>");
        for (k, c) in r.iter().enumerate() {
            let cls = if right.get(k).copied().unwrap_or(false) {
                " class=\"r\""
            } else {
                ""
            };
            let _ = write!(out, "<td{cls}>{}</td>", esc(c));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table>\n");
    out
}

/// The colour legend of the method groups, shared by every figure (a group has one colour).
fn legend(runs: &Runs, groups: &[usize], note: &str) -> String {
    let mut out = String::from("<div class=\"legend\">");
    for &g in groups {
        let c = figures::color(g);
        let _ = write!(
            out,
            "<span><i style=\"background:rgb({},{},{})\"></i>{} {}</span>",
            c.0,
            c.1,
            c.2,
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

/// One time series of a run: (t, u_C), (t, σ_C), (t, E), exact (t, u_C), (t, σ_C).
#[derive(Default)]
struct RunSeries {
    u: Vec<(f64, f64)>,
    sigma: Vec<(f64, f64)>,
    energy: Vec<(f64, f64)>,
    u_exact: Vec<(f64, f64)>,
    sigma_exact: Vec<(f64, f64)>,
    /// Frictional runs (null columns otherwise): (t, E, W_f) where both are recorded, and
    /// (t, v_t) the contact node's slip velocity.
    balance: Vec<(f64, f64, f64)>,
    v_t: Vec<(f64, f64)>,
}

/// The series of the runs `chosen`, in time order. Only the series parts that hold them are
/// read (the sink names a batch's series part like its runs part, which `runs::load` records
/// per run); of a part, first its `run_id` column (dictionary-encoded: a few bytes a run), then
/// only the rows of the chosen runs and only the columns drawn, the page index skipping the
/// pages of the other runs (`sink::parquet::read_rows_f64`).
fn read_series(dir: &Path, chosen: &[&runs::Run]) -> anyhow::Result<HashMap<String, RunSeries>> {
    use crate::sink::parquet as pq;
    let mut out: HashMap<String, RunSeries> = HashMap::new();
    let folder = dir.join("series");
    if !folder.exists() || chosen.is_empty() {
        return Ok(out);
    }
    // A run without its part's name (not known to the loader) means: read every part.
    let parts: Option<HashSet<String>> = chosen.iter().map(|r| r.part.clone()).collect();
    let wanted: HashSet<&str> = chosen.iter().map(|r| r.run_id.as_str()).collect();
    // The friction columns are absent from frictionless parts: read as nulls, nothing drawn.
    const DRAWN: [&str; 8] = [
        "t",
        "u_contact",
        "sigma_contact",
        "energy",
        "u_contact_exact",
        "sigma_contact_exact",
        "friction_work",
        "v_t_contact",
    ];
    for part in crate::sink::parquet_parts(&folder)? {
        let name = part
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if parts.as_ref().is_some_and(|p| !p.contains(&name)) {
            continue;
        }
        // An unreadable part is skipped: `summarize` warns about it (sink::unreadable_parts).
        let Ok(ranges) = pq::run_ranges(&part, &wanted) else {
            continue;
        };
        if ranges.is_empty() {
            continue;
        }
        let rows: Vec<_> = ranges.iter().map(|(_, r)| r.clone()).collect();
        let Ok(cols) = pq::read_rows_f64(&part, &rows, &DRAWN) else {
            continue;
        };
        let [t, u, s, en, ue, se, wf, vt] = &cols[..] else {
            unreachable!("one vector per drawn column")
        };
        let mut k = 0;
        for (id, r) in ranges {
            let rs = out.entry(id).or_default();
            for _ in r {
                if let Some(t) = t[k] {
                    let push = |v: &mut Vec<(f64, f64)>, y: Option<f64>| {
                        if let Some(y) = y.filter(|y| y.is_finite()) {
                            v.push((t, y));
                        }
                    };
                    push(&mut rs.u, u[k]);
                    push(&mut rs.sigma, s[k]);
                    push(&mut rs.energy, en[k]);
                    push(&mut rs.u_exact, ue[k]);
                    push(&mut rs.sigma_exact, se[k]);
                    push(&mut rs.v_t, vt[k]);
                    if let (Some(e), Some(w)) = (en[k], wf[k])
                        && e.is_finite()
                        && w.is_finite()
                    {
                        rs.balance.push((t, e, w));
                    }
                }
                k += 1;
            }
        }
    }
    // A run's rows are in step order within its part; a run resumed across sessions is not
    // split, but sorting keeps the figures right whatever the order.
    for rs in out.values_mut() {
        for v in [
            &mut rs.u,
            &mut rs.sigma,
            &mut rs.energy,
            &mut rs.u_exact,
            &mut rs.sigma_exact,
            &mut rs.v_t,
        ] {
            if !v.is_sorted_by(|a, b| a.0 <= b.0) {
                v.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
        }
        if !rs.balance.is_sorted_by(|a, b| a.0 <= b.0) {
            rs.balance.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
    }
    Ok(out)
}

/// The frictional runs' figures (only when some chosen run has a friction law and recorded its
/// work): E, W_f and E + W_f against t in one panel — E + W_f flat while E falls is a scheme
/// that lost only the friction's work, the class the energy table calls "dissipative with
/// friction accounted" — and the slip velocity v_t of the contact node.
fn frictional_figures(
    runs: &Runs,
    chosen: &[(usize, usize)],
    series: &HashMap<String, RunSeries>,
    body: &mut String,
    count: &mut usize,
    skipped: &mut Vec<String>,
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
                    color: g,
                });
            }
            drawn = true;
        }
        if !rs.v_t.is_empty() {
            slip.push(Curve {
                name: name.clone(),
                points: figures::decimate(&rs.v_t, 1500),
                color: g,
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
        match fig {
            Ok(svg) => {
                body.push_str(&svg);
                *count += 1;
            }
            Err(x) => skipped.push(x.to_string()),
        }
    }
    body.push_str("</div>\n");
}

const CSS: &str = "body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;margin:0 auto;max-width:1560px;padding:16px 24px;color:#222;line-height:1.4}
h1{font-size:1.6em;margin:.2em 0}h2{border-bottom:1px solid #ccc;margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0;font-size:.86em}th,td{border:1px solid #ddd;padding:2px 6px;text-align:left}
th{background:#f3f3f3}td.r{text-align:right;font-variant-numeric:tabular-nums}
.figs{display:grid;grid-template-columns:repeat(auto-fill,minmax(600px,1fr));gap:12px}
.figs svg,.fig svg{max-width:100%;height:auto;border:1px solid #eee}
pre{background:#f7f7f7;padding:8px;overflow-x:auto;font-size:.85em}
.hints{background:#fff8e1;border-left:4px solid #e6a700;padding:6px 12px}
.note{color:#666;font-size:.9em}details{margin:.6em 0}summary{cursor:pointer;font-weight:600}
nav a{margin-right:1em}
.legend{display:flex;flex-wrap:wrap;gap:4px 18px;font-size:.85em;margin:.4em 0}.legend i{display:inline-block;width:22px;height:4px;margin:0 6px 3px 0;vertical-align:middle}";

fn render(dir: &Path, sections: &Sections) -> anyhow::Result<Html> {
    let Sections {
        runs,
        title,
        conv,
        en,
        wp,
        st,
        methods,
        ..
    } = sections;
    let ses = session(dir)?;
    let name = ses.sweep.clone().unwrap_or_else(|| title.clone());
    let mut figures = 0usize;
    let mut skipped: Vec<String> = Vec::new();
    let mut body = String::new();

    // 1. The sweep.
    let ok = runs.runs.iter().filter(|r| r.ok()).count();
    let _ = writeln!(body, "<h1>Sweep <code>{}</code></h1>", esc(&name));
    let description = ses.text.as_deref().and_then(|t| {
        crate::sweep::tree::parse(t).ok().and_then(|top| {
            top.into_iter()
                .find_map(|(k, _, n)| match (k.as_str(), n.kind) {
                    ("description", crate::sweep::tree::Kind::Str(s)) => Some(s),
                    _ => None,
                })
        })
    });
    if let Some(d) = description {
        let _ = writeln!(body, "<p>{}</p>", esc(&d));
    }
    let _ = writeln!(
        body,
        "<p>{} runs ({ok} ok) in {} method groups{}, from <code>{}</code>; contact-sweep {}{}{}.</p>",
        runs.runs.len(),
        runs.groups.len(),
        ses.scene
            .as_deref()
            .map(|s| format!(", scene {}", esc(s)))
            .unwrap_or_default(),
        esc(&dir.display().to_string()),
        esc(ses.version.as_deref().unwrap_or(env!("CARGO_PKG_VERSION"))),
        ses.commit
            .as_deref()
            .map(|c| format!(" ({})", esc(&c[..c.len().min(12)])))
            .unwrap_or_default(),
        ses.finished
            .as_deref()
            .map(|f| format!(", finished {}", esc(f)))
            .unwrap_or_default(),
    );
    body.push_str("<nav><a href=\"#convergence\">convergence</a><a href=\"#work\">work-precision</a><a href=\"#series\">time series</a><a href=\"#methods\">method table</a><a href=\"#classes\">method classes</a><a href=\"#energy\">energy</a><a href=\"#tables\">all tables</a><a href=\"#sweep\">sweep file and plan</a></nav>\n");
    if !conv.groups.hints.is_empty() {
        body.push_str("<div class=\"hints\"><b>What to look at</b><ul>");
        for h in &conv.groups.hints {
            let _ = write!(body, "<li>{}</li>", esc(h));
        }
        body.push_str("</ul></div>\n");
    }

    // 2a. Convergence figures: every displayed column, every group's main path.
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
    } else {
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
                    color: g,
                });
            }
            let t = format!("{abbr}: {what}");
            match figures::convergence(&t, refined, runs.errors[e], &curves, &slopes) {
                Ok(svg) => {
                    body.push_str(&svg);
                    figures += 1;
                }
                Err(x) => skipped.push(x.to_string()),
            }
        }
        body.push_str("</div>\n");
    }

    // 2b. Work-precision: the first displayed column against wall time.
    body.push_str("<h2 id=\"work\">Work-precision</h2>\n");
    match conv.display.first() {
        None => body.push_str("<p class=\"note\">No error column: nothing to plot.</p>\n"),
        Some(&e) => {
            let mut groups: Vec<Curve> = runs
                .groups
                .iter()
                .enumerate()
                .map(|(k, g)| Curve {
                    name: g.title.clone(),
                    points: Vec::new(),
                    color: k,
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
            match figures::work_precision(&t, runs.errors[e], &groups, &front) {
                Ok(svg) => {
                    let _ = writeln!(body, "<div class=\"fig\">{svg}</div>");
                    figures += 1;
                }
                Err(x) => skipped.push(x.to_string()),
            }
        }
    }

    // 2c. Time series: one run per group, the finest ok level of its main path.
    body.push_str(
        "<h2 id=\"series\">Contact displacement, pressure and energy against time</h2>\n",
    );
    let chosen: Vec<(usize, usize)> = runs
        .groups
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
        .take(SERIES_GROUPS)
        .collect();
    let picked: Vec<&runs::Run> = chosen.iter().map(|&(_, i)| &runs.runs[i]).collect();
    let series = read_series(dir, &picked)?;
    if series.is_empty() {
        body.push_str("<p class=\"note\">No time series in <code>series/</code> (series_every = 0?): nothing to plot.</p>\n");
    } else {
        let _ = writeln!(
            body,
            "<p class=\"note\">One run per method group: the finest ok level of its main refinement path{}. Black dashes: the exact solution (closed form; for 2D/3D scenes the reference run). Energy in units of the run's <code>energy_scale</code> (E⁰ for the bars, so E/E⁰; m·g·gap under gravity, where E⁰ = 0).</p>",
            if runs.groups.len() > SERIES_GROUPS {
                format!(
                    " (the first {SERIES_GROUPS} groups of {})",
                    runs.groups.len()
                )
            } else {
                String::new()
            }
        );
        let mut u = Vec::new();
        let mut s = Vec::new();
        let mut en = Vec::new();
        let mut exact_u: Option<Curve> = None;
        let mut exact_s: Option<Curve> = None;
        for &(g, i) in &chosen {
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
            u.push(Curve {
                name: name.clone(),
                points: figures::decimate(&rs.u, 1500),
                color: g,
            });
            s.push(Curve {
                name: name.clone(),
                points: figures::decimate(&rs.sigma, 1500),
                color: g,
            });
            // In units of the run's energy_scale, the unit of its `energy_drift` (E⁰ for the
            // bars: the curve E/E⁰; m·g·gap under gravity, where E⁰ = 0). Older folders without
            // the column: E⁰ when it is not zero.
            let scale = r
                .energy_scale
                .or_else(|| rs.energy.first().map(|p| p.1).filter(|e| *e != 0.0));
            if let Some(scale) = scale {
                let rel: Vec<(f64, f64)> = rs.energy.iter().map(|&(t, e)| (t, e / scale)).collect();
                en.push(Curve {
                    name,
                    points: figures::decimate(&rel, 1500),
                    color: g,
                });
            }
            // The exact solution of the longest run (the finest time resolution).
            if rs.u_exact.len() > exact_u.as_ref().map_or(0, |c| c.points.len()) {
                exact_u = Some(Curve {
                    name: "exact".into(),
                    points: figures::decimate(&rs.u_exact, 1500),
                    color: 0,
                });
            }
            if rs.sigma_exact.len() > exact_s.as_ref().map_or(0, |c| c.points.len()) {
                exact_s = Some(Curve {
                    name: "exact".into(),
                    points: figures::decimate(&rs.sigma_exact, 1500),
                    color: 0,
                });
            }
        }
        let gs: Vec<usize> = chosen.iter().map(|&(g, _)| g).collect();
        body.push_str(&legend(runs, &gs, "black dashes: exact"));
        body.push_str("<div class=\"figs\">\n");
        for (t, y, curves, exact) in [
            ("contact displacement u_C(t)", "u_C", &u, exact_u.as_ref()),
            ("contact pressure σ_C(t)", "σ_C", &s, exact_s.as_ref()),
            ("energy E(t)/energy_scale", "E/E_s", &en, None),
        ] {
            if curves.is_empty() {
                continue;
            }
            match figures::series(t, y, curves, exact) {
                Ok(svg) => {
                    body.push_str(&svg);
                    figures += 1;
                }
                Err(x) => skipped.push(x.to_string()),
            }
        }
        body.push_str("</div>\n");
        frictional_figures(
            runs,
            &chosen,
            &series,
            &mut body,
            &mut figures,
            &mut skipped,
        );
    }

    // 3. The method table, as the terminal prints it, with its legend.
    body.push_str("<h2 id=\"methods\">Method groups</h2>\n");
    let _ = writeln!(body, "<p>{}.</p>", esc(&conv.groups.caption));
    body.push_str(&html_table(
        &conv.groups.header,
        &conv.groups.right,
        &conv.groups.rows,
    ));
    body.push_str("<ul class=\"note\">");
    for l in &conv.groups.legend {
        let _ = write!(body, "<li>{}</li>", esc(l));
    }
    body.push_str("</ul>\n");
    let params: Vec<String> = runs.params.iter().map(|(n, _)| n.to_string()).collect();
    let prow: Vec<Vec<String>> = runs
        .groups
        .iter()
        .enumerate()
        .map(|(g, grp)| {
            let r = &runs.runs[grp.runs[0]];
            let mut row = vec![(g + 1).to_string(), grp.title.clone()];
            row.push(format!(
                "{}/{}",
                grp.runs.iter().filter(|&&i| runs.runs[i].ok()).count(),
                grp.runs.len()
            ));
            row.extend(r.params.iter().map(|c| c.show().unwrap_or_default()));
            row
        })
        .collect();
    let mut ph = vec!["#".to_string(), "method".into(), "ok/runs".into()];
    ph.extend(params);
    let _ = writeln!(
        body,
        "<details><summary>Every parameter of each group</summary>{}</details>",
        html_table(&ph, &[true, false, true], &prow)
    );

    // 3b. The method classes (Doyen–Ern–Piperno's comparison), as `summary/methods.md`.
    if !methods.rows.is_empty() {
        body.push_str("<h2 id=\"classes\">Method classes</h2>\n");
        body.push_str(&html_table(
            &methods.header,
            &[false, false, false, false, true, true],
            &methods.rows,
        ));
        let _ = writeln!(body, "<p class=\"note\">{}</p>", esc(&methods.legend));
    }

    // 4. Energy and the full tables.
    body.push_str("<h2 id=\"energy\">Energy behaviour</h2>\n");
    // The section has its own heading: drop the file's "# Energy".
    let energy_md = en
        .markdown
        .strip_prefix("# Energy\n")
        .unwrap_or(&en.markdown);
    let (groups_md, runs_md) = match energy_md.find("\n## Per run") {
        Some(k) => energy_md.split_at(k),
        None => (energy_md, ""),
    };
    body.push_str(&markdown(groups_md, 1));
    if !runs_md.is_empty() {
        let _ = writeln!(
            body,
            "<details><summary>Per run</summary>{}</details>",
            markdown(runs_md, 1)
        );
    }
    if st.table.height() > 0 {
        body.push_str("<h2 id=\"stability\">Stability map</h2>\n");
        body.push_str(&markdown(
            st.markdown
                .strip_prefix("# Stability maps\n")
                .unwrap_or(&st.markdown),
            1,
        ));
    }
    body.push_str("<h2 id=\"tables\">Convergence and work-precision tables</h2>\n");
    let _ = writeln!(
        body,
        "<p class=\"note\">The summary's tables (<code>summary/convergence.md</code>, <code>summary/work_precision.md</code>); every column is in the Parquet/CSV files beside them.</p>"
    );
    let _ = writeln!(
        body,
        "<details><summary>Convergence: {} refinement paths with rates, LSQ slopes and flags</summary>{}</details>",
        runs.paths.len(),
        markdown(&conv.markdown, 1)
    );
    let _ = writeln!(
        body,
        "<details><summary>Work-precision: Pareto fronts and cost to reach ε</summary>{}</details>",
        markdown(&wp.markdown, 1)
    );

    // 5. The sweep file and the plan.
    body.push_str("<h2 id=\"sweep\">Sweep file and plan</h2>\n");
    match &ses.text {
        None => body.push_str(
            "<p class=\"note\">No sweep file recorded (no manifest.json in the folder).</p>\n",
        ),
        Some(text) => {
            let file = ses.file.clone().unwrap_or_else(|| "sweep.toml".into());
            let _ = writeln!(
                body,
                "<p><code>{}</code>:</p><pre>{}</pre>",
                esc(&file),
                esc(text)
            );
            if !ses.sets.is_empty() {
                let _ = writeln!(
                    body,
                    "<p>With the command-line overrides: {}</p>",
                    ses.sets
                        .iter()
                        .map(|s| format!("<code>--set {}</code>", esc(s)))
                        .collect::<Vec<_>>()
                        .join(" ")
                );
            }
            let planned = crate::sweep::SweepFile::parse_with(Path::new(&file), text, &ses.sets)
                .map_err(anyhow::Error::new)
                .and_then(|sf| crate::sweep::expand(&sf).map_err(anyhow::Error::new));
            match planned {
                Ok(plan) => {
                    let _ = writeln!(
                        body,
                        "<pre>{}</pre><details><summary>The plan: {} runs</summary><pre>{}</pre></details>",
                        esc(&plan.summary()),
                        plan.runs.len(),
                        esc(&plan.table())
                    );
                }
                Err(e) => {
                    let _ = writeln!(
                        body,
                        "<p class=\"note\">The plan cannot be recomputed by this version: {}</p>",
                        esc(&format!("{e:#}"))
                    );
                }
            }
        }
    }
    if !skipped.is_empty() {
        body.push_str("<h2>Figures not drawn</h2><ul>");
        for s in &skipped {
            let _ = write!(body, "<li>{}</li>", esc(s));
        }
        body.push_str("</ul>\n");
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_tables_headings_and_code_become_html() {
        let md = "# Title\n\nSome `code` and **bold** < text.\n\n| a | b \\| c |\n|:---|---:|\n| 1 | 2 |\n\n- item\n";
        let h = markdown(md, 1);
        assert!(h.contains("<h2>Title</h2>"), "{h}");
        assert!(
            h.contains("<code>code</code>") && h.contains("<b>bold</b>") && h.contains("&lt; text")
        );
        assert!(
            h.contains("<th>b | c</th>") && h.contains("<td class=\"r\">2</td>"),
            "{h}"
        );
        assert!(h.contains("<li>item</li>"));
    }

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
