//! The report's text sections: the sweep (name, description, what ran, the "what to look
//! at" hints), the method table with every parameter of each group, the method classes, the
//! contact patch test's table, the energy behaviour, the stability map, the summary's convergence and work-precision tables
//! (its Markdown, rendered), the sweep file as run with its plan, and the figures not drawn.
//! Everything comes from the summary's sections, so the report and `DIR/summary/` agree.

use std::fmt::Write as _;
use std::path::Path;

use crate::summary::Sections;

use super::html::{esc, html_table, markdown};
use super::session::Session;

/// The sweep: its name, description, runs and groups, where it ran from and with which
/// version, the navigation, and the hints.
pub(super) fn sweep(body: &mut String, dir: &Path, ses: &Session, name: &str, s: &Sections) {
    let Sections { runs, conv, .. } = s;
    let ok = runs.runs.iter().filter(|r| r.ok()).count();
    let _ = writeln!(body, "<h1>Sweep <code>{}</code></h1>", esc(name));
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
    // The patch-test link only where the section is.
    let patch = if s.patch.is_empty() {
        ""
    } else {
        "<a href=\"#patch\">patch test</a>"
    };
    let _ = writeln!(
        body,
        "<nav><a href=\"#convergence\">convergence</a><a href=\"#work\">work-precision</a><a href=\"#series\">time series</a><a href=\"#methods\">method table</a><a href=\"#classes\">method classes</a>{patch}<a href=\"#energy\">energy</a><a href=\"#tables\">all tables</a><a href=\"#sweep\">sweep file and plan</a></nav>"
    );
    if !conv.groups.hints.is_empty() {
        body.push_str("<div class=\"hints\"><b>What to look at</b><ul>");
        for h in &conv.groups.hints {
            let _ = write!(body, "<li>{}</li>", esc(h));
        }
        body.push_str("</ul></div>\n");
    }
}

/// The method table, as the terminal prints it, with its legend and every parameter of each
/// group; then the method classes (Doyen–Ern–Piperno's comparison), as `summary/methods.md`.
pub(super) fn methods(body: &mut String, s: &Sections) {
    let Sections {
        runs,
        conv,
        methods,
        ..
    } = s;
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
}

/// The contact patch test (contract §1.10), as `summary/patch_test.md`: the verdict of every
/// method per dimension and mesh ratio, then each column group's errors per refinement. Only
/// for a folder with patch-test runs.
pub(super) fn patch(body: &mut String, s: &Sections) {
    let p = &s.patch;
    if p.is_empty() {
        return;
    }
    body.push_str("<h2 id=\"patch\">Contact patch test</h2>\n");
    let _ = writeln!(body, "<p class=\"note\">{}</p>", esc(&p.legend));
    body.push_str(&html_table(
        p.verdicts.header(),
        &p.verdicts.right(),
        p.verdicts.rows(),
    ));
    for (head, d) in &p.details {
        let _ = writeln!(body, "<h3>{}</h3>", esc(head));
        body.push_str(&html_table(d.header(), &d.right(), d.rows()));
    }
}

/// The energy behaviour, the stability map when the sweep has one, and the summary's
/// convergence and work-precision tables.
pub(super) fn tables(body: &mut String, s: &Sections) {
    let Sections {
        runs,
        conv,
        en,
        wp,
        st,
        ..
    } = s;
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
}

/// The sweep file as run, its `--set` overrides, and its plan recomputed by this version.
pub(super) fn sweep_file(body: &mut String, ses: &Session) {
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
}

/// The figures that could not be drawn, with the reason.
pub(super) fn not_drawn(body: &mut String, skipped: &[String]) {
    if !skipped.is_empty() {
        body.push_str("<h2>Figures not drawn</h2><ul>");
        for s in skipped {
            let _ = write!(body, "<li>{}</li>", esc(s));
        }
        body.push_str("</ul>\n");
    }
}
