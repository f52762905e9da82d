//! The set-up of a non-matching 3D interface — the projection's bins over Γ^b and the
//! segmentation of Γ^a by Γ^b's projected faces (`space::fe::interface`) — at four sizes, each
//! with about twice the faces of the one before (issue 45, done-when 5, first half: "grows
//! linearly with the interface, ≤ 2.5× per doubling of face count, 3D").
//!
//! Γ^a: the unit square as n × n Q1 faces at z = 0; Γ^b: m × m faces at z = 0.2/n, facing it,
//! with n, m coprime (20/27, 28/37, 40/53, 56/75: ratio ≈ 4/3, no grid line of one side on the
//! other's except the border, so the pieces number ~(n + m)² at every size). The reach (gap
//! tolerance) is one face of Γ^a: a tolerance fixed in length while the faces shrink would put
//! (reach/h)² faces of Γ^b in every bin, which is not the interface growing but the tolerance
//! meaning more faces.
//!
//! Criterion's medians are wall clock; the machine running it may be shared, so the set-up also
//! times each size in the process's CPU time (median of 5) and prints the ratios per doubling.
//!
//! Measured once at issue 45 (`cargo bench --bench interface`, 2 cores shared with ~8 builds,
//! load average 11–16): linear, ≤ 2.11× the CPU time per doubling of the faces (the wall-clock
//! medians move with the load of the moment).
//!
//! | Γ^a on Γ^b | pieces | CPU median of 5 | ratio | criterion median (wall) |
//! | --- | --- | --- | --- | --- |
//! | 20² on 27² | 2 116 | 4.83 ms | | 15.0 ms |
//! | 28² on 37² | 4 096 | 9.30 ms | 1.93 (faces × 1.96) | 25.8 ms |
//! | 40² on 53² | 8 464 | 19.65 ms | 2.11 (faces × 2.04) | 54.6 ms |
//! | 56² on 75² | 16 900 | 40.56 ms | 2.06 (faces × 1.96) | 146.4 ms |

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::cpu_seconds;

use contact_sweep::space::fe::interface::{FaceKind, Projector, Segmentation, Surface, segment};

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

const SIZES: [(usize, usize); 4] = [(20, 27), (28, 37), (40, 53), (56, 75)];

/// The two sides and the reach of size (n, m).
fn sides(n: usize, m: usize) -> (Surface, Surface, f64) {
    let h = 1.0 / n as f64;
    (sheet(n, 0.0, true), sheet(m, 0.2 * h, false), h)
}

fn setup(a: &Surface, b: &Surface, reach: f64) -> Segmentation {
    let proj = Projector::new(b, reach);
    segment(a, &proj).expect("a segmentation")
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
    t.sort_by(f64::total_cmp);
    t[2]
}

fn interface(c: &mut Criterion) {
    let mut prev: Option<(usize, f64)> = None;
    for (n, m) in SIZES {
        let (a, b, reach) = sides(n, m);
        let pieces = setup(&a, &b, reach).pieces.len();
        let cpu = cpu_median(&a, &b, reach);
        let ratio = prev.map_or(String::new(), |(f, t)| {
            format!(
                ", ×{:.2} the time for ×{:.2} the faces",
                cpu / t,
                (n * n) as f64 / f as f64
            )
        });
        eprintln!(
            "{n}×{n} on {m}×{m}: {pieces} pieces, CPU median {:.2} ms{ratio}",
            cpu * 1e3
        );
        prev = Some((n * n, cpu));
    }
    let mut g = c.benchmark_group("interface-setup");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for (n, m) in SIZES {
        let (a, b, reach) = sides(n, m);
        g.bench_function(format!("{}-faces", n * n), |bench| {
            bench.iter(|| setup(&a, &b, reach))
        });
    }
    g.finish();
}

criterion_group!(benches, interface);
criterion_main!(benches);
