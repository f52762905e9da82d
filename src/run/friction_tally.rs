//! The friction observables of a finite-element run (contract §1.8, §2.5, §5), one tally for every
//! FE engine with friction (the mixed Newmark/θ stepper, contract §3.2's methods, Nitsche).
//!
//! Per step n → n+1 the engine hands over the contact forces f^{n+1} of its contact points
//! (node-major [f_n, f_t…], d per point, on the body: f_n ≥ 0 along e_d, f_t along e_1 (, e_2))
//! and the tangential displacement increments Δu_t = u_t^{n+1} − u_t^n. The tally keeps
//!
//! - the frictional work W_f^{n+1} = W_f^n − Σ_i f̄_t,i·Δu_t,i with the scheme's
//!   f̄ = (1 − γ) f_t^n + γ f_t^{n+1} (CN/Newmark: γ; θ-scheme: θ; generalized-α: 1 − α_f;
//!   kane, Moreau–Jean: 1), the tangential force as it enters the momentum equation, so that
//!   E^{n+1} + W_f^{n+1} − (E^n + W_f^n) is the normal contact's work in the step;
//! - the largest one-step rise of E + W_f (the engine reports each E^n, step 0 first);
//! - the step's own tangential work −Σ_i f_t,i^{n+1}·Δu_t,i, whose minimum over the steps is
//!   ≥ 0 for every position-level method (the law's sign: f_t opposes the slip);
//! - contact point-steps in stick (f_n > 0 and |Δu_t| ≤ 1e-12·h) and in slip;
//! - max over the contact steps of |Σ f_t|/Σ f_n, the apparent friction coefficient;
//! - the total tangential force Σ_i f_t,i of the step (the series' `sigma_t_contact`);
//! - `stop_time`: the first time the body's mean tangential velocity 1ᵀMv_1/1ᵀM1 (reported by
//!   the engine every step) reaches 0, linearly interpolated between the two steps where it
//!   changes sign; none if it never does or starts at 0.
//!
//! Nothing is allocated after [`FrictionTally::new`].
//!
//! [`MeanVelocity`] gives the body's mean velocity per axis, v̄_k = 1_kᵀMv/1_kᵀM1_k with 1_k the
//! indicator of axis k's dofs (the momentum along e_k over the mass along it), from the M v the
//! engines carry: the stop time's e_1 component and the final `tangential_velocity_final`
//! (v̄_1 in 2D, √(v̄_1² + v̄_2²) in 3D) and `normal_velocity_final` (v̄_d) of contract §5.

use super::observe::Metrics;
use crate::space::fe::SymMatrix;

/// The body's mean velocity per axis from M v (module header): each axis' reduced dofs and
/// 1ᵀM1 over them, made once at setup.
#[derive(Debug, Clone)]
pub struct MeanVelocity {
    /// Reduced dofs of e_1, e_2 (empty in 2D) and e_d.
    axes: [Vec<usize>; 3],
    /// 1_kᵀM1_k per axis (0 for an empty axis).
    mass: [f64; 3],
}

impl MeanVelocity {
    /// In dimension `d` (2 or 3) with the mass matrix `m` over the reduced dofs, whose
    /// component (0 ≤ c < d) is `axis_of(r)`.
    pub fn new(d: usize, m: &SymMatrix, axis_of: impl Fn(usize) -> usize) -> Self {
        assert!(d == 2 || d == 3, "d = 2 or 3");
        let n = m.n();
        let axis = |c: usize| -> Vec<usize> { (0..n).filter(|&r| axis_of(r) == c).collect() };
        let axes = [
            axis(0),
            if d == 3 { axis(1) } else { Vec::new() },
            axis(d - 1),
        ];
        // 1ᵀM1 over each axis: M applied to the axis' indicator, summed on it (setup only).
        let (mut one, mut m1) = (vec![0.0; n], vec![0.0; n]);
        let mass = [0, 1, 2].map(|k| {
            one.iter_mut().for_each(|x| *x = 0.0);
            axes[k].iter().for_each(|&r| one[r] = 1.0);
            m.matvec_into(&one, &mut m1);
            axes[k].iter().map(|&r| m1[r]).sum::<f64>()
        });
        MeanVelocity { axes, mass }
    }

    /// [v̄_1, v̄_2, v̄_d] from `mv` = M v into `out` (v̄_2 = 0 in 2D; 0 on an axis without mass).
    pub fn means_into(&self, mv: &[f64], out: &mut [f64; 3]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = if self.mass[k] == 0.0 {
                0.0
            } else {
                self.axes[k].iter().map(|&r| mv[r]).sum::<f64>() / self.mass[k]
            };
        }
    }

    /// The tangential value of contract §5 from [v̄_1, v̄_2, v̄_d]: v̄_1 in 2D, the norm
    /// √(v̄_1² + v̄_2²) in 3D.
    pub fn tangential(&self, means: &[f64; 3]) -> f64 {
        if self.axes[1].is_empty() {
            means[0]
        } else {
            means[0].hypot(means[1])
        }
    }
}

/// One step's apparent friction coefficient |Σf_t|/Σf_n (the sums over the contact points, the
/// tangential one a vector in 3D) into the running maximum `ratio_max`; a step without normal
/// force has none.
fn ratio_step(ratio_max: &mut Option<f64>, sum_n: f64, sum_t: [f64; 2]) {
    if sum_n > 0.0 {
        let r = (sum_t[0] * sum_t[0] + sum_t[1] * sum_t[1]).sqrt() / sum_n;
        *ratio_max = Some(ratio_max.map_or(r, |m| m.max(r)));
    }
}

/// The running friction observables of one run (module header).
#[derive(Debug, Clone)]
pub struct FrictionTally {
    points: usize,
    /// d: rows per point (normal, then d − 1 tangential).
    d: usize,
    /// 1e-12·h: a point-step sticks when |Δu_t| is below it.
    stick_tol: f64,
    /// f̄ = (1 − γ) fⁿ + γ f^{n+1}.
    gamma: f64,
    /// f_t^n of each point ((d − 1) per point).
    ft_prev: Vec<f64>,
    work: f64,
    /// E + W_f of the last reported step, and E⁰.
    balance_prev: Option<f64>,
    e0: Option<f64>,
    max_inc: f64,
    tangential_work_min: f64,
    stick: i64,
    slip: i64,
    ratio_max: Option<f64>,
    total_t: [f64; 2],
    /// The mean tangential velocity: its first value, the last (t, v), the stop.
    v_first: Option<f64>,
    v_last: Option<(f64, f64)>,
    stop_time: Option<f64>,
    steps: usize,
    /// The contact solve's iterations per stage over the run ([`stage_columns`]).
    stages: [usize; 3],
}

impl FrictionTally {
    /// A tally for `points` contact points in dimension `d` (2 or 3), mesh size `h` (the
    /// stick threshold 1e-12·h) and the scheme's weight `gamma` of f^{n+1} in f̄.
    pub fn new(points: usize, d: usize, h: f64, gamma: f64) -> Self {
        assert!(d == 2 || d == 3, "d = 2 or 3");
        FrictionTally {
            points,
            d,
            stick_tol: 1e-12 * h,
            gamma,
            ft_prev: vec![0.0; points * (d - 1)],
            work: 0.0,
            balance_prev: None,
            e0: None,
            max_inc: f64::NEG_INFINITY,
            tangential_work_min: f64::INFINITY,
            stick: 0,
            slip: 0,
            ratio_max: None,
            total_t: [0.0; 2],
            v_first: None,
            v_last: None,
            stop_time: None,
            steps: 0,
            stages: [0; 3],
        }
    }

    /// The forces at t = 0 (`points`·d, node-major), f_t⁰ of the first step's f̄_t and the
    /// series' Σf_t at step 0: a quasi-static start's (contract §2.2), zero otherwise.
    pub fn start_forces(&mut self, forces: &[f64]) {
        let (d, t) = (self.d, self.d - 1);
        assert_eq!(forces.len(), self.points * d, "d forces per point");
        self.total_t = [0.0; 2];
        for i in 0..self.points {
            let ft = &forces[i * d + 1..(i + 1) * d];
            self.ft_prev[i * t..(i + 1) * t].copy_from_slice(ft);
            for (s, f) in self.total_t.iter_mut().zip(ft) {
                *s += f;
            }
        }
    }

    /// Step n → n+1: the forces f^{n+1} (`points`·d, node-major) and the increments Δu_t
    /// (`points`·(d − 1), node-major). Returns W_f^{n+1}.
    pub fn step(&mut self, forces: &[f64], du_t: &[f64]) -> f64 {
        self.step_with(forces, du_t, None)
    }

    /// [`Self::step`] with each point's stick/slip state given (`slides[i]`: point i slides)
    /// instead of the increment rule: Nitsche's and the penalty's regularised stick, decided
    /// by their cone at the quadrature points (the Γ_C contact solve's own state).
    pub fn step_with(&mut self, forces: &[f64], du_t: &[f64], slides: Option<&[bool]>) -> f64 {
        let (d, t) = (self.d, self.d - 1);
        assert_eq!(forces.len(), self.points * d, "d forces per point");
        assert_eq!(du_t.len(), self.points * t, "d − 1 increments per point");
        let (g0, g1) = (1.0 - self.gamma, self.gamma);
        let (mut work, mut own) = (0.0, 0.0);
        let (mut sum_n, mut sum_t) = (0.0, [0.0; 2]);
        for i in 0..self.points {
            let f_n = forces[i * d];
            let ft = &forces[i * d + 1..(i + 1) * d];
            let du = &du_t[i * t..(i + 1) * t];
            let prev = &mut self.ft_prev[i * t..(i + 1) * t];
            let mut du2 = 0.0;
            for c in 0..t {
                work -= (g0 * prev[c] + g1 * ft[c]) * du[c];
                own -= ft[c] * du[c];
                du2 += du[c] * du[c];
                prev[c] = ft[c];
                sum_t[c] += ft[c];
            }
            sum_n += f_n;
            if f_n > 0.0 {
                let stuck = slides.map_or(du2.sqrt() <= self.stick_tol, |s| !s[i]);
                if stuck {
                    self.stick += 1;
                } else {
                    self.slip += 1;
                }
            }
        }
        self.work += work;
        self.tangential_work_min = self.tangential_work_min.min(own);
        self.total_t = sum_t;
        ratio_step(&mut self.ratio_max, sum_n, sum_t);
        self.steps += 1;
        self.work
    }

    /// E^n of the state just made (step 0 first): the balance E + W_f and its largest rise.
    /// The first energy is E⁰, whose balance is E⁰ + W_f⁰ = E⁰ whatever the tally holds: an
    /// engine that hands E⁰ in only after its first step (Nitsche, penalty: E⁰ with E¹) has
    /// W_f¹ here already, and E⁰ + W_f¹ as the start hid step 1's rise (+0.35 energy scales
    /// reported as −4.2e-4, issue 42).
    pub fn energy(&mut self, e: f64) {
        let balance = if self.e0.is_none() { e } else { e + self.work };
        if let Some(prev) = self.balance_prev {
            self.max_inc = self.max_inc.max(balance - prev);
        }
        self.e0.get_or_insert(e);
        self.balance_prev = Some(balance);
    }

    /// The body's mean tangential velocity 1ᵀMv_1/1ᵀM1 at time t (every step, step 0 first).
    pub fn velocity(&mut self, t: f64, v: f64) {
        let first = *self.v_first.get_or_insert(v);
        if self.stop_time.is_none()
            && first != 0.0
            && let Some((t0, v0)) = self.v_last
            && v * first.signum() <= 0.0
        {
            // v0 has the sign of the first value (no stop yet): v0 − v ≠ 0.
            self.stop_time = Some(t0 + (t - t0) * v0 / (v0 - v));
        }
        self.v_last = Some((t, v));
    }

    /// W_f so far.
    pub fn work(&self) -> f64 {
        self.work
    }

    /// Σ_i f_t,i of the last step (e_1, e_2; the second 0 in 2D).
    pub fn total_tangential(&self) -> [f64; 2] {
        self.total_t
    }

    /// min over the steps of the step's own tangential work −Σ f_t^{n+1}·Δu_t (∞ before the
    /// first step).
    pub fn tangential_work_min(&self) -> f64 {
        self.tangential_work_min
    }

    /// A step's contact solve spent `s` iterations in its stages ([`stage_columns`]).
    pub fn add_stages(&mut self, s: [usize; 3]) {
        for (a, b) in self.stages.iter_mut().zip(s) {
            *a += b;
        }
    }

    /// The friction columns (contract §5) into `metrics`: energies over `energy_scale`, and the
    /// body's final mean tangential (3D: the norm of both) and normal velocities.
    pub fn finish(
        &self,
        metrics: &mut Metrics,
        energy_scale: f64,
        tangential_velocity_final: f64,
        normal_velocity_final: f64,
    ) {
        let scale = energy_scale.abs().max(f64::MIN_POSITIVE);
        metrics.friction_work = Some(self.work / scale);
        stage_columns(metrics, self.stages);
        metrics.energy_balance_drift = match (self.balance_prev, self.e0) {
            (Some(b), Some(e0)) => Some((b - e0) / scale),
            _ => None,
        };
        metrics.energy_balance_max_increase = Some(if self.steps > 0 && self.max_inc.is_finite() {
            self.max_inc / scale
        } else {
            0.0
        });
        metrics.stick_steps = Some(self.stick);
        metrics.slip_steps = Some(self.slip);
        metrics.friction_ratio_max = self.ratio_max;
        metrics.tangential_velocity_final = Some(tangential_velocity_final);
        metrics.normal_velocity_final = Some(normal_velocity_final);
        metrics.stop_time = self.stop_time;
        metrics.tangential_work_min = Some(if self.steps > 0 {
            self.tangential_work_min / scale
        } else {
            0.0
        });
    }
}

/// The frictional solve's iterations per stage over the run into `metrics` (contract §4):
/// the primary Newton, the continuation in the bound, the fallback (Gauss–Seidel and its polish,
/// then Nitsche/penalty's Lemke in 2D).
pub fn stage_columns(metrics: &mut Metrics, s: [usize; 3]) {
    metrics.friction_newton_iterations = Some(s[0] as i64);
    metrics.friction_continuation_iterations = Some(s[1] as i64);
    metrics.friction_fallback_iterations = Some(s[2] as i64);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two points in 2D over two steps, by hand: W_f with CN's f̄, the own work, stick/slip,
    /// the ratio, the balance. Binary fractions: exact.
    #[test]
    fn a_hand_computed_tally() {
        let mut t = FrictionTally::new(2, 2, 0.5, 0.5);
        t.energy(1.0);
        // Step 1: point 0 slides +0.25 under f_t = −0.5 (f_n = 2), point 1 sticks (f_n = 1,
        // f_t = 0.25), W_f = −(½·0 + ½·(−0.5))·0.25 = 0.0625.
        let w = t.step(&[2.0, -0.5, 1.0, 0.25], &[0.25, 0.0]);
        assert_eq!(w, 0.0625);
        assert_eq!(t.tangential_work_min(), 0.125);
        t.energy(0.9375);
        // Step 2: no contact, point 0 moves back by 0.5: f̄ = ½(−0.5) + 0, W_f += −0.125.
        let w = t.step(&[0.0, 0.0, 0.0, 0.0], &[-0.5, 0.0]);
        assert_eq!(w, -0.0625);
        t.energy(1.0);
        let mut m = Metrics::default();
        t.finish(&mut m, 2.0, 0.1, -0.2);
        assert_eq!(m.friction_work, Some(-0.03125));
        assert_eq!(m.stick_steps, Some(1));
        assert_eq!(m.slip_steps, Some(1));
        // |Σf_t|/Σf_n = 0.25/3 at step 1.
        assert_eq!(m.friction_ratio_max, Some(0.25 / 3.0));
        // E + W_f: 1, 1, 0.9375: the rise 0 at step 1, and drift −0.0625/2.
        assert_eq!(m.energy_balance_max_increase, Some(0.0));
        assert_eq!(m.energy_balance_drift, Some(-0.03125));
        assert_eq!(m.tangential_work_min, Some(0.0));
    }

    /// E⁰ handed in after the first step (the Nitsche/penalty engines: E⁰ with E¹) starts the
    /// balance at E⁰ + W_f⁰ = E⁰, not at E⁰ + W_f¹: a first step that gains energy is counted
    /// (issue 42). One point in 2D, binary fractions: exact. E⁰ = 1; step 1 slides 0.5 under
    /// f_t = −0.5 (γ = 1): W_f¹ = 0.25; E¹ = 1.5, so E + W_f rises by 0.75 — where the balance
    /// started at E⁰ + W_f¹ it read 0.5.
    #[test]
    fn late_initial_energy_counts_the_first_step() {
        let mut t = FrictionTally::new(1, 2, 1.0, 1.0);
        assert_eq!(t.step(&[1.0, -0.5], &[0.5]), 0.25);
        t.energy(1.0);
        t.energy(1.5);
        let mut m = Metrics::default();
        t.finish(&mut m, 1.0, 0.0, 0.0);
        assert_eq!(m.energy_balance_max_increase, Some(0.75));
        assert_eq!(m.energy_balance_drift, Some(0.75));
    }

    /// The mean velocities from M v: a 3D body of two nodes (dofs node-major x, y, z) with
    /// the mass M = diag(1, 1, 1, 3, 3, 3) plus the coupling 1 between the nodes' x dofs:
    /// 1ᵀM1 = 1 + 3 + 2 = 6 along x, 4 along y and z. Binary fractions: exact.
    #[test]
    fn mean_velocity_per_axis_from_mv() {
        let mut a = vec![0.0; 36];
        for (i, m) in [1.0, 1.0, 1.0, 3.0, 3.0, 3.0].into_iter().enumerate() {
            a[i * 6 + i] = m;
        }
        a[3] = 1.0;
        a[18] = 1.0;
        let m = SymMatrix::from_dense(6, &a).unwrap();
        let mean = MeanVelocity::new(3, &m, |r| r % 3);
        // v = (1, 2, −1 | 3, 0, 1): M v = (4, 2, −1 | 10, 0, 3).
        let v = [1.0, 2.0, -1.0, 3.0, 0.0, 1.0];
        let mut mv = [0.0; 6];
        m.matvec_into(&v, &mut mv);
        let mut out = [f64::NAN; 3];
        mean.means_into(&mv, &mut out);
        // x: (4 + 10)/6; y: 2/4; z: (−1 + 3)/4.
        assert_eq!(out, [14.0 / 6.0, 0.5, 0.5]);
        assert_eq!(mean.tangential(&out), (14.0f64 / 6.0).hypot(0.5));
        // 2D (the same matrix read as three nodes of two dofs): v̄_2 = 0 and the tangential
        // value is v̄_1. x = dofs 0, 2, 4: 1ᵀM1 = 1 + 1 + 3 = 5, (4 − 1 + 0)/5; y = dofs
        // 1, 3, 5: 1 + 3 + 3 = 7 (the coupling joins dof 0, an x dof, to 3), (2 + 10 + 3)/7.
        let mean = MeanVelocity::new(2, &m, |r| r % 2);
        mean.means_into(&mv, &mut out);
        assert_eq!(out, [3.0 / 5.0, 0.0, 15.0 / 7.0]);
        assert_eq!(mean.tangential(&out), 3.0 / 5.0);
    }

    /// The stop time interpolates linearly where the mean velocity changes sign, once; it is
    /// null when the velocity starts at 0 or never changes sign.
    #[test]
    fn stop_time_interpolates_the_sign_change() {
        let mut t = FrictionTally::new(1, 3, 1.0, 1.0);
        for (time, v) in [
            (0.0, 1.0),
            (0.5, 0.5),
            (1.0, -0.25),
            (1.5, 0.5),
            (2.0, -1.0),
        ] {
            t.velocity(time, v);
        }
        let mut m = Metrics::default();
        t.finish(&mut m, 1.0, 0.0, 0.0);
        // Between (0.5, 0.5) and (1.0, −0.25): 0.5 + 0.5·0.5/0.75.
        assert!((m.stop_time.unwrap() - (0.5 + 0.25 / 0.75)).abs() < 1e-15);
        let mut t = FrictionTally::new(1, 2, 1.0, 1.0);
        for (time, v) in [(0.0, 0.0), (0.5, 0.5), (1.0, -0.25)] {
            t.velocity(time, v);
        }
        let mut m = Metrics::default();
        t.finish(&mut m, 1.0, 0.0, 0.0);
        assert_eq!(m.stop_time, None);
    }
}
