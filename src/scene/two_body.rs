//! The choices both two-body scenes share (contract §2.6): which bodies a mass variant modifies
//! (`mass_side`), how the unbiased Nitsche method weights its two sides (`nitsche_sides`), and
//! B's material keys, which default to A's values (contract §1.9, §1.10). One definition, so
//! `bars1d` and `blocks2d`/`blocks3d` read the keys the same way.

use super::{InterfaceUse, Physics};
use crate::space::fe::interface::Basis;

/// B's value of a material key `name` (`name_b`): its own, or A's where the sweep gives none
/// (the key's default is NaN, which no given value can be).
pub(super) fn b_value(p: &Physics, name: &str) -> f64 {
    let own = p.get(&format!("{name}_b"));
    if own.is_nan() { p.get(name) } else { own }
}

/// Whether B takes A's value of a key that A sets away from 1 — the keys' default before B's
/// keys defaulted to A's, so such a run's numbers changed with that default.
pub(super) fn b_follows_a_off_one(p: &Physics, names: &[&str]) -> bool {
    names
        .iter()
        .any(|n| p.get(&format!("{n}_b")).is_nan() && p.get(n) != 1.0)
}

/// Which bodies a mass variant modifies (contract §2.6 `mass_side`): layer 0 of body i is its
/// elements touching its own contact face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassSide {
    Both,
    A,
    B,
}

impl MassSide {
    /// From the `mass_side` key's index into its choices (both, a, b).
    pub fn from_index(x: f64) -> MassSide {
        match x as usize {
            1 => MassSide::A,
            2 => MassSide::B,
            _ => MassSide::Both,
        }
    }

    /// Whether the mass variant acts on body `body` (0 = A, 1 = B).
    pub fn includes(self, body: usize) -> bool {
        match self {
            MassSide::Both => true,
            MassSide::A => body == 0,
            MassSide::B => body == 1,
        }
    }
}

/// The weights of the two sides' Nitsche terms (contract §2.6 `nitsche_sides`): unbiased
/// (w_a = w_b = ½) or A the slave (w_a = 1, w_b = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NitscheSides {
    Unbiased,
    A,
}

impl NitscheSides {
    /// From the `nitsche_sides` key's index into its choices (unbiased, a).
    pub fn from_index(x: f64) -> NitscheSides {
        if x == 1.0 {
            NitscheSides::A
        } else {
            NitscheSides::Unbiased
        }
    }

    /// The sides' weights (w_a, w_b).
    pub fn weights(self) -> [f64; 2] {
        match self {
            NitscheSides::Unbiased => [0.5, 0.5],
            NitscheSides::A => [1.0, 0.0],
        }
    }
}

/// How `mixed` and `penalty` pair the two faces (contract §2.6 `pairing`; issue 45).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pairing {
    /// One row per Γ^a node against the Γ^b node below it (a matching interface).
    NodeToNode,
    /// One row per Γ^a node against Γ^b's face below it (one pass, A the slave).
    NodeToSegment,
    /// One row per multiplier function ψ_k of Γ^a, weighted by ∫ψ_k over the interface.
    Mortar,
}

impl Pairing {
    /// From the `pairing` key's index into its choices (node-to-node, node-to-segment, mortar).
    pub fn from_index(x: f64) -> Pairing {
        match x as usize {
            1 => Pairing::NodeToSegment,
            2 => Pairing::Mortar,
            _ => Pairing::NodeToNode,
        }
    }
}

/// Where the interface integrals are computed (contract §2.6 `interface_quadrature`): on the
/// segmentation of Γ^a by Γ^b's projected faces (exact on non-matching faces) or with Γ^a's
/// own face rule, the other body evaluated at the projected points (what GetFEM does).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InterfaceQuadrature {
    Segment,
    Element,
}

impl InterfaceQuadrature {
    /// From the `interface_quadrature` key's index into its choices (segment, element).
    pub fn from_index(x: f64) -> InterfaceQuadrature {
        if x == 1.0 {
            InterfaceQuadrature::Element
        } else {
            InterfaceQuadrature::Segment
        }
    }
}

/// The mortar multiplier's basis from the `mortar_basis` key's index (standard, dual).
pub fn mortar_basis_from_index(x: f64) -> crate::space::fe::interface::Basis {
    if x == 1.0 {
        crate::space::fe::interface::Basis::Dual
    } else {
        crate::space::fe::interface::Basis::Standard
    }
}

/// The interface keys against the run's treatment, friction and scheme (contract §2.6): the
/// checks both two-body scenes with faces share (`blocks2d`/`blocks3d`, whose `mesh_ratio` is
/// `ratio`, and the two-body Gmsh files, `ratio` = 1: a file's non-matching interface is
/// refused with node-to-node by the planner, which reads the file). A choice key not given
/// (NaN, a file's) reads as its first word.
pub(super) fn check_interface(
    p: &Physics,
    ratio: f64,
    m: InterfaceUse<'_>,
) -> Result<(), (&'static [&'static str], String)> {
    let (space, frictional) = (m.space, m.frictional);
    let pairing = Pairing::from_index(p.get("pairing"));
    // The words of the choice keys (the model's `Key::choices`, which this layer does
    // not see), by their indices.
    let word = |key: &str| {
        let words: &[&str] = match key {
            "pairing" => &["node-to-node", "node-to-segment", "mortar"],
            "mortar_basis" => &["standard", "dual"],
            _ => &["segment", "element"],
        };
        words[p.get(key) as usize]
    };
    // Nitsche takes any mesh_ratio (its points come from the interface geometry).
    if space == "nitsche" && pairing != Pairing::NodeToNode {
        return Err((
            &["pairing", "space"],
            format!(
                "pairing = {} with space = nitsche: a pairing makes the rows of mixed and penalty; nitsche integrates over the interface (interface_quadrature)",
                word("pairing")
            ),
        ));
    }
    if mortar_basis_from_index(p.get("mortar_basis")) != Basis::Standard
        && pairing != Pairing::Mortar
    {
        return Err((
            &["mortar_basis", "pairing", "space"],
            format!(
                "mortar_basis = {} with pairing = {}: the basis of the mortar multiplier applies to pairing = \"mortar\" only",
                word("mortar_basis"),
                word("pairing")
            ),
        ));
    }
    let quadrature = InterfaceQuadrature::from_index(p.get("interface_quadrature"));
    if quadrature != InterfaceQuadrature::Segment
        && space != "nitsche"
        && pairing != Pairing::Mortar
    {
        return Err((
            &["interface_quadrature", "pairing", "space"],
            format!(
                "interface_quadrature = {} with pairing = {}: it applies to the interface integrals of pairing = \"mortar\" and of space = nitsche only (node rows carry no interface integral)",
                word("interface_quadrature"),
                word("pairing")
            ),
        ));
    }
    if space != "nitsche" && ratio != 1.0 && pairing == Pairing::NodeToNode {
        return Err((
            &["mesh_ratio", "pairing", "space"],
            format!(
                "mesh_ratio = {ratio} with pairing = node-to-node: non-matching interface: choose node-to-segment or mortar, or nitsche (issue 45; node-to-node needs every Γ^a node above a Γ^b node)"
            ),
        ));
    }
    if m.kinematic && pairing != Pairing::NodeToNode {
        return Err((
            &["pairing", "scheme", "mass"],
            format!(
                "central-difference with mass = lumped and pairing = {}: kinematic contact acts row by row on rows that share no node (node-to-node pairs; these rows share Γ^b's nodes)",
                word("pairing")
            ),
        ));
    }
    if frictional && space == "nitsche" && ratio != 1.0 {
        return Err((
            &["mesh_ratio", "friction", "space"],
            format!(
                "friction with space = nitsche and mesh_ratio = {ratio}: the relative slip's Nitsche rows are built for the matching blocks only (mesh_ratio = 1; contract §2.6)"
            ),
        ));
    }
    if frictional && pairing != Pairing::NodeToNode {
        return Err((
            &["pairing", "friction"],
            format!(
                "friction with pairing = {}: the relative slip's rows are built for node-to-node pairs only (contract §2.6)",
                word("pairing")
            ),
        ));
    }
    Ok(())
}
