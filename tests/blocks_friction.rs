//! Friction between two bodies (contract §2.5, §2.6; issue 44): `blocks2d`/`blocks3d` with a
//! matching interface, Coulomb and Tresca acting on the relative slip (u^a − u^b∘π)_t through
//! the tangential rows e_{a,i,t} − e_{b,π(i),t}.

use std::path::Path;

use contact_sweep::run::{Outcome, RunOptions, Status, simulate};
use contact_sweep::sweep::{SweepFile, expand};

/// Every run of a sweep text, with its label (the run's parameters as the planner lists them).
fn run_all(text: &str) -> Vec<(String, Outcome)> {
    let plan = expand(&SweepFile::parse(Path::new("blocks_friction.toml"), text).expect("valid"))
        .expect("plan");
    assert!(!plan.runs.is_empty(), "{text}");
    plan.runs
        .iter()
        .map(|spec| {
            let label = format!("{:?}", spec.params);
            (label, simulate(&spec.config, &RunOptions::default()))
        })
        .collect()
}

#[test]
fn explore() {
    let text = "name = \"x\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.8\nh = 0.25\ndt = 0.02\nvelocity = -1.0\nvelocity_tangential = 0.7\nvelocity_b = 0.2\ngap = 0.05\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n[grid]\nspace = [\"mixed\", { space = \"penalty\", penalty_gamma0 = 10.0 }]\nmethod = [{ scheme = \"newmark\", newmark_beta = 0.3, newmark_gamma = 0.6 }, { scheme = \"crank-nicolson\" }, { scheme = \"theta\", theta_scheme = 0.6 }, { scheme = \"backward-euler\" }, { scheme = \"kane\" }, { scheme = \"contact-stabilized-newmark\" }, { scheme = \"generalized-alpha\", rho_inf = 0.5 }, { scheme = \"hht\", hht_alpha = 0.1 }, { scheme = \"moreau-jean\", restitution = 0.0 }]\nmass = [\"consistent\", \"lumped\", \"zero-contact\"]\n";
    for (label, o) in run_all(text) {
        let m = &o.metrics;
        eprintln!(
            "{label}: {:?} {:?} drift {:?} stick {:?} slip {:?} wf {:?} vt {:?} phases {:?}",
            o.status,
            o.message,
            m.momentum_drift,
            m.stick_steps,
            m.slip_steps,
            m.friction_work,
            m.tangential_velocity_final,
            m.contact_phases
        );
    }
}

#[allow(dead_code)]
fn ok(o: &Outcome) -> bool {
    o.status == Status::Ok
}
