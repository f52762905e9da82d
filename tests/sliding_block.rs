//! The sliding block (contract §1.8, issue 33 "done when" 1): a Gmsh block with nothing clamped
//! (`sweeps/meshes/block2d.msh`, 8 × 4 Q1 quadrilaterals of [0,1]×[0,0.5];
//! `sweeps/meshes/block3d.msh`, 4 × 2 × 2 Q1 hexahedra of [0,1]×[0,0.5]²) resting on the plane
//! (gap 0) under gravity g, thrown along it at V e_1, on a flat plane and on one tilted by α.
//!
//! The invariant. Let P_c = 1ᵀM v_c be the total momentum along e_c (1 the vector of ones on the
//! dofs of component c), ΣF_c = 1ᵀF_c the summed volume load (ρ|Ω|·g·(sin α, −cos α) along
//! (e_1, e_d): the body load ∫ρ f·φ sums to ∫ρ f since Σ_a φ_a = 1, whatever the mass variant)
//! and f_n ≥ 0, f_t the contact forces on the body along e_d and e_1. Without clamping, a rigid
//! translation 1_c has no strain, so K 1_c = 0 and, K being symmetric, 1_cᵀK = 0 (Nitsche's Θ
//! term too: σ(1_c) = 0). Crank–Nicolson (β = ¼, γ = ½) with the contact force f^k in each
//! level's equation M a^k = F − K u^k + f^k reads
//!   M(v^{n+1} − v^n) = τ/2 (2F − K(u^n + u^{n+1}) + f^n + f^{n+1}),
//! so, multiplied by 1_cᵀ,
//!   P_c^{n+1} − P_c^n = τ (ΣF_c + ½(Σf_c^n + Σf_c^{n+1})).
//! While every contact point slides forward (+e_1) at both levels, Coulomb's law gives
//! f_t = −μ_f f_n point by point, hence Σf_1^k = −μ_f Σf_d^k for k = n, n+1, and
//!   (P_1 + μ_f P_d)^{n+1} − (P_1 + μ_f P_d)^n = τ (ΣF_1 + μ_f ΣF_d):
//!   Q = P_1 + μ_f P_d − (ΣF_1 + μ_f ΣF_d)·t is constant,
//! for any mass matrix (M only enters through P). The same holds with one force per step (kane:
//! M(v^{n+1} − v^n) = τ(F − K u^{n+½} + f); moreau-jean: the impulse p = τf), the frictional
//! work aside; the Nitsche and penalty forces obey the same law at the quadrature points.
//! With μ_f = 0 it says P_1 − ΣF_1·t is constant: the frictionless block keeps its tangential
//! momentum on a flat plane and gains m·g·sin α per unit time on the incline.
//!
//! How the test sees P. The engines record a reference run's displacements at every node and
//! step (`RunContext::record_reference`, the library path a reference run takes); every scheme
//! here has (u^{n+1} − u^n)/τ = (v^n + v^{n+1})/2 (CN and Moreau–Jean θ = ½ by their update,
//! kane by v^{n+1} = 2Δu/τ − v^n), so with the consistent mass's row sums m_a = ∫ρφ_a
//!   P_c^{n+½} = Σ_a m_a (u_{a,c}^{n+1} − u_{a,c}^n)/τ = (P_c^n + P_c^{n+1})/2,
//! and Q at the half levels is the mean of two consecutive Q's: constant where Q is.
//!
//! The frictionless assertions (P_1 − ΣF_1·t constant for mixed + CN, kane, moreau-jean,
//! nitsche + CN, penalty + CN, flat and tilted, 2D and 3D; the incline's load; the block
//! resting on the plane) and the frictional ones (the invariant, `stop_time`) all run; what
//! holds in 3D and for the CN-based stops is stated, with the measurements, at each test.

use std::path::{Path, PathBuf};

use contact_sweep::run::{Outcome, RunContext, RunOptions, simulate_with};
use contact_sweep::space::fe::mesh::mesh_layers;
use contact_sweep::space::fe::{
    DofMap, ElementOp, GmshMesh, Mesh, assemble, assemble_load, fe_pattern,
};
use contact_sweep::sweep::{SweepFile, expand};

/// The block's material and load (sweeps/sliding_block.toml): ρ = 1, λ = μ = 10 (E = 25,
/// ν = 0.25), g = 0.1, thrown at V = 0.5, τ = 0.05.
const RHO: f64 = 1.0;
const LAME: f64 = 10.0;
const GRAVITY: f64 = 0.1;
const V: f64 = 0.5;
const DT: f64 = 0.05;
/// Coulomb's coefficient of the frictional runs.
const MU_F: f64 = 0.2;
/// The tilt of the inclined runs (tan α = 0.087 < μ_f: the block still stops).
const INCLINE: f64 = 5.0;

/// The methods of the issue: (label, sweep bundle).
const METHODS: [(&str, &str); 5] = [
    (
        "mixed + CN",
        "{ space = \"mixed\", scheme = \"crank-nicolson\" }",
    ),
    ("kane", "{ space = \"mixed\", scheme = \"kane\" }"),
    (
        "moreau-jean",
        "{ space = \"mixed\", scheme = \"moreau-jean\", restitution = 0.0 }",
    ),
    (
        "nitsche + CN",
        "{ space = \"nitsche\", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = \"crank-nicolson\" }",
    ),
    (
        "penalty + CN",
        "{ space = \"penalty\", penalty_gamma0 = 100.0, scheme = \"crank-nicolson\" }",
    ),
];

fn sweeps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps")
}

fn mesh_path(dim: usize) -> PathBuf {
    sweeps_dir().join(format!("meshes/block{dim}d.msh"))
}

/// One run of the block and what the test reads from it.
struct Trace {
    what: String,
    outcome: Outcome,
    /// ρ|Ω|: 0.5 (2D), 0.25 (3D).
    mass: f64,
    /// t^{n+½} and P^{n+½} per direction (e_1 first, e_d last).
    t_half: Vec<f64>,
    p_half: Vec<[f64; 3]>,
    /// Whether every Γ_C node moved forward (Δu_1 > 0) in step n → n+1.
    all_forward: Vec<bool>,
    /// The centre of mass's vertical displacement Σ m_a u_{a,d}/m at each step.
    com_d: Vec<f64>,
    /// The engine's total contact force (along +e_d) at each step.
    force: Vec<f64>,
    /// The plain mean of u_1 over every node at each step.
    mean_u1: Vec<f64>,
    dim: usize,
    /// Every node's displacement at every step (node-major, step by step).
    u: Vec<f64>,
}

impl Trace {
    /// ΣF along e_1 and e_d: ρ|Ω|·g·(sin α, −cos α).
    fn load_sum(&self, incline: f64) -> (f64, f64) {
        let (s, c) = incline.to_radians().sin_cos();
        (self.mass * GRAVITY * s, -self.mass * GRAVITY * c)
    }
}

/// Plan and run the block with one method; `friction`: Coulomb's μ_f (None: frictionless).
fn trace(dim: usize, method: (&str, &str), incline: f64, friction: Option<f64>, t: f64) -> Trace {
    trace_with(dim, method, incline, friction, t, LAME, 0.0)
}

/// [`trace`] with Lamé's λ (μ = [`LAME`]; λ = 0 is ν = 0) and the initial gap given.
fn trace_with(
    dim: usize,
    method: (&str, &str),
    incline: f64,
    friction: Option<f64>,
    t: f64,
    lambda: f64,
    gap: f64,
) -> Trace {
    let friction_keys = friction.map_or(String::new(), |mu| {
        format!("friction = \"coulomb\"\nfriction_coefficient = {mu:?}\n")
    });
    let text = format!(
        "name = \"block\"\nscene = \"mesh{dim}d\"\n[fixed]\nmesh = \"meshes/block{dim}d.msh\"\ndensity = {RHO:?}\nlame_lambda = {lambda:?}\nlame_mu = {LAME:?}\ngravity = {GRAVITY:?}\ngap = {gap:?}\nvelocity_tangential = {V:?}\nincline = {incline:?}\nT = {t:?}\ndt = {DT:?}\n{friction_keys}[grid]\nmethod = [{}]\n",
        method.1
    );
    let path = sweeps_dir().join("sliding_block_test.toml");
    let plan = expand(&SweepFile::parse(&path, &text).expect("valid sweep")).expect("plan");
    assert_eq!(plan.runs.len(), 1, "{text}");
    let spec = &plan.runs[0];
    let what = format!("{dim}D {} α = {incline}° μ_f = {friction:?}", method.0);
    let o = simulate_with(
        &spec.config,
        &RunOptions {
            series_every: 1,
            ..RunOptions::default()
        },
        &RunContext {
            reference: None,
            record_reference: Some((1, 1)),
        },
    );
    assert_eq!(o.status.as_str(), "ok", "{what}: {:?}", o.message);
    let data = o
        .reference
        .as_ref()
        .expect("a recorded run keeps its solution");

    // The consistent mass's row sums m_a = ∫ρφ_a (1ᵀM restricted to node a, any component).
    let mesh = GmshMesh::read(&mesh_path(dim)).expect("the committed block mesh");
    let n = mesh.num_nodes();
    let mut e1 = [0.0; 3];
    e1[0] = 1.0;
    let lumped = assemble_load(&mesh, &DofMap::all(n * dim), RHO, e1, &|_| 1.0);
    let m_a: Vec<f64> = (0..n).map(|a| lumped[a * dim]).collect();
    let mass: f64 = m_a.iter().sum();
    let contact = mesh.contact_nodes();
    assert_eq!(data.lattice[0], n, "{what}: the record holds every node");

    let stride = n * dim;
    let u = |k: usize, a: usize, c: usize| data.u[k * stride + a * dim + c];
    let mut t_half = Vec::new();
    let mut p_half = Vec::new();
    let mut all_forward = Vec::new();
    // Moreau–Jean's slip is the velocity v_t^{n+1} (contract §2.5), not the increment: a node may
    // stick at the velocity level (v_t^{n+1} = 0) while (u^{n+1} − u^n)/τ = (v^n + v^{n+1})/2
    // is still positive. Its contact velocities from the displacements, v^{k+1} = 2(u^{k+1} −
    // u^k)/τ − v^k (θ = ½), from v⁰ = V.
    let velocity_slip = method.0 == "moreau-jean";
    let mut v_t = vec![V; contact.len()];
    for k in 0..data.times - 1 {
        let mut p = [0.0; 3];
        for (c, pc) in p.iter_mut().enumerate().take(dim) {
            *pc = (0..n)
                .map(|a| m_a[a] * (u(k + 1, a, c) - u(k, a, c)))
                .sum::<f64>()
                / DT;
        }
        // Keep e_d last whatever the dimension: p[dim − 1] is the normal momentum.
        t_half.push((k as f64 + 0.5) * DT);
        p_half.push(p);
        if velocity_slip {
            for (v, &a) in v_t.iter_mut().zip(&contact) {
                *v = 2.0 * (u(k + 1, a, 0) - u(k, a, 0)) / DT - *v;
            }
            // 1e-9·V: the recursion's round-off over 10³ steps of increments ~Vτ.
            all_forward.push(v_t.iter().all(|&v| v > 1e-9 * V));
        } else {
            all_forward.push(contact.iter().all(|&a| u(k + 1, a, 0) > u(k, a, 0)));
        }
    }
    let mean_u1 = (0..data.times)
        .map(|k| (0..n).map(|a| u(k, a, 0)).sum::<f64>() / n as f64)
        .collect();
    let com_d = (0..data.times)
        .map(|k| (0..n).map(|a| m_a[a] * u(k, a, dim - 1)).sum::<f64>() / mass)
        .collect();
    Trace {
        what,
        mass,
        t_half,
        p_half,
        all_forward,
        com_d,
        force: data.force.clone(),
        mean_u1,
        dim,
        u: data.u.clone(),
        outcome: o,
    }
}

impl Trace {
    /// The forward-sliding steps again, a Γ_C node counting as forward only if its Δu_1 exceeds
    /// `tol` (a stuck massless node moves by round-off).
    fn forward_beyond(mut self, tol: f64) -> Trace {
        let mesh = GmshMesh::read(&mesh_path(self.dim)).expect("the committed block mesh");
        let (n, dim) = (mesh.num_nodes(), self.dim);
        let contact = mesh.contact_nodes();
        let u = |k: usize, a: usize| self.u[k * n * dim + a * dim];
        self.all_forward = (0..self.all_forward.len())
            .map(|k| contact.iter().all(|&a| u(k + 1, a) - u(k, a) > tol))
            .collect();
        self
    }

    /// P^{n+½} again with the run's own mass: `rows[a]` = (M 1_c)_a, the row sum of node a's
    /// component-c row over component c (the same for every c; a mass variant that zeroes or
    /// reweights rows changes it — contract §1.8's P is 1ᵀM v with the run's M).
    fn with_mass_rows(mut self, rows: &[f64]) -> Trace {
        let (dim, n) = (self.dim, rows.len());
        let stride = n * dim;
        let u = |k: usize, a: usize, c: usize| self.u[k * stride + a * dim + c];
        let p_half = (0..self.p_half.len())
            .map(|k| {
                let mut p = [0.0; 3];
                for (c, pc) in p.iter_mut().enumerate().take(dim) {
                    *pc = (0..n)
                        .map(|a| rows[a] * (u(k + 1, a, c) - u(k, a, c)))
                        .sum::<f64>()
                        / DT;
                }
                p
            })
            .collect();
        // `mass` stays ρ|Ω|: the body load's sum ΣF, whatever M keeps.
        self.p_half = p_half;
        self
    }
}

/// The row sums (M_run 1_c)_a of a mass variant on the block (contract §2.2): the consistent
/// mass assembled with the element weights of `mass` by layer (layer 0 the cells touching Γ_C,
/// by topology; mod2 and mod3 with the measured layer masses, as the engine), and for
/// `zero-contact` the consistent mass with the Γ_C nodes' rows and columns zeroed. `weights`:
/// the layer weights [0, w1, w2, …] (the last repeating).
fn mass_rows(dim: usize, mass: &str, weights: &[f64]) -> Vec<f64> {
    let mesh = GmshMesh::read(&mesh_path(dim)).expect("the committed block mesh");
    let n = mesh.num_nodes();
    let contact = mesh.contact_nodes();
    let layer = mesh_layers(&mesh, &contact);
    let all = DofMap::all(n * dim);
    let mut e1 = [0.0; 3];
    e1[0] = 1.0;
    let rows_with = |w: &dyn Fn(usize) -> f64| -> Vec<f64> {
        let load = assemble_load(&mesh, &all, RHO, e1, &|e| w(layer[e]));
        (0..n).map(|a| load[a * dim]).collect()
    };
    let layer_mass = |l: usize| {
        rows_with(&|k| f64::from(u8::from(k == l)))
            .iter()
            .sum::<f64>()
    };
    let total: f64 = rows_with(&|_| 1.0).iter().sum();
    let (m0, m1) = (layer_mass(0), layer_mass(1));
    let w: Box<dyn Fn(usize) -> f64> = match mass {
        "mod1" => Box::new(|k| if k == 0 { 0.0 } else { 1.0 }),
        "mod2" => Box::new(move |k| if k == 0 { 0.0 } else { total / (total - m0) }),
        "mod3" => Box::new(move |k| match k {
            0 => 0.0,
            1 => 1.0 + m0 / m1,
            _ => 1.0,
        }),
        "weights" => Box::new(|k| {
            if k == 0 {
                0.0
            } else {
                weights[(k - 1).min(weights.len() - 1)]
            }
        }),
        "zero-contact" => {
            // Σ_b∉Γ_C M_ab for a ∉ Γ_C, 0 on Γ_C: the consistent M applied to 1 off Γ_C.
            let pattern = fe_pattern(&mesh, &all);
            let m = assemble(&mesh, &all, &pattern, ElementOp::Mass { rho: RHO }, &|_| {
                1.0
            });
            let on = |a: usize| contact.contains(&a);
            let x: Vec<f64> = (0..n * dim)
                .map(|i| f64::from(u8::from(i % dim == 0 && !on(i / dim))))
                .collect();
            let mut y = vec![0.0; n * dim];
            m.matvec_into(&x, &mut y);
            return (0..n)
                .map(|a| if on(a) { 0.0 } else { y[a * dim] })
                .collect();
        }
        other => panic!("not a massless variant: {other}"),
    };
    rows_with(&*w)
}

/// |Ω| of the blocks: the rectangle 1 × 0.5, the box 1 × 0.5 × 0.5.
fn volume(dim: usize) -> f64 {
    if dim == 2 { 0.5 } else { 0.25 }
}

/// max_n |x^n − x^0| over a slice of half levels, relative to `scale`.
fn max_dev(x: impl Iterator<Item = f64>, scale: f64) -> f64 {
    let v: Vec<f64> = x.collect();
    v.iter()
        .map(|y| ((y - v[0]) / scale).abs())
        .fold(0.0, f64::max)
}

/// Frictionless (μ_f = 0 is the law-free engine, every method available now): P_1 − ΣF_1·t is
/// constant to 1e-10·mV for the five methods, flat and tilted, 2D and 3D; on the flat plane the
/// block slides at its initial mean velocity V; on the incline its momentum grows at m·g·sin α,
/// the incline's load measured through the engine's own displacements.
///
/// Tolerance 1e-10·mV: the identity is exact in exact arithmetic (module header); P^{n+½} is a
/// difference quotient of displacements of size ≤ V·T ≈ 5 (flat) and ½ g sin α T² ≈ 2.7 (tilted)
/// over τ = 0.05, so its round-off is ~ 1e-16·5/0.05·√(nodes) ≈ 1e-13, and the step solves
/// (sparse Cholesky, exact active sets) are backward stable: 1e-10 leaves three decades.
#[test]
fn frictionless_block_keeps_its_tangential_momentum() {
    let t = 10.0;
    for dim in [2, 3] {
        for method in METHODS {
            for incline in [0.0, INCLINE] {
                let tr = trace(dim, method, incline, None, t);
                let m = RHO * volume(dim);
                assert!(
                    (tr.mass - m).abs() <= 1e-13 * m,
                    "{}: Σ∫ρφ_a = {} ≠ ρ|Ω| = {m}",
                    tr.what,
                    tr.mass
                );
                let (f1, _) = tr.load_sum(incline);
                let q = tr.t_half.iter().zip(&tr.p_half).map(|(t, p)| p[0] - f1 * t);
                let dev = max_dev(q, m * V);
                println!("{}: max |ΔQ|/(mV) = {dev:.2e}", tr.what);
                assert!(
                    dev <= 1e-10,
                    "{}: P_1 − ΣF_1·t moved by {dev:e}·mV",
                    tr.what
                );
                // The first half level: P_1^{½} = m(V + ½τ·g sin α) (P_1 = mV at t = 0 and
                // the invariant), so the mean tangential velocity is V where the plane is flat.
                let p0 = tr.p_half[0][0];
                let want = m * V + f1 * 0.5 * DT;
                assert!(
                    (p0 - want).abs() <= 1e-12 * m * V,
                    "{}: P_1^{{½}} = {p0}, want {want}",
                    tr.what
                );
            }
        }
    }
}

/// The block rests on the plane (mixed + CN, consistent mass). Crank–Nicolson's normal momentum
/// balance with the engine's recorded contact force, P_d^{n+½} − P_d^{½} = τ Σ_{k=1..n} (ΣF_d +
/// (f^{k−1} + 2f^k + f^{k+1})/4) (the CN increment of the module header averaged over two
/// steps), holds to 1e-10·m·g·T: the plane carries the weight ρ|Ω|·g·cos α and nothing else
/// acts along e_d. The centre of mass settles by at most 3δ, δ = ρ g cos α H²/(3E') the static
/// settlement of the centre of mass of a free column of height H = 0.5 under its weight
/// (E' = E/(1 − ν²) in plane strain, E in 3D, where the lateral faces are free): a suddenly
/// applied weight doubles the static settlement in an undamped elastic body (measured 1.9δ in
/// 2D, 2.4δ in 3D, where CN's chatter adds energy), 3δ leaving room for the coarse Q1 mesh. It
/// rises above its start only by what the energy CN gained allows: with F the body load,
/// −Fᵀu = m·g·cos α·z (z the centre of mass's vertical displacement, the along-slope part
/// aside on the incline), and ½vᵀMv ≥ P_1²/(2m), so m·g·cos α·z ≤ E^n − E⁰ +
/// (P_1^0² − P_1^n²)/(2m) — flat: z ≤ max_n (E^n − E⁰)/(m g) (the consistent mass's CN gains up
/// to 1e-2 of the energy scale here: contract §2.1's spurious growth, which lifts the 3D block
/// 3e-3 off the plane at times). The nodes never go below the plane (max_penetration at
/// round-off).
#[test]
fn frictionless_block_rests_on_the_plane() {
    let t = 10.0;
    let e = LAME * (3.0 * LAME + 2.0 * LAME) / (LAME + LAME);
    let nu = LAME / (2.0 * (LAME + LAME));
    for dim in [2, 3] {
        for incline in [0.0, INCLINE] {
            let tr = trace(dim, METHODS[0], incline, None, t);
            let (_, fd) = tr.load_sum(incline);
            let m = tr.mass;
            let mut acc = 0.0;
            let mut worst: f64 = 0.0;
            for n in 1..tr.p_half.len() {
                let f = &tr.force;
                acc += DT * (fd + (f[n - 1] + 2.0 * f[n] + f[n + 1]) / 4.0);
                let dp = tr.p_half[n][tr.dim - 1] - tr.p_half[0][tr.dim - 1];
                worst = worst.max((dp - acc).abs());
            }
            let scale = m * GRAVITY * t;
            println!("{}: normal balance {:.2e}·mgT", tr.what, worst / scale);
            assert!(
                worst <= 1e-10 * scale,
                "{}: P_d − ∫(ΣF_d + f) off by {:e}·mgT",
                tr.what,
                worst / scale
            );
            let e_eff = if dim == 2 { e / (1.0 - nu * nu) } else { e };
            let delta = RHO * GRAVITY * incline.to_radians().cos() * 0.25 / (3.0 * e_eff);
            let settle = tr.com_d.iter().fold(0.0_f64, |a, z| a.max(-z));
            let rise = tr.com_d.iter().fold(0.0_f64, |a, &z| a.max(z));
            println!(
                "{}: centre of mass settles by at most {settle:.3e} (δ = {delta:.3e}), rises by {rise:.1e}",
                tr.what
            );
            assert!(settle <= 3.0 * delta, "{}: settled by {settle:e}", tr.what);
            if incline == 0.0 {
                let gained = tr.outcome.metrics.energy_max_dev.expect("reported")
                    * tr.outcome.metrics.energy_scale.expect("reported");
                let allowed = gained / (m * GRAVITY) + 1e-14;
                assert!(
                    rise <= allowed,
                    "{}: rose by {rise:e} > {allowed:e}, more than the energy gained allows",
                    tr.what
                );
            }
            let pen = tr
                .outcome
                .metrics
                .max_penetration
                .expect("FE runs report it");
            assert!(pen <= 1e-12, "{}: penetration {pen:e}", tr.what);
        }
    }
}

/// A body with nothing clamped runs with every mass variant of the FE scenes (issue 33, part
/// 3): the step matrix M + cτ²K is positive definite as soon as M is positive on the rigid
/// motions (the null space of K) — true of every variant: the ones that zero layer 0 or the
/// Γ_C rows keep the mass of the nodes above Γ_C, on which no rigid motion vanishes; the one
/// that would keep no mass at all (a single element layer) is refused with its reason. On the
/// flat frictionless plane the block (symmetric about x = ½, as every layer-based variant)
/// translates at V: the plain mean of u_1 over the nodes is V·t, the lateral Poisson spreading
/// under the weight being antisymmetric. Tolerance 1e-8·V·T: the asymmetry is round-off, which
/// the contact's chatter amplifies where Γ_C keeps mass (CN with a mass on the contact rows
/// gains up to 1e-1 of the energy scale here, contract §2.1): measured 3e-10 (3D lumped), ≤ 2e-11
/// with the massless variants.
#[test]
fn frictionless_block_slides_with_every_mass_variant() {
    let t = 10.0;
    for dim in [2, 3] {
        for mass in [
            "consistent",
            "lumped",
            "mod1",
            "mod2",
            "mod3",
            "zero-contact",
        ] {
            let bundle =
                format!("{{ space = \"mixed\", mass = \"{mass}\", scheme = \"crank-nicolson\" }}");
            let tr = trace(dim, (mass, &bundle), 0.0, None, t);
            let dev = tr
                .mean_u1
                .iter()
                .enumerate()
                .map(|(k, x)| (x - V * k as f64 * DT).abs())
                .fold(0.0, f64::max)
                / (V * t);
            println!("{}: mean u_1 − V·t ≤ {dev:.2e}·V·T", tr.what);
            assert!(dev <= 1e-8, "{}: mean u_1 off V·t by {dev:e}·V·T", tr.what);
            let drift = tr.outcome.metrics.energy_drift.expect("reported");
            println!("{}: energy drift {drift:.2e}·energy_scale", tr.what);
        }
    }
}

/// The forward-sliding window of a frictional trace (the steps up to the first where some Γ_C
/// node does not move forward) and Q's largest change over it, relative to m·V:
/// Q = P_1 + μ_f P_d − (ΣF_1 + μ_f ΣF_d)·t. Asserts the window lasts at least a fifth of the
/// rigid stopping time V/(g(μ_f cos α − sin α)), so that Q is tested over hundreds of steps:
/// kane and Moreau–Jean slide until near the stop (0.85–0.97·t_rigid: the elastic block's mean
/// velocity follows the rigid one to μ_f·v_d, v_d ≈ 1e-2 its vertical vibration); the
/// Crank–Nicolson runs' chatter makes some node stick or step back earlier (measured ≥ 0.24,
/// mixed + CN in 3D at 5°).
fn frictional_invariant(tr: &Trace, incline: f64, t_rigid: f64) -> (usize, f64) {
    let (f1, fd) = tr.load_sum(incline);
    let window = tr.all_forward.iter().take_while(|&&f| f).count();
    let t_end = window as f64 * DT;
    println!(
        "{}: every contact point slides forward until t = {t_end:.3} (rigid stop {t_rigid:.3})",
        tr.what
    );
    assert!(
        t_end >= 0.2 * t_rigid,
        "{}: a contact point stopped sliding at t = {t_end} < t_rigid/5",
        tr.what
    );
    let d = tr.dim - 1;
    let q = tr.t_half[..window]
        .iter()
        .zip(&tr.p_half[..window])
        .map(|(t, p)| p[0] + MU_F * p[d] - (f1 + MU_F * fd) * t);
    let dev = max_dev(q, tr.mass * V);
    println!("{}: max |ΔQ|/(mV) = {dev:.2e}", tr.what);
    (window, dev)
}

/// Issue 33 "done when" 1 in 2D: while every contact point slides forward, Q = P_1 + μ_f P_d −
/// (ΣF_1 + μ_f ΣF_d)·t stays constant to 1e-10·mV (the tolerance of the frictionless test, the
/// same round-off: the contact solves are exact active-set or Newton solves to round-off), for
/// the five methods, flat and on the incline (measured ≤ 9.5e-11·mV, Nitsche at 5°).
///
/// The same block in 3D (ν = 0.25) is measured here too, and does not keep Q exactly, nor
/// should it: the Coulomb disc gives f_t1 = −μ_f f_n·cos θ_i, θ_i the angle of node i's slip
/// from e_1, and the box's Γ_C nodes also slip sideways as it spreads under its weight
/// (Poisson), so Σ f_t1 ≠ −μ_f Σ f_n: measured 1.0e-3 … 5.0e-3·mV over the five methods'
/// windows, asserted below 1e-2 (μ_f times the lateral slip velocity over V, ~ν·the weight's
/// strain rate over the vibration, is of that order). The exact 3D statement, where the slip
/// stays along e_1, is the next test.
#[test]
fn sliding_block_keeps_the_frictional_invariant_until_it_sticks() {
    for dim in [2, 3] {
        for method in METHODS {
            for incline in [0.0, INCLINE] {
                let (s, c) = incline.to_radians().sin_cos();
                let t_rigid = V / (GRAVITY * (MU_F * c - s));
                let tr = trace(dim, method, incline, Some(MU_F), 1.2 * t_rigid);
                let (_, dev) = frictional_invariant(&tr, incline, t_rigid);
                let tol = if dim == 2 { 1e-10 } else { 1e-2 };
                assert!(dev <= tol, "{}: Q moved by {dev:e}·mV", tr.what);
            }
        }
    }
}

/// The massless variants' weights of `mass = "weights"` here: layer 1 × 1.5, the rest × 1.
const WEIGHTS: [f64; 2] = [1.5, 1.0];

/// Issue 42 "done when" 2: the invariant of the previous test for Crank–Nicolson with every
/// massless variant (mixed contact, 2D, flat and on the incline), P with the run's own mass
/// ([`mass_rows`]). The Γ_C nodes have no inertia: their equation is quasi-static at every
/// level, t = 0 included, so the momentum balance of the module header holds from the first
/// step only if the start is the quasi-static one with the sliding nodes' friction
/// f_t⁰ = −μ_f f_n⁰ (contract §2.2): without f_t⁰, CN's f̄_t of the first step misses half a
/// step's friction and Q is off by a constant from then on (1.3e-4·mV with mod3 before issue
/// 42). Asserted: the first step keeps Q to 1e-14·mV (measured ≤ 9e-16), and the window to
/// 1e-10·mV, the bound of the consistent mass and of the frictionless test (the same
/// round-off argument: the contact solves are exact to round-off; measured ≤ 5.8e-12·mV, mod2 at
/// 5° over 736 steps). A massless node that stops has Δu_1 at round-off (2.7e-15 measured,
/// mod1), not 0: the window ends where some Γ_C node's Δu_1 falls below the engine's stick
/// threshold 1e-12·h (contract §5, h = 0.125). These runs step in increments
/// (`run::fe::newmark`'s header): solved for the totals u^{n+1}, the solve's round-off is
/// relative to the distance travelled (u_1 ≈ V·t ≫ Vτ) and Q random-walked with growing steps
/// (mod1 at 5°: 1.7e-12, 9.5e-12, 2.4e-11, 1.5e-10·mV after 100, 200, 300, 595 steps; 5.2e-10
/// for mod2 at 5°), while the engine's Coulomb sums Σf_t + μ_f Σf_n are ≤ 7e-18 at every step.
#[test]
fn sliding_block_keeps_the_frictional_invariant_with_every_massless_variant() {
    for mass in ["zero-contact", "mod1", "mod2", "mod3", "weights"] {
        let weights = if mass == "weights" {
            format!(", mass_weights = {WEIGHTS:?}")
        } else {
            String::new()
        };
        let bundle = format!(
            "{{ space = \"mixed\", mass = \"{mass}\"{weights}, scheme = \"crank-nicolson\" }}"
        );
        let rows = mass_rows(2, mass, &WEIGHTS);
        for incline in [0.0, INCLINE] {
            let (s, c) = incline.to_radians().sin_cos();
            let t_rigid = V / (GRAVITY * (MU_F * c - s));
            let tr = trace(2, (mass, &bundle), incline, Some(MU_F), 1.2 * t_rigid)
                .with_mass_rows(&rows)
                .forward_beyond(1e-12 * 0.125);
            let (f1, fd) = tr.load_sum(incline);
            let q = |k: usize| {
                let p = tr.p_half[k];
                p[0] + MU_F * p[1] - (f1 + MU_F * fd) * tr.t_half[k]
            };
            let first = ((q(1) - q(0)) / (tr.mass * V)).abs();
            println!("{}: first step |ΔQ|/(mV) = {first:.2e}", tr.what);
            assert!(
                first <= 1e-14,
                "{}: the first step moved Q by {first:e}·mV",
                tr.what
            );
            let (_, dev) = frictional_invariant(&tr, incline, t_rigid);
            assert!(dev <= 1e-10, "{}: Q moved by {dev:e}·mV", tr.what);
        }
    }
}

/// Issue 33 "done when" 1 in 3D: the invariant to 1e-10·mV for the five methods, flat and on
/// the incline, where contract §1.8's premise holds — every contact point slides along +e_1. With
/// Lamé λ = 0 (ν = 0) the weight and the e_1–e_d friction strain the box in no lateral way, and
/// on the structured Q1 box the solution independent of x_2 with u_2 = 0 solves the discrete
/// equations (every e_2 equation's terms carry ∂/∂x_2 of u_1, u_d or u_2 itself), so the
/// lateral momentum P_2 stays at round-off and the disc law gives f_t = −μ_f f_n e_1 at each
/// node. The box starts 1e-3 above the plane: resting at gap 0, Moreau–Jean's index set
/// (predicted gap (Buⁿ + g) + ½τBvⁿ ≤ 0, contract §3.2) decides nodes whose gap is 0 to round-off by
/// the sign of that round-off, which breaks the box's mirror symmetry at the second step
/// (lateral displacements of 1e-5 per step, P_2 ~ 1e-9 … 4e-5·mV after, measured): a property of
/// the method's sharp index set, not of the friction. Landing at √(2g·1e-3) = 0.014, every node
/// penetrates by ~τ·v/2 = 3.5e-4 and stays in the index set by that margin.
/// Tolerance 1e-10·mV as in 2D (measured ≤ 4.5e-11·mV, penalty at 5°); P_2 ≤ 1e-9·mV over the
/// window (measured ≤ 1.4e-10·mV, Nitsche at 5°: round-off grown by the CN chatter).
#[test]
fn sliding_block_keeps_the_frictional_invariant_in_3d_when_it_slides_along_e1() {
    for method in METHODS {
        for incline in [0.0, INCLINE] {
            let (s, c) = incline.to_radians().sin_cos();
            let t_rigid = V / (GRAVITY * (MU_F * c - s));
            let tr = trace_with(3, method, incline, Some(MU_F), 1.2 * t_rigid, 0.0, 1e-3);
            let (window, dev) = frictional_invariant(&tr, incline, t_rigid);
            assert!(dev <= 1e-10, "{}: Q moved by {dev:e}·mV", tr.what);
            let lateral = tr.p_half[..window]
                .iter()
                .fold(0.0f64, |a, p| a.max(p[1].abs()))
                / (tr.mass * V);
            println!("{}: max |P_2|/(mV) = {lateral:.2e}", tr.what);
            assert!(lateral <= 1e-9, "{}: P_2 = {lateral:e}·mV", tr.what);
        }
    }
}

/// Issue 33: the block stops near the rigid time V/(g(μ_f cos α − sin α)) (25 flat, 44.6 at 5°). Tolerance
/// 5 %: while every point slides the invariant gives the mean velocity V − a·t − μ_f·v_d
/// (a the rigid deceleration, v_d the centre of mass's vertical velocity, ≲ 1e-2 by the rest
/// test's settlement bound), a shift of μ_f·v_d/a ≲ 0.1 (0.4 %); the last slip–stick
/// transition of the elastic block lasts about a shear round trip 2H/c_s = 0.32 (1.3 % of 25):
/// 5 % holds both twice over.
#[test]
fn sliding_block_stops_near_the_rigid_time() {
    for dim in [2, 3] {
        let mod3 = (
            "mixed mod3 + CN",
            "{ space = \"mixed\", mass = \"mod3\", scheme = \"crank-nicolson\", contact_init = \"interpolant\" }",
        );
        let mod3_quasi_static = (
            "mixed mod3 + CN, quasi-static start",
            "{ space = \"mixed\", mass = \"mod3\", scheme = \"crank-nicolson\" }",
        );
        for method in METHODS.into_iter().chain([mod3, mod3_quasi_static]) {
            for incline in [0.0, INCLINE] {
                let (s, c) = incline.to_radians().sin_cos();
                let t_rigid = V / (GRAVITY * (MU_F * c - s));
                let mod3_run = method.0.starts_with("mixed mod3");
                let t_end = if mod3_run { 1.6 } else { 1.2 } * t_rigid;
                let tr = trace(dim, method, incline, Some(MU_F), t_end);
                let stop = tr.outcome.metrics.stop_time.unwrap_or(f64::NAN);
                println!("{}: stop_time {stop:.4} (rigid {t_rigid:.4})", tr.what);
                // Measured (stop_time / rigid): kane 1.043, 1.084 (5°) in 2D, 1.041, 1.072 in
                // 3D; Moreau–Jean 1.028 (2D), 1.031, 1.082 (3D), none by 1.2·t_rigid at 5° in
                // 2D. The CN-based runs (mixed, Nitsche, penalty with the consistent mass) gain
                // energy at the contact (contract §2.1's spurious oscillations: the block hops)
                // and stop late or not by 1.2·t_rigid: printed, not asserted. Asserted: kane
                // and Moreau–Jean stop within 5 % on the flat plane, kane within 10 % at 5°
                // (the net deceleration g(μ_f cos α − sin α) is 2 % of g there, so the elastic
                // block's stick–slip end weighs more).
                // Crank–Nicolson with the redistributed mass mod3 (002's remedy for the
                // spurious oscillations: no inertia at Γ_C, the block does not hop,
                // energy_balance_max_increase ≤ 5e-4 of the scale), flat plane: started at
                // u⁰ = 0 (`contact_init = "interpolant"`) it stops 3.3 % (2D) and 4.9 % (3D)
                // late, asserted within 6 % as before; started quasi-static (issue 42, the
                // default) 39.7 % (2D) and 23.3 % (3D) late. Not a defect of the start (its f_t⁰
                // reaches the tallies and CN's f̄_t: the first step keeps contract §1.8's
                // invariant to 9e-16·mV, the previous test), but what this stop is: the
                // vertical vibration of the suddenly loaded block, which CN does not damp (Σf_n
                // swings between 0.04 and 3 times the weight), makes the elastic block creep at
                // ~2 % of V once its Γ_C nodes start to stick, the friction of the sticking
                // nodes even pointing forward — so the stop after t_rigid is ill-conditioned.
                // Measured (stop/t_rigid) at τ = 0.05, 0.04, 0.025: u⁰ = 0 1.033, 1.099, 1.106
                // (2D), 1.049, 1.067, 1.194 (3D); quasi-static 1.397, 1.130, 1.196 (2D), 1.233,
                // 1.084, 1.167 (3D). Asserted for both starts: a stop in [0.99, 1.5]·t_rigid.
                // The lower end is a theorem: Coulomb's cone |Σf_t| ≤ μ_f Σf_n holds sliding or
                // stuck, and ∫Σf_n = m·g·t + ΔP_d, so the mean velocity is ≥ V − μ_f g t −
                // μ_f|Δv̄_d| and cannot reach 0 before t_rigid − |Δv̄_d|/g, |v̄_d| ≲ 1e-2 (the
                // rest test's settlement bound): 0.99·t_rigid. The upper end is the envelope of
                // the τ scan above (1.40) with room, run to 1.6·t_rigid.
                if mod3_run && incline == 0.0 {
                    assert!(
                        (0.99 * t_rigid..=1.5 * t_rigid).contains(&stop),
                        "{}: stop_time {stop} vs rigid {t_rigid}",
                        tr.what
                    );
                }
                let bound = match (method.0, incline == 0.0) {
                    ("kane" | "moreau-jean", true) => Some(0.05),
                    ("kane", false) => Some(0.10),
                    ("mixed mod3 + CN", true) => Some(0.06),
                    _ => None,
                };
                let Some(bound) = bound else { continue };
                assert!(
                    (stop - t_rigid).abs() <= bound * t_rigid,
                    "{}: stop_time {stop} vs rigid {t_rigid}",
                    tr.what
                );
            }
        }
    }
}

/// `zero-contact` (003's modified mass: Γ_C's rows and columns of the consistent M removed)
/// keeps 1ᵀM1 = m − ⅔·m_layer, m_layer the bottom element layer's mass: Q1's vertical factor
/// [2 1; 1 2]/6 puts ½ of the layer in the Γ_C rows and ⅓ in their mutual block, so the removed
/// part is 2·½ − ⅓ = ⅔ of it — 1/6 of the 2D block (4 layers), 1/3 of the 3D one (2 layers).
/// The whole weight still presses on the plane, so the momentum 1ᵀMv of the remaining inertia
/// m_M decelerates at μ_f·m·g/m_M: the block stops at (m_M/m)·V/(μ_f g) — 20.83 (2D) and 16.67
/// (3D) on the flat plane. Tolerance 5 % as for kane and Moreau–Jean (the elastic block's end of
/// the slide; measured 0.7 % and 0.6 % late). A consistency error O(h) of the variant, not of
/// the friction: the test pins what the reported `stop_time` means for it.
#[test]
fn zero_contact_mass_stops_the_block_early_by_the_mass_it_removes() {
    let bundle = "{ space = \"mixed\", mass = \"zero-contact\", scheme = \"crank-nicolson\" }";
    for (dim, layers) in [(2, 4.0), (3, 2.0)] {
        let t_rigid = V / (GRAVITY * MU_F);
        let tr = trace(
            dim,
            ("zero-contact + CN", bundle),
            0.0,
            Some(MU_F),
            1.2 * t_rigid,
        );
        let kept = 1.0 - 2.0 / 3.0 / layers;
        let want = kept * t_rigid;
        let stop = tr.outcome.metrics.stop_time.unwrap_or(f64::NAN);
        println!(
            "{}: stop_time {stop:.4}, (m_M/m)·t_rigid = {want:.4}",
            tr.what
        );
        assert!(
            (stop - want).abs() <= 0.05 * want,
            "{}: stop_time {stop} vs {want}",
            tr.what
        );
    }
}

/// Backward Euler stops the block at the rigid time. Its momentum equation summed over the
/// nodes (1ᵀK = 0) is P^{n+1} − P^n = τ(ΣF + Σf^{n+1}) — one force level per step — and while
/// every contact point slides forward Σf_1^{n+1} = −μ_f Σf_d^{n+1}, so P_1 + μ_f P_d falls at
/// exactly m·g(μ_f cos α − sin α): the mean velocity reaches 0 at t_rigid + μ_f P_d(t_stop)/
/// (m g(μ_f cos α − sin α)). The scheme's damping takes the weight's vertical vibration (so P_d)
/// and the shear vibration out long before the stop, and every point slides to the end: the
/// stop is the rigid one to the damped remainder. Tolerance 1e-3·t_rigid (two steps τ = 0.05
/// in 25 would be 4e-3); measured ≤ 8.8e-5 (3D penalty at 5°; 2.2e-11 for mixed in 2D on the
/// flat plane) for every method, 2D and 3D, flat and at 5° (in 3D the sideways slip under the
/// weight is damped away too). `mixed`, Nitsche Θ = 1 and 0, the
/// penalty: the regression test of the frictional Nitsche Newton that settled on a
/// local minimum of its merit as the block came to rest (Θ = 0, t = 25.75: `solver-failed`),
/// now restarted cold.
#[test]
fn backward_euler_stops_the_block_at_the_rigid_time() {
    let methods = [
        (
            "mixed + BE",
            "{ space = \"mixed\", scheme = \"backward-euler\" }",
        ),
        (
            "nitsche Θ = 1 + BE",
            "{ space = \"nitsche\", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = \"backward-euler\" }",
        ),
        (
            "nitsche Θ = 0 + BE",
            "{ space = \"nitsche\", nitsche_theta = 0.0, nitsche_gamma0 = 1e-3, scheme = \"backward-euler\" }",
        ),
        (
            "penalty + BE",
            "{ space = \"penalty\", penalty_gamma0 = 100.0, scheme = \"backward-euler\" }",
        ),
    ];
    let mut worst: f64 = 0.0;
    for dim in [2, 3] {
        for method in methods {
            for incline in [0.0, INCLINE] {
                let (s, c) = incline.to_radians().sin_cos();
                let t_rigid = V / (GRAVITY * (MU_F * c - s));
                let tr = trace(dim, method, incline, Some(MU_F), 1.2 * t_rigid);
                let stop = tr.outcome.metrics.stop_time.unwrap_or(f64::NAN);
                let dev = (stop - t_rigid).abs() / t_rigid;
                println!(
                    "{}: stop_time {stop:.5} (rigid {t_rigid:.5}), {dev:.1e}",
                    tr.what
                );
                worst = worst.max(dev);
                assert!(dev <= 1e-3, "{}: stop_time {stop} vs {t_rigid}", tr.what);
            }
        }
    }
    println!("largest |stop − t_rigid|/t_rigid: {worst:.2e}");
}
