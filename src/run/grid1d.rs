//! The discretisation of a 1D run: the mesh, the step and the method triple (contact treatment,
//! mass variant, time scheme) that the bar (contract §1.1, §1.4) and the frictional layer
//! (contract §1.7, two chains on one mesh) share.
//!
//! One value so the two configurations state it once: the layer's chains are bars of the same
//! grid, and tests and benches build either from the same six numbers.

use crate::space::{ContactMethod, MassVariant};
use crate::time::Scheme;

/// P1 elements on the body's height, a uniform step τ and its count, the contact treatment,
/// the mass variant and the scheme.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid1d {
    pub elements: usize,
    pub dt: f64,
    pub steps: usize,
    pub method: ContactMethod,
    pub mass: MassVariant,
    pub scheme: Scheme,
}

impl Grid1d {
    /// `elements` elements and step `dt` up to `t_final`, rounded up to a whole number of steps
    /// (the 1e-9 keeps T/τ that is whole up to round-off from gaining a step).
    pub fn new(
        elements: usize,
        dt: f64,
        t_final: f64,
        method: ContactMethod,
        mass: MassVariant,
        scheme: Scheme,
    ) -> Self {
        Self::with_steps(
            elements,
            dt,
            (t_final / dt - 1e-9).ceil() as usize,
            method,
            mass,
            scheme,
        )
    }

    /// As [`Grid1d::new`] with the step count given (the planner's, which has already rounded).
    pub fn with_steps(
        elements: usize,
        dt: f64,
        steps: usize,
        method: ContactMethod,
        mass: MassVariant,
        scheme: Scheme,
    ) -> Self {
        Self {
            elements,
            dt,
            steps,
            method,
            mass,
            scheme,
        }
    }
}
