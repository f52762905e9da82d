//! The report's figures tell many method groups apart (issue 41): a bar1d sweep of 12 method
//! groups (12 values of Nitsche's γ0, two meshes each, a few milliseconds a run) is run and
//! reported, and the SVG of every figure is read back: each draws all 12 groups — 12 curves
//! of 12 different colours where it draws curves, and 12 different (marker shape, colour)
//! pairs — and the HTML legend names 12 groups with 12 different (colour, glyph) pairs. Before,
//! the time series stopped at 8 groups and colours cycled after 8.
//!
//! The SVG is plotters' (one element per line): a curve is a `<polyline>` with its `stroke`
//! colour, a marker a filled `<circle>` or a `<polygon>` whose shape is its points relative to
//! the first one. Black is the exact solution's and the Pareto front's, not a group's.

mod common;

use std::collections::HashSet;

use common::{cli, write};

const GROUPS: usize = 12;

/// The value of attribute `name` in one SVG element's text.
fn attr<'a>(element: &'a str, name: &str) -> Option<&'a str> {
    let start = element.find(&format!(" {name}=\""))? + name.len() + 3;
    let len = element[start..].find('"')?;
    Some(&element[start..start + len])
}

/// The elements `<tag …/>` of an SVG, one per line as plotters writes them.
fn elements<'a>(svg: &'a str, tag: &str) -> Vec<&'a str> {
    let open = format!("<{tag} ");
    svg.lines().filter(|l| l.starts_with(&open)).collect()
}

/// The colours of the curves of a figure (black excluded).
fn curve_colours(svg: &str) -> HashSet<String> {
    elements(svg, "polyline")
        .iter()
        .filter_map(|e| attr(e, "stroke"))
        .filter(|c| *c != "#000000")
        .map(String::from)
        .collect()
}

/// The (shape, colour) pairs of a figure's markers: filled circles, and polygons by their
/// points relative to the first one (black excluded).
fn marker_looks(svg: &str) -> HashSet<(String, String)> {
    let mut out = HashSet::new();
    for e in elements(svg, "circle") {
        if let Some(fill) = attr(e, "fill").filter(|f| *f != "none" && *f != "#000000") {
            out.insert(("circle".to_string(), fill.to_string()));
        }
    }
    for e in elements(svg, "polygon") {
        let (Some(fill), Some(points)) = (attr(e, "fill"), attr(e, "points")) else {
            continue;
        };
        let pts: Vec<(i64, i64)> = points
            .split_whitespace()
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        let shape: Vec<String> = pts
            .iter()
            .map(|p| format!("{},{}", p.0 - pts[0].0, p.1 - pts[0].1))
            .collect();
        if fill != "#000000" {
            out.insert((shape.join(" "), fill.to_string()));
        }
    }
    out
}

/// The SVG figures of one section of the report (from its `<h2 id=…>` to the next `<h2`).
fn figures_of<'a>(html: &'a str, id: &str) -> Vec<&'a str> {
    let start = html
        .find(&format!("<h2 id=\"{id}\">"))
        .unwrap_or_else(|| panic!("no section {id}"));
    let rest = &html[start + 4..];
    let section = &rest[..rest.find("<h2").unwrap_or(rest.len())];
    section
        .split("<svg")
        .skip(1)
        .map(|s| &s[..s.find("</svg>").unwrap()])
        .collect()
}

/// The legend entries above a section's figures: (colour, glyph) of each group.
fn legend_of(html: &str, id: &str) -> Vec<(String, String)> {
    let start = html.find(&format!("<h2 id=\"{id}\">")).unwrap();
    let rest = &html[start..];
    let legend = &rest[rest.find("<div class=\"legend\">").unwrap()..];
    let legend = &legend[..legend.find("</div>").unwrap()];
    legend
        .split("<span><i style=\"")
        .skip(1)
        .map(|s| {
            let (style, rest) = s.split_once("\">").unwrap();
            let glyph = &rest[..rest.find("</i>").unwrap()];
            (style.to_string(), glyph.to_string())
        })
        .collect()
}

#[test]
fn twelve_method_groups_are_drawn_apart_in_every_figure() {
    let tmp = tempfile::tempdir().unwrap();
    let gammas: Vec<String> = (1..=GROUPS).map(|k| format!("{k}e-6")).collect();
    let sweep = write(
        tmp.path(),
        "twelve.toml",
        &format!(
            "name = \"twelve\"\nscene = \"bar1d\"\n\n[fixed]\nT = 2.0\ncourant = 1.0\nspace = \"nitsche\"\nscheme = \"crank-nicolson\"\n\n[grid]\nh = [0.125, 0.0625]\nnitsche_gamma0 = [{}]\n",
            gammas.join(", ")
        ),
    );
    let o = cli(
        tmp.path(),
        &[
            "run",
            sweep.to_str().unwrap(),
            "--out",
            "out",
            "--threads",
            "2",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = std::fs::read_to_string(tmp.path().join("out/report.html")).unwrap();
    assert!(
        html.contains(&format!("in {GROUPS} method groups")),
        "{html}"
    );

    // Convergence: per error column, a curve and a marker per group.
    let conv = figures_of(&html, "convergence");
    assert!(!conv.is_empty());
    for svg in &conv {
        assert_eq!(curve_colours(svg).len(), GROUPS, "convergence curves");
        assert_eq!(marker_looks(svg).len(), GROUPS, "convergence markers");
    }
    // Work-precision: every run marked by its group.
    let work = figures_of(&html, "work");
    assert_eq!(work.len(), 1);
    assert_eq!(
        marker_looks(work[0]).len(),
        GROUPS,
        "work-precision markers"
    );
    // Time series: one run per group — all twelve, not the first eight.
    let series = figures_of(&html, "series");
    assert_eq!(series.len(), 3, "u_C, σ_C and E against t");
    for svg in &series {
        assert_eq!(curve_colours(svg).len(), GROUPS, "time-series curves");
        assert_eq!(marker_looks(svg).len(), GROUPS, "time-series markers");
    }
    assert!(!html.contains("the first 8 groups"));

    // The legends: twelve groups, twelve different looks.
    for id in ["convergence", "work", "series"] {
        let legend = legend_of(&html, id);
        assert_eq!(legend.len(), GROUPS, "{id} legend");
        let looks: HashSet<_> = legend.into_iter().collect();
        assert_eq!(looks.len(), GROUPS, "{id} legend looks");
    }
}

/// The SVG figures of a `<h3 id=…>` subsection (up to the next heading).
fn subsection_figures<'a>(html: &'a str, id: &str) -> Vec<&'a str> {
    let start = html
        .find(&format!("<h3 id=\"{id}\">"))
        .unwrap_or_else(|| panic!("no subsection {id}"));
    let rest = &html[start + 4..];
    let end = [rest.find("<h2"), rest.find("<h3")]
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(rest.len());
    rest[..end]
        .split("<svg")
        .skip(1)
        .map(|s| &s[..s.find("</svg>").unwrap()])
        .collect()
}

/// The report of sweep `body` (run in a temporary folder): its HTML.
fn report_of(body: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = write(tmp.path(), "s.toml", body);
    let args = [
        "run",
        sweep.to_str().unwrap(),
        "--out",
        "out",
        "--threads",
        "2",
    ];
    let o = cli(tmp.path(), &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(tmp.path().join("out/report.html")).unwrap()
}

#[test]
fn two_body_runs_draw_both_contact_faces_and_the_momentum() {
    // Two bars (contract §1.9) in three method groups: both faces and the momentum are drawn
    // for each, in its group's colour.
    let html = report_of(
        "name = \"bars\"\nscene = \"bars1d\"\n\n[fixed]\nT = 3.0\ncourant = 1.0\nscheme = \"crank-nicolson\"\nmass = \"zero-contact\"\n\n[grid]\nelements = [10, 20]\ncase = [{ space = \"mixed\" }, { space = \"penalty\", penalty_gamma0 = 10.0 }, { space = \"nitsche\", nitsche_gamma0 = 0.1 }]\n",
    );
    let figs = subsection_figures(&html, "two-body");
    assert_eq!(figs.len(), 2, "u_C^a/u_C^b and the momentum");
    for svg in &figs {
        assert_eq!(curve_colours(svg).len(), 3, "one colour per method group");
    }
    assert!(figs[0].contains("u_C^a, u_C^b"), "{}", figs[0]);
    assert!(figs[1].contains("momentum"), "{}", figs[1]);
}

#[test]
fn a_one_body_report_has_no_two_body_figures() {
    let html = report_of(
        "name = \"one\"\nscene = \"bar1d\"\n\n[fixed]\nT = 2.0\ncourant = 1.0\nscheme = \"crank-nicolson\"\n\n[grid]\nh = [0.125, 0.0625]\n",
    );
    assert!(html.contains("<h2 id=\"series\">"));
    assert!(!html.contains("id=\"two-body\""));
}
