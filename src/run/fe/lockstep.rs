//! Lockstep groups (issue 24): runs that share their step matrix A = M + cτ²K advance together,
//! one multi-column solve per step.
//!
//! Why: a 2D/3D step is one forward and one backward triangular solve, which stream the whole
//! Cholesky factor from memory; the engine is at that wall. With k right-hand sides the factor
//! is read once for all k, so the time per right-hand side falls by several times (README's
//! Performance table). Many runs of a sweep share A — the contact enters only through the
//! condensed contact set: the members of a round-off ensemble, runs differing only in the gap,
//! the initial velocity, γ at fixed β or T.
//!
//! Each member keeps its own state, contact solve, observer and outcome ([`super::newmark::Stepper`]); what the
//! members share is every read of a shared operator: the solve, Z's columns, and the products
//! with M and K (each matrix read once per 8 vectors — in 3D the members' own products were
//! most of a group's step: sphere3d Q2, 4 503 dofs, made K u twice and M u, M v per member and
//! step). Column j of the block solve is member j's right-hand side, and each column gets
//! exactly the arithmetic of a single solve ([`crate::space::linalg::Cholesky::solve_columns_in_place`]:
//! faer's simplicial solve as it is, a supernodal factor swept supernode by supernode with
//! faer's one-column kernels), so a member's numbers equal its run alone bit for bit (tested).
//! That matters beyond tidiness: a contact that chatters magnifies any difference — faer's
//! blocked supernodal solve, whose kernels depend on the block's width, put 2.7e-10 between a
//! member's `energy_final` and its run alone on a 21 120-dof 2D ensemble. A member that
//! fails, diverges or reaches its last step leaves the group; the others go on. Members whose
//! factors are not the same shared object (a cache eviction between their setups) are stepped
//! as separate groups: one solve must use one factor.

use std::sync::Arc;
use std::time::Instant;

use super::cache::geometry_key;
use super::config::{FeConfig, frictional, handles};
use super::factor::Factored;
use super::newmark::Stepper;
use crate::run::{Outcome, Stop};
use crate::space::fe::SymMatrix;
use crate::space::step_solver::Solver;

/// The key under which runs may share a lockstep group: equal keys mean the same step matrix
/// and condensation (the geometry, mass, method, cτ², the direct solver; the gap where the
/// method puts it into the operators). `None`: the run steps alone — the methods of contract §3.2
/// (their own loops), CG runs (nothing factored to share), invalid schemes.
pub fn lockstep_key(cfg: &FeConfig) -> Option<String> {
    if handles(cfg) || cfg.solver != Solver::Direct || frictional(cfg) {
        return None;
    }
    let (_, c, _) = cfg.coefficients().ok()?;
    let c_tau2 = c * cfg.dt * cfg.dt;
    Some(format!(
        "{}|{:?}|{:?}|{:e}|gap {:e}",
        geometry_key(&cfg.setup),
        cfg.mass,
        cfg.method,
        c_tau2,
        if cfg.method == crate::space::ContactMethod::Mixed {
            0.0
        } else {
            cfg.setup.gap
        }
    ))
}

/// Most vectors of one joint product with M or K (accumulators kept in registers).
const PRODUCT_CHUNK: usize = 8;

/// The time loop of runs sharing one factor (a run alone is a group of one). Per step: each
/// member's right-hand side; one solve for all (alone: the member's own work, so CG
/// warm-starts); each member's contact problem; u^{n+1} = y + cτ²Zλ with each column of Z read
/// once for all; each member's acceleration (u ← y in the same pass); the products with M and
/// K, each matrix read once per [`PRODUCT_CHUNK`] vectors; each member's updates and
/// observation. The right-hand sides are written into, and u^{n+1} read from, the block the
/// solve works on (no copies). Every operation, the solve included, does for each member
/// exactly the arithmetic of its run alone (same order of summation).
pub(super) fn step_together(mut active: Vec<(usize, Stepper)>) -> Vec<(usize, Outcome)> {
    let members = active.len();
    let mut finished = Vec::with_capacity(members);
    if members == 0 {
        return finished;
    }
    let fac: Arc<Factored> = Arc::clone(&active[0].1.fac);
    let n = fac.chol.n();
    let nz = fac.z.len().checked_div(n).unwrap_or(0);
    let c_tau2 = active[0].1.c_tau2;
    // Column j: member j's right-hand side, solved in place, then its u^{n+1}.
    let mut block = vec![0.0; n * members];
    let mut work = (members > 1).then(|| fac.chol.work_for(members));
    let loop_start = Instant::now();
    // A member that stops leaves with its outcome; the order of the others is kept.
    let leave = |active: &mut Vec<(usize, Stepper)>,
                 finished: &mut Vec<(usize, Outcome)>,
                 j: usize,
                 stop: Result<(), Stop<String>>| {
        let (idx, s) = active.remove(j);
        finished.push((idx, s.finish(stop)));
    };
    // Step 0's observation (with K u⁰ where it needs it); a member may already diverge there.
    products(&fac, &mut active);
    let mut j = 0;
    while j < active.len() {
        active[j].1.loop_start = loop_start;
        match active[j].1.observe(0) {
            Ok(()) => j += 1,
            Err(d) => leave(&mut active, &mut finished, j, Err(Stop::Diverged(d))),
        }
    }
    let last = active.iter().map(|(_, s)| s.cfg.steps).max().unwrap_or(0);
    for step in 1..=last {
        // Members past their last step leave with their whole run done.
        let mut j = 0;
        while j < active.len() {
            if active[j].1.cfg.steps < step {
                leave(&mut active, &mut finished, j, Ok(()));
            } else {
                j += 1;
            }
        }
        let k = active.len();
        if k == 0 {
            break;
        }
        for ((_, s), y) in active.iter_mut().zip(block.chunks_exact_mut(n)) {
            s.prepare(y);
        }
        // The solve. The direct solve cannot fail; CG's failure is the member's (alone).
        if let (Some(work), true) = (work.as_mut(), k > 1) {
            fac.chol
                .solve_columns_in_place(&mut block[..k * n], k, work);
            if let Some(e) = work.check().err().map(|e| e.to_string()) {
                while !active.is_empty() {
                    leave(
                        &mut active,
                        &mut finished,
                        0,
                        Err(Stop::Solver(step, e.clone())),
                    );
                }
                break;
            }
        } else {
            // k = 1: the member is alone in its group.
            let s = &mut active[0].1;
            fac.chol.solve_in_place(&mut block[..n], &mut s.work);
            if let Err(e) = s.work.check() {
                leave(
                    &mut active,
                    &mut finished,
                    0,
                    Err(Stop::Solver(step, e.to_string())),
                );
                break;
            }
        }
        // Members leave by removing their column: the block is compacted with them.
        let mut j = 0;
        while j < active.len() {
            match active[j].1.contact(step, &block[j * n..(j + 1) * n]) {
                Ok(()) => j += 1,
                Err(stop) => {
                    leave(&mut active, &mut finished, j, Err(stop));
                    block.copy_within((j + 1) * n..(active.len() + 1) * n, j * n);
                }
            }
        }
        add_contact(&fac, c_tau2, nz, &mut active, &mut block);
        let mut j = 0;
        while j < active.len() {
            match active[j].1.refine(step, &mut block[j * n..(j + 1) * n]) {
                Ok(()) => j += 1,
                Err(stop) => {
                    leave(&mut active, &mut finished, j, Err(stop));
                    block.copy_within((j + 1) * n..(active.len() + 1) * n, j * n);
                }
            }
        }
        for ((_, s), y) in active.iter_mut().zip(block.chunks_exact(n)) {
            s.accelerate(y);
        }
        products(&fac, &mut active);
        let mut j = 0;
        while j < active.len() {
            match active[j].1.end_step(step) {
                Ok(()) => j += 1,
                Err(stop) => leave(&mut active, &mut finished, j, Err(stop)),
            }
        }
    }
    for (idx, s) in active {
        finished.push((idx, s.finish(Ok(()))));
    }
    if members > 1 {
        let share = loop_start.elapsed().as_secs_f64() / members as f64;
        for (_, out) in &mut finished {
            out.metrics.stepping_time_s = Some(share);
        }
    }
    finished
}

/// Rows per tile of [`add_contact`]: 8 members' tiles of y and one of z_c (9 × 16 KiB) stay in
/// the L2 cache while the tile's columns are added.
const TILE: usize = 2048;

/// u^{n+1} = y + cτ² Σ_{λ_c ≠ 0} λ_c z_c for every member (column j of `block` is member j's
/// y), by tiles of rows: each tile of a column z_c is read once for all members while their
/// tiles of y stay in cache (column by column over the whole vectors, a group of 8 would stream
/// its y's from memory once per column). Each entry of y receives the columns' terms in
/// ascending c, as in the run alone.
fn add_contact(
    fac: &Factored,
    c_tau2: f64,
    nz: usize,
    active: &mut [(usize, Stepper)],
    block: &mut [f64],
) {
    let n = fac.chol.n();
    let touched = active
        .iter()
        .any(|(_, s)| s.lambda.iter().any(|&l| l != 0.0));
    if !touched {
        return;
    }
    for lo in (0..n).step_by(TILE) {
        let hi = (lo + TILE).min(n);
        for c in 0..nz {
            let zc = &fac.z[c * n + lo..c * n + hi];
            for ((_, s), y) in active.iter().zip(block.chunks_exact_mut(n)) {
                // ≠ 0, not > 0: a frictional run's tangential forces have either sign (the
                // normal ones, and every frictionless force, are ≥ 0: the same terms).
                let l = s.lambda[c];
                if l != 0.0 {
                    let f = c_tau2 * l;
                    for (yi, zi) in y[lo..hi].iter_mut().zip(zc) {
                        *yi += f * zi;
                    }
                }
            }
        }
    }
}

/// Every member's products with M ([`Stepper::mass_pairs`]) and with K ([`Stepper::k_pair`]),
/// each matrix read once per [`PRODUCT_CHUNK`] vectors.
fn products(fac: &Factored, active: &mut [(usize, Stepper)]) {
    let Some(geo) = active.first().map(|(_, s)| Arc::clone(&s.geo)) else {
        return;
    };
    let pairs = active
        .iter_mut()
        .flat_map(|(_, s)| s.mass_pairs().into_iter().flatten());
    batched(&fac.m_products, pairs);
    batched(&geo.k, active.iter_mut().filter_map(|(_, s)| s.k_pair()));
}

/// The products y = A x of `pairs`, [`PRODUCT_CHUNK`] per pass over A; no allocation (the
/// pairs of a pass live in arrays on the stack).
fn batched<'a>(a: &SymMatrix, pairs: impl Iterator<Item = (&'a [f64], &'a mut [f64])>) {
    let mut xs: [&[f64]; PRODUCT_CHUNK] = [&[]; PRODUCT_CHUNK];
    let mut ys: [&mut [f64]; PRODUCT_CHUNK] = Default::default();
    let mut c = 0;
    for (x, y) in pairs {
        if c == PRODUCT_CHUNK {
            a.matvec_many_into(&xs[..c], &mut ys[..c]);
            c = 0;
        }
        xs[c] = x;
        ys[c] = y;
        c += 1;
    }
    if c > 0 {
        a.matvec_many_into(&xs[..c], &mut ys[..c]);
    }
}
