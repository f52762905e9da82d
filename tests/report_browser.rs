//! The HTML report in a real browser: headless Chromium (Debian's `chromium`, installed by
//! `tests/install_chromium.sh` when missing) opens `report.html` of the quickstart and of the
//! 003 Fig 10 ladder, takes a screenshot, and the test checks that the figures rendered — the
//! figure region of the PNG holds coloured pixels (the curves; text and rules are grey), the
//! DOM after load holds every inline SVG — and that the console logged no error.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::cli;

const CHROMIUM: &str = "/usr/bin/chromium";

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Chromium, installed on first use (idempotent; `.ci/run` installs it beforehand).
fn chromium() -> &'static str {
    if !Path::new(CHROMIUM).exists() {
        let o = Command::new("bash")
            .arg(repo().join("tests/install_chromium.sh"))
            .output()
            .expect("bash runs");
        assert!(
            o.status.success(),
            "installing chromium failed: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    CHROMIUM
}

/// Chromium's flags for a quiet, offline, sandbox-less headless run with its own profile.
fn browser(profile: &Path) -> Command {
    let mut c = Command::new(chromium());
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--enable-logging=stderr",
        "--v=0",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    c
}

/// An RGB(A) 8-bit PNG: (width, height, channels, pixels).
fn decode(png_path: &Path) -> (usize, usize, usize, Vec<u8>) {
    let file = std::io::BufReader::new(std::fs::File::open(png_path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => panic!("unexpected PNG colour type {other:?}"),
    };
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, channels, buf)
}

/// What the screenshot shows between rows `y0` and `y1`: (non-white pixels, coloured pixels).
/// Coloured: channels spread by more than 60 — the curves of the palette; text, rules, grid
/// and the pale backgrounds stay below.
fn pixels(png_path: &Path, y0: usize, y1: usize) -> (usize, usize) {
    let (w, h, ch, buf) = decode(png_path);
    let (mut ink, mut colour) = (0, 0);
    for y in y0.min(h)..y1.min(h) {
        for x in 0..w {
            let p = &buf[(y * w + x) * ch..(y * w + x) * ch + 3];
            let (lo, hi) = (*p.iter().min().unwrap(), *p.iter().max().unwrap());
            if lo < 245 {
                ink += 1;
            }
            if hi - lo > 60 {
                colour += 1;
            }
        }
    }
    (ink, colour)
}

struct Rendered {
    /// Non-white and coloured pixels of the figure region (below the page header).
    ink: usize,
    colour: usize,
    /// `<svg` elements in the DOM after load.
    svgs: usize,
}

/// Screenshot and DOM of `html`; panics on console errors.
fn render(html: &Path, tmp: &Path, name: &str) -> Rendered {
    let url = format!("file://{}", html.canonicalize().unwrap().display());
    let png = tmp.join(format!("{name}.png"));
    let o = browser(&tmp.join(format!("profile-{name}")))
        .arg(format!("--screenshot={}", png.display()))
        .arg("--window-size=1280,2000")
        .arg(&url)
        .output()
        .expect("chromium starts");
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "chromium failed: {log}");
    for bad in ["ERROR:CONSOLE", "Uncaught", ":CONSOLE("] {
        assert!(!log.contains(bad), "console error in {name}: {log}");
    }
    let o = browser(&tmp.join(format!("profile-{name}-dom")))
        .arg("--dump-dom")
        .arg(&url)
        .output()
        .expect("chromium starts");
    assert!(o.status.success());
    let dom = String::from_utf8_lossy(&o.stdout);
    // Below the title, the summary line and the hints: the figures start about 500 px down.
    let (ink, colour) = pixels(&png, 450, 2000);
    Rendered {
        ink,
        colour,
        svgs: dom.matches("<svg").count(),
    }
}

/// The self-containment promise: no script, no stylesheet or image from elsewhere.
fn assert_self_contained(html: &str) {
    for bad in [
        "<script",
        "<link",
        "<img",
        "src=\"http",
        "href=\"http",
        "@import",
    ] {
        assert!(!html.contains(bad), "the report loads something: `{bad}`");
    }
}

fn run_into(tmp: &Path, sweep: &str, out: &str) -> PathBuf {
    let dir = tmp.join(out);
    let o = cli(repo(), &["run", sweep, "--out", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    dir
}

#[test]
fn quickstart_report_renders_its_figures_in_chromium() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run_into(tmp.path(), "sweeps/quickstart.toml", "qs");
    // `run` wrote the report next to the summaries.
    let html_path = dir.join("report.html");
    let html = std::fs::read_to_string(&html_path).unwrap();
    assert_self_contained(&html);
    // 4 convergence figures (the default error columns), work-precision, 3 time series.
    assert_eq!(html.matches("<svg").count(), 8);
    for s in [
        "What to look at",
        "Pareto front",
        "mixed · zero-contact · crank-nicolson",
        "name = &quot;quickstart&quot;", // the sweep file, HTML-escaped
        "60 combinations → 60 runs",
        "LSQ slope, finest 3",
    ] {
        assert!(html.contains(s), "the report lacks `{s}`");
    }
    let r = render(&html_path, tmp.path(), "quickstart");
    assert_eq!(r.svgs, 8, "SVGs in the DOM after load");
    // The screenshot's figure region (1280 × 1550 px) is drawn: measured 112 000 non-white and
    // 24 500 coloured pixels (Fig 10 ladder: 115 000 and 19 400); a page whose SVGs did not
    // render keeps its text and tables, grey: a few hundred coloured pixels (links, legend).
    assert!(r.ink > 50_000, "non-white pixels: {}", r.ink);
    assert!(r.colour > 5_000, "coloured pixels: {}", r.colour);
    eprintln!(
        "quickstart: {} bytes, {} non-white and {} coloured pixels",
        html.len(),
        r.ink,
        r.colour
    );
}

#[test]
fn fig10_ladder_report_renders_and_report_writes_where_asked() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run_into(tmp.path(), "sweeps/003_fig10_ladder.toml", "fig10");
    let out = tmp.path().join("elsewhere/fig10.html");
    let o = cli(
        repo(),
        &[
            "report",
            dir.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("5 figures"));
    let html = std::fs::read_to_string(&out).unwrap();
    assert_self_contained(&html);
    // series_every = 0: no time series, said so; 4 convergence figures and work-precision.
    assert!(html.contains("No time series"));
    assert_eq!(html.matches("<svg").count(), 5);
    let r = render(&out, tmp.path(), "fig10");
    assert_eq!(r.svgs, 5);
    assert!(r.ink > 50_000, "non-white pixels: {}", r.ink);
    assert!(r.colour > 5_000, "coloured pixels: {}", r.colour);
    eprintln!(
        "fig10: {} bytes, {} non-white and {} coloured pixels",
        html.len(),
        r.ink,
        r.colour
    );
    // A folder without runs is refused, naming it.
    let o = cli(
        repo(),
        &["report", tmp.path().join("nothing").to_str().unwrap()],
    );
    assert_ne!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nothing"));
}
