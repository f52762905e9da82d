//! The matrices of one run: the mass variant, the step matrix A = M + cτ²K (mixed) or its
//! Nitsche/penalty form, its factor (or A itself for CG), and the condensation Z = A⁻¹Cᵀ,
//! W = cτ²CZ onto the contact rows. Made once per key and shared through [`FACTORS`].

use super::bodies::frictional_points;
use super::cache::{Cache, geometry_key};
use super::config::{FeConfig, frictional};
use super::full_newton::full_only;
use super::geometry::{Geometry, reduce_points, tangential_rows};
use super::mass::mass_matrix;
use super::nitsche::{NitscheOps, SPARSE_MIN_ACTIVE};
use super::nitsche_pair::sided_points;
use super::rows::Rows;
use super::schur::ContactSchur;
use crate::run::Status;
use crate::scene::{FeGeometry, InterfaceQuadrature};
use crate::space::ContactMethod;
use crate::space::fe::SymMatrix;
use crate::space::fe::nitsche::ContactPoint;
use crate::space::step_solver::StepSolver;

/// The status of a run whose matrices could not be made: a mass variant the mesh cannot take
/// ("mass = …", [`super::mass::mass_matrix`]) is the input's fault, anything else the solver's.
pub(super) fn factor_failure(message: &str) -> Status {
    if message.starts_with("mass = ") {
        Status::Invalid
    } else {
        Status::SolverFailed
    }
}

/// The matrices of one run: its mass variant and the factored (or, with `cg`, the iterated)
/// condensed step matrix.
#[derive(Debug)]
pub(super) struct Factored {
    pub(super) m: SymMatrix,
    /// M without its stored zeros, for the products of the time loop ([`SymMatrix::without_zeros`]:
    /// the same numbers, half the entries of the 2D vector mass).
    pub(super) m_products: SymMatrix,
    pub(super) mass_total: f64,
    /// The step solves: the Cholesky factor of A, or A itself for CG.
    pub(super) chol: StepSolver,
    /// Z = A⁻¹Bᵀ, column-major (n × n_c).
    pub(super) z: Vec<f64>,
    /// Mixed: H = cτ² B Z (n_c × n_c, row-major). Nitsche: W = P Z (Q × Q, row-major).
    pub(super) h: Vec<f64>,
    /// Nitsche's rows of the run (Θ, γ0 applied); Z's columns are then A⁻¹(−t_q).
    pub(super) nitsche: Option<NitscheOps>,
    /// Mixed with friction (contract §2.5): the tangential rows; Z then holds the tangential
    /// columns after the normal ones.
    pub(super) friction: Option<FrictionFactor>,
    /// Whether Z and W were made: false for the two-body runs solved on the full system only
    /// ([`super::full_newton::full_only`]; `z` and `h` are then empty).
    pub(super) condensed: bool,
    /// Frictional Nitsche/penalty with at least [`SPARSE_MIN_ACTIVE`] unknowns: S = R A⁻¹ Rᵀ over
    /// the points' dofs, for the Newton on large active sets ([`super::schur`]); `None` otherwise.
    pub(super) schur: Option<ContactSchur>,
}

/// The mixed method's condensation over the normal and tangential rows C of Γ_C.
#[derive(Debug)]
pub(super) struct FrictionFactor {
    /// The tangential rows of the Γ_C nodes, node-major (d − 1 per node, e_1 then e_2;
    /// [`tangential_rows`]: one body's unit dofs, two bodies' relative slips): Z's column
    /// nc + i(d − 1) + c is A⁻¹ of row i(d − 1) + c.
    pub(super) tangential: Rows,
    /// W = cτ² C Z (dm × dm, row-major), rows and columns node-major [normal, tangential…].
    pub(super) w: Vec<f64>,
}

pub(super) static FACTORS: Cache<Factored> = Cache::new();

/// The part of a factor's cache key beyond geometry, mass, method and step: the run's gap when
/// the Nitsche/penalty rows carry it (box and Gmsh meshes, [`factor`]); empty otherwise, so the
/// mixed runs and the ball share their entries as before.
/// The identity of a run's step matrix and condensation (the [`FACTORS`] cache's key): the
/// geometry, mass, contact method, cτ² and solver — and the gap where it enters the operators.
/// The solver is part of it: a `cg` entry holds A itself, not its factor.
pub(super) fn factor_key(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> String {
    format!(
        "{}|{:?}|{:?}|{:e}|{:?}",
        geometry_key(&cfg.setup),
        cfg.mass,
        cfg.method,
        c_tau2,
        cfg.solver
    ) + &factor_key_gap(g, cfg)
        + if frictional(cfg) && cfg.method == ContactMethod::Mixed {
            // The tangential columns are added: not the frictionless entry.
            "|friction"
        } else {
            ""
        }
        + &factor_key_friction(cfg)
}

/// A frictional Nitsche/penalty run's factor has the tangential rows (their k_q = 1/(γτ) holds
/// τ itself, not only cτ²): its own entry; empty for every other run.
pub(super) fn factor_key_friction(cfg: &FeConfig) -> String {
    if frictional(cfg) && cfg.method != ContactMethod::Mixed {
        format!("|friction τ {:e}", cfg.dt)
    } else {
        String::new()
    }
}

pub(super) fn factor_key_gap(g: &Geometry, cfg: &FeConfig) -> String {
    if cfg.method == ContactMethod::Mixed || g.gap_in_geometry {
        String::new()
    } else {
        format!("|gap {:e}", cfg.setup.gap)
    }
}

pub(super) fn factor(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> Result<Factored, String> {
    let points = || -> Result<&[ContactPoint], String> {
        match &g.points {
            Ok(p) if !p.is_empty() => Ok(p),
            Ok(_) => Err(format!(
                "space = {} is not available for scene {}: Γ_C has no quadrature points",
                cfg.method.name(),
                cfg.setup.scene
            )),
            Err(e) => Err(format!(
                "space = {} is not available for scene {}: {e}",
                cfg.method.name(),
                cfg.setup.scene
            )),
        }
    };
    // Two bodies: the frictional penalty's node points carry the relative slip's rows too, and
    // Nitsche takes both faces' points (which carry them as well).
    let penalty = matches!(cfg.method, ContactMethod::Penalty { .. });
    let slip_points = if penalty && frictional(cfg) && g.bodies.is_some() {
        let nt = g.mesh.dim() - 1;
        Some(frictional_points(points()?, &tangential_rows(g)?, nt))
    } else if matches!(cfg.method, ContactMethod::Nitsche { .. }) && g.bodies.is_some() {
        // Two bodies: Nitsche's points of both faces, weighted per `nitsche_sides`
        // ([`super::nitsche_pair`]); `g.points` are the penalty's node rows there.
        Some(pair_points(g, cfg)?)
    } else {
        None
    };
    let points = || -> Result<&[ContactPoint], String> {
        match &slip_points {
            Some(p) => Ok(p),
            None => points(),
        }
    };
    let mut ops = match cfg.method {
        ContactMethod::Nitsche { theta, gamma0 } => NitscheOps::new(points()?, theta, gamma0),
        ContactMethod::Penalty { gamma0 } => {
            // Young's modulus E = μ(3λ + 2μ)/(λ + μ) of κ = E·γ0/h_K (contract §2.4); two
            // bodies: E_a = λ_a + 2μ_a and h A's mesh size (contract §2.6).
            let (l, m) = (cfg.setup.lame_lambda, cfg.setup.lame_mu);
            let young = if g.bodies.is_some() {
                l + 2.0 * m
            } else {
                m * (3.0 * l + 2.0 * m) / (l + m)
            };
            NitscheOps::penalty(points()?, young, gamma0)
        }
        ContactMethod::Mixed => return factor_mixed(g, cfg, c_tau2),
    };
    // The box's and Gmsh meshes' points hold their heights above Γ_C's lowest level; the
    // plane is the run's gap below it (the ball's gap is in its geometry: nothing added).
    if !g.gap_in_geometry {
        ops.gap.iter_mut().for_each(|x| *x += cfg.setup.gap);
    }
    if frictional(cfg) {
        ops = ops.with_friction(points()?, cfg.dt);
    }
    factor_nitsche(g, cfg, c_tau2, ops)
}

/// Nitsche's points between two bodies (contract §2.6): both faces' points with the side
/// weights of the run's `nitsche_sides` — the blocks' matching points
/// ([`super::nitsche_pair`], each with the relative slip's tangential rows), or the points of
/// a general interface placed now ([`super::nitsche_interface`]: a file's faces, non-matching
/// blocks; no tangential rows yet, so a frictional run there is refused here rather than run
/// frictionless — the planner refuses it first).
fn pair_points(g: &Geometry, cfg: &FeConfig) -> Result<Vec<ContactPoint>, String> {
    let (sides, rule) = match &cfg.setup.geometry {
        FeGeometry::Blocks(b) => (Some(b.nitsche_sides), b.interface_quadrature),
        FeGeometry::Mesh {
            bodies: Some(m), ..
        } => (Some(m.nitsche_sides), m.interface_quadrature),
        _ => (None, InterfaceQuadrature::Segment),
    };
    let (Some(two), Some(sides)) = (&g.bodies, sides) else {
        return Err(format!(
            "space = nitsche between two bodies needs blocks2d/blocks3d or a two-body mesh (scene {})",
            cfg.setup.scene
        ));
    };
    let points = if two.nitsche_points[0].is_empty() {
        let faces = two.interface.as_ref().map_err(|e| e.clone())?;
        let placed = faces.points(g.mesh.mesh(), two.lame, rule)?;
        sided_points(&placed.map(|p| reduce_points(p, &g.dofs)), sides)
    } else {
        sided_points(&two.nitsche_points, sides)
    };
    if frictional(cfg) && points.iter().any(|p| p.ut.is_empty()) {
        return Err(format!(
            "space = nitsche with friction on scene {}: a point of the interface has no tangential rows (friction with two-body Nitsche is built for the matching blocks)",
            cfg.setup.scene
        ));
    }
    Ok(points)
}

/// The mixed method's factor: A = M + cτ²K, Z = A⁻¹Bᵀ, H = cτ² B Z. With friction Z also holds
/// A⁻¹ of the tangential unit vectors of the Γ_C nodes and W = cτ² C Z spans the normal and
/// tangential rows ([`FrictionFactor`]); H and the normal columns are made as without.
pub(super) fn factor_mixed(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> Result<Factored, String> {
    let (m, mass_total) = mass_matrix(g, &cfg.setup, &cfg.mass)?;
    let a = SymMatrix::lin_comb(1.0, &m, c_tau2, &g.k);
    let chol = StepSolver::new(cfg.solver, || g.symbolic(), a).map_err(|e| e.to_string())?;
    let n = g.dofs.n_free();
    let nc = g.rows.len();
    let tangential = if frictional(cfg) {
        tangential_rows(g)?
    } else {
        Rows::unit(&[])
    };
    let nz = nc + tangential.len();
    let mut z = vec![0.0; n * nz];
    for j in 0..nc {
        g.rows.add(j, 1.0, &mut z[j * n..(j + 1) * n]);
    }
    for j in 0..tangential.len() {
        tangential.add(j, 1.0, &mut z[(nc + j) * n..(nc + j + 1) * n]);
    }
    let mut work = chol.work_for(nz);
    chol.try_solve_many_in_place(&mut z, nz, &mut work)
        .map_err(|e| format!("the condensation columns A⁻¹Bᵀ: {e}"))?;
    let mut h = vec![0.0; nc * nc];
    for i in 0..nc {
        for j in 0..nc {
            h[i * nc + j] = c_tau2 * g.rows.dot(i, &z[j * n..(j + 1) * n]);
        }
    }
    // W is symmetric in exact arithmetic; symmetrise the round-off.
    symmetrise(&mut h, nc);
    let friction = (!tangential.is_empty()).then(|| {
        let d = g.mesh.dim();
        let dm = nc * d;
        // Row/column (i, a) of W: node i's normal row (a = 0) or tangential dof a − 1, and
        // its column of Z.
        let row_dot = |k: usize, x: &[f64]| {
            let (i, a) = (k / d, k % d);
            if a == 0 {
                g.rows.dot(i, x)
            } else {
                tangential.dot(i * (d - 1) + a - 1, x)
            }
        };
        let col = |k: usize| {
            let (i, a) = (k / d, k % d);
            if a == 0 { i } else { nc + i * (d - 1) + a - 1 }
        };
        let mut w = vec![0.0; dm * dm];
        for r in 0..dm {
            for c in 0..dm {
                w[r * dm + c] = c_tau2 * row_dot(r, &z[col(c) * n..(col(c) + 1) * n]);
            }
        }
        symmetrise(&mut w, dm);
        FrictionFactor { tangential, w }
    });
    Ok(Factored {
        m_products: m.without_zeros(),
        m,
        mass_total,
        chol,
        z,
        h,
        nitsche: None,
        friction,
        condensed: true,
        schur: None,
    })
}

/// The average of a square matrix (row-major, k × k) and its transpose, in place.
pub(super) fn symmetrise(h: &mut [f64], k: usize) {
    for i in 0..k {
        for j in 0..i {
            let s = 0.5 * (h[i * k + j] + h[j * k + i]);
            h[i * k + j] = s;
            h[j * k + i] = s;
        }
    }
}

/// A = M + cτ²(K − Θ Σ_q w_q γ_q s_q s_qᵀ) factored once, Z = A⁻¹C and W = P Z
/// ([`crate::run::fe::nitsche`]; the penalty is the case Θ = 0 with its own rows). Each s_q lives on
/// one element's dofs, so the rank-one updates stay in the FE pattern.
pub(super) fn factor_nitsche(
    g: &Geometry,
    cfg: &FeConfig,
    c_tau2: f64,
    ops: NitscheOps,
) -> Result<Factored, String> {
    let (m, mass_total) = mass_matrix(g, &cfg.setup, &cfg.mass)?;
    let mut a = SymMatrix::lin_comb(1.0, &m, c_tau2, &g.k);
    let (theta, gamma0) = match cfg.method {
        ContactMethod::Nitsche { theta, gamma0 } => (theta, gamma0),
        _ => (0.0, 0.0),
    };
    let (k, nq, n) = (ops.k, ops.len(), g.dofs.n_free());
    // The points' dofs are reduced indices already ([`reduce_points`]).
    let red = |gd: usize| gd;
    if theta != 0.0 {
        // σ_n's rows, and with friction the σ_t rows too (the full-vector form's
        // −Θ∫γ σ_t(u)·σ_t(v), nitsche.rs header).
        let td = ops.friction.as_ref().map_or(0, |f| f.td);
        for q in 0..nq {
            let f = c_tau2 * theta * ops.w[q] * ops.gamma[q];
            let d = &ops.dofs[q * k..(q + 1) * k];
            for r in 0..=td {
                let sq = match (r, ops.friction.as_ref()) {
                    (0, _) => &ops.s[q * k..(q + 1) * k],
                    (r, Some(fr)) => &fr.st[(q * td + r - 1) * k..(q * td + r) * k],
                    (_, None) => unreachable!("no tangential rows without friction"),
                };
                // Zero entries skipped (subtracting 0 changes no value): two bodies' points
                // span both bodies, whose cross entries are not in the pattern, and σ_n^i is
                // zero on the other body's dofs.
                for (i, &gi) in d.iter().enumerate() {
                    if sq[i] == 0.0 {
                        continue;
                    }
                    for (j, &gj) in d.iter().enumerate() {
                        if sq[j] == 0.0 {
                            continue;
                        }
                        let pos = a
                            .pattern
                            .position(red(gi), red(gj))
                            .expect("element dofs are in the pattern");
                        a.values[pos] -= f * sq[i] * sq[j];
                    }
                }
            }
        }
    }
    // The condensed unknowns: the points' P_γ (and P_t with friction).
    let nq = ops.unknowns();
    let chol = StepSolver::new(cfg.solver, || g.symbolic(), a).map_err(|e| {
        format!("the Nitsche step matrix M + cτ²(K − Θ·γ-term) is not positive definite (Θ = {theta}, γ0 = {gamma0}): {e}")
    })?;
    if full_only(g.bodies.is_some(), cfg, &ops) {
        return Ok(Factored {
            m_products: m.without_zeros(),
            m,
            mass_total,
            chol,
            z: Vec::new(),
            h: Vec::new(),
            nitsche: Some(ops),
            friction: None,
            condensed: false,
            schur: None,
        });
    }
    let mut z = vec![0.0; n * nq];
    for q in 0..nq {
        let (c_row, dofs) = ops.c_row(q);
        for (&gd, &c) in dofs.iter().zip(c_row) {
            z[q * n + red(gd)] += c;
        }
    }
    let mut work = chol.work_for(nq);
    chol.try_solve_many_in_place(&mut z, nq, &mut work).map_err(|e| {
        format!("the Nitsche step matrix M + cτ²(K − Θ·γ-term) (Θ = {theta}, γ0 = {gamma0}), its condensation columns: {e}")
    })?;
    let schur = (ops.friction.is_some() && nq >= SPARSE_MIN_ACTIVE)
        .then(|| {
            ContactSchur::new(n, &ops.dofs, |cols, ncols| {
                chol.try_solve_many_in_place(cols, ncols, &mut chol.work_for(ncols))
                    .map_err(|e| {
                        format!(
                            "the contact dofs' columns of the Nitsche step matrix's inverse: {e}"
                        )
                    })
            })
        })
        .transpose()?;
    let mut h = vec![0.0; nq * nq];
    for q in 0..nq {
        let (p_row, dofs) = ops.p_row(q);
        for r in 0..nq {
            let zr = &z[r * n..(r + 1) * n];
            h[q * nq + r] = p_row.iter().zip(dofs).map(|(a, &g)| a * zr[g]).sum();
        }
    }
    Ok(Factored {
        m_products: m.without_zeros(),
        m,
        mass_total,
        chol,
        z,
        h,
        nitsche: Some(ops),
        friction: None,
        condensed: true,
        schur,
    })
}
