//! Point location for references on meshes that are not nested (issue 22, SPEC §1.6): a disc
//! of Q2 elements with ~10⁵ nodes located node by node in a disc of ~10⁶ nodes (the mapped
//! meshes of two sizes, not nested), and the index built on the fine mesh.
//!
//! - `locate/build-1e6`: the bins of the fine mesh ([`PointLocator::new`]).
//! - `locate/weights-1e5-in-1e6`: every coarse node located (bins, then Newton on the inverse
//!   isoparametric map) and its interpolation weights computed — what a coarse run does once
//!   against its reference.
//!
//! `cargo bench --bench locate`; the README's Performance section has the medians.

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};

use contact_sweep::space::fe::locate::PointLocator;
use contact_sweep::space::fe::{BallMesh, Mesh};

fn disc(h: f64) -> BallMesh {
    BallMesh::with_size(2, 2, 20.0, [0.0, 21.0, 0.0], h).expect("a valid disc")
}

fn locate(c: &mut Criterion) {
    // h = 0.095 → 1.0·10⁶ nodes, h = 0.3 → 1.0·10⁵ (nodes ≈ 8968/h² for the Q2 disc).
    let fine = disc(0.095);
    let coarse = disc(0.3);
    let points: Vec<[f64; 3]> = (0..coarse.num_nodes()).map(|n| coarse.coord(n)).collect();
    eprintln!(
        "locate: {} coarse nodes in a mesh of {} nodes, {} elements",
        points.len(),
        fine.num_nodes(),
        fine.num_elements()
    );
    let mut g = c.benchmark_group("locate");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.bench_function("build-1e6", |b| {
        b.iter(|| PointLocator::new(&fine).expect("supported kind"))
    });
    let loc = PointLocator::new(&fine).expect("supported kind");
    g.bench_function("weights-1e5-in-1e6", |b| {
        b.iter(|| {
            let mut total = 0.0;
            for &x in &points {
                total += loc
                    .weights(x)
                    .expect("every coarse node is in the fine disc")
                    .iter()
                    .map(|w| w.1)
                    .sum::<f64>();
            }
            total
        })
    });
    g.finish();
}

criterion_group!(benches, locate);
criterion_main!(benches);
