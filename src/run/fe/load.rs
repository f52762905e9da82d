//! The volume load of a run with gravity (contract §1.3, §1.8): F, the consistent initial
//! acceleration a⁰ and the free-fall quantities the observers compare the centre of mass with.

use super::bodies::TwoBodies;
use super::config::FeConfig;
use super::geometry::{FeMesh, Geometry};
use crate::scene::LoadModel;
use crate::space::MassVariant;
use crate::space::cg::{CgOptions, CgWork, jacobi, pcg_into};
use crate::space::fe::{DofMap, SymMatrix, assemble_load};

/// The volume load of a run with gravity (contract §1.3, §1.8) and what its time loop needs of it.
#[derive(Debug)]
pub(super) struct GravityLoad {
    /// F on the free dofs: ∫ρ f·φ (`load = "body"`) or M_run f (`"inertial"`), with
    /// f = gravity·(sin α e_1 − cos α e_d) (α the `incline`, 0 but on the mesh scenes).
    pub(super) force: Vec<f64>,
    /// a⁰ with M a⁰ = F − K u⁰ = F on the dofs with inertia (u⁰ = 0, no contact at t = 0; 003
    /// Remark 2.1), 0 on the massless ones (their rows are quasi-static: they never use it).
    pub(super) a0: Vec<f64>,
    /// M e_d (the run's M), for the centre of mass e_dᵀ M u / e_dᵀ M e_d.
    pub(super) m_ed: Vec<f64>,
    /// e_dᵀ M e_d.
    pub(super) vertical_mass: f64,
    /// The unit relative energies are measured in, the same for every mass variant:
    /// m·|f|·d + ½m|v⁰|² ([`crate::scene::FeSetup::energy_scale`], contract §1.3), d the gap or,
    /// for a body that starts on the plane, its height H along e_d.
    pub(super) energy_scale: f64,
}

/// The load of `cfg`'s gravity on `g` with the run's mass matrix `m` (None without gravity).
///
/// The load per unit mass is f = gravity·(sin α e_1 − cos α e_d) (contract §1.8: a plane tilted by
/// the `incline` α, seen in the plane's frame; α = 0 is f = −gravity e_d bit for bit, sin 0 = 0
/// and cos 0 = 1). With `load = "body"` (the papers' model) and a mass variant that keeps
/// 1ᵀM = ∫ρφ (consistent, lumped), F = M f in exact arithmetic (per component) and a⁰ = f
/// exactly: the body moves rigidly. A redistributed or removed mass keeps F but not M, so
/// a⁰ = M⁻¹F is no longer uniform (the body strains in free fall, contract §1.3): it is solved on
/// the dofs with inertia by conjugate gradients on M (κ = O(1), a few dozen iterations to
/// round-off).
pub(super) fn gravity_load(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
) -> Result<Option<GravityLoad>, String> {
    let s = &cfg.setup;
    let fall = -s.gravity;
    if fall == 0.0 {
        return pressure_load(g, cfg, m);
    }
    if g.mesh.as_box().is_some() {
        return Err(format!(
            "scene {}: a volume load on the clamped bar is not supported",
            s.scene
        ));
    }
    let n = g.dofs.n_free();
    let mesh = g.mesh.mesh();
    let d = mesh.dim();
    // The load's components per unit mass: along the slope (e_1) and into the plane (e_d).
    let (sin, cos) = s.incline.to_radians().sin_cos();
    // A flat plane keeps f = −gravity e_d bit for bit (no −0.0 slope component either).
    let f_t = if s.incline == 0.0 {
        0.0
    } else {
        s.gravity * sin
    };
    let f_d = fall * cos;
    let mut ed = vec![0.0; n];
    for &r in &g.vertical {
        ed[r] = 1.0;
    }
    let mut m_ed = vec![0.0; n];
    m.matvec_into(&ed, &mut m_ed);
    let vertical_mass: f64 = g.vertical.iter().map(|&r| m_ed[r]).sum();
    // The body force on every dof, clamped ones included: its vertical sum is f_d·∫ρ (Σφ = 1).
    let mut f = [0.0; 3];
    f[0] = f_t;
    f[d - 1] = f_d;
    let all = DofMap::all(mesh.num_nodes() * d);
    // Two bodies (contract §1.10): each element with its body's density.
    let body = match (&g.bodies, &g.mesh) {
        (Some(two), FeMesh::Bodies { mesh: bm, .. }) => {
            assemble_load(mesh, &all, 1.0, f, &|e| two.density[bm.element_body(e)])
        }
        _ => assemble_load(mesh, &all, s.density, f, &|_| 1.0),
    };
    // |f_d| ≥ gravity·cos 89.99…° > 0: the planner keeps |α| < 90°.
    let body_mass = body.iter().skip(d - 1).step_by(d).sum::<f64>() / f_d;
    // M e_1 for the inertial load's slope component (only on an incline).
    let m_e1 = (f_t != 0.0).then(|| {
        let mut e1 = vec![0.0; n];
        for &r in &g.tangential {
            e1[r] = 1.0;
        }
        let mut out = vec![0.0; n];
        m.matvec_into(&e1, &mut out);
        out
    });
    let mut force: Vec<f64> = match s.load {
        LoadModel::Body => g.dofs.free.iter().map(|&gd| body[gd]).collect(),
        LoadModel::Inertial => match &m_e1 {
            None => m_ed.iter().map(|x| f_d * x).collect(),
            Some(m_e1) => m_ed
                .iter()
                .zip(m_e1)
                .map(|(x, y)| f_d * x + f_t * y)
                .collect(),
        },
    };
    // The rigid acceleration f on every free dof.
    let mut rigid: Vec<f64> = ed.iter().map(|e| f_d * e).collect();
    if f_t != 0.0 {
        for &r in &g.tangential {
            rigid[r] = f_t;
        }
    }
    // The blocks' pressure on A's top acts with the weight (contract §1.10).
    let pressure = g.bodies.as_ref().and_then(|two| two.pressure.as_ref());
    if let Some(p) = pressure {
        force.iter_mut().zip(p).for_each(|(f, p)| *f += p);
    }
    let keeps_row_sums = matches!(cfg.mass, MassVariant::Consistent | MassVariant::Lumped);
    let a0 = if (s.load == LoadModel::Inertial || keeps_row_sums) && pressure.is_none() {
        rigid
    } else {
        inertial_solve(m, &force, rigid)?
    };
    if g.bodies.is_some() {
        let energy_scale = blocks_energy_scale(g, cfg, &m_ed, body_mass);
        return Ok(Some(GravityLoad {
            force,
            a0,
            m_ed,
            vertical_mass,
            energy_scale,
        }));
    }
    // contract §1.3: m·|f|·d + ½m|v⁰|², d the gap or the body's height on the plane.
    let energy_scale = s.energy_scale(body_mass, || {
        let heights = (0..mesh.num_nodes()).map(|a| mesh.coord(a)[d - 1]);
        let (lo, hi) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
            (lo.min(z), hi.max(z))
        });
        hi - lo
    });
    Ok(Some(GravityLoad {
        force,
        a0,
        m_ed,
        vertical_mass,
        energy_scale,
    }))
}

/// The energy unit of two blocks under gravity (contract §1.10): the weight's work over the gap
/// m|f|g (m = ∫ρ over both bodies, the same for every mass variant; over the pair's height
/// H_a + H_b where g = 0), the bodies' kinetic energies ½Σ_i m_i|V_i|² with the run's masses
/// m_i = 1ᵀM_i1, and with a pressure its static column's strain energy
/// ([`pressure_load`]'s). A free pair falls together, so the gap is a length, not the work
/// the weight does on the contact: the unit only has to be continuous and non-zero.
fn blocks_energy_scale(g: &Geometry, cfg: &FeConfig, m_ed: &[f64], body_mass: f64) -> f64 {
    let Some(two) = &g.bodies else {
        return 0.0;
    };
    let s = &cfg.setup;
    let (ma, mb) = body_masses(g, two, m_ed);
    let ([h_a, h_b], (lambda_b, mu_b), p) = (two.heights, two.lame[1], two.pressure_value);
    let d = if s.gap != 0.0 { s.gap } else { h_a + h_b };
    let compliance = h_a / (s.lame_lambda + 2.0 * s.lame_mu) + h_b / (lambda_b + 2.0 * mu_b);
    body_mass * s.gravity.abs() * d
        + p * p * g.contact_measure * compliance
        + 0.5 * ma * (s.v0 * s.v0 + s.v0_tangential * s.v0_tangential)
        + 0.5 * mb * two.velocity_b * two.velocity_b
}

/// Each body's run mass 1ᵀM_i1 along e_d from M 1_d.
fn body_masses(g: &Geometry, two: &TwoBodies, m1: &[f64]) -> (f64, f64) {
    let (mut ma, mut mb) = (0.0, 0.0);
    for &r in &g.vertical {
        if two.body[r] == 0 {
            ma += m1[r];
        } else {
            mb += m1[r];
        }
    }
    (ma, mb)
}

/// The traction −p e_d on the upper block's top face (contract §1.10 `pressure`; None without
/// one): F, a⁰ with M a⁰ = F on the dofs with inertia (u⁰ = 0), and the energy unit
/// p²|Γ|(H_a/(λ_a + 2μ_a) + H_b/(λ_b + 2μ_b)) + ½Σ_i m_i V_i² — the static column's strain
/// energy scale plus the bodies' kinetic energy — since the patch test starts at rest (E⁰ = 0).
fn pressure_load(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
) -> Result<Option<GravityLoad>, String> {
    let Some(two) = &g.bodies else {
        return Ok(None);
    };
    let Some(force) = &two.pressure else {
        return Ok(None);
    };
    let s = &cfg.setup;
    let a0 = inertial_solve(m, force, vec![0.0; force.len()])?;
    let mut ones = vec![0.0; force.len()];
    for &r in &g.vertical {
        ones[r] = 1.0;
    }
    let mut m1 = vec![0.0; force.len()];
    m.matvec_into(&ones, &mut m1);
    let (ma, mb) = body_masses(g, two, &m1);
    let ([h_a, h_b], (lambda_b, mu_b), p) = (two.heights, two.lame[1], two.pressure_value);
    let compliance = h_a / (s.lame_lambda + 2.0 * s.lame_mu) + h_b / (lambda_b + 2.0 * mu_b);
    let energy_scale = p * p * g.contact_measure * compliance
        + 0.5 * ma * (s.v0 * s.v0 + s.v0_tangential * s.v0_tangential)
        + 0.5 * mb * two.velocity_b * two.velocity_b;
    Ok(Some(GravityLoad {
        force: force.clone(),
        a0,
        m_ed: m1,
        vertical_mass: ma + mb,
        energy_scale,
    }))
}

/// a with M_ff a_f = r_f on the dofs with inertia and a = 0 on the massless ones, by conjugate
/// gradients on M + I_massless (κ = O(1), a few dozen iterations to round-off) from `guess`:
/// M's massless rows and columns are zero (module header of the mass variants), so the shifted
/// system with r = 0 on the massless rows is M_ff a_f = r_f, a_c = 0. The initial acceleration
/// of a redistributed or removed mass ([`gravity_load`], [`super::start`]).
pub(super) fn inertial_solve(
    m: &SymMatrix,
    r: &[f64],
    guess: Vec<f64>,
) -> Result<Vec<f64>, String> {
    let n = r.len();
    let mut shifted = m.clone();
    let diag = m.diagonal();
    let mut rhs = r.to_vec();
    for (j, &dj) in diag.iter().enumerate() {
        if dj == 0.0 {
            let k = shifted
                .pattern
                .position(j, j)
                .expect("the pattern holds the diagonal");
            shifted.values[k] = 1.0;
            rhs[j] = 0.0;
        }
    }
    let inv = jacobi(&shifted).map_err(|e| format!("initial acceleration: {e}"))?;
    let mut a = guess;
    let mut work = CgWork::new(n);
    pcg_into(
        &shifted,
        &inv,
        &rhs,
        &mut a,
        CgOptions::new(1e-14),
        &mut work,
    )
    .map_err(|e| format!("initial acceleration M a⁰ = F − K̃u⁰: {e}"))?;
    Ok(a)
}
