//! Two bodies as engine data (contract §1.10, §2.6; issue 44): the blocks' meshes joined into one
//! numbering ([`BodiesMesh`]: A's nodes, then B's), each body's material in its block of K,
//! and the contact pair A–B as node-to-node rows B_i = e_{a,i,d} − e_{b,π(i),d} ([`Rows`]).
//!
//! A body is (mesh, material, density, mass layers, initial velocity); a pair is the list of
//! (Γ^a node, Γ^b node) it matches; the rows are what the condensed solve takes. Nothing here
//! is a time loop: every scheme and §3.2 method runs two bodies through the rows, the one-body
//! scenes being the case of unit rows against the obstacle.

use std::sync::Arc;

use super::nitsche_interface::PairFaces;
use super::nitsche_pair::{blocks_interface, pair_points};
use super::pairing::{GeneralRows, InterfaceKeys, box_face, general_rows};
use super::rows::{RowEntries, Rows};
use crate::run::Metrics;
use crate::scene::{Blocks, FeSetup, MassSide, Pairing};
use crate::space::fe::element::q1_gradient_at;
use crate::space::fe::nitsche::ContactPoint;
use crate::space::fe::{
    BodiesMesh, BoxMesh, DofMap, ElementOp, Mesh, Pattern, SymMatrix, assemble, fe_pattern,
};

/// What a second body adds to a geometry.
#[derive(Debug)]
pub(super) struct TwoBodies {
    /// The body (0 = A, 1 = B) of each reduced dof.
    pub(super) body: Vec<u8>,
    /// Element layers of each body (layer 0 touches the body's own contact face).
    pub(super) layer_counts: [usize; 2],
    /// Each body's density and Lamé coefficients (λ, μ).
    pub(super) density: [f64; 2],
    pub(super) lame: [(f64, f64); 2],
    /// B's initial e_d velocity (A's is the run's `velocity`).
    pub(super) velocity_b: f64,
    /// A node clamped (B's base, `far_end = "clamped"`, or a mesh's `clamped` group): no
    /// momentum invariant.
    pub(super) base_clamped: bool,
    pub(super) mass_side: MassSide,
    /// The traction −p e_d on A's top face (its loaded face) as forces on the reduced dofs
    /// (None: p = 0), and p.
    pub(super) pressure: Option<Vec<f64>>,
    pub(super) pressure_value: f64,
    /// Each body's extent along e_d (H_a, H_b): the pressure's energy unit (contract §1.10).
    pub(super) heights: [f64; 2],
    /// `mod2`/`mod3` put layer 0's mass back by the layers' measured masses (a file's unequal
    /// layers), not by equal layers (the blocks' lattice).
    pub(super) measured_layers: bool,
    /// Nitsche's points of Γ^a and Γ^b, each with both bodies' traces and unit side weight
    /// ([`super::nitsche_pair`]; dofs reduced by the geometry). Built for the blocks' boxes;
    /// empty where the interface is general (a file's faces, non-matching blocks): then
    /// `interface` places them when a Nitsche run is factored.
    pub(super) nitsche_points: [Vec<ContactPoint>; 2],
    /// Γ^a's and Γ^b's faces for Nitsche's points on a general interface
    /// ([`super::nitsche_interface`]), or why there are none (a file whose contact groups
    /// hold no faces: `mixed` and `penalty` still run).
    pub(super) interface: Result<PairFaces, String>,
}

/// The parts of a two-body geometry ([`super::geometry::build_bodies`] makes the
/// [`super::geometry::Geometry`]).
pub(super) struct BlocksParts {
    pub(super) mesh: BodiesMesh,
    /// Mass layer of each element within its body.
    pub(super) layers: Vec<usize>,
    pub(super) dofs: DofMap,
    pub(super) pattern: Arc<Pattern>,
    pub(super) k: SymMatrix,
    /// A's Γ^a vertical dofs (reduced) in row order, and the rows.
    pub(super) contact: Vec<usize>,
    pub(super) rows: Rows,
    /// Each row's initial gap beyond the run's `gap` (the file's shape of the interface; 0 for
    /// the blocks).
    pub(super) contact_height: Vec<f64>,
    /// Weights of the Γ^a nodes (sum 1, ∫_Γa φ_i/|Γ^a|) and |Γ^a|.
    pub(super) contact_weight: Vec<f64>,
    pub(super) contact_measure: f64,
    /// Global nodes whose mass a massless variant removes (both faces, per `mass_side`).
    pub(super) contact_node: Vec<bool>,
    /// The penalty's node-to-node rows as contact points ([`node_rows_as_points`]).
    pub(super) points: Vec<ContactPoint>,
    pub(super) two: TwoBodies,
}

/// Two bodies as data (issue 44's design): the joined mesh, what is clamped, the matched
/// pairs with their weights, and each body's material — whatever made them (the blocks'
/// boxes, a Gmsh file). [`bodies_parts`] turns it into the engine's parts.
pub(super) struct BodiesSpec {
    pub(super) mesh: BodiesMesh,
    /// Each element's mass layer within its body, and each body's layer count.
    pub(super) layers: Vec<usize>,
    pub(super) layer_counts: [usize; 2],
    /// Per global node: every component fixed.
    pub(super) clamped: Vec<bool>,
    /// (Γ^a node, Γ^b node), global ids, one per row; each row's gap beyond the run's, its
    /// weight (sum 1) and its γ = h (the penalty's size), and |Γ^a|. A projecting pairing
    /// (node-to-segment, mortar: `general`) gives its rows instead of the pairs, one per Γ^a
    /// node, with these gaps and weights.
    pub(super) pairs: Vec<(usize, usize)>,
    pub(super) general: Option<GeneralRows>,
    pub(super) height: Vec<f64>,
    pub(super) weight: Vec<f64>,
    pub(super) row_h: Vec<f64>,
    pub(super) measure: f64,
    /// A's loaded face: (node, weight, sum 1) and its measure, where `pressure` acts.
    pub(super) loaded: Vec<(usize, f64)>,
    pub(super) loaded_measure: f64,
    pub(super) heights: [f64; 2],
    pub(super) measured_layers: bool,
    /// B's material and velocity, which side the mass variant acts on, p.
    pub(super) density_b: f64,
    pub(super) lame_b: (f64, f64),
    pub(super) velocity_b: f64,
    pub(super) mass_side: MassSide,
    pub(super) pressure: f64,
}

/// Trapezoidal weight of a face node of a box with `cells` across: ½ per end of each axis.
fn face_weight(idx: [usize; 3], cells: &[usize], d: usize) -> f64 {
    (0..d - 1)
        .map(|a| {
            if idx[a] == 0 || idx[a] == cells[a] {
                0.5
            } else {
                1.0
            }
        })
        .product()
}

/// The two blocks of `s` (contract §1.10): B = [0, W]^{d−1} × [0, H_b] (body 1), A the box of
/// height H_a placed on B's top (body 0; the gap is the run's, in the rows, so every gap shares
/// the geometry), Q1, the same elements across so every Γ^a node lies above a Γ^b node.
pub(super) fn blocks_parts(s: &FeSetup, b: &Blocks) -> Result<BlocksParts, String> {
    let d = s.dim;
    let mut ext = vec![b.width; d];
    let mut cells = vec![b.across; d];
    ext[d - 1] = b.height_a;
    cells[d - 1] = b.cells_a;
    let mut mesh_a = BoxMesh::try_new(&ext, &cells).map_err(|e| e.to_string())?;
    mesh_a
        .coords
        .iter_mut()
        .for_each(|c| c[d - 1] += b.height_b);
    let cells_a = cells.clone();
    ext[d - 1] = b.height_b;
    cells = vec![b.across_b; d];
    cells[d - 1] = b.cells_b;
    let mesh_b = BoxMesh::try_new(&ext, &cells).map_err(|e| e.to_string())?;
    let mesh = BodiesMesh::new(&[&mesh_a, &mesh_b]);
    let b0 = mesh.node(1, 0);
    let clamped = (0..mesh.num_nodes())
        .map(|n| b.base_clamped && n >= b0 && mesh_b.node_index(n - b0)[d - 1] == 0)
        .collect();
    // Layers from each body's contact face: A's bottom rows upward, B's top rows downward.
    let (ea, eb) = (mesh_a.num_elements(), mesh_b.num_elements());
    let layers: Vec<usize> = (0..ea)
        .map(|e| mesh_a.element_layer(e))
        .chain((0..eb).map(|e| b.cells_b - 1 - mesh_b.element_layer(e)))
        .collect();
    let a_face = mesh_a.nodes_on_plane(d - 1, 0);
    // π(i): the node of B's top face with the same horizontal index; on a non-matching
    // interface (Nitsche's, whose forces are its points) the nearest one, for the observables'
    // rows only (u_contact_b, max_penetration).
    let matching = b.across_b == b.across;
    let partner = |n: usize| {
        let mut idx = mesh_a.node_index(n);
        if !matching {
            for i in idx.iter_mut().take(d - 1) {
                *i = (*i as f64 * b.across_b as f64 / b.across as f64).round() as usize;
            }
        }
        idx[d - 1] = b.cells_b;
        mesh.node(1, mesh_b.node_id(idx))
    };
    let mut weight: Vec<f64> = a_face
        .iter()
        .map(|&n| face_weight(mesh_a.node_index(n), &cells_a, d))
        .collect();
    let total: f64 = weight.iter().sum();
    weight.iter_mut().for_each(|w| *w /= total);
    let mut measure: f64 = b.width.powi(d as i32 - 1);
    let loaded_measure = measure;
    let (pairs, general) = if b.pairing == Pairing::NodeToNode {
        (a_face.iter().map(|&n| (n, partner(n))).collect(), None)
    } else {
        let side_a = box_face(&mesh_a, 0, b.height_b, true, |n| mesh.node(0, n))?;
        let side_b = box_face(&mesh_b, b.cells_b, b.height_b, false, |n| mesh.node(1, n))?;
        // Π's reach: the faces coincide (gap 0 in the reference configuration), so any point
        // of Γ^a is within round-off of Γ^b; half an element leaves room and finds one face.
        let reach = 0.5 * b.width / b.across.max(b.across_b) as f64;
        let rows = general_rows(InterfaceKeys::of_blocks(b), &side_a, &side_b, reach)?;
        // |Γ^a| as the rows' weights sum it, so weight·measure is each row's ∫φ_i or ∫ψ_k.
        measure = rows.weight.iter().sum();
        weight = rows.weight.iter().map(|w| w / measure).collect();
        (Vec::new(), Some(rows))
    };
    let rows_len = weight.len();
    let loaded = mesh_a
        .nodes_on_plane(d - 1, b.cells_a)
        .into_iter()
        .map(|n| (n, face_weight(mesh_a.node_index(n), &cells_a, d) / total))
        .collect();
    let h = b.width / b.across as f64;
    let lame = [(s.lame_lambda, s.lame_mu), (b.lame_lambda_b, b.lame_mu_b)];
    // Nitsche's points: the matching path, or the general interface's, placed when a Nitsche
    // run is factored (`run::fe::nitsche_interface`).
    let (nitsche_points, interface) = if matching {
        (pair_points(&mesh_a, &mesh_b, b0, lame), None)
    } else {
        (Default::default(), Some(blocks_interface(&mesh_a, &mesh_b)))
    };
    let mut parts = bodies_parts(
        s,
        BodiesSpec {
            layers,
            layer_counts: [b.cells_a, b.cells_b],
            clamped,
            height: general
                .as_ref()
                .map_or_else(|| vec![0.0; rows_len], |g| g.height.clone()),
            row_h: vec![h; rows_len],
            pairs,
            general,
            weight,
            measure,
            loaded,
            loaded_measure,
            heights: [b.height_a, b.height_b],
            measured_layers: false,
            density_b: b.density_b,
            lame_b: (b.lame_lambda_b, b.lame_mu_b),
            velocity_b: b.velocity_b,
            mass_side: b.mass_side,
            pressure: b.pressure,
            mesh,
        },
    )?;
    parts.two.nitsche_points = nitsche_points;
    if let Some(faces) = interface {
        parts.two.interface = Ok(faces);
    }
    Ok(parts)
}

/// The engine's parts of two bodies ([`BodiesSpec`]): dofs (the clamped nodes removed), the
/// pattern, K with each body's material in its own block, the node-to-node rows
/// B_i = e_{a,i,d} − e_{b,π(i),d}, the massless nodes of `mass_side`, the pressure's forces
/// and the penalty's rows as points.
pub(super) fn bodies_parts(s: &FeSetup, spec: BodiesSpec) -> Result<BlocksParts, String> {
    let d = s.dim;
    let mesh = spec.mesh;
    let nn = mesh.num_nodes();
    let b_node = |n: usize| mesh.node_body(n) == 1;
    let dofs = DofMap::new(nn * d, |g| spec.clamped[g / d]);
    let pattern = fe_pattern(&mesh, &dofs);
    let body_of = |e: usize| mesh.element_body(e);
    // Each body's material in its own block (the blocks do not couple).
    let stiffness = |lambda: f64, mu: f64, body: usize| {
        let w = move |e: usize| f64::from(u8::from(body_of(e) == body));
        assemble(
            &mesh,
            &dofs,
            &pattern,
            ElementOp::Stiffness { lambda, mu },
            &w,
        )
    };
    let (lambda_b, mu_b) = spec.lame_b;
    let k = SymMatrix::lin_comb(
        1.0,
        &stiffness(s.lame_lambda, s.lame_mu, 0),
        1.0,
        &stiffness(lambda_b, mu_b, 1),
    );
    let free = |n: usize| {
        dofs.free_index(n * d + d - 1)
            .ok_or_else(|| format!("contact node {n} is clamped"))
    };
    let mut pairs = Vec::with_capacity(spec.pairs.len());
    for &(a, b) in &spec.pairs {
        pairs.push((free(a)?, free(b)?));
    }
    let mut contact: Vec<usize> = pairs.iter().map(|p| p.0).collect();
    let mut contact_node = vec![false; nn];
    for &(a, b) in &spec.pairs {
        contact_node[a] |= spec.mass_side.includes(0);
        contact_node[b] |= spec.mass_side.includes(1);
    }
    let rows = match &spec.general {
        None => Rows::pairs(&pairs),
        Some(g) => {
            contact = g
                .a_node
                .iter()
                .map(|&a| free(a))
                .collect::<Result<_, _>>()?;
            for &a in &g.a_node {
                contact_node[a] |= spec.mass_side.includes(0);
            }
            for &b in &g.b_nodes {
                contact_node[b] |= spec.mass_side.includes(1);
            }
            let on_dofs = |e: &[(usize, f64)]| -> Result<Vec<(usize, f64)>, String> {
                e.iter().map(|&(n, c)| Ok((free(n)?, c))).collect()
            };
            let rows: Vec<RowEntries> = g
                .rows
                .iter()
                .map(|(a, b)| Ok((on_dofs(a)?, on_dofs(b)?)))
                .collect::<Result<_, String>>()?;
            Rows::general(&rows)
        }
    };
    let body = dofs.free.iter().map(|&g| u8::from(b_node(g / d))).collect();
    // −p ∫φ_i on A's loaded nodes: the weights times the face's measure.
    let pressure = if spec.pressure != 0.0 {
        let mut f = vec![0.0; dofs.n_free()];
        for &(n, w) in &spec.loaded {
            if let Some(r) = dofs.free_index(n * d + d - 1) {
                f[r] = -spec.pressure * w * spec.loaded_measure;
            }
        }
        Some(f)
    } else {
        None
    };
    let points = rows_as_points(
        &rows,
        (&spec.weight, &spec.height),
        spec.measure,
        &spec.row_h,
    );
    Ok(BlocksParts {
        points,
        layers: spec.layers,
        dofs,
        pattern,
        k,
        rows,
        contact,
        contact_height: spec.height,
        contact_weight: spec.weight,
        contact_measure: spec.measure,
        contact_node,
        two: TwoBodies {
            body,
            layer_counts: spec.layer_counts,
            density: [s.density, spec.density_b],
            lame: [(s.lame_lambda, s.lame_mu), spec.lame_b],
            velocity_b: spec.velocity_b,
            base_clamped: spec.clamped.iter().any(|&c| c),
            mass_side: spec.mass_side,
            pressure,
            pressure_value: spec.pressure,
            heights: spec.heights,
            measured_layers: spec.measured_layers,
            nitsche_points: [Vec::new(), Vec::new()],
            interface: Err("the interface's faces were not given".to_string()),
        },
        mesh,
    })
}

/// The rows of `penalty` (contract §2.6) in the form the engine's Nitsche/penalty operators
/// take ([`super::nitsche::NitscheOps::penalty`]): one "point" per row with the row's dofs,
/// u_n = δ_i = −B_i·u (a node-to-node pair: (u^a_i − u^b_{π(i)})·n = −u^a_d + u^b_d, n = −e_d),
/// σ_n = 0 (no Nitsche term: `nitsche` takes its own points, [`super::nitsche_pair`]), weight
/// w_i = ∫_Γa φ_i (a mortar row: ∫ψ_k) and γ = h, A's mesh size, so κ_i = E_a γ0/h and the
/// row force is w_i κ [δ_i − g_i]_+ — the weighted rows that pass the patch test (an unweighted
/// force gives the end nodes twice their share). Each row's gap is its height beyond the run's
/// gap (0 for the blocks): the run's gap is added where the operators are made, as for the
/// one-body box. `h` per row (a Gmsh interface's faces differ in size). The operators take
/// one dof count for every point: shorter rows (node-to-segment, mortar) are padded with
/// their first dof at coefficient 0, which adds nothing.
fn rows_as_points(
    rows: &Rows,
    (weight, height): (&[f64], &[f64]),
    measure: f64,
    h: &[f64],
) -> Vec<ContactPoint> {
    let k = (0..rows.len())
        .map(|i| rows.entries(i).0.len())
        .max()
        .unwrap_or(0);
    (0..rows.len())
        .zip(weight)
        .zip(h)
        .zip(height)
        .map(|(((i, w), &h), &gap)| {
            let (dofs, coef) = rows.entries(i);
            let mut dofs = dofs.to_vec();
            let mut un: Vec<f64> = coef.iter().map(|c| -c).collect();
            dofs.resize(k, dofs[0]);
            un.resize(k, 0.0);
            ContactPoint {
                weight: w * measure,
                gamma: h,
                gap,
                dofs,
                un,
                sn: vec![0.0; k],
                ut: Vec::new(),
                st: Vec::new(),
            }
        })
        .collect()
}

/// The penalty's node-to-node points with the relative slip's rows for friction (contract
/// §2.5, §2.6): point q (row q) gains the dofs of its tangential rows q·nt … q·nt + nt − 1
/// ([`super::geometry::tangential_rows`]: e_{a,q,c} − e_{b,π(q),c}) after its two vertical
/// ones, u_n and σ_n zero there, and u_t's row c holds row q·nt + c's coefficients on them, so
/// the penalty's f_t = proj(−κ Δ(u^a − u^b)_t) acts on A and, opposite, on B. Only frictional
/// runs take these: the frictionless points keep their two dofs, and their numbers.
pub(super) fn frictional_points(
    points: &[ContactPoint],
    tangential: &Rows,
    nt: usize,
) -> Vec<ContactPoint> {
    points
        .iter()
        .enumerate()
        .map(|(q, p)| {
            let mut p = p.clone();
            let base = p.dofs.len();
            for c in 0..nt {
                p.dofs.extend_from_slice(tangential.entries(q * nt + c).0);
            }
            let k = p.dofs.len();
            p.un.resize(k, 0.0);
            p.sn.resize(k, 0.0);
            p.ut = vec![0.0; nt * k];
            p.st = vec![0.0; nt * k];
            let mut slot = base;
            for c in 0..nt {
                for &coef in tangential.entries(q * nt + c).1 {
                    p.ut[c * k + slot] = coef;
                    slot += 1;
                }
            }
            p
        })
        .collect()
}

/// The element weights of a mass variant on two bodies: each body's density times its layer
/// weight `weight(layer, body)` where `mass_side` puts the variant, 1 elsewhere (contract
/// §2.6), with each body's own redistribution.
pub(super) fn body_weight(
    two: &TwoBodies,
    element_body: usize,
    weight: impl Fn(usize, usize) -> f64,
    layer: usize,
) -> f64 {
    let w = if two.mass_side.includes(element_body) {
        weight(layer, element_body)
    } else {
        1.0
    };
    two.density[element_body] * w
}

/// The total momentum along e_d, P = Σ over the vertical dofs of (M v) (contract §2.6), and
/// each body's share: (P, P_a, P_b).
pub(super) fn momentum(two: &TwoBodies, vertical: &[usize], mv: &[f64]) -> (f64, f64, f64) {
    let (mut pa, mut pb) = (0.0, 0.0);
    for &r in vertical {
        if two.body[r] == 0 {
            pa += mv[r];
        } else {
            pb += mv[r];
        }
    }
    (pa + pb, pa, pb)
}

/// The two-body columns of a run (contract §5): P^n along e_d at every observed step, its largest
/// deviation from P⁰ + tⁿF (F = 1_dᵀF the total load along e_d: the weight of both bodies and
/// the pressure; 0 without a load) over Σ_i m_i|V_i| + T|F| (null with a clamp, or when
/// both terms vanish) and each body's final mean velocity 1ᵀM_i v/m_i. Every scheme's momentum
/// balance gives P^{n+1} = Pⁿ + τF exactly (1_dᵀK = 0, every row's 1_dᵀB_iᵀ = 0, and
/// 1_dᵀM aⁿ = F from a⁰ on: the quasi-static start puts the massless rows' load into a⁰'s
/// equation), so the deviation is round-off.
#[derive(Debug, Clone)]
pub(super) struct MomentumTally {
    /// m_a, m_b: 1ᵀM_i1 over the e_d component, the run's masses.
    masses: [f64; 2],
    /// Σ_i m_i|V_i| + T|F|, or None where the drift is not defined.
    scale: Option<f64>,
    /// F: the total load along e_d.
    force: f64,
    p0: Option<f64>,
    max_dev: f64,
    last: [f64; 2],
    /// Frictional runs (contract §2.5): the reduced dofs of each tangential axis, whose momenta
    /// the drift measures too (the friction rows act along them), and their P⁰; empty without
    /// friction, so the frictionless runs keep their figures.
    tangential: Vec<Vec<usize>>,
    p0_t: Vec<f64>,
}

impl MomentumTally {
    /// With the run's mass matrix `m`, A's and B's initial e_d velocities, the run's load
    /// vector `load` (None: no load), its final time and, with friction, the tangential axes'
    /// dofs and A's e_1 velocity (the scale then takes A's speed |V_a|).
    pub(super) fn new(
        two: &TwoBodies,
        vertical: &[usize],
        m: &SymMatrix,
        (v_a, v_b): (f64, f64),
        load: Option<&[f64]>,
        t_final: f64,
        tangential: Option<(Vec<Vec<usize>>, f64)>,
    ) -> MomentumTally {
        let mut ones = vec![0.0; m.n()];
        for &r in vertical {
            ones[r] = 1.0;
        }
        let mut m1 = vec![0.0; m.n()];
        m.matvec_into(&ones, &mut m1);
        let (_, ma, mb) = momentum(two, vertical, &m1);
        let (tangential, speed_a) = match tangential {
            Some((axes, v_t)) => (axes, v_a.hypot(v_t)),
            None => (Vec::new(), v_a.abs()),
        };
        let force = load.map_or(0.0, |f| vertical.iter().map(|&r| f[r]).sum());
        let mut scale = ma * speed_a + mb * v_b.abs();
        if force != 0.0 {
            scale += t_final * force.abs();
        }
        let defined = !two.base_clamped && scale > 0.0;
        MomentumTally {
            masses: [ma, mb],
            scale: defined.then_some(scale),
            force,
            p0: None,
            max_dev: 0.0,
            last: [0.0; 2],
            p0_t: vec![f64::NAN; tangential.len()],
            tangential,
        }
    }

    /// Step n's momentum at time t from the run's M v; returns P^n.
    pub(super) fn observe(
        &mut self,
        two: &TwoBodies,
        vertical: &[usize],
        mv: &[f64],
        t: f64,
    ) -> f64 {
        let (p, pa, pb) = momentum(two, vertical, mv);
        let first = self.p0.is_none();
        let p0 = *self.p0.get_or_insert(p);
        // Without a load P⁰ itself, bit for bit (no − 0·t term).
        let expected = if self.force == 0.0 {
            p0
        } else {
            p0 + t * self.force
        };
        self.max_dev = self.max_dev.max((p - expected).abs());
        // The loads act along e_d only (no incline between two bodies): the tangential
        // momenta stay at their P⁰.
        for (axis, p0) in self.tangential.iter().zip(&mut self.p0_t) {
            let pt: f64 = axis.iter().map(|&r| mv[r]).sum();
            if first {
                *p0 = pt;
            }
            self.max_dev = self.max_dev.max((pt - *p0).abs());
        }
        self.last = [pa, pb];
        p
    }

    /// `momentum_drift`, `velocity_a_final`, `velocity_b_final` into the run's metrics.
    pub(super) fn finish(&self, metrics: &mut Metrics) {
        metrics.momentum_drift = self.scale.map(|s| self.max_dev / s);
        metrics.velocity_a_final = Some(self.last[0] / self.masses[0]);
        metrics.velocity_b_final = Some(self.last[1] / self.masses[1]);
    }
}

/// The patch test's stress error (contract §1.10): the largest entry of |σ_h + p e_d⊗e_d|/p
/// over the 2^d Gauss points of every cell of both bodies, σ = λ tr(ε) I + 2με per body.
pub(super) fn patch_stress_error(
    mesh: &BodiesMesh,
    dofs: &DofMap,
    two: &TwoBodies,
    u: &[f64],
    p: f64,
) -> f64 {
    match mesh.dim() {
        2 => stress_error::<2, 4>(mesh, dofs, two, u, p),
        _ => stress_error::<3, 8>(mesh, dofs, two, u, p),
    }
}

fn stress_error<const D: usize, const NN: usize>(
    mesh: &BodiesMesh,
    dofs: &DofMap,
    two: &TwoBodies,
    u: &[f64],
    p: f64,
) -> f64 {
    let g = 1.0 / 3f64.sqrt();
    let mut worst = 0.0f64;
    for e in 0..mesh.num_elements() {
        let (lambda, mu) = two.lame[mesh.element_body(e)];
        let mut x = [[0.0; D]; NN];
        let mut ue = [[0.0; D]; NN];
        for (a, &n) in mesh.element_nodes(e).iter().enumerate() {
            let c = mesh.coord(n);
            for k in 0..D {
                x[a][k] = c[k];
                ue[a][k] = dofs.free_index(n * D + k).map_or(0.0, |r| u[r]);
            }
        }
        for corner in 0..1usize << D {
            let xi: [f64; D] = std::array::from_fn(|k| if (corner >> k) & 1 == 1 { g } else { -g });
            let grad = q1_gradient_at::<D, NN>(&x, &ue, xi);
            let tr: f64 = (0..D).map(|k| grad[k][k]).sum();
            for i in 0..D {
                for j in 0..D {
                    let eps = 0.5 * (grad[i][j] + grad[j][i]);
                    let mut s = 2.0 * mu * eps + if i == j { lambda * tr } else { 0.0 };
                    if i == D - 1 && j == D - 1 {
                        s += p;
                    }
                    worst = worst.max((s / p).abs());
                }
            }
        }
    }
    worst
}
