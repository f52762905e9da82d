//! The discrete gradient of a scalar contact potential (contract §3.2 `discrete-gradient`;
//! Gonzalez 1996, Armero–Petőcz 1998, Hauret–Le Tallec 2006).
//!
//! The contact potential of one contact point is Φ(s) = k/2 [s]₊² in its argument s (penalty:
//! s = −u₀ − g, k = κ; Nitsche with Θ = 1: s = P_γ(u) − g, k = 1/γ_h). The midpoint rule
//! conserves E^h + Φ exactly when the contact force is the difference quotient
//!
//!   D(a, s) = (Φ(s) − Φ(a)) / (s − a),   a = sⁿ, s = s^{n+1},
//!
//! (Φ'((a + s)/2) = k[(a + s)/2]₊ when |s − a| ≤ 1e-14·max(1, |a|)). Written per sign case it
//! has no cancellation: k(a + s)/2 when both are ≥ 0, 0 when both are ≤ 0, k s²/(2(s − a)) or
//! k a²/(2(a − s)) across the kink — so Φ(s) − Φ(a) = D·(s − a) holds to round-off, which is
//! what the energy balance needs.
//!
//! Condensed onto the contact point, the step is the scalar equation s = s_free − w D(a, s)
//! with w = pᵀA⁻¹q̃ > 0 (A SPD, q̃ a positive multiple of p). Φ is convex, so D is
//! non-decreasing in s and g(s) = s + w D(a, s) − s_free is strictly increasing (g' ≥ 1): the
//! root is unique and bracketed by [s_free − w D(a, s_free), s_free]. It is found by the
//! semismooth Newton iteration on g, safeguarded by that bracket (a step leaving it bisects).

/// D(a, s), the difference quotient of Φ = k/2 [·]₊² between a and s.
pub fn difference_quotient(k: f64, a: f64, s: f64) -> f64 {
    if (s - a).abs() <= 1e-14 * a.abs().max(1.0) {
        return k * (0.5 * (a + s)).max(0.0);
    }
    match (a > 0.0, s > 0.0) {
        (true, true) => 0.5 * k * (a + s),
        (false, false) => 0.0,
        (false, true) => 0.5 * k * s * s / (s - a),
        (true, false) => 0.5 * k * a * a / (a - s),
    }
}

/// ∂D/∂s (a generalized derivative at the kinks).
pub fn difference_quotient_slope(k: f64, a: f64, s: f64) -> f64 {
    if (s - a).abs() <= 1e-14 * a.abs().max(1.0) {
        return if a + s > 0.0 { 0.5 * k } else { 0.0 };
    }
    match (a > 0.0, s > 0.0) {
        (true, true) => 0.5 * k,
        (false, false) => 0.0,
        (false, true) => 0.5 * k * s * (s - 2.0 * a) / ((s - a) * (s - a)),
        (true, false) => 0.5 * k * a * a / ((a - s) * (a - s)),
    }
}

/// Why the discrete-gradient contact equation could not be solved.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum GradientSolveError {
    #[error("the condensed contact operator is not positive (w = {w:.3e})")]
    NonPositive { w: f64 },
    #[error("the discrete-gradient contact equation did not converge in {iterations} iterations")]
    NotConverged { iterations: usize },
}

/// The solved step: s^{n+1}, D(sⁿ, s^{n+1}) and the Newton iterations taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradientSolution {
    pub s: f64,
    pub d: f64,
    pub iterations: usize,
}

/// Most Newton iterations (contract §4).
pub const MAX_ITERATIONS: usize = 100;

/// Solve s = s_free − w D(a, s) for the potential k/2 [s]₊² (k ≥ 0, w > 0).
pub fn solve(k: f64, a: f64, s_free: f64, w: f64) -> Result<GradientSolution, GradientSolveError> {
    if w.is_nan() || w < 0.0 || !w.is_finite() {
        return Err(GradientSolveError::NonPositive { w });
    }
    let g = |s: f64| s + w * difference_quotient(k, a, s) - s_free;
    let mut hi = s_free;
    let mut lo = s_free - w * difference_quotient(k, a, s_free);
    if g(hi) <= 0.0 {
        // D(a, s_free) = 0: the free motion is the solution.
        return Ok(GradientSolution {
            s: hi,
            d: difference_quotient(k, a, hi),
            iterations: 0,
        });
    }
    // Start from the in-contact midpoint branch s = (s_free − wka/2)/(1 + wk/2), clamped.
    let mut s = ((s_free - 0.5 * w * k * a) / (1.0 + 0.5 * w * k)).clamp(lo, hi);
    // Converged on the *residual* g, at the round-off of its terms: the energy balance is off
    // by (Φ'(s) − D)·r (r the residual), and g' = 1 + w D' reaches 1e7 for a stiff penalty,
    // so a step-size test (|Δs| ~ ε|s_free|) would leave r ~ 1e7·ε|s_free| — 1e-11 of E⁰
    // measured, where this test leaves round-off.
    for it in 1..=MAX_ITERATIONS {
        let d = difference_quotient(k, a, s);
        let r = s + w * d - s_free;
        let noise = 4.0 * f64::EPSILON * (s.abs() + (w * d).abs() + s_free.abs());
        if r.abs() <= noise || hi - lo <= 2.0 * f64::EPSILON * hi.abs().max(lo.abs()) {
            return Ok(GradientSolution {
                s,
                d,
                iterations: it,
            });
        }
        if r > 0.0 {
            hi = s;
        } else {
            lo = s;
        }
        let next = s - r / (1.0 + w * difference_quotient_slope(k, a, s));
        s = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    Err(GradientSolveError::NotConverged {
        iterations: MAX_ITERATIONS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn phi(k: f64, s: f64) -> f64 {
        0.5 * k * s.max(0.0).powi(2)
    }

    #[test]
    fn quotient_is_the_secant_of_the_potential() {
        // Across the kink, on one side and at a double point: Φ(s) − Φ(a) = D (s − a) to a few
        // ulps of the O(1) values involved.
        for (a, s) in [(-0.3, 0.7), (0.4, -0.2), (0.25, 0.5), (-1.0, -0.5)] {
            let d = difference_quotient(3.0, a, s);
            assert!(
                (phi(3.0, s) - phi(3.0, a) - d * (s - a)).abs() < 1e-15,
                "{a} {s}"
            );
        }
        assert_eq!(difference_quotient(2.0, 0.5, 0.5), 1.0);
    }

    #[test]
    fn solve_meets_its_equation_on_every_branch() {
        // Residual s + w D − s_free at round-off of the O(1) data: 1e-15.
        for (a, s_free) in [
            (-0.2, 0.9),
            (0.3, -0.4),
            (0.3, 0.8),
            (-0.1, -0.5),
            (0.0, 1e-3),
        ] {
            let sol = solve(50.0, a, s_free, 0.7).unwrap();
            let r = sol.s + 0.7 * difference_quotient(50.0, a, sol.s) - s_free;
            assert!(r.abs() < 1e-15, "{a} {s_free}: residual {r}");
            assert!(sol.iterations <= 60);
        }
    }
}
