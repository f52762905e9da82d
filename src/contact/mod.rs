//! The condensed contact solve (contract §4).
//!
//! Every implicit step has the form A x = b + φ q̃ with A constant (factored once per run) and
//! the nonlinearity acting through one scalar s = pᵀx + p₀. With z = A⁻¹q̃ precomputed and
//! y = A⁻¹b, x = y + φ z and the step reduces to the scalar equation
//!
//!   s = s_free + w φ(s),   s_free = pᵀy + p₀,  w = pᵀz,
//!
//! where φ is either a piecewise-linear function of s (Nitsche, penalty, the hybrid switches) or
//! the Signorini complementarity graph (mixed). Both are solved *exactly* by enumerating the
//! linear branches — no Newton iteration, no tolerance. The count of solutions is itself the
//! well-posedness condition of 003 §2.2.3: none or several (a branch on which 1 − w·slope ≤ 0)
//! is reported, never silently resolved.
//!
//! The finite-element scenes condense onto several contact dofs: [`lcp`] solves the resulting
//! small dense complementarity problem exactly by an active-set method. The discrete-gradient
//! scheme's contact force is a difference quotient, not a piecewise-linear law: [`gradient`]
//! solves its scalar equation by a safeguarded semismooth Newton iteration.
//!
//! Friction (contract §2.5) is a law of its own, [`friction`]: the law as data (none, Tresca,
//! Coulomb) and the exact case analysis of one point's normal and tangential rows, which every
//! stepper calls with its condensed rows — the same local solve for every scheme. Several
//! coupled frictional nodes (the FE scenes' Γ_C) are [`coulomb`]'s: semismooth Newton on the
//! Alart–Curnier functions over the condensed normal and tangential rows.

pub mod coulomb;
pub mod friction;
pub mod gradient;
pub mod lcp;
pub mod lemke;

pub use coulomb::{FrictionalContact, FrictionalContactError};
pub use lcp::{Lcp, LcpError};

/// A contact law φ(s) on the scalar contact argument.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactLaw {
    /// Signorini complementarity: s ≥ 0, φ ≤ 0, s φ = 0 (φ is the multiplier).
    Complementarity,
    /// φ(s) = k [s]₊ (Nitsche: k = −1/γ_h; penalty: k = −κ).
    PositivePart { k: f64 },
    /// The hybrid switch of 003 (11): φ(s) = k Φ(s_prev, s) with
    /// Φ = H(s_prev)[(s_prev + s)/2]₊ + H(−s_prev)([s_prev]₊ + [s]₊)/2, H(0) = ½.
    HybridNitsche { k: f64, s_prev: f64 },
    /// The switch of 000 §5 on the reduced system, with s = u₁ + g:
    /// φ(s) = k Ψ(s_prev, s) + offset, Ψ = H(−s_prev)[(s_prev + s)/2]₊ + H(s_prev)([s_prev]₊ + [s]₊)/2.
    HybridReduced { k: f64, s_prev: f64, offset: f64 },
}

/// One linear piece: φ(s) = slope·s + intercept on [lo, hi].
#[derive(Debug, Clone, Copy)]
struct Piece {
    lo: f64,
    hi: f64,
    slope: f64,
    intercept: f64,
}

const INF: f64 = f64::INFINITY;

impl ContactLaw {
    /// The law's linear pieces (at most two), without allocation.
    fn pieces(&self) -> ([Piece; 2], usize) {
        let pc = |lo, hi, slope, intercept| Piece {
            lo,
            hi,
            slope,
            intercept,
        };
        match *self {
            ContactLaw::Complementarity => unreachable!("graph, not a function"),
            ContactLaw::PositivePart { k } => ([pc(-INF, 0.0, 0.0, 0.0), pc(0.0, INF, k, 0.0)], 2),
            ContactLaw::HybridNitsche { k, s_prev } => {
                if s_prev > 0.0 {
                    // midpoint: k[(s_prev + s)/2]₊
                    let b = -s_prev;
                    (
                        [pc(-INF, b, 0.0, 0.0), pc(b, INF, k / 2.0, k * s_prev / 2.0)],
                        2,
                    )
                } else {
                    // Crank–Nicolson ([s_prev]₊ = 0) and the H(0) = ½ average coincide: k[s]₊/2
                    ([pc(-INF, 0.0, 0.0, 0.0), pc(0.0, INF, k / 2.0, 0.0)], 2)
                }
            }
            ContactLaw::HybridReduced { k, s_prev, offset } => {
                if s_prev < 0.0 {
                    let b = -s_prev;
                    (
                        [
                            pc(-INF, b, 0.0, offset),
                            pc(b, INF, k / 2.0, k * s_prev / 2.0 + offset),
                        ],
                        2,
                    )
                } else {
                    let c = k * s_prev.max(0.0) / 2.0 + offset;
                    ([pc(-INF, 0.0, 0.0, c), pc(0.0, INF, k / 2.0, c)], 2)
                }
            }
        }
    }
}

/// Why the scalar contact equation could not be solved.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ContactSolveError {
    #[error(
        "the contact equation has no solution (well-posedness condition of 003 §2.2.3 violated: 1 − w·φ' ≤ 0 on a branch, w = {w:.3e})"
    )]
    NoSolution { w: f64 },
    #[error(
        "the contact equation has several solutions (well-posedness condition of 003 §2.2.3 violated: 1 − w·φ' ≤ 0 on a branch, w = {w:.3e})"
    )]
    Multiple { w: f64 },
    #[error(
        "the condensed contact operator is not positive (w = {w:.3e}); the multiplier is undetermined"
    )]
    NonPositive { w: f64 },
    #[error(transparent)]
    Gradient(#[from] gradient::GradientSolveError),
}

/// Solution of the scalar problem: the contact argument s and the force factor φ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSolution {
    pub s: f64,
    pub phi: f64,
}

/// Solve s = s_free + w φ(s) exactly.
pub fn solve(law: &ContactLaw, s_free: f64, w: f64) -> Result<ContactSolution, ContactSolveError> {
    if let ContactLaw::Complementarity = law {
        // s = s_free + w λ with λ ≤ 0 ⊥ s ≥ 0; unique iff w < 0 (A SPD gives w = −(A⁻¹)₀₀ < 0).
        if s_free >= 0.0 {
            return Ok(ContactSolution {
                s: s_free,
                phi: 0.0,
            });
        }
        if w >= 0.0 || !w.is_finite() {
            return Err(ContactSolveError::NonPositive { w });
        }
        return Ok(ContactSolution {
            s: 0.0,
            phi: -s_free / w,
        });
    }
    let (pieces, n) = law.pieces();
    let mut found: Option<ContactSolution> = None;
    let scale = s_free.abs().max(1e-300);
    for pc in &pieces[..n] {
        // s − w (slope s + intercept) = s_free
        let a = 1.0 - w * pc.slope;
        let rhs = s_free + w * pc.intercept;
        if a == 0.0 {
            if rhs == 0.0 {
                return Err(ContactSolveError::Multiple { w });
            }
            continue;
        }
        let s = rhs / a;
        // Accept a root on the closed piece, with a relative slack for the rounding of s.
        let tol = 1e-13 * (s.abs().max(scale));
        if s >= pc.lo - tol && s <= pc.hi + tol {
            let sol = ContactSolution {
                s,
                phi: pc.slope * s + pc.intercept,
            };
            match found {
                None => found = Some(sol),
                Some(prev) if (prev.s - s).abs() <= tol => {}
                Some(_) => return Err(ContactSolveError::Multiple { w }),
            }
        }
    }
    found.ok_or(ContactSolveError::NoSolution { w })
}

/// Solve two coupled rows s_r = s_free_r + Σ_c w[r][c] φ_c(s_c) exactly (the two sides'
/// rows of the unbiased Nitsche term between two bodies, contract §2.6): each law is
/// piecewise linear ([`ContactLaw::pieces`]), so every pair of pieces is a 2×2 linear system,
/// accepted when both roots lie on their pieces (with [`solve`]'s slack). One solution or an
/// error, as for one row. The complementarity graph has no pieces: two multiplier rows are
/// [`lcp`]'s.
pub fn solve_pair(
    laws: [&ContactLaw; 2],
    s_free: [f64; 2],
    w: [[f64; 2]; 2],
) -> Result<[ContactSolution; 2], ContactSolveError> {
    let (p0, n0) = laws[0].pieces();
    let (p1, n1) = laws[1].pieces();
    let scale = s_free[0].abs().max(s_free[1].abs()).max(1e-300);
    let wmax = w[0][0].abs().max(w[1][1].abs());
    let mut found: Option<[ContactSolution; 2]> = None;
    for a in &p0[..n0] {
        for b in &p1[..n1] {
            // (I − W diag(slope)) s = s_free + W intercept
            let m = [
                [1.0 - w[0][0] * a.slope, -w[0][1] * b.slope],
                [-w[1][0] * a.slope, 1.0 - w[1][1] * b.slope],
            ];
            let r = [
                s_free[0] + w[0][0] * a.intercept + w[0][1] * b.intercept,
                s_free[1] + w[1][0] * a.intercept + w[1][1] * b.intercept,
            ];
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            if det == 0.0 {
                continue;
            }
            let s = [
                (r[0] * m[1][1] - m[0][1] * r[1]) / det,
                (m[0][0] * r[1] - m[1][0] * r[0]) / det,
            ];
            let tol = 1e-13 * s[0].abs().max(s[1].abs()).max(scale);
            let on = |s: f64, pc: &Piece| s >= pc.lo - tol && s <= pc.hi + tol;
            if on(s[0], a) && on(s[1], b) {
                let sol = [
                    ContactSolution {
                        s: s[0],
                        phi: a.slope * s[0] + a.intercept,
                    },
                    ContactSolution {
                        s: s[1],
                        phi: b.slope * s[1] + b.intercept,
                    },
                ];
                match found {
                    None => found = Some(sol),
                    Some(prev)
                        if (prev[0].s - s[0]).abs() <= tol && (prev[1].s - s[1]).abs() <= tol => {}
                    Some(_) => return Err(ContactSolveError::Multiple { w: wmax }),
                }
            }
        }
    }
    found.ok_or(ContactSolveError::NoSolution { w: wmax })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complementarity_projects_onto_the_cone() {
        let law = ContactLaw::Complementarity;
        let a = solve(&law, 0.3, -2.0).unwrap();
        assert_eq!((a.s, a.phi), (0.3, 0.0));
        let b = solve(&law, -0.4, -2.0).unwrap();
        assert_eq!(b.s, 0.0);
        assert!((b.phi + 0.2).abs() < 1e-16);
        assert!(solve(&law, -0.4, 1.0).is_err());
    }

    #[test]
    fn positive_part_unique_when_monotone_and_flags_otherwise() {
        // s = s_free + w k [s]₊ with w k < 1: unique.
        let law = ContactLaw::PositivePart { k: -10.0 };
        let r = solve(&law, 1.0, 0.5).unwrap();
        // s (1 + 5) = 1
        assert!((r.s - 1.0 / 6.0).abs() < 1e-15);
        // w k = 2 > 1: for s_free = −1 two roots (s = −1 and s = 1), for s_free = 1 none.
        let law = ContactLaw::PositivePart { k: 2.0 };
        assert!(matches!(
            solve(&law, -1.0, 1.0),
            Err(ContactSolveError::Multiple { .. })
        ));
        assert!(matches!(
            solve(&law, 1.0, 1.0),
            Err(ContactSolveError::NoSolution { .. })
        ));
    }

    /// Two decoupled rows are two scalar solves; a coupled pair matches its active branch
    /// solved by hand. Exact arithmetic up to one division: 1e-15.
    #[test]
    fn pair_of_rows_solves_its_active_branch() {
        let law = ContactLaw::PositivePart { k: -10.0 };
        let r = solve_pair([&law, &law], [1.0, -1.0], [[0.5, 0.0], [0.0, 0.5]]).unwrap();
        assert!((r[0].s - 1.0 / 6.0).abs() < 1e-15);
        assert_eq!((r[1].s, r[1].phi), (-1.0, 0.0));
        // Both active: s = (1, 1) + W(−10 s), W = [[0.5, 0.25], [0.25, 0.5]]: (I + 10W) s = 1,
        // [[6, 2.5], [2.5, 6]] s = (1, 1), s = 1/8.5 each.
        let r = solve_pair([&law, &law], [1.0, 1.0], [[0.5, 0.25], [0.25, 0.5]]).unwrap();
        assert!((r[0].s - 1.0 / 8.5).abs() < 1e-15 && (r[1].s - 1.0 / 8.5).abs() < 1e-15);
    }

    #[test]
    fn hybrid_switch_is_continuous_at_its_breakpoint() {
        let law = ContactLaw::HybridNitsche {
            k: -4.0,
            s_prev: 0.2,
        };
        // With w = 0 the solution is s_free itself and φ = k[(0.2 + s)/2]₊.
        let r = solve(&law, 0.1, 0.0).unwrap();
        assert!((r.phi + 4.0 * 0.15).abs() < 1e-15);
        let r = solve(&law, -0.3, 0.0).unwrap();
        assert_eq!(r.phi, 0.0);
    }
}
