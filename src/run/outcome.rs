//! What every engine shares about one run, below the engines: its status, the options that
//! change what is recorded or how long it may take, its context (reference solution), why a
//! time loop stopped, and the outcome it hands back. Low in `run/`: the engines read these,
//! nothing here reads an engine.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use super::observe::{Metrics, Series};

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

/// What a run receives besides its configuration: the reference solution its errors are
/// measured against, and whether it must record itself as a reference for others.
#[derive(Debug, Clone, Default)]
pub struct RunContext {
    pub reference: Option<std::sync::Arc<super::reference::ReferenceData>>,
    /// Record the solution on this lattice (space stride, time stride).
    pub record_reference: Option<(usize, usize)>,
}

/// Why an engine's time loop stopped before its last step.
pub(crate) enum Stop<E> {
    /// The contact problem of this step had no (or several) solutions.
    Solver(usize, E),
    Diverged(super::observe::Divergence),
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
    pub reference: Option<super::reference::ReferenceData>,
}
