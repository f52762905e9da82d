//! Quadrature rules that are exact on *curved* degree-2 cells (contract §1.2, §1.6, issue 34), and
//! the test that tells a curved cell from an affine one.
//!
//! Why: on an affine cell the element integrands are polynomials of the shape functions' degree
//! (P2 mass: degree 4), but on a curved (isoparametric) cell det J is a polynomial too, and the
//! mass integrand N_a N_b det J gains its degree:
//!
//! | cell | det J | mass integrand | rule used on a curved cell |
//! |---|---|---|---|
//! | P2 triangle | 2 | 6 | collapsed Gauss, 4 × 4 points (degree 7) |
//! | P2 tetrahedron | 3 | 7 | collapsed Gauss, 4 × 4 × 4 points (degree 7) |
//! | Q1 hexahedron | 2 per variable | 4 per variable | Gauss–Legendre 3³ (degree 5) |
//! | Q2 quadrilateral | 3 per variable | 7 per variable | Gauss–Legendre 4² (degree 7) |
//! | Q2 hexahedron | 5 per variable | 9 per variable | Gauss–Legendre 5³ (degree 9) |
//!
//! (A Q1 quadrilateral's det J has degree 1 per variable, its mass degree 3: the 2-point rule is
//! exact on every Q1 quadrilateral.) The load ∫ρ f N_a det J has lower degree and is exact too.
//! The stiffness on a curved cell is rational (J⁻¹) and no rule is exact; a rule of the mass's
//! degree brings it within round-off of much higher-order rules (the disc's first contact force
//! moves by ≤ 1e-11 from degree 6 to 14, measured). Affine cells keep the cheaper rules of
//! the element kernels (`element.rs`, `simplex.rs`, which call this file), exact there — so the
//! bars' matrices, and every straight-sided cell's, are bit for bit those of before.
//!
//! The simplex rules are conical products (Stroud; the Duffy collapse): on the reference
//! triangle ξ = t, η = (1 − t)s with dξdη = (1 − t) dt ds, so a polynomial of degree p becomes a
//! polynomial of degree ≤ p in each of t and s, integrated exactly by n-point Gauss–Jacobi rules
//! in t (weight 1 − t) and Gauss–Legendre in s with 2n − 1 ≥ p; on the tetrahedron ζ = (1 − t)(1 −
//! s)r adds the weight (1 − t)²(1 − s). All weights are positive (a layer-weighted or lumped
//! mass stays semi-definite at every point). The one-dimensional Gauss–Jacobi rules are made by
//! Golub–Welsch (the eigenvalues of the Jacobi matrix) and polished by Newton's method on the
//! three-term recurrence, so they are accurate to round-off for any n.

use std::sync::OnceLock;

use nalgebra::{DMatrix, SymmetricEigen};

/// The n-point Gauss–Jacobi rule on [0, 1] for the weight (1 − t)^α (α = 0: Gauss–Legendre):
/// points and weights, exact for polynomials of degree ≤ 2n − 1 times the weight.
pub fn gauss_jacobi(n: usize, alpha: u32) -> Vec<(f64, f64)> {
    assert!(n >= 1, "a quadrature rule has at least one point");
    let a = f64::from(alpha);
    // Golub–Welsch on [−1, 1] for (1 − x)^α: diagonal a_k, off-diagonal b_k of the monic
    // Jacobi polynomials' recurrence (β = 0).
    let mut jm = DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        let kf = k as f64;
        let s = 2.0 * kf + a;
        jm[(k, k)] = if k == 0 {
            -a / (a + 2.0)
        } else {
            -a * a / (s * (s + 2.0))
        };
        if k + 1 < n {
            let k1 = kf + 1.0;
            let s1 = 2.0 * k1 + a;
            let b2 = 4.0 * k1 * (k1 + a) * k1 * (k1 + a) / (s1 * s1 * (s1 + 1.0) * (s1 - 1.0));
            jm[(k, k + 1)] = b2.sqrt();
            jm[(k + 1, k)] = b2.sqrt();
        }
    }
    let mut x: Vec<f64> = SymmetricEigen::new(jm)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    x.sort_by(f64::total_cmp);
    let mut out = Vec::with_capacity(n);
    for mut xi in x {
        // Newton on P_n^{(α,0)}; the eigenvalues are already within ~1e-15, two or three steps
        // bring them to the polynomial's own root.
        for _ in 0..4 {
            let (p, dp) = jacobi_and_derivative(n, a, xi);
            let dx = p / dp;
            xi -= dx;
            if dx.abs() <= 1e-16 * xi.abs().max(1.0) {
                break;
            }
        }
        let (_, dp) = jacobi_and_derivative(n, a, xi);
        // W_i = 2^{α+1} / ((1 − x_i²) P_n'(x_i)²) on [−1, 1] (β = 0, integer α), then t = (1 + x)/2
        // and (1 − x)^α dx = 2^{α+1} (1 − t)^α dt.
        let w = 2f64.powi(alpha as i32 + 1) / ((1.0 - xi * xi) * dp * dp);
        out.push((0.5 * (1.0 + xi), w / 2f64.powi(alpha as i32 + 1)));
    }
    out
}

/// P_n^{(α,0)}(x) and its derivative by the three-term recurrence.
fn jacobi_and_derivative(n: usize, a: f64, x: f64) -> (f64, f64) {
    let mut p0 = 1.0;
    let mut p1 = 0.5 * ((a + 2.0) * x + a);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let s = 2.0 * k + a;
        let c1 = 2.0 * k * (k + a) * (s - 2.0);
        let c2 = (s - 1.0) * (s * (s - 2.0) * x + a * a);
        let c3 = 2.0 * (k + a - 1.0) * (k - 1.0) * s;
        let p2 = (c2 * p1 - c3 * p0) / c1;
        p0 = p1;
        p1 = p2;
    }
    // (2n + α)(1 − x²) P_n' = n[α − (2n + α) x] P_n + 2(n + α) n P_{n−1}.
    let nf = n as f64;
    let s = 2.0 * nf + a;
    let dp = (nf * (a - s * x) * p1 + 2.0 * (nf + a) * nf * p0) / (s * (1.0 - x * x));
    (p1, dp)
}

/// The n-point Gauss–Legendre rule on [−1, 1] (exact to degree 2n − 1), for any n.
pub fn gauss_legendre_any(n: usize) -> Vec<(f64, f64)> {
    gauss_jacobi(n, 0)
        .into_iter()
        .map(|(t, w)| (2.0 * t - 1.0, 2.0 * w))
        .collect()
}

/// The conical-product rule on the reference simplex of dimension `d` (2 or 3) with `n` points
/// per direction: exact to degree 2n − 1, n^d positive weights summing to 1/d!; points padded
/// to 3 coordinates.
pub fn collapsed_simplex_rule(d: usize, n: usize) -> Vec<([f64; 3], f64)> {
    let leg = gauss_jacobi(n, 0);
    let j1 = gauss_jacobi(n, 1);
    match d {
        2 => {
            let mut out = Vec::with_capacity(n * n);
            for &(t, wt) in &j1 {
                for &(s, ws) in &leg {
                    out.push(([t, (1.0 - t) * s, 0.0], wt * ws));
                }
            }
            out
        }
        3 => {
            let j2 = gauss_jacobi(n, 2);
            let mut out = Vec::with_capacity(n * n * n);
            for &(t, wt) in &j2 {
                for &(s, ws) in &j1 {
                    for &(r, wr) in &leg {
                        let y = (1.0 - t) * s;
                        let z = (1.0 - t) * (1.0 - s) * r;
                        out.push(([t, y, z], wt * ws * wr));
                    }
                }
            }
            out
        }
        _ => unreachable!("simplices exist in 2D and 3D only"),
    }
}

/// The rule of a curved P2 simplex (module header): degree 6 needed on triangles, 7 on
/// tetrahedra; 4 points per direction give degree 7 for both. Made once.
pub fn curved_simplex_rule(d: usize) -> &'static [([f64; 3], f64)] {
    static TRI: OnceLock<Vec<([f64; 3], f64)>> = OnceLock::new();
    static TET: OnceLock<Vec<([f64; 3], f64)>> = OnceLock::new();
    match d {
        2 => TRI.get_or_init(|| collapsed_simplex_rule(2, 4)),
        3 => TET.get_or_init(|| collapsed_simplex_rule(3, 4)),
        _ => unreachable!("simplices exist in 2D and 3D only"),
    }
}

/// Gauss points per direction on a curved tensor cell with `n1` nodes per axis (module header).
pub const fn curved_tensor_points(d: usize, n1: usize) -> usize {
    match (d, n1) {
        // Q1 quadrilateral: mass of degree 3 per variable on any cell.
        (2, 2) => 2,
        (3, 2) => 3,
        (2, 3) => 4,
        (3, 3) => 5,
        _ => panic!("tensor cells are Q1 or Q2 in 2D or 3D"),
    }
}

/// Whether the isoparametric map of a cell is affine: its Jacobian, a polynomial of degree ≤ 1
/// on P2 simplices and of degree ≤ p per variable (≤ p − 1 in its own) on Q_p cells, takes one
/// value at the given reference points (the simplex's vertices; every tensor node), which
/// determine it. Relative tolerance 1e-12 of the Jacobian's size: a cell that close to affine
/// is integrated by the affine rule with an error far below 1e-13 of its mass.
pub fn is_affine<const D: usize>(jacobians: impl Iterator<Item = [[f64; D]; D]>) -> bool {
    let mut first: Option<[[f64; D]; D]> = None;
    let mut scale = 0.0f64;
    let mut spread = 0.0f64;
    for j in jacobians {
        match first {
            None => {
                scale = j.iter().flatten().fold(0.0, |m, x| m.max(x.abs()));
                first = Some(j);
            }
            Some(f) => {
                for (a, b) in j.iter().flatten().zip(f.iter().flatten()) {
                    spread = spread.max((a - b).abs());
                }
            }
        }
    }
    spread <= 1e-12 * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exact_simplex_monomial(d: usize, e: [u32; 3]) -> f64 {
        // ∫ ξ^a η^b ζ^c over the reference simplex = a! b! c! / (a + b + c + d)!.
        let f = |k: u32| (1..=k).map(f64::from).product::<f64>();
        let s: u32 = e.iter().sum();
        f(e[0]) * f(e[1]) * f(e[2]) / f(s + d as u32)
    }

    #[test]
    fn gauss_jacobi_rules_are_exact_to_degree_2n_minus_1() {
        // ∫_0^1 t^k (1 − t)^α dt = k! α! / (k + α + 1)!: a wrong node or weight shows at ~1e-10
        // or worse; the rules are built to round-off, and t^k (up to 19 products) with a sum of
        // ≤ 10 terms adds ~20 ulp: 1e-14 relative.
        let f = |k: u32| (1..=k).map(f64::from).product::<f64>();
        for alpha in 0..=2u32 {
            for n in 1..=10usize {
                let rule = gauss_jacobi(n, alpha);
                for k in 0..(2 * n as u32) {
                    let q: f64 = rule.iter().map(|&(t, w)| w * t.powi(k as i32)).sum();
                    let exact = f(k) * f(alpha) / f(k + alpha + 1);
                    assert!(
                        (q - exact).abs() <= 1e-14 * exact,
                        "α = {alpha}, n = {n}, k = {k}: {q} vs {exact}"
                    );
                }
                assert!(rule.iter().all(|&(t, w)| w > 0.0 && t > 0.0 && t < 1.0));
            }
        }
    }

    #[test]
    fn legendre_rules_equal_the_tabulated_ones() {
        // The tabulated 1…6-point rules of `element::gauss_legendre` carry 16 digits.
        for n in 1..=6 {
            let a = gauss_legendre_any(n);
            let b = super::super::element::gauss_legendre(n);
            for (p, q) in a.iter().zip(b) {
                assert!(
                    (p.0 - q.0).abs() < 4e-16 && (p.1 - q.1).abs() < 4e-16,
                    "n = {n}"
                );
            }
        }
    }

    #[test]
    fn collapsed_rules_are_exact_to_their_degree() {
        for (d, n) in [(2, 4), (3, 4), (2, 8), (3, 6)] {
            let rule = collapsed_simplex_rule(d, n);
            let deg = 2 * n as u32 - 1;
            for a in 0..=deg {
                for b in 0..=deg - a {
                    for c in 0..=if d == 3 { deg - a - b } else { 0 } {
                        let q: f64 = rule
                            .iter()
                            .map(|&(p, w)| {
                                w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)
                            })
                            .sum();
                        let exact = exact_simplex_monomial(d, [a, b, c]);
                        assert!(
                            (q - exact).abs() <= 1e-14 * exact,
                            "d = {d}, n = {n}, ξ^{a} η^{b} ζ^{c}: {q} vs {exact}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn affine_test_tells_a_constant_jacobian() {
        let j = [[1.0, 0.2], [0.0, 0.9]];
        assert!(is_affine([j, j, j].into_iter()));
        let bent = [[1.0, 0.2], [1e-9, 0.9]];
        assert!(!is_affine([j, bent, j].into_iter()));
    }
}
