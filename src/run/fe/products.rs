//! Quadratic forms and dot products of the engine's loops, summed in one fixed order (the
//! observers' energies and the reference errors depend on it bit for bit).

use crate::space::fe::SymMatrix;

/// xᵀAx with `tmp` as scratch.
pub(super) fn quad(a: &SymMatrix, x: &[f64], tmp: &mut [f64]) -> f64 {
    a.matvec_into(x, tmp);
    dot(x, tmp)
}

/// xᵀy summed in order from −0.0 (the iterator sum's arithmetic, which the fused passes of
/// the time loop repeat).
pub(super) fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(p, q)| p * q).sum()
}
