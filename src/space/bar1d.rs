//! P1 discretisation of the bar (0, L): nodes x_i = i h, i = 0 … m, node m clamped and
//! eliminated (m unknowns) or, with a free right end (contract §1.4), kept (m + 1 unknowns, a
//! natural boundary condition: nothing else changes); node 0 the contact node. All operators
//! are tridiagonal.
//!
//! Mass variants (contract §2.2): element k (nodes k, k+1) carries ρ h/6 [2 1; 1 2] times a weight
//! w_k (element-weight family of 000 §3), or is lumped, or has the contact row modified.
//! `mass_total` = 1ᵀ M 1 over all m+1 nodes (the clamped node included), i.e. the total mass
//! the matrix represents: ρL for consistent, lumped, mod2, mod3; ρ(L − h) for mod1.
//!
//! Contact (contract §2.1, §2.3, §2.4), with s = pᵀu + p₀ the argument of the nonlinearity and the
//! force F_c = φ · q entering the right-hand side:
//! - mixed: s = u₀ + g, q = −e₀, φ = λ ≤ 0 (complementarity);
//! - Nitsche: s = P_γ(u) − g = −u₀ − γ₀E(u₁ − u₀) − g, q = ∂P_Θγ/∂v = (−1 + Θγ₀E, −Θγ₀E),
//!   φ = −[s]₊/γ_h, and K becomes K_Θ = K − Θ γ₀ E²/h (e₁ − e₀)(e₁ − e₀)ᵀ;
//! - penalty: s = −u₀ − g, q = −e₀, φ = −κ[s]₊, κ = E γ₀/h.
//!
//! In each case φ is the contact pressure σ_C (negative in compression).

use super::{ContactMethod, MassVariant, Tridiag};

/// Physical parameters of the bar (contract §1.1 defaults: L = E = ρ = 1, a = ½, g = 0, clamped
/// at x = L, at rest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarParams {
    pub length: f64,
    pub young: f64,
    pub density: f64,
    pub amplitude: f64,
    pub gap: f64,
    /// The end x = L is traction-free (contract §1.4) instead of clamped.
    pub free_end: bool,
    /// Uniform initial velocity v0 (negative towards the obstacle).
    pub velocity: f64,
}

impl Default for BarParams {
    fn default() -> Self {
        Self {
            length: 1.0,
            young: 1.0,
            density: 1.0,
            amplitude: 0.5,
            gap: 0.0,
            free_end: false,
            velocity: 0.0,
        }
    }
}

impl BarParams {
    /// Wave speed c0 = sqrt(E/ρ).
    pub fn wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }

    /// Initial displacement u0(x) = a (1 − x/L).
    pub fn initial_displacement(&self, x: f64) -> f64 {
        self.amplitude * (1.0 - x / self.length)
    }

    /// Initial velocity v0(x): uniform.
    pub fn initial_velocity(&self, _x: f64) -> f64 {
        self.velocity
    }
}

/// A sparse vector on the first two nodes (all contact vectors of the 1D bar live there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair(pub [f64; 2]);

impl Pair {
    pub fn dot(&self, x: &[f64]) -> f64 {
        self.0[0] * x[0] + if x.len() > 1 { self.0[1] * x[1] } else { 0.0 }
    }
}

/// The assembled 1D space for one run.
#[derive(Debug, Clone)]
pub struct Bar1dSpace {
    pub bar: BarParams,
    /// Number of unknowns: the elements m with the right end clamped (nodes 0 … m−1), m + 1
    /// with it free (nodes 0 … m). The engines size their vectors with it.
    pub m: usize,
    pub h: f64,
    pub mass: Tridiag,
    /// Plain stiffness K (energies are ½uᵀKu with this one).
    pub stiffness: Tridiag,
    /// Stiffness of the linear part of the equation (K_Θ for Nitsche, K otherwise).
    pub stiffness_lin: Tridiag,
    pub mass_total: f64,
    pub massless_contact: bool,
    pub method: ContactMethod,
    /// s = p·u + p0.
    pub p: Pair,
    pub p0: f64,
    /// Direction of the contact force.
    pub q: Pair,
}

/// Why a space could not be assembled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpaceError {
    #[error("the mesh needs at least 2 elements (got {0})")]
    TooFewElements(usize),
    #[error("mass_weights must list at least one weight")]
    NoWeights,
    #[error("mass matrix of the free nodes is singular (pivot {pivot} at node {node})")]
    SingularMass { node: usize, pivot: f64 },
}

impl Bar1dSpace {
    pub fn new(
        bar: BarParams,
        m: usize,
        mass: &MassVariant,
        method: ContactMethod,
    ) -> Result<Self, SpaceError> {
        if m < 2 {
            return Err(SpaceError::TooFewElements(m));
        }
        if matches!(mass, MassVariant::Weights(w) if w.is_empty()) {
            return Err(SpaceError::NoWeights);
        }
        let h = bar.length / m as f64;
        let rho = bar.density;
        let e = bar.young;
        // A free end keeps node m as an unknown: the last element's block is then assembled in
        // full by `add_element` instead of losing its clamped row and column.
        let unknowns = if bar.free_end { m + 1 } else { m };
        let mut k = Tridiag::zeros(unknowns);
        let mut mm = Tridiag::zeros(unknowns);
        let kel = e / h;
        let cons = |w: f64| {
            let a = w * rho * h / 6.0;
            [[2.0 * a, a], [a, 2.0 * a]]
        };
        let mut total = 0.0;
        for el in 0..m {
            k.add_element(el, [[kel, -kel], [-kel, kel]]);
            let block = match mass {
                MassVariant::Consistent | MassVariant::ZeroContact => cons(1.0),
                MassVariant::SingularDynamic | MassVariant::NodeNeighbour => cons(1.0),
                MassVariant::Lumped => [[rho * h / 2.0, 0.0], [0.0, rho * h / 2.0]],
                MassVariant::Mod1 => cons(if el == 0 { 0.0 } else { 1.0 }),
                MassVariant::Mod2 => cons(if el == 0 {
                    0.0
                } else {
                    m as f64 / (m as f64 - 1.0)
                }),
                MassVariant::Mod3 => cons(match el {
                    0 => 0.0,
                    1 => 2.0,
                    _ => 1.0,
                }),
                MassVariant::Weights(w) => cons(if el == 0 {
                    0.0
                } else {
                    w[(el - 1).min(w.len() - 1)]
                }),
            };
            total += block[0][0] + block[0][1] + block[1][0] + block[1][1];
            mm.add_element(el, block);
        }
        // Contact-row variants modify the assembled matrix; the total follows the matrix.
        match mass {
            MassVariant::ZeroContact => {
                total -= mm.diag[0] + 2.0 * mm.upper[0];
                mm.clear_row_col(0);
            }
            MassVariant::SingularDynamic => {
                total -= mm.diag[0] + 2.0 * mm.upper[0];
                mm.clear_row_col(0);
                total += 7.0 * rho * h / 12.0 - mm.diag[1];
                mm.diag[1] = 7.0 * rho * h / 12.0;
            }
            MassVariant::NodeNeighbour => {
                let row0 = mm.diag[0] + mm.upper[0];
                total -= mm.diag[0] + 2.0 * mm.upper[0];
                mm.clear_row_col(0);
                mm.diag[1] += row0;
                total += row0;
            }
            _ => {}
        }
        let massless = mass.massless_contact();
        // The free nodes' mass must be invertible (a user weight list could break it).
        let free = if massless {
            let mut f = mm.clone();
            f.set_row(0, (0.0, 1.0, 0.0));
            f.lower[0] = 0.0;
            f
        } else {
            mm.clone()
        };
        if free.factor().is_none() || free.diag.iter().any(|&d| d <= 0.0) {
            let node = free.diag.iter().position(|&d| d <= 0.0).unwrap_or(0);
            return Err(SpaceError::SingularMass {
                node,
                pivot: free.diag[node],
            });
        }
        let g = bar.gap;
        let (stiffness_lin, p, p0, q) = match method {
            ContactMethod::Mixed => (k.clone(), Pair([1.0, 0.0]), g, Pair([-1.0, 0.0])),
            ContactMethod::Penalty { .. } => (k.clone(), Pair([-1.0, 0.0]), -g, Pair([-1.0, 0.0])),
            ContactMethod::Nitsche { theta, gamma0 } => {
                let mut kt = k.clone();
                // −Θ γ_h σ_n(u) σ_n(v) = −Θ γ₀ E²/h (u₁ − u₀)(v₁ − v₀)
                let c = theta * gamma0 * e * e / h;
                kt.add_element(0, [[-c, c], [c, -c]]);
                let ge = gamma0 * e;
                let tge = theta * gamma0 * e;
                (kt, Pair([-1.0 + ge, -ge]), -g, Pair([-1.0 + tge, -tge]))
            }
        };
        Ok(Self {
            bar,
            m: unknowns,
            h,
            mass: mm,
            stiffness: k,
            stiffness_lin,
            mass_total: total,
            massless_contact: massless,
            method,
            p,
            p0,
            q,
        })
    }

    /// Contact pressure σ_C as a function of the state (Nitsche and penalty); for the mixed
    /// method it is the stress of the contact element, exact when node 0 is quasi-static.
    pub fn contact_pressure(&self, u: &[f64]) -> f64 {
        let s = self.p.dot(u) + self.p0;
        match self.method {
            ContactMethod::Mixed => self.bar.young * (u[1] - u[0]) / self.h,
            ContactMethod::Nitsche { gamma0, .. } => -s.max(0.0) / (gamma0 * self.h),
            ContactMethod::Penalty { gamma0 } => -self.penalty_stiffness(gamma0) * s.max(0.0),
        }
    }

    /// The mean velocity 1ᵀMv/1ᵀM1 of the unknowns (the free bar's rigid velocity: its
    /// momentum over its mass).
    pub fn mean_velocity(&self, v: &[f64]) -> f64 {
        let (mut p, mut mass) = (0.0, 0.0);
        for i in 0..self.m {
            let (l, d, u) = self.mass.row(i);
            let row = l + d + u;
            mass += row;
            p += row * v[i];
        }
        p / mass
    }

    pub fn penalty_stiffness(&self, gamma0: f64) -> f64 {
        self.bar.young * gamma0 / self.h
    }

    /// ½uᵀKu summed element by element from the strains (u_{k+1} − u_k)/h: the nodal form
    /// Σ K_ii u_i² + 2 Σ K_i,i+1 u_i u_{i+1} cancels terms of size E/h·u² down to O(1) and loses
    /// ~1e-12 relative accuracy, which energy-monotonicity checks at 1e-12 would see.
    pub fn strain_energy(&self, u: &[f64]) -> f64 {
        // u_m = 0 (clamped): the last element's strain is −u_{m−1}/h; a free end's node m is
        // in u, and the windows already hold every element.
        let last = if self.bar.free_end {
            0.0
        } else {
            u[u.len() - 1]
        };
        let s: f64 = u
            .windows(2)
            .map(|w| (w[1] - w[0]) * (w[1] - w[0]))
            .sum::<f64>()
            + last * last;
        0.5 * self.bar.young / self.h * s
    }

    /// Mechanical energy E^h = ½vᵀMv + ½uᵀKu, plus the penalty potential κ/2 [s]₊² for the
    /// penalty method (contract §2.4), and the augmented Nitsche energy E_Θ (contract §2.3) if any.
    pub fn energies(&self, u: &[f64], v: &[f64]) -> (f64, Option<f64>) {
        let eh = 0.5 * self.mass.quad(v) + self.strain_energy(u);
        let s = self.p.dot(u) + self.p0;
        match self.method {
            ContactMethod::Mixed => (eh, None),
            ContactMethod::Penalty { gamma0 } => {
                let sp = s.max(0.0);
                (eh + 0.5 * self.penalty_stiffness(gamma0) * sp * sp, None)
            }
            ContactMethod::Nitsche { theta, gamma0 } => {
                let gh = gamma0 * self.h;
                let sig = self.bar.young * (u[1] - u[0]) / self.h;
                let sp = s.max(0.0);
                let r = 0.5 * (gh * sig * sig - sp * sp / gh);
                (eh, Some(eh - theta * r))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total(mass: MassVariant, m: usize) -> f64 {
        Bar1dSpace::new(BarParams::default(), m, &mass, ContactMethod::Mixed)
            .unwrap()
            .mass_total
    }

    // Sums of O(m) entries of size ~h: round-off ~m·ε ≈ 1e-14 at m = 10.
    #[test]
    fn mass_totals_follow_their_definitions() {
        let m = 10;
        let h = 0.1;
        assert!((total(MassVariant::Consistent, m) - 1.0).abs() < 1e-14);
        assert!((total(MassVariant::Lumped, m) - 1.0).abs() < 1e-14);
        assert!((total(MassVariant::Mod1, m) - (1.0 - h)).abs() < 1e-14);
        assert!((total(MassVariant::Mod2, m) - 1.0).abs() < 1e-14);
        assert!((total(MassVariant::Mod3, m) - 1.0).abs() < 1e-14);
        assert!((total(MassVariant::ZeroContact, m) - (1.0 - 2.0 * h / 3.0)).abs() < 1e-14);
        assert!((total(MassVariant::SingularDynamic, m) - (1.0 - 0.75 * h)).abs() < 1e-14);
        assert!((total(MassVariant::NodeNeighbour, m) - (1.0 - h / 6.0)).abs() < 1e-14);
    }

    #[test]
    fn mod3_and_node_neighbour_entries_match_spec() {
        let h = 0.1;
        let s = Bar1dSpace::new(
            BarParams::default(),
            10,
            &MassVariant::Mod3,
            ContactMethod::Mixed,
        )
        .unwrap();
        assert!((s.mass.diag[1] - 2.0 * h / 3.0).abs() < 1e-15);
        assert!((s.mass.upper[1] - h / 3.0).abs() < 1e-15);
        assert_eq!(s.mass.row(0), (0.0, 0.0, 0.0));
        let s = Bar1dSpace::new(
            BarParams::default(),
            10,
            &MassVariant::NodeNeighbour,
            ContactMethod::Mixed,
        )
        .unwrap();
        assert!((s.mass.diag[1] - 7.0 * h / 6.0).abs() < 1e-15);
        assert!((s.mass.upper[1] - h / 6.0).abs() < 1e-15);
    }
}
