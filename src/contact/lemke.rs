//! Lemke's complementary pivoting, and the 2D frictional condensed problem of Nitsche and the
//! penalty (contract §2.5) as a linear complementarity problem for it — the rescue that
//! `run::fe::nitsche`'s frictional solve tries last (issue 43).
//!
//! **Why.** The semismooth Newton on G(x) = x − x0 − cτ² W Λ(x) = 0 (`run::fe::nitsche`'s
//! header) minimises the merit ½|G|² along its steps and can settle in a local minimum of it
//! that is no root; its continuation in the friction bound follows the solution path from the
//! frictionless problem, and at μ_f of 3–5 that path folds (it turns back in the bound), where
//! a continuation in the bound stalls. The projected Gauss–Seidel is a descent too. Lemke's
//! method is a piecewise-linear homotopy in an artificial variable z₀ that follows the path
//! through its folds; on the issue 43 campaign's steps that every other stage failed, it ends
//! on a solution (measured: all five Coulomb steps, and Tresca with its onset ramp at 1e-8 of
//! the normal scale — contract §2.5's closure).
//!
//! **The LCP.** In 2D Λ is piecewise linear: per point q, with the forces λ = (λ_n, λ_t),
//!   λ_n ≥ 0 ⊥ (γ/w) λ_n − x_n + g ≥ 0                         (f_n = (1/γ)[x_n − g]_+),
//!   λ_t = w x_t − w (σ⁺ − σ⁻),  σ⁺ ≥ 0 ⊥ b − λ_t ≥ 0,  σ⁻ ≥ 0 ⊥ b + λ_t ≥ 0,
//! with the bound b = μ λ_n (Coulomb; w r = w μ_f f_n) or, for Tresca's ramp s·min(1, (x_n − g)/ε),
//! b = min(μ λ_n, c) with μ = s γ/ε, c = s w, written with a fourth variable
//! ρ ≥ 0 ⊥ ρ − μ λ_n + c ≥ 0 (ρ = [μλ_n − c]_+) and b = μ λ_n − ρ. With x = x0 + cτ² W λ the
//! tangential equation (D_w⁻¹ − cτ²W_tt) λ_t = x0_t + cτ² W_tn λ_n − σ⁺ + σ⁻ gives λ_t
//! linear in (λ_n, σ⁺, σ⁻) through B = (D_w⁻¹ − cτ²W_tt)⁻¹, and the rest is z = (λ_n, σ⁺, σ⁻[, ρ])
//! ≥ 0 ⊥ M z + q ≥ 0.
//!
//! **Numerics.** Points out of contact make the LCP degenerate (λ_n = λ_t = 0 leave σ^± one
//! free difference), on which the pivoting can stop on a secondary ray; q is perturbed by a
//! small positive multiple of its size (1 + i/n, distinct per row, as a lexicographic rule's
//! first term), and the rows and columns of M equilibrated. The perturbed problem's solution
//! is a start, not the answer: the caller polishes it with its Newton on the exact law and
//! accepts only what meets its tolerance. Dense: O(n²) per pivot on n = 3–4 × the points.

/// Lemke's algorithm on z ≥ 0, w = M z + q ≥ 0, zᵀw = 0 (M row-major n × n) with the
/// covering vector of ones: returns z, and the pivots made, or why it stopped (a secondary
/// ray — no conclusion on existence — or the pivot cap).
pub fn lemke(
    m: &[f64],
    q: &[f64],
    n: usize,
    max_pivots: usize,
) -> Result<(Vec<f64>, usize), String> {
    if q.iter().all(|&v| v >= 0.0) {
        return Ok((vec![0.0; n], 0));
    }
    // Tableau rows: w − M z − 1 z₀ = q; columns w (n), z (n), z₀, right-hand side.
    let cols = 2 * n + 2;
    let (z0, rhs) = (2 * n, 2 * n + 1);
    let mut t = vec![0.0; n * cols];
    for i in 0..n {
        t[i * cols + i] = 1.0;
        for j in 0..n {
            t[i * cols + n + j] = -m[i * n + j];
        }
        t[i * cols + z0] = -1.0;
        t[i * cols + rhs] = q[i];
    }
    let mut basis: Vec<usize> = (0..n).collect();
    let pivot = |t: &mut [f64], r: usize, c: usize| {
        let p = t[r * cols + c];
        for j in 0..cols {
            t[r * cols + j] /= p;
        }
        for i in (0..n).filter(|&i| i != r) {
            let f = t[i * cols + c];
            if f != 0.0 {
                for j in 0..cols {
                    t[i * cols + j] -= f * t[r * cols + j];
                }
            }
        }
    };
    // z₀ enters at the most negative q.
    let r = (0..n).fold(0, |b, i| if q[i] < q[b] { i } else { b });
    pivot(&mut t, r, z0);
    let mut leaving = basis[r];
    basis[r] = z0;
    for pivots in 1..=max_pivots {
        // The complement of the variable that left enters.
        let entering = if leaving < n {
            leaving + n
        } else {
            leaving - n
        };
        // Minimum ratio; ties to z₀ (it ends the path), then to the lower index.
        let mut best: Option<(usize, f64)> = None;
        for i in 0..n {
            let a = t[i * cols + entering];
            if a <= 1e-12 {
                continue;
            }
            let ratio = t[i * cols + rhs] / a;
            let better = match best {
                None => true,
                Some((b, br)) => {
                    ratio < br - 1e-14
                        || (ratio <= br + 1e-14
                            && (basis[i] == z0 || (basis[b] != z0 && basis[i] < basis[b])))
                }
            };
            if better {
                best = Some((i, ratio));
            }
        }
        let Some((r, _)) = best else {
            return Err(format!("Lemke: secondary ray after {pivots} pivots"));
        };
        pivot(&mut t, r, entering);
        leaving = basis[r];
        basis[r] = entering;
        if leaving == z0 {
            let mut z = vec![0.0; n];
            for (i, &b) in basis.iter().enumerate() {
                if (n..2 * n).contains(&b) {
                    z[b - n] = t[i * cols + rhs];
                }
            }
            return Ok((z, pivots));
        }
    }
    Err(format!("Lemke: no solution in {max_pivots} pivots"))
}

/// One step's 2D frictional condensed problem (module header): `nq` points of 2 unknowns
/// (x_n, x_t), point-major; W (2nq × 2nq, row-major) and cτ² as the Newton's.
pub struct Frictional2d<'a> {
    pub gap: &'a [f64],
    pub w: &'a [f64],
    pub gamma: &'a [f64],
    pub wm: &'a [f64],
    pub c_tau2: f64,
    pub x0: &'a [f64],
}

/// The bound of the tangential force (module header): Coulomb's b = μ λ_n, or Tresca's ramp
/// b = min(μ_q λ_n, c_q) with μ_q = s γ_q/ε and c_q = s w_q.
#[derive(Clone, Copy, Debug)]
pub enum Bound {
    Coulomb { mu: f64 },
    TrescaRamp { threshold: f64, width: f64 },
}

/// Solve the LCP of `p` with `bound` by [`lemke`], q perturbed by `perturb` × its size (module
/// header): the forces λ (point-major (λ_n, λ_t)) and the pivots made.
pub fn solve_2d(p: &Frictional2d, bound: Bound, perturb: f64) -> Result<(Vec<f64>, usize), String> {
    let nq = p.gap.len();
    let nu = 2 * nq;
    let c = p.c_tau2;
    let wm = |i: usize, j: usize| p.wm[i * nu + j];
    // B = (D_w⁻¹ − cτ² W_tt)⁻¹ applied to the right-hand sides a (x0_t), F (cτ² W_tn), B (I).
    let mut bi = vec![0.0; nq * nq];
    for i in 0..nq {
        for j in 0..nq {
            let diag = if i == j { 1.0 / p.w[i] } else { 0.0 };
            bi[i * nq + j] = diag - c * wm(2 * i + 1, 2 * j + 1);
        }
    }
    // Right-hand sides as columns: [x0_t | cτ² W_tn | I], solved at once.
    let k = 1 + 2 * nq;
    let mut rhs = vec![0.0; nq * k];
    for i in 0..nq {
        rhs[i * k] = p.x0[2 * i + 1];
        for j in 0..nq {
            rhs[i * k + 1 + j] = c * wm(2 * i + 1, 2 * j);
            rhs[i * k + 1 + nq + j] = if i == j { 1.0 } else { 0.0 };
        }
    }
    gauss_solve(&mut bi, nq, &mut rhs, k)?;
    let a = |i: usize| rhs[i * k];
    let f = |i: usize, j: usize| rhs[i * k + 1 + j];
    let b = |i: usize, j: usize| rhs[i * k + 1 + nq + j];
    let tresca = matches!(bound, Bound::TrescaRamp { .. });
    let nv = if tresca { 4 } else { 3 };
    let n = nv * nq;
    let (mut m, mut q) = (vec![0.0; n * n], vec![0.0; n]);
    for i in 0..nq {
        let mu = match bound {
            Bound::Coulomb { mu } => mu,
            Bound::TrescaRamp { threshold, width } => threshold * p.gamma[i] / width,
        };
        // cτ² W_nt times a, F's and B's columns: the normal row's coupling through λ_t.
        let wnt = |v: &dyn Fn(usize) -> f64| {
            (0..nq)
                .map(|r| c * wm(2 * i, 2 * r + 1) * v(r))
                .sum::<f64>()
        };
        q[i] = p.gap[i] - p.x0[2 * i] - wnt(&a);
        q[nq + i] = -a(i);
        q[2 * nq + i] = a(i);
        for j in 0..nq {
            let (wf, wb) = (wnt(&|r| f(r, j)), wnt(&|r| b(r, j)));
            let (diag, mu_ij) = if i == j {
                (p.gamma[i] / p.w[i], mu)
            } else {
                (0.0, 0.0)
            };
            let row = |v: usize| v * nq + i;
            m[row(0) * n + j] = diag - c * wm(2 * i, 2 * j) - wf;
            m[row(0) * n + nq + j] = wb;
            m[row(0) * n + 2 * nq + j] = -wb;
            m[row(1) * n + j] = mu_ij - f(i, j);
            m[row(1) * n + nq + j] = b(i, j);
            m[row(1) * n + 2 * nq + j] = -b(i, j);
            m[row(2) * n + j] = mu_ij + f(i, j);
            m[row(2) * n + nq + j] = -b(i, j);
            m[row(2) * n + 2 * nq + j] = b(i, j);
            if tresca && i == j {
                // b = μλ_n − ρ in the bound's rows; ρ ⊥ ρ − μλ_n + s w.
                m[row(1) * n + 3 * nq + j] = -1.0;
                m[row(2) * n + 3 * nq + j] = -1.0;
                m[row(3) * n + j] = -mu;
                m[row(3) * n + 3 * nq + j] = 1.0;
            }
        }
        if let Bound::TrescaRamp { threshold, .. } = bound {
            q[3 * nq + i] = threshold * p.w[i];
        }
    }
    // Equilibrate columns, then rows, by their largest entries; perturb q.
    let mut dc = vec![1.0; n];
    for (j, d) in dc.iter_mut().enumerate() {
        let mx = (0..n).fold(0.0f64, |s, i| s.max(m[i * n + j].abs()));
        if mx > 0.0 {
            *d = 1.0 / mx;
        }
    }
    for i in 0..n {
        let mx = (0..n).fold(0.0f64, |s, j| s.max((m[i * n + j] * dc[j]).abs()));
        let dr = if mx > 0.0 { 1.0 / mx } else { 1.0 };
        for j in 0..n {
            m[i * n + j] *= dr * dc[j];
        }
        q[i] *= dr;
    }
    let qmax = q.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    for (i, qi) in q.iter_mut().enumerate() {
        *qi += perturb * qmax * (1.0 + i as f64 / n as f64);
    }
    let (z, pivots) = lemke(&m, &q, n, 50 * n)?;
    let z: Vec<f64> = z.iter().zip(&dc).map(|(v, d)| v * d).collect();
    let mut lambda = vec![0.0; nu];
    for i in 0..nq {
        lambda[2 * i] = z[i];
        lambda[2 * i + 1] = a(i)
            + (0..nq)
                .map(|j| f(i, j) * z[j] - b(i, j) * (z[nq + j] - z[2 * nq + j]))
                .sum::<f64>();
    }
    Ok((lambda, pivots))
}

/// Gaussian elimination with partial pivoting of the n × n row-major `a`, solving for the k
/// right-hand sides in the columns of the n × k row-major `b` (overwritten).
fn gauss_solve(a: &mut [f64], n: usize, b: &mut [f64], k: usize) -> Result<(), String> {
    for col in 0..n {
        let piv = (col..n).fold(col, |p, i| {
            if a[i * n + col].abs() > a[p * n + col].abs() {
                i
            } else {
                p
            }
        });
        let pv = a[piv * n + col];
        if !(pv.abs() > 0.0 && pv.is_finite()) {
            return Err(format!("Lemke: singular tangential block at column {col}"));
        }
        if piv != col {
            for j in 0..n {
                a.swap(col * n + j, piv * n + j);
            }
            for j in 0..k {
                b.swap(col * k + j, piv * k + j);
            }
        }
        for i in col + 1..n {
            let l = a[i * n + col] / pv;
            if l == 0.0 {
                continue;
            }
            for j in col..n {
                a[i * n + j] -= l * a[col * n + j];
            }
            for j in 0..k {
                b[i * k + j] -= l * b[col * k + j];
            }
        }
    }
    for col in (0..n).rev() {
        for j in 0..k {
            let mut acc = b[col * k + j];
            for r in col + 1..n {
                acc -= a[col * n + r] * b[r * k + j];
            }
            b[col * k + j] = acc / a[col * n + col];
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 2 LCP with a known solution: M = [[2, 1], [1, 2]], q = (−5, −6) has z = (4/3, 7/3),
    /// w = 0 (both active); Lemke ends there in finitely many pivots (exact up to round-off of
    /// a few operations: 1e-14).
    #[test]
    fn lemke_solves_a_small_p_matrix_lcp() {
        let (z, pivots) = lemke(&[2.0, 1.0, 1.0, 2.0], &[-5.0, -6.0], 2, 100).unwrap();
        assert!((z[0] - 4.0 / 3.0).abs() < 1e-14 && (z[1] - 7.0 / 3.0).abs() < 1e-14);
        assert!(pivots <= 3);
    }

    /// One point pressed into the plane and pushed sideways (W = −I, so x = x0 − cτ²λ): with a
    /// large tangential predictor it slides, λ_t = μ λ_n, and λ_n solves
    /// (γ/w) λ_n = x0_n − cτ² λ_n − g. Exact to round-off (1e-12 relative after the
    /// perturbation 1e-9 and its polish-free reading: the LCP's solution moves by ≤ the
    /// perturbation × the equilibrated scale).
    #[test]
    fn a_sliding_point_takes_its_coulomb_bound() {
        let wm = [-1.0, 0.0, 0.0, -1.0];
        let p = Frictional2d {
            gap: &[0.0],
            w: &[1.0],
            gamma: &[1.0],
            wm: &wm,
            c_tau2: 1.0,
            x0: &[1.0, 10.0],
        };
        let (l, _) = solve_2d(&p, Bound::Coulomb { mu: 0.5 }, 1e-9).unwrap();
        // λ_n = x0_n/(γ/w + cτ²) = 0.5; λ_t = 0.25 (slides: w x_t = 10 − λ_t > 0.25).
        assert!((l[0] - 0.5).abs() < 1e-8, "{l:?}");
        assert!((l[1] - 0.25).abs() < 1e-8, "{l:?}");
    }
}
