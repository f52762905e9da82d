//! Gmsh MSH 4.1 meshes (ASCII or binary) read into the engine's mesh representation: the body of
//! the `mesh2d`/`mesh3d` scenes (contract §1.6, issue 22), validated before anything is run.
//!
//! Why here: every scene of the engine reaches assembly through the [`Mesh`] trait ("an element =
//! its node ids + its node coordinates"), so a Gmsh mesh is one more implementation of that trait
//! ([`GmshMesh`]), not a parallel mesh type.
//!
//! What is read (by [`super::msh`], the engine's own MSH 4.1 parser, which cannot panic and
//! checks every count against the bytes left before allocating):
//! - the nodes, numbered by increasing tag whatever order or block header the file has (a
//!   rewrite listing them otherwise is the same mesh, to the bit);
//! - the cells: the elements of the highest dimension present, one type per mesh among 3- and
//!   6-node triangles, 4- and 9-node quadrilaterals, 4- and 10-node tetrahedra, 8- and 27-node
//!   hexahedra ([`ElementKind`]);
//! - the physical groups by name (`contact` = Γ_C, required; `clamped`; any other), each with the
//!   entities it tags, its elements (boundary lines/faces, or cells) as node ids, and its nodes.
//!
//! Node order of a cell (the engine's contract, see [`ElementKind`]): triangles and tetrahedra
//! keep Gmsh's order (vertices, then edge midpoints); quadrilaterals and hexahedra are permuted
//! into the tensor order of [`super::element`] (local node a has index ⌊a/(p+1)^k⌋ mod (p+1)
//! along axis k), so the Q1/Q2 kernels apply unchanged.
//!
//! Validation (each failure a [`GmshError`] naming the file, the element/node/group and the
//! reason, on one line): a file that is not MSH 4.1 or not well formed (the section, the block
//! and why), a node tag given twice, a coordinate that is not finite, mixed cell types, no
//! cells, a missing `contact` group, a 2D mesh whose nodes do not share one z, unreferenced
//! nodes (not in any cell), inverted or degenerate cells — det J is evaluated at every
//! reference node of the cell and at its quadrature points ([`ElementKind::quadrature`]), then
//! certified positive over the whole cell by its Bernstein coefficients — and the whole-mesh
//! checks of [`super::check`]: cells listed twice, faces shared by more than two cells or by
//! two on one side (overlaps), neighbours not sharing their midside nodes, coincident distinct
//! nodes (a crack), and `contact`/`clamped` elements that are not boundary faces of the cells'
//! type; and the geometric check of [`super::overlap`]: cells that intersect other than along
//! shared faces, edges or vertices (found with a bounding-box tree, O(n log n)). A 2D mesh whose cells are all clockwise in the (x, y) plane (a surface oriented
//! towards −z) is
//! reoriented rather than refused; a cell of the other orientation is then inverted.
//!
//! Also returned: `h` = the largest cell diameter (largest distance between two nodes of a
//! cell: for affine cells the longest edge) and the SHA-256 of the file's bytes (the run id
//! includes it, contract §1.6).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::SystemTime;

use sha2::{Digest, Sha256};

pub use super::element_kind::ElementKind;
use super::element_kind::{det_from_gradients, jacobian_det};
pub use super::gmsh_bodies::GmshBodies;
use super::gmsh_bodies::{Interface, match_interface, node_bodies};
pub use super::gmsh_error::GmshError;
use super::mesh::Mesh;
use super::{check, msh, overlap};

/// Node tag → node index of a file.
enum TagIndex {
    Dense { lo: u64, table: Vec<usize> },
    Map(HashMap<u64, usize>),
}

impl TagIndex {
    /// Tag → index: a table when the tags are dense (Gmsh numbers nodes 1..n; a 10⁵-node file
    /// spent 5 % of its reading in SipHash), a map otherwise. A tag given twice is refused: its
    /// elements would be ambiguous.
    fn new(file: &str, node_tags: &[u64]) -> Result<TagIndex, GmshError> {
        let (lo, hi) = node_tags
            .iter()
            .fold((u64::MAX, 0), |(lo, hi), &t| (lo.min(t), hi.max(t)));
        let twice = |t: u64| GmshError::DuplicateNodeTag {
            file: file.to_string(),
            node: t,
        };
        if !node_tags.is_empty() && hi - lo <= 2 * node_tags.len() as u64 + 16 {
            let mut table = vec![usize::MAX; (hi - lo + 1) as usize];
            for (i, &t) in node_tags.iter().enumerate() {
                let slot = &mut table[(t - lo) as usize];
                if *slot != usize::MAX {
                    return Err(twice(t));
                }
                *slot = i;
            }
            Ok(TagIndex::Dense { lo, table })
        } else {
            let mut m = HashMap::with_capacity(node_tags.len());
            for (i, &t) in node_tags.iter().enumerate() {
                if m.insert(t, i).is_some() {
                    return Err(twice(t));
                }
            }
            Ok(TagIndex::Map(m))
        }
    }

    fn get(&self, t: u64) -> Option<usize> {
        match self {
            TagIndex::Dense { lo, table } => t
                .checked_sub(*lo)
                .and_then(|k| table.get(k as usize))
                .copied()
                .filter(|&i| i != usize::MAX),
            TagIndex::Map(m) => m.get(&t).copied(),
        }
    }
}

/// A named physical group: the entities it tags and their elements.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalGroup {
    pub name: String,
    /// Dimension of the tagged entities (d − 1 for a boundary, d for cells).
    pub dim: usize,
    /// Gmsh's physical tag.
    pub tag: i32,
    /// Tags of the geometric entities (of dimension `dim`) in the group.
    pub entities: Vec<i32>,
    /// The group's elements as node ids, Gmsh's local order (boundary lines/faces, or cells).
    pub elements: Vec<Vec<usize>>,
    /// The distinct nodes of those elements, increasing.
    pub nodes: Vec<usize>,
}

/// A validated Gmsh mesh (see the module header).
#[derive(Debug, Clone, PartialEq)]
pub struct GmshMesh {
    /// The file it was read from, as given.
    pub file: String,
    /// 2 or 3.
    pub dim: usize,
    pub kind: ElementKind,
    /// Node coordinates (z = 0 in 2D, whatever the plane's z in the file).
    pub coords: Vec<[f64; 3]>,
    /// Gmsh tag of each node.
    pub node_tags: Vec<u64>,
    /// Cells' node ids, `kind.num_nodes()` per cell, engine local order.
    pub elements: Vec<usize>,
    /// Gmsh tag of each cell.
    pub element_tags: Vec<u64>,
    pub groups: Vec<PhysicalGroup>,
    /// Largest cell diameter.
    pub h: f64,
    /// SHA-256 of the file's bytes, lowercase hex.
    pub content_hash: String,
    /// Whether the 2D cells were reoriented (all clockwise in the file).
    pub reoriented: bool,
    /// Two bodies (groups `body_a`/`body_b`, contract §1.10): each node's body and the
    /// matched interface ([`GmshBodies`]); None for one body.
    pub bodies: Option<GmshBodies>,
}

impl GmshMesh {
    /// Read and validate a mesh file.
    pub fn read(path: &Path) -> Result<GmshMesh, GmshError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| GmshError::Io {
            file: file.clone(),
            source,
        })?;
        GmshMesh::from_bytes(&file, &bytes)
    }

    /// Validate the bytes of a mesh file (`file` names it in errors). The stages run in this
    /// order, each refusing with the first failure it meets: the format, the nodes, the cells,
    /// their point-wise and whole-mesh checks, the physical groups.
    pub fn from_bytes(file: &str, bytes: &[u8]) -> Result<GmshMesh, GmshError> {
        GmshMesh::validate(file, bytes, true)
    }

    /// [`GmshMesh::from_bytes`] without the geometric overlap check ([`super::overlap`]), for
    /// `benches/mesh_overlap.rs` alone: issue 42 bounds that check's cost against the read
    /// before it, measured side by side in one run. Nothing else skips it.
    #[doc(hidden)]
    pub fn from_bytes_without_overlap_check(
        file: &str,
        bytes: &[u8],
    ) -> Result<GmshMesh, GmshError> {
        GmshMesh::validate(file, bytes, false)
    }

    /// [`GmshMesh::from_bytes`], the geometric overlap check made if `geometric`.
    fn validate(file: &str, bytes: &[u8], geometric: bool) -> Result<GmshMesh, GmshError> {
        check_version(file, bytes)?;
        let msh::MshFile {
            names,
            entities,
            node_blocks,
            element_blocks: blocks,
            ..
        } = msh::parse(bytes).map_err(|error| GmshError::Parse {
            file: file.to_string(),
            error,
        })?;
        let mut nodes = Nodes::read(file, &node_blocks)?;
        let index = TagIndex::new(file, &nodes.tags)?;
        let dim = cell_dimension(file, &blocks)?;
        let reader = BlockReader {
            file,
            blocks: &blocks,
            index: &index,
            dim,
        };
        reader.check_element_nodes()?;
        let mut cells = reader.cells()?;
        cells.check_referenced(file, &nodes.tags)?;
        if dim == 2 {
            nodes.flatten_2d(file)?;
        }
        let reoriented = dim == 2 && cells.orient_2d(&nodes.coords);
        let h = cells.check_jacobians_at_points(file, &nodes.coords)?;
        // Two bodies: each node's body first, since nodes of two bodies may coincide (contract
        // §1.10: bodies touching at g = 0), where nodes of one body may not (a crack).
        let node_body = reader.node_bodies(&names, entities.as_ref(), &nodes.tags)?;
        let topo = check_topology(file, &nodes, &cells, geometric, node_body.as_deref())?;
        let groups = reader.groups(names, entities.as_ref(), &topo)?;
        require_contact(file, &groups, node_body.is_some())?;
        let bodies = match node_body {
            None => None,
            Some(node_body) => {
                let nodes_of = |name: &str| {
                    groups
                        .iter()
                        .find(|g| g.name == name)
                        .map_or(&[][..], |g| &g.nodes[..])
                };
                Some(match_interface(Interface {
                    file,
                    dim,
                    coords: &nodes.coords,
                    node_tags: &nodes.tags,
                    node_body,
                    contact_a: nodes_of("contact_a"),
                    contact_b: nodes_of("contact_b"),
                    clamped: nodes_of("clamped"),
                    h,
                })?)
            }
        };
        let content_hash = Sha256::digest(bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        Ok(GmshMesh {
            file: file.to_string(),
            dim,
            kind: cells.kind,
            coords: nodes.coords,
            node_tags: nodes.tags,
            elements: cells.elements,
            element_tags: cells.tags,
            groups,
            h,
            content_hash,
            reoriented,
            bodies,
        })
    }

    /// [`GmshMesh::read`] through a process-wide cache: the planner validates a sweep's mesh
    /// files once per file (a `[grid]` crosses each with many methods) and the runs of the
    /// same process reuse the read mesh. Keyed by the path and the file's size and modification
    /// time, so a file rewritten between two sweeps of one process is read again.
    pub fn read_shared(path: &Path) -> Result<Arc<GmshMesh>, GmshError> {
        type Key = (PathBuf, u64, Option<SystemTime>);
        static CACHE: Mutex<Vec<(Key, Arc<GmshMesh>)>> = Mutex::new(Vec::new());
        /// Distinct files kept: a refinement family of a few meshes, and its reference.
        const CAP: usize = 8;
        let meta = std::fs::metadata(path).map_err(|source| GmshError::Io {
            file: path.display().to_string(),
            source,
        })?;
        let key: Key = (path.to_path_buf(), meta.len(), meta.modified().ok());
        {
            let cache = CACHE.lock().unwrap_or_else(|p| p.into_inner());
            if let Some((_, m)) = cache.iter().find(|(k, _)| *k == key) {
                return Ok(Arc::clone(m));
            }
        }
        let mesh = Arc::new(GmshMesh::read(path)?);
        let mut cache = CACHE.lock().unwrap_or_else(|p| p.into_inner());
        cache.retain(|(k, _)| k.0 != key.0);
        cache.push((key, Arc::clone(&mesh)));
        if cache.len() > CAP {
            cache.remove(0);
        }
        Ok(mesh)
    }

    /// The physical group of this name, if any.
    pub fn group(&self, name: &str) -> Option<&PhysicalGroup> {
        self.groups.iter().find(|g| g.name == name)
    }

    /// The nodes that carry contact (contract §1.6): those of the `contact` group not in `clamped`
    /// (a clamped node never moves towards the obstacle), increasing.
    pub fn contact_nodes(&self) -> Vec<usize> {
        let clamped = self.group("clamped").map_or(&[][..], |g| &g.nodes[..]);
        self.group("contact").map_or_else(Vec::new, |g| {
            // Both lists are increasing: a merge, not a search per node.
            let mut c = clamped.iter().peekable();
            g.nodes
                .iter()
                .copied()
                .filter(|&n| {
                    while c.next_if(|&&m| m < n).is_some() {}
                    c.peek() != Some(&&n)
                })
                .collect()
        })
    }

    /// The lowest x_d of the contact nodes ([`GmshMesh::contact_nodes`]), None without any: the
    /// rigid plane x_d = this − gap (contract §1.6), so a run's `gap` and `obstacle` are two names
    /// of one plane.
    pub fn contact_floor(&self) -> Option<f64> {
        self.contact_nodes()
            .iter()
            .map(|&n| self.coords[n][self.dim - 1])
            .reduce(f64::min)
    }

    /// The extent along e_d (max − min of x_d) of the nodes `which` takes: the body's height,
    /// or one body's of two.
    pub fn extent(&self, which: impl Fn(usize) -> bool) -> f64 {
        let d = self.dim;
        let z = (0..self.coords.len())
            .filter(|&n| which(n))
            .map(|n| self.coords[n][d - 1]);
        z.clone().fold(f64::NEG_INFINITY, f64::max) - z.fold(f64::INFINITY, f64::min)
    }

    /// |Ω_h| = Σ_K ∫_K̂ det J by [`ElementKind::quadrature`] (exact for affine cells).
    pub fn measure(&self) -> f64 {
        let q = self.kind.quadrature();
        let nn = self.kind.num_nodes();
        self.elements
            .chunks_exact(nn)
            .map(|cell| {
                let x: Vec<[f64; 3]> = cell.iter().map(|&n| self.coords[n]).collect();
                q.iter()
                    .map(|&(xi, w)| w * jacobian_det(self.kind, &x, xi))
                    .sum::<f64>()
            })
            .sum()
    }
}

impl Mesh for GmshMesh {
    fn dim(&self) -> usize {
        self.dim
    }
    fn num_nodes(&self) -> usize {
        self.coords.len()
    }
    fn num_elements(&self) -> usize {
        self.element_tags.len()
    }
    fn nodes_per_element(&self) -> usize {
        self.kind.num_nodes()
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        let nn = self.kind.num_nodes();
        &self.elements[e * nn..(e + 1) * nn]
    }
    fn coord(&self, node: usize) -> [f64; 3] {
        self.coords[node]
    }
}

/// The nodes of a file: coordinates and Gmsh tags, numbered by increasing tag.
struct Nodes {
    coords: Vec<[f64; 3]>,
    tags: Vec<u64>,
}

impl Nodes {
    /// The tags of every block, kept whatever the section's header says about their range
    /// (issue 36: a file listing its nodes out of tag order is read as written); every
    /// coordinate finite.
    fn read(file: &str, node_blocks: &[msh::NodeBlock]) -> Result<Nodes, GmshError> {
        let total: usize = node_blocks.iter().map(|b| b.tags.len()).sum();
        let mut coords = Vec::with_capacity(total);
        let mut node_tags = Vec::with_capacity(total);
        for block in node_blocks {
            node_tags.extend_from_slice(&block.tags);
            coords.extend_from_slice(&block.coords);
        }
        // Nodes are numbered in increasing tag order, not in the order the file lists them: a
        // file and its rewrite with the nodes listed otherwise (another writer's block order)
        // are then one mesh, and run to the same numbers to the bit (the assembly and the
        // factor's ordering follow the node numbering). Gmsh lists its nodes in tag order, so
        // its files keep their numbering.
        if node_tags.windows(2).any(|w| w[0] >= w[1]) {
            let mut order: Vec<usize> = (0..node_tags.len()).collect();
            order.sort_by_key(|&i| node_tags[i]);
            node_tags = order.iter().map(|&i| node_tags[i]).collect();
            coords = order.iter().map(|&i| coords[i]).collect();
        }
        for (i, c) in coords.iter().enumerate() {
            if let Some(k) = (0..3).find(|&k| !c[k].is_finite()) {
                return Err(GmshError::NonFinite {
                    file: file.to_string(),
                    node: node_tags[i],
                    axis: ["x", "y", "z"][k],
                    value: c[k],
                });
            }
        }
        Ok(Nodes {
            coords,
            tags: node_tags,
        })
    }

    /// A 2D mesh lies in one plane z = const (to 10⁻¹² of its size), then z := 0.
    fn flatten_2d(&mut self, file: &str) -> Result<(), GmshError> {
        let coords = &mut self.coords;
        let (lo, hi) = check::bounding_box(coords);
        let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1.0);
        let z0 = coords[0][2];
        if let Some(i) = coords.iter().position(|c| (c[2] - z0).abs() > 1e-12 * size) {
            return Err(GmshError::NotPlanar {
                file: file.to_string(),
                node: self.tags[i],
                z: coords[i][2],
                first: self.tags[0],
                z0,
            });
        }
        for c in coords {
            c[2] = 0.0;
        }
        Ok(())
    }
}

/// The dimension of the cells: the highest of the element blocks (the parser checked that each
/// block's type has its entity's dimension); below 2 there are no cells.
fn cell_dimension(file: &str, blocks: &[msh::ElementBlock]) -> Result<usize, GmshError> {
    let dim = blocks
        .iter()
        .map(|b| b.entity_dim.max(0) as usize)
        .max()
        .unwrap_or(0);
    if dim < 2 {
        return Err(GmshError::NoCells {
            file: file.to_string(),
        });
    }
    Ok(dim)
}

/// The groups that name boundary faces (contract §1.6, §1.10): Γ_C, the clamped face, and
/// the two bodies' contact faces and loaded face.
const BOUNDARY_GROUPS: [&str; 5] = ["contact", "clamped", "contact_a", "contact_b", "loaded"];

/// The tags of the entities of dimension `gdim` that the physical group `tag` holds.
fn entities_of(entities: Option<&[Vec<msh::Entity>; 4]>, gdim: usize, tag: i32) -> Vec<i32> {
    entities.map_or_else(Vec::new, |en| {
        en[gdim.min(3)]
            .iter()
            .filter(|x| x.physical_tags.iter().any(|&t| t.abs() == tag))
            .map(|x| x.tag)
            .collect()
    })
}

/// The element blocks of a file with what reading them needs: node tags → node ids, the
/// dimension of the cells.
struct BlockReader<'a> {
    file: &'a str,
    blocks: &'a [msh::ElementBlock],
    index: &'a TagIndex,
    dim: usize,
}

impl BlockReader<'_> {
    fn node(&self, element: u64, t: u64) -> Result<usize, GmshError> {
        self.index.get(t).ok_or_else(|| GmshError::UnknownNode {
            file: self.file.to_string(),
            element,
            node: t,
        })
    }

    /// Every element's nodes are defined, those of blocks no group names included.
    fn check_element_nodes(&self) -> Result<(), GmshError> {
        for b in self.blocks {
            for (i, &t) in b.tags.iter().enumerate() {
                for &n in b.element(i) {
                    self.node(t, n)?;
                }
            }
        }
        Ok(())
    }

    /// The cells: the elements of the cells' dimension, all of one supported kind, their
    /// nodes permuted into the engine's local order.
    fn cells(&self) -> Result<Cells, GmshError> {
        let (file, dim) = (self.file, self.dim);
        let mut kind: Option<ElementKind> = None;
        let mut elements = Vec::new();
        let mut element_tags = Vec::new();
        for b in self.blocks.iter().filter(|b| b.entity_dim as usize == dim) {
            let element = b.tags.first().copied().unwrap_or(0);
            let Some(k) = ElementKind::from_gmsh(b.element_type).filter(|k| k.dim() == dim) else {
                return Err(GmshError::MixedElements {
                    file: file.to_string(),
                    element,
                    found: "lower-dimensional element",
                    first: if dim == 2 {
                        "surface cell"
                    } else {
                        "volume cell"
                    },
                });
            };
            let first = *kind.get_or_insert(k);
            if k != first {
                return Err(GmshError::MixedElements {
                    file: file.to_string(),
                    element,
                    found: k.name(),
                    first: first.name(),
                });
            }
            let perm = k.gmsh_local_order();
            elements.reserve(b.tags.len() * perm.len());
            for (i, &t) in b.tags.iter().enumerate() {
                let nodes = b.element(i);
                for &g in &perm {
                    elements.push(self.node(t, nodes[g])?);
                }
                element_tags.push(t);
            }
        }
        let kind = kind.ok_or_else(|| GmshError::NoCells {
            file: file.to_string(),
        })?;
        Ok(Cells {
            kind,
            elements,
            tags: element_tags,
        })
    }

    /// Physical groups: entities by (dim, physical tag), then their elements.
    fn groups(
        &self,
        names: Vec<(usize, i32, String)>,
        entities: Option<&[Vec<msh::Entity>; 4]>,
        topo: &check::Topology,
    ) -> Result<Vec<PhysicalGroup>, GmshError> {
        let mut groups = Vec::new();
        for (gdim, tag, name) in names {
            let ents = entities_of(entities, gdim, tag);
            groups.push(self.group(gdim, tag, name, ents, Some(topo))?);
        }
        Ok(groups)
    }

    /// Each node's body (0 = A, 1 = B) of a two-body file (groups `body_a`, `body_b` of the
    /// cells' dimension, contract §1.10), None for one body.
    fn node_bodies(
        &self,
        names: &[(usize, i32, String)],
        entities: Option<&[Vec<msh::Entity>; 4]>,
        node_tags: &[u64],
    ) -> Result<Option<Vec<u8>>, GmshError> {
        if !names.iter().any(|n| n.2 == "body_a" || n.2 == "body_b") {
            return Ok(None);
        }
        let mut body = [Vec::new(), Vec::new()];
        for (gdim, tag, name) in names {
            let Some(i) = ["body_a", "body_b"].iter().position(|b| b == name) else {
                continue;
            };
            let ents = entities_of(entities, *gdim, *tag);
            body[i].extend(self.group(*gdim, *tag, name.clone(), ents, None)?.nodes);
        }
        node_bodies(self.file, node_tags, &body[0], &body[1]).map(Some)
    }

    /// The group `name` of dimension `gdim` over the entities `ents`: its elements and nodes.
    fn group(
        &self,
        gdim: usize,
        tag: i32,
        name: String,
        ents: Vec<i32>,
        topo: Option<&check::Topology>,
    ) -> Result<PhysicalGroup, GmshError> {
        let (file, dim) = (self.file, self.dim);
        let boundary = BOUNDARY_GROUPS.contains(&name.as_str());
        let cells = name == "body_a" || name == "body_b";
        if (boundary && gdim + 1 != dim) || (cells && gdim != dim) {
            return Err(GmshError::GroupDimension {
                file: file.to_string(),
                group: name,
                found: gdim,
                expected: if cells { dim } else { dim - 1 },
                mesh_dim: dim,
            });
        }
        let mut els = Vec::new();
        let mut nodes = Vec::new();
        for b in self
            .blocks
            .iter()
            .filter(|b| b.entity_dim as usize == gdim && ents.contains(&b.entity_tag))
        {
            for (i, &t) in b.tags.iter().enumerate() {
                let ids = b
                    .element(i)
                    .iter()
                    .map(|&n| self.node(t, n))
                    .collect::<Result<Vec<_>, _>>()?;
                // `contact` and `clamped` are boundary faces of the cells' degree: Γ_C's
                // quadrature and the clamped nodes act on them (a point or an interior face
                // would fail or silently cut the body inside the runs).
                if let (true, Some(topo)) = (boundary, topo) {
                    topo.boundary_face(b.element_type, &ids).map_err(|reason| {
                        GmshError::GroupElement {
                            file: file.to_string(),
                            group: name.clone(),
                            element: t,
                            reason,
                        }
                    })?;
                }
                nodes.extend_from_slice(&ids);
                els.push(ids);
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        Ok(PhysicalGroup {
            name,
            dim: gdim,
            tag,
            entities: ents,
            elements: els,
            nodes,
        })
    }
}

/// The cells of a file: one kind, node ids (`kind.num_nodes()` per cell, engine local order)
/// and Gmsh tags.
struct Cells {
    kind: ElementKind,
    elements: Vec<usize>,
    tags: Vec<u64>,
}

impl Cells {
    /// Every node is a node of some cell.
    fn check_referenced(&self, file: &str, node_tags: &[u64]) -> Result<(), GmshError> {
        let mut used = vec![false; node_tags.len()];
        for &n in &self.elements {
            used[n] = true;
        }
        if let Some(i) = used.iter().position(|u| !u) {
            return Err(GmshError::UnreferencedNode {
                file: file.to_string(),
                node: node_tags[i],
                cell: self.kind.name(),
            });
        }
        Ok(())
    }

    /// Copy cell `e`'s node coordinates into `x` (one buffer for every cell: the checks run at
    /// every cell of the mesh).
    fn cell_x(&self, coords: &[[f64; 3]], x: &mut [[f64; 3]], e: usize) {
        let nn = self.kind.num_nodes();
        for (xa, &n) in x.iter_mut().zip(&self.elements[e * nn..(e + 1) * nn]) {
            *xa = coords[n];
        }
    }

    /// Orientation of a 2D mesh: the majority sign of det J at the cells' centres defines it;
    /// all clockwise → every cell mirrored (returns whether it was).
    fn orient_2d(&mut self, coords: &[[f64; 3]]) -> bool {
        let kind = self.kind;
        let dim = kind.dim();
        let nn = kind.num_nodes();
        let centre = {
            let r = kind.reference_nodes();
            let mut c = [0.0; 3];
            let nv = if kind.is_simplex() { dim + 1 } else { r.len() };
            for p in r.iter().take(nv) {
                for k in 0..3 {
                    c[k] += p[k] / nv as f64;
                }
            }
            c
        };
        let mut x = vec![[0.0; 3]; nn];
        let ne = self.tags.len();
        let at_centre = kind.shape_gradients(centre);
        let negative = (0..ne)
            .filter(|&e| {
                self.cell_x(coords, &mut x, e);
                det_from_gradients(dim, &x, &at_centre) < 0.0
            })
            .count();
        if 2 * negative <= ne {
            return false;
        }
        let m = kind.mirror_2d();
        for cell in self.elements.chunks_exact_mut(nn) {
            let old = cell.to_vec();
            for (a, slot) in cell.iter_mut().enumerate() {
                *slot = old[m[a]];
            }
        }
        true
    }

    /// det J positive (and not degenerate, relative to the cell's size) at every reference
    /// node and quadrature point of every cell (in 3D the orientation must be positive as
    /// given); returns `h`, the largest cell diameter.
    fn check_jacobians_at_points(&self, file: &str, coords: &[[f64; 3]]) -> Result<f64, GmshError> {
        let kind = self.kind;
        let dim = kind.dim();
        let nn = kind.num_nodes();
        let mut x = vec![[0.0; 3]; nn];
        let mut checks = kind.reference_nodes();
        checks.extend(kind.quadrature().into_iter().map(|(xi, _)| xi));
        let check_grads: Vec<Vec<[f64; 3]>> =
            checks.iter().map(|&xi| kind.shape_gradients(xi)).collect();
        // Reference measure: det J of an undistorted cell of diameter h_K is ~ h_K^d times this.
        let ref_measure = if kind.is_simplex() {
            0.5
        } else {
            2f64.powi(-(dim as i32))
        };
        let mut h: f64 = 0.0;
        for e in 0..self.tags.len() {
            self.cell_x(coords, &mut x, e);
            let mut diam: f64 = 0.0;
            for a in 0..nn {
                for b in a + 1..nn {
                    diam = diam.max(dist(x[a], x[b]));
                }
            }
            h = h.max(diam);
            let scale = diam.powi(dim as i32) * ref_measure;
            for (&xi, grads) in checks.iter().zip(&check_grads) {
                let det = det_from_gradients(dim, &x, grads);
                let relative = det / scale;
                if relative.is_nan() || relative.abs() <= 1e-10 {
                    return Err(GmshError::Degenerate {
                        file: file.to_string(),
                        element: self.tags[e],
                        det,
                        relative,
                        xi,
                    });
                }
                if det < 0.0 {
                    return Err(GmshError::Inverted {
                        file: file.to_string(),
                        element: self.tags[e],
                        det,
                        xi,
                    });
                }
            }
        }
        Ok(h)
    }
}

/// Topology (issue 36): no cell twice, every face shared by at most two cells lying on either
/// side of it with the same midside nodes, no distinct nodes at one point, and det J certified
/// positive on the whole of every curved cell; then geometry (issue 42): no two cells
/// overlapping other than along what they share (last: it cuts the cells into straight pieces,
/// which only valid cells make meaningful; skipped if not `geometric`, for its benchmark only).
/// Returns the cells' faces, which the boundary groups are checked against.
fn check_topology<'a>(
    file: &str,
    nodes: &'a Nodes,
    cells: &'a Cells,
    geometric: bool,
    node_body: Option<&[u8]>,
) -> Result<check::Topology<'a>, GmshError> {
    let f = || file.to_string();
    let topo = check::Topology::new(cells.kind, &cells.elements, &nodes.tags, &cells.tags);
    topo.check(file)?;
    // Nodes of two bodies may coincide (their interface at g = 0), nodes of one may not.
    let apart = |a: usize, b: usize| node_body.is_some_and(|nb| nb[a] != nb[b]);
    check::coincident_nodes(cells.kind.dim(), &nodes.coords, &apart).map_err(
        |(a, b, distance)| GmshError::CoincidentNodes {
            file: f(),
            a: nodes.tags[a],
            b: nodes.tags[b],
            distance,
        },
    )?;
    check::certify_jacobians(cells.kind, &nodes.coords, &cells.elements)
        .map_err(|e| e.into_gmsh(f(), &cells.tags))?;
    if geometric {
        overlap::overlapping_cells(cells.kind, &nodes.coords, &cells.elements).map_err(|o| {
            GmshError::Overlap {
                file: f(),
                a: cells.tags[o.a],
                b: cells.tags[o.b],
                depth: o.depth,
                relative: o.relative,
            }
        })?;
    }
    Ok(topo)
}

/// The `contact` group (Γ_C) is required; of two bodies (contract §1.10), both bodies and both
/// contact faces.
fn require_contact(file: &str, groups: &[PhysicalGroup], two: bool) -> Result<(), GmshError> {
    let required: &[&str] = if two {
        &["body_a", "body_b", "contact_a", "contact_b"]
    } else {
        &["contact"]
    };
    if let Some(missing) = required
        .iter()
        .find(|r| !groups.iter().any(|g| g.name == **r))
    {
        return Err(GmshError::MissingGroup {
            file: file.to_string(),
            group: (*missing).into(),
            found: if groups.is_empty() {
                "none".into()
            } else {
                groups
                    .iter()
                    .map(|g| format!("\"{}\"", g.name))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
        });
    }
    Ok(())
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The `$MeshFormat` header must be the first section and say version 4.1.
fn check_version(file: &str, bytes: &[u8]) -> Result<(), GmshError> {
    let bad = |reason: String| GmshError::NotMsh41 {
        file: file.to_string(),
        reason,
    };
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(256)]);
    let mut lines = head.lines().map(str::trim);
    if lines.next() != Some("$MeshFormat") {
        return Err(bad("it does not start with $MeshFormat".into()));
    }
    let version = lines
        .next()
        .and_then(|l| l.split_whitespace().next())
        .unwrap_or("");
    if version != "4.1" {
        return Err(bad(format!("format version \"{version}\"")));
    }
    Ok(())
}
