//! One run: a validated [`RunConfig`] in, an [`Outcome`] (the numbers of one row of the runs
//! table, plus the optional time series) out.
//!
//! The run never panics on numerical trouble: a step whose contact equation has no or several
//! solutions ends the run `solver-failed`; a non-finite value or an energy above 1e6·E⁰ ends it
//! `diverged` (SPEC §5); a run past its time budget ends `timeout`. What was observed up to that
//! point is kept.

pub mod bar1d;
pub mod estimate;
pub mod fe;
mod fe_nitsche;
pub mod friction_tally;
pub mod impacts;
pub mod layer1d;
pub mod observe;
pub mod oscillator;
pub mod record;
pub mod reference;
mod spec;
mod stepping;

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crate::scene::SceneSetup;
use crate::space::{ContactInit, ContactMethod, MassVariant};
use crate::time::Scheme;

pub use observe::{Metrics, Series, SeriesRow};
pub use record::{RunRecord, SERIES_COLUMNS};
pub use spec::RunSpec;

/// A finished run: its row and its (possibly decimated) time series — what the executor hands
/// the sink.
#[derive(Debug, Clone)]
pub struct RunResult {
    pub record: RunRecord,
    pub series: Series,
}

/// Final state of a run (the `status` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Status {
    Ok,
    Diverged,
    SolverFailed,
    Invalid,
    Timeout,
    /// Interrupted (Ctrl-C, or the scheduler's SIGTERM): never written — the run is redone when
    /// the sweep resumes.
    Cancelled,
}

impl Status {
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Diverged => "diverged",
            Status::SolverFailed => "solver-failed",
            Status::Invalid => "invalid",
            Status::Timeout => "timeout",
            Status::Cancelled => "cancelled",
        }
    }
}

/// Options that change what is recorded or how long a run may take, never its numbers.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// Keep every k-th step in the time series (0: none). Step 0 and the last step are always
    /// kept when k > 0.
    pub series_every: usize,
    pub timeout: Option<Duration>,
    /// Set by a signal handler: runs in flight stop at their next clock check.
    pub cancel: Option<&'static AtomicBool>,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            series_every: 1,
            timeout: None,
            cancel: None,
        }
    }
}

impl RunOptions {
    /// Whether the sweep was interrupted.
    pub fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// The time loop's checkpoint, looked at every `every` steps (reading the clock each step
    /// would cost more than a 1D step): the time budget and an interruption of the sweep.
    pub(crate) fn step_stop<E>(
        &self,
        step: usize,
        every: usize,
        start: std::time::Instant,
    ) -> Result<(), Stop<E>> {
        if !step.is_multiple_of(every) {
            return Ok(());
        }
        if self.cancelled() {
            return Err(Stop::Cancelled);
        }
        if self.timeout.is_some_and(|limit| start.elapsed() > limit) {
            return Err(Stop::Timeout(step));
        }
        Ok(())
    }

    /// A checkpoint of the setup (between its allocation-heavy phases: operators, factors,
    /// workspace): the time budget covers the setup too, and an interruption (the scheduler's
    /// SIGTERM) must not wait for the time loop. `phase` is what was just built.
    pub(crate) fn setup_stop(
        &self,
        start: std::time::Instant,
        phase: &str,
    ) -> Option<(Status, String)> {
        if self.cancelled() {
            return Some((Status::Cancelled, "interrupted".into()));
        }
        self.timeout
            .filter(|limit| start.elapsed() > *limit)
            .map(|_| {
                (
                    Status::Timeout,
                    format!(
                        "run timeout after {:.3} s during setup (after {phase}, before the first step)",
                        start.elapsed().as_secs_f64()
                    ),
                )
            })
    }
}

/// The validated configuration of one run, per discretisation family: the tridiagonal 1D
/// engine or the sparse finite-element engine (which runs every FE scene).
#[derive(Debug, Clone, PartialEq)]
pub enum RunConfig {
    Bar1d(bar1d::Bar1dConfig),
    Fe(fe::FeConfig),
    Oscillator(oscillator::OscillatorConfig),
    Layer1d(layer1d::Layer1dConfig),
}

impl RunConfig {
    /// The run of a scene's setup with a contact method, mass, scheme and step.
    pub fn new(
        setup: SceneSetup,
        method: ContactMethod,
        mass: MassVariant,
        scheme: Scheme,
        dt: f64,
        steps: usize,
    ) -> RunConfig {
        match setup {
            SceneSetup::Bar1d { bar, elements } => RunConfig::Bar1d(bar1d::Bar1dConfig {
                bar,
                elements,
                dt,
                steps,
                method,
                mass,
                scheme,
                contact_init: ContactInit::Consistent,
                perturbation: None,
            }),
            SceneSetup::Fe(setup) => RunConfig::Fe(fe::FeConfig {
                setup,
                method,
                mass,
                scheme,
                dt,
                steps,
                solver: crate::space::step_solver::Solver::Direct,
                perturbation: None,
                friction: crate::contact::friction::FrictionLaw::None,
            }),
            // The oscillator's one dof is its mass: no mass variant to keep.
            SceneSetup::Oscillator(params) => RunConfig::Oscillator(oscillator::OscillatorConfig {
                params,
                method,
                scheme,
                dt,
                steps,
                perturbation: None,
            }),
            SceneSetup::Layer1d { layer, elements } => RunConfig::Layer1d(layer1d::Layer1dConfig {
                layer,
                elements,
                dt,
                steps,
                method,
                mass,
                scheme,
                perturbation: None,
            }),
        }
    }

    /// The friction law at the contact (SPEC §2.5). Only the layer has a tangential direction
    /// today; the planner refuses a law ≠ none on every other scene before a config is built,
    /// so for them the law is none and nothing changes.
    pub fn with_friction(mut self, law: crate::contact::friction::FrictionLaw) -> RunConfig {
        match &mut self {
            RunConfig::Layer1d(c) => c.layer.friction = law,
            RunConfig::Fe(c) => c.friction = law,
            _ => {}
        }
        self
    }

    /// The initial value of a massless contact node (SPEC §2.2). The FE scenes start from
    /// rest and unloaded, where the interpolant of u⁰ = 0 is already the quasi-static value:
    /// both starts are the same state there.
    pub fn with_contact_init(mut self, init: ContactInit) -> RunConfig {
        if let RunConfig::Bar1d(c) = &mut self {
            c.contact_init = init;
        }
        self
    }

    /// How the step systems of a finite-element run are solved (the 1D engines' tridiagonal
    /// solves have no choice: unchanged).
    pub fn with_solver(mut self, solver: crate::space::step_solver::Solver) -> RunConfig {
        if let RunConfig::Fe(c) = &mut self {
            c.solver = solver;
        }
        self
    }

    /// Ensemble member: relative amplitude of a perturbation of u⁰ and its seed.
    pub fn set_perturbation(&mut self, p: Option<(f64, u64)>) {
        match self {
            RunConfig::Bar1d(c) => c.perturbation = p,
            RunConfig::Fe(c) => c.perturbation = p,
            RunConfig::Oscillator(c) => c.perturbation = p,
            RunConfig::Layer1d(c) => c.perturbation = p,
        }
    }

    /// The largest stable dt of an explicit scheme, from the assembled operators (None for
    /// implicit schemes); `Err` names the key at fault and why the operators cannot be built
    /// or the scheme cannot run.
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        match self {
            RunConfig::Bar1d(c) => c.explicit_dt_limit(),
            RunConfig::Fe(c) => c.explicit_dt_limit(),
            RunConfig::Oscillator(c) => c.explicit_dt_limit(),
            RunConfig::Layer1d(c) => c.explicit_dt_limit(),
        }
    }

    /// Work estimate: steps × unknowns (saturating: a refused run may exceed u64).
    pub fn work(&self) -> u64 {
        let (steps, unknowns) = match self {
            RunConfig::Bar1d(c) => (c.steps, c.elements),
            RunConfig::Fe(c) => (c.steps, c.unknowns()),
            RunConfig::Oscillator(c) => (c.steps, 1),
            RunConfig::Layer1d(c) => (c.steps, 2 * c.elements),
        };
        (steps as u64).saturating_mul(unknowns as u64)
    }
}

/// What a run receives besides its configuration: the reference solution its errors are
/// measured against, and whether it must record itself as a reference for others.
#[derive(Debug, Clone, Default)]
pub struct RunContext {
    pub reference: Option<std::sync::Arc<reference::ReferenceData>>,
    /// Record the solution on this lattice (space stride, time stride).
    pub record_reference: Option<(usize, usize)>,
}

/// Why an engine's time loop stopped before its last step.
pub(crate) enum Stop<E> {
    /// The contact problem of this step had no (or several) solutions.
    Solver(usize, E),
    Diverged(observe::Divergence),
    Timeout(usize),
    Cancelled,
}

impl<E: std::fmt::Display> Stop<E> {
    /// The run's status and message for how its loop ended (`tau` and `steps` for the
    /// message); a solver failure is counted in `metrics`.
    pub(crate) fn status(
        end: Result<(), Stop<E>>,
        tau: f64,
        steps: usize,
        start: std::time::Instant,
        metrics: &mut Metrics,
    ) -> (Status, Option<String>) {
        match end {
            Ok(()) => (Status::Ok, None),
            Err(Stop::Solver(n, e)) => {
                metrics.solver_failures = 1;
                (
                    Status::SolverFailed,
                    Some(format!("step {n} (t = {:.6}): {e}", n as f64 * tau)),
                )
            }
            Err(Stop::Diverged(d)) => (Status::Diverged, Some(d.0)),
            Err(Stop::Cancelled) => (Status::Cancelled, Some("interrupted".into())),
            Err(Stop::Timeout(n)) => (
                Status::Timeout,
                Some(format!(
                    "run timeout after {:.3} s at step {n} of {steps}",
                    start.elapsed().as_secs_f64()
                )),
            ),
        }
    }
}

/// What a run produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub status: Status,
    pub message: Option<String>,
    pub metrics: Metrics,
    pub series: Series,
    /// The recorded solution, when the context asked for it.
    pub reference: Option<reference::ReferenceData>,
}

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
    }
}

/// The key of the lockstep groups a run may join: runs with equal keys share their step matrix
/// and may make their step solves together ([`simulate_group`]). `None` for runs that step
/// alone: the 1D engines (a tridiagonal solve is not memory-bound) and the FE runs whose loop
/// has no shared solve ([`fe::lockstep_key`]).
pub fn lockstep_key(config: &RunConfig) -> Option<String> {
    match config {
        RunConfig::Fe(c) => fe::lockstep_key(c),
        RunConfig::Bar1d(_) | RunConfig::Oscillator(_) | RunConfig::Layer1d(_) => None,
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
