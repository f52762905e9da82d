//! The impact oscillator (contract §1.5; Code_Aster V5.01.102/108, Siconos' BouncingBall, Acary
//! 2016): one mass on one spring under a constant force, above a rigid obstacle.
//!
//! m ẍ + k x = f, x ≥ −g, Newton's impact law ẋ(t⁺) = −e_x ẋ(t⁻) at each contact. It is the
//! cheapest problem with an exact solution *event by event*, so it measures how the order of a
//! time scheme degrades at impacts, and it is where a restitution axis makes sense.
//!
//! Exact solution: between impacts the free motion x = x_e + R cos(ω(t − t₀) + φ) about the
//! equilibrium x_e = f/k, ω = √(k/m). The next impact solves x = −g in closed form: the mass
//! reaches the obstacle moving down where cos(θ + φ) = q = (−g − x_e)/R and sin(θ + φ) ≥ 0,
//! so θ = (acos q − φ) mod 2π; the impact speed is ω√(R² − (g + x_e)²) (energy). The rebound
//! −e_x·ẋ(t⁻) starts the next free segment. With f = 0 the flights have a length bounded
//! below (finitely many impacts per unit time). With the net force at the obstacle pushing into
//! it (f + k g < 0) and e_x < 1 the rebound speeds fall geometrically and the flight times with
//! them (Zeno): the flights are summed until the rebound speed falls below 1e-14 of the
//! motion's speed scale (the contract says 1e-14·|v0|; with v0 = 0 the scale is ω·R of the first
//! segment instead), and the mass then rests on the obstacle for good (the force still pushes
//! into it). A rebound that slow with the net force pulling away is a grazing orbit: the mass
//! touches the obstacle at zero speed once per period, which is no impact.
//!
//! The scene has no mesh: `elements` = 1 and h = 1 are reported, and the wave speed is ω, so
//! `courant` reads as the dimensionless step ω·τ.

use super::{
    ErrorSource, MeshChoice, MethodNames, Physics, PhysicsKey, Scene, SceneFacts, SceneSetup,
};
use crate::time::Scheme;

/// The scene `oscillator` (contract §1.5).
#[derive(Debug, Clone, Copy)]
pub struct OscillatorScene;

const OSCILLATOR_PHYSICS: [PhysicsKey; 8] = [
    PhysicsKey {
        name: "point_mass",
        default: 1.0,
    },
    PhysicsKey {
        name: "stiffness",
        default: 1.0,
    },
    PhysicsKey {
        name: "force",
        default: 0.0,
    },
    PhysicsKey {
        name: "gap",
        default: 0.5,
    },
    PhysicsKey {
        name: "amplitude",
        default: 0.0,
    },
    PhysicsKey {
        name: "velocity",
        default: -1.0,
    },
    PhysicsKey {
        name: "impact_law",
        default: 1.0,
    },
    // Dry friction on the mass (contract §1.5): 0 is the frictionless oscillator, and being the
    // default it enters no run id.
    PhysicsKey {
        name: "friction_force",
        default: 0.0,
    },
];

/// The scene's name, its physics keys and its default final time.
const FACTS: SceneFacts = SceneFacts {
    name: "oscillator",
    physics: &OSCILLATOR_PHYSICS,
    default_t: 10.0,
};

impl OscillatorScene {
    fn params(p: &Physics) -> OscillatorParams {
        OscillatorParams {
            mass: p.get("point_mass"),
            stiffness: p.get("stiffness"),
            force: p.get("force"),
            gap: p.get("gap"),
            x0: p.get("amplitude"),
            v0: p.get("velocity"),
            impact_law: p.get("impact_law"),
            friction: p.get("friction_force"),
        }
    }
}

const NO_MESH: &str = "scene oscillator has no mesh (one mass, one spring): leave h and elements out; give dt, or courant = ω·dt";

impl Scene for OscillatorScene {
    fn facts(&self) -> SceneFacts {
        FACTS
    }
    fn mesh_from_h(&self, _physics: &Physics, _h: f64) -> Result<MeshChoice, String> {
        Err(NO_MESH.into())
    }
    fn mesh_from_elements(&self, _physics: &Physics, _e: usize) -> Result<MeshChoice, String> {
        Err(NO_MESH.into())
    }
    fn default_mesh(&self) -> Option<MeshChoice> {
        Some(MeshChoice {
            elements: 1,
            h: 1.0,
        })
    }
    /// ω = √(k/m): `courant` is ω·dt (the oscillator has no mesh to take a length from).
    fn wave_speed(&self, physics: &Physics) -> f64 {
        Self::params(physics).omega()
    }
    /// The mass meets the obstacle along its one dof: a friction law at the contact has no
    /// direction to act in. Dry friction on the mass is contract §1.5's physics key
    /// `friction_force`, not the friction axis.
    fn supports_friction(&self) -> Result<(), String> {
        Err("the oscillator's one dof is normal to the obstacle: dry friction on the mass is contract §1.5's `friction_force` key, not a friction law at the contact".into())
    }

    /// Dry friction enters a step as a relay on the step's slip (contract §1.5): the increment
    /// (x^{n+1} − xⁿ)/τ of an implicit position-level step, Moreau–Jean's v^{n+1}. An explicit
    /// step's increment does not depend on the step's own force, so the relay has nothing to
    /// solve; and the schemes contract §2.5 gives no frictional version (Paoli–Schatzman's two-step
    /// contact argument, the hybrid and discrete-gradient energy splittings) are not invented
    /// here.
    fn supports_physics(
        &self,
        physics: &Physics,
        scheme: &Scheme,
    ) -> Result<(), (&'static str, String)> {
        if physics.get("friction_force") == 0.0 {
            return Ok(());
        }
        let why = match scheme {
            Scheme::PaoliSchatzman(_) => {
                "paoli-schatzman has no frictional version in the literature (contract §2.5)"
            }
            Scheme::Hybrid => {
                "the hybrid scheme has no frictional version in the literature (contract §2.5)"
            }
            Scheme::DiscreteGradient => {
                "discrete-gradient has no frictional version in the literature (contract §2.5)"
            }
            s if s.is_explicit() => {
                "an explicit step's increment does not depend on the step's friction force: the relay on (x^{n+1} − xⁿ)/τ is undetermined"
            }
            _ => return Ok(()),
        };
        Err((
            "friction_force",
            format!(
                "friction_force > 0 with scheme = {}: {why}; dry friction runs with the newmark and theta families, kane, contact-stabilized-newmark, generalized-alpha, hht and moreau-jean",
                scheme.family()
            ),
        ))
    }

    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        let MethodNames {
            space,
            mass,
            scheme,
        } = m;
        super::require("space", space, &["mixed", "penalty"], || {
            format!(
                "space = {space} does not apply to the oscillator (contract §1.5: a multiplier on the one dof, `mixed`, or `penalty`)"
            )
        })?;
        super::require("mass", mass, &["consistent", "lumped"], || {
            format!(
                "mass = {mass} does not apply to the oscillator: its one dof is the mass (contract §1.5: mass variants do not apply)"
            )
        })?;
        // The families the oscillator's engine implements (`run::oscillator`); a new family
        // is refused here, with its reason, until its arm is written there.
        if !matches!(
            scheme,
            "newmark"
                | "theta"
                | "paoli-schatzman"
                | "hybrid"
                | "kane"
                | "contact-stabilized-newmark"
                | "generalized-alpha"
                | "hht"
                | "moreau-jean"
                | "discrete-gradient"
        ) {
            return Err((
                "scheme",
                format!("scheme = {scheme} is not implemented for the oscillator yet"),
            ));
        }
        // contract §3.2: kane, contact-stabilized Newmark and Moreau–Jean are multiplier (impulse)
        // methods, `mixed` only; the discrete gradient is the penalty potential's.
        if matches!(
            scheme,
            "kane" | "contact-stabilized-newmark" | "moreau-jean"
        ) && space != "mixed"
        {
            return Err((
                "scheme",
                format!("scheme = {scheme} applies to space = mixed only (contract §3.2)"),
            ));
        }
        if scheme == "discrete-gradient" && space != "penalty" {
            return Err((
                "scheme",
                "scheme = discrete-gradient applies to the oscillator with space = penalty only (contract §3.2)".into(),
            ));
        }
        if scheme == "hybrid" && space != "penalty" {
            return Err((
                "scheme",
                "scheme = hybrid applies to the oscillator with space = penalty only (with `mixed` it needs a massless contact node, 000 §5)".into(),
            ));
        }
        Ok(())
    }
    fn error_source(&self, _physics: &Physics) -> Option<ErrorSource> {
        Some(ErrorSource::Exact)
    }
    fn setup(&self, physics: &Physics, _mesh: MeshChoice) -> SceneSetup {
        SceneSetup::Oscillator(Self::params(physics))
    }
}

/// Physical parameters of the oscillator (contract §1.5 defaults: m = k = 1, f = 0, g = ½,
/// x0 = 0, v0 = −1, e_x = 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OscillatorParams {
    pub mass: f64,
    pub stiffness: f64,
    pub force: f64,
    pub gap: f64,
    pub x0: f64,
    pub v0: f64,
    /// Newton's restitution coefficient e_x of the exact solution.
    pub impact_law: f64,
    /// Dry (Coulomb) friction force F ≥ 0 on the mass (`friction_force`; 0: frictionless).
    pub friction: f64,
}

impl Default for OscillatorParams {
    fn default() -> Self {
        Self {
            mass: 1.0,
            stiffness: 1.0,
            force: 0.0,
            gap: 0.5,
            x0: 0.0,
            v0: -1.0,
            impact_law: 1.0,
            friction: 0.0,
        }
    }
}

impl OscillatorParams {
    /// ω = √(k/m).
    pub fn omega(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// Equilibrium x_e = f/k of the free spring.
    pub fn equilibrium(&self) -> f64 {
        self.force / self.stiffness
    }

    /// Mechanical energy ½mv² + ½kx² − fx (the load's potential zero at x = 0).
    pub fn energy(&self, x: f64, v: f64) -> f64 {
        0.5 * self.mass * v * v + 0.5 * self.stiffness * x * x - self.force * x
    }

    /// The exact solution over [0, t_final].
    pub fn exact(&self, t_final: f64) -> OscillatorExact {
        OscillatorExact::new(*self, t_final)
    }
}

/// The oscillator with dry (Coulomb) friction on the mass (contract §1.5, Siconos'
/// FrictionOscillator): m ẍ + k x = f − F·sign(ẋ) while it moves, at rest where |k x − f| ≤ F.
///
/// Exact, piece by piece: while the mass moves in the direction s = ±1 the friction is the
/// constant −sF, so the motion is a free oscillation about the shifted centre c = (f − sF)/k,
/// x = c + R cos(ω(t − t₀) + φ). It runs until the velocity vanishes — a turning point
/// x_j = c + sR, whence x_{j+1} = 2f/k + 2(F/k)·sign(x_j − f/k) − x_j — or, moving down, until
/// it meets the obstacle x = −g (the impact angle in closed form as for the frictionless
/// oscillator, about c instead of f/k), where Newton's law reverses the velocity. At a turning
/// point the mass stays for good if the spring and the load cannot overcome the friction,
/// |k x_j − f| ≤ F: that instant is `stop_time_exact`. The whole history is a handful of
/// segments (the amplitude drops by 2F/k per half period), built once.
#[derive(Debug, Clone, PartialEq)]
pub struct DryFrictionExact {
    p: OscillatorParams,
    friction: f64,
    /// (t₀, x₀, v₀, centre; at rest).
    segments: Vec<(f64, f64, f64, f64, bool)>,
    turning_points: Vec<(f64, f64)>,
    impacts: Vec<f64>,
    stop: Option<(f64, f64)>,
}

impl DryFrictionExact {
    /// The exact motion over [0, t_final] with the friction force `friction` = F ≥ 0.
    pub fn new(p: OscillatorParams, friction: f64, t_final: f64) -> Self {
        let (w, k, f, g) = (p.omega(), p.stiffness, p.force, p.gap);
        let tau2 = std::f64::consts::TAU;
        let v_scale =
            p.v0.abs()
                .max(w * (p.x0 - f / k).abs())
                .max(f64::MIN_POSITIVE);
        let slow = 1e-14 * v_scale;
        // Sized once for the usual history — a half oscillation per π/ω, plus room for a
        // Zeno sequence (rebound speeds falling by e_x to 1e-14 of the first: 47 impacts at
        // e_x = ½) — so that the set-up's allocations do not grow with T (a longer sequence,
        // e_x near 1, may still outgrow it: correct, only less tidy).
        let cap = (2.0 * w * t_final.max(0.0) / std::f64::consts::PI).min(1e5) as usize + 128;
        let mut out = Self {
            p,
            friction,
            segments: Vec::with_capacity(cap),
            turning_points: Vec::with_capacity(cap),
            impacts: Vec::with_capacity(cap),
            stop: None,
        };
        let (mut t0, mut x0, mut v0) = (0.0, p.x0, p.v0);
        // Each pass is one half oscillation or one flight to the obstacle; the amplitude about
        // f/k drops by 2F/k per half period, so the loop ends (the cap guards F = 0).
        for _ in 0..1_000_000 {
            let s = if v0 != 0.0 {
                v0.signum()
            } else {
                let net = f - k * x0;
                // On the obstacle the obstacle holds a mass pushed into it.
                if net.abs() <= friction || (x0 <= -g && net < 0.0) {
                    out.segments.push((t0, x0, 0.0, x0, true));
                    out.stop = Some((t0, x0));
                    break;
                }
                net.signum()
            };
            let c = (f - s * friction) / k;
            out.segments.push((t0, x0, v0, c, false));
            let dx = x0 - c;
            let r = (dx * dx + (v0 / w).powi(2)).sqrt();
            let phi = (-v0 / w).atan2(dx);
            let turn = if s > 0.0 {
                -phi
            } else {
                std::f64::consts::PI - phi
            };
            let mut theta = turn.rem_euclid(tau2);
            if theta == 0.0 {
                theta = tau2;
            }
            if s < 0.0 && c - r < -g {
                // The flight meets the obstacle before its turning point.
                let speed = (v0 * v0 + w * w * (x0 + g) * (x0 - g - 2.0 * c))
                    .max(0.0)
                    .sqrt();
                let alpha = (speed / w).atan2(-g - c);
                let t_hit = t0 + (alpha - phi).rem_euclid(tau2) / w;
                if t_hit > t_final {
                    break;
                }
                let rebound = p.impact_law * speed;
                if speed > slow {
                    out.impacts.push(t_hit);
                }
                (t0, x0, v0) = (t_hit, -g, if rebound > slow { rebound } else { 0.0 });
                continue;
            }
            let t_turn = t0 + theta / w;
            if t_turn > t_final {
                break;
            }
            let x_turn = c + s * r;
            out.turning_points.push((t_turn, x_turn));
            (t0, x0, v0) = (t_turn, x_turn, 0.0);
        }
        out
    }

    /// The friction force F.
    pub fn friction(&self) -> f64 {
        self.friction
    }
    /// The turning points (t_j, x_j) in [0, T], in order.
    pub fn turning_points(&self) -> &[(f64, f64)] {
        &self.turning_points
    }
    /// The impact times in [0, T].
    pub fn impacts(&self) -> &[f64] {
        &self.impacts
    }
    /// Where and when the mass comes to rest for good (`stop_time_exact`), if before T.
    pub fn stop(&self) -> Option<(f64, f64)> {
        self.stop
    }

    /// (x, v) at t.
    pub fn state(&self, t: f64) -> (f64, f64) {
        let k = self
            .segments
            .partition_point(|s| s.0 <= t)
            .saturating_sub(1);
        let (t0, x0, v0, c, rest) = self.segments[k];
        if rest {
            return (x0, 0.0);
        }
        let w = self.p.omega();
        let (sin, cos) = (w * (t - t0)).sin_cos();
        (
            c + (x0 - c) * cos + v0 / w * sin,
            -(x0 - c) * w * sin + v0 * cos,
        )
    }

    /// Mechanical energy ½mv² + ½kx² − fx at t: it falls by F·|x_{j+1} − x_j| from one
    /// turning point to the next (the friction's work), the identity a test checks.
    pub fn energy(&self, t: f64) -> f64 {
        let (x, v) = self.state(t);
        self.p.energy(x, v)
    }
}

/// One piece of the exact motion: free flight from (x0, v0) at t0, or rest on the obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    t0: f64,
    x0: f64,
    v0: f64,
    rest: bool,
}

/// The exact solution, event by event: its free segments, its impact times, and where the
/// mass comes to rest.
#[derive(Debug, Clone, PartialEq)]
pub struct OscillatorExact {
    p: OscillatorParams,
    segments: Vec<Segment>,
    impacts: Vec<f64>,
}

impl OscillatorExact {
    fn new(p: OscillatorParams, t_final: f64) -> Self {
        let w = p.omega();
        let xe = p.equilibrium();
        let g = p.gap;
        let mut seg = Segment {
            t0: 0.0,
            x0: p.x0,
            v0: p.v0,
            rest: false,
        };
        let radius0 = ((p.x0 - xe).powi(2) + (p.v0 / w).powi(2)).sqrt();
        let v_scale = if p.v0 != 0.0 { p.v0.abs() } else { w * radius0 };
        let slow = 1e-14 * v_scale;
        // Net force on the mass resting at the obstacle: f − k(−g).
        let pushes_in = p.force + p.stiffness * g < 0.0;
        let mut segments = vec![seg];
        let mut impacts = Vec::new();
        loop {
            let dx = seg.x0 - xe;
            let r = (dx * dx + (seg.v0 / w).powi(2)).sqrt();
            // The orbit's lowest point x_e − R must reach −g.
            if r == 0.0 || xe - r > -g {
                break;
            }
            // Impact speed from the energy of the free motion, v² = v0² + ω²(dx² − d²) with
            // d = −g − x_e, factored as (dx − d)(dx + d) = (x0 + g)(x0 − g − 2x_e): no
            // cancellation when the segment starts on the obstacle (then it is |v0| exactly).
            let speed = (seg.v0 * seg.v0 + w * w * (seg.x0 + g) * (seg.x0 - g - 2.0 * xe))
                .max(0.0)
                .sqrt();
            // acos((−g − x_e)/R) as an angle from its sine and cosine: accurate near 0, where
            // Zeno's short flights live (acos loses half the digits there).
            let alpha = (speed / w).atan2(-g - xe);
            let phi = (-seg.v0 / w).atan2(dx);
            let theta = (alpha - phi).rem_euclid(std::f64::consts::TAU);
            let t_hit = seg.t0 + theta / w;
            if t_hit > t_final {
                break;
            }
            let rebound = p.impact_law * speed;
            if speed > slow {
                impacts.push(t_hit);
            }
            if rebound <= slow {
                if pushes_in {
                    seg = Segment {
                        t0: t_hit,
                        x0: -g,
                        v0: 0.0,
                        rest: true,
                    };
                } else {
                    // A grazing orbit (or at rest on the obstacle with no net force): free
                    // motion from the obstacle at zero speed, touching it without impact.
                    seg = Segment {
                        t0: t_hit,
                        x0: -g,
                        v0: 0.0,
                        rest: false,
                    };
                }
                segments.push(seg);
                break;
            }
            seg = Segment {
                t0: t_hit,
                x0: -g,
                v0: rebound,
                rest: false,
            };
            segments.push(seg);
        }
        Self {
            p,
            segments,
            impacts,
        }
    }

    /// The impact times in [0, T], in order.
    pub fn impacts(&self) -> &[f64] {
        &self.impacts
    }

    /// When the mass comes to rest on the obstacle for good (Zeno's accumulation point), if it
    /// does before T.
    pub fn rest_time(&self) -> Option<f64> {
        self.segments.iter().find(|s| s.rest).map(|s| s.t0)
    }

    /// (x, v) at t; `cursor` remembers the segment of the previous call (times increasing:
    /// O(1) per call), start it at 0. At an impact time the state after the impact.
    pub fn state(&self, t: f64, cursor: &mut usize) -> (f64, f64) {
        if *cursor >= self.segments.len() || self.segments[*cursor].t0 > t {
            *cursor = 0;
        }
        while *cursor + 1 < self.segments.len() && self.segments[*cursor + 1].t0 <= t {
            *cursor += 1;
        }
        let s = self.segments[*cursor];
        if s.rest {
            return (s.x0, 0.0);
        }
        let w = self.p.omega();
        let xe = self.p.equilibrium();
        let (sin, cos) = (w * (t - s.t0)).sin_cos();
        (
            xe + (s.x0 - xe) * cos + s.v0 / w * sin,
            -(s.x0 - xe) * w * sin + s.v0 * cos,
        )
    }

    /// The exact energy at t (constant between impacts; each impact multiplies the kinetic
    /// energy by e_x²).
    pub fn energy(&self, t: f64, cursor: &mut usize) -> f64 {
        let (x, v) = self.state(t, cursor);
        self.p.energy(x, v)
    }
}
