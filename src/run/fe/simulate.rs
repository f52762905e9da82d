//! The engine's entry points: route one run to its time loop (the lockstep stepper alone, or a
//! contract §3.2 method), refuse the friction combinations without a frictional version, and run
//! groups sharing a step matrix together.

use std::sync::Arc;

use super::config::{FeConfig, frictional, handles, mixed_stepper};
use super::lockstep::step_together;
use super::methods;
use super::newmark::Stepper;
use crate::run::{Metrics, Outcome, RunContext, RunOptions, Series, Status};
use crate::space::ContactMethod;
use crate::time::Scheme;

/// Run one finite-element simulation.
pub fn simulate(cfg: &FeConfig, opts: &RunOptions, ctx: &RunContext) -> Outcome {
    // The methods of contract §3.2 solve friction with the nodal multiplier in their own loops.
    if frictional(cfg) && handles(cfg) && cfg.method == ContactMethod::Mixed {
        return methods::simulate(cfg, opts, ctx);
    }
    // Friction is solved by Nitsche and the penalty with the Newmark family and θ-schemes
    // (nitsche.rs header) and with generalized-α/HHT (methods header, the same frictional
    // Newton), by the mixed method in [`Stepper`] and in the §3.2 methods' loops.
    let nitsche_solved = cfg.method != ContactMethod::Mixed
        && (matches!(cfg.scheme, Scheme::Newmark(_) | Scheme::Theta(_)) && !handles(cfg)
            || matches!(cfg.scheme, Scheme::GeneralizedAlpha(_)));
    if frictional(cfg) && !mixed_stepper(cfg) && !nitsche_solved {
        return Outcome {
            status: Status::Invalid,
            message: Some(format!(
                "friction = {} with space = {} and scheme = {} has no frictional version (contract §2.5)",
                cfg.friction.kind().name(),
                cfg.method.name(),
                cfg.scheme.label()
            )),
            metrics: Metrics::default(),
            series: Series::default(),
            reference: None,
        };
    }
    if handles(cfg) {
        return methods::simulate(cfg, opts, ctx);
    }
    // Alone is a lockstep group of one: the same loop, each solve with the run's own work
    // (CG warm-starts from its previous step).
    match Stepper::new(cfg, opts, ctx) {
        Err(out) => *out,
        Ok(s) => {
            let mut done = step_together(vec![(0, s)]);
            done.pop().expect("one member, one outcome").1
        }
    }
}

/// Run `cfgs` (which share a [`super::lockstep::lockstep_key`]) in lockstep, each with its context; the
/// outcomes in the order of `cfgs`. The caller times the whole group; each member's
/// `stepping_time_s` is the group's stepping time divided among the members.
pub fn simulate_group(cfgs: &[&FeConfig], opts: &RunOptions, ctxs: &[RunContext]) -> Vec<Outcome> {
    assert_eq!(cfgs.len(), ctxs.len(), "one context per member");
    let mut outcomes: Vec<Option<Outcome>> = vec![None; cfgs.len()];
    // Members set up, by their shared factor.
    let mut groups: Vec<Vec<(usize, Stepper)>> = Vec::new();
    for (i, (cfg, ctx)) in cfgs.iter().zip(ctxs).enumerate() {
        if handles(cfg) {
            outcomes[i] = Some(simulate(cfg, opts, ctx));
            continue;
        }
        match Stepper::new(cfg, opts, ctx) {
            Err(out) => outcomes[i] = Some(*out),
            Ok(s) => match groups.iter_mut().find(|g| Arc::ptr_eq(&g[0].1.fac, &s.fac)) {
                Some(g) => g.push((i, s)),
                None => groups.push(vec![(i, s)]),
            },
        }
    }
    for group in groups {
        for (i, out) in step_together(group) {
            outcomes[i] = Some(out);
        }
    }
    outcomes
        .into_iter()
        .map(|o| o.expect("every member has an outcome"))
        .collect()
}
