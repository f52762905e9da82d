//! The geometry of a non-matching two-body interface and its mortar matrices (contract §2.6,
//! issue 45): a self-contained library the pairings `node-to-segment` and `mortar` and the
//! `segment` interface quadrature build on; the blocks' node-to-segment and mortar rows take it
//! (`run::fe::pairing`).
//!
//! - [`surface`]: the two sides Γ^a, Γ^b as face sets (segments; triangles, bilinear
//!   quadrilaterals), their shape functions and normals, the typed [`InterfaceError`]s;
//! - [`projection`]: Π, the closest point of Γ^b in the reference configuration, found through
//!   a uniform bin grid over Γ^b's faces (set-up and queries linear in the interface);
//! - [`segment`]: the segmentation of Γ^a by Γ^b's projected faces (2D breakpoints; 3D
//!   Sutherland–Hodgman clipping of face pairs) and each piece's exact rule;
//! - [`mortar`]: D, M, the weighted gaps and ∫ψ_k for the `standard` and `dual` bases, sparse
//!   over Γ^a/Γ^b node indices.
//!
//! The files import one way: surface < projection < segment < mortar.

pub mod mortar;
pub mod projection;
pub mod segment;
pub mod surface;

pub use mortar::{
    Basis, Mortar, SparseRows, basis_coefficients, face_integrals, mortar_matrices,
    mortar_matrices_element,
};
pub use projection::{Projection, Projector, closest_on_face, project_brute};
pub use segment::{Piece, PiecePoint, Segmentation, segment};
pub use surface::{FaceKind, InterfaceError, Surface};
