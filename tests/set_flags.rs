//! Parameters from the command line: `--set key=value` on a sweep file and `--scene` without
//! one give the runs (and run ids) of the equivalent file, are checked by the file's checks with
//! the flag named, and are recorded in the manifest.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::{cli, write};
use contact_sweep::sink::read_runs;
use contact_sweep::sweep::{self, SweepFile};

fn ids(sf: &SweepFile) -> Vec<String> {
    sweep::expand(sf)
        .unwrap_or_else(|e| panic!("{e}"))
        .runs
        .into_iter()
        .map(|r| r.run_id)
        .collect()
}

fn sets(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

const FILE: &str = "name = \"f\"\nscene = \"bar1d\"\n[fixed]\nT = 2.0\ncourant = 1.0\n[grid]\nh = [0.25, 0.125]\nmethod = [ { space = \"nitsche\", nitsche_gamma0 = 1e-6, scheme = \"hybrid\" }, { mass = \"mod3\" } ]\n";

#[test]
fn flags_give_the_ids_of_the_equivalent_file() {
    let file = SweepFile::parse(Path::new("f.toml"), FILE).unwrap();
    let want = ids(&file);
    assert_eq!(want.len(), 4);
    // No file at all: the same four runs, in the same order, with the same ids.
    let flags = SweepFile::from_flags(
        "bar1d",
        &sets(&[
            "T=2.0",
            "courant=1",
            "h=[0.25,0.125]",
            "grid.method=[{ space = \"nitsche\", nitsche_gamma0 = 1e-6, scheme = \"hybrid\" }, { mass = \"mod3\" }]",
        ]),
    )
    .unwrap();
    assert_eq!(flags.name, "bar1d");
    assert_eq!(ids(&flags), want);
    // On a file: replacing its h axis by a single value keeps the ids of those runs.
    let one = SweepFile::parse_with(Path::new("f.toml"), FILE, &sets(&["h=0.125"])).unwrap();
    // (the grid's last axis varies fastest: h = 0.125 holds the last two runs)
    assert_eq!(ids(&one), want[2..4]);
    // fixed.h with the grid's h left in place: the axis overrides [fixed] (as in a file).
    let fixed = SweepFile::parse_with(Path::new("f.toml"), FILE, &sets(&["fixed.h=0.5"])).unwrap();
    assert_eq!(ids(&fixed), want);
    assert!(
        fixed.overridden.iter().any(|n| n.contains("fixed.h")),
        "{:?}",
        fixed.overridden
    );
    // Bare words are strings; a list of them is an axis.
    let masses = SweepFile::from_flags(
        "bar1d",
        &sets(&["h=0.25", "courant=1", "T=2", "mass=[consistent,mod3]"]),
    )
    .unwrap();
    let plan = sweep::expand(&masses).unwrap();
    let labels: Vec<&str> = plan.runs.iter().map(|r| r.label.as_str()).collect();
    assert_eq!(
        labels,
        [
            "mixed · consistent · crank-nicolson",
            "mixed · mod3 · crank-nicolson"
        ]
    );
}

#[test]
fn a_bad_set_is_refused_like_the_file_naming_the_flag_and_the_key() {
    // The same value in a file and on the command line: the same reason, another place.
    let in_file = SweepFile::parse(
        Path::new("f.toml"),
        "name = \"f\"\nscene = \"bar1d\"\n[fixed]\nnewmark_beta = 0.9\n",
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        in_file,
        "f.toml:4: key `fixed.newmark_beta`: must lie in [0, 0.5], got 0.9"
    );
    let on_flag = SweepFile::from_flags("bar1d", &sets(&["newmark_beta=0.9"]))
        .unwrap_err()
        .to_string();
    assert_eq!(
        on_flag,
        "--set newmark_beta=0.9: key `fixed.newmark_beta`: must lie in [0, 0.5], got 0.9"
    );
    // A clash between the file and the flag names both.
    let clash = SweepFile::parse_with(
        Path::new("f.toml"),
        "name = \"f\"\nscene = \"bar1d\"\n[zip]\nh = [0.1, 0.05]\ndt = [0.1, 0.05]\n",
        &sets(&["grid.dt=[0.1,0.2]"]),
    )
    .unwrap_err()
    .to_string();
    assert!(
        clash.contains(
            "f.toml:5: key `zip.dt[0]`: `dt` is also set by grid.dt[0] (--set grid.dt=[0.1,0.2])"
        ),
        "{clash}"
    );
}

#[test]
fn run_with_flags_only_matches_the_file_and_records_the_overrides() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "f.toml", FILE);
    let o = cli(tmp.path(), &["run", "f.toml", "--out", "file"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = cli(
        tmp.path(),
        &[
            "run",
            "--scene",
            "bar1d",
            "--set",
            "T=2",
            "--set",
            "courant=1",
            "--set",
            "h=[0.25,0.125]",
            "--set",
            "grid.method=[{ space = \"nitsche\", nitsche_gamma0 = 1e-6, scheme = \"hybrid\" }, { mass = \"mod3\" }]",
            "--out",
            "flags",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("  --set h=[0.25,0.125]"));
    let run_ids = |d: &str| -> BTreeSet<String> {
        let df = read_runs(&tmp.path().join(d)).unwrap();
        df.column("run_id")
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .map(|s| s.unwrap().to_string())
            .collect()
    };
    assert_eq!(run_ids("file").len(), 4);
    assert_eq!(run_ids("file"), run_ids("flags"));
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.path().join("flags/manifest.json")).unwrap(),
    )
    .unwrap();
    let s = &manifest["sessions"][0];
    assert_eq!(s["sweep_file"], "--scene bar1d");
    assert_eq!(s["overrides"][2], "h=[0.25,0.125]");
    assert_eq!(s["overrides"].as_array().unwrap().len(), 4);

    // `summarize` finds a [summary] choice given by --set again (through the manifest).
    let o = cli(
        tmp.path(),
        &[
            "run",
            "f.toml",
            "--out",
            "chosen",
            "--set",
            "summary.errors=[err_u_l2h1]",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = cli(tmp.path(), &["summarize", "chosen"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(tmp.path().join("chosen/summary/convergence.md")).unwrap();
    assert!(md.contains("| err_u_l2h1 | rate |") && !md.contains("| err_u_l2l2 |"));
}

#[test]
fn bad_flags_exit_2_naming_the_flag_and_the_key() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "f.toml", FILE);
    for (args, want) in [
        (
            vec!["run", "f.toml", "--set", "fixed.newmark_beta=0.9"],
            "--set fixed.newmark_beta=0.9: key `fixed.newmark_beta`: must lie in [0, 0.5], got 0.9",
        ),
        (
            vec!["run", "--scene", "bar1d", "--set", "hh=0.1"],
            "--set hh=0.1: key `hh`: unknown top-level key",
        ),
        (
            vec!["plan", "f.toml", "--set", "h=[0.25,-1]"],
            "--set h=[0.25,-1]: key `grid.h[1]`",
        ),
        (
            vec!["run", "f.toml", "--set", "h"],
            "--set `h`: expected key=value",
        ),
        (
            vec!["run", "--scene", "bar4d", "--set", "h=0.1"],
            "--scene bar4d: key `scene`: unknown scene `bar4d`",
        ),
        (
            vec!["run", "--set", "h=0.1"],
            "give a sweep file, or --scene",
        ),
    ] {
        let o = cli(tmp.path(), &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    // Nothing was written for a refused sweep.
    assert!(!tmp.path().join("out").exists());
}

/// Regression: the disc starts with E⁰ = 0 (at rest, potential measured from the start), and
/// the result table printed E(T)/E⁰ as ±inf. It now prints 1 + energy_drift (drift relative to
/// energy_scale = m·g·gap), which for CN's exact free fall is 1 to round-off.
#[test]
fn a_disc_run_prints_a_finite_energy_ratio() {
    let tmp = tempfile::tempdir().unwrap();
    let o = cli(
        tmp.path(),
        &[
            "run",
            "--scene",
            "disc2d",
            "--set",
            "degree=1",
            "--set",
            "h=4",
            "--set",
            "T=2",
            "--set",
            "dt=0.1",
            "--table",
            "runs",
            "--no-summary",
            "--out",
            "disc",
        ],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let row = out
        .lines()
        .find(|l| l.contains("disc") || l.contains(" ok "))
        .unwrap_or_else(|| panic!("no run row in:\n{out}"));
    assert!(!out.contains("inf"), "{out}");
    assert!(row.contains("1.000"), "{row}\n{out}");

    // Regression (issue 20): the report of the same folder drew no energy history (E⁰ = 0) and
    // its method table printed "—" for E(T)/E⁰. Now the energy is drawn in units of
    // energy_scale and the table prints the terminal's 1 + drift.
    let dir = tmp.path().join("disc");
    let html_path = tmp.path().join("disc.html");
    let r = cli(
        tmp.path(),
        &[
            "report",
            dir.to_str().unwrap(),
            "--out",
            html_path.to_str().unwrap(),
        ],
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let html = std::fs::read_to_string(&html_path).unwrap();
    assert!(
        html.contains("energy E(t)/energy_scale"),
        "no energy figure"
    );
    let table = &html[html.find("id=\"methods\"").expect("method table")..];
    let table = &table[..table.find("</table>").expect("table end")];
    let row = &table[table.find("<td").expect("a row")..];
    assert!(
        row.contains("1.000") && !row.contains("—</td></tr>"),
        "E(T)/E⁰ missing from the report's method table: {row}"
    );
}
