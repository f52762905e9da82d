//! What the FE benchmarks share (`benches/fe.rs`, `benches/solves.rs`): the bars of
//! `scene::bar` as the engine sets them up, and their step matrix assembled outside the engine.

use contact_sweep::run::fe::{FeConfig, cholesky_options};
use contact_sweep::scene::{BarScene, MeshChoice, Physics, Scene, SceneSetup};
use contact_sweep::space::fe::{BoxMesh, DofMap, ElementOp, SymMatrix, assemble, fe_pattern};
use contact_sweep::space::linalg::CholeskyOptions;
use contact_sweep::space::step_solver::Solver;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{NewmarkParams, Scheme};

/// The `dim`-D bar at mesh size `h`: mixed, mod3, Crank–Nicolson, τ = h/2, `steps` steps.
pub fn config(dim: usize, h: f64, steps: usize) -> FeConfig {
    let scene = BarScene { dim };
    let physics = Physics(
        scene
            .physics()
            .iter()
            .map(|k| (k.name, k.default))
            .collect(),
    );
    let mesh: MeshChoice = scene.mesh_from_h(&physics, h).unwrap();
    let SceneSetup::Fe(setup) = scene.setup(&physics, mesh) else {
        unreachable!("the bars are FE scenes")
    };
    FeConfig {
        setup,
        method: ContactMethod::Mixed,
        mass: MassVariant::Mod3,
        scheme: Scheme::Newmark(NewmarkParams::crank_nicolson()),
        dt: h / 2.0,
        steps,
        solver: Solver::Direct,
        perturbation: None,
        friction: contact_sweep::contact::friction::FrictionLaw::None,
        contact_init: contact_sweep::space::ContactInit::Consistent,
    }
}

/// The step matrix A = M + τ²/4 K of `config` (mod3 mass), assembled outside the engine, and
/// the engine's choice of ordering and factor kind for it.
pub fn step_matrix(cfg: &FeConfig) -> (SymMatrix, usize, CholeskyOptions) {
    let contact_sweep::scene::FeGeometry::Box { extent, cells } = &cfg.setup.geometry else {
        panic!("the bench runs the bars");
    };
    let mesh = BoxMesh::new(extent, cells);
    let d = mesh.dim;
    let dofs = DofMap::new(mesh.num_nodes() * d, |g| {
        mesh.node_index(g / d)[d - 1] == cells[d - 1]
    });
    let p = fe_pattern(&mesh, &dofs);
    let k = assemble(
        &mesh,
        &dofs,
        &p,
        ElementOp::Stiffness {
            lambda: 0.25,
            mu: 0.5,
        },
        &|_| 1.0,
    );
    let m = assemble(
        &mesh,
        &dofs,
        &p,
        ElementOp::Mass { rho: 1.0 },
        &|e| match mesh.element_layer(e) {
            0 => 0.0,
            1 => 2.0,
            _ => 1.0,
        },
    );
    let tau = cfg.dt;
    let opts = cholesky_options(&mesh, &dofs);
    (
        SymMatrix::lin_comb(1.0, &m, tau * tau / 4.0, &k),
        dofs.n_free(),
        opts,
    )
}
