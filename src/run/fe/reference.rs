//! Errors against a reference run and the recording of one (contract §1.2): the map from a
//! reference's lattice (or its mesh, interpolated) to this run's dofs, and the lattice a
//! reference run records.

use std::sync::Arc;

use super::cache::{Cache, geometry_key};
use super::config::FeConfig;
use super::geometry::Geometry;
use super::products::quad;
use crate::run::RunContext;
use crate::run::observe::ExactValues;
use crate::run::reference::ReferenceData;
use crate::space::fe::Mesh;
use crate::space::fe::locate::{PlainMesh, PointLocator};

/// How the run reads its reference: for every free dof, its offset in a stored time slice (or,
/// on a mesh not nested in the reference's, the offsets and weights that interpolate the
/// reference there); and the stored index of coarse step n is n·`time_ratio`.
pub(super) struct RefMap {
    pub(super) data: Arc<ReferenceData>,
    pub(super) dof_offset: Vec<usize>,
    pub(super) interp: Option<Arc<Interpolation>>,
    pub(super) time_ratio: usize,
}

/// I u_ref at the run's free dofs: dof i is Σ_k w_k u_ref[offset_k] over
/// `start[i]..start[i + 1]` ([`crate::space::fe::locate`]).
#[derive(Debug)]
pub(super) struct Interpolation {
    pub(super) start: Vec<usize>,
    pub(super) offset: Vec<usize>,
    pub(super) weight: Vec<f64>,
}

impl RefMap {
    /// The run at step n against the reference at the same time: e = u − I u_ref into `err`,
    /// its squared L2 and H1-seminorm (the Gram and grad-grad matrices, `tmp` as scratch), and
    /// the reference's scalar observables. One definition for every time loop of the engine.
    pub(super) fn compare(
        &self,
        g: &Geometry,
        step: usize,
        u: &[f64],
        err: &mut [f64],
        tmp: &mut [f64],
    ) -> ExactValues {
        let k = step * self.time_ratio;
        let base = k * self.data.lattice.iter().product::<usize>() * self.data.dim;
        for (i, e) in err.iter_mut().enumerate() {
            *e = u[i] - self.value(base, i);
        }
        let l2_sq = quad(&g.gram, err, tmp);
        let h1_semi_sq = quad(&g.grad, err, tmp);
        ExactValues {
            u_contact: self.data.u_contact[k],
            sigma_contact: -self.data.force[k],
            sigma_contact_mid: None,
            energy: self.data.energy[k],
            l2_sq,
            h1_semi_sq,
        }
    }

    /// The reference's value at free dof i in the stored slice starting at `base`.
    #[inline]
    pub(super) fn value(&self, base: usize, i: usize) -> f64 {
        match &self.interp {
            None => self.data.u[base + self.dof_offset[i]],
            Some(ip) => (ip.start[i]..ip.start[i + 1])
                .map(|k| ip.weight[k] * self.data.u[base + ip.offset[k]])
                .sum(),
        }
    }
}

/// Interpolations shared by the runs of one mesh against one reference.
pub(super) static INTERPOLATIONS: Cache<Interpolation> = Cache::new();

pub(super) fn ref_map(
    g: &Geometry,
    cfg: &FeConfig,
    data: &Arc<ReferenceData>,
) -> Result<RefMap, String> {
    let Some(mesh) = g.mesh.as_box() else {
        return ball_ref_map(g, cfg, data);
    };
    let d = mesh.dim;
    let ratio = |coarse: f64, fine: f64, stride: usize, what: &str| {
        let q = coarse / fine;
        let r = q.round() as usize;
        if r == 0 || (q - r as f64).abs() > 1e-9 * q || !r.is_multiple_of(stride) {
            Err(format!(
                "the reference's {what} ({fine}) is not nested in the run's ({coarse}) on its stored lattice (stride {stride})"
            ))
        } else {
            Ok(r / stride)
        }
    };
    let rs = ratio(cfg.setup.h, data.h, data.space_stride, "mesh size")?;
    let rt = ratio(cfg.dt, data.dt, data.time_stride, "time step")?;
    if data.dim != d || (0..d).any(|a| mesh.cells[a] * rs + 1 != data.lattice[a]) {
        return Err("the reference's lattice does not cover the run's mesh".into());
    }
    if cfg.steps * rt >= data.times {
        return Err(format!(
            "the reference holds {} stored times, the run needs {}",
            data.times,
            cfg.steps * rt + 1
        ));
    }
    let slice = data.lattice.iter().product::<usize>() * d;
    let _ = slice;
    let dof_offset = g
        .dofs
        .free
        .iter()
        .map(|&gd| {
            let idx = mesh.node_index(gd / d);
            let l = [idx[0] * rs, idx[1] * rs, idx[2] * rs];
            let node = l[0] + data.lattice[0] * (l[1] + data.lattice[1] * l[2]);
            node * d + gd % d
        })
        .collect();
    Ok(RefMap {
        data: Arc::clone(data),
        dof_offset,
        interp: None,
        time_ratio: rt,
    })
}

/// The disc/ball or a mesh file's run against its reference. On the run's own mesh (a finer
/// step only) the stored dofs are the run's, read one to one. On another mesh — the mapped
/// meshes of two sizes are not nested: n_t = 2·round(πR/(4h)) and n_r = round((R − a)/h) give
/// (8, 3), (16, 5), (32, 10) at h = 4, 2, 1; another mesh file; the bars' box meshed by a mesh
/// file (contract §1.6) — each run node is located in the reference's stored mesh and the
/// reference's finite-element function is evaluated there ([`Interpolation`]).
pub(super) fn ball_ref_map(
    g: &Geometry,
    cfg: &FeConfig,
    data: &Arc<ReferenceData>,
) -> Result<RefMap, String> {
    // The reference stores every node of its mesh, node-major (`record_lattice`; a mesh
    // file's clamped nodes as zeros, a box's at stride 1 in its lattice order = node order).
    let d = g.mesh.dim();
    let mesh = g.mesh.mesh();
    let nodes = mesh.num_nodes();
    let same_mesh = data.h == cfg.setup.h
        && data.lattice == [nodes, 1, 1]
        && data.mesh.as_ref().is_none_or(|m| {
            m.dim == d
                && m.nodes_per_element == mesh.nodes_per_element()
                && m.coords.len() == nodes
                && (0..nodes).all(|n| m.coords[n] == mesh.coord(n))
                && (0..mesh.num_elements()).all(|e| m.element_nodes(e) == mesh.element_nodes(e))
        });
    // Interpolating reads the reference's dofs by node (rn·d + component): every node of its
    // stored mesh must be stored.
    let interpolable = data
        .mesh
        .as_ref()
        .is_some_and(|m| data.lattice.iter().product::<usize>() == m.coords.len());
    if data.space_stride != 1 || (!same_mesh && !interpolable) {
        return Err(format!(
            "scene {}: the reference (h = {}, {} stored nodes) is on another mesh than the run's (h = {}, {nodes} nodes) and cannot be interpolated: it does not store its whole mesh (written by an older version: remove DIR/references/ to record it again)",
            cfg.setup.scene,
            data.h,
            data.lattice.iter().product::<usize>(),
            cfg.setup.h
        ));
    }
    let q = cfg.dt / data.dt;
    let r = q.round() as usize;
    if r == 0 || (q - r as f64).abs() > 1e-9 * q || !r.is_multiple_of(data.time_stride) {
        return Err(format!(
            "the reference's time step ({}) is not nested in the run's ({}) on its stored times (stride {})",
            data.dt, cfg.dt, data.time_stride
        ));
    }
    let rt = r / data.time_stride;
    if data.dim != d || cfg.steps * rt >= data.times {
        return Err(format!(
            "the reference holds {} stored times, the run needs {}",
            data.times,
            cfg.steps * rt + 1
        ));
    }
    let interp = match (&data.mesh, same_mesh) {
        (Some(ref_mesh), false) => {
            let key = format!(
                "{}|{:p}|{:e}|{}|{}",
                geometry_key(&cfg.setup),
                Arc::as_ptr(data),
                data.h,
                data.times,
                ref_mesh.coords.len()
            );
            let (ip, _) = INTERPOLATIONS.get(key, || interpolation(g, ref_mesh));
            Some(ip.map_err(|e| format!("scene {}: {e}", cfg.setup.scene))?)
        }
        _ => None,
    };
    Ok(RefMap {
        data: Arc::clone(data),
        // On the same mesh: free dof i is global dof free[i] = node·d + component.
        dof_offset: g.dofs.free.clone(),
        interp,
        time_ratio: rt,
    })
}

/// Locate every node of the run's mesh in the reference mesh; the weights of a node serve each
/// of its components (the reference stores every dof of its mesh, node-major).
pub(super) fn interpolation(g: &Geometry, reference: &PlainMesh) -> Result<Interpolation, String> {
    let d = g.mesh.dim();
    let locator = PointLocator::new(reference).map_err(|e| e.to_string())?;
    let mesh = g.mesh.mesh();
    let mut per_node: Vec<Option<Vec<(usize, f64)>>> = vec![None; mesh.num_nodes()];
    let n = g.dofs.n_free();
    let mut ip = Interpolation {
        start: Vec::with_capacity(n + 1),
        offset: Vec::new(),
        weight: Vec::new(),
    };
    ip.start.push(0);
    for &gd in &g.dofs.free {
        let node = gd / d;
        if per_node[node].is_none() {
            per_node[node] = Some(
                locator
                    .weights(mesh.coord(node))
                    .map_err(|e| format!("run node {node}: {e}"))?,
            );
        }
        for &(rn, w) in per_node[node].as_ref().expect("just set") {
            ip.offset.push(rn * d + gd % d);
            ip.weight.push(w);
        }
        ip.start.push(ip.offset.len());
    }
    Ok(ip)
}

/// The stored slots (a reduced dof or none, per lattice node and component) and the lattice of
/// a reference run: every `space_stride`-th node of the bars' box, or every node of the
/// disc/ball or mesh file, clamped ones included (stride 1 only: its meshes are not nested,
/// [`ball_ref_map`]).
pub(super) fn record_lattice(
    g: &Geometry,
    cfg: &FeConfig,
    space_stride: usize,
) -> Result<(Vec<Option<usize>>, [usize; 3]), String> {
    let d = g.mesh.dim();
    let Some(bx) = g.mesh.as_box() else {
        if space_stride != 1 {
            return Err(format!(
                "scene {}: a reference run must be on the runs' mesh (their h / its h = {space_stride}): the mapped meshes of different sizes are not nested",
                cfg.setup.scene
            ));
        }
        // Node-major over every node: a run on another mesh reads the reference by node
        // ([`interpolation`]); a clamped dof (mesh files) has no slot and is stored as 0.
        let n = g.mesh.mesh().num_nodes() * d;
        return Ok((
            (0..n).map(|gd| g.dofs.free_index(gd)).collect(),
            [n / d, 1, 1],
        ));
    };
    let lattice = [0, 1, 2].map(|ax| {
        if ax < d {
            bx.cells[ax] / space_stride + 1
        } else {
            1
        }
    });
    let mut slots = Vec::with_capacity(lattice.iter().product::<usize>() * d);
    for k in 0..lattice[2] {
        for j in 0..lattice[1] {
            for i in 0..lattice[0] {
                let node = bx.node_id([i * space_stride, j * space_stride, k * space_stride]);
                for comp in 0..d {
                    slots.push(g.dofs.free_index(node * d + comp));
                }
            }
        }
    }
    Ok((slots, lattice))
}

/// The reference this run records, if it is one: the slots of its stored lattice and the empty
/// data. Meshes that are not nested store themselves: a coarser run locates its nodes in this
/// one ([`ball_ref_map`]). So does the bars' box stored whole (stride 1: its lattice is its
/// node numbering), for the runs on a mesh file of the same bar (contract §1.6); a nested bar run
/// still reads it node for node.
#[allow(clippy::type_complexity)]
pub(super) fn reference_record(
    g: &Geometry,
    cfg: &FeConfig,
    ctx: &RunContext,
) -> Result<Option<(Vec<Option<usize>>, ReferenceData)>, String> {
    let Some((space_stride, time_stride)) = ctx.record_reference else {
        return Ok(None);
    };
    let (slots, lattice) = record_lattice(g, cfg, space_stride)?;
    let times = cfg.steps / time_stride + 1;
    let mesh = (g.mesh.as_box().is_none() || space_stride == 1)
        .then(|| PlainMesh::from_mesh(g.mesh.mesh()));
    let data = ReferenceData::new(
        g.mesh.dim(),
        cfg.setup.h,
        cfg.dt,
        space_stride,
        time_stride,
        lattice,
        times,
        mesh,
    );
    Ok(Some((slots, data)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::fe::geometry::build_geometry;
    use crate::scene::{FeGeometry, FeSetup, LoadModel};
    use crate::space::fe::BallMesh;

    fn disc(h: f64) -> FeSetup {
        let (n_t, n_r) = BallMesh::counts_for_size(20.0, h);
        FeSetup {
            scene: "disc2d",
            dim: 2,
            geometry: FeGeometry::Ball {
                dim: 2,
                degree: 2,
                radius: 20.0,
                centre_height: 21.0,
                n_t,
                n_r,
            },
            h,
            density: 1.0,
            lame_lambda: 1.0,
            lame_mu: 1.0,
            gap: 1.0,
            gravity: 0.1,
            load: LoadModel::Body,
            v0: 0.0,
            v0_tangential: 0.0,
            incline: 0.0,
            static_start: false,
        }
    }

    /// Issue 22: for nested meshes the interpolating path equals the node-for-node one to
    /// 1e-12. The disc against a reference on its own mesh: every run dof takes its own
    /// reference dof with weight 1 and every other weight vanishes, to round-off of the
    /// inverse map (Newton to 1e-15 on elements of size ~1, weights O(1)).
    #[test]
    fn interpolating_a_reference_on_the_same_mesh_is_the_identity() {
        let g = build_geometry(&disc(4.0)).unwrap();
        let plain = PlainMesh::from_mesh(g.mesh.mesh());
        let ip = interpolation(&g, &plain).unwrap();
        for i in 0..g.dofs.n_free() {
            for k in ip.start[i]..ip.start[i + 1] {
                let want = if ip.offset[k] == i { 1.0 } else { 0.0 };
                // A node shared by several elements appears once: its weight is 1.
                assert!(
                    (ip.weight[k] - want).abs() < 1e-12,
                    "dof {i}: weight {} at offset {}",
                    ip.weight[k],
                    ip.offset[k]
                );
            }
            let total: f64 = (ip.start[i]..ip.start[i + 1]).map(|k| ip.weight[k]).sum();
            assert!((total - 1.0).abs() < 1e-12, "partition of unity at dof {i}");
        }
    }

    /// A coarser disc in finer ones: each run node gets weights summing to 1 (the shape
    /// functions' partition of unity), and a smooth field given at the reference nodes is
    /// evaluated at the run's nodes with the error of Q2 interpolation, O(h_ref³): halving
    /// h_ref divides it by ~8 (measured 2.84e-4 → 3.06e-5, ×9.3; asserted ≥ 6), and it is
    /// small in absolute terms (f = sin(x/7)·cos(y/5), third derivatives ≤ 1/125).
    #[test]
    fn a_coarse_disc_interpolates_finer_ones_at_the_q2_rate() {
        let f = |x: [f64; 3]| (x[0] / 7.0).sin() * (x[1] / 5.0).cos();
        // h = 4: (n_t, n_r) = (8, 3), not nested in (16, 5) or (32, 10).
        let coarse = build_geometry(&disc(4.0)).unwrap();
        let error = |h_ref: f64| {
            let fine = build_geometry(&disc(h_ref)).unwrap();
            let plain = PlainMesh::from_mesh(fine.mesh.mesh());
            let ip = interpolation(&coarse, &plain).unwrap();
            let mut worst = 0.0f64;
            for (i, &gd) in coarse.dofs.free.iter().enumerate() {
                let total: f64 = (ip.start[i]..ip.start[i + 1]).map(|k| ip.weight[k]).sum();
                assert!((total - 1.0).abs() < 1e-12);
                let v: f64 = (ip.start[i]..ip.start[i + 1])
                    .map(|k| ip.weight[k] * f(plain.coords[ip.offset[k] / 2]))
                    .sum();
                worst = worst.max((v - f(coarse.mesh.mesh().coord(gd / 2))).abs());
            }
            worst
        };
        let (e2, e1) = (error(2.0), error(1.0));
        assert!(
            e1 < e2 / 6.0 && e1 < 1e-4,
            "max errors {e2:e} (h = 2), {e1:e} (h = 1)"
        );
    }
}
