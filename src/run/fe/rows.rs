//! Contact rows: the constraints every contact pair hands to the condensed solve (contract §2.1,
//! §2.6, §4).
//!
//! A row i is a sparse vector B_i over the reduced dofs and a gap g_i, the constraint being
//! B_i·u + g_i ≥ 0 with the force λ_i ≥ 0 acting as B_iᵀλ_i. A body against the obstacle gives
//! B_i = e_{node,d} (u_d + g ≥ 0, an upward force); a node-to-node pair of two bodies, A above
//! B, gives B_i = e_{a,i,d} − e_{b,π(i),d} (the relative normal displacement
//! δ_i = (u^a_i − u^b_{π(i)})·n with n = −e_d, so δ_i ≤ g_i reads B_i·u + g_i ≥ 0), whose force
//! pushes A up and B down by the same amount — action = reaction, so Σ_j (B_iᵀ)_j over a
//! component vanishes and the total momentum is an exact invariant (contract §2.6).
//!
//! The non-matching pairings (issue 45) give rows with more entries: node-to-segment
//! e_{a,i,d} − Σ_j N_j(ξ_i) e_{b,j,d}, mortar Σ_i D_ki e_{a,i,d} − Σ_j M_kj e_{b,j,d} (scaled by
//! 1/∫ψ_k, [`super::pairing`]); each row's coefficients sum to zero up to round-off, which keeps
//! the invariant. A row records where its Γ^b entries start, for Γ^b's mean displacement.
//!
//! Why one type for both: the condensation Z = A⁻¹Bᵀ, W = BZ, the LCP, the energies and the
//! §3.2 methods only ever take B·x and Bᵀλ, so a second body is data (rows with two entries),
//! not a branch. A one-entry row with coefficient 1 computes exactly what the obstacle engine
//! computed before rows existed (1·x = x, and a sum is started from its first term, never from
//! 0.0, which would turn −0 into +0), so the one-body runs keep their numbers bit for bit.

/// A general row's entries as (global node or dof, coefficient of its e_d component): A's,
/// then B's.
pub(super) type RowEntries = (Vec<(usize, f64)>, Vec<(usize, f64)>);

/// The rows of one run's contact set, in compressed sparse row form.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Rows {
    start: Vec<usize>,
    dof: Vec<usize>,
    coef: Vec<f64>,
    /// Per row, the offset of its first Γ^b entry ([`Rows::general`]); empty: 1 for every row
    /// (unit rows have none, a node-to-node pair's second entry is Γ^b's).
    b_from: Vec<usize>,
}

impl Rows {
    /// One row e_c per dof c (a body against the obstacle).
    pub(super) fn unit(dofs: &[usize]) -> Rows {
        Rows {
            start: (0..=dofs.len()).collect(),
            dof: dofs.to_vec(),
            coef: vec![1.0; dofs.len()],
            b_from: Vec::new(),
        }
    }

    /// One row e_a − e_b per pair (a, b) (node-to-node between two bodies, A above B).
    pub(super) fn pairs(pairs: &[(usize, usize)]) -> Rows {
        let mut r = Rows {
            start: vec![0],
            ..Rows::default()
        };
        for &(a, b) in pairs {
            r.dof.extend([a, b]);
            r.coef.extend([1.0, -1.0]);
            r.start.push(r.dof.len());
        }
        r
    }

    /// General two-body rows, one per (A's entries, B's entries): B_i = Σ_a c_a e_a + Σ_b c_b e_b
    /// (node-to-segment and mortar, issue 45).
    pub(super) fn general(rows: &[RowEntries]) -> Rows {
        let mut r = Rows {
            start: vec![0],
            ..Rows::default()
        };
        for (a, b) in rows {
            r.b_from.push(a.len());
            for &(dof, c) in a.iter().chain(b) {
                r.dof.push(dof);
                r.coef.push(c);
            }
            r.start.push(r.dof.len());
        }
        r
    }

    /// The tangential rows of these normal rows (contract §2.5, §2.6): for each row i and each
    /// tangential direction c < `nt`, row i·nt + c has row i's coefficients on the dofs
    /// `dof(k, c)` of its entries k (the same node's e_c component). A unit row e_{node,d} gives
    /// the unit tangential row e_{node,c} (one body's u_t), a pair e_{a,d} − e_{b,d} gives
    /// e_{a,c} − e_{b,c}: the relative slip (u^a − u^b∘π)_c, whose force acts equally and
    /// oppositely on the two bodies.
    pub(super) fn tangential(
        &self,
        nt: usize,
        dof: impl Fn(usize, usize) -> Result<usize, String>,
    ) -> Result<Rows, String> {
        let mut r = Rows {
            start: vec![0],
            ..Rows::default()
        };
        for i in 0..self.len() {
            for c in 0..nt {
                for k in self.start[i]..self.start[i + 1] {
                    r.dof.push(dof(self.dof[k], c)?);
                    r.coef.push(self.coef[k]);
                }
                r.start.push(r.dof.len());
            }
        }
        Ok(r)
    }

    /// Rows taken in turn from `from`: row k of the result is row `pick(k).1` of the rows
    /// `pick(k).0` (the node-major [normal, tangential…] order of a frictional solve's unknowns).
    pub(super) fn gather<'a>(count: usize, pick: impl Fn(usize) -> (&'a Rows, usize)) -> Rows {
        let mut r = Rows {
            start: vec![0],
            ..Rows::default()
        };
        for k in 0..count {
            let (from, i) = pick(k);
            let (s, e) = (from.start[i], from.start[i + 1]);
            r.dof.extend_from_slice(&from.dof[s..e]);
            r.coef.extend_from_slice(&from.coef[s..e]);
            r.start.push(r.dof.len());
        }
        r
    }

    /// Every row's dofs and coefficients, flat (one per row for unit rows).
    pub(super) fn all(&self) -> (&[usize], &[f64]) {
        (&self.dof, &self.coef)
    }

    /// Row i's dofs and coefficients.
    pub(super) fn entries(&self, i: usize) -> (&[usize], &[f64]) {
        let (s, e) = (self.start[i], self.start[i + 1]);
        (&self.dof[s..e], &self.coef[s..e])
    }

    /// The number of rows.
    pub(super) fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// Whether there is no row.
    pub(super) fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether every row is a single unit entry (a body against the obstacle): the methods
    /// that act node by node (the kinematic impulse of central difference, the quasi-static
    /// start's friction) take only those.
    pub(super) fn is_unit(&self) -> bool {
        self.len() == self.dof.len() && self.coef.iter().all(|&c| c == 1.0)
    }

    /// Whether no dof belongs to two rows (node-to-node rows on a matching interface; unit
    /// rows of distinct nodes): then the rows' kinematic impulses ([`Rows::impulse`]) act on
    /// disjoint dofs and each one is exact whatever the order.
    pub(super) fn disjoint(&self) -> bool {
        let mut seen = std::collections::HashSet::with_capacity(self.dof.len());
        self.dof.iter().all(|&d| seen.insert(d))
    }

    /// The kinematic impulse of central difference on row i (contract §3.2; Taylor–Flanagan,
    /// Carpenter–Taylor–Katona's forward increment for a diagonal mass): if the predicted
    /// state violates B_i·u + g_i ≥ 0 by d < 0, the force λ = −d/(τ² Σ_k c_k²/m_k) ≥ 0 acting
    /// as B_iᵀλ over the step moves each entry's dof by τ²c_kλ/m_k and its half-step velocity by
    /// τc_kλ/m_k, which brings the row exactly onto the constraint. A pair row's two dofs
    /// receive m_k Δv_k = ±τλ: action = reaction, the momentum unchanged. Returns λ (0 when the
    /// row stays admissible). The unit rows keep their own formula ([`crate::time::kinematic_impulse`]).
    pub(super) fn impulse(
        &self,
        i: usize,
        gap: f64,
        mass: &[f64],
        tau: f64,
        u: &mut [f64],
        v: &mut [f64],
    ) -> f64 {
        let d = self.dot(i, u) + gap;
        if d >= 0.0 {
            return 0.0;
        }
        let (s, e) = (self.start[i], self.start[i + 1]);
        let w: f64 = (s..e)
            .map(|k| self.coef[k] * self.coef[k] / mass[self.dof[k]])
            .sum();
        let lambda = -d / (tau * tau * w);
        for k in s..e {
            let j = self.dof[k];
            let dv = tau * self.coef[k] * lambda / mass[j];
            v[j] += dv;
            u[j] += tau * dv;
        }
        lambda
    }

    /// Σ_i w_i (−Σ_{Γ^b entries k} c_k x_k) (a node-to-node row's Γ^b dof; unit rows add
    /// nothing): Γ^b's mean displacement with Γ^a's weights, the `u_contact_b` series (contract
    /// §5) — B's displacement at Π(x_i) for node-to-segment rows, its ψ_k-weighted mean for
    /// mortar rows.
    pub(super) fn second_mean(&self, w: &[f64], x: &[f64]) -> f64 {
        (0..self.len())
            .zip(w)
            .filter(|&(i, _)| self.start[i + 1] - self.start[i] > self.b_from(i))
            .map(|(i, w)| {
                let (s, e) = (self.start[i] + self.b_from(i), self.start[i + 1]);
                // −(−1)·x = x: a pair's one Γ^b entry gives w·x bit for bit.
                let mut b = -self.coef[s] * x[self.dof[s]];
                for k in s + 1..e {
                    b -= self.coef[k] * x[self.dof[k]];
                }
                w * b
            })
            .sum()
    }

    /// Whether these are a projecting pairing's rows ([`Rows::general`]).
    pub(super) fn is_general(&self) -> bool {
        !self.b_from.is_empty()
    }

    /// The offset of row i's first Γ^b entry.
    fn b_from(&self, i: usize) -> usize {
        self.b_from.get(i).copied().unwrap_or(1)
    }

    /// B_i·x, summed from the first entry on (a one-entry row gives x_c itself, bit for bit).
    #[inline]
    pub(super) fn dot(&self, i: usize, x: &[f64]) -> f64 {
        let (s, e) = (self.start[i], self.start[i + 1]);
        let mut acc = self.coef[s] * x[self.dof[s]];
        for k in s + 1..e {
            acc += self.coef[k] * x[self.dof[k]];
        }
        acc
    }

    /// B_i·(x + y), each entry's sum formed first (a one-entry row gives x_c + y_c, bit for bit:
    /// the increment form of a step, `run::fe::newmark`).
    #[inline]
    pub(super) fn dot_sum(&self, i: usize, x: &[f64], y: &[f64]) -> f64 {
        let (s, e) = (self.start[i], self.start[i + 1]);
        let mut acc = self.coef[s] * (x[self.dof[s]] + y[self.dof[s]]);
        for k in s + 1..e {
            acc += self.coef[k] * (x[self.dof[k]] + y[self.dof[k]]);
        }
        acc
    }

    /// The largest penetration max_i (−B_i·u − g_i)_+ (contract §1.3: (u_n − g)_+ at the nodes).
    pub(super) fn penetration(&self, gaps: &[f64], u: &[f64]) -> f64 {
        gaps.iter()
            .enumerate()
            .fold(0.0f64, |m, (i, gap)| m.max(-self.dot(i, u) - gap))
    }

    /// y += s B_iᵀ.
    #[inline]
    pub(super) fn add(&self, i: usize, s: f64, y: &mut [f64]) {
        for k in self.start[i]..self.start[i + 1] {
            y[self.dof[k]] += s * self.coef[k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit rows reproduce the indexed reads and writes exactly, −0 included; pair rows act
    /// equally and oppositely (exact binary fractions).
    #[test]
    fn unit_rows_are_indexing_and_pairs_balance() {
        let x = [-0.0, 0.5, -0.25, 3.0];
        let u = Rows::unit(&[0, 2]);
        assert_eq!(u.len(), 2);
        assert!(u.is_unit());
        assert_eq!(u.dot(0, &x).to_bits(), (-0.0f64).to_bits());
        assert_eq!(u.dot(1, &x), -0.25);
        let p = Rows::pairs(&[(1, 3), (2, 0)]);
        assert!(!p.is_unit());
        assert_eq!(p.dot(0, &x), 0.5 - 3.0);
        let mut y = [0.0; 4];
        p.add(0, 2.0, &mut y);
        assert_eq!(y, [0.0, 2.0, 0.0, -2.0]);
        assert_eq!(y.iter().sum::<f64>(), 0.0);
        assert_eq!(p.dot(1, &x), -0.25 - -0.0);
        assert!(p.disjoint() && u.disjoint());
        assert!(!Rows::pairs(&[(0, 1), (1, 2)]).disjoint());
    }

    /// A pair row's kinematic impulse puts the row on its constraint and gives the two dofs
    /// equal and opposite momenta: masses 2 and 6, τ = ½, a penetration of 0.25 (binary
    /// fractions throughout, so the checks are exact): λ = 0.25/(¼·(½ + ⅙)) = 1.5, Δv_a =
    /// ½·1.5/2 = 0.375, Δv_b = −0.125.
    #[test]
    fn a_pair_impulse_conserves_momentum() {
        let r = Rows::pairs(&[(0, 1)]);
        let mass = [2.0, 6.0];
        let (mut u, mut v) = ([-0.25, 0.0], [0.0, 0.0]);
        let l = r.impulse(0, 0.0, &mass, 0.5, &mut u, &mut v);
        assert!((l - 1.5).abs() < 1e-15, "{l}");
        assert!(
            (v[0] - 0.375).abs() < 1e-15 && (v[1] + 0.125).abs() < 1e-15,
            "{v:?}"
        );
        assert!(r.dot(0, &u).abs() < 1e-15, "{u:?}");
        assert!((mass[0] * v[0] + mass[1] * v[1]).abs() < 1e-15);
        // An admissible row is left alone.
        assert_eq!(r.impulse(0, 1.0, &mass, 0.5, &mut u, &mut v), 0.0);
    }

    /// The tangential rows copy each row's coefficients onto the mapped dofs (node-major), and
    /// `gather` interleaves rows of two sets in the order asked: a unit row stays a unit row,
    /// a pair row's tangential rows balance (e_{a,c} − e_{b,c}).
    #[test]
    fn tangential_rows_follow_their_normal_rows() {
        // Vertical dofs 2 and 5 (d = 2: the tangential dof is one below).
        let below = |dof: usize, c: usize| Ok(dof - 1 + c);
        let u = Rows::unit(&[2, 5]).tangential(1, below).unwrap();
        assert!(u.is_unit());
        assert_eq!(u.all(), (&[1usize, 4][..], &[1.0, 1.0][..]));
        let p = Rows::pairs(&[(2, 5)]).tangential(1, below).unwrap();
        assert_eq!(p.entries(0), (&[1usize, 4][..], &[1.0, -1.0][..]));
        let x = [0.0, 0.75, 0.0, 0.0, 0.5, 0.0];
        assert_eq!(p.dot(0, &x), 0.25);
        let mut y = [0.0; 6];
        p.add(0, 3.0, &mut y);
        assert_eq!(y.iter().sum::<f64>(), 0.0);
        let n = Rows::pairs(&[(2, 5)]);
        let g = Rows::gather(2, |k| if k == 0 { (&n, 0) } else { (&p, 0) });
        assert_eq!(g.len(), 2);
        assert_eq!(g.entries(1), p.entries(0));
        assert_eq!(g.entries(0), n.entries(0));
        assert!(Rows::unit(&[]).is_empty());
    }
}
