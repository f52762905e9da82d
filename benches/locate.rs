//! Point location for references on meshes that are not nested (issue 22, contract §1.6,
//! done-when 5: "locating 10⁵ coarse nodes in a 10⁶-node reference mesh takes less than 1 s"),
//! on the two kinds of bodies a sweep meets:
//!
//! - the disc of Q2 elements (`disc2d`'s mapped mesh): ~10⁵ nodes located node by node in a
//!   disc of ~10⁶ nodes (the mapped meshes of two sizes are not nested);
//! - a mesh scene's Gmsh file: the Hertz half-disc (`sweeps/meshes/hertz_halfdisc.geo`, P2
//!   triangles, unstructured, graded 4:1 towards the contact point, curved P2 edges on the arc)
//!   meshed by Gmsh at two sizes (`-clscale` 0.114 and 0.036: ~10⁵ and ~10⁶ nodes). Gmsh is
//!   installed by `tests/install_gmsh.sh` as the tests do; the two files are made once into
//!   cargo's target temporary folder (~30 s for the fine one) and reused by later runs.
//!
//! Per body:
//! - `…/build-1e6`: the bins of the fine mesh ([`PointLocator::new`]).
//! - `…/weights-1e5-in-1e6`: every coarse node located (bins, then Newton on the inverse
//!   isoparametric map) and its interpolation weights computed — what a coarse run does once
//!   against its reference.
//!
//! `cargo bench --bench locate`; docs/performance.md has the medians.

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};

use std::path::{Path, PathBuf};
use std::process::Command;

use contact_sweep::space::fe::locate::PointLocator;
use contact_sweep::space::fe::{BallMesh, GmshMesh, Mesh};

fn disc(h: f64) -> BallMesh {
    BallMesh::with_size(2, 2, 20.0, [0.0, 21.0, 0.0], h).expect("a valid disc")
}

/// The Hertz half-disc meshed by Gmsh with its sizes scaled by `scale`, made once into cargo's
/// target temporary folder (module header).
fn hertz(scale: f64) -> GmshMesh {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("locate_meshes");
    std::fs::create_dir_all(&dir).expect("the target folder is writable");
    let file = dir.join(format!("hertz_halfdisc_{scale}.msh"));
    if !file.exists() {
        let ok = |c: &mut Command| c.status().is_ok_and(|s| s.success());
        assert!(
            ok(Command::new("bash").arg(root.join("tests/install_gmsh.sh"))),
            "gmsh is missing and tests/install_gmsh.sh failed"
        );
        // Written under another name first: an interrupted run leaves no half file behind.
        let part = file.with_extension("part");
        assert!(
            ok(Command::new("gmsh")
                .args(["-v", "1", "-format", "msh41", "-bin", "-2", "-order", "2"])
                .args(["-clscale", &scale.to_string()])
                .arg(root.join("sweeps/meshes/hertz_halfdisc.geo"))
                .arg("-o")
                .arg(&part)),
            "gmsh failed on hertz_halfdisc.geo"
        );
        std::fs::rename(&part, &file).expect("rename");
    }
    GmshMesh::read(&file).unwrap_or_else(|e| panic!("{e}"))
}

/// The two benchmarks of one body: the fine mesh's bins, and every coarse node located.
fn bench_body(c: &mut Criterion, name: &str, fine: &dyn Mesh, coarse: &dyn Mesh) {
    let points: Vec<[f64; 3]> = (0..coarse.num_nodes()).map(|n| coarse.coord(n)).collect();
    eprintln!(
        "{name}: {} coarse nodes in a mesh of {} nodes, {} elements",
        points.len(),
        fine.num_nodes(),
        fine.num_elements()
    );
    let mut g = c.benchmark_group(name);
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.bench_function("build-1e6", |b| {
        b.iter(|| PointLocator::new(fine).expect("supported kind"))
    });
    let loc = PointLocator::new(fine).expect("supported kind");
    g.bench_function("weights-1e5-in-1e6", |b| {
        b.iter(|| {
            let mut total = 0.0;
            for &x in &points {
                total += loc
                    .weights(x)
                    .expect("every coarse node is in the fine body")
                    .iter()
                    .map(|w| w.1)
                    .sum::<f64>();
            }
            total
        })
    });
    g.finish();
}

fn locate(c: &mut Criterion) {
    // h = 0.095 → 1.0·10⁶ nodes, h = 0.3 → 1.0·10⁵ (nodes ≈ 8968/h² for the Q2 disc).
    bench_body(c, "locate", &disc(0.095), &disc(0.3));
    // Nodes ∝ scale⁻² (1 604 at scale 1; 8.2·10⁵ at 0.04): 0.114 → 1.0·10⁵, 0.036 → 1.0·10⁶.
    bench_body(c, "locate-gmsh-p2", &hertz(0.036), &hertz(0.114));
}

criterion_group!(benches, locate);
criterion_main!(benches);
