//! The step solve with eight right-hand sides, three ways, on the bars' step matrices
//! A = M + τ²/4 K (mod3, τ = h/2: `common::step_matrix`; issue 24: lockstep groups):
//!
//! - `8 × one`: eight single-column solves (eight runs alone);
//! - `faer block`: faer's blocked solve of the 8 columns at once — not what a group may use on
//!   a supernodal factor, since its dense products pick their kernel by the block's width and
//!   a column then rounds differently from its solve alone;
//! - `columns`: `Cholesky::solve_columns_in_place`, the groups' solve — faer's own blocked
//!   solve for a simplicial factor (already column by column), the engine's
//!   supernode-by-supernode sweep with faer's one-column kernels for a supernodal one.
//!
//! Cases: the 2D bar at h = 0.05/16 (21 120 dofs) and h = 0.05/32 (83 200 dofs), AMD, each
//! factored simplicial and supernodal; the 3D bar at h = 0.0125 (19 440 dofs), nested
//! dissection, supernodal (the engine's choices: `run::fe::cholesky_options`). The three ways
//! are interleaved, repetition by repetition, so that they see the same machine load; the
//! table gives medians and the ratios to `8 × one`, and checks that `columns` equals `8 × one`
//! bit for bit.
//!
//!   cargo bench --bench solves [-- REPS]   (default 15)

mod common;

use std::time::Instant;

use contact_sweep::space::linalg::{Cholesky, FactorKind, SymbolicCholesky};

/// A benchmark case: its name, the bar's dimension and mesh size, and the factor kind (`None`:
/// the engine's choice).
struct Case {
    name: &'static str,
    dim: usize,
    h: f64,
    kind: Option<FactorKind>,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // `cargo bench` passes `--bench`; the first number given is the repetition count.
    let reps: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(15);
    const K: usize = 8;
    let case = |name, dim, h, kind| Case { name, dim, h, kind };
    let cases = [
        case(
            "2D 21 120, simplicial",
            2,
            0.05 / 16.0,
            Some(FactorKind::Simplicial),
        ),
        case(
            "2D 21 120, supernodal",
            2,
            0.05 / 16.0,
            Some(FactorKind::Supernodal),
        ),
        case(
            "2D 83 200, simplicial",
            2,
            0.05 / 32.0,
            Some(FactorKind::Simplicial),
        ),
        case(
            "2D 83 200, supernodal",
            2,
            0.05 / 32.0,
            Some(FactorKind::Supernodal),
        ),
        case("3D 19 440, supernodal", 3, 0.0125, None),
    ];
    println!("ms for {K} right-hand sides, medians of {reps} interleaved repetitions");
    println!(
        "| case | entries of L | supernodes | {K} × one | faer block | columns | columns = {K} × one |"
    );
    println!("|---|---|---|---|---|---|---|");
    for Case { name, dim, h, kind } in cases {
        let (a, _, mut opts) = common::step_matrix(&common::config(dim, h, 1));
        if let Some(kind) = kind {
            opts.kind = kind;
        }
        let sym = SymbolicCholesky::with_options(&a.pattern, &opts).expect("symbolic");
        let ch = Cholesky::new(&sym, &a).expect("SPD");
        let n = ch.n();
        let mut rng = fastrand::Rng::with_seed(24);
        let b: Vec<f64> = (0..n * K).map(|_| rng.f64() - 0.5).collect();
        let mut work = ch.work_for(K);
        let mut t = [vec![], vec![], vec![]];
        let (mut one, mut cols) = (b.clone(), b.clone());
        for _ in 0..reps {
            one.copy_from_slice(&b);
            let s = Instant::now();
            for col in one.chunks_exact_mut(n) {
                ch.solve_in_place(col, &mut work);
            }
            t[0].push(s.elapsed().as_secs_f64() * 1e3);
            let mut x = b.clone();
            let s = Instant::now();
            ch.solve_many_in_place(&mut x, K, &mut work);
            t[1].push(s.elapsed().as_secs_f64() * 1e3);
            cols.copy_from_slice(&b);
            let s = Instant::now();
            ch.solve_columns_in_place(&mut cols, K, &mut work);
            t[2].push(s.elapsed().as_secs_f64() * 1e3);
        }
        let same = one
            .iter()
            .zip(&cols)
            .all(|(u, v)| u.to_bits() == v.to_bits());
        let [m0, m1, m2] = t.map(|mut v| median(&mut v));
        println!(
            "| {name} | {:.2} M | {} | {m0:.1} | {m1:.1} ({:.2}) | {m2:.1} ({:.2}) | {} |",
            sym.factor_nnz() as f64 / 1e6,
            sym.supernodes(),
            m1 / m0,
            m2 / m0,
            if same { "bit for bit" } else { "NO" }
        );
    }
}
