//! The set-up every time loop of the engine shares (the Newmark/θ/hybrid [`super::newmark`]
//! stepper and the contract §3.2 methods): the run's first metrics, the shared geometry and step
//! factor with their cache counters, the reference map, the gaps of the contact dofs, the
//! initial velocity and its perturbation, the free fall and the observer. One copy, so both
//! loops start from the same numbers and report the same set-up failures.

use std::sync::Arc;
use std::time::Instant;

use super::bodies::MomentumTally;
use super::cache::geometry_key;
use super::config::{FeConfig, frictional};
use super::factor::{FACTORS, Factored, factor, factor_key};
use super::geometry::{GEOMETRIES, Geometry, build_geometry};
use super::reference::{RefMap, ref_map};
use crate::run::observe::Observer;
use crate::run::{Metrics, Outcome, RunContext, RunOptions, Series, Status};
use crate::space::fe::SymMatrix;

/// The metrics known before anything can fail: a failed row still gets its size and its energy
/// tolerance's length scale.
pub(super) fn initial_metrics(cfg: &FeConfig) -> Metrics {
    Metrics {
        dofs: cfg.unknowns() as i64,
        length_scale: Some(cfg.setup.geometry.length_scale()),
        ..Metrics::default()
    }
}

/// The outcome of a run that could not start.
pub(super) fn failed(status: Status, msg: String, metrics: Metrics) -> Outcome {
    Outcome {
        status,
        message: Some(msg),
        metrics,
        series: Series::default(),
        reference: None,
    }
}

/// The run's geometry from the shared cache (built by the first run that asks).
pub(super) fn shared_geometry(cfg: &FeConfig) -> Result<Arc<Geometry>, String> {
    GEOMETRIES
        .get(geometry_key(&cfg.setup), || build_geometry(&cfg.setup))
        .0
}

/// The run's geometry, then the set-up checkpoint after it (checked outside the shared
/// caches: an entry is never left half built).
pub(super) fn checked_geometry(
    cfg: &FeConfig,
    opts: &RunOptions,
    start: Instant,
) -> Result<Arc<Geometry>, (Status, String)> {
    let geo = shared_geometry(cfg).map_err(|e| (Status::Invalid, e))?;
    if let Some(stop) = opts.setup_stop(start, "the mesh and operators") {
        return Err(stop);
    }
    Ok(geo)
}

/// The step factor with stiffness coefficient `c` (cτ² of A = M + cτ²K, or the §3.2 method's
/// c) from the shared cache, its counters set in `metrics`. CG factors nothing: no
/// factorisation made, none reused (its matrix and condensation columns are still shared
/// through the cache).
pub(super) fn shared_factor(
    g: &Geometry,
    cfg: &FeConfig,
    c: f64,
    metrics: &mut Metrics,
) -> Result<Arc<Factored>, String> {
    let (fac, hit) = FACTORS.get(factor_key(g, cfg, c), || factor(g, cfg, c));
    let fac = fac?;
    let factored = fac.chol.is_factored();
    metrics.factorizations = i64::from(!hit && factored);
    metrics.factor_cache_hits = factored.then_some(i64::from(hit));
    metrics.mass_total = Some(fac.mass_total);
    Ok(fac)
}

/// The map to the reference solution of the context, if it has one.
pub(super) fn reference_map(
    g: &Geometry,
    cfg: &FeConfig,
    ctx: &RunContext,
) -> Result<Option<RefMap>, String> {
    ctx.reference
        .as_ref()
        .map(|r| ref_map(g, cfg, r))
        .transpose()
}

/// Gap of each contact dof: its height above the plane (ball) or the run's gap (box).
pub(super) fn contact_gaps(g: &Geometry, cfg: &FeConfig) -> Vec<f64> {
    let base_gap = if g.gap_in_geometry {
        0.0
    } else {
        cfg.setup.gap
    };
    g.contact_height.iter().map(|h| h + base_gap).collect()
}

/// v⁰: the scene's vertical and tangential velocities (two bodies: A's, and B's `velocity_b`
/// along e_d), times the ensemble member's perturbation 1 + δ(2r − 1) per dof.
pub(super) fn initial_velocity(g: &Geometry, cfg: &FeConfig, v: &mut [f64]) {
    for &r in &g.vertical {
        v[r] = cfg.setup.v0;
    }
    for &r in &g.tangential {
        v[r] = cfg.setup.v0_tangential;
    }
    if let Some(two) = &g.bodies {
        for &r in g.vertical.iter().chain(&g.tangential) {
            if two.body[r] == 1 {
                v[r] = 0.0;
            }
        }
        for &r in &g.vertical {
            if two.body[r] == 1 {
                v[r] = two.velocity_b;
            }
        }
    }
    if let Some((delta, seed)) = cfg.perturbation {
        let mut rng = fastrand::Rng::with_seed(seed);
        for x in v.iter_mut() {
            *x *= 1.0 + delta * (2.0 * rng.f64() - 1.0);
        }
    }
}

/// Two bodies' momentum tally with the run's mass and load vector `force` (contract §5), None for
/// one body. A clamp leaves the drift undefined; a load (gravity, pressure) moves the
/// invariant to P⁰ + tF.
pub(super) fn momentum_tally(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
    force: &[f64],
) -> Option<MomentumTally> {
    let two = g.bodies.as_ref()?;
    let loaded = cfg.setup.gravity != 0.0 || two.pressure.is_some();
    let v = (cfg.setup.v0, two.velocity_b);
    // Friction acts along the tangential axes: their momenta enter the drift (contract §2.6).
    let tangential = frictional(cfg).then(|| {
        let d = g.mesh.dim();
        let axis = |c: usize| (0..g.dofs.n_free()).filter(move |&r| g.dofs.free[r] % d == c);
        (
            (0..d - 1).map(|c| axis(c).collect()).collect(),
            cfg.setup.v0_tangential,
        )
    });
    let t_final = cfg.steps as f64 * cfg.dt;
    let load = loaded.then_some(force);
    Some(MomentumTally::new(
        two,
        &g.vertical,
        m,
        v,
        load,
        t_final,
        tangential,
    ))
}

/// The fall along e_d: on an incline (contract §1.8) the load's e_d part is −g cos α (cos 0 = 1:
/// the flat runs' numbers unchanged); free_fall_error compares the centre of mass with it.
pub(super) fn free_fall(cfg: &FeConfig) -> f64 {
    -cfg.setup.gravity * cfg.setup.incline.to_radians().cos()
}

/// The run's observer, with the gravity load's energy scale when there is one.
pub(super) fn observer(cfg: &FeConfig, opts: &RunOptions, energy_scale: Option<f64>) -> Observer {
    let mut obs = Observer::new(cfg.dt, opts.series_every, cfg.steps);
    if let Some(sc) = energy_scale {
        obs = obs.with_energy_scale(sc);
    }
    obs
}
