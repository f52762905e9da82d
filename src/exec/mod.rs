//! The executor: runs a plan's runs, serially (the reference path, a plain loop) or on a rayon
//! pool, and hands each finished run to a callback in the calling thread (the sink).
//!
//! A run that panics becomes a row (`solver-failed`, "internal error: …"); the sweep goes on.
//! Rows do not depend on the thread count: every run is a pure function of its spec, so the
//! 1-thread and N-thread outputs are identical except the timing columns (tested).

pub mod references;
pub mod shard;
pub mod slurm;
pub mod status;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use rayon::prelude::*;

use crate::run::record::Timing;
use std::collections::HashMap;
use std::sync::Arc;

use crate::run::reference::ReferenceData;
use crate::run::{self, Metrics, Outcome, RunContext, RunOptions, RunRecord, Series, Status};
use crate::sweep::RunSpec;

/// A finished run: its row and its (possibly decimated) time series.
#[derive(Debug, Clone)]
pub struct RunResult {
    pub record: RunRecord,
    pub series: Series,
}

/// How to execute.
#[derive(Debug, Clone, Copy)]
pub struct ExecOptions {
    /// 1: the serial reference loop; N > 1: a rayon pool of N threads; 0: rayon's default.
    pub threads: usize,
    pub run: RunOptions,
}

/// Run `f`; a panic becomes a `solver-failed` outcome carrying the panic message, so one bad
/// run never takes the sweep down.
fn guarded(f: impl FnOnce() -> Outcome) -> Outcome {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Outcome {
            status: Status::SolverFailed,
            message: Some(format!("internal error (panic): {what}")),
            metrics: Metrics::default(),
            series: Series::default(),
            reference: None,
        }
    })
}

/// The reference solutions of a sweep's runs, by reference run_id.
pub type References = HashMap<String, Arc<ReferenceData>>;

/// Run one spec (with its timing repeats), never panicking.
pub fn run_one(sweep: &str, spec: &RunSpec, opts: &RunOptions, refs: &References) -> RunResult {
    let ctx = RunContext {
        reference: spec.reference.as_ref().and_then(|id| refs.get(id).cloned()),
        record_reference: None,
    };
    let mut times = Vec::with_capacity(spec.repeats.max(1));
    let mut outcome: Option<Outcome> = None;
    for rep in 0..spec.repeats.max(1) {
        // Only the first repeat keeps the series; the numbers are identical across repeats.
        let o = RunOptions {
            series_every: if rep == 0 { opts.series_every } else { 0 },
            ..*opts
        };
        let start = Instant::now();
        let out = guarded(|| run::simulate_with(&spec.config, &o, &ctx));
        times.push(start.elapsed().as_secs_f64());
        let stop = out.status != Status::Ok;
        if outcome.is_none() {
            outcome = Some(out);
        }
        if stop {
            break;
        }
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let median = if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    };
    let mut out = outcome.expect("at least one repeat");
    let timing = Timing {
        median_s: median,
        min_s: sorted[0],
        max_s: sorted[n - 1],
        repeats: n,
    };
    let record = RunRecord::new(sweep, spec, &out, timing);
    RunResult {
        record,
        series: std::mem::take(&mut out.series),
    }
}

/// Execute `runs`, calling `on_result` in this thread as each finishes (in plan order for the
/// serial path, in completion order otherwise). Stops early if `on_result` returns an error.
/// When `opts.run.cancel` is raised no run starts any more, and the runs it interrupted are
/// dropped (they are redone on resume); every run finished before is still handed over.
pub fn execute<E: Send>(
    sweep: &str,
    runs: &[&RunSpec],
    refs: &References,
    opts: &ExecOptions,
    mut on_result: impl FnMut(RunResult) -> Result<(), E>,
) -> Result<(), E> {
    let keep = |r: &RunResult| r.record.status != Status::Cancelled.as_str();
    if opts.threads == 1 {
        for spec in runs {
            if opts.run.cancelled() {
                break;
            }
            let r = run_one(sweep, spec, &opts.run, refs);
            if keep(&r) {
                on_result(r)?;
            }
        }
        return Ok(());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .expect("a rayon pool of N threads can be built");
    let (tx, rx) = mpsc::channel::<RunResult>();
    let run_opts = opts.run;
    let cancel = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let cancel = &cancel;
        scope.spawn(move || {
            pool.install(|| {
                runs.par_iter().for_each_with(tx, |tx, spec| {
                    // The consumer failed (e.g. the disk is full) or the sweep was interrupted:
                    // start nothing new.
                    if !cancel.load(Ordering::Relaxed) && !run_opts.cancelled() {
                        let r = run_one(sweep, spec, &run_opts, refs);
                        if keep(&r) {
                            let _ = tx.send(r);
                        }
                    }
                });
            });
        });
        let mut result = Ok(());
        for res in rx.iter() {
            if let Err(e) = on_result(res) {
                cancel.store(true, Ordering::Relaxed);
                result = Err(e);
                break;
            }
        }
        drop(rx);
        result
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_a_failed_outcome_with_its_message() {
        let out = guarded(|| panic!("index out of bounds: the len is 3"));
        assert_eq!(out.status, Status::SolverFailed);
        let msg = out.message.unwrap();
        assert!(
            msg.contains("internal error (panic)") && msg.contains("the len is 3"),
            "{msg}"
        );
        let out = guarded(|| panic!("{} of {}", 1, 2));
        assert!(out.message.unwrap().contains("1 of 2"));
    }
}
