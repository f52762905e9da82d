//! Tridiagonal matrices: the 1D P1 operators and their once-per-run LU factorisation.
//!
//! Every 1D matrix of the engine (M, K, M + c K, …) is tridiagonal, so a step costs O(m). The
//! factorisation is the Thomas algorithm without pivoting, which is stable for the diagonally
//! dominant or symmetric positive definite matrices built here; a zero pivot is reported.

/// A square tridiagonal matrix: `lower[i] = A[i+1][i]`, `diag[i] = A[i][i]`, `upper[i] = A[i][i+1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tridiag {
    pub lower: Vec<f64>,
    pub diag: Vec<f64>,
    pub upper: Vec<f64>,
}

impl Tridiag {
    pub fn zeros(n: usize) -> Self {
        Self {
            lower: vec![0.0; n.saturating_sub(1)],
            diag: vec![0.0; n],
            upper: vec![0.0; n.saturating_sub(1)],
        }
    }

    pub fn len(&self) -> usize {
        self.diag.len()
    }

    pub fn is_empty(&self) -> bool {
        self.diag.is_empty()
    }

    /// Add the 2×2 block `k` at rows/columns (i, i+1); the entries of a node beyond the matrix
    /// (the clamped end) are dropped.
    pub fn add_element(&mut self, i: usize, k: [[f64; 2]; 2]) {
        let n = self.len();
        self.diag[i] += k[0][0];
        if i + 1 < n {
            self.upper[i] += k[0][1];
            self.lower[i] += k[1][0];
            self.diag[i + 1] += k[1][1];
        }
    }

    /// `self + c · other`.
    pub fn axpy(&self, c: f64, other: &Tridiag) -> Tridiag {
        let z = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x + c * y).collect();
        Tridiag {
            lower: z(&self.lower, &other.lower),
            diag: z(&self.diag, &other.diag),
            upper: z(&self.upper, &other.upper),
        }
    }

    /// Row i as (A[i][i-1], A[i][i], A[i][i+1]) with zeros outside.
    pub fn row(&self, i: usize) -> (f64, f64, f64) {
        let l = if i > 0 { self.lower[i - 1] } else { 0.0 };
        let u = if i + 1 < self.len() {
            self.upper[i]
        } else {
            0.0
        };
        (l, self.diag[i], u)
    }

    /// Zero row and column i.
    pub fn clear_row_col(&mut self, i: usize) {
        self.diag[i] = 0.0;
        if i > 0 {
            self.lower[i - 1] = 0.0;
            self.upper[i - 1] = 0.0;
        }
        if i < self.lower.len() {
            self.lower[i] = 0.0;
            self.upper[i] = 0.0;
        }
    }

    /// Replace row i by (l, d, u).
    pub fn set_row(&mut self, i: usize, (l, d, u): (f64, f64, f64)) {
        if i > 0 {
            self.lower[i - 1] = l;
        }
        self.diag[i] = d;
        if i + 1 < self.len() {
            self.upper[i] = u;
        }
    }

    /// `out = A x`. The first and last rows are peeled so that the interior loop has no
    /// branch (this product runs twice per step over every node).
    pub fn mul_into(&self, x: &[f64], out: &mut [f64]) {
        let n = self.len();
        if n == 1 {
            out[0] = self.diag[0] * x[0];
            return;
        }
        let (l, d, u) = (&self.lower[..n - 1], &self.diag[..n], &self.upper[..n - 1]);
        let (x, out) = (&x[..n], &mut out[..n]);
        out[0] = d[0] * x[0] + u[0] * x[1];
        for i in 1..n - 1 {
            out[i] = l[i - 1] * x[i - 1] + d[i] * x[i] + u[i] * x[i + 1];
        }
        out[n - 1] = l[n - 2] * x[n - 2] + d[n - 1] * x[n - 1];
    }

    /// xᵀ A x without a temporary.
    pub fn quad(&self, x: &[f64]) -> f64 {
        let n = self.len();
        let (l, d, u) = (&self.lower[..n - 1], &self.diag[..n], &self.upper[..n - 1]);
        let x = &x[..n];
        let mut s = d[n - 1] * x[n - 1] * x[n - 1];
        for i in 0..n - 1 {
            s += d[i] * x[i] * x[i] + (u[i] + l[i]) * x[i] * x[i + 1];
        }
        s
    }

    /// Sum of all entries (1ᵀ A 1).
    pub fn total(&self) -> f64 {
        self.diag.iter().chain(&self.lower).chain(&self.upper).sum()
    }

    /// LU factorisation (Thomas). `None` on a zero or non-finite pivot.
    pub fn factor(&self) -> Option<TridiagLu> {
        let n = self.len();
        let mut piv = vec![0.0; n];
        let mut mult = vec![0.0; n.saturating_sub(1)];
        let mut prev = 0.0;
        for i in 0..n {
            let mut d = self.diag[i];
            if i > 0 {
                let l = self.lower[i - 1] / prev;
                mult[i - 1] = l;
                d -= l * self.upper[i - 1];
            }
            if d == 0.0 || !d.is_finite() {
                return None;
            }
            piv[i] = 1.0 / d;
            prev = d;
        }
        Some(TridiagLu {
            mult,
            piv,
            upper: self.upper.clone(),
        })
    }

    /// Number of negative eigenvalues of the symmetric pencil `self − λ·mass` (Sylvester's law
    /// of inertia on its LDLᵀ). Counts the finite generalized eigenvalues below λ when `mass` is
    /// positive semi-definite; used to bound the spectrum for CFL checks.
    pub fn count_below(&self, lambda: f64, mass: &Tridiag) -> usize {
        let n = self.len();
        let mut count = 0;
        let mut prev = 1.0;
        for i in 0..n {
            let mut d = self.diag[i] - lambda * mass.diag[i];
            if i > 0 {
                let off = self.lower[i - 1] - lambda * mass.lower[i - 1];
                d -= off * off / prev;
            }
            if d == 0.0 {
                d = -f64::EPSILON * (self.diag[i].abs() + lambda * mass.diag[i].abs()).max(1e-300);
            }
            if d < 0.0 {
                count += 1;
            }
            prev = d;
        }
        count
    }

    /// Largest finite generalized eigenvalue of (self, mass) by bisection on the inertia count.
    pub fn max_generalized_eigenvalue(&self, mass: &Tridiag) -> f64 {
        let n_finite = (0..self.len()).filter(|&i| mass.diag[i] > 0.0).count();
        let mut hi = 1.0;
        while self.count_below(hi, mass) < n_finite && hi < 1e300 {
            hi *= 2.0;
        }
        let mut lo = 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.count_below(mid, mass) < n_finite {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }
}

/// The Thomas factorisation of a [`Tridiag`]: solve in O(n) without allocation.
#[derive(Debug, Clone)]
pub struct TridiagLu {
    mult: Vec<f64>,
    /// Inverse pivots (a multiplication per row instead of a division).
    piv: Vec<f64>,
    upper: Vec<f64>,
}

impl TridiagLu {
    /// The factors: multipliers of the forward sweep, inverse pivots, the upper diagonal (for a
    /// benchmark that solves several systems at once: `benches/bar1d.rs`, `lanes-ratio`).
    pub fn parts(&self) -> (&[f64], &[f64], &[f64]) {
        (&self.mult, &self.piv, &self.upper)
    }

    /// Overwrite `x` (the right-hand side) with the solution.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = self.piv.len();
        let x = &mut x[..n];
        let (mult, piv, upper) = (&self.mult[..n - 1], &self.piv[..n], &self.upper[..n - 1]);
        for i in 1..n {
            x[i] -= mult[i - 1] * x[i - 1];
        }
        x[n - 1] *= piv[n - 1];
        for i in (0..n - 1).rev() {
            x[i] = (x[i] - upper[i] * x[i + 1]) * piv[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_recovers_known_vector() {
        let mut a = Tridiag::zeros(5);
        for i in 0..5 {
            a.add_element(i, [[2.0, -1.0], [-1.0, 2.0]]);
        }
        let x: Vec<f64> = (0..5).map(|i| (i as f64).sin() + 1.0).collect();
        let mut b = vec![0.0; 5];
        a.mul_into(&x, &mut b);
        a.factor().unwrap().solve_in_place(&mut b);
        // A is well conditioned (cond < 20): round-off stays at a few ulps.
        for (u, v) in b.iter().zip(&x) {
            assert!((u - v).abs() < 1e-14);
        }
    }

    #[test]
    fn inertia_bisection_finds_the_largest_eigenvalue() {
        // K = tridiag(-1, 2, -1) of size n, M = I: eigenvalues 2 - 2 cos(kπ/(n+1)).
        let n = 7;
        let mut k = Tridiag::zeros(n);
        let mut m = Tridiag::zeros(n);
        for i in 0..n {
            k.diag[i] = 2.0;
            m.diag[i] = 1.0;
            if i + 1 < n {
                k.lower[i] = -1.0;
                k.upper[i] = -1.0;
            }
        }
        let exact = 2.0 - 2.0 * (n as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos();
        // Bisection to the last bit of the bracket: relative 1e-12 is loose.
        assert!((k.max_generalized_eigenvalue(&m) - exact).abs() < 1e-12 * exact);
    }
}
