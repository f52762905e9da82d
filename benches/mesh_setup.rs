//! A mesh scene's set-up against its size (issue 36, done-when 3): a 1 × n strip of Q1 squares
//! (`contact` at the bottom, so n mass layers) at n = 20 000 and 80 000, planned and run for one
//! step through the library — the plan reads and validates the file (parse, det J, conformity,
//! coincident nodes, groups), the run builds its geometry (dofs, pattern, K, M, the mass layers,
//! Γ_C's faces), factors its step matrix (banded: linear in n) and makes one step. Done when
//! 80 000 costs at most 5× 20 000 (the layer sweep scanned every cell per layer: 1.0, 3.4 and
//! 13.6 s at 20 000, 40 000, 80 000, 14×).
//!
//! Each iteration writes the strip with its own `$Comments` line, so its content hash — and
//! with it the process-wide mesh and geometry caches' keys — is new: every iteration sets up.
//!
//! `cargo bench --bench mesh_setup`; prints the medians' ratio. docs/performance.md has them.

use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};

use contact_sweep::exec::{self, ExecOptions};
use contact_sweep::run::RunOptions;
use contact_sweep::sweep::{SweepFile, expand};

/// The MSH 4.1 text of [0, 1] × [0, n] as n unit squares stacked along y (nodes (i, j), tag
/// 1 + i + 2 j), `contact` = the bottom edge, `body` = the squares; `note` goes in a comment.
fn strip_msh(n: usize, note: usize) -> String {
    let mut s = String::new();
    s.push_str("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    writeln!(s, "$Comments\niteration {note}\n$EndComments").unwrap();
    s.push_str("$PhysicalNames\n2\n1 1 \"contact\"\n2 2 \"body\"\n$EndPhysicalNames\n");
    s.push_str("$Entities\n0 1 1 0\n1 0 0 0 1 0 0 1 1 0\n");
    writeln!(s, "1 0 0 0 1 {n} 0 1 2 0\n$EndEntities").unwrap();
    let nn = 2 * (n + 1);
    writeln!(s, "$Nodes\n1 {nn} 1 {nn}\n2 1 0 {nn}").unwrap();
    for t in 1..=nn {
        writeln!(s, "{t}").unwrap();
    }
    for j in 0..=n {
        writeln!(s, "0 {j} 0\n1 {j} 0").unwrap();
    }
    s.push_str("$EndNodes\n");
    writeln!(s, "$Elements\n2 {} 1 {}\n1 1 1 1\n1 1 2", n + 1, n + 1).unwrap();
    writeln!(s, "2 1 3 {n}").unwrap();
    let tag = |i: usize, j: usize| 1 + i + 2 * j;
    for j in 0..n {
        writeln!(
            s,
            "{} {} {} {} {}",
            j + 2,
            tag(0, j),
            tag(1, j),
            tag(1, j + 1),
            tag(0, j + 1)
        )
        .unwrap();
    }
    s.push_str("$EndElements\n");
    s
}

/// Plan and run one step of the strip (mixed contact, mod3 mass: the layers are used).
fn setup(dir: &Path, n: usize, note: usize) -> Duration {
    let mesh = dir.join("strip.msh");
    std::fs::write(&mesh, strip_msh(n, note)).expect("the mesh written");
    let text = "name = \"strip\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"strip.msh\"\ndt = 0.01\nT = 0.01\nmass = \"mod3\"\nscheme = \"crank-nicolson\"\nvelocity = -0.5\n";
    let start = Instant::now();
    let sweep = SweepFile::parse(&dir.join("strip.toml"), text).expect("valid sweep");
    let plan = expand(&sweep).expect("plan");
    let runs: Vec<_> = plan.runs.iter().collect();
    let opts = RunOptions {
        series_every: 0,
        timeout: None,
        cancel: None,
    };
    let refs = exec::references::ensure(dir, &plan, &runs, &opts).expect("references");
    let mut status = Vec::new();
    exec::execute::<()>(
        &plan.sweep.name,
        &runs,
        &refs,
        &ExecOptions {
            threads: 1,
            lockstep: ExecOptions::LOCKSTEP_DEFAULT,
            run: opts,
        },
        |r| {
            status.push(r.record.status.clone());
            Ok(())
        },
    )
    .expect("the run");
    let took = start.elapsed();
    assert_eq!(status.len(), 1);
    took
}

fn mesh_setup(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mut g = c.benchmark_group("strip-setup");
    g.sample_size(10).warm_up_time(Duration::from_millis(100));
    let mut medians = Vec::new();
    for n in [20_000, 80_000] {
        let mut note = 0;
        let mut samples = Vec::new();
        g.bench_function(format!("n={n}"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    note += 1;
                    let t = setup(dir.path(), n, note);
                    samples.push(t.as_secs_f64());
                    total += t;
                }
                total
            })
        });
        samples.sort_by(f64::total_cmp);
        medians.push(samples[samples.len() / 2]);
    }
    g.finish();
    println!(
        "strip set-up medians: n = 20 000: {:.3} s, n = 80 000: {:.3} s, ratio {:.2} (done when ≤ 5)",
        medians[0],
        medians[1],
        medians[1] / medians[0]
    );
}

criterion_group!(benches, mesh_setup);
criterion_main!(benches);
