//! The time loop's frame shared by the 1D engines (bar1d, layer1d, the oscillator): what every
//! run does around its steps, whatever it steps.
//!
//! A run builds its operators (an early failure is a row without series, [`failed`]), then
//! [`time_loop`] records the set-up time, hands the engine's loop a [`Clock`] — which times the
//! observation of one step in 64 ([`SampledTimer`]) and looks at the wall clock and the sweep's
//! interruption every few steps ([`RunOptions::step_stop`]) — and turns the way the loop ended
//! into the run's status and message ([`Stop::status`]): `steps` is the last step completed.
//! The engine's arithmetic stays in its own file; this frame only counts, times and stops, so
//! moving a loop into it changes no number.

use std::time::Instant;

use super::observe::{Divergence, Observer, SampledTimer};
use super::{Metrics, Outcome, RunOptions, Series, Status, Stop};
use crate::contact::ContactSolveError;

/// How a 1D loop's body ends: completed, or stopped by a step.
pub(super) type LoopEnd = Result<(), Stop<ContactSolveError>>;

/// The row of a run that stopped before its time loop: its status, message and the metrics of
/// the set-up so far, no series.
pub(super) fn failed(status: Status, message: String, metrics: Metrics) -> Outcome {
    Outcome {
        status,
        message: Some(message),
        metrics,
        series: Series::default(),
        reference: None,
    }
}

/// The row of a run whose loop ran: the observer's series with the loop's status.
pub(super) fn finished(
    status: Status,
    message: Option<String>,
    metrics: Metrics,
    obs: &mut Observer,
) -> Outcome {
    Outcome {
        status,
        message,
        metrics,
        series: std::mem::take(&mut obs.series),
        reference: None,
    }
}

/// The loop's bookkeeping, handed to the engine's loop body.
pub(super) struct Clock<'a> {
    opts: &'a RunOptions,
    start: Instant,
    /// Steps between two looks at the wall clock.
    every: usize,
    /// The last step completed.
    done: usize,
    timer: SampledTimer,
}

impl Clock<'_> {
    /// Observe step `n` (timed when the step is sampled); a divergence stops the loop.
    pub(super) fn observe(
        &mut self,
        n: usize,
        observe: impl FnOnce() -> Result<(), Divergence>,
    ) -> LoopEnd {
        self.timer.time(n, observe).map_err(Stop::Diverged)
    }

    /// Step `n` is complete: count it, then stop if the time budget is spent or the sweep was
    /// interrupted (looked at every `every` steps).
    pub(super) fn completed(&mut self, n: usize) -> LoopEnd {
        self.done = n;
        self.opts.step_stop(n, self.every, self.start)
    }
}

/// What the loop ended with: the run's status and message and the last step completed.
pub(super) struct LoopResult {
    pub status: Status,
    pub message: Option<String>,
    pub done: usize,
}

/// Run the time loop `body` of a run started at `start` (its set-up done): the set-up, stepping
/// and observation times, `steps` (the last step completed) and, for a solver failure,
/// `solver_failures` go into `metrics`. `tau` and `steps` (the planned number) are for the
/// status message; `every` is how many steps pass between two looks at the clock.
pub(super) fn time_loop(
    opts: &RunOptions,
    start: Instant,
    (every, tau, steps): (usize, f64, usize),
    metrics: &mut Metrics,
    body: impl FnOnce(&mut Clock, &mut Metrics) -> LoopEnd,
) -> LoopResult {
    metrics.setup_time_s = Some(start.elapsed().as_secs_f64());
    let loop_start = Instant::now();
    let mut clock = Clock {
        opts,
        start,
        every,
        done: 0,
        timer: SampledTimer::default(),
    };
    let end = body(&mut clock, metrics);
    metrics.steps = clock.done as i64;
    metrics.stepping_time_s = Some(loop_start.elapsed().as_secs_f64());
    metrics.observe_time_s = clock.timer.estimate_s();
    let (status, message) = Stop::status(end, tau, steps, start, metrics);
    LoopResult {
        status,
        message,
        done: clock.done,
    }
}
