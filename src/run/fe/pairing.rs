//! The non-matching pairings of `mixed` and `penalty` between the two blocks (contract §2.6;
//! issue 45): the faces Γ^a (A's bottom) and Γ^b (B's top) as [`Surface`]s with their maps to
//! the bodies' global nodes, and the contact rows they make:
//!
//! - `node-to-segment` (one pass, A the slave): row i = e_{a,i,d} − Σ_j N_j(ξ_i) e_{b,j,d}, ξ_i
//!   the projection Π of Γ^a's node i on Γ^b's faces, its gap (Π(x_i) − x_i)·n and its weight
//!   w_i = ∫_Γa φ_i;
//! - `mortar`: row k = (Σ_i D_ki e_{a,i,d} − Σ_j M_kj e_{b,j,d})/∫ψ_k, gap ∫ψ_k g/∫ψ_k, weight
//!   ∫ψ_k, with D and M on the segmentation (`interface_quadrature = "segment"`) or with Γ^a's
//!   face rule (`"element"`).
//!
//! Why a mortar row is divided by ∫ψ_k: the constraint g̃_k ≤ 0 and its complementarity do
//! not change under a positive scale, and the scaled row is a relative displacement with a gap
//! in length units like every other row, so the multiplier of row k is λ_k∫ψ_k and the engine's
//! contact pressure (multiplier over the row's weight) is the mortar coefficient λ_k itself;
//! the penalty's row force w_k κ[δ_k − g_k]_+ on the scaled row is κ[g̃_k]_+/∫ψ_k through the
//! mortar rows (contract §2.6), its pressure κ[δ_k − g_k]_+ = λ_k. Π and the segmentation are
//! computed once, in the reference configuration, with the projector's bin grid (set-up
//! linear in the interface).
//!
//! The blocks' faces lie on one plane x_d = H_b (the run's gap is added to the rows), so the
//! surfaces are built on that plane exactly, from the node indices: the reference gaps are 0
//! with no coordinate round-off.

use super::rows::RowEntries;
use crate::scene::{Blocks, InterfaceQuadrature, Pairing};
use crate::space::fe::BoxMesh;
use crate::space::fe::interface::{
    Basis, FaceKind, Projector, Surface, face_integrals, mortar_matrices, mortar_matrices_element,
    segment,
};

/// The interface keys of a run (contract §2.6): `pairing`, `mortar_basis`,
/// `interface_quadrature` — the blocks' or a two-body file's.
#[derive(Debug, Clone, Copy)]
pub(super) struct InterfaceKeys {
    pub(super) pairing: Pairing,
    pub(super) basis: Basis,
    pub(super) quadrature: InterfaceQuadrature,
}

impl InterfaceKeys {
    pub(super) fn of_blocks(b: &Blocks) -> InterfaceKeys {
        InterfaceKeys {
            pairing: b.pairing,
            basis: b.mortar_basis,
            quadrature: b.interface_quadrature,
        }
    }
}

/// One face of the interface: the surface and, per surface node, its global node.
pub(super) struct Side {
    pub(super) surface: Surface,
    pub(super) global: Vec<usize>,
}

/// The rows of a projecting pairing over global nodes (module header).
pub(super) struct GeneralRows {
    pub(super) rows: Vec<RowEntries>,
    /// The Γ^a node each row belongs to (its vertical dof is the row's contact dof).
    pub(super) a_node: Vec<usize>,
    /// Each row's reference gap (beyond the run's) and weight (∫φ_i or ∫ψ_k).
    pub(super) height: Vec<f64>,
    pub(super) weight: Vec<f64>,
    /// Γ^b's nodes (the massless variants' layer on B).
    pub(super) b_nodes: Vec<usize>,
}

/// The face of box `mesh` at vertical index `level` as a surface on the plane x_d = `plane`:
/// segments in 2D, quadrilaterals in 3D, ordered so the normal is −e_d (`down`, A's bottom) or
/// +e_d (B's top); `global(n)` maps the box's node to the joined mesh's.
pub(super) fn box_face(
    mesh: &BoxMesh,
    level: usize,
    plane: f64,
    down: bool,
    global: impl Fn(usize) -> usize,
) -> Result<Side, String> {
    let d = mesh.dim;
    let n = mesh.cells[0];
    let m = if d == 3 { mesh.cells[1] } else { 0 };
    let id = |i: usize, j: usize| {
        let mut idx = [i, j, 0];
        idx[d - 1] = level;
        mesh.node_id(idx)
    };
    let (mut coords, mut nodes) = (Vec::new(), Vec::new());
    for j in 0..=m {
        for i in 0..=n {
            let node = id(i, j);
            let mut x = mesh.coords[node];
            x[d - 1] = plane;
            coords.push(x);
            nodes.push(global(node));
        }
    }
    let s = |i: usize, j: usize| i + (n + 1) * j;
    let mut conn = Vec::new();
    let kind = if d == 2 {
        for i in 0..n {
            let (l, r) = (s(i, 0), s(i + 1, 0));
            conn.extend(if down { [l, r] } else { [r, l] });
        }
        FaceKind::Seg2
    } else {
        for j in 0..m {
            for i in 0..n {
                let q = [s(i, j), s(i + 1, j), s(i + 1, j + 1), s(i, j + 1)];
                // x_ξ × x_η along the first and last edges: e_x × e_y = +e_d; reversed, −e_d.
                conn.extend(if down { [q[0], q[3], q[2], q[1]] } else { q });
            }
        }
        FaceKind::Quad4
    };
    let side = if down { 'a' } else { 'b' };
    let surface = Surface::new(side, kind, coords, conn).map_err(|e| e.to_string())?;
    Ok(Side {
        surface,
        global: nodes,
    })
}

/// The rows of `b.pairing` (node-to-segment or mortar) between Γ^a and Γ^b (module header);
/// `reach` bounds Π's search (no Γ^a point may lie farther from Γ^b).
pub(super) fn general_rows(
    b: InterfaceKeys,
    a: &Side,
    bside: &Side,
    reach: f64,
) -> Result<GeneralRows, String> {
    let proj = Projector::new(&bside.surface, reach);
    let sa = &a.surface;
    let normal = sa.normal(0);
    let gap = |x: [f64; 3], y: [f64; 3]| (0..3).map(|c| (y[c] - x[c]) * normal[c]).sum::<f64>();
    let b_nodes = bside.global.clone();
    let mut out = GeneralRows {
        rows: Vec::new(),
        a_node: a.global.clone(),
        height: Vec::new(),
        weight: Vec::new(),
        b_nodes,
    };
    match b.pairing {
        Pairing::NodeToSegment => {
            out.weight = face_integrals(sa);
            for x in &sa.coords {
                let p = proj.project(*x).map_err(|e| e.to_string())?;
                let n = bside.surface.kind.shape(p.xi);
                let bs = bside.surface.face(p.face);
                // Exact zeros (Π on a node or an edge) add no entry.
                let entries = bs
                    .iter()
                    .zip(n)
                    .filter(|(_, nj)| *nj != 0.0)
                    .map(|(&j, nj)| (bside.global[j], -nj))
                    .collect();
                out.rows.push((Vec::new(), entries));
                out.height.push(gap(*x, p.point));
            }
            for (row, &g) in out.rows.iter_mut().zip(&a.global) {
                row.0.push((g, 1.0));
            }
        }
        Pairing::Mortar => {
            let m = match b.quadrature {
                InterfaceQuadrature::Segment => {
                    let seg = segment(sa, &proj).map_err(|e| e.to_string())?;
                    mortar_matrices(sa, &bside.surface, &seg, b.basis)
                }
                InterfaceQuadrature::Element => mortar_matrices_element(sa, &proj, b.basis),
            }
            .map_err(|e| e.to_string())?;
            for k in 0..sa.num_nodes() {
                let psi = m.psi_integral[k];
                if psi <= 0.0 {
                    return Err(format!(
                        "mortar row of Γ^a's node at {:?}: ∫ψ_k = {psi:e} (Γ^b does not cover its faces)",
                        sa.coords[k]
                    ));
                }
                let ar = m.d.row(k).map(|(i, v)| (a.global[i], v / psi)).collect();
                let br =
                    m.m.row(k)
                        .map(|(j, v)| (bside.global[j], -v / psi))
                        .collect();
                out.rows.push((ar, br));
                out.height.push(m.weighted_gap[k] / psi);
                out.weight.push(psi);
            }
        }
        Pairing::NodeToNode => unreachable!("node-to-node pairs are matched by index"),
    }
    Ok(out)
}
