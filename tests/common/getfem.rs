//! The GetFEM checks' shared set-up (tests/getfem_disc.rs, tests/friction_nitsche.rs,
//! tests/getfem_blocks.rs, tests/getfem_nonmatching.rs): the 003 disc as P2 triangles
//! (`sweeps/meshes/disc_p2.msh`), its sweep text for the engine, and the scripts of
//! tests/getfem/ run by Debian's python3-getfem — installed, when missing, by
//! tests/install_getfem.sh (a failed install fails the test: nothing is skipped) — with their
//! JSON read back.

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Gmsh P2 disc both sides read.
pub fn disc_mesh() -> PathBuf {
    root().join("sweeps/meshes/disc_p2.msh")
}

/// The disc's sweep (`mesh2d`, ρ = 1, λ = μ = 20, gravity 0.1, gap 5, τ = 0.1, Crank–Nicolson,
/// the scripts' setting) to `t_final` over the grid's `methods` (TOML inline tables, each
/// followed by a comma).
pub fn disc_sweep(name: &str, methods: &str, t_final: f64) -> String {
    disc_sweep_with(name, r#"scheme = "crank-nicolson""#, methods, t_final)
}

/// [`disc_sweep`] with the fixed line `scheme` (empty: each method sets its scheme).
pub fn disc_sweep_with(name: &str, scheme: &str, methods: &str, t_final: f64) -> String {
    format!(
        r#"
name = "{name}"
scene = "mesh2d"
[fixed]
mesh = "{}"
density = 1.0
lame_lambda = 20.0
lame_mu = 20.0
gravity = 0.1
gap = 5.0
T = {t_final}
dt = 0.1
{scheme}
[grid]
method = [{methods}]
"#,
        disc_mesh().display()
    )
}

/// Run `tests/getfem/SCRIPT MESH OUT.json ARGS…` on the disc with Debian's python3 (installing
/// python3-getfem first if needed) and return the JSON it wrote.
pub fn run_script(script: &str, args: &[String]) -> serde_json::Value {
    run_script_on(script, Some(&disc_mesh()), args)
}

/// Run `tests/getfem/SCRIPT [MESH] OUT.json ARGS…` with Debian's python3 (installing
/// python3-getfem first if needed) and return the JSON it wrote; a script that builds its own
/// meshes (tests/getfem/blocks.py) takes no MESH.
pub fn run_script_on(
    script: &str,
    mesh: Option<&std::path::Path>,
    args: &[String],
) -> serde_json::Value {
    let install = Command::new("bash")
        .arg(root().join("tests/install_getfem.sh"))
        .status()
        .expect("bash");
    assert!(install.success(), "tests/install_getfem.sh failed");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("getfem.json");
    let o = Command::new("/usr/bin/python3")
        .arg(root().join("tests/getfem").join(script))
        .args(mesh)
        .arg(&out)
        .args(args)
        .output()
        .expect("python3");
    assert!(
        o.status.success(),
        "{script}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap()
}

/// A JSON array of numbers.
pub fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|y| y.as_f64().unwrap())
        .collect()
}
