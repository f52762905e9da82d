//! Benchmarks of the 1D engine, reusing the bar of contract §1.1.
//!
//! - `step/…`: one run per scheme at m = 1000, ν = 1, one period (3000 steps): the cost of the
//!   O(m) step (tridiagonal solve + exact scalar contact solve + exact error integration).
//! - `observe/…`: the same run with and without the time series, to show what storing it costs.
//! - `exec/…`: a 16-run plan on the serial loop and on the rayon pool (2 threads): the ratio is
//!   the parallel speed-up measured in one process, both sides under the same machine load.
//!
//! - `thomas-ratio`: for m = 10², 10³, 10⁴, 10⁵, the cost of one CN step (mixed, mod3, errors
//!   against the closed form included, series off) per node against one tridiagonal solve
//!   with precomputed factors (Thomas, plus the copy of its right-hand side) per node — the floor a step cannot beat. Both are timed
//!   in alternation, 9 rounds, medians; the table is printed (`per-step ÷ Thomas`).
//!
//! - `scheme-ratio`: for m = 10³, 10⁴, 10⁵, the cost of a run (errors included, series off) of
//!   each method of contract §3.2 against Crank–Nicolson on the same mesh and step (mixed +
//!   consistent mass; the discrete gradient with the penalty, central difference with the
//!   lumped mass at ν = 0.9), timed in alternation, 5 rounds, medians; target ≤ 1.3×.
//!
//! - `lanes-ratio` (issue 24's 1D bullet: lockstep across SIMD lanes, "if it pays"): for
//!   m = 10², 10³, 10⁴, eight Thomas solves one after another against the same eight solved
//!   together, one run per lane of an `[f64; 8]` row (the compiler vectorises the lanes; each
//!   lane does a single solve's arithmetic, checked bit for bit), next to one CN step per node.
//!   The last column bounds what 1D lockstep could save: (Thomas − lanes) ÷ step.
//!
//! `cargo bench --bench bar1d`; compare medians, not single runs.
//! `cargo bench --bench bar1d -- thomas-ratio` prints only the ratio table.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

use contact_sweep::exec::{self, ExecOptions};
use contact_sweep::run::bar1d::Bar1dConfig;
use contact_sweep::run::{Grid1d, RunConfig, RunOptions, simulate};
use contact_sweep::scene::BarParams;
use contact_sweep::space::{Bar1dSpace, ContactMethod, MassVariant, TridiagLu};
use contact_sweep::sweep::{self, SweepFile};
use contact_sweep::time::{NewmarkParams, PaoliSchatzmanParams, Scheme, ThetaParams};

fn config(method: ContactMethod, mass: MassVariant, scheme: Scheme) -> RunConfig {
    let m = 1000;
    RunConfig::Bar1d(Bar1dConfig::new(
        BarParams::default(),
        Grid1d::new(m, 1.0 / m as f64, 3.0, method, mass, scheme),
    ))
}

fn steps(c: &mut Criterion) {
    let nitsche = ContactMethod::Nitsche {
        theta: 1.0,
        gamma0: 1e-6,
    };
    let cases = [
        (
            "mixed-mod3-cn",
            config(
                ContactMethod::Mixed,
                MassVariant::Mod3,
                Scheme::Newmark(NewmarkParams::crank_nicolson()),
            ),
        ),
        (
            "mixed-mod3-hybrid",
            config(ContactMethod::Mixed, MassVariant::Mod3, Scheme::Hybrid),
        ),
        (
            "nitsche-hybrid",
            config(nitsche, MassVariant::Consistent, Scheme::Hybrid),
        ),
        (
            "nitsche-backward-euler",
            config(
                nitsche,
                MassVariant::Consistent,
                Scheme::Theta(ThetaParams::backward_euler()),
            ),
        ),
        (
            "mixed-mod3-paoli-schatzman",
            config(
                ContactMethod::Mixed,
                MassVariant::Mod3,
                Scheme::PaoliSchatzman(PaoliSchatzmanParams::paper()),
            ),
        ),
    ];
    let mut g = c.benchmark_group("step");
    g.sample_size(20);
    g.throughput(Throughput::Elements(1000 * 3000));
    for (name, cfg) in &cases {
        g.bench_function(*name, |b| b.iter(|| simulate(cfg, &NO_SERIES)));
    }
    g.finish();

    let mut g = c.benchmark_group("observe");
    g.sample_size(20);
    let cfg = &cases[2].1;
    for (name, every) in [("no-series", 0), ("every-step", 1), ("every-50", 50)] {
        let o = RunOptions {
            series_every: every,
            timeout: None,
            cancel: None,
        };
        g.bench_function(name, |b| b.iter(|| simulate(cfg, &o)));
    }
    g.finish();
}

fn executor(c: &mut Criterion) {
    let text = r#"
name = "bench"
scene = "bar1d"
series_every = 0
[fixed]
T = 3.0
courant = 1.0
h = 0.002
[grid]
amplitude = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]
scheme = ["crank-nicolson", "hybrid"]
mass = ["mod3"]
"#;
    let sf = SweepFile::parse(Path::new("bench.toml"), text).expect("valid sweep");
    let plan = sweep::expand(&sf).expect("valid plan");
    let runs: Vec<_> = plan.runs.iter().collect();
    let mut g = c.benchmark_group("exec");
    g.sample_size(10);
    for threads in [1usize, 2] {
        let opts = ExecOptions {
            threads,
            lockstep: ExecOptions::LOCKSTEP_DEFAULT,
            run: RunOptions {
                series_every: 0,
                timeout: None,
                cancel: None,
            },
        };
        g.bench_function(format!("threads-{threads}"), |b| {
            b.iter(|| {
                let mut n = 0;
                exec::execute::<()>("bench", &runs, &Default::default(), &opts, |_| {
                    n += 1;
                    Ok(())
                })
                .unwrap();
                n
            })
        });
    }
    g.finish();
}

/// Median of a sample.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Whether the non-criterion table `name` is wanted: criterion's name filter, honoured by hand
/// (`cargo bench --bench bar1d -- step` skips the tables).
fn wanted(name: &str) -> bool {
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    filter.is_empty() || filter.iter().any(|f| name.contains(f.as_str()))
}

/// A CN run (mixed, mod3, errors against the closed form, ν = 1 on the unit bar: τ = 1/m) of
/// `steps` steps on m elements, and its iteration matrix M + (τ²/4) K factored once — the
/// Thomas side of the ratio tables.
fn cn_run_and_factor(m: usize, steps: usize) -> (RunConfig, TridiagLu) {
    let dt = 1.0 / m as f64;
    let cfg = RunConfig::Bar1d(Bar1dConfig::new(
        BarParams::default(),
        Grid1d::with_steps(
            m,
            dt,
            steps,
            ContactMethod::Mixed,
            MassVariant::Mod3,
            Scheme::Newmark(NewmarkParams::crank_nicolson()),
        ),
    ));
    let sp = Bar1dSpace::new(
        BarParams::default(),
        m,
        &MassVariant::Mod3,
        ContactMethod::Mixed,
    )
    .expect("a valid space");
    let lu = sp
        .mass
        .axpy(0.25 * dt * dt, &sp.stiffness_lin)
        .factor()
        .expect("M + cK is SPD");
    (cfg, lu)
}

/// Series off, no timeout.
const NO_SERIES: RunOptions = RunOptions {
    series_every: 0,
    timeout: None,
    cancel: None,
};

/// Per-step cost of a CN run against a bare Thomas solve, per node, for m = 10² … 10⁵.
/// Not a criterion benchmark: the two sides are timed in alternation so that both see the same
/// machine load, and their ratio is what is reported.
fn thomas_ratio(c: &mut Criterion) {
    if !wanted("thomas-ratio") {
        return;
    }
    let _ = c;
    println!(
        "\nthomas-ratio: one CN step (mixed, mod3, errors included) per node against one Thomas solve per node"
    );
    println!(
        "{:>8} {:>8} {:>14} {:>14} {:>8}",
        "m", "steps", "step ns/node", "Thomas ns/node", "ratio"
    );
    for m in [100usize, 1_000, 10_000, 100_000] {
        // About 3·10⁷ node-steps per sample: ≈ 0.25 s.
        let steps = (30_000_000 / m).max(10);
        let (cfg, lu) = cn_run_and_factor(m, steps);
        let rhs: Vec<f64> = (0..m).map(|i| 1.0 + (i % 7) as f64).collect();
        let mut x = rhs.clone();
        let (mut run_ns, mut thomas_ns) = (Vec::new(), Vec::new());
        for _ in 0..9 {
            let t = Instant::now();
            let out = simulate(&cfg, &NO_SERIES);
            run_ns.push(t.elapsed().as_secs_f64() * 1e9 / (steps * m) as f64);
            assert_eq!(out.metrics.steps as usize, steps);
            let t = Instant::now();
            for _ in 0..steps {
                // A fresh right-hand side each time, as a step builds one (repeated solves of
                // x ← A⁻¹x would grow like h⁻ⁿ and overflow): the copy is counted on this side.
                x.copy_from_slice(&rhs);
                lu.solve_in_place(&mut x);
            }
            std::hint::black_box(&x);
            thomas_ns.push(t.elapsed().as_secs_f64() * 1e9 / (steps * m) as f64);
        }
        let (r, t) = (median(run_ns), median(thomas_ns));
        println!("{m:>8} {steps:>8} {r:>14.2} {t:>14.2} {:>8.2}", r / t);
    }
}

/// Eight Thomas solves in the lanes of `[f64; 8]` rows: each lane does the arithmetic of
/// `TridiagLu::solve_in_place` (same operations, same order), the eight chains interleaved.
fn thomas_lanes(mult: &[f64], piv: &[f64], upper: &[f64], x: &mut [[f64; 8]]) {
    let n = piv.len();
    for i in 1..n {
        let (m, prev) = (mult[i - 1], x[i - 1]);
        for (xi, p) in x[i].iter_mut().zip(prev) {
            *xi -= m * p;
        }
    }
    for xi in x[n - 1].iter_mut() {
        *xi *= piv[n - 1];
    }
    for i in (0..n - 1).rev() {
        let (u, q, next) = (upper[i], piv[i], x[i + 1]);
        for (xi, nx) in x[i].iter_mut().zip(next) {
            *xi = (*xi - u * nx) * q;
        }
    }
}

/// 1D lockstep's ceiling (module header, `lanes-ratio`): the tridiagonal solve of 8 runs one by
/// one against 8 in lanes, per node and run, against a whole CN step per node.
fn lanes_ratio(c: &mut Criterion) {
    if !wanted("lanes-ratio") {
        return;
    }
    let _ = c;
    println!("\nlanes-ratio: ns per node and run; 8 runs, their solves one by one or in lanes");
    println!(
        "{:>8} {:>12} {:>12} {:>12} {:>10} {:>16}",
        "m", "CN step", "Thomas", "8 in lanes", "speed-up", "saving ≤ of step"
    );
    for m in [100usize, 1_000, 10_000] {
        let steps = (10_000_000 / m).max(10);
        let (cfg, lu) = cn_run_and_factor(m, steps);
        let (mult, piv, upper) = lu.parts();
        let rhs: Vec<Vec<f64>> = (0..8)
            .map(|l| (0..m).map(|i| 1.0 + ((i + l) % 7) as f64).collect())
            .collect();
        let rows: Vec<[f64; 8]> = (0..m).map(|i| std::array::from_fn(|l| rhs[l][i])).collect();
        let mut xs = rhs.clone();
        let mut xl = rows.clone();
        let (mut run_ns, mut one_ns, mut lanes_ns) = (Vec::new(), Vec::new(), Vec::new());
        let per =
            |t: Instant, runs: usize| t.elapsed().as_secs_f64() * 1e9 / (steps * m * runs) as f64;
        for _ in 0..7 {
            let t = Instant::now();
            simulate(&cfg, &NO_SERIES);
            run_ns.push(per(t, 1));
            let t = Instant::now();
            for _ in 0..steps {
                for (x, b) in xs.iter_mut().zip(&rhs) {
                    x.copy_from_slice(b);
                    lu.solve_in_place(x);
                }
            }
            std::hint::black_box(&xs);
            one_ns.push(per(t, 8));
            let t = Instant::now();
            for _ in 0..steps {
                xl.copy_from_slice(&rows);
                thomas_lanes(mult, piv, upper, &mut xl);
            }
            std::hint::black_box(&xl);
            lanes_ns.push(per(t, 8));
        }
        let same = (0..m).all(|i| (0..8).all(|l| xs[l][i].to_bits() == xl[i][l].to_bits()));
        assert!(same, "each lane does a single solve's arithmetic");
        let (r, o, l) = (median(run_ns), median(one_ns), median(lanes_ns));
        println!(
            "{m:>8} {r:>12.2} {o:>12.2} {l:>12.2} {:>10.1} {:>15.0} %",
            o / l,
            100.0 * (o - l) / r
        );
    }
}

/// Per-step cost of each contract §3.2 method against Crank–Nicolson, m = 10³ … 10⁵ (module header).
fn scheme_ratio(c: &mut Criterion) {
    use contact_sweep::time::{GeneralizedAlphaParams, MoreauJeanParams};
    if !wanted("scheme-ratio") {
        return;
    }
    let _ = c;
    let mixed = ContactMethod::Mixed;
    let cn = Scheme::Newmark(NewmarkParams::crank_nicolson());
    let methods = [
        ("kane", mixed, MassVariant::Consistent, Scheme::Kane),
        (
            "contact-stabilized-newmark",
            mixed,
            MassVariant::Consistent,
            Scheme::ContactStabilizedNewmark,
        ),
        (
            "generalized-alpha",
            mixed,
            MassVariant::Consistent,
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::from_rho_inf(0.5)),
        ),
        (
            "moreau-jean",
            mixed,
            MassVariant::Consistent,
            Scheme::MoreauJean(MoreauJeanParams::midpoint()),
        ),
        (
            "discrete-gradient",
            ContactMethod::Penalty { gamma0: 1.0 },
            MassVariant::Consistent,
            Scheme::DiscreteGradient,
        ),
        (
            "central-difference",
            mixed,
            MassVariant::Lumped,
            Scheme::Newmark(NewmarkParams::central_difference()),
        ),
    ];
    println!(
        "\nscheme-ratio: a run of each contract §3.2 method against Crank–Nicolson (ns per node-step)"
    );
    println!(
        "{:>8} {:>28} {:>10} {:>10} {:>8}",
        "m", "method", "method", "CN", "ratio"
    );
    for m in [1_000usize, 10_000, 100_000] {
        // About 2·10⁷ node-steps per sample, through the first impact (t ≥ 1.5 at ν ≤ 1).
        let steps = (20_000_000 / m).max(10);
        for (name, method, mass, scheme) in &methods {
            let nu = if name == &"central-difference" {
                0.9
            } else {
                1.0
            };
            let dt = nu / m as f64;
            let cfg = |method, mass, scheme| {
                RunConfig::Bar1d(Bar1dConfig::new(
                    BarParams::default(),
                    Grid1d::with_steps(m, dt, steps, method, mass, scheme),
                ))
            };
            let (a, b) = (
                cfg(*method, mass.clone(), *scheme),
                cfg(*method, mass.clone(), cn),
            );
            let (mut ta, mut tb) = (Vec::new(), Vec::new());
            for _ in 0..5 {
                for (cfg, out) in [(&a, &mut ta), (&b, &mut tb)] {
                    let t = Instant::now();
                    let o = simulate(cfg, &NO_SERIES);
                    out.push(t.elapsed().as_secs_f64() * 1e9 / (steps * m) as f64);
                    assert_eq!(o.metrics.steps as usize, steps, "{name}: {:?}", o.message);
                }
            }
            let (x, y) = (median(ta), median(tb));
            println!("{m:>8} {name:>28} {x:>10.2} {y:>10.2} {:>8.2}", x / y);
        }
    }
}

criterion_group!(
    benches,
    steps,
    executor,
    thomas_ratio,
    lanes_ratio,
    scheme_ratio
);
criterion_main!(benches);
