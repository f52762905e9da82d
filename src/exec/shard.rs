//! Shards: the plan cut into N parts of about equal estimated work, for the tasks of a job array.
//!
//! Each run's work is its estimate steps × unknowns × repeats ([`crate::run::RunConfig::work`]);
//! the runs are dealt, largest first, to the shard with the least work so far (longest
//! processing time first: the heaviest shard exceeds the mean by at most the largest run, and a
//! ladder's finest level no longer lands in one shard with the next finest). Ties go to the
//! earlier run and the lower shard, so every task of an array, planning the same frozen sweep
//! file, computes the same assignment — nothing is stored. With equal works it is round-robin.
//!
//! A task may run several shards: `--shard 0-3/16` (a range) or `--shard 1,5,9/16` (a list),
//! which is how `status` resubmits only the shards that still miss runs.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fmt;

use crate::sweep::RunSpec;

/// Which shards of how many a session runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShardSpec {
    /// Sorted, distinct, each < `of`.
    pub shards: Vec<usize>,
    pub of: usize,
}

impl ShardSpec {
    /// Parse `K/N`, `A-B/N` (inclusive) or `A,B,C/N` (lists may hold ranges: `0-3,7/16`).
    pub fn parse(text: &str) -> Result<ShardSpec, String> {
        let bad = || {
            format!(
                "--shard must be K/N, A-B/N or A,B,…/N with every shard < N (e.g. 0/4, 0-3/16, 1,5/16), got `{text}`"
            )
        };
        let (list, n) = text.split_once('/').ok_or_else(bad)?;
        let of: usize = n.trim().parse().map_err(|_| bad())?;
        if of == 0 {
            return Err(bad());
        }
        let mut shards = Vec::new();
        for item in list.split(',') {
            let item = item.trim();
            let (a, b) = match item.split_once('-') {
                Some((a, b)) => (a.trim(), b.trim()),
                None => (item, item),
            };
            let a: usize = a.parse().map_err(|_| bad())?;
            let b: usize = b.parse().map_err(|_| bad())?;
            if a > b || b >= of {
                return Err(bad());
            }
            shards.extend(a..=b);
        }
        shards.sort_unstable();
        shards.dedup();
        Ok(ShardSpec { shards, of })
    }

    pub fn contains(&self, shard: usize) -> bool {
        self.shards.binary_search(&shard).is_ok()
    }
}

impl fmt::Display for ShardSpec {
    /// Compact: consecutive shards as ranges (`0-3,7/16`; one shard as `K/N`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", compact(&self.shards), self.of)
    }
}

/// `0-3,7,9-10` from a sorted list.
pub fn compact(list: &[usize]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < list.len() {
        let mut j = i;
        while j + 1 < list.len() && list[j + 1] == list[j] + 1 {
            j += 1;
        }
        parts.push(if j == i {
            list[i].to_string()
        } else {
            format!("{}-{}", list[i], list[j])
        });
        i = j + 1;
    }
    parts.join(",")
}

/// A run's estimated work (at least 1, so runs of no work still spread).
pub fn work(spec: &RunSpec) -> u64 {
    spec.config
        .work()
        .saturating_mul(spec.repeats.max(1) as u64)
        .max(1)
}

/// The shard of every run of `runs` (in order) when cut into `n` shards balanced by work.
pub fn assign(runs: &[RunSpec], n: usize) -> Vec<usize> {
    let n = n.max(1);
    let mut order: Vec<usize> = (0..runs.len()).collect();
    let works: Vec<u64> = runs.iter().map(work).collect();
    // Largest first; the sort is stable, so equal works keep plan order.
    order.sort_by_key(|&i| Reverse(works[i]));
    let mut heap: BinaryHeap<Reverse<(u64, usize)>> = (0..n).map(|s| Reverse((0, s))).collect();
    let mut out = vec![0; runs.len()];
    for i in order {
        let Reverse((load, s)) = heap.pop().expect("n ≥ 1 shards");
        out[i] = s;
        heap.push(Reverse((load.saturating_add(works[i]), s)));
    }
    out
}

/// Total estimated work of each of `n` shards.
pub fn loads(runs: &[RunSpec], assignment: &[usize], n: usize) -> Vec<u64> {
    let mut loads = vec![0u64; n.max(1)];
    for (r, &s) in runs.iter().zip(assignment) {
        loads[s] = loads[s].saturating_add(work(r));
    }
    loads
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{SweepFile, expand};

    #[test]
    fn shard_specs_parse_and_print_compactly() {
        let s = ShardSpec::parse("0-3,7,5/16").unwrap();
        assert_eq!(s.shards, [0, 1, 2, 3, 5, 7]);
        assert_eq!(s.to_string(), "0-3,5,7/16");
        assert_eq!(ShardSpec::parse("2/4").unwrap().to_string(), "2/4");
        for bad in ["4/4", "1/0", "3-1/8", "x/2", "1", "1,/4"] {
            assert!(ShardSpec::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn shards_are_balanced_by_work_not_by_count() {
        // A ladder: each level 4× the work of the previous (h and dt halved), three methods.
        let text = r#"
name = "l"
scene = "bar1d"
[fixed]
courant = 1.0
[grid]
h = [0.125, 0.0625, 0.03125, 0.015625, 0.0078125, 0.00390625]
mass = ["consistent", "mod1", "mod3"]
"#;
        let plan = expand(&SweepFile::parse("l.toml".as_ref(), text).unwrap()).unwrap();
        let n = 3;
        let lpt = assign(&plan.runs, n);
        let loads_lpt = loads(&plan.runs, &lpt, n);
        let total: u64 = loads_lpt.iter().sum();
        let biggest = plan.runs.iter().map(work).max().unwrap();
        // LPT's bound: the heaviest shard exceeds the mean by at most the largest run.
        assert!(*loads_lpt.iter().max().unwrap() <= total / n as u64 + biggest);
        // Each level holds three runs of equal work (one per mass): one per shard, exactly.
        assert_eq!(
            loads_lpt.iter().max().unwrap() - loads_lpt.iter().min().unwrap(),
            0,
            "{loads_lpt:?}"
        );
        // A plan with the mesh axis fastest: round-robin over 2 shards puts the odd levels
        // (4× the work each) on shard 1; LPT balances within one coarse run.
        let text2 = text.replace(
            "h = [0.125, 0.0625, 0.03125, 0.015625, 0.0078125, 0.00390625]\nmass = [\"consistent\", \"mod1\", \"mod3\"]",
            "mass = [\"consistent\", \"mod1\", \"mod3\"]\nh = [0.125, 0.0625, 0.03125, 0.015625, 0.0078125, 0.00390625]",
        );
        let plan = expand(&SweepFile::parse("l.toml".as_ref(), &text2).unwrap()).unwrap();
        let rr: Vec<usize> = (0..plan.runs.len()).map(|i| i % 2).collect();
        let lrr = loads(&plan.runs, &rr, 2);
        let llpt = loads(&plan.runs, &assign(&plan.runs, 2), 2);
        let spread = |l: &[u64]| *l.iter().max().unwrap() as f64 / *l.iter().min().unwrap() as f64;
        assert!(spread(&lrr) > 3.5, "round-robin {lrr:?}");
        assert!(spread(&llpt) < 1.1, "by work {llpt:?}");
        // Deterministic.
        assert_eq!(assign(&plan.runs, 2), assign(&plan.runs, 2));
    }
}
