//! What a run will cost before it runs: resident memory and work, from its configuration only
//! (nothing is allocated here, so a plan of huge runs can be refused before any of them starts).
//!
//! Memory = state + kept series.
//! - bar1d: every per-node array of the tridiagonal engine (mass, stiffness, their LU, the
//!   Newmark state, the workspace, the exact-error buffers): 288 bytes per element, measured
//!   (peak RSS of runs with 10⁶ and 4·10⁶ elements differ by 288 B per element); the
//!   Paoli–Schatzman scheme keeps a second engine for its start (+ half again).
//! - FE scenes: the sparse Cholesky factor dominates. Its fill on the structured box is that of
//!   nested dissection, nnz(L) ≈ c·n·log₂n in 2D and c·n^{4/3} in 3D, with c calibrated on the
//!   factors measured for docs/performance.md (2D: 4.92 M entries at n = 83 200 → c = 3.63; 3D: 6.55 M at
//!   n = 19 440 → c = 12.5); 16 bytes per entry (value and row index). Besides: the step matrix,
//!   K and M ((2p+1)^d·d entries per row for degree p, 16 bytes each), the condensed contact
//!   columns Z = A⁻¹Bᵀ (n × n_c dense; the disc and ball: n_c ≈ n^((d−1)/d), a boundary's worth),
//!   and 12 work vectors of n. The mapped disc/ball meshes are taken with the box's fill.
//!   With `solver = "cg"` there is no factor: the step matrix A is kept instead (one matrix
//!   more) with CG's vectors (residual, direction, product, preconditioned residual, the
//!   previous solution and 1/diag(A): 6 of n) and, for the condensation columns, its 8-column
//!   block (4 × 8 of n, freed after the setup but part of the peak).
//! - series: (steps / series_every + 2) rows of [`SeriesRow`] (the sink's batch keys a run's
//!   rows by one id).
//!
//! Work = steps × unknowns (what the plan table prints and the Slurm shards balance).
//! The estimates are within a factor of about 2 of what a run uses; they decide refusals only
//! for runs that are far from fitting (the message states the figure).

use super::config::RunConfig;
use super::observe::SeriesRow;
use crate::scene::FeGeometry;
use crate::space::step_solver::Solver;
use crate::time::Scheme;

/// Bytes per bar1d element (measured, module header).
const BAR1D_BYTES_PER_ELEMENT: f64 = 288.0;
/// Bytes of one kept series row in the sink's batch.
const SERIES_ROW_BYTES: f64 = std::mem::size_of::<SeriesRow>() as f64;

/// A run's estimated cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Unknowns of the space discretisation.
    pub unknowns: f64,
    /// Bytes of the operators, factors and state.
    pub state_bytes: f64,
    /// Bytes of the kept time series.
    pub series_bytes: f64,
    /// Steps × unknowns.
    pub work: f64,
}

impl Estimate {
    pub fn bytes(&self) -> f64 {
        self.state_bytes + self.series_bytes
    }
}

impl RunConfig {
    /// Time steps of the run.
    pub fn steps(&self) -> usize {
        match self {
            RunConfig::Bar1d(c) => c.grid.steps,
            RunConfig::Fe(c) => c.steps,
            RunConfig::Oscillator(c) => c.steps,
            RunConfig::Layer1d(c) => c.grid.steps,
            RunConfig::Bars1d(c) => c.grid.steps,
        }
    }

    /// Memory and work of this run when every `series_every`-th step is kept (0: none). In
    /// floating point: the sizes of a refused run may exceed every integer type.
    pub fn estimate(&self, series_every: usize) -> Estimate {
        let steps = self.steps() as f64;
        let series_bytes = if series_every == 0 {
            0.0
        } else {
            (steps / series_every as f64 + 2.0) * SERIES_ROW_BYTES
        };
        let (unknowns, state_bytes) = match self {
            RunConfig::Bar1d(c) => {
                let m = c.grid.elements as f64;
                let engines = if matches!(c.grid.scheme, Scheme::PaoliSchatzman(_)) {
                    1.5
                } else {
                    1.0
                };
                (m, m * BAR1D_BYTES_PER_ELEMENT * engines)
            }
            // One dof: a few scalars and the exact solution's events (one per impact).
            RunConfig::Oscillator(_) => (1.0, 4096.0),
            // Two chains of the bar's engine.
            RunConfig::Layer1d(c) => {
                let m = c.grid.elements as f64;
                (2.0 * m, 2.0 * m * BAR1D_BYTES_PER_ELEMENT)
            }
            // One engine over both bars' unknowns.
            RunConfig::Bars1d(c) => {
                let m = (c.grid.elements + c.elements_b()) as f64;
                (m, m * BAR1D_BYTES_PER_ELEMENT)
            }
            RunConfig::Fe(c) => {
                // (unknowns, dimension, matrix entries per row, contact columns of Z), in f64.
                let (n, d, per_row, contact) = match &c.setup.geometry {
                    FeGeometry::Box { cells, .. } => {
                        let d = cells.len();
                        let nodes: f64 = cells.iter().map(|&k| k as f64 + 1.0).product();
                        let bottom: f64 = cells[..d - 1].iter().map(|&k| k as f64 + 1.0).product();
                        let n = (nodes - bottom) * d as f64;
                        (n, d, 3f64.powi(d as i32) * d as f64, bottom)
                    }
                    // Two blocks (contract §1.10): all their nodes, one row per Γ^a node.
                    FeGeometry::Blocks(b) => {
                        let d = c.setup.dim;
                        let face_of = |n: usize| (n as f64 + 1.0).powi(d as i32 - 1);
                        let face = face_of(b.across);
                        let nodes = face * (b.cells_a + 1) as f64
                            + face_of(b.across_b) * (b.cells_b + 1) as f64;
                        (nodes * d as f64, d, 3f64.powi(d as i32) * d as f64, face)
                    }
                    FeGeometry::Ball {
                        dim,
                        degree,
                        n_t,
                        n_r,
                        ..
                    } => {
                        // The node count of FeConfig::unknowns; Γ_C holds about a boundary's
                        // worth of points, n^((d−1)/d).
                        let (t, r) = ((n_t * degree) as f64, (n_r * degree) as f64);
                        let nodes = if *dim == 2 {
                            (t + 1.0).powi(2) + 4.0 * t * r
                        } else {
                            (t + 1.0).powi(3) + r * (6.0 * t * t + 2.0)
                        };
                        let n = nodes * *dim as f64;
                        let per_row = ((2 * degree + 1) as f64).powi(*dim as i32) * *dim as f64;
                        (n, *dim, per_row, n.powf((*dim as f64 - 1.0) / *dim as f64))
                    }
                    FeGeometry::Mesh {
                        dim,
                        nodes,
                        clamped_nodes,
                        contact_nodes,
                        nodes_per_element,
                        ..
                    } => {
                        let n = (nodes - clamped_nodes) as f64 * *dim as f64;
                        // Nodes coupled to a node (its row's nodes) on a regular mesh of each
                        // cell kind, the worst node kind: Q1/Q2 3^d/5^d as the box and ball;
                        // triangles 7 (P1) and 19 (P2, a vertex of 6 triangles); tetrahedra
                        // 27 (P1, a vertex of ~24 Freudenthal tetrahedra) and 85 (P2).
                        let coupled = match (*dim, *nodes_per_element) {
                            (2, 3) => 7.0,
                            (2, 6) => 19.0,
                            (2, 4) => 9.0,
                            (2, _) => 25.0,
                            (3, 4) => 27.0,
                            (3, 10) => 85.0,
                            (3, 8) => 27.0,
                            _ => 125.0,
                        };
                        (n, *dim, coupled * *dim as f64, *contact_nodes as f64)
                    }
                };
                let (fill, matrices, vectors) = match c.solver {
                    Solver::Direct => (
                        if d == 2 {
                            3.63 * n * n.max(2.0).log2()
                        } else {
                            12.5 * n.powf(4.0 / 3.0)
                        },
                        3.0,
                        12.0,
                    ),
                    Solver::Cg { .. } => (0.0, 4.0, 12.0 + 6.0 + 32.0),
                };
                let matrices = matrices * per_row * n * 16.0;
                (
                    n,
                    fill * 16.0 + matrices + n * contact * 8.0 + vectors * n * 8.0,
                )
            }
        };
        Estimate {
            unknowns,
            state_bytes,
            series_bytes,
            work: steps * unknowns,
        }
    }
}

/// Bytes as a human figure: 1.5 GiB, 300 MiB.
pub fn human_bytes(b: f64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut x = b;
    let mut u = 0;
    while x >= 1024.0 && u + 1 < UNITS.len() {
        x /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{x:.0} {}", UNITS[u])
    } else {
        format!("{x:.1} {}", UNITS[u])
    }
}

/// Parse a byte size: a number with an optional unit K, M, G, T (powers of 1024; `KiB`, `KB`,
/// `k` … accepted).
pub fn parse_bytes(text: &str) -> Option<f64> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == 'E'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let x: f64 = num.parse().ok()?;
    let scale = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" | "kib" => 1024.0,
        "m" | "mb" | "mib" => 1024f64.powi(2),
        "g" | "gb" | "gib" => 1024f64.powi(3),
        "t" | "tb" | "tib" => 1024f64.powi(4),
        _ => return None,
    };
    (x.is_finite() && x > 0.0).then_some(x * scale)
}

/// Memory available to new processes (MemAvailable of /proc/meminfo), if the kernel says.
pub fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_print() {
        assert_eq!(parse_bytes("512M"), Some(512.0 * 1024.0 * 1024.0));
        assert_eq!(parse_bytes("2GiB"), Some(2.0 * 1024f64.powi(3)));
        assert_eq!(parse_bytes("1000"), Some(1000.0));
        assert_eq!(parse_bytes("-1G"), None);
        assert_eq!(parse_bytes("3X"), None);
        assert_eq!(human_bytes(1.5 * 1024f64.powi(3)), "1.5 GiB");
        assert_eq!(human_bytes(100.0), "100 B");
    }
}
