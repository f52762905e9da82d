//! Lockstep groups (issue 24, done-when 2): runs that share their step matrix, stepped together
//! with one multi-column solve per step, write the rows they write alone.
//!
//! Why bit for bit: a member's contact solve, Z-update, products with M and observation do its
//! run-alone arithmetic in the same order (`run::fe` lockstep module), and so does the solve.
//! faer's simplicial solve (every 2D step matrix) treats each column of a block with the
//! single-column arithmetic; a supernodal factor (3D) is solved by the engine's
//! column-by-column sweep over faer's supernodes (`Cholesky::solve_columns_in_place`), which
//! calls faer's one-column kernels for every column. faer's own blocked supernodal solve picks
//! its GEMM kernel by the block's width: until this sweep the 3D rows differed by up to
//! 1.33e-12 relative (`err_u_contact_max`), and a chattering 2D ensemble on a supernodal factor
//! (21 120 dofs) by 2.7e-10 in `energy_final` — a contact that switches on round-off
//! magnifies it. Now every compared column is equal, so the tests ask for 0.

use std::path::Path;

use contact_sweep::exec::{self, ExecOptions};
use contact_sweep::run::record::ColumnData;
use contact_sweep::run::{RunOptions, RunRecord};
use contact_sweep::sweep::{SweepFile, expand};

/// The columns that may differ: the timings, the group's size, and whether this run or an
/// earlier one of the process made the shared factor (the cache's bookkeeping: the second
/// sweep of a test finds the first one's factor).
const NOT_COMPARED: [&str; 9] = [
    "factorizations",
    "factor_cache_hits",
    "wall_time_s",
    "wall_time_min_s",
    "wall_time_max_s",
    "setup_time_s",
    "stepping_time_s",
    "observe_time_s",
    "lockstep",
];

/// Columns compared absolutely: already relative to the energy scale (`energy_drift`,
/// `energy_max_dev`, the largest one-step increases, the energy's error — of a conserving
/// scheme they are round-off themselves, ~1e-14, where a relative difference means nothing),
/// or a penetration of the mixed method that is round-off too (≈ 1e-16 m on a bar of 1 m).
const ABSOLUTE: [&str; 6] = [
    "energy_drift",
    "energy_max_dev",
    "err_energy_l2",
    "energy_max_increase",
    "energy_theta_max_increase",
    "max_penetration",
];

/// The sweep's rows with `--threads 1 --lockstep N`, by run id.
fn rows(text: &str, lockstep: usize) -> Vec<RunRecord> {
    let sweep = SweepFile::parse(Path::new("lockstep.toml"), text).expect("valid sweep");
    let plan = expand(&sweep).expect("plan");
    let dir = tempfile::tempdir().unwrap();
    let runs: Vec<_> = plan.runs.iter().collect();
    let opts = RunOptions {
        series_every: 0,
        timeout: None,
        cancel: None,
    };
    let refs = exec::references::ensure(dir.path(), &plan, &runs, &opts).expect("references");
    let mut out = Vec::new();
    exec::execute::<()>(
        &plan.sweep.name,
        &runs,
        &refs,
        &ExecOptions {
            threads: 1,
            lockstep,
            run: opts,
        },
        |r| {
            out.push(r.record);
            Ok(())
        },
    )
    .unwrap();
    out.sort_by(|a, b| a.run_id.cmp(&b.run_id));
    out
}

/// The largest relative difference over every float column compared (errors, energies,
/// positions, forces…; `energy_drift` and `energy_max_increase`, already relative to the
/// energy scale, absolutely), after checking that every other column is equal.
fn largest_difference(alone: &[RunRecord], group: &[RunRecord]) -> (f64, &'static str) {
    assert_eq!(alone.len(), group.len());
    let (a, b) = (RunRecord::to_columns(alone), RunRecord::to_columns(group));
    let mut worst = (0.0f64, "");
    for ((name, x), (_, y)) in a.into_iter().zip(b) {
        if NOT_COMPARED.contains(&name) {
            continue;
        }
        // Lists (the impacts' energies) are compared entry by entry.
        let flat = |c: &ColumnData| -> Option<Vec<Option<f64>>> {
            match c {
                ColumnData::F64(v) => Some(v.clone()),
                ColumnData::ListF64(v) => Some(
                    v.iter()
                        .flat_map(|l| l.clone().unwrap_or_default())
                        .collect(),
                ),
                _ => None,
            }
        };
        if let ColumnData::ListF64(x) = &x {
            let ColumnData::ListF64(y) = &y else {
                unreachable!("same schema")
            };
            let lens = |v: &Vec<Option<Vec<Option<f64>>>>| -> Vec<Option<usize>> {
                v.iter().map(|l| l.as_ref().map(Vec::len)).collect()
            };
            assert_eq!(lens(x), lens(y), "column {name}: list lengths");
        }
        match (flat(&x), flat(&y)) {
            (Some(x), Some(y)) => {
                assert_eq!(x.len(), y.len(), "column {name}");
                for (p, q) in x.iter().zip(&y) {
                    let d = match (p, q) {
                        (Some(p), Some(q)) if p.is_nan() && q.is_nan() => 0.0,
                        (Some(p), Some(q)) => {
                            let scale = if ABSOLUTE.contains(&name) {
                                1.0
                            } else {
                                p.abs().max(q.abs()).max(f64::MIN_POSITIVE)
                            };
                            (p - q).abs() / scale
                        }
                        (None, None) => 0.0,
                        _ => panic!("{name}: {p:?} alone, {q:?} in lockstep"),
                    };
                    if d > worst.0 {
                        worst = (d, name);
                    }
                }
            }
            _ => assert_eq!(x, y, "column {name}"),
        }
    }
    worst
}

#[test]
fn a_2d_group_writes_the_rows_of_its_runs_alone_bit_for_bit() {
    // One key, eight runs: Newmark β = 1/4 with γ = 1/2 (Crank–Nicolson) and γ = 0.6 (the same
    // step matrix M + τ²/4 K), two gaps, two final times (the members with T = 0.5 leave while
    // the others go on), errors against a common finer reference.
    let text = r#"
name = "lockstep-2d"
scene = "bar2d"
reference = { h = 0.0125, dt = 0.00625, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
h = 0.025
dt = 0.0125
mass = "mod3"
scheme = "newmark"
newmark_beta = 0.25
[grid]
newmark_gamma = [0.5, 0.6]
gap = [0.2, 0.1]
T = [0.5, 1.0]
"#;
    let alone = rows(text, 1);
    let group = rows(text, 8);
    assert_eq!(alone.len(), 8);
    assert!(
        alone
            .iter()
            .all(|r| r.status == "ok" && r.lockstep.is_none())
    );
    assert!(
        group.iter().all(|r| r.lockstep == Some(8)),
        "one group of 8"
    );
    assert!(
        alone.iter().all(|r| r.err_u_l2l2.is_some()),
        "errors measured"
    );
    let (d, col) = largest_difference(&alone, &group);
    assert_eq!(d, 0.0, "largest difference {d:e} in {col}");
}

#[test]
fn a_3d_group_on_a_supernodal_factor_writes_the_rows_of_its_runs_alone_bit_for_bit() {
    // Round-off ensembles of the mixed method with Crank–Nicolson and of Nitsche-hybrid (one
    // group of 4 each), T = 1 (the impact and the rebound), errors against a reference with a
    // finer step.
    let text = |space: &str| {
        format!(
            r#"
name = "lockstep-3d"
scene = "bar3d"
ensemble = {{ perturbation = 1e-12, samples = 4, seed = 24 }}
reference = {{ dt = 0.0125, space = "mixed", mass = "mod3", scheme = "crank-nicolson" }}
[fixed]
h = 0.05
dt = 0.025
T = 1.0
{space}
"#
        )
    };
    let mut alone = Vec::new();
    let mut group = Vec::new();
    for space in [
        "space = \"mixed\"\nmass = \"mod3\"\nscheme = \"crank-nicolson\"",
        "space = \"nitsche\"\nnitsche_gamma0 = 0.01\nmass = \"consistent\"\nscheme = \"hybrid\"",
    ] {
        alone.extend(rows(&text(space), 1));
        group.extend(rows(&text(space), 8));
    }
    assert_eq!(alone.len(), 8);
    assert!(alone.iter().all(|r| r.status == "ok"));
    assert!(
        group.iter().all(|r| r.lockstep == Some(4)),
        "two groups of 4"
    );
    assert!(
        alone.iter().all(|r| r.err_u_l2l2.is_some()),
        "errors measured"
    );
    let (d, col) = largest_difference(&alone, &group);
    assert_eq!(d, 0.0, "largest difference {d:e} in {col}");
}

#[test]
fn groups_are_cut_to_keep_every_thread_busy_and_rows_do_not_depend_on_it() {
    // Eight members and two threads: two groups of 4 (one would leave a thread idle); the rows
    // are those of `--threads 1` (simplicial 2D: bit for bit).
    let text = r#"
name = "lockstep-threads"
scene = "bar2d"
ensemble = { perturbation = 1e-10, samples = 8, seed = 7 }
[fixed]
h = 0.025
dt = 0.0125
T = 0.6
mass = "mod3"
scheme = "crank-nicolson"
"#;
    let sweep = SweepFile::parse(Path::new("lockstep.toml"), text).unwrap();
    let plan = expand(&sweep).unwrap();
    let runs: Vec<_> = plan.runs.iter().collect();
    let mut two = Vec::new();
    exec::execute::<()>(
        &plan.sweep.name,
        &runs,
        &Default::default(),
        &ExecOptions {
            threads: 2,
            lockstep: 8,
            run: RunOptions {
                series_every: 0,
                timeout: None,
                cancel: None,
            },
        },
        |r| {
            two.push(r.record);
            Ok(())
        },
    )
    .unwrap();
    two.sort_by(|a, b| a.run_id.cmp(&b.run_id));
    assert!(two.iter().all(|r| r.lockstep == Some(4)), "two groups of 4");
    let one = rows(text, 1);
    let (d, col) = largest_difference(&one, &two);
    assert_eq!(d, 0.0, "largest difference {d:e} in {col}");
}
