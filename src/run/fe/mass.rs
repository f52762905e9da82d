//! The mass variants of contract §2.2 on the FE meshes: the consistent and lumped matrices and the
//! redistributions that move the contact layer's mass inward (massless contact dofs).

use super::bodies::body_weight;
use super::geometry::{FeMesh, Geometry};
use crate::scene::FeSetup;
use crate::space::MassVariant;
use crate::space::fe::{DofMap, ElementOp, Mesh, SymMatrix, assemble, fe_pattern};

/// How `mod2` and `mod3` put the mass of layer 0 back (contract §2.2): the weight of every other
/// layer (mod2) and the weight of layer 1 (mod3).
#[derive(Debug, Clone, Copy)]
pub(super) struct Redistribution {
    pub(super) mod2: f64,
    pub(super) mod3: f64,
}

impl Redistribution {
    /// Layers of equal mass m/L (the bars' box: uniform elements, as many per layer):
    /// mod2 = L/(L−1), mod3 = 2 — the 1D weights of 000 §3.
    pub(super) fn equal_layers(layers: usize) -> Redistribution {
        Redistribution {
            mod2: layers as f64 / (layers as f64 - 1.0),
            mod3: 2.0,
        }
    }

    /// From the measured masses: total m, layer 0 m₀, layer 1 m₁ (the disc/ball, whose layers
    /// differ): mod2 = m/(m − m₀), mod3 = 1 + m₀/m₁, so the total mass is conserved.
    pub(super) fn measured(total: f64, m0: f64, m1: f64) -> Redistribution {
        Redistribution {
            mod2: total / (total - m0),
            mod3: 1.0 + m0 / m1,
        }
    }
}

/// The element weight of layer `layer` (layer 0 touches Γ_C) for a mass variant (contract §2.2).
pub(super) fn layer_weight(mass: &MassVariant, layer: usize, r: Redistribution) -> f64 {
    match (mass, layer) {
        (
            MassVariant::Mod1 | MassVariant::Mod2 | MassVariant::Mod3 | MassVariant::Weights(_),
            0,
        ) => 0.0,
        (MassVariant::Mod2, _) => r.mod2,
        (MassVariant::Mod3, 1) => r.mod3,
        (MassVariant::Weights(w), k) => w[(k - 1).min(w.len() - 1)],
        _ => 1.0,
    }
}

/// 1ᵀM1 over one component of the mass assembled with the element weights `weight` on the full
/// dof set (clamped nodes included), leaving out the entries `zeroed(i, j)` (dofs).
pub(super) fn component_total(
    mesh: &dyn Mesh,
    rho: f64,
    weight: &dyn Fn(usize) -> f64,
    zeroed: &dyn Fn(usize, usize) -> bool,
) -> f64 {
    let d = mesh.dim();
    let all = DofMap::all(mesh.num_nodes() * d);
    let full_pattern = fe_pattern(mesh, &all);
    let full = assemble(mesh, &all, &full_pattern, ElementOp::Mass { rho }, weight);
    let mut total = 0.0;
    for j in (0..full_pattern.n).filter(|j| j % d == 0) {
        for k in full_pattern.col_ptr[j]..full_pattern.col_ptr[j + 1] {
            if !zeroed(full_pattern.row_idx[k], j) {
                total += full.values[k];
            }
        }
    }
    total
}

/// The run's mass matrix and 1ᵀM1 (per component: the total mass it represents).
pub(super) fn mass_matrix(
    g: &Geometry,
    s: &FeSetup,
    mass: &MassVariant,
) -> Result<(SymMatrix, f64), String> {
    let layers = g.mesh.num_layers();
    // Two bodies: each body the variant acts on needs its two layers (contract §2.6).
    let too_thin = match &g.bodies {
        Some(two) => (0..2).any(|b| two.mass_side.includes(b) && two.layer_counts[b] < 2),
        None => layers < 2,
    };
    if too_thin && mass.massless_contact() {
        return Err(format!(
            "mass = {} needs at least two element layers",
            mass.name()
        ));
    }
    let fm = &g.mesh;
    let mesh = fm.mesh();
    let never = |_: usize, _: usize| false;
    let redistribution = match fm {
        FeMesh::Ball(_) | FeMesh::Gmsh { .. }
            if matches!(mass, MassVariant::Mod2 | MassVariant::Mod3) =>
        {
            let layer_mass = |l: usize| {
                let w = |e: usize| f64::from(u8::from(fm.element_layer(e) == l));
                component_total(mesh, s.density, &w, &never)
            };
            let total = component_total(mesh, s.density, &|_| 1.0, &never);
            Redistribution::measured(total, layer_mass(0), layer_mass(1))
        }
        _ => Redistribution::equal_layers(layers),
    };
    // Two bodies: the densities in the weights (ρ = 1 in the element), each body with its own
    // redistribution ([`body_weight`]): equal layers on the blocks' lattice, the layers'
    // measured masses in a file (as one body's, above; the body's density cancels).
    let (weight, density): (Box<dyn Fn(usize) -> f64 + '_>, f64) = match (&g.bodies, fm) {
        (Some(two), FeMesh::Bodies { mesh: bm, .. }) => {
            let redistribution: [Redistribution; 2] = std::array::from_fn(|b| {
                let measured =
                    two.measured_layers && matches!(mass, MassVariant::Mod2 | MassVariant::Mod3);
                if !measured {
                    return Redistribution::equal_layers(two.layer_counts[b]);
                }
                let in_body = |e: usize, l: Option<usize>| {
                    bm.element_body(e) == b && l.is_none_or(|l| fm.element_layer(e) == l)
                };
                let mass_of = |l: Option<usize>| {
                    let w = |e: usize| f64::from(u8::from(in_body(e, l)));
                    component_total(mesh, 1.0, &w, &never)
                };
                Redistribution::measured(mass_of(None), mass_of(Some(0)), mass_of(Some(1)))
            });
            (
                Box::new(move |e: usize| {
                    let lw = |l: usize, b: usize| layer_weight(mass, l, redistribution[b]);
                    body_weight(two, bm.element_body(e), lw, fm.element_layer(e))
                }),
                1.0,
            )
        }
        _ => (
            Box::new(|e: usize| layer_weight(mass, fm.element_layer(e), redistribution)),
            s.density,
        ),
    };
    let rho = ElementOp::Mass { rho: density };
    let mut m = assemble(mesh, &g.dofs, &g.pattern, rho, &weight);
    match mass {
        MassVariant::Lumped => {
            let sums = m.row_sums();
            // Row-sum lumping of P2 simplices gives the vertices no mass (triangles: their rows
            // of the P2 mass matrix sum to 0) or a negative one (tetrahedra): the step then
            // has massless or anti-inertial dofs and blows up at the contact (the Hertz
            // half-disc, docs/methods.md). Refused rather than run.
            if let Some((i, x)) = sums.iter().enumerate().find(|(_, x)| **x <= 0.0) {
                return Err(format!(
                    "mass = lumped: row-sum lumping gives free dof {i} the mass {x:.3e} ≤ 0 (the vertices of P2 triangles and tetrahedra); use consistent or a modified mass, or degree-1 elements"
                ));
            }
            m = SymMatrix::diagonal_from(&g.pattern, &sums);
        }
        MassVariant::ZeroContact => {
            let p = &g.pattern;
            for j in 0..p.n {
                for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                    if g.on_contact_node[j] || g.on_contact_node[p.row_idx[k]] {
                        m.values[k] = 0.0;
                    }
                }
            }
        }
        _ => {}
    }
    // 1ᵀM1 over one component, clamped nodes included: assembled on the full dof set.
    let d = mesh.dim();
    let bottom_node = |dof: usize| g.contact_node[dof / d];
    let zeroed = |i: usize, j: usize| {
        matches!(mass, MassVariant::ZeroContact) && (bottom_node(i) || bottom_node(j))
    };
    let total = component_total(mesh, density, &weight, &zeroed);
    Ok((m, total))
}
