//! Friction laws as data (contract §2.5) and the exact local solve of one contact point.
//!
//! A contact point carries a normal force f_n ≥ 0 (on the body, away from the obstacle) and a
//! tangential force f_t with |f_t| ≤ b, f_t = −b·ṡ/|ṡ| where the slip ṡ ≠ 0 (stick: ṡ = 0). The
//! bound is the law's: b = μ_f f_n (Coulomb), b = s·w (Tresca, w the point's weight — the unit
//! cross-section in 1D — and only while in contact), b = 0 (none).
//!
//! What "slip" means is the scheme's, not the law's: the increment (u_t^{n+1} − u_t^n)/τ for
//! the position-level schemes, the velocity v_t^{n+1} for Moreau–Jean, the predicted velocity
//! for the relay of a dry-friction oscillator. Whatever it is, once the step is condensed onto
//! the contact point it is affine in the two forces:
//!
//!   gap  = gap_free  + w_nn f_n + w_nt f_t      (≥ 0, ⊥ f_n ≥ 0),
//!   slip = slip_free + w_tn f_n + w_tt f_t,
//!
//! with w_nn, w_tt > 0 (pushing the body away opens the gap, pulling it along moves it along).
//! This is the 1D local problem of contract §2.5/§4, and it is solved *exactly* by case analysis,
//! as the frictionless scalar problem is solved by branch enumeration ([`super::solve`]):
//!
//! - open (take-off): f_n = f_t = 0, admissible iff gap_free ≥ 0;
//! - stick: gap = 0 and slip = 0 — a 2×2 linear system — admissible iff f_n ≥ 0, |f_t| ≤ b(f_n);
//! - slip forward / backward (σ = ±1): gap = 0 and f_t = −σ b(f_n) — one linear equation in f_n
//!   — admissible iff f_n ≥ 0 and σ·slip ≥ 0.
//!
//! Written on velocities with e = 0 these are exactly De Saxcé's take-off / stick / slide cases
//! of the bipotential (û = (u_n + μ|u_t|, u_t) ⊥ r in the cone): Moreau–Jean calls the same
//! function. Where the normal and tangential rows decouple (w_nt = w_tn = 0: the layer's two
//! chains, a mass on a flat obstacle) exactly one case holds; with coupling and a large μ_f
//! Coulomb's problem may have several solutions (Klarbring's non-uniqueness), which is
//! reported as an error, never resolved silently.
//!
//! No allocation: the cases are four, evaluated in registers; steppers call this once per
//! contact point and step.

/// The friction law's name (`friction` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrictionKind {
    None,
    Tresca,
    Coulomb,
}

impl FrictionKind {
    pub const NAMES: [&'static str; 3] = ["none", "tresca", "coulomb"];

    pub fn from_name(name: &str) -> Option<FrictionKind> {
        match name {
            "none" => Some(FrictionKind::None),
            "tresca" => Some(FrictionKind::Tresca),
            "coulomb" => Some(FrictionKind::Coulomb),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            FrictionKind::None => "none",
            FrictionKind::Tresca => "tresca",
            FrictionKind::Coulomb => "coulomb",
        }
    }
}

/// A friction law with its parameter (contract §2.5).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FrictionLaw {
    /// Frictionless: f_t = 0 (today's engine).
    #[default]
    None,
    /// |f_t| ≤ s·w while in contact (s a traction, w the point's weight).
    Tresca { threshold: f64 },
    /// |f_t| ≤ μ_f f_n.
    Coulomb { coefficient: f64 },
}

impl FrictionLaw {
    pub fn kind(&self) -> FrictionKind {
        match self {
            FrictionLaw::None => FrictionKind::None,
            FrictionLaw::Tresca { .. } => FrictionKind::Tresca,
            FrictionLaw::Coulomb { .. } => FrictionKind::Coulomb,
        }
    }

    /// Whether the law ever produces a tangential force.
    pub fn is_none(&self) -> bool {
        matches!(self, FrictionLaw::None)
    }

    /// The bound b on |f_t| of a point in contact with normal force `f_n` and weight `weight`.
    pub fn bound(&self, f_n: f64, weight: f64) -> f64 {
        match *self {
            FrictionLaw::None => 0.0,
            FrictionLaw::Tresca { threshold } => threshold * weight,
            FrictionLaw::Coulomb { coefficient } => coefficient * f_n,
        }
    }

    /// b(f_n) = slope·f_n + offset (affine in the normal force for every law).
    fn bound_affine(&self, weight: f64) -> (f64, f64) {
        match *self {
            FrictionLaw::None => (0.0, 0.0),
            FrictionLaw::Tresca { threshold } => (0.0, threshold * weight),
            FrictionLaw::Coulomb { coefficient } => (coefficient, 0.0),
        }
    }
}

/// The condensed relations of one contact point (module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Condensed {
    pub gap_free: f64,
    pub slip_free: f64,
    pub w_nn: f64,
    pub w_nt: f64,
    pub w_tn: f64,
    pub w_tt: f64,
}

impl Condensed {
    /// Decoupled rows (w_nt = w_tn = 0).
    pub fn decoupled(gap_free: f64, w_nn: f64, slip_free: f64, w_tt: f64) -> Condensed {
        Condensed {
            gap_free,
            slip_free,
            w_nn,
            w_nt: 0.0,
            w_tn: 0.0,
            w_tt,
        }
    }
}

/// Which case of the local problem holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointState {
    /// No contact (take-off): no force.
    Open,
    /// In contact, no slip.
    Stick,
    /// In contact, slipping forward (slip > 0, f_t = −b).
    SlipForward,
    /// In contact, slipping backward (slip < 0, f_t = +b).
    SlipBackward,
}

impl PointState {
    pub fn in_contact(self) -> bool {
        self != PointState::Open
    }
}

/// The solution of one point's local problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointSolution {
    pub f_n: f64,
    pub f_t: f64,
    pub gap: f64,
    pub slip: f64,
    pub state: PointState,
}

/// Why a point's local problem has no unique solution.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FrictionSolveError {
    #[error(
        "the condensed contact operator of a frictional point is not positive (w_nn = {w_nn:.3e}, w_tt = {w_tt:.3e}); the forces are undetermined"
    )]
    NonPositive { w_nn: f64, w_tt: f64 },
    #[error(
        "the frictional contact problem of a point has no solution (coupled rows, w_nt = {w_nt:.3e}, w_tn = {w_tn:.3e})"
    )]
    NoSolution { w_nt: f64, w_tn: f64 },
    #[error(
        "the frictional contact problem of a point has several solutions (Coulomb with coupled rows, w_nt = {w_nt:.3e}, w_tn = {w_tn:.3e}: Klarbring's non-uniqueness)"
    )]
    Multiple { w_nt: f64, w_tn: f64 },
}

/// The tangential problem with a given bound b ≥ 0: slip = slip_free + w f_t, |f_t| ≤ b,
/// f_t = −b·sign(slip) where slip ≠ 0. The projection f_t = proj_[−b, b](−slip_free/w),
/// written by its three cases so that the stick case returns slip = 0 exactly.
pub fn solve_tangential(slip_free: f64, w: f64, b: f64) -> (f64, f64, PointState) {
    let stick = -slip_free / w;
    if stick.abs() <= b {
        (stick, 0.0, PointState::Stick)
    } else if slip_free > 0.0 {
        (-b, slip_free - w * b, PointState::SlipForward)
    } else {
        (b, slip_free + w * b, PointState::SlipBackward)
    }
}

/// The penalised tangential problem (contract §2.5, `penalty`): slip = slip_free + w f_t with
/// f_t = proj_[−b, b](−κ·slip) — an elastic spring of stiffness κ on the slip, capped at the
/// bound. Monotone in f_t, so exactly one of its two branches holds: the spring branch
/// f_t = −κ slip_free/(1 + κw) when it lies within the bound (reported as stick), the capped
/// branch f_t = −b·sign(slip_free) otherwise.
pub fn solve_tangential_penalized(
    slip_free: f64,
    w: f64,
    kappa: f64,
    b: f64,
) -> (f64, f64, PointState) {
    let spring = -kappa * slip_free / (1.0 + kappa * w);
    if spring.abs() <= b {
        (spring, slip_free + w * spring, PointState::Stick)
    } else if slip_free > 0.0 {
        (-b, slip_free - w * b, PointState::SlipForward)
    } else {
        (b, slip_free + w * b, PointState::SlipBackward)
    }
}

/// Solve one contact point's frictional problem exactly (module header). `weight` is the
/// point's weight for Tresca's bound.
pub fn solve_point(
    law: &FrictionLaw,
    weight: f64,
    c: &Condensed,
) -> Result<PointSolution, FrictionSolveError> {
    if !(c.w_nn > 0.0 && c.w_tt > 0.0) {
        return Err(FrictionSolveError::NonPositive {
            w_nn: c.w_nn,
            w_tt: c.w_tt,
        });
    }
    // Open: no force at all (Tresca acts only while in contact).
    if c.gap_free >= 0.0 {
        return Ok(PointSolution {
            f_n: 0.0,
            f_t: 0.0,
            gap: c.gap_free,
            slip: c.slip_free,
            state: PointState::Open,
        });
    }
    let (slope, offset) = law.bound_affine(weight);
    if c.w_nt == 0.0 && c.w_tn == 0.0 {
        // Decoupled: the normal force is Signorini's alone, then the tangential projection.
        let f_n = -c.gap_free / c.w_nn;
        let b = slope * f_n + offset;
        let (f_t, slip, state) = solve_tangential(c.slip_free, c.w_tt, b);
        return Ok(PointSolution {
            f_n,
            f_t,
            gap: 0.0,
            slip,
            state,
        });
    }
    // Coupled rows: every closed case, keep the admissible ones.
    let scale_f = (c.gap_free.abs() / c.w_nn).max(c.slip_free.abs() / c.w_tt);
    let tol_f = 1e-13 * scale_f.max(f64::MIN_POSITIVE);
    let tol_s = 1e-13 * c.slip_free.abs().max(c.w_tt * scale_f);
    let mut found: Option<PointSolution> = None;
    let mut consider = |sol: PointSolution| -> Result<(), FrictionSolveError> {
        match found {
            None => found = Some(sol),
            Some(prev)
                if (prev.f_n - sol.f_n).abs() <= tol_f && (prev.f_t - sol.f_t).abs() <= tol_f => {}
            Some(_) => {
                return Err(FrictionSolveError::Multiple {
                    w_nt: c.w_nt,
                    w_tn: c.w_tn,
                });
            }
        }
        Ok(())
    };
    // Stick: [w_nn w_nt; w_tn w_tt] f = −[gap_free; slip_free].
    let det = c.w_nn * c.w_tt - c.w_nt * c.w_tn;
    if det != 0.0 {
        let f_n = (-c.gap_free * c.w_tt + c.slip_free * c.w_nt) / det;
        let f_t = (-c.slip_free * c.w_nn + c.gap_free * c.w_tn) / det;
        if f_n >= -tol_f && f_t.abs() <= slope * f_n + offset + tol_f {
            consider(PointSolution {
                f_n: f_n.max(0.0),
                f_t,
                gap: 0.0,
                slip: 0.0,
                state: PointState::Stick,
            })?;
        }
    }
    // Slip σ = ±1: f_t = −σ(slope f_n + offset), gap = 0.
    for (sigma, state) in [
        (1.0, PointState::SlipForward),
        (-1.0, PointState::SlipBackward),
    ] {
        let a = c.w_nn - sigma * slope * c.w_nt;
        let rhs = -c.gap_free + sigma * offset * c.w_nt;
        if a == 0.0 {
            continue;
        }
        let f_n = rhs / a;
        let f_t = -sigma * (slope * f_n + offset);
        let slip = c.slip_free + c.w_tn * f_n + c.w_tt * f_t;
        if f_n >= -tol_f && sigma * slip > tol_s {
            consider(PointSolution {
                f_n: f_n.max(0.0),
                f_t,
                gap: 0.0,
                slip,
                state,
            })?;
        }
    }
    found.ok_or(FrictionSolveError::NoSolution {
        w_nt: c.w_nt,
        w_tn: c.w_tn,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const COULOMB: FrictionLaw = FrictionLaw::Coulomb { coefficient: 0.3 };

    // Every case below has a hand-computed answer made of a few exact binary fractions or one
    // rounding: 1e-15 is a few ulps.
    #[test]
    fn the_three_cases_of_a_decoupled_point() {
        // gap_free = −0.5, w_nn = 2: f_n = 0.25, b = 0.075.
        let stick = solve_point(&COULOMB, 1.0, &Condensed::decoupled(-0.5, 2.0, 0.1, 4.0)).unwrap();
        assert_eq!(stick.state, PointState::Stick);
        assert_eq!((stick.slip, stick.gap), (0.0, 0.0));
        assert!((stick.f_t + 0.025).abs() < 1e-15 && (stick.f_n - 0.25).abs() < 1e-15);
        let fwd = solve_point(&COULOMB, 1.0, &Condensed::decoupled(-0.5, 2.0, 1.0, 4.0)).unwrap();
        assert_eq!(fwd.state, PointState::SlipForward);
        assert!((fwd.f_t + 0.075).abs() < 1e-15);
        assert!((fwd.slip - 0.7).abs() < 1e-15);
        let back = solve_point(&COULOMB, 1.0, &Condensed::decoupled(-0.5, 2.0, -1.0, 4.0)).unwrap();
        assert_eq!(back.state, PointState::SlipBackward);
        assert!((back.f_t - 0.075).abs() < 1e-15);
        assert!((back.slip + 0.7).abs() < 1e-15);
        // Open: no force whatever the slip, Tresca included (it acts only in contact).
        let tresca = FrictionLaw::Tresca { threshold: 2.0 };
        let open = solve_point(&tresca, 1.0, &Condensed::decoupled(0.1, 2.0, 1.0, 4.0)).unwrap();
        assert_eq!(
            (open.f_n, open.f_t, open.state),
            (0.0, 0.0, PointState::Open)
        );
        // Tresca's bound ignores f_n: s·w = 2·0.5 = 1 holds slip_free/w_tt = 0.25 in stick.
        let t = solve_point(&tresca, 0.5, &Condensed::decoupled(-1e-3, 2.0, 1.0, 4.0)).unwrap();
        assert_eq!(t.state, PointState::Stick);
        assert_eq!(t.f_t, -0.25);
    }

    /// The penalised law: the spring branch inside the bound (its slip and force satisfy
    /// f_t = −κ·slip), the cap outside. Values are ratios of small integers: 1e-15.
    #[test]
    fn the_penalised_law_caps_a_spring() {
        // slip_free = 1, w = 1, κ = 3: spring f_t = −3/4, slip = 1/4.
        let (f, s, st) = solve_tangential_penalized(1.0, 1.0, 3.0, 1.0);
        assert_eq!(st, PointState::Stick);
        assert!((f + 0.75).abs() < 1e-15 && (s - 0.25).abs() < 1e-15);
        assert!((f + 3.0 * s).abs() < 1e-15);
        let (f, s, st) = solve_tangential_penalized(-1.0, 1.0, 3.0, 0.5);
        assert_eq!(st, PointState::SlipBackward);
        assert_eq!((f, s), (0.5, -0.5));
        // A zero bound: no force, the free slip.
        assert_eq!(solve_tangential_penalized(0.7, 2.0, 5.0, 0.0).1, 0.7);
    }

    #[test]
    fn a_zero_bound_is_frictionless_bit_for_bit() {
        for law in [
            FrictionLaw::None,
            FrictionLaw::Coulomb { coefficient: 0.0 },
            FrictionLaw::Tresca { threshold: 0.0 },
        ] {
            let s = solve_point(&law, 1.0, &Condensed::decoupled(-0.3, 3.0, 0.7, 5.0)).unwrap();
            assert_eq!(s.f_t, 0.0);
            assert_eq!(s.slip, 0.7);
            assert_eq!(s.f_n, 0.3 / 3.0);
        }
    }

    /// The coupled case reduces to the decoupled one when the coupling vanishes, and each
    /// solution it returns satisfies the law (checked by substitution).
    #[test]
    fn coupled_points_satisfy_the_law() {
        let mut seed = 0x2545f4914f6cdd1du64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut solved = 0;
        for _ in 0..2000 {
            let c = Condensed {
                gap_free: rnd() * 2.0 - 1.5,
                slip_free: rnd() * 2.0 - 1.0,
                w_nn: 0.5 + rnd(),
                w_nt: (rnd() - 0.5) * 0.2,
                w_tn: (rnd() - 0.5) * 0.2,
                w_tt: 0.5 + rnd(),
            };
            let law = FrictionLaw::Coulomb { coefficient: rnd() };
            let Ok(s) = solve_point(&law, 1.0, &c) else {
                continue;
            };
            solved += 1;
            let gap = c.gap_free + c.w_nn * s.f_n + c.w_nt * s.f_t;
            let slip = c.slip_free + c.w_tn * s.f_n + c.w_tt * s.f_t;
            let b = law.bound(s.f_n, 1.0);
            assert!(gap >= -1e-12 && s.f_n >= 0.0 && (gap * s.f_n).abs() < 1e-12);
            assert!((slip - s.slip).abs() < 1e-12, "{c:?} {s:?}");
            assert!(s.f_t.abs() <= b + 1e-12);
            if slip.abs() > 1e-12 {
                assert!((s.f_t + b * slip.signum()).abs() < 1e-12, "{c:?} {s:?}");
            }
        }
        // With |w_nt| μ_f ≤ 0.1 < w_nn every draw is well posed (the slip equations are
        // monotone): all 2000 solve.
        assert_eq!(solved, 2000);
    }
}
