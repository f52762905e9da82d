//! Benchmarks of the 1D engine, reusing the bar of SPEC §1.1.
//!
//! - `step/…`: one run per scheme at m = 1000, ν = 1, one period (3000 steps): the cost of the
//!   O(m) step (tridiagonal solve + exact scalar contact solve + exact error integration).
//! - `observe/…`: the same run with and without the time series, to show what storing it costs.
//! - `exec/…`: a 16-run plan on the serial loop and on the rayon pool (2 threads): the ratio is
//!   the parallel speed-up measured in one process, both sides under the same machine load.
//!
//! `cargo bench --bench bar1d`; compare medians, not single runs.

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

use contact_sweep::exec::{self, ExecOptions};
use contact_sweep::run::bar1d::Bar1dConfig;
use contact_sweep::run::{RunConfig, RunOptions, simulate};
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::sweep::{self, SweepFile};
use contact_sweep::time::{NewmarkParams, PaoliSchatzmanParams, Scheme, ThetaParams};

fn config(method: ContactMethod, mass: MassVariant, scheme: Scheme) -> RunConfig {
    let m = 1000;
    RunConfig::Bar1d(Bar1dConfig::new(
        BarParams::default(),
        m,
        1.0 / m as f64,
        3.0,
        method,
        mass,
        scheme,
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
    let no_series = RunOptions {
        series_every: 0,
        timeout: None,
        cancel: None,
    };
    for (name, cfg) in &cases {
        g.bench_function(*name, |b| b.iter(|| simulate(cfg, &no_series)));
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

criterion_group!(benches, steps, executor);
criterion_main!(benches);
