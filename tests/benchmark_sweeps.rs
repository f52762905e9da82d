//! The benchmark keys and sweeps of issue 21 in the planner: the new bar1d keys at their
//! defaults leave every run id as it was, the word-valued `right_end` is validated and stored
//! as a word, the oscillator needs no mesh, and the three benchmark sweep files plan.

mod common;

use std::path::Path;

use contact_sweep::sweep::{self, Key, Plan, SweepFile, Value};

fn plan(text: &str) -> Plan {
    let sf = SweepFile::parse(Path::new("bench.toml"), text).unwrap_or_else(|e| panic!("{e}"));
    sweep::expand(&sf).unwrap_or_else(|e| panic!("{e}"))
}

fn refused(text: &str) -> String {
    match SweepFile::parse(Path::new("bench.toml"), text) {
        Err(e) => e.to_string(),
        Ok(sf) => match sweep::expand(&sf) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {text}"),
        },
    }
}

fn ids(p: &Plan) -> Vec<String> {
    p.runs.iter().map(|r| r.run_id.clone()).collect()
}

const HEAD: &str = "name = \"n\"\nscene = \"bar1d\"\n";

#[test]
fn new_bar1d_keys_at_their_defaults_keep_every_run_id() {
    // The frozen ids of tests/planner.rs (003's CN run, consistent mass and mod3), with the
    // new keys written out at their defaults: clamped, at rest.
    let explicit = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\nright_end = \"clamped\"\nvelocity = 0.0\n[grid]\nmass = [\"consistent\", \"mod3\"]\n"
    ));
    assert_eq!(
        ids(&explicit),
        vec![
            "35050bcfa8862a8f".to_string(),
            "0475aa43696174b7".to_string()
        ]
    );
    // The columns: the word, and the number.
    assert_eq!(
        explicit.runs[0].params[&Key::RightEnd],
        Value::Str("clamped".into())
    );
    assert_eq!(explicit.runs[0].params[&Key::Velocity], Value::Num(0.0));
    // A free end or a velocity is another run.
    let free = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n[grid]\nright_end = [\"clamped\", \"free\"]\nvelocity = [0.0, -1.0]\n"
    ));
    assert_eq!(free.runs.len(), 4);
    assert_eq!(free.runs[0].run_id, "35050bcfa8862a8f");
    let mut all = ids(&free);
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 4);
    assert_eq!(
        free.runs[2].params[&Key::RightEnd],
        Value::Str("free".into())
    );
}

#[test]
fn bad_benchmark_input_names_file_key_and_reason() {
    let e = refused(&format!(
        "{HEAD}[fixed]\nh = 0.1\ndt = 0.1\nright_end = \"hinged\"\n"
    ));
    assert!(
        e.contains("bench.toml")
            && e.contains("right_end")
            && e.contains("expected clamped or free"),
        "{e}"
    );
    let e = refused("name = \"o\"\nscene = \"oscillator\"\n[fixed]\nh = 0.1\ndt = 0.01\n");
    assert!(
        e.contains("bench.toml") && e.contains("h") && e.contains("has no mesh"),
        "{e}"
    );
    let e = refused("name = \"o\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nimpact_law = 1.5\n");
    assert!(e.contains("impact_law") && e.contains("[0, 1]"), "{e}");
    let e = refused(
        "name = \"o\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nspace = \"nitsche\"\nnitsche_gamma0 = 1.0\n",
    );
    assert!(e.contains("space") && e.contains("oscillator"), "{e}");
    let e = refused("name = \"o\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nmass = \"mod3\"\n");
    assert!(e.contains("mass") && e.contains("do not apply"), "{e}");
    // A bar1d key the oscillator does not declare.
    let e =
        refused("name = \"o\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nright_end = \"free\"\n");
    assert!(e.contains("right_end"), "{e}");
    // contract §3.2's applicability on the oscillator: kane, CSN and Moreau–Jean are multiplier
    // (impulse) methods, the discrete gradient is the penalty potential's.
    let e = refused(
        "name = \"o\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nspace = \"penalty\"\npenalty_gamma0 = 1.0\nscheme = \"kane\"\n",
    );
    assert!(e.contains("kane") && e.contains("mixed only"), "{e}");
    let e = refused(
        "name = \"o\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nscheme = \"discrete-gradient\"\n",
    );
    assert!(
        e.contains("discrete-gradient") && e.contains("penalty only"),
        "{e}"
    );
}

#[test]
fn oscillator_runs_without_a_mesh_and_reads_courant_as_omega_tau() {
    // ω = √(k/m) = 2: courant 0.1 is τ = 0.05.
    let p = plan(
        "name = \"o\"\nscene = \"oscillator\"\n[fixed]\ncourant = 0.1\nstiffness = 4.0\n[grid]\nscheme = [\"crank-nicolson\", \"paoli-schatzman\"]\n",
    );
    assert_eq!(p.runs.len(), 2);
    let dt = p.runs[0].params[&Key::Dt].as_f64().unwrap();
    assert!((dt - 0.05).abs() < 1e-15, "dt = {dt}");
    assert_eq!(p.runs[0].params[&Key::Elements], Value::Int(1));
    assert_eq!(p.runs[0].params[&Key::ImpactLaw], Value::Num(1.0));
    assert_eq!(p.runs[0].params[&Key::Velocity], Value::Num(-1.0));
}

#[test]
fn benchmark_sweep_files_plan() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps");
    let load = |name: &str| {
        let path = root.join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let sf = SweepFile::parse(&path, &text).unwrap_or_else(|e| panic!("{e}"));
        sweep::expand(&sf).unwrap_or_else(|e| panic!("{e}"))
    };
    // 7 levels × 3 Courant numbers × 23 methods (16 of contract §2–§3, 7 of §3.2).
    assert_eq!(load("flying_bar.toml").runs.len(), 7 * 3 * 23);
    assert_eq!(load("siconos_impacting_bar.toml").runs.len(), 12);
    // 7 steps × 3 laws × 15 methods (8 of contract §3, 7 of §3.2).
    assert_eq!(load("oscillator.toml").runs.len(), 7 * 3 * 15);
}

/// The summary's convergence tables are per scheme and per exact law: runs with another
/// `impact_law` are another group (the oscillator's rates in τ, issue 21).
#[test]
fn summary_groups_the_oscillator_per_impact_law() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = common::write(
        dir.path(),
        "osc.toml",
        "name = \"osc\"\nscene = \"oscillator\"\nseries_every = 0\n[fixed]\nT = 10.0\nscheme = \"paoli-schatzman\"\nrestitution = 1.0\n[grid]\nimpact_law = [1.0, 0.5]\ncourant = [0.02, 0.01, 0.005]\n",
    );
    let out = dir.path().join("out");
    let o = common::cli(
        dir.path(),
        &[
            "run",
            sweep.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(out.join("summary/convergence.md")).unwrap();
    assert_eq!(md.matches("\n## group").count(), 2, "{md}");
    assert!(
        md.contains("impact_law=1,") && md.contains("impact_law=0.5,"),
        "{md}"
    );
}
