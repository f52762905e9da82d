//! Issue 45, done-when 5: the cost of a non-matching interface.
//!
//! `interface-setup/…`: the set-up of a non-matching interface as a mortar run makes it
//! (`space::fe::interface`): the projection's bins over Γ^b, the segmentation of Γ^a by Γ^b's
//! projected faces, and the mortar matrices D, M, the weighted gaps and ∫ψ_k on it — at four
//! sizes, each with about twice the faces of the one before ("grows linearly with the
//! interface, ≤ 2.5× per doubling of face count, 3D").
//!
//! - 3D: Γ^a the unit square as n × n Q1 faces at z = 0, Γ^b m × m faces at z = 0.2/n facing
//!   it, n and m coprime (20/27, 28/37, 40/53, 56/75: ratio ≈ 4/3, no grid line of one side on
//!   the other's except the border, so the pieces number ~(n + m)² at every size);
//! - 2D: Γ^a n segments of the unit interval, Γ^b 7n/5 (`mesh_ratio` 7/5, n = 500 … 4000).
//!
//! The reach (gap tolerance) is one face of Γ^a: a tolerance fixed in length while the faces
//! shrink would put (reach/h)² faces of Γ^b in every bin, which is not the interface growing
//! but the tolerance meaning more faces. Criterion's medians are wall clock and the machine
//! may be shared, so each size is also timed in the process's CPU time (median of 5) and the
//! ratios per doubling are printed.
//!
//! `mortar-step-cost`: one time step of a non-matching `blocks3d` (`mesh_ratio` 4/3, A 12 × 12
//! across on B 16 × 16, 6 870 dofs, 169 mortar rows) with `pairing = "mortar"` against
//! node-to-node on a matching `blocks3d`, `mixed` (standard and dual bases) and `penalty`
//! (γ0 = 10), consistent mass, Crank–Nicolson, τ = 1/64, A thrown down at 1 onto B thrown up at
//! ½ over a gap of 0.02 (contact from the first step, then chatter and release). Two matching
//! meshes, since equal dofs and equal rows cannot both hold: h = 1/15 with A 4 and B 3 cells up
//! (6 912 dofs, +0.6 %; 256 rows) — the done-when's "equal dofs" — and h = 1/12 with A 7 and B
//! 5 cells up (7 098 dofs, +3.3 %; 169 rows as the mortar's). Per row of the table, per step,
//! set-up excluded: the engine's stepping clock over a 32-step run, and the process's CPU over
//! steps 17–32 (a 32-step run's CPU less a 16-step run's, both finding the set-up cached);
//! medians of 5 rounds interleaved over the rows, in one process. Not a criterion group: a run
//! lasts seconds under load, and criterion's fewest samples would take minutes per row.
//!
//! Measured at issue 45 (`cargo bench --bench interface`, 2:45 min; 2 cores shared with other
//! builds, load average 9–10; docs/performance.md has the tables): the set-up grows linearly,
//! CPU ×2.03, ×2.06, ×1.54 per doubling of the faces in 3D (27.6, 55.9, 115.1, 177.5 ms;
//! criterion's wall medians 55.4, 120.5, 253.8, 514.4 ms: ×2.18, ×2.11, ×2.03) and ×2.05, ×2.06,
//! ×2.08 in 2D (1.08 … 9.44 ms) — target ≤ 2.5× met. A mortar step costs ×0.27 (clock) / ×0.40
//! (CPU) a node-to-node step at equal dofs with `mixed`, ×0.97 / ×1.00 with `penalty`; ×0.88 /
//! ×0.76 and ×0.98 / ×0.83 at equal rows — target ≤ 1.3× met.

use std::time::Duration;

use criterion::{Criterion, criterion_group};

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::cpu_seconds;

use contact_sweep::run::{RunConfig, RunOptions, simulate};
use contact_sweep::space::fe::interface::{
    Basis, FaceKind, Mortar, Projector, Surface, mortar_matrices, segment,
};

/// The unit square at height z as n × n quadrilaterals, normal +z (`up`) or −z.
fn sheet(n: usize, z: f64, up: bool) -> Surface {
    let h = 1.0 / n as f64;
    let mut coords = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            coords.push([h * i as f64, h * j as f64, z]);
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut conn = Vec::with_capacity(4 * n * n);
    for j in 0..n {
        for i in 0..n {
            let mut q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if !up {
                q.reverse();
            }
            conn.extend_from_slice(&q);
        }
    }
    Surface::new('a', FaceKind::Quad4, coords, conn).expect("a valid side")
}

/// The unit segment at height y as n segments, normal +y (`up`, ordered right to left: the
/// normal (t_y, −t_x) of a leftward tangent points up) or −y.
fn line(n: usize, y: f64, up: bool) -> Surface {
    let h = 1.0 / n as f64;
    let coords = (0..=n).map(|i| [h * i as f64, y, 0.0]).collect();
    let conn = (0..n)
        .flat_map(|i| if up { [i + 1, i] } else { [i, i + 1] })
        .collect();
    Surface::new('a', FaceKind::Seg2, coords, conn).expect("a valid side")
}

/// 3D: Γ^a n × n on Γ^b m × m (n, m coprime, m/n ≈ 4/3).
const SIZES_3D: [(usize, usize); 4] = [(20, 27), (28, 37), (40, 53), (56, 75)];
/// 2D: Γ^a n on Γ^b m = 7n/5 (`mesh_ratio` 7/5: every fifth node of Γ^a above one of Γ^b).
const SIZES_2D: [(usize, usize); 4] = [(500, 700), (1000, 1400), (2000, 2800), (4000, 5600)];

/// The two sides and the reach (one face of Γ^a) of size (n, m).
fn sides(dim: usize, n: usize, m: usize) -> (Surface, Surface, f64) {
    let h = 1.0 / n as f64;
    if dim == 3 {
        (sheet(n, 0.0, true), sheet(m, 0.2 * h, false), h)
    } else {
        (line(n, 0.0, true), line(m, 0.2 * h, false), h)
    }
}

/// The whole interface set-up of a mortar run: Π's bins, the segmentation, D, M and the gaps.
fn setup(a: &Surface, b: &Surface, reach: f64) -> Mortar {
    let proj = Projector::new(b, reach);
    let seg = segment(a, &proj).expect("a segmentation");
    mortar_matrices(a, b, &seg, Basis::Standard).expect("the mortar matrices")
}

/// Median of a sample (sorted in place).
fn median(t: &mut [f64]) -> f64 {
    t.sort_by(f64::total_cmp);
    let k = t.len() / 2;
    if t.len() % 2 == 1 {
        t[k]
    } else {
        0.5 * (t[k - 1] + t[k])
    }
}

/// Median CPU seconds of 5 set-ups.
fn cpu_median(a: &Surface, b: &Surface, reach: f64) -> f64 {
    let mut t: Vec<f64> = (0..5)
        .map(|_| {
            let t0 = cpu_seconds();
            std::hint::black_box(setup(a, b, reach));
            cpu_seconds() - t0
        })
        .collect();
    median(&mut t)
}

fn interface(c: &mut Criterion) {
    let sizes_cpu = if wants("interface-setup") {
        &[(3, SIZES_3D), (2, SIZES_2D)][..]
    } else {
        &[]
    };
    for &(dim, sizes) in sizes_cpu {
        let faces = |n: usize| if dim == 3 { n * n } else { n };
        let mut prev: Option<(usize, f64)> = None;
        for (n, m) in sizes {
            let (a, b, reach) = sides(dim, n, m);
            let proj = Projector::new(&b, reach);
            let pieces = segment(&a, &proj).expect("a segmentation").pieces.len();
            let cpu = cpu_median(&a, &b, reach);
            let ratio = prev.map_or(String::new(), |(f, t)| {
                format!(
                    ", ×{:.2} the time for ×{:.2} the faces",
                    cpu / t,
                    faces(n) as f64 / f as f64
                )
            });
            eprintln!(
                "{dim}D: {} faces on {}: {pieces} pieces, CPU median {:.2} ms{ratio}",
                faces(n),
                faces(m),
                cpu * 1e3
            );
            prev = Some((faces(n), cpu));
        }
    }
    let mut g = c.benchmark_group("interface-setup");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for (dim, sizes) in [(3, SIZES_3D), (2, SIZES_2D)] {
        for (n, m) in sizes {
            let (a, b, reach) = sides(dim, n, m);
            let faces = if dim == 3 { n * n } else { n };
            g.bench_function(format!("{dim}d-{faces}-faces"), |bench| {
                bench.iter(|| setup(&a, &b, reach))
            });
        }
    }
    g.finish();
}

/// The runs of the step-cost comparison (module header): label, the mesh keys and the method
/// keys of a blocks3d run, and the row it is compared with.
const STEP_RUNS: [(&str, &str, &str, usize); 7] = [
    ("node-to-node-mixed (equal dofs)", MATCHING_DOFS, MIXED, 0),
    ("node-to-node-mixed (equal rows)", MATCHING_ROWS, MIXED, 1),
    ("mortar-mixed", NONMATCHING, MIXED, 0),
    ("mortar-dual-mixed", NONMATCHING, MIXED_DUAL, 0),
    (
        "node-to-node-penalty (equal dofs)",
        MATCHING_DOFS,
        PENALTY,
        4,
    ),
    (
        "node-to-node-penalty (equal rows)",
        MATCHING_ROWS,
        PENALTY,
        5,
    ),
    ("mortar-penalty", NONMATCHING, PENALTY, 4),
];
const MIXED: &str = "space = \"mixed\"\nmortar_basis = \"standard\"";
const MIXED_DUAL: &str = "space = \"mixed\"\nmortar_basis = \"dual\"";
const PENALTY: &str = "space = \"penalty\"\npenalty_gamma0 = 10.0\nmortar_basis = \"standard\"";
/// h = 1/15, A 4 cells up, B 3: 16² × (5 + 4) nodes, 6 912 dofs; 256 rows.
const MATCHING_DOFS: &str = "h = 0.06666666666666667\nheight = 0.26666666666666666\nheight_b = 0.2\npairing = \"node-to-node\"";
/// h = 1/12, A 7 cells up, B 5: 13² × (8 + 6) nodes, 7 098 dofs; 169 rows as the mortar's.
const MATCHING_ROWS: &str = "h = 0.08333333333333333\nheight = 0.5833333333333334\nheight_b = 0.4166666666666667\npairing = \"node-to-node\"";
/// h = 1/12, A 12 across, B 16 (`mesh_ratio` 4/3), both 4 cells up: 13² × 5 + 17² × 5 nodes,
/// 6 870 dofs; 169 rows (Γ^a's nodes).
const NONMATCHING: &str = "h = 0.08333333333333333\nheight = 0.3333333333333333\nheight_b = 0.3333333333333333\nmesh_ratio = 1.3333333333333333\npairing = \"mortar\"";
/// τ of every comparison run, the steps of the short run (the long one has twice as many), the
/// interleaved rounds.
const DT: f64 = 0.015625;
const STEPS: f64 = 16.0;
const ROUNDS: usize = 5;

/// The blocks3d run of one comparison row, lasting `t`.
fn step_config(mesh: &str, method: &str, t: f64) -> RunConfig {
    let text = format!(
        "name = \"mortar-cost\"\nscene = \"blocks3d\"\n[fixed]\nT = {t:?}\ndt = {DT:?}\nvelocity = -1.0\nvelocity_b = 0.5\ngap = 0.02\nmass = \"consistent\"\nscheme = \"crank-nicolson\"\n{mesh}\n{method}\n"
    );
    let sweep = contact_sweep::sweep::SweepFile::parse(std::path::Path::new("cost.toml"), &text)
        .expect("valid sweep");
    let mut plan = contact_sweep::sweep::expand(&sweep).expect("plan");
    plan.runs.swap_remove(0).config
}

/// Per-step cost of one row: the engine's stepping clock per step of the long run, and the
/// process's CPU per step of its second half, CPU(2T) − CPU(T) (the set-up and the first T
/// alike in both and cancelled). The short run is made first once more so that both timed runs
/// find the set-up in the engine's caches (they keep 4 keys: the other rows evict it).
fn step_cost(short: &RunConfig, long: &RunConfig, opts: &RunOptions) -> (f64, f64) {
    simulate(short, opts);
    let t0 = cpu_seconds();
    let a = simulate(short, opts);
    let t1 = cpu_seconds();
    let b = simulate(long, opts);
    let t2 = cpu_seconds();
    let wall = b.metrics.stepping_time_s.expect("timed") / b.metrics.steps as f64;
    (wall, ((t2 - t1) - (t1 - t0)) / a.metrics.steps as f64)
}

/// Issue 45's step cost of mortar against node-to-node (module header): interleaved rounds,
/// medians, ratios printed. Not a criterion group: a run of 32 steps lasts seconds under load,
/// and criterion's fewest samples (55 runs per row) would take minutes per row.
fn mortar_cost() {
    let opts = RunOptions {
        series_every: 0,
        ..RunOptions::default()
    };
    let runs: Vec<(&str, RunConfig, RunConfig, usize)> = STEP_RUNS
        .iter()
        .map(|&(what, mesh, method, base)| {
            let short = step_config(mesh, method, STEPS * DT);
            let long = step_config(mesh, method, 2.0 * STEPS * DT);
            (what, short, long, base)
        })
        .collect();
    for (what, short, long, _) in &runs {
        let out = simulate(long, &opts);
        assert_eq!(out.status.as_str(), "ok", "{what}: {:?}", out.message);
        let RunConfig::Fe(cfg) = short else {
            unreachable!("blocks3d is an FE scene")
        };
        eprintln!(
            "{what}: {} dofs, {} steps, {} contact switches, {} contact iterations (at most {:?} in one step), set-up {:.3} s",
            cfg.unknowns(),
            out.metrics.steps,
            out.metrics.contact_switches,
            out.metrics.iterations,
            out.metrics.iterations_max_step.unwrap_or(0),
            out.metrics.setup_time_s.unwrap_or(f64::NAN)
        );
    }
    // Interleaved rounds: every row once per round, so a change of the machine's load falls on
    // all of them alike.
    let mut wall = vec![Vec::new(); runs.len()];
    let mut cpu = vec![Vec::new(); runs.len()];
    for _ in 0..ROUNDS {
        for (k, (_, short, long, _)) in runs.iter().enumerate() {
            let (w, p) = step_cost(short, long, &opts);
            wall[k].push(w);
            cpu[k].push(p);
        }
    }
    let w: Vec<f64> = wall.iter_mut().map(|v| median(v)).collect();
    let p: Vec<f64> = cpu.iter_mut().map(|v| median(v)).collect();
    for (k, (what, _, _, base)) in runs.iter().enumerate() {
        // The matching row of equal rows for the same treatment.
        let alt = if *base < 4 { 1 } else { 5 };
        eprintln!(
            "{what}: per step, median of {ROUNDS}: engine clock {:.3} ms (×{:.2}; ×{:.2} equal rows), CPU of steps {}–{} {:.3} ms (×{:.2}; ×{:.2} equal rows)",
            w[k] * 1e3,
            w[k] / w[*base],
            w[k] / w[alt],
            STEPS + 1.0,
            2.0 * STEPS,
            p[k] * 1e3,
            p[k] / p[*base],
            p[k] / p[alt],
        );
    }
}

/// Whether the group `name`'s own measurements run: no filter, or one that `name` contains
/// (`cargo bench --bench interface -- mortar` skips the set-up's CPU medians).
fn wants(name: &str) -> bool {
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()))
}

fn main() {
    if wants("mortar-step-cost") {
        mortar_cost();
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}

criterion_group!(benches, interface);
