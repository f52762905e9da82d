//! Reference solutions of scenes without a closed form (SPEC §1.2): a run of the same scene on a
//! nested finer mesh and step records its solution on the lattice its consumers need — every
//! `space_stride`-th node along each axis, every `time_stride`-th step — and each coarse run
//! reads its own nodes and times from it (nested meshes: every coarse node is a reference node,
//! every coarse time a reference time, so I_h u_ref is a plain lookup).
//!
//! On disk (`DIR/references/<run_id>.ref`): a JSON header line, then the values as
//! little-endian f64 — the file is written to a temporary name, fsynced and renamed, so it is
//! either whole or absent.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

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
        let header = serde_json::to_string(self).expect("serialisable header");
        writeln!(f, "{header}").map_err(io)?;
        for block in [&self.u, &self.force, &self.energy, &self.u_contact] {
            for x in block.iter() {
                f.write_all(&x.to_le_bytes()).map_err(io)?;
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
        let expected = (n_u + 3 * data.times) * 8;
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
        data.u_contact = vals.take(data.times).collect();
        Ok(data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn save_and_load_round_trip_bit_for_bit() {
        let d = ReferenceData {
            dim: 2,
            h: 0.025,
            dt: 0.0125,
            space_stride: 2,
            time_stride: 4,
            lattice: [3, 2, 1],
            times: 2,
            u: (0..24).map(|i| (i as f64).sin()).collect(),
            force: vec![0.0, 1.5],
            energy: vec![0.125, 0.124],
            u_contact: vec![0.0, -0.1],
        };
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
}
