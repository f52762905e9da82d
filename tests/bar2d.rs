//! The 2D and 3D bars dropped on an obstacle (contract §1.2, §6; paper 000 Table 1, paper 002).
//!
//! The target figures come from a GetFEM implementation of the same discretisation (Q1,
//! exact element integration, nodal contact on every bottom node, the same mass layers), so
//! they are matched to 1 %: the only differences left are the reference run's own round-off
//! and the LCP tolerance (1e-12), both far below 1 %.

mod common;

use common::run_sweep_text;
use contact_sweep::run::RunRecord;

fn find<'a>(rows: &'a [RunRecord], mass: &str, scheme: &str, h: f64) -> &'a RunRecord {
    rows.iter()
        .find(|r| r.mass == mass && r.scheme_label == scheme && (r.h - h).abs() < 1e-12)
        .unwrap_or_else(|| panic!("no run {mass} {scheme} h = {h}"))
}

fn ratio(r: &RunRecord) -> f64 {
    r.energy_final.unwrap() / r.energy_initial.unwrap()
}

fn close(x: f64, target: f64, rel: f64, what: &str) {
    assert!(
        ((x - target) / target).abs() <= rel,
        "{what}: {x:.5e}, expected {target:.5e} ± {:.1} %",
        rel * 100.0
    );
}

/// contract §6: L∞(0,T;L2) at h = 0.05, τ = h/2 with CN against the mod3 + CN reference at h/32,
/// τ/32 (82 k dofs, 2560 steps): consistent 9.18e-3, mod1 3.70e-3, mod2 3.69e-3, mod3 1.50e-3.
/// Printed to three digits, so 1 % (the issue's tolerance) also covers the rounding.
#[test]
fn table1_linf_l2_against_the_h_over_32_reference() {
    let rows = run_sweep_text(
        r#"
name = "t1"
scene = "bar2d"
reference = { h = 0.0015625, dt = 0.00078125, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 2.0
h = 0.05
dt = 0.025
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
"#,
    );
    for (mass, target) in [
        ("consistent", 9.18e-3),
        ("mod1", 3.70e-3),
        ("mod2", 3.69e-3),
        ("mod3", 1.50e-3),
    ] {
        let r = find(&rows, mass, "crank-nicolson", 0.05);
        assert_eq!(r.status, "ok", "{:?}", r.message);
        close(r.err_u_linfl2.unwrap(), target, 0.01, mass);
    }
}

/// contract §6 / 002 Figs 1–3: CN with the consistent mass gains energy and chatters — E(T)/E⁰ =
/// 2.75 at h = 0.05, 3.48 at h/2, 4.58 at h/4 (printed to three digits: ±0.5 % covers the
/// rounding) with a contact force switching on and off ≥ 10 times, more under refinement —
/// while the modified masses keep E(T)/E⁰ within 1e-3 of 1 with one clean contact interval
/// (force on once, off once) and backward Euler dissipates to E(T)/E⁰ ≈ 0.57–0.61.
#[test]
fn consistent_mass_with_cn_chatters_and_gains_energy_the_modified_masses_do_not() {
    let rows = run_sweep_text(
        r#"
name = "f13"
scene = "bar2d"
[zip]
h = [0.05, 0.025, 0.0125]
dt = [0.025, 0.0125, 0.00625]
[fixed]
T = 2.0
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
scheme = ["crank-nicolson", "backward-euler"]
"#,
    );
    assert!(rows.iter().all(|r| r.status == "ok"));
    let mut toggles = Vec::new();
    for (h, target) in [(0.05, 2.75), (0.025, 3.48), (0.0125, 4.58)] {
        let r = find(&rows, "consistent", "crank-nicolson", h);
        close(
            ratio(r),
            target,
            0.005,
            &format!("consistent + CN E(T)/E0 at h = {h}"),
        );
        toggles.push(r.contact_toggles.unwrap());
        for mass in ["mod1", "mod2", "mod3"] {
            let r = find(&rows, mass, "crank-nicolson", h);
            assert!(
                (ratio(r) - 1.0).abs() < 1e-3,
                "{mass} h = {h}: {}",
                ratio(r)
            );
            assert_eq!(
                r.contact_toggles,
                Some(2),
                "{mass} h = {h}: one contact interval"
            );
        }
    }
    assert!(toggles[0] >= 10, "{toggles:?}");
    assert!(
        toggles.windows(2).all(|w| w[1] > w[0]),
        "chatter grows: {toggles:?}"
    );
    for mass in ["consistent", "mod1", "mod2", "mod3"] {
        let r = find(&rows, mass, "backward-euler", 0.05);
        let e = ratio(r);
        assert!((0.565..=0.615).contains(&e), "{mass} + BE: E(T)/E0 = {e}");
    }
    // Total mass 1ᵀM1 = ρ·0.1 except mod1, which drops layer 0 (0.1 − 0.1·h).
    for h in [0.05, 0.025, 0.0125] {
        let m = find(&rows, "mod1", "crank-nicolson", h).mass_total.unwrap();
        assert!((m - (0.1 - 0.1 * h)).abs() < 1e-13, "mod1 mass {m}");
        for mass in ["consistent", "mod2", "mod3"] {
            let m = find(&rows, mass, "crank-nicolson", h).mass_total.unwrap();
            assert!((m - 0.1).abs() < 1e-13, "{mass} mass {m}");
        }
    }
}

/// contract §6, 3D at h = 0.05 (τ = h/2), against a mod3 + CN reference at h/4, τ/4 (the setting
/// whose figures the contract quotes): mod3 7.7e-4 < mod2 1.47e-3 < mod1 1.56e-3 in L∞(0,T;L2),
/// consistent + CN E(T)/E⁰ = 2.65. Two or three printed digits: 1 % tolerance.
#[test]
fn bar3d_orders_the_masses_like_2d() {
    let rows = run_sweep_text(
        r#"
name = "b3"
scene = "bar3d"
reference = { h = 0.0125, dt = 0.00625, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 2.0
h = 0.05
dt = 0.025
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
"#,
    );
    let e = |m| find(&rows, m, "crank-nicolson", 0.05).err_u_linfl2.unwrap();
    close(e("mod3"), 7.7e-4, 0.01, "mod3");
    close(e("mod2"), 1.47e-3, 0.01, "mod2");
    close(e("mod1"), 1.56e-3, 0.01, "mod1");
    assert!(e("mod3") < e("mod2") && e("mod2") < e("mod1"));
    close(
        ratio(find(&rows, "consistent", "crank-nicolson", 0.05)),
        2.65,
        0.005,
        "3D consistent + CN E(T)/E0",
    );
    let r = find(&rows, "mod3", "crank-nicolson", 0.05);
    // 3 × 3 nodes on Γ_C, 3 × 3 × 20 free nodes × 3 components.
    assert_eq!((r.contact_dofs, r.dofs), (Some(9), 540));
}

/// The layer weights are one mechanism (contract §2.2): `weights = [2, 1]` is mod3 and
/// `weights = [n_d/(n_d−1)]` is mod2, to the last bit of the error norms (same matrices,
/// same operations). Lumped and zero-contact run too, with the total mass they represent:
/// lumping keeps ρ·|Ω| = 0.1; zero-contact drops the bottom nodes' rows and columns, i.e. the
/// entries of the layer-0 elements that touch a bottom node. The Q1 mass is the tensor product
/// of the 1D (h/6)[2 1; 1 2], so an element's two top nodes keep (4 + 4 + 2 + 2)/36 = ⅓ of its
/// mass: removed = ⅔ · ρ·0.1·h = 0.00333… at h = 0.05.
#[test]
fn weights_reproduce_mod2_and_mod3_and_every_mass_variant_runs() {
    let rows = run_sweep_text(
        r#"
name = "w"
scene = "bar2d"
reference = { h = 0.0125, dt = 0.00625, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 1.0
h = 0.05
dt = 0.025
[grid]
method = [
  { mass = "mod3" },
  { mass = "weights", mass_weights = [2.0, 1.0] },
  { mass = "mod2" },
  { mass = "weights", mass_weights = [1.0526315789473684] },
  { mass = "lumped" },
  { mass = "zero-contact" },
]
"#,
    );
    assert!(rows.iter().all(|r| r.status == "ok"), "{rows:?}");
    let by = |m: &str, w: Option<&str>| {
        rows.iter()
            .find(|r| r.mass == m && r.mass_weights.as_deref() == w)
            .unwrap()
    };
    let mod3 = by("mod3", None);
    let w3 = by("weights", Some("2,1"));
    assert_eq!(mod3.err_u_linfl2, w3.err_u_linfl2);
    assert_eq!(mod3.energy_final, w3.energy_final);
    let mod2 = by("mod2", None);
    let w2 = rows
        .iter()
        .find(|r| r.mass == "weights" && r.mass_weights.as_deref() != Some("2,1"))
        .unwrap();
    // 20/19 is not exact in binary: the weights agree to one rounding, the results to 1e-12.
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    assert!(rel(w2.err_u_linfl2.unwrap(), mod2.err_u_linfl2.unwrap()) < 1e-12);
    assert!((by("lumped", None).mass_total.unwrap() - 0.1).abs() < 1e-14);
    let zc = by("zero-contact", None).mass_total.unwrap();
    assert!(
        (zc - (0.1 - 2.0 / 3.0 * 0.1 * 0.05)).abs() < 1e-14,
        "zero-contact mass {zc}"
    );
}

/// Reference runs through the command line: computed once into DIR/references, reused by the
/// next shard writing into the same folder, and a damaged stored file is recomputed with a
/// warning rather than trusted.
#[test]
fn the_reference_is_computed_once_per_folder_and_reused() {
    use common::{cli, write};
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        r#"
name = "r"
scene = "bar2d"
reference = { h = 0.0125, dt = 0.00625, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 1.0
h = 0.05
dt = 0.025
[grid]
mass = ["mod1", "mod3"]
"#,
    );
    let run = |extra: &[&str]| {
        let mut args = vec!["run", "s.toml", "--out", "o", "--no-summary"];
        args.extend_from_slice(extra);
        let o = cli(tmp.path(), &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let first = run(&["--shard", "0/2"]);
    assert!(
        first.contains("computing") && first.contains("stored in"),
        "{first}"
    );
    let second = run(&["--shard", "1/2"]);
    assert!(
        second.contains("stored, reused") && !second.contains("computing"),
        "{second}"
    );
    let refs = tmp.path().join("o/references");
    let file = std::fs::read_dir(&refs)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "ref"))
        .unwrap();
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
    std::fs::remove_dir_all(tmp.path().join("o/runs")).unwrap();
    std::fs::remove_dir_all(tmp.path().join("o/series")).unwrap();
    let third = run(&[]);
    assert!(
        third.contains("damaged reference") && third.contains("computing"),
        "{third}"
    );
    assert_eq!(
        std::fs::read(&file).unwrap(),
        bytes,
        "recomputed bit for bit"
    );
}

/// Runs with the same matrix (mesh, material, mass, dt, scheme coefficient) share one
/// factorisation: the second finds it in the cache. T and Newmark's γ do not enter
/// A = M + βτ²K, so these three runs need one factorisation in all. (A material value no other
/// test uses keeps the process-wide cache key to this test.)
#[test]
fn runs_with_the_same_matrix_share_one_factorisation() {
    let rows = run_sweep_text(
        r#"
name = "c"
scene = "bar2d"
[fixed]
h = 0.05
dt = 0.025
lame_mu = 0.4375
mass = "mod3"
[grid]
method = [
  { T = 0.5, scheme = "crank-nicolson" },
  { T = 1.0, scheme = "crank-nicolson" },
  { T = 1.0, scheme = "newmark", newmark_beta = 0.25, newmark_gamma = 0.6 },
]
"#,
    );
    let computed: i64 = rows.iter().map(|r| r.factorizations).sum();
    let hits: i64 = rows.iter().map(|r| r.factor_cache_hits.unwrap()).sum();
    assert_eq!((computed, hits), (1, 2), "{rows:?}");
}
