//! The sparse finite-element engine: every FE scene × mass variant × implicit scheme with nodal
//! (`mixed`) Signorini contact (SPEC §1.2, §2.1–2.2, §3, §4).
//!
//! Semi-discrete system M ü + K u = F + Bᵀλ on the free dofs (the clamped face removed), with
//! λ ≥ 0 the upward nodal contact forces on the vertical dofs of Γ_C and u_d + g ≥ 0 there.
//! Newmark(β, γ) and the θ-scheme share one form,
//!
//!   u^{n+1} = p^n + c τ² a^{n+1},   p^n = u^n + τ v^n + c₁ τ² a^n,
//!   v^{n+1} = v^n + τ((1−γ) a^n + γ a^{n+1}),   equation at t^{n+1},
//!
//! with (c₁, c, γ) = ((1−2β)/2, β, γ) for Newmark and (θ(1−θ), θ², θ) for the θ-scheme. So every
//! step solves (M + c τ² K) u^{n+1} = M p^n + c τ² (F + Bᵀλ^{n+1}): A = M + cτ²K is constant —
//! factored once per run (sparse Cholesky, symbolic analysis once per mesh) and shared between
//! runs with the same matrix. The contact is condensed onto the contact dofs: Z = A⁻¹Bᵀ and
//! W = B Z are computed once per run; a step is one sparse solve y = A⁻¹(M p^n + cτ²F), the exact
//! LCP λ ≥ 0 ⊥ By + g + cτ²Wλ ≥ 0 ([`crate::contact::lcp`], warm-started from the previous
//! step), and u^{n+1} = y + cτ² Z λ over the active contact dofs. Never a refactorisation.
//!
//! Massless dofs (the bottom nodes with mod1/mod2/mod3/weights/zero-contact) need no special
//! case: their rows of M are zero, so their row of the step system is c τ² (K u − F − Bᵀλ) = 0,
//! the quasi-static equation at t^{n+1} (SPEC §1.2). Their a and v are never used (their M rows
//! and columns vanish), the energy E = ½vᵀMv + ½uᵀKu − Fᵀu is the run's own.
//!
//! Errors against a reference run (nested mesh and step): e^n = u^n − I_h u_ref(t^n) at the
//! coarse nodes, ‖e‖²_L2 = eᵀ G e with the unweighted Gram matrix, H1 = L2 + eᵀ D e with
//! D = ∫∇e:∇e (SPEC §1.2). Nothing is allocated in the time loop.

use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use super::observe::{Divergence, ExactValues, Observer, SampledTimer, StepValues};
use super::reference::ReferenceData;
use super::{Metrics, Outcome, RunContext, RunOptions, Status, Stop};
use crate::contact::{Lcp, LcpError};
use crate::scene::{FeGeometry, FeSetup};
use crate::space::fe::{BoxMesh, DofMap, ElementOp, Pattern, SymMatrix, assemble, fe_pattern};
use crate::space::linalg::{
    Cholesky, CholeskyOptions, FactorKind, Ordering, SolveWork, SymbolicCholesky,
};
use crate::space::{ContactMethod, MassVariant};
use crate::time::Scheme;

/// Steps between two checks of the clock and of an interruption.
const CLOCK_EVERY: usize = 64;
/// The contact LCP: tolerance relative to the largest gap, and the iteration cap (SPEC §4).
const LCP_TOL: f64 = 1e-12;
const LCP_MAX_ITER: usize = 100;

/// A validated finite-element run.
#[derive(Debug, Clone, PartialEq)]
pub struct FeConfig {
    pub setup: FeSetup,
    pub method: ContactMethod,
    pub mass: MassVariant,
    pub scheme: Scheme,
    pub dt: f64,
    pub steps: usize,
    /// Ensemble member: relative amplitude of a uniform perturbation of v⁰ (u⁰ = 0 here) and
    /// its seed.
    pub perturbation: Option<(f64, u64)>,
}

impl FeConfig {
    /// Free unknowns (nodes off the clamped face × d).
    pub fn unknowns(&self) -> usize {
        match &self.setup.geometry {
            FeGeometry::Box { cells, .. } => {
                let d = cells.len();
                // Saturating: the planner sizes runs before refusing the huge ones.
                let count = |cs: &[usize]| cs.iter().fold(1usize, |p, c| p.saturating_mul(c + 1));
                let (nodes, top) = (count(cells), count(&cells[..d - 1]));
                (nodes - top).saturating_mul(d)
            }
        }
    }

    /// Explicit schemes are not offered by the FE engine (the scene refuses them first).
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        if self.scheme.is_explicit() {
            return Err((
                "scheme",
                format!(
                    "scheme {} is explicit: with the nodal multiplier the contact dofs must be massless, whose quasi-static rows make the step implicit; scene {} takes implicit newmark and theta schemes",
                    self.scheme.label(),
                    self.setup.scene
                ),
            ));
        }
        Ok(None)
    }

    /// (c₁, c, γ) of the common scheme form (module header).
    fn coefficients(&self) -> Result<(f64, f64, f64), String> {
        match self.scheme {
            Scheme::Newmark(p) if p.beta > 0.0 => Ok((0.5 - p.beta, p.beta, p.gamma)),
            Scheme::Theta(p) if p.theta > 0.0 => {
                Ok((p.theta * (1.0 - p.theta), p.theta * p.theta, p.theta))
            }
            s => Err(format!(
                "scheme {} is not available for scene {}",
                s.label(),
                self.setup.scene
            )),
        }
    }
}

/// The operators of one geometry and material, shared by every run on it.
#[derive(Debug)]
struct Geometry {
    mesh: BoxMesh,
    dofs: DofMap,
    pattern: Arc<Pattern>,
    symbolic: Arc<SymbolicCholesky>,
    k: SymMatrix,
    /// Unweighted Gram matrix (ρ = 1) and ∫∇u:∇v, for the error norms.
    gram: SymMatrix,
    grad: SymMatrix,
    /// Reduced index of the vertical dof of each Γ_C node, and the node.
    contact: Vec<usize>,
    /// Trapezoidal weights of the Γ_C nodes (sum 1): the mean of a nodal field over Γ_C.
    contact_weight: Vec<f64>,
    /// Reduced dofs that belong to a Γ_C node (all components).
    on_contact_node: Vec<bool>,
    /// Reduced indices of the vertical component.
    vertical: Vec<usize>,
}

/// The matrices of one run: its mass variant and the factored, condensed step matrix.
#[derive(Debug)]
struct Factored {
    m: SymMatrix,
    mass_total: f64,
    chol: Cholesky,
    /// Z = A⁻¹Bᵀ, column-major (n × n_c).
    z: Vec<f64>,
    /// H = cτ² B Z (n_c × n_c, row-major).
    h: Vec<f64>,
}

/// A process-wide cache: entries shared by concurrent runs (a second run waits for the first to
/// finish building) and kept for the next `CAP` distinct keys, so serial runs reuse them too.
struct Cache<T> {
    entries: Mutex<Vec<(String, Slot<T>)>>,
}

/// One cache entry: built once, by the first run that asks for it.
type Slot<T> = Arc<OnceLock<Result<Arc<T>, String>>>;

impl<T> Cache<T> {
    const CAP: usize = 4;

    const fn new() -> Self {
        Cache {
            entries: Mutex::new(Vec::new()),
        }
    }

    /// The value for `key`, built by `make` if absent; the flag says whether it was a hit.
    fn get(
        &self,
        key: String,
        make: impl FnOnce() -> Result<T, String>,
    ) -> (Result<Arc<T>, String>, bool) {
        let cell = {
            let mut e = self.entries.lock().unwrap_or_else(|p| p.into_inner());
            match e.iter().position(|(k, _)| *k == key) {
                Some(i) => {
                    let entry = e.remove(i);
                    let cell = Arc::clone(&entry.1);
                    e.push(entry);
                    cell
                }
                None => {
                    let cell = Arc::new(OnceLock::new());
                    e.push((key, Arc::clone(&cell)));
                    if e.len() > Self::CAP {
                        e.remove(0);
                    }
                    cell
                }
            }
        };
        let mut built = false;
        let r = cell
            .get_or_init(|| {
                built = true;
                make().map(Arc::new)
            })
            .clone();
        (r, !built)
    }
}

static GEOMETRIES: Cache<Geometry> = Cache::new();
static FACTORS: Cache<Factored> = Cache::new();

fn geometry_key(s: &FeSetup) -> String {
    format!(
        "{:?}|{:e}|{:e}|{:e}",
        s.geometry, s.density, s.lame_lambda, s.lame_mu
    )
}

/// The engine's fill-reducing ordering and factor kind, measured on M + τ²/4 K of the bars (one
/// solve): 2D 65 × 641 nodes: AMD simplicial 4.9 M entries in L, 14.0 ms (AMD supernodal
/// 6.2 M, 15.4 ms; nested dissection 5.3–6.9 M, 16 ms); 3D 9 × 9 × 81: the geometric nested
/// dissection of the box with supernodes, 6.6 M, 9.5 ms (AMD supernodal 10.0 M, 13.5 ms).
pub fn cholesky_options(mesh: &BoxMesh, dofs: &DofMap) -> CholeskyOptions {
    let d = mesh.dim;
    if d == 2 {
        CholeskyOptions {
            ordering: Ordering::Amd,
            kind: FactorKind::Simplicial,
        }
    } else {
        CholeskyOptions {
            ordering: Ordering::Custom(dofs.order_by_nodes(&mesh.nested_dissection(), d)),
            kind: FactorKind::Supernodal,
        }
    }
}

fn build_geometry(s: &FeSetup) -> Result<Geometry, String> {
    let FeGeometry::Box { extent, cells } = &s.geometry;
    let mesh = BoxMesh::try_new(extent, cells).map_err(|e| e.to_string())?;
    let d = mesh.dim;
    let top = cells[d - 1];
    let clamped = |node: usize| mesh.node_index(node)[d - 1] == top;
    let dofs = DofMap::new(mesh.num_nodes() * d, |g| clamped(g / d));
    let pattern = fe_pattern(&mesh, &dofs);
    let opts = cholesky_options(&mesh, &dofs);
    let symbolic = SymbolicCholesky::with_options(&pattern, &opts).map_err(|e| e.to_string())?;
    let one = |_: usize| 1.0;
    let k = assemble(
        &mesh,
        &dofs,
        &pattern,
        ElementOp::Stiffness {
            lambda: s.lame_lambda,
            mu: s.lame_mu,
        },
        &one,
    );
    let gram = assemble(&mesh, &dofs, &pattern, ElementOp::Mass { rho: 1.0 }, &one);
    let grad = assemble(&mesh, &dofs, &pattern, ElementOp::GradGrad, &one);
    let bottom = mesh.nodes_on_plane(d - 1, 0);
    let free = |g: usize| dofs.free_index(g).expect("Γ_C is not clamped");
    let contact: Vec<usize> = bottom.iter().map(|&n| free(n * d + d - 1)).collect();
    // Trapezoidal weight of a node of the bottom face: ½ per end of each horizontal axis.
    let mut contact_weight: Vec<f64> = bottom
        .iter()
        .map(|&n| {
            let idx = mesh.node_index(n);
            (0..d - 1)
                .map(|a| {
                    if idx[a] == 0 || idx[a] == cells[a] {
                        0.5
                    } else {
                        1.0
                    }
                })
                .product()
        })
        .collect();
    let total: f64 = contact_weight.iter().sum();
    contact_weight.iter_mut().for_each(|w| *w /= total);
    let mut on_contact_node = vec![false; dofs.n_free()];
    for &n in &bottom {
        for c in 0..d {
            on_contact_node[free(n * d + c)] = true;
        }
    }
    let vertical = (0..dofs.n_free())
        .filter(|&r| dofs.free[r] % d == d - 1)
        .collect();
    Ok(Geometry {
        mesh,
        dofs,
        pattern,
        symbolic,
        k,
        gram,
        grad,
        contact,
        contact_weight,
        on_contact_node,
        vertical,
    })
}

/// The element weight of layer `layer` (layer 0 touches Γ_C) for a mass variant (SPEC §2.2).
fn layer_weight(mass: &MassVariant, layer: usize, layers: usize) -> f64 {
    match (mass, layer) {
        (
            MassVariant::Mod1 | MassVariant::Mod2 | MassVariant::Mod3 | MassVariant::Weights(_),
            0,
        ) => 0.0,
        (MassVariant::Mod2, _) => layers as f64 / (layers as f64 - 1.0),
        (MassVariant::Mod3, 1) => 2.0,
        (MassVariant::Weights(w), k) => w[(k - 1).min(w.len() - 1)],
        _ => 1.0,
    }
}

/// The run's mass matrix and 1ᵀM1 (per component: the total mass it represents).
fn mass_matrix(g: &Geometry, s: &FeSetup, mass: &MassVariant) -> Result<(SymMatrix, f64), String> {
    let layers = g.mesh.num_layers();
    if layers < 2 && mass.massless_contact() {
        return Err(format!(
            "mass = {} needs at least two element layers",
            mass.name()
        ));
    }
    let mesh = &g.mesh;
    let weight = |e: usize| layer_weight(mass, mesh.element_layer(e), layers);
    let rho = ElementOp::Mass { rho: s.density };
    let mut m = assemble(mesh, &g.dofs, &g.pattern, rho, &weight);
    match mass {
        MassVariant::Lumped => m = SymMatrix::diagonal_from(&g.pattern, &m.row_sums()),
        MassVariant::ZeroContact => {
            let p = &g.pattern;
            for j in 0..p.n {
                for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                    if g.on_contact_node[j] || g.on_contact_node[p.row_idx[k]] {
                        m.values[k] = 0.0;
                    }
                }
            }
        }
        _ => {}
    }
    // 1ᵀM1 over one component, clamped nodes included: assembled on the full dof set.
    let d = mesh.dim;
    let all = DofMap::all(mesh.num_nodes() * d);
    let full_pattern = fe_pattern(mesh, &all);
    let full = assemble(mesh, &all, &full_pattern, rho, &weight);
    let bottom_node = |dof: usize| mesh.node_index(dof / d)[d - 1] == 0;
    let mut total = 0.0;
    for j in (0..full_pattern.n).filter(|j| j % d == 0) {
        for k in full_pattern.col_ptr[j]..full_pattern.col_ptr[j + 1] {
            let i = full_pattern.row_idx[k];
            let zeroed =
                matches!(mass, MassVariant::ZeroContact) && (bottom_node(i) || bottom_node(j));
            if !zeroed {
                total += full.values[k];
            }
        }
    }
    Ok((m, total))
}

fn factor(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> Result<Factored, String> {
    let (m, mass_total) = mass_matrix(g, &cfg.setup, &cfg.mass)?;
    let a = SymMatrix::lin_comb(1.0, &m, c_tau2, &g.k);
    let chol = Cholesky::new(&g.symbolic, &a).map_err(|e| e.to_string())?;
    let n = g.dofs.n_free();
    let nc = g.contact.len();
    let mut z = vec![0.0; n * nc];
    for (j, &c) in g.contact.iter().enumerate() {
        z[j * n + c] = 1.0;
    }
    let mut work = chol.work_for(nc);
    chol.solve_many_in_place(&mut z, nc, &mut work);
    let mut h = vec![0.0; nc * nc];
    for (i, &ci) in g.contact.iter().enumerate() {
        for j in 0..nc {
            h[i * nc + j] = c_tau2 * z[j * n + ci];
        }
    }
    // W is symmetric in exact arithmetic; symmetrise the round-off.
    for i in 0..nc {
        for j in 0..i {
            let s = 0.5 * (h[i * nc + j] + h[j * nc + i]);
            h[i * nc + j] = s;
            h[j * nc + i] = s;
        }
    }
    Ok(Factored {
        m,
        mass_total,
        chol,
        z,
        h,
    })
}

/// How the run reads its reference: for every free dof, its offset in a stored time slice; and
/// the stored index of coarse step n is n·`time_ratio`.
struct RefMap {
    data: Arc<ReferenceData>,
    dof_offset: Vec<usize>,
    time_ratio: usize,
}

fn ref_map(g: &Geometry, cfg: &FeConfig, data: &Arc<ReferenceData>) -> Result<RefMap, String> {
    let d = g.mesh.dim;
    let ratio = |coarse: f64, fine: f64, stride: usize, what: &str| {
        let q = coarse / fine;
        let r = q.round() as usize;
        if r == 0 || (q - r as f64).abs() > 1e-9 * q || !r.is_multiple_of(stride) {
            Err(format!(
                "the reference's {what} ({fine}) is not nested in the run's ({coarse}) on its stored lattice (stride {stride})"
            ))
        } else {
            Ok(r / stride)
        }
    };
    let rs = ratio(cfg.setup.h, data.h, data.space_stride, "mesh size")?;
    let rt = ratio(cfg.dt, data.dt, data.time_stride, "time step")?;
    if data.dim != d || (0..d).any(|a| g.mesh.cells[a] * rs + 1 != data.lattice[a]) {
        return Err("the reference's lattice does not cover the run's mesh".into());
    }
    if cfg.steps * rt >= data.times {
        return Err(format!(
            "the reference holds {} stored times, the run needs {}",
            data.times,
            cfg.steps * rt + 1
        ));
    }
    let slice = data.lattice.iter().product::<usize>() * d;
    let _ = slice;
    let dof_offset = g
        .dofs
        .free
        .iter()
        .map(|&gd| {
            let idx = g.mesh.node_index(gd / d);
            let l = [idx[0] * rs, idx[1] * rs, idx[2] * rs];
            let node = l[0] + data.lattice[0] * (l[1] + data.lattice[1] * l[2]);
            node * d + gd % d
        })
        .collect();
    Ok(RefMap {
        data: Arc::clone(data),
        dof_offset,
        time_ratio: rt,
    })
}

/// Run one finite-element simulation.
pub fn simulate(cfg: &FeConfig, opts: &RunOptions, ctx: &RunContext) -> Outcome {
    let start = Instant::now();
    let mut metrics = Metrics {
        dofs: cfg.unknowns() as i64,
        ..Metrics::default()
    };
    let fail = |status, msg: String, metrics: Metrics| Outcome {
        status,
        message: Some(msg),
        metrics,
        series: Vec::new(),
        reference: None,
    };
    if cfg.method != ContactMethod::Mixed {
        return fail(
            Status::Invalid,
            format!(
                "space = {} is not available for scene {}",
                cfg.method.name(),
                cfg.setup.scene
            ),
            metrics,
        );
    }
    let (c1, c, gamma) = match cfg.coefficients() {
        Ok(x) => x,
        Err(e) => return fail(Status::Invalid, e, metrics),
    };
    let tau = cfg.dt;
    let c_tau2 = c * tau * tau;
    let (geo, _) = GEOMETRIES.get(geometry_key(&cfg.setup), || build_geometry(&cfg.setup));
    let geo = match geo {
        Ok(g) => g,
        Err(e) => return fail(Status::Invalid, e, metrics),
    };
    // Checked outside the shared caches: an entry is never left half built.
    if let Some((status, msg)) = opts.setup_stop(start, "the mesh and operators") {
        return fail(status, msg, metrics);
    }
    let factor_key = format!("{}|{:?}|{:e}", geometry_key(&cfg.setup), cfg.mass, c_tau2);
    let (fac, hit) = FACTORS.get(factor_key, || factor(&geo, cfg, c_tau2));
    let fac = match fac {
        Ok(f) => f,
        Err(e) => return fail(Status::SolverFailed, e, metrics),
    };
    metrics.factorizations = i64::from(!hit);
    metrics.factor_cache_hits = Some(i64::from(hit));
    metrics.mass_total = Some(fac.mass_total);
    if let Some((status, msg)) = opts.setup_stop(start, "the factorisation") {
        return fail(status, msg, metrics);
    }
    let refmap = match ctx.reference.as_ref().map(|r| ref_map(&geo, cfg, r)) {
        Some(Err(e)) => return fail(Status::Invalid, e, metrics),
        Some(Ok(m)) => Some(m),
        None => None,
    };

    let g = &*geo;
    let n = g.dofs.n_free();
    let nc = g.contact.len();
    let d = g.mesh.dim;
    metrics.contact_dofs = Some(nc as i64);
    let gap = cfg.setup.gap;

    // Workspace: every vector of the time loop, allocated once. M u, M v and M a are carried
    // along the recursions of u, v, a, so a step costs one product with M (M a^{n+1}) besides
    // the solve: M p^n = Mu + τ Mv + c₁τ² Ma, and the energy needs no product at all,
    // uᵀKu = uᵀ(Bᵀλ − M a) by the equation at t^{n+1} (F = 0).
    let mut u = vec![0.0; n];
    let mut v = vec![0.0; n];
    let mut a = vec![0.0; n];
    let mut mu = vec![0.0; n];
    let mut mv = vec![0.0; n];
    let mut ma = vec![0.0; n];
    let mut pred = vec![0.0; n];
    let mut y = vec![0.0; n];
    let mut tmp = vec![0.0; n];
    let mut err = vec![0.0; n];
    let mut q = vec![0.0; nc];
    let mut lambda = vec![0.0; nc];
    let mut lcp = Lcp::new(nc, fac.h.clone());
    let mut work: SolveWork = fac.chol.work();
    for &r in &g.vertical {
        v[r] = cfg.setup.v0;
    }
    if let Some((delta, seed)) = cfg.perturbation {
        let mut rng = fastrand::Rng::with_seed(seed);
        for x in v.iter_mut() {
            *x *= 1.0 + delta * (2.0 * rng.f64() - 1.0);
        }
    }
    fac.m.matvec_into(&v, &mut mv);
    // a⁰ = M⁻¹(F − Ku⁰) = 0: u⁰ = 0 and no volume load in the bars.
    if cfg.setup.gravity != 0.0 {
        return fail(
            Status::Invalid,
            "a volume load is not supported by this engine yet".into(),
            metrics,
        );
    }

    // The reference lattice this run records, if it is one.
    let record = ctx.record_reference.map(|(space_stride, time_stride)| {
        let lattice = [0, 1, 2].map(|ax| {
            if ax < d {
                g.mesh.cells[ax] / space_stride + 1
            } else {
                1
            }
        });
        let mut slots = Vec::with_capacity(lattice.iter().product::<usize>() * d);
        for k in 0..lattice[2] {
            for j in 0..lattice[1] {
                for i in 0..lattice[0] {
                    let node =
                        g.mesh
                            .node_id([i * space_stride, j * space_stride, k * space_stride]);
                    for comp in 0..d {
                        slots.push(g.dofs.free_index(node * d + comp));
                    }
                }
            }
        }
        let times = cfg.steps / time_stride + 1;
        let data = ReferenceData {
            dim: d,
            h: cfg.setup.h,
            dt: tau,
            space_stride,
            time_stride,
            lattice,
            times,
            u: Vec::with_capacity(times * slots.len()),
            force: Vec::with_capacity(times),
            energy: Vec::with_capacity(times),
            u_contact: Vec::with_capacity(times),
        };
        (slots, data)
    });
    let mut record = record;
    if let Some((status, msg)) = opts.setup_stop(start, "the workspace") {
        return fail(status, msg, metrics);
    }
    metrics.setup_time_s = Some(start.elapsed().as_secs_f64());
    let loop_start = Instant::now();

    let mut obs = Observer::new(tau, opts.series_every, cfg.steps);
    // E = ½vᵀMv + ½uᵀKu with Mv carried and Ku = Bᵀλ − Ma (module header).
    let energy = |u: &[f64], v: &[f64], mv: &[f64], ma: &[f64], lambda: &[f64]| {
        let kinetic: f64 = v.iter().zip(mv).map(|(x, y)| x * y).sum();
        let contact: f64 = g.contact.iter().zip(lambda).map(|(&c, l)| l * u[c]).sum();
        let uma: f64 = u.iter().zip(ma).map(|(x, y)| x * y).sum();
        0.5 * kinetic + 0.5 * (contact - uma)
    };
    let mean = |x: &[f64]| -> f64 {
        g.contact
            .iter()
            .zip(&g.contact_weight)
            .map(|(&c, w)| w * x[c])
            .sum()
    };
    // Observe step n with state (u, v) and contact forces λ.
    #[allow(clippy::too_many_arguments)]
    let mut observe = |step: usize,
                       u: &[f64],
                       v: &[f64],
                       mv: &[f64],
                       ma: &[f64],
                       lambda: &[f64],
                       tmp: &mut [f64],
                       err: &mut [f64]|
     -> Result<(), Divergence> {
        let e = energy(u, v, mv, ma, lambda);
        let force: f64 = lambda.iter().sum();
        let uc = mean(u);
        if let Some((slots, data)) = record.as_mut()
            && step.is_multiple_of(data.time_stride)
        {
            data.u.extend(slots.iter().map(|s| s.map_or(0.0, |r| u[r])));
            data.force.push(force);
            data.energy.push(e);
            data.u_contact.push(uc);
        }
        let exact = refmap.as_ref().map(|rm| {
            let k = step * rm.time_ratio;
            let slice = rm.data.lattice.iter().product::<usize>() * d;
            let base = k * slice;
            for (i, e) in err.iter_mut().enumerate() {
                *e = u[i] - rm.data.u[base + rm.dof_offset[i]];
            }
            let l2_sq = quad(&g.gram, err, tmp);
            let h1_semi_sq = quad(&g.grad, err, tmp);
            ExactValues {
                u_contact: rm.data.u_contact[k],
                sigma_contact: -rm.data.force[k],
                sigma_contact_mid: None,
                energy: rm.data.energy[k],
                l2_sq,
                h1_semi_sq,
            }
        });
        obs.observe(
            StepValues {
                step,
                t: step as f64 * tau,
                u_contact: uc,
                v_contact: mean(v),
                sigma_contact: -force,
                sigma_mid: None,
                energy: e,
                energy_theta: None,
            },
            exact,
        )
    };

    let mut done = 0usize;
    let mut iterations = 0i64;
    let mut observe_timer = SampledTimer::default();
    let stop = (|| -> Result<(), Stop<LcpError>> {
        observe(0, &u, &v, &mv, &ma, &lambda, &mut tmp, &mut err).map_err(Stop::Diverged)?;
        let (t1, ct2) = (tau, c1 * tau * tau);
        for step in 1..=cfg.steps {
            // p^n and M p^n (the right-hand side) from the carried products.
            for i in 0..n {
                pred[i] = u[i] + t1 * v[i] + ct2 * a[i];
                y[i] = mu[i] + t1 * mv[i] + ct2 * ma[i];
            }
            // M p^n is M u^{n+1} before the correction below; keep it.
            mu.copy_from_slice(&y);
            fac.chol.solve_in_place(&mut y, &mut work);
            for (qi, &ci) in q.iter_mut().zip(&g.contact) {
                *qi = y[ci] + gap;
            }
            iterations += lcp
                .solve(&q, &mut lambda, LCP_MAX_ITER, LCP_TOL)
                .map_err(|e| Stop::Solver(step, e))? as i64;
            for (j, &l) in lambda.iter().enumerate() {
                if l > 0.0 {
                    let zj = &fac.z[j * n..(j + 1) * n];
                    let s = c_tau2 * l;
                    for (yi, zi) in y.iter_mut().zip(zj) {
                        *yi += s * zi;
                    }
                }
            }
            // y = u^{n+1}; tmp = a^{n+1} = (u^{n+1} − p^n)/(cτ²), then M a^{n+1} into pred.
            for i in 0..n {
                tmp[i] = (y[i] - pred[i]) / c_tau2;
            }
            fac.m.matvec_into(&tmp, &mut pred);
            for i in 0..n {
                v[i] += tau * ((1.0 - gamma) * a[i] + gamma * tmp[i]);
                mv[i] += tau * ((1.0 - gamma) * ma[i] + gamma * pred[i]);
                mu[i] += c_tau2 * pred[i];
            }
            std::mem::swap(&mut a, &mut tmp);
            std::mem::swap(&mut ma, &mut pred);
            std::mem::swap(&mut u, &mut y);
            observe_timer
                .time(step, || {
                    observe(step, &u, &v, &mv, &ma, &lambda, &mut tmp, &mut err)
                })
                .map_err(Stop::Diverged)?;
            done = step;
            if step.is_multiple_of(CLOCK_EVERY) {
                if opts.cancelled() {
                    return Err(Stop::Cancelled);
                }
                if opts.timeout.is_some_and(|limit| start.elapsed() > limit) {
                    return Err(Stop::Timeout(step));
                }
            }
        }
        Ok(())
    })();
    metrics.steps = done as i64;
    metrics.iterations = iterations;
    metrics.stepping_time_s = Some(loop_start.elapsed().as_secs_f64());
    metrics.observe_time_s = observe_timer.estimate_s();
    let (status, message) = Stop::status(stop, tau, cfg.steps, start, &mut metrics);
    obs.finish(&mut metrics, status == Status::Ok);
    // The observer's pressure columns are the total force here; there is no midpoint pressure.
    metrics.err_force_l2 = metrics.err_sigma_l2.take();
    metrics.err_sigma_mid_l2 = None;
    metrics.contact_toggles = Some(metrics.contact_switches);
    metrics.energy_scale = metrics.energy_initial;
    let reference = match record {
        Some((_, data)) if status == Status::Ok => Some(data),
        _ => None,
    };
    Outcome {
        status,
        message,
        metrics,
        series: std::mem::take(&mut obs.series),
        reference,
    }
}

/// xᵀAx with `tmp` as scratch.
fn quad(a: &SymMatrix, x: &[f64], tmp: &mut [f64]) -> f64 {
    a.matvec_into(x, tmp);
    x.iter().zip(tmp.iter()).map(|(p, q)| p * q).sum()
}
