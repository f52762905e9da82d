//! Two-body Gmsh files with non-matching interfaces (contract §1.10 "Two bodies from Gmsh",
//! §2.6; issue 45): a file whose Γ^a nodes do not lie above Γ^b's runs with the pairings that
//! project (`node-to-segment`, `mortar`, `space = nitsche`) on the same interface geometry as
//! the blocks' `mesh_ratio` ≠ 1 (the file's faces as surfaces, Π and the segmentation once
//! per run), and node-to-node refuses it at plan time naming `pairing`.
//!
//! The files are written here ([`two_body_msh`]: MSH 4.1 ASCII, the library's own boxes'
//! coordinates, Q1 or cut into P1 triangles and tetrahedra).

mod common;
mod two_body_msh;

use common::outcomes_at;
use contact_sweep::run::{Outcome, Status};
use two_body_msh::{Boxes, boxes_msh, boxes_msh_q2, difference, refused};

/// A sweep's runs with their labels.
type Runs = Vec<(String, Outcome)>;

/// blocks2d at h = 1/3 with mesh_ratio 4/3: A 3 × 3 squares on B 4 × 3.
const SQUARES: Boxes = Boxes {
    dim: 2,
    width: 1.0,
    height_a: 1.0,
    height_b: 1.0,
    across: 3,
    across_b: 4,
    cells_a: 3,
    cells_b: 3,
};

/// blocks3d likewise: A 3 × 3 × 3 cubes on B 4 × 4 × 3.
const CUBES: Boxes = Boxes { dim: 3, ..SQUARES };

/// The blocks sweep of `b` (mesh_ratio 4/3) and its Gmsh copy's, in a fresh folder; with
/// `clamped` B's base is clamped (blocks: `far_end`; the file: its `clamped` group).
fn both(b: Boxes, clamped: bool, physics: &str, methods: &str) -> (Runs, Runs) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("two.msh"),
        boxes_msh(b, clamped, false, 0.0),
    )
    .unwrap();
    let far_end = if clamped {
        "far_end = \"clamped\"\n"
    } else {
        ""
    };
    let blocks = format!(
        "name = \"k\"\nscene = \"blocks{}d\"\n[fixed]\nh = {}\nmesh_ratio = 1.3333333333333333\nwidth = {}\nheight = {}\nheight_b = {}\n{far_end}{physics}[grid]\n{methods}",
        b.dim,
        b.width / b.across as f64,
        b.width,
        b.height_a,
        b.height_b
    );
    let mesh = format!(
        "name = \"g\"\nscene = \"mesh{}d\"\n[fixed]\nmesh = \"two.msh\"\n{physics}[grid]\n{methods}",
        b.dim
    );
    let path = dir.path().join("s.toml");
    (outcomes_at(&path, &blocks), outcomes_at(&path, &mesh))
}

/// Both bodies move, their materials differ, the gap is the run's.
const PHYSICS: &str = "T = 0.8\ndt = 0.02\npenalty_gamma0 = 10.0\nnitsche_gamma0 = 0.05\ndensity = 1.0\nlame_lambda = 0.5\nlame_mu = 1.0\ndensity_b = 2.0\nlame_lambda_b = 0.25\nlame_mu_b = 0.5\nvelocity = -1.0\nvelocity_b = 0.5\ngap = 0.1\n";

/// Node-to-segment + mixed, mortar + penalty or mixed (dual basis), nitsche on the segmentation
/// and on Γ^i's element rule.
const METHODS: &str = r#"method = [
  { space = "mixed", pairing = "node-to-segment", mass = "consistent", scheme = "crank-nicolson" },
  { space = "penalty", pairing = "mortar", mass = "consistent", scheme = "crank-nicolson" },
  { space = "mixed", pairing = "mortar", mortar_basis = "dual", mass = "zero-contact", scheme = "backward-euler" },
  { space = "nitsche", mass = "zero-contact", scheme = "crank-nicolson" },
  { space = "nitsche", interface_quadrature = "element", mass = "zero-contact", scheme = "backward-euler" },
]
"#;

/// Every copy run ended ok, touched, and equals its blocks run to `tol` relative to each
/// column's scale or `floor`; returns the largest difference.
fn assert_copies(k: &Runs, g: &Runs, floor: f64, tol: f64) -> f64 {
    assert_eq!(k.len(), g.len());
    let mut worst = 0.0f64;
    for ((lk, ok), (lg, og)) in k.iter().zip(g) {
        assert_eq!(ok.status, Status::Ok, "{lk}: {:?}", ok.message);
        assert_eq!(og.status, Status::Ok, "{lg}: {:?}", og.message);
        assert!(
            ok.metrics.contact_phases.unwrap_or(0) >= 1,
            "{lk}: no contact"
        );
        let (d, name) = difference(ok, og, floor);
        eprintln!("{lk}: largest difference {d:e} ({name})");
        assert!(d <= tol, "{lk}: {name} differs by {d:e}");
        worst = worst.max(d);
    }
    worst
}

/// The Gmsh copy of non-matching blocks2d and blocks3d (mesh_ratio 4/3) runs as the blocks:
/// the same faces as surfaces (the file's vertices in the blocks' order, oriented outward as
/// the blocks' faces), so the same rows and points up to the round-off of the file's doubles
/// (B's top from its own box, A's bottom shifted by H_b, as the blocks) and of the face sizes
/// (γ = h per row from each face's measure). Tolerance 1e-12 relative to each column's scale
/// or 1 (the columns that are round-off themselves, momentum_drift ~1e-16, differ in their
/// own digits once two computations are not bit for bit); measured figures printed.
#[test]
fn gmsh_copies_of_non_matching_blocks_are_the_blocks() {
    for b in [SQUARES, CUBES] {
        let (k, g) = both(b, false, PHYSICS, METHODS);
        assert_eq!(g.len(), 5);
        let w = assert_copies(&k, &g, 1.0, 1e-12);
        eprintln!("{}D: worst difference {w:e}", b.dim);
    }
}

/// The implicit schemes each treatment takes on two bodies (tests/blocks_momentum.rs's lists).
const MIXED: &str = r#"scheme = [
  { scheme = "newmark", newmark_beta = 0.3, newmark_gamma = 0.6 },
  "crank-nicolson",
  "backward-euler",
  { scheme = "generalized-alpha", rho_inf = 0.5 },
]
"#;
const PENALTY: &str = r#"scheme = [
  { scheme = "newmark", newmark_beta = 0.3, newmark_gamma = 0.6 },
  "crank-nicolson",
  "backward-euler",
  "hybrid",
  { scheme = "generalized-alpha", rho_inf = 0.8 },
]
"#;
const NITSCHE: &str = r#"scheme = ["crank-nicolson", "backward-euler", "hybrid"]
"#;

/// One random two-body file (`simplex`: triangles/tetrahedra) and the [fixed] physics of a
/// random case: h (A's cells across), B's ratio, τ, materials, velocities, penalty γ0.
fn random_case(
    rng: &mut fastrand::Rng,
    dim: usize,
    simplex: bool,
    steps: usize,
) -> (String, String) {
    // Tetrahedra: A 2 × 2 across (Nitsche's 3D points on the segmentation of triangles are
    // many, and its condensed solve is dense over them).
    let across = match (dim, simplex) {
        (2, _) => rng.usize(3..=5),
        (_, false) => rng.usize(2..=3),
        _ => 2,
    };
    let ratio = [4.0 / 3.0, 1.4, 0.75][rng.usize(0..3)];
    let b = Boxes {
        dim,
        width: 1.0,
        height_a: 1.0,
        height_b: 1.0,
        across,
        across_b: ((across as f64 * ratio).round() as usize).max(1) + usize::from(rng.bool()),
        cells_a: 2,
        cells_b: 2,
    };
    let msh = boxes_msh(b, false, simplex, 0.05 * rng.f64());
    let dt = 0.01 + 0.03 * rng.f64();
    let fixed = format!(
        "T = {t}\ndt = {dt}\nvelocity = {va}\nvelocity_b = {vb}\ngap = {gap}\ndensity = {ra}\ndensity_b = {rb}\nlame_lambda = {la}\nlame_mu = {ma}\nlame_lambda_b = {lb}\nlame_mu_b = {mb}\npenalty_gamma0 = {g0}\nnitsche_gamma0 = 0.05\n",
        t = steps as f64 * dt,
        va = -0.5 - rng.f64(),
        vb = 0.5 * rng.f64() - 0.25,
        gap = 0.02 + 0.05 * rng.f64(),
        ra = 0.5 + rng.f64(),
        rb = 0.5 + rng.f64(),
        la = 2.0 * rng.f64(),
        ma = 0.5 + 1.5 * rng.f64(),
        lb = 2.0 * rng.f64(),
        mb = 0.5 + 1.5 * rng.f64(),
        g0 = 1.0 + 19.0 * rng.f64(),
    );
    (msh, fixed)
}

/// Issue 45 done-when 2 on files: `momentum_drift` ≤ 1e-12 on non-matching two-body files
/// (random h, B's lattice, τ, materials, velocities, a drawn gap in the file) for every
/// pairing (node-to-segment; mortar with both bases on both quadratures) × `mixed`/`penalty`
/// × scheme, and `nitsche` (both sides, both quadratures), 2D and 3D, Q1 and P1 cells. Every
/// row acts equally and oppositely (Σ_j N_j = 1, Σ_i D_ki = Σ_j M_kj; Nitsche's two traces at
/// one point), a rigid translation has no strain, so each scheme's balance keeps P to
/// round-off: O(10 ε) per step over ≤ 40 steps (tests/blocks_momentum.rs's bound).
#[test]
fn momentum_holds_on_non_matching_files() {
    let mut rng = fastrand::Rng::with_seed(4545);
    let pairings = "method = [\n  { pairing = \"node-to-segment\" },\n  { pairing = \"mortar\", mortar_basis = \"standard\" },\n  { pairing = \"mortar\", mortar_basis = \"dual\", interface_quadrature = \"element\" },\n]\n";
    let nitsche = "mass = [\"zero-contact\"]\nnitsche_sides = [\"unbiased\", \"a\"]\ninterface_quadrature = [\"segment\", \"element\"]\n";
    let mut worst = 0.0f64;
    let mut total = 0;
    for (dim, simplex, steps) in [(2, false, 40), (2, true, 40), (3, false, 12), (3, true, 8)] {
        let (msh, fixed) = random_case(&mut rng, dim, simplex, steps);
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("two.msh"), msh).unwrap();
        for (space, grid) in [
            ("mixed", format!("{MIXED}{pairings}")),
            ("penalty", format!("{PENALTY}{pairings}")),
            ("nitsche", format!("{NITSCHE}{nitsche}")),
        ] {
            let text = format!(
                "name = \"m\"\nscene = \"mesh{dim}d\"\n[fixed]\nmesh = \"two.msh\"\n{fixed}space = \"{space}\"\n[grid]\n{grid}"
            );
            let runs = outcomes_at(&dir.path().join("s.toml"), &text);
            assert!(runs.len() >= 4, "{space}: {} runs", runs.len());
            let w = common::assert_momentum(&runs, 1e-12);
            eprintln!(
                "{dim}D simplex {simplex} {space}: {} runs of {steps} steps, worst momentum_drift {w:e}",
                runs.len()
            );
            worst = worst.max(w);
            total += runs.len();
        }
    }
    eprintln!("{total} runs, worst momentum_drift {worst:e}");
}

/// The contact patch test (contract §1.10, §6's setting: tests/patch_nonmatching.rs) on a
/// non-matching file, B's base clamped by its group and p on A's `loaded` face, 2D and 3D:
/// mortar (both bases, `mixed` and `penalty`, the segmentation) and Nitsche on the
/// segmentation (both sides choices, Θ = −1, 0, 1) give the static solution,
/// `patch_stress_error` and `patch_pressure_error` ≤ 1e-8 (§6's bound: the solution is in the
/// discrete space and the segmentation integrates the rows exactly; round-off of the step's
/// solve remains).
#[test]
fn the_patch_test_passes_on_a_non_matching_file() {
    let physics = "T = 1e6\ndt = 1e6\nscheme = \"backward-euler\"\ngap = 0.0\nvelocity = 0.0\nvelocity_b = 0.0\nlame_lambda = 0.0\nlame_lambda_b = 0.0\nlame_mu = 1.0\nlame_mu_b = 2.0\npressure = 1e-2\npenalty_gamma0 = 10.0\n";
    let mortar = "pairing = \"mortar\"\n[grid]\nspace = [\"mixed\", \"penalty\"]\nmortar_basis = [\"standard\", \"dual\"]\n";
    let nitsche = "space = \"nitsche\"\nnitsche_gamma0 = 0.05\nmass = \"zero-contact\"\n[grid]\nnitsche_theta = [-1.0, 0.0, 1.0]\nnitsche_sides = [\"unbiased\", \"a\"]\n";
    for b in [SQUARES, CUBES] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("two.msh"), boxes_msh(b, true, false, 0.0)).unwrap();
        for (what, method, n) in [("mortar", mortar, 4), ("nitsche", nitsche, 6)] {
            let text = format!(
                "name = \"p\"\nscene = \"mesh{}d\"\n[fixed]\nmesh = \"two.msh\"\n{physics}{method}",
                b.dim
            );
            let runs = outcomes_at(&dir.path().join("s.toml"), &text);
            assert_eq!(runs.len(), n, "{what}");
            common::assert_patch(&format!("{}D file {what}", b.dim), &runs);
        }
    }
}

/// Bad non-matching files and keys, refused at plan time naming the file, the key and why.
#[test]
fn bad_non_matching_files_are_refused() {
    let good = boxes_msh(SQUARES, false, false, 0.0);
    // Node-to-node (the default) on a non-matching interface names the node and `pairing`.
    let e = refused(&good, 2, "");
    assert!(
        e.contains("two.msh")
            && e.contains("has no node of \"contact_b\" below it")
            && e.contains("set `pairing`"),
        "{e}"
    );
    let e = refused(&good, 2, "pairing = \"node-to-node\"\n");
    assert!(e.contains("pairing") && e.contains("set `pairing`"), "{e}");
    // The bodies drawn apart by more than h: the faces do not face each other.
    let far = boxes_msh(SQUARES, false, false, 0.5);
    let e = refused(&far, 2, "pairing = \"mortar\"\n");
    assert!(
        e.contains("two.msh") && e.contains("the faces do not face each other"),
        "{e}"
    );
    // A wider than B: A's end nodes project on B's edge.
    let wide = good.replacen("\n0.0 1.0 0.0\n", "\n-0.2 1.0 0.0\n", 1);
    assert_ne!(wide, good);
    let e = refused(&wide, 2, "pairing = \"node-to-segment\"\n");
    assert!(
        e.contains("two.msh") && e.contains("the projection leaves Γ^b"),
        "{e}"
    );
    // A's node sunk into B: the reader's overlap check of the cells sees it first.
    let sunk = good.replacen(
        "\n0.3333333333333333 1.0 0.0\n",
        "\n0.3333333333333333 0.99 0.0\n",
        1,
    );
    assert_ne!(sunk, good);
    let e = refused(&sunk, 2, "pairing = \"mortar\"\n");
    assert!(e.contains("two.msh") && e.contains("overlap"), "{e}");
    // The interface keys on a one-body file, and with the wrong treatment.
    let e = refused(&good, 2, "space = \"nitsche\"\npairing = \"mortar\"\n");
    assert!(e.contains("pairing = mortar with space = nitsche"), "{e}");
}

/// Degree-2 cells on a non-matching interface (Q2, straight faces): `node-to-segment` and
/// `mortar` build their rows on the faces' vertices and are refused at plan time naming the
/// file and `pairing`; `nitsche` takes them (each point's traces from its own Q2 cells, Π on
/// the straight vertex surface, exact for straight faces) and keeps the momentum to 1e-12
/// (as above: round-off per step over 40 steps).
#[test]
fn degree_two_cells_on_a_non_matching_file() {
    let msh = boxes_msh_q2(Boxes {
        cells_a: 2,
        cells_b: 2,
        ..SQUARES
    });
    for pairing in ["node-to-segment", "mortar"] {
        let e = refused(&msh, 2, &format!("pairing = \"{pairing}\"\n"));
        assert!(
            e.contains("two.msh") && e.contains(&format!("pairing = {pairing} on degree-2 cells")),
            "{e}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("two.msh"), &msh).unwrap();
    let text = format!(
        "name = \"q2\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"two.msh\"\n{PHYSICS}space = \"nitsche\"\nmass = \"zero-contact\"\n[grid]\nnitsche_sides = [\"unbiased\", \"a\"]\nscheme = [\"crank-nicolson\", \"backward-euler\"]\n"
    );
    let runs = outcomes_at(&dir.path().join("s.toml"), &text);
    assert_eq!(runs.len(), 4);
    let w = common::assert_momentum(&runs, 1e-12);
    eprintln!("Q2 non-matching nitsche: worst momentum_drift {w:e}");
}
