//! `bars1d`'s bad inputs (contract §7, issue 44): a second body's key on a one-body scene,
//! negative lengths and moduli, overlapping bodies, a clamped far end with a velocity, and the
//! methods the two-bar engine does not take — each refused before anything runs, with exit
//! status 2 and a message naming the file, the key and the reason. And the two sweeps of
//! §1.9 plan, and their runs fill the two-body columns.

mod common;

use common::{cli, write};

/// (file body, key the message must name, a phrase of the reason)
const CASES: &[(&str, &str, &str)] = &[
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nlength_b = 2.0\n",
        "fixed.length_b",
        "`length_b` is not a parameter of scene bar1d (scenes that take it: bars1d)",
    ),
    (
        "name = \"x\"\nscene = \"layer1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nvelocity_b = 1.0\n",
        "fixed.velocity_b",
        "`velocity_b` is not a parameter of scene layer1d (scenes that take it: mesh2d, mesh3d, bars1d, blocks2d, blocks3d)",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[grid]\nmass_side = [\"a\"]\n",
        "grid.mass_side[0]",
        "`mass_side` is not a parameter of scene bar2d",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nnitsche_sides = \"a\"\n",
        "fixed.nitsche_sides",
        "`nitsche_sides` is not a parameter of scene bar1d",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nyoung_b = -1.0\n",
        "fixed.young_b",
        "must be > 0, got -1",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nlength = -2.0\n",
        "fixed.length",
        "must be > 0, got -2",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\n[grid]\ndensity_b = [1.0, 0.0]\n",
        "grid.density_b[1]",
        "must be > 0, got 0",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\ngap = -0.1\n",
        "fixed.gap",
        "must be ≥ 0, got -0.1",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nfar_end = \"clamped\"\nvelocity_b = 0.5\n",
        "fixed.velocity_b",
        "a clamped bar starts at rest",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nfar_end = \"pinned\"\n",
        "fixed.far_end",
        "unknown far_end `pinned` (expected free or clamped",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nmass_side = \"c\"\n",
        "fixed.mass_side",
        "unknown mass_side `c` (expected both or a or b",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n",
        "fixed.friction",
        "scene bars1d has no tangential direction",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nscheme = \"paoli-schatzman\"\n",
        "fixed.scheme",
        "scheme = paoli-schatzman is not available for scene bars1d",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.01\nmass = \"lumped\"\nscheme = \"central-difference\"\n",
        "fixed.scheme",
        "bars1d steps the implicit schemes only",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nspace = \"mixed\"\nmass = \"zero-contact\"\nscheme = \"hybrid\"\n",
        "fixed.space",
        "scheme = hybrid on bars1d takes nitsche or penalty",
    ),
    (
        "name = \"x\"\nscene = \"bars1d\"\n[fixed]\nelements = 10\ndt = 0.1\nlength_b = 0.1\n",
        "fixed.elements",
        "bar B gets round(elements·length_b/length) = 1 elements",
    ),
];

#[test]
fn every_bad_bars1d_input_is_refused_with_the_key_and_exit_2() {
    let tmp = tempfile::tempdir().unwrap();
    for (i, (body, key, reason)) in CASES.iter().enumerate() {
        let file = format!("bad{i}.toml");
        write(tmp.path(), &file, body);
        let o = cli(tmp.path(), &["plan", file.as_str()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "case {i}: stderr:\n{err}");
        assert!(!err.contains("panicked"), "case {i}: panic\n{err}");
        assert!(err.contains(&file), "case {i}: file not named\n{err}");
        assert!(
            err.contains(&format!("`{key}`")),
            "case {i}: key `{key}` not named\n{err}"
        );
        assert!(err.contains(reason), "case {i}: reason missing\n{err}");
    }
}

/// The two sweeps of contract §1.9 plan as committed: the table's five rows and the clamped
/// case on six meshes, and SDNL111's two readings.
#[test]
fn the_two_bar_sweeps_plan() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for (file, runs) in [("sweeps/two_bars.toml", 36), ("sweeps/sdnl111.toml", 2)] {
        let o = cli(root, &["plan", file]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{file}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            out.contains(&format!("→ {runs} runs")),
            "{file}: expected {runs} runs\n{out}"
        );
    }
}

/// A planned bars1d run fills the two-body columns: both mean velocities, the momentum drift
/// (free ends; null with the clamp), the physics keys as written, and the series'
/// `u_contact_b` and `momentum` at every kept step. Equal bars with `mixed` and the consistent
/// mass: P = 1 (m_a V) to round-off, 1e-12 (the drift test's bound).
#[test]
fn a_bars1d_run_fills_the_two_body_columns() {
    use contact_sweep::run::{RunOptions, RunRecord, record::Timing, simulate};
    use contact_sweep::sweep::{SweepFile, expand};
    let text = "name = \"t\"\nscene = \"bars1d\"\n[fixed]\nT = 3.0\nelements = 20\ncourant = 0.5\n[grid]\nfar_end = [\"free\", \"clamped\"]\n";
    let plan = expand(&SweepFile::parse(std::path::Path::new("t.toml"), text).unwrap()).unwrap();
    let timing = Timing {
        median_s: 0.0,
        min_s: 0.0,
        max_s: 0.0,
        repeats: 1,
    };
    let rows: Vec<(RunRecord, contact_sweep::run::Series)> = plan
        .runs
        .iter()
        .map(|spec| {
            let out = simulate(&spec.config, &RunOptions::default());
            (RunRecord::new("t", spec, &out, timing), out.series)
        })
        .collect();
    let (free, series) = &rows[0];
    assert_eq!(free.status, "ok");
    assert_eq!(free.far_end.as_deref(), Some("free"));
    assert_eq!(free.mass_side.as_deref(), Some("both"));
    // B's length defaults to A's (contract §1.9): not given, so its column is null.
    assert_eq!(free.length_b, None);
    assert!(free.momentum_drift.unwrap() <= 1e-12);
    assert!(free.velocity_a_final.is_some() && free.velocity_b_final.is_some());
    for r in series.rows() {
        assert!((r.momentum.unwrap() - 1.0).abs() <= 1e-12, "{r:?}");
        assert!(r.u_contact_b.is_some());
    }
    let (clamped, _) = &rows[1];
    assert_eq!(clamped.far_end.as_deref(), Some("clamped"));
    assert_eq!(clamped.momentum_drift, None);
}

/// B's material keys default to A's values (contract §1.9): A of length 2, modulus 4 and
/// density 3 with B's keys omitted is the run with B's keys written equal to A's — the same
/// numbers bit for bit (the same parameters reach the engine), under different ids (the
/// written keys enter the id), and the omitted ones leave B's columns null. Equal bars leave
/// A at rest and B at A's speed (contract §1.9's first row), so v̄_b is near V = 1 (within
/// 2e-2 at 20 elements: the two-bar test's errors are 1e-2 at that level).
#[test]
fn b_material_defaults_to_a() {
    let text = "name = \"t\"\nscene = \"bars1d\"\n[fixed]\nT = 6.0\nelements = 20\ncourant = 1.0\nmass = \"zero-contact\"\nscheme = \"crank-nicolson\"\nlength = 2.0\nyoung = 4.0\ndensity = 3.0\n[grid]\ncase = [{}, { length_b = 2.0, young_b = 4.0, density_b = 3.0 }]\n";
    let rec = common::run_sweep_text(text);
    assert_eq!(rec.len(), 2);
    let (omitted, written) = (&rec[0], &rec[1]);
    assert_eq!(omitted.status, "ok");
    assert_ne!(omitted.run_id, written.run_id);
    assert_eq!(
        (omitted.length_b, omitted.young_b, omitted.density_b),
        (None, None, None)
    );
    assert_eq!(written.length_b, Some(2.0));
    for (a, b) in [
        (omitted.velocity_a_final, written.velocity_a_final),
        (omitted.velocity_b_final, written.velocity_b_final),
        (omitted.energy_final, written.energy_final),
        (omitted.momentum_drift, written.momentum_drift),
    ] {
        assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
    }
    assert!((omitted.velocity_b_final.unwrap() - 1.0).abs() < 2e-2);
}
