//! One run: a validated [`RunConfig`] in, an [`Outcome`] (the numbers of one row of the runs
//! table, plus the optional time series) out.
//!
//! The run never panics on numerical trouble: a step whose contact equation has no or several
//! solutions ends the run `solver-failed`; a non-finite value or an energy above 1e6·E⁰ ends it
//! `diverged` (SPEC §5); a run past its time budget ends `timeout`. What was observed up to that
//! point is kept.

pub mod bar1d;
pub mod observe;
pub mod record;

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

pub use observe::{Metrics, SeriesRow};
pub use record::{RunRecord, SERIES_COLUMNS};

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
}

/// The validated configuration of one run, per scene.
#[derive(Debug, Clone, PartialEq)]
pub enum RunConfig {
    Bar1d(bar1d::Bar1dConfig),
}

/// What a run produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub status: Status,
    pub message: Option<String>,
    pub metrics: Metrics,
    pub series: Vec<SeriesRow>,
}

/// Run one simulation.
pub fn simulate(config: &RunConfig, options: &RunOptions) -> Outcome {
    match config {
        RunConfig::Bar1d(c) => bar1d::simulate(c, options),
    }
}
