//! Reference solutions of scenes without a closed form (contract §1.2): a run of the same scene on a
//! nested finer mesh and step records its solution on the lattice its consumers need — every
//! `space_stride`-th node along each axis, every `time_stride`-th step — and each coarse run
//! reads its own nodes and times from it (nested meshes: every coarse node is a reference node,
//! every coarse time a reference time, so I_h u_ref is a plain lookup).
//!
//! Meshes that are not nested (the disc and ball's mapped meshes of two sizes, mesh files, contract
//! §1.6) store every node (`space_stride` 1; a mesh file's clamped nodes as zeros) and the mesh
//! itself ([`ReferenceData::mesh`]): a coarse run locates its nodes in it and evaluates the
//! reference's finite-element function there ([`crate::space::fe::locate`]). The bars' box
//! stored at stride 1 keeps its mesh too, for the runs on a mesh file of the same bar.
//!
//! On disk (`DIR/references/<run_id>.ref`): a JSON header line, then the values as
//! little-endian f64 — the file is written to a temporary name, fsynced and renamed, so it is
//! either whole or absent. With a mesh, its node coordinates (3 per node) and connectivity (as
//! f64, exact below 2⁵³) follow; files without one (every file before) read as before.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::space::fe::locate::PlainMesh;

/// The recorded reference solution.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceData {
    pub dim: usize,
    /// Reference mesh size and step.
    pub h: f64,
    pub dt: f64,
    pub space_stride: usize,
    pub time_stride: usize,
    /// Lattice nodes per axis (unused axes 1), x fastest.
    pub lattice: [usize; 3],
    /// Number of stored times (steps 0, time_stride, 2·time_stride, …).
    pub times: usize,
    /// Displacements: times × lattice nodes × dim.
    #[serde(skip)]
    pub u: Vec<f64>,
    /// Total contact force at each stored time.
    #[serde(skip)]
    pub force: Vec<f64>,
    /// Energy at each stored time.
    #[serde(skip)]
    pub energy: Vec<f64>,
    /// Mean vertical displacement of Γ_C at each stored time.
    #[serde(skip)]
    pub u_contact: Vec<f64>,
    /// The reference's mesh, for runs on meshes not nested in it (None: nested lattices).
    #[serde(skip)]
    pub mesh: Option<PlainMesh>,
    /// Sizes of the stored mesh (0 without one; absent in older files).
    #[serde(default)]
    mesh_nodes: usize,
    #[serde(default)]
    mesh_elements: usize,
    #[serde(default)]
    nodes_per_element: usize,
}

/// Why a reference file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error("{path}: cannot read the reference solution: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: damaged reference solution: {reason}")]
    Damaged { path: PathBuf, reason: String },
}

impl ReferenceData {
    /// A new reference (no values yet): `mesh` only for meshes that are not nested.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        dim: usize,
        h: f64,
        dt: f64,
        space_stride: usize,
        time_stride: usize,
        lattice: [usize; 3],
        times: usize,
        mesh: Option<PlainMesh>,
    ) -> ReferenceData {
        let n = lattice.iter().product::<usize>() * dim;
        ReferenceData {
            dim,
            h,
            dt,
            space_stride,
            time_stride,
            lattice,
            times,
            u: Vec::with_capacity(times * n),
            force: Vec::with_capacity(times),
            energy: Vec::with_capacity(times),
            u_contact: Vec::with_capacity(times),
            mesh,
            mesh_nodes: 0,
            mesh_elements: 0,
            nodes_per_element: 0,
        }
    }

    /// The header fields alone (the values are written as binary blocks).
    fn clone_header(&self) -> ReferenceData {
        ReferenceData {
            u: Vec::new(),
            force: Vec::new(),
            energy: Vec::new(),
            u_contact: Vec::new(),
            mesh: None,
            ..*self
        }
    }

    fn nodes(&self) -> usize {
        self.lattice.iter().product()
    }

    /// Displacement component `comp` at lattice index `idx` and stored time `k`.
    pub fn u_at(&self, k: usize, idx: [usize; 3], comp: usize) -> f64 {
        let node = idx[0] + self.lattice[0] * (idx[1] + self.lattice[1] * idx[2]);
        self.u[(k * self.nodes() + node) * self.dim + comp]
    }

    /// Write atomically to `path`.
    pub fn save(&self, path: &Path) -> Result<(), ReferenceError> {
        let io = |source| ReferenceError::Io {
            path: path.to_path_buf(),
            source,
        };
        let tmp = path.with_file_name(format!(
            ".{}.tmp",
            path.file_name().and_then(|n| n.to_str()).unwrap_or("ref")
        ));
        let mut f = std::io::BufWriter::new(std::fs::File::create(&tmp).map_err(io)?);
        let mut header = self.clone_header();
        if let Some(m) = &self.mesh {
            header.mesh_nodes = m.coords.len();
            header.nodes_per_element = m.nodes_per_element;
            header.mesh_elements = m.elements.len() / m.nodes_per_element.max(1);
        }
        let header = serde_json::to_string(&header).expect("serialisable header");
        writeln!(f, "{header}").map_err(io)?;
        for block in [&self.u, &self.force, &self.energy, &self.u_contact] {
            for x in block.iter() {
                f.write_all(&x.to_le_bytes()).map_err(io)?;
            }
        }
        if let Some(m) = &self.mesh {
            for x in m.coords.iter().flatten() {
                f.write_all(&x.to_le_bytes()).map_err(io)?;
            }
            for &n in &m.elements {
                f.write_all(&(n as f64).to_le_bytes()).map_err(io)?;
            }
        }
        let file = f.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    }

    /// Read a file written by [`ReferenceData::save`].
    pub fn load(path: &Path) -> Result<ReferenceData, ReferenceError> {
        let io = |source| ReferenceError::Io {
            path: path.to_path_buf(),
            source,
        };
        let damaged = |reason: String| ReferenceError::Damaged {
            path: path.to_path_buf(),
            reason,
        };
        let mut r = BufReader::new(std::fs::File::open(path).map_err(io)?);
        let mut header = String::new();
        r.read_line(&mut header).map_err(io)?;
        let mut data: ReferenceData =
            serde_json::from_str(header.trim_end()).map_err(|e| damaged(e.to_string()))?;
        let mut bytes = Vec::new();
        r.read_to_end(&mut bytes).map_err(io)?;
        let n_u = data.times * data.nodes() * data.dim;
        let n_mesh = 3 * data.mesh_nodes + data.mesh_elements * data.nodes_per_element;
        let expected = (n_u + 3 * data.times + n_mesh) * 8;
        if bytes.len() != expected {
            return Err(damaged(format!(
                "{} bytes of values, expected {expected}",
                bytes.len()
            )));
        }
        let mut vals = bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")));
        data.u = vals.by_ref().take(n_u).collect();
        data.force = vals.by_ref().take(data.times).collect();
        data.energy = vals.by_ref().take(data.times).collect();
        data.u_contact = vals.by_ref().take(data.times).collect();
        if data.mesh_nodes > 0 {
            let coords: Vec<[f64; 3]> = (0..data.mesh_nodes)
                .map(|_| [0; 3].map(|_| vals.next().expect("counted above")))
                .collect();
            let elements: Vec<usize> = vals.map(|x| x as usize).collect();
            if elements.iter().any(|&n| n >= coords.len()) || data.dim == 0 {
                return Err(damaged(
                    "mesh connectivity names a node that is not stored".into(),
                ));
            }
            data.mesh = Some(PlainMesh {
                dim: data.dim,
                nodes_per_element: data.nodes_per_element,
                coords,
                elements,
            });
        }
        Ok(data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn save_and_load_round_trip_bit_for_bit() {
        let mut d = ReferenceData::new(2, 0.025, 0.0125, 2, 4, [3, 2, 1], 2, None);
        d.u = (0..24).map(|i| (i as f64).sin()).collect();
        d.force = vec![0.0, 1.5];
        d.energy = vec![0.125, 0.124];
        d.u_contact = vec![0.0, -0.1];
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.ref");
        d.save(&p).unwrap();
        let back = ReferenceData::load(&p).unwrap();
        assert_eq!(back, d);
        assert_eq!(back.u_at(1, [2, 1, 0], 1), d.u[(6 + 5) * 2 + 1]);
        // A truncated file is reported as damaged, not read as shorter data.
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(&p, &bytes[..bytes.len() - 8]).unwrap();
        assert!(matches!(
            ReferenceData::load(&p),
            Err(ReferenceError::Damaged { .. })
        ));
    }

    #[test]
    fn a_stored_mesh_round_trips_and_a_file_without_one_still_reads() {
        let mesh = crate::space::fe::BallMesh::new(2, 2, 20.0, [0.0, 20.0, 0.0], 2, 1).unwrap();
        let plain = PlainMesh::from_mesh(&mesh);
        let nodes = plain.coords.len();
        let mut d = ReferenceData::new(2, 4.0, 0.1, 1, 1, [nodes, 1, 1], 1, Some(plain));
        d.u = (0..2 * nodes).map(|i| i as f64 * 0.5).collect();
        d.force = vec![2.0];
        d.energy = vec![0.0];
        d.u_contact = vec![-1.0];
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("ball.ref");
        d.save(&p).unwrap();
        let back = ReferenceData::load(&p).unwrap();
        assert_eq!(back.mesh, d.mesh);
        assert_eq!((back.u, back.force), (d.u, d.force));
        // A header of the previous version (no mesh fields) with its values reads as before.
        let old = "{\"dim\":1,\"h\":0.5,\"dt\":0.5,\"space_stride\":1,\"time_stride\":1,\"lattice\":[2,1,1],\"times\":1}\n";
        let mut bytes = old.as_bytes().to_vec();
        for x in [1.0f64, 2.0, 3.0, 4.0, 5.0] {
            bytes.extend(x.to_le_bytes());
        }
        std::fs::write(&p, bytes).unwrap();
        let old = ReferenceData::load(&p).unwrap();
        assert_eq!(
            (old.u, old.u_contact, old.mesh),
            (vec![1.0, 2.0], vec![5.0], None)
        );
    }
}
