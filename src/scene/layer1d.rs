//! The frictional layer of contract §1.7 and its exact solution — the frictional twin of the
//! flying bar (§1.4).
//!
//! A layer 0 < z < H of an elastic solid (ρ, λ, μ) in plane strain, every field a function of
//! (z, t): the normal displacement w carries a P-wave (c_p = √((λ+2μ)/ρ), Z_p = ρc_p), the
//! tangential displacement u an S-wave (c_s = √(μ/ρ), Z_s = ρc_s); they are decoupled in the
//! bulk and meet only at the base z = 0, where w obeys Signorini against a rigid plane at gap g
//! and u the friction law (§2.5) with the normal force −σ_n. The top is free; the layer starts
//! unstrained with the uniform velocity (w_t, u_t) = (−V_n, V_t).
//!
//! Why it is exact. Each component is a layer with a free top driven by a base stress history
//! Σ(t) = S·1_W(t): its solution is the sum of the pulse's reflections,
//!
//!   σ(z,t) = q(t − z/c) − q(t + z/c − T_c),   v(z,t) = V0 − [q(t − z/c) + q(t + z/c − T_c)]/Z,
//!
//! with T_c = 2H/c the round trip and q(a) = Σ_{n≥0} Σ(a − nT_c) (at z = 0 it gives Σ, at z = H
//! zero stress). The normal part is the flying bar: contact on W = [t_c, t_c + D], t_c = g/V_n,
//! D = 2H/c_p, S = −Z_p V_n, then a rigid flight at +V_n. The shear pulse emitted at t_c needs
//! 2H/c_s ≥ D (c_s < c_p always) to come back, so during the whole contact the incoming shear
//! invariant is Z_s V_t and the base traction is one constant, σ_t* = proj_[−b,b](Z_s V_t)
//! (b = μ_f Z_p V_n, or Tresca's s): stick on all of W iff Z_s|V_t| ≤ b, slip on all of W at
//! v_slip = V_t − σ_t*/Z_s otherwise. After release the shear pulse stays trapped in the flying
//! layer, bouncing between its two free faces.
//!
//! Every field is piecewise constant (velocities, stresses) or piecewise affine (displacements)
//! between the fronts z = c(t − a) and z = c(a − t + T_c) of the breakpoints a of q — at most
//! four per component at a time — so energies are integrated exactly piece by piece and error
//! norms exactly by splitting each element at the fronts of both components (§1.4's method).
//! Energy identity: E(t) = E⁰ − W_f(t), W_f(t) = σ_t*·v_slip·|W ∩ [0, t]|.

use super::{
    ErrorSource, MeshChoice, MethodNames, Physics, PhysicsKey, Scene, SceneFacts, SceneSetup,
};
use crate::contact::friction::FrictionLaw;

/// The scene `layer1d` (contract §1.7).
#[derive(Debug, Clone, Copy)]
pub struct Layer1dScene;

const LAYER1D_PHYSICS: [PhysicsKey; 7] = [
    PhysicsKey {
        name: "height",
        default: 1.0,
    },
    PhysicsKey {
        name: "density",
        default: 1.0,
    },
    PhysicsKey {
        name: "lame_lambda",
        default: 2.0,
    },
    PhysicsKey {
        name: "lame_mu",
        default: 1.0,
    },
    PhysicsKey {
        name: "gap",
        default: 0.1,
    },
    PhysicsKey {
        name: "velocity",
        default: -1.0,
    },
    PhysicsKey {
        name: "velocity_tangential",
        default: 0.3,
    },
];

/// The scene's name, its physics keys and its default final time.
const FACTS: SceneFacts = SceneFacts {
    name: "layer1d",
    physics: &LAYER1D_PHYSICS,
    default_t: 2.5,
};

impl Layer1dScene {
    fn layer(physics: &Physics) -> LayerParams {
        LayerParams {
            height: physics.get("height"),
            density: physics.get("density"),
            lame_lambda: physics.get("lame_lambda"),
            lame_mu: physics.get("lame_mu"),
            gap: physics.get("gap"),
            velocity: physics.get("velocity"),
            velocity_tangential: physics.get("velocity_tangential"),
            // The planner sets the run's law (`RunConfig::with_friction`).
            friction: FrictionLaw::None,
        }
    }
}

impl Scene for Layer1dScene {
    fn facts(&self) -> SceneFacts {
        FACTS
    }
    /// c0 = c_p (the Courant number of the faster, normal, chain).
    fn wave_speed(&self, physics: &Physics) -> f64 {
        Self::layer(physics).c_p()
    }
    fn mesh_from_h(&self, physics: &Physics, h: f64) -> Result<MeshChoice, String> {
        super::bar1d::uniform_mesh(("height", "H", physics.get("height")), h)
    }
    fn mesh_from_elements(&self, physics: &Physics, elements: usize) -> Result<MeshChoice, String> {
        Ok(super::bar1d::uniform_elements(
            physics.get("height"),
            elements,
        ))
    }
    /// `mixed` and `penalty` with every 1D mass variant; the one-step schemes whose frictional
    /// version the literature defines (contract §2.5). Paoli–Schatzman, the hybrid schemes and
    /// the discrete gradient have none, and the layer exists for friction.
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        let (space, scheme) = (m.space, m.scheme);
        super::require("space", space, &["mixed", "penalty"], || {
            format!(
                "space = {space} is not available for scene layer1d (mixed, penalty; frictional Nitsche is issue 33)"
            )
        })?;
        if matches!(scheme, "paoli-schatzman" | "hybrid" | "discrete-gradient") {
            return Err((
                "scheme",
                format!(
                    "scheme = {scheme} has no frictional version in the literature (contract §2.5), and layer1d is the frictional benchmark: it runs the newmark and theta families, kane, contact-stabilized-newmark, generalized-alpha, hht, moreau-jean and central-difference"
                ),
            ));
        }
        Ok(())
    }
    fn error_source(&self, physics: &Physics) -> Option<ErrorSource> {
        Self::layer(physics).exact().map(|_| ErrorSource::Exact)
    }
    fn supports_friction(&self) -> Result<(), String> {
        Ok(())
    }
    fn setup(&self, physics: &Physics, mesh: MeshChoice) -> SceneSetup {
        SceneSetup::Layer1d {
            layer: Self::layer(physics),
            elements: mesh.elements,
        }
    }
}

/// The layer's physics (contract §1.7 keys) and its friction law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerParams {
    /// H (`height`).
    pub height: f64,
    /// ρ (`density`).
    pub density: f64,
    /// λ (`lame_lambda`).
    pub lame_lambda: f64,
    /// μ (`lame_mu`).
    pub lame_mu: f64,
    /// g (`gap`).
    pub gap: f64,
    /// The initial normal velocity −V_n (`velocity`; negative towards the obstacle).
    pub velocity: f64,
    /// The initial tangential velocity V_t (`velocity_tangential`).
    pub velocity_tangential: f64,
    /// The law at the base.
    pub friction: FrictionLaw,
}

impl Default for LayerParams {
    /// contract §1.7's defaults: H = ρ = μ = 1, λ = 2 (c_p = 2, c_s = 1), g = 0.1, V_n = 1,
    /// V_t = 0.3, frictionless.
    fn default() -> Self {
        LayerParams {
            height: 1.0,
            density: 1.0,
            lame_lambda: 2.0,
            lame_mu: 1.0,
            gap: 0.1,
            velocity: -1.0,
            velocity_tangential: 0.3,
            friction: FrictionLaw::None,
        }
    }
}

impl LayerParams {
    /// The P-wave modulus λ + 2μ (the normal chain's stiffness).
    pub fn p_modulus(&self) -> f64 {
        self.lame_lambda + 2.0 * self.lame_mu
    }
    /// c_p = √((λ+2μ)/ρ), the scene's c0.
    pub fn c_p(&self) -> f64 {
        (self.p_modulus() / self.density).sqrt()
    }
    /// c_s = √(μ/ρ).
    pub fn c_s(&self) -> f64 {
        (self.lame_mu / self.density).sqrt()
    }
    /// Z_p = ρ c_p.
    pub fn z_p(&self) -> f64 {
        self.density * self.c_p()
    }
    /// Z_s = ρ c_s.
    pub fn z_s(&self) -> f64 {
        self.density * self.c_s()
    }
    /// E⁰ = ½ρH(V_n² + V_t²).
    pub fn energy_initial(&self) -> f64 {
        0.5 * self.density
            * self.height
            * (self.velocity * self.velocity + self.velocity_tangential * self.velocity_tangential)
    }

    /// The closed form: the layer moving towards the obstacle (V_n > 0). None otherwise (it
    /// never touches; the error columns are null).
    pub fn exact(&self) -> Option<LayerExact> {
        (self.velocity < 0.0).then(|| LayerExact::new(*self))
    }
}

/// One plane-wave component: a layer with a free top driven at its base by the stress S on
/// W = [t_c, t_c + D] (module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneWave {
    /// Wave speed c.
    pub c: f64,
    /// Impedance Z = ρc.
    pub impedance: f64,
    /// Initial (uniform) velocity V0.
    pub v0: f64,
    /// Base stress S on W.
    pub stress: f64,
    /// Start of W.
    pub t_c: f64,
    /// Length of W.
    pub duration: f64,
    /// Round trip T_c = 2H/c.
    pub round_trip: f64,
    /// H.
    pub height: f64,
}

impl PlaneWave {
    /// q(a) = S·[r < D] with a − t_c = nT_c + r, 0 before t_c.
    fn q(&self, a: f64) -> f64 {
        if a < self.t_c {
            return 0.0;
        }
        let r = (a - self.t_c).rem_euclid(self.round_trip);
        if r < self.duration { self.stress } else { 0.0 }
    }

    /// Q(a) = ∫q = S·(nD + min(r, D)), 0 before t_c.
    fn q_int(&self, a: f64) -> f64 {
        if a < self.t_c {
            return 0.0;
        }
        let x = a - self.t_c;
        let n = (x / self.round_trip).floor();
        let r = x - n * self.round_trip;
        self.stress * (n * self.duration + r.min(self.duration))
    }

    /// The arguments t − z/c and t + z/c − T_c, the second formed as the first plus
    /// (2z/c − T_c): at the free top z = H both are the same number, so a front arriving
    /// there is seen by both characteristics alike (their difference would otherwise round
    /// to either side of a breakpoint and leave a spurious stress on the free face).
    fn args(&self, z: f64, t: f64) -> (f64, f64) {
        let up = t - z / self.c;
        (up, up + (2.0 * z / self.c - self.round_trip))
    }

    /// Velocity v(z, t).
    pub fn velocity(&self, z: f64, t: f64) -> f64 {
        let (up, down) = self.args(z, t);
        self.v0 - (self.q(up) + self.q(down)) / self.impedance
    }

    /// Stress σ(z, t) (the modulus times the strain).
    pub fn stress(&self, z: f64, t: f64) -> f64 {
        let (up, down) = self.args(z, t);
        self.q(up) - self.q(down)
    }

    /// Displacement (from the unstrained start).
    pub fn displacement(&self, z: f64, t: f64) -> f64 {
        let (up, down) = self.args(z, t);
        self.v0 * t - (self.q_int(up) + self.q_int(down)) / self.impedance
    }

    /// The fronts strictly inside (0, H) at time t, ascending, in `out`; returns their count
    /// (at most four: the breakpoints t_c + nT_c and t_c + nT_c + D in (t − T_c, t), one of
    /// each family per half round trip).
    pub fn fronts(&self, t: f64, out: &mut [f64; 4]) -> usize {
        let mut k = 0;
        for base in [self.t_c, self.t_c + self.duration] {
            let first = ((t - self.round_trip - base) / self.round_trip)
                .ceil()
                .max(0.0);
            let mut n = first;
            loop {
                let a = base + n * self.round_trip;
                if a >= t {
                    break;
                }
                if a > t - self.round_trip {
                    let z = if a > t - 0.5 * self.round_trip {
                        self.c * (t - a)
                    } else {
                        self.c * (a - t + self.round_trip)
                    };
                    if z > 0.0 && z < self.height && k < 4 {
                        out[k] = z;
                        k += 1;
                    }
                }
                n += 1.0;
            }
        }
        out[..k].sort_unstable_by(f64::total_cmp);
        k
    }

    /// ∫₀ᴴ (½ρv² + σ²/(2M)) dz with M = Z c the modulus, exactly (constant between fronts).
    pub fn energy(&self, t: f64, density: f64) -> f64 {
        let mut fronts = [0.0; 4];
        let k = self.fronts(t, &mut fronts);
        let modulus = self.impedance * self.c;
        let mut total = 0.0;
        let mut left = 0.0;
        for right in fronts[..k]
            .iter()
            .copied()
            .chain(std::iter::once(self.height))
        {
            if right > left {
                let mid = 0.5 * (left + right);
                let (v, s) = (self.velocity(mid, t), self.stress(mid, t));
                total += (right - left) * (0.5 * density * v * v + 0.5 * s * s / modulus);
                left = right;
            }
        }
        total
    }
}

/// The exact solution of the layer (module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerExact {
    p: LayerParams,
    normal: PlaneWave,
    tangential: PlaneWave,
    sigma_t_star: f64,
}

impl LayerExact {
    fn new(p: LayerParams) -> LayerExact {
        let v_n = -p.velocity;
        let t_c = p.gap / v_n;
        let duration = 2.0 * p.height / p.c_p();
        let (z_p, z_s) = (p.z_p(), p.z_s());
        // The base's bound during contact: the normal force is Z_p V_n (per unit area).
        let b = p.friction.bound(z_p * v_n, 1.0);
        let sigma_t_star = (z_s * p.velocity_tangential).clamp(-b, b);
        let wave = |c: f64, z: f64, v0: f64, stress: f64| PlaneWave {
            c,
            impedance: z,
            v0,
            stress,
            t_c,
            duration,
            round_trip: 2.0 * p.height / c, // = 2z/c at z = H, bit for bit (args)
            height: p.height,
        };
        LayerExact {
            p,
            normal: wave(p.c_p(), z_p, p.velocity, -z_p * v_n),
            tangential: wave(p.c_s(), z_s, p.velocity_tangential, sigma_t_star),
            sigma_t_star,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &LayerParams {
        &self.p
    }
    /// The normal (P-wave) component.
    pub fn normal(&self) -> &PlaneWave {
        &self.normal
    }
    /// The tangential (S-wave) component.
    pub fn tangential(&self) -> &PlaneWave {
        &self.tangential
    }
    /// The contact W = [t_c, t_c + D]: (t_c, D).
    pub fn contact_window(&self) -> (f64, f64) {
        (self.normal.t_c, self.normal.duration)
    }
    /// σ_t*, the base's tangential stress during contact.
    pub fn sigma_t_star(&self) -> f64 {
        self.sigma_t_star
    }
    /// Whether the base sticks during the contact (Z_s|V_t| ≤ b).
    pub fn sticks(&self) -> bool {
        self.v_slip() == 0.0
    }
    /// The base's slip velocity during contact, V_t − σ_t*/Z_s (0 in stick).
    pub fn v_slip(&self) -> f64 {
        let b = self.p.velocity_tangential - self.sigma_t_star / self.p.z_s();
        // Stick: σ_t* = Z_s V_t, whose division may leave one rounding.
        if (self.p.z_s() * self.p.velocity_tangential).abs() <= self.sigma_t_star.abs() {
            0.0
        } else {
            b
        }
    }

    /// t snapped onto the window's ends within 1e-12 of the time scale max(t, H/c_p): a step
    /// meant to land on an end must not fall on either side of the stress jump by round-off.
    fn snap(&self, t: f64) -> f64 {
        let (t_c, d) = self.contact_window();
        let tol = 1e-12 * t.abs().max(self.p.height / self.p.c_p());
        if (t - t_c).abs() <= tol {
            t_c
        } else if (t - t_c - d).abs() <= tol {
            t_c + d
        } else {
            t
        }
    }

    /// |W ∩ [0, t]|.
    pub fn contact_time_until(&self, t: f64) -> f64 {
        let (t_c, d) = self.contact_window();
        (self.snap(t) - t_c).clamp(0.0, d)
    }

    /// Whether the base is in contact at t (the open window: a step on either end takes 0).
    pub fn in_contact(&self, t: f64) -> bool {
        let (t_c, d) = self.contact_window();
        let s = self.snap(t);
        s > t_c && s < t_c + d
    }

    /// w(z, t).
    pub fn w(&self, z: f64, t: f64) -> f64 {
        self.normal.displacement(z, self.snap(t))
    }
    /// w_t(z, t).
    pub fn w_t(&self, z: f64, t: f64) -> f64 {
        self.normal.velocity(z, self.snap(t))
    }
    /// σ_n(z, t) = (λ+2μ) w_z.
    pub fn sigma_n(&self, z: f64, t: f64) -> f64 {
        self.normal.stress(z, self.snap(t))
    }
    /// u(z, t).
    pub fn u(&self, z: f64, t: f64) -> f64 {
        self.tangential.displacement(z, self.snap(t))
    }
    /// u_t(z, t).
    pub fn u_t(&self, z: f64, t: f64) -> f64 {
        self.tangential.velocity(z, self.snap(t))
    }
    /// σ_t(z, t) = μ u_z.
    pub fn sigma_t(&self, z: f64, t: f64) -> f64 {
        self.tangential.stress(z, self.snap(t))
    }

    /// The base's normal stress σ_n(0, t): −Z_p V_n inside the window, 0 outside and on its
    /// ends (as the flying bar's pressure).
    pub fn base_sigma_n(&self, t: f64) -> f64 {
        if self.in_contact(t) {
            self.normal.stress
        } else {
            0.0
        }
    }
    /// The base's tangential stress σ_t(0, t): σ_t* inside the window, 0 outside.
    pub fn base_sigma_t(&self, t: f64) -> f64 {
        if self.in_contact(t) {
            self.sigma_t_star
        } else {
            0.0
        }
    }
    /// The base's tangential velocity u_t(0, t) (v_slip during the contact).
    pub fn base_u_t(&self, t: f64) -> f64 {
        if self.in_contact(t) {
            self.v_slip()
        } else {
            self.u_t(0.0, t)
        }
    }

    /// W_f(t) = σ_t*·v_slip·|W ∩ [0, t]|.
    pub fn friction_work(&self, t: f64) -> f64 {
        self.sigma_t_star * self.v_slip() * self.contact_time_until(t)
    }
    /// E⁰ = ½ρH(V_n² + V_t²).
    pub fn energy_initial(&self) -> f64 {
        self.p.energy_initial()
    }
    /// E(t) = E⁰ − W_f(t).
    pub fn energy(&self, t: f64) -> f64 {
        self.energy_initial() - self.friction_work(t)
    }
    /// The fields' energy ∫(½ρ(w_t² + u_t²) + σ_n²/(2(λ+2μ)) + σ_t²/(2μ)) dz, integrated
    /// piece by piece between the fronts (independent of [`LayerExact::energy`]: the identity
    /// E = E⁰ − W_f is a test of the solution).
    pub fn field_energy(&self, t: f64) -> f64 {
        let t = self.snap(t);
        self.normal.energy(t, self.p.density) + self.tangential.energy(t, self.p.density)
    }
    /// Mean tangential velocity at t: V_t − σ_t*·|W ∩ [0, t]|/(ρH) (the base's impulse).
    pub fn mean_tangential_velocity(&self, t: f64) -> f64 {
        self.p.velocity_tangential
            - self.sigma_t_star * self.contact_time_until(t) / (self.p.density * self.p.height)
    }
    /// v̄_t⁺ = V_t − 2σ_t*/Z_p, the mean tangential velocity after the impact.
    pub fn mean_tangential_velocity_after(&self) -> f64 {
        self.p.velocity_tangential - 2.0 * self.sigma_t_star / self.p.z_p()
    }

    /// Squared L2 norm and squared H1 seminorm of the 2-vector error (w_h − w, u_h − u)(·, t)
    /// for the P1 fields with nodal values `w` and `u` on the uniform mesh of spacing `h`
    /// (nodes 0 … m): each component integrated exactly, its elements split at its own fronts.
    pub fn error_sq(&self, w: &[f64], u: &[f64], h: f64, t: f64) -> (f64, f64) {
        let t = self.snap(t);
        let m = w.len() - 1;
        let mut fronts = [0.0; 4];
        let k = self.normal.fronts(t, &mut fronts);
        let (l2n, h1n) = super::bar1d::integrate_error(
            m,
            |i| w[i],
            h,
            &fronts[..k],
            |z| self.normal.displacement(z, t),
        );
        let k = self.tangential.fronts(t, &mut fronts);
        let (l2t, h1t) = super::bar1d::integrate_error(
            m,
            |i| u[i],
            h,
            &fronts[..k],
            |z| self.tangential.displacement(z, t),
        );
        (l2n + l2t, h1n + h1t)
    }
}
