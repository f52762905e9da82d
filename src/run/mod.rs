//! One run: a validated [`RunConfig`] in, an [`Outcome`] (the numbers of one row of the runs
//! table, plus the optional time series) out.
//!
//! The run never panics on numerical trouble: a step whose contact equation has no or several
//! solutions ends the run `solver-failed`; a non-finite value or an energy above 1e6·E⁰ ends it
//! `diverged` (contract §5); a run past its time budget ends `timeout`. What was observed up to that
//! point is kept.

pub mod bar1d;
pub mod bars1d;
mod config;
mod dispatch;
pub mod estimate;
pub mod fe;
pub mod friction_tally;
mod grid1d;
pub mod impacts;
pub mod layer1d;
pub mod observe;
pub mod oscillator;
mod outcome;
pub mod record;
pub mod reference;
mod spec;
mod stepping;

pub use config::RunConfig;
pub use dispatch::{lockstep_key, simulate, simulate_group, simulate_with};
pub use grid1d::Grid1d;
pub use observe::{Metrics, Series, SeriesRow};
pub(crate) use outcome::Stop;
pub use outcome::{Outcome, RunContext, RunOptions, Status};
pub use record::{RunRecord, RunResult, SERIES_COLUMNS};
pub use spec::RunSpec;
