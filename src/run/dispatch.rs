//! Running a configuration: each family's engine, alone or in a lockstep group of runs sharing
//! their step matrix. The top of `run/`: it calls the engines, none of them calls it.

use super::config::RunConfig;
use super::outcome::{Outcome, RunContext, RunOptions};
use super::{bar1d, bars1d, fe, layer1d, oscillator};

/// Run one simulation.
pub fn simulate(config: &RunConfig, options: &RunOptions) -> Outcome {
    simulate_with(config, options, &RunContext::default())
}

/// Run one simulation with its reference solution (or recording itself as one).
pub fn simulate_with(config: &RunConfig, options: &RunOptions, ctx: &RunContext) -> Outcome {
    match config {
        RunConfig::Bar1d(c) => bar1d::simulate(c, options),
        RunConfig::Fe(c) => fe::simulate(c, options, ctx),
        RunConfig::Oscillator(c) => oscillator::simulate(c, options),
        RunConfig::Layer1d(c) => layer1d::simulate(c, options),
        RunConfig::Bars1d(c) => bars1d::simulate(c, options),
    }
}

/// The key of the lockstep groups a run may join: runs with equal keys share their step matrix
/// and may make their step solves together ([`simulate_group`]). `None` for runs that step
/// alone: the 1D engines (a tridiagonal solve is not memory-bound) and the FE runs whose loop
/// has no shared solve ([`fe::lockstep_key`]).
pub fn lockstep_key(config: &RunConfig) -> Option<String> {
    match config {
        RunConfig::Fe(c) => fe::lockstep_key(c),
        RunConfig::Bar1d(_)
        | RunConfig::Oscillator(_)
        | RunConfig::Layer1d(_)
        | RunConfig::Bars1d(_) => None,
    }
}

/// Run configurations sharing a [`lockstep_key`] together, each with its context: the outcomes
/// in order, each equal to its run alone to round-off (its `lockstep` metric set to the group's
/// size). A configuration without the group's key is run alone.
pub fn simulate_group(
    configs: &[&RunConfig],
    options: &RunOptions,
    ctxs: &[RunContext],
) -> Vec<Outcome> {
    let fe: Option<Vec<&fe::FeConfig>> = configs
        .iter()
        .map(|c| match c {
            RunConfig::Fe(f) => Some(f),
            _ => None,
        })
        .collect();
    let same = configs
        .first()
        .and_then(|c| lockstep_key(c))
        .is_some_and(|k| configs.iter().all(|c| lockstep_key(c).as_ref() == Some(&k)));
    match fe {
        Some(fe) if same && fe.len() > 1 => {
            let mut out = fe::simulate_group(&fe, options, ctxs);
            for o in &mut out {
                o.metrics.lockstep = Some(fe.len() as i64);
            }
            out
        }
        _ => configs
            .iter()
            .zip(ctxs)
            .map(|(c, ctx)| simulate_with(c, options, ctx))
            .collect(),
    }
}
