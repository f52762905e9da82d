//! exploration (temporary)
use std::path::{Path, PathBuf};

use contact_sweep::run::{Outcome, RunOptions};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run_all(path: &Path, text: &str) -> Vec<(String, Outcome)> {
    let plan = contact_sweep::sweep::expand(
        &contact_sweep::sweep::SweepFile::parse(path, text).expect("valid sweep"),
    )
    .expect("plan");
    plan.runs
        .iter()
        .map(|spec| {
            let t = std::time::Instant::now();
            let o = contact_sweep::run::simulate_with(
                &spec.config,
                &RunOptions {
                    series_every: 1,
                    ..RunOptions::default()
                },
                &Default::default(),
            );
            eprintln!(
                "{:60} {:8} {:.2}s it {} max {:?} stick {:?} slip {:?} vt {:?} {:?}",
                spec.label,
                o.status.as_str(),
                t.elapsed().as_secs_f64(),
                o.metrics.iterations,
                o.metrics.iterations_max_step,
                o.metrics.stick_steps,
                o.metrics.slip_steps,
                o.metrics.tangential_velocity_final,
                o.message
            );
            (spec.label.clone(), o)
        })
        .collect()
}

fn block(extra_fixed: &str, grid: &str) -> String {
    format!(
        r#"
name = "block"
scene = "mesh2d"
[fixed]
mesh = "meshes/block2d.msh"
density = 1.0
lame_lambda = 10.0
lame_mu = 10.0
gravity = 0.1
gap = 0.0
{extra_fixed}
[grid]
{grid}
"#
    )
}

#[test]
#[ignore]
fn explore() {
    let path = root().join("sweeps/x.toml");
    let case = std::env::var("CASE").unwrap_or_default();
    let text = match case.as_str() {
        "tresca" => block(
            "velocity_tangential = 0.5\nfriction = \"tresca\"\nT = 50.0\ndt = 0.05",
            r#"incline = [0.0, 5.0]
tresca_threshold = [0.01, 0.02, 0.03, 0.04, 0.05]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "crank-nicolson" },
]"#,
        ),
        "stick" => block(
            "velocity_tangential = 0.01\nfriction = \"coulomb\"\nT = 5.0\ndt = 0.05",
            r#"friction_coefficient = [1.0, 2.0, 5.0]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-4, scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-4, scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = -1.0, nitsche_gamma0 = 1e-4, scheme = "backward-euler" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 1000.0, scheme = "backward-euler" },
]"#,
        ),
        "named" => {
            let disc = format!(
                r#"
name = "disc-incline"
scene = "mesh2d"
[fixed]
mesh = "{}"
density = 1.0
lame_lambda = 20.0
lame_mu = 20.0
gravity = 0.1
gap = 5.0
T = 15.0
dt = 0.1
incline = 26.0
friction = "coulomb"
friction_coefficient = 0.86
[grid]
velocity_tangential = [0.0, 0.5]
method = [
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = "crank-nicolson" }},
  {{ space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-3, scheme = "crank-nicolson" }},
]
"#,
                root().join("sweeps/meshes/disc_p2.msh").display()
            );
            run_all(&path, &disc);
            run_all(
                &path,
                &block(
                    "incline = 18.0\nfriction = \"coulomb\"\nfriction_coefficient = 0.61\nT = 5.0\ndt = 0.05",
                    r#"velocity_tangential = [0.01, 0.05]
method = [
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "hht", hht_alpha = 0.1 },
  { space = "penalty", penalty_gamma0 = 1000.0, scheme = "hht", hht_alpha = 0.3 },
]"#,
                ),
            );
            block(
                "velocity_tangential = 0.5\nfriction = \"coulomb\"\nT = 10.0\ndt = 0.05\nmass = \"mod3\"",
                r#"friction_coefficient = [0.2, 0.5, 0.917]
incline = [0.0, 5.0]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = "backward-euler" },
  { space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-3, scheme = "backward-euler" },
]"#,
            )
        }
        _ => std::env::var("TEXT").expect("CASE or TEXT"),
    };
    run_all(&path, &text);
}
