//! The executor: runs a plan's runs, serially (the reference path, a plain loop) or on a rayon
//! pool, and hands each finished run to a callback in the thread that ran it (the sink, which
//! encodes its output there so that the output's CPU grows with the workers), then what that
//! returns to a callback in the calling thread (progress).
//!
//! A run that panics becomes a row (`solver-failed`, "internal error: …"); the sweep goes on.
//! Rows do not depend on the thread count: every run is a pure function of its spec, so the
//! 1-thread and N-thread outputs are identical except the timing columns (tested).
//!
//! Lockstep groups (issue 24): runs whose step matrix is the same ([`run::lockstep_key`]) are
//! cut into groups of at most [`ExecOptions::lockstep`] members, each group one unit of work
//! stepped together ([`run::simulate_group`]: one multi-column solve per step). A member's
//! numbers equal its run alone bit for bit; only its `lockstep` and timing columns differ.
//! Groups are cut to keep every thread busy: a key's runs are split into more, smaller groups
//! when there are fewer units than threads.

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

/// A finished run (defined with the runs, so the sink below the executor can take it).
pub use crate::run::RunResult;

/// How to execute.
#[derive(Debug, Clone, Copy)]
pub struct ExecOptions {
    /// 1: the serial reference loop; N > 1: a rayon pool of N threads; 0: rayon's default.
    pub threads: usize,
    /// Most members of a lockstep group (1: every run steps alone).
    pub lockstep: usize,
    pub run: RunOptions,
}

impl ExecOptions {
    /// The default group size, measured on the 2D bar at 21 120 dofs (docs/performance.md):
    /// the time per member falls up to 8 members and no further at 16 (the factor is read once
    /// per step either way; the members' own work then dominates), while a group's workspace
    /// grows with its members.
    pub const LOCKSTEP_DEFAULT: usize = 8;
}

/// A unit of work: one run, or a lockstep group (members in plan order).
type Unit<'a> = Vec<&'a RunSpec>;

/// Cut `runs` into units: runs with a lockstep key and no timing repeats (a repeat measures a
/// run alone) grouped by key, at most `max` per group and in more groups when there would be
/// fewer units than `threads`; units in the plan order of their first member.
fn units<'a>(runs: &[&'a RunSpec], max: usize, threads: usize) -> Vec<Unit<'a>> {
    // Keys in order of first appearance; a map finds a run's key in O(1) (sweeps of 10⁴ runs).
    let mut keyed: Vec<(String, Vec<usize>)> = Vec::new();
    let mut slot: HashMap<String, usize> = HashMap::new();
    let mut alone: Vec<usize> = Vec::new();
    for (i, spec) in runs.iter().enumerate() {
        match run::lockstep_key(&spec.config).filter(|_| max > 1 && spec.repeats <= 1) {
            Some(k) => match slot.get(&k) {
                Some(&s) => keyed[s].1.push(i),
                None => {
                    slot.insert(k.clone(), keyed.len());
                    keyed.push((k, vec![i]));
                }
            },
            None => alone.push(i),
        }
    }
    // Groups per key: enough for `max`, then split further while threads would idle.
    let mut parts: Vec<usize> = keyed.iter().map(|(_, v)| v.len().div_ceil(max)).collect();
    loop {
        let total = alone.len() + parts.iter().sum::<usize>();
        if total >= threads {
            break;
        }
        // The key with the largest groups gets one more group, if its groups can shrink.
        let best = (0..parts.len())
            .filter(|&k| parts[k] < keyed[k].1.len())
            .max_by(|&a, &b| {
                let size = |k: usize| keyed[k].1.len() as f64 / parts[k] as f64;
                size(a).total_cmp(&size(b))
            });
        match best {
            Some(k) => parts[k] += 1,
            None => break,
        }
    }
    let mut out: Vec<(usize, Unit<'a>)> = alone.into_iter().map(|i| (i, vec![runs[i]])).collect();
    for ((_, idx), p) in keyed.iter().zip(parts) {
        // p near-equal groups of consecutive members.
        let (q, r) = (idx.len() / p, idx.len() % p);
        let mut at = 0;
        for g in 0..p {
            let len = q + usize::from(g < r);
            let members = &idx[at..at + len];
            out.push((members[0], members.iter().map(|&i| runs[i]).collect()));
            at += len;
        }
    }
    out.sort_by_key(|(first, _)| *first);
    out.into_iter().map(|(_, u)| u).collect()
}

/// Run a unit: a single run through [`run_one`], a group in lockstep (one repeat; each
/// member's time is the group's divided among its members).
fn run_unit(
    sweep: &str,
    unit: &[&RunSpec],
    opts: &RunOptions,
    refs: &References,
) -> Vec<RunResult> {
    if let [spec] = unit {
        return vec![run_one(sweep, spec, opts, refs)];
    }
    let ctxs: Vec<RunContext> = unit
        .iter()
        .map(|spec| RunContext {
            reference: spec.reference.as_ref().and_then(|id| refs.get(id).cloned()),
            record_reference: None,
        })
        .collect();
    let configs: Vec<&run::RunConfig> = unit.iter().map(|s| &s.config).collect();
    let start = Instant::now();
    let outs = catch_unwind(AssertUnwindSafe(|| {
        run::simulate_group(&configs, opts, &ctxs)
    }));
    let outs = match outs {
        Ok(o) => o,
        // A panic in the group: every member again alone, each guarded (the panic is then its
        // own row, the others' rows are what they would have been).
        Err(_) => {
            return unit
                .iter()
                .map(|spec| run_one(sweep, spec, opts, refs))
                .collect();
        }
    };
    let share = start.elapsed().as_secs_f64() / unit.len() as f64;
    let timing = Timing {
        median_s: share,
        min_s: share,
        max_s: share,
        repeats: 1,
    };
    unit.iter()
        .zip(outs)
        .map(|(spec, mut out)| RunResult {
            record: RunRecord::new(sweep, spec, &out, timing),
            series: std::mem::take(&mut out.series),
        })
        .collect()
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

/// Execute `runs`, calling `on_result` in this thread as each finishes (in plan order of the
/// units for the serial path — a lockstep group's members together, at its first member's
/// place — in completion order otherwise). Stops early if `on_result` returns an error.
/// When `opts.run.cancel` is raised no run starts any more, and the runs it interrupted are
/// dropped (they are redone on resume); every run finished before is still handed over.
pub fn execute<E: Send>(
    sweep: &str,
    runs: &[&RunSpec],
    refs: &References,
    opts: &ExecOptions,
    on_result: impl FnMut(RunResult) -> Result<(), E>,
) -> Result<(), E> {
    execute_with(sweep, runs, refs, opts, |r| Ok(r), on_result)
}

/// [`execute`], with each finished run first handed to `on_worker` in the thread that ran it
/// (a worker of the pool; the calling thread on the serial path), and what it returns to
/// `on_result` in the calling thread. Work that grows with the runs (encoding their output)
/// goes in `on_worker`, so it runs in parallel; `on_result` is serial. An error from either
/// stops the sweep as [`execute`] does.
pub fn execute_with<M: Send, E: Send>(
    sweep: &str,
    runs: &[&RunSpec],
    refs: &References,
    opts: &ExecOptions,
    on_worker: impl Fn(RunResult) -> Result<M, E> + Sync,
    mut on_result: impl FnMut(M) -> Result<(), E>,
) -> Result<(), E> {
    let keep = |r: &RunResult| r.record.status != Status::Cancelled.as_str();
    let threads = if opts.threads == 0 {
        rayon::current_num_threads()
    } else {
        opts.threads
    };
    let units = units(runs, opts.lockstep, threads);
    if opts.threads == 1 {
        for unit in &units {
            if opts.run.cancelled() {
                break;
            }
            for r in run_unit(sweep, unit, &opts.run, refs) {
                if keep(&r) {
                    on_result(on_worker(r)?)?;
                }
            }
        }
        return Ok(());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .expect("a rayon pool of N threads can be built");
    let (tx, rx) = mpsc::channel::<Result<M, E>>();
    let run_opts = opts.run;
    let cancel = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (cancel, on_worker) = (&cancel, &on_worker);
        scope.spawn(move || {
            pool.install(|| {
                units.par_iter().for_each_with(tx, |tx, unit| {
                    // The consumer failed (e.g. the disk is full) or the sweep was interrupted:
                    // start nothing new.
                    if !cancel.load(Ordering::Relaxed) && !run_opts.cancelled() {
                        for r in run_unit(sweep, unit, &run_opts, refs) {
                            if keep(&r) {
                                let out = on_worker(r);
                                if out.is_err() {
                                    cancel.store(true, Ordering::Relaxed);
                                }
                                let _ = tx.send(out);
                            }
                        }
                    }
                });
            });
        });
        let mut result = Ok(());
        for res in rx.iter() {
            if let Err(e) = res.and_then(&mut on_result) {
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
