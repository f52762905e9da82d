//! Observables of a run: energies, contact quantities and error norms against the exact
//! solution, accumulated step by step without storing the trajectory (contract §5).
//!
//! Sums and maxima run over n = 0 … N, both ends included (003 §4.1.2e):
//! err_u_l2l2 = (τ Σ‖e^n‖²_L2)^½, err_u_l2h1 = (τ Σ‖e^n‖²_H1)^½ with the full H1 norm,
//! err_u_linfl2 = max‖e^n‖_L2, err_sigma_l2 = (τ Σ(σ_C^n − σ(t^n))²)^½,
//! err_energy_l2 = (τ Σ(E^n − E)²)^½, err_u_contact_max = max|u^n(0) − u(0, t^n)|.
//! err_sigma_mid_l2 = (τ Σ_{n=1}^{N} (σ_C^{n−½} − σ(t^{n−½}))²)^½: 003 §4.1.2e plots and
//! measures σ_C "at midpoint", σ_C evaluated on u^{n−½} = (u^{n−1} + u^n)/2 (for a multiplier,
//! the mean of two consecutive ones). It filters the step-to-step alternation of the pressure:
//! Nitsche-Hybrid's σ_C^n alternates between 0 and ≈ 3× the exact value while σ_C(u^{n−½})
//! stays near it.

/// Scalar results of a run (contract §5). Energies are relative to E⁰, the energy of the initial
/// (consistent) discrete state.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Metrics {
    pub steps: i64,
    pub dofs: i64,
    pub iterations: i64,
    pub factorizations: i64,
    pub solver_failures: i64,
    pub mass_total: Option<f64>,
    pub energy_initial: Option<f64>,
    pub energy_final: Option<f64>,
    pub energy_drift: Option<f64>,
    pub energy_max_dev: Option<f64>,
    pub energy_max_increase: Option<f64>,
    pub energy_theta_max_increase: Option<f64>,
    /// (E_Θ^N − E_Θ⁰)/E_Θ⁰: the drift of the augmented energy (Nitsche), the functional the
    /// energy classification of a Nitsche run is judged by.
    pub energy_theta_drift: Option<f64>,
    pub contact_switches: i64,
    pub err_u_l2l2: Option<f64>,
    pub err_u_l2h1: Option<f64>,
    pub err_u_linfl2: Option<f64>,
    pub err_sigma_l2: Option<f64>,
    pub err_sigma_mid_l2: Option<f64>,
    pub err_energy_l2: Option<f64>,
    pub err_u_contact_max: Option<f64>,
    /// The scene's energy scale (E⁰ for the bars).
    pub energy_scale: Option<f64>,
    /// The body's size L that mesh sizes are compared with (bar: its length; disc/ball: the
    /// diameter): the energy classification's tolerance is max(1, ν)·h/L.
    pub length_scale: Option<f64>,
    /// l2(τ) error of the total contact force against a reference run (FE scenes).
    pub err_force_l2: Option<f64>,
    /// Contact unknowns (the dofs the contact problem is condensed onto).
    pub contact_dofs: Option<i64>,
    /// Times the total contact force switched between zero and non-zero (FE scenes).
    pub contact_toggles: Option<i64>,
    /// Factorisations taken from the sweep's cache instead of being computed.
    pub factor_cache_hits: Option<i64>,
    /// Setup time: operators, factorisation, condensation.
    pub setup_time_s: Option<f64>,
    /// Time spent in the time loop (observables included).
    pub stepping_time_s: Option<f64>,
    /// First t^n with a non-zero contact force (FE scenes).
    pub first_contact_time: Option<f64>,
    /// Times the contact force switched on (FE scenes).
    pub contact_phases: Option<i64>,
    /// Centre of mass against free fall before the first contact (scenes with gravity).
    pub free_fall_error: Option<f64>,
    /// Most contact-solver iterations in one step (FE scenes).
    pub iterations_max_step: Option<i64>,
    /// CG iterations of the step solves over the time loop, and the most in one step
    /// (`solver = "cg"`; None for the direct solver).
    pub solver_iterations: Option<i64>,
    pub solver_iterations_max_step: Option<i64>,
    /// Members of the lockstep group the run was stepped in (None: alone).
    pub lockstep: Option<i64>,
    /// Part of the stepping time spent on observables and error norms (sampled estimate).
    pub observe_time_s: Option<f64>,
    /// Contact phases detected at every step ([`super::impacts`]); None if no step was observed.
    pub impacts: Option<Vec<super::impacts::Phase>>,
    /// E_Θ⁰ (Nitsche): the unit of the impacts' E_Θ losses.
    pub energy_theta_initial: Option<f64>,
    /// max over the observed steps of the step's penetration (u_n − g)_+ (contract §1.3), where
    /// the engine reports one ([`StepValues::penetration`]).
    pub max_penetration: Option<f64>,
    /// l2(τ) error of the velocity (oscillator, contract §1.5).
    pub err_v_l2: Option<f64>,
    /// Largest distance from an exact impact time to the nearest discrete contact start
    /// (oscillator, contract §1.5).
    pub err_impact_time: Option<f64>,
    /// The bar's mean velocity 1ᵀMv/1ᵀM1 at the last step (bar1d with a free end).
    pub exit_velocity: Option<f64>,
    /// max over the contact phases of TV(σ_C)/(2·max|σ_C|) (contract §3.2), from the phases.
    pub pressure_oscillation: Option<f64>,
    /// Friction (contract §5; null without a friction law): W_f(T), E^N + W_f^N − E⁰ and the
    /// largest one-step rise of E + W_f, all over energy_scale; contact node-steps in stick
    /// and in slip; max |f_t|/f_n over the contact steps.
    pub friction_work: Option<f64>,
    /// The frictional contact solve's iterations per stage over the run (contract §4; null
    /// without friction): the primary Newton (mixed: with Tresca's closure; Nitsche/penalty:
    /// from the previous forces, then from rest), the continuation in the bound, and the
    /// fallback (block Gauss–Seidel sweeps and its Newton polish; Nitsche/penalty in 2D, then
    /// Lemke's pivots and theirs).
    pub friction_newton_iterations: Option<i64>,
    pub friction_continuation_iterations: Option<i64>,
    pub friction_fallback_iterations: Option<i64>,
    pub energy_balance_drift: Option<f64>,
    pub energy_balance_max_increase: Option<f64>,
    pub stick_steps: Option<i64>,
    pub slip_steps: Option<i64>,
    /// max over the contact steps of |Σf_t|/Σf_n (contract §5).
    pub friction_ratio_max: Option<f64>,
    /// Mean tangential and normal velocities 1ᵀMv/1ᵀM1 at T (scenes with a tangential
    /// direction; FE: e_1 in 2D, the tangential norm in 3D, and e_d).
    pub tangential_velocity_final: Option<f64>,
    pub normal_velocity_final: Option<f64>,
    /// l2(τ) error of σ_t at the base and |v̄_t(T) − exact| (layer1d, contract §1.7).
    pub err_sigma_t_l2: Option<f64>,
    pub err_vt_final: Option<f64>,
    /// Two bodies (contract §5): max_n |Pⁿ − P⁰|/Σ m_i|V_i| (null with a clamp, a load or at
    /// rest), each body's mean velocity 1ᵀM_iv/m_i at T along e_x (1D) or e_d, and its error
    /// against the exact one (bars1d).
    pub momentum_drift: Option<f64>,
    pub velocity_a_final: Option<f64>,
    pub velocity_b_final: Option<f64>,
    pub err_velocity_a_final: Option<f64>,
    pub err_velocity_b_final: Option<f64>,
    /// Dry friction on the oscillator (contract §1.5): the time after which the mass never moves
    /// again (null while it moves at T), and the exact rest time (null if after T).
    pub stop_time: Option<f64>,
    pub stop_time_exact: Option<f64>,
    /// min over the steps of the step's own tangential work −Σ f_t^{n+1}·Δu_t over
    /// energy_scale (FE scenes with friction, [`super::friction_tally`]; ≥ 0 for the
    /// position-level methods, contract §2.5). Not a column of the runs table: for the tests.
    pub tangential_work_min: Option<f64>,
    /// The contact patch test's errors (contract §1.10, with `pressure`).
    pub patch_stress_error: Option<f64>,
    pub patch_pressure_error: Option<f64>,
}

/// One step in this many is timed by a [`SampledTimer`].
pub const SAMPLE_EVERY: usize = 64;

/// Times one part of a time loop on every [`SAMPLE_EVERY`]-th step only, and extrapolates to
/// all steps. Reading the clock around every call would cost two clock reads (≈ 40 ns) per
/// step — up to a quarter of a 1D step at m = 20 — while one step in 64 costs < 1 ns per step
/// on average. The estimate is unbiased as long as the part's cost does not correlate with
/// n mod 64 (contact phases last hundreds of steps and are not aligned with it).
#[derive(Debug, Clone, Copy, Default)]
pub struct SampledTimer {
    sampled: std::time::Duration,
    samples: u64,
    calls: u64,
}

impl SampledTimer {
    /// Run `f` for step `step`, timing it if the step is sampled.
    #[inline]
    pub fn time<R>(&mut self, step: usize, f: impl FnOnce() -> R) -> R {
        self.calls += 1;
        if step.is_multiple_of(SAMPLE_EVERY) {
            let start = std::time::Instant::now();
            let r = f();
            self.sampled += start.elapsed();
            self.samples += 1;
            r
        } else {
            f()
        }
    }

    /// Estimated total time over every call (None if no call was sampled).
    pub fn estimate_s(&self) -> Option<f64> {
        (self.samples > 0)
            .then(|| self.sampled.as_secs_f64() * self.calls as f64 / self.samples as f64)
    }
}

/// One row of the time series (contract §5).
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesRow {
    pub step: i64,
    pub t: f64,
    pub u_contact: f64,
    pub v_contact: f64,
    pub sigma_contact: f64,
    pub energy: f64,
    pub energy_theta: Option<f64>,
    pub u_contact_exact: Option<f64>,
    pub sigma_contact_exact: Option<f64>,
    pub energy_kinetic: Option<f64>,
    pub energy_elastic: Option<f64>,
    pub energy_gravity: Option<f64>,
    pub u_lowest: Option<f64>,
    /// Friction (contract §5): the base's σ_t (1D; 2D/3D the total tangential force), the contact
    /// node's slip velocity (2D/3D: the Γ_C mean of v_1), W_f.
    pub sigma_t_contact: Option<f64>,
    pub v_t_contact: Option<f64>,
    pub friction_work: Option<f64>,
    /// Two bodies (contract §5): B's contact end (1D; Γ^b's mean normal displacement in 2D/3D)
    /// and the total momentum Pⁿ.
    pub u_contact_b: Option<f64>,
    pub momentum: Option<f64>,
}

/// The optional series columns, in schema order (null where a run has no such quantity).
pub const OPTIONAL_SERIES: [&str; 12] = [
    "energy_theta",
    "u_contact_exact",
    "sigma_contact_exact",
    "energy_kinetic",
    "energy_elastic",
    "energy_gravity",
    "u_lowest",
    "sigma_t_contact",
    "v_t_contact",
    "friction_work",
    "u_contact_b",
    "momentum",
];

/// The index of `friction_work` in [`OPTIONAL_SERIES`].
const FRICTION_WORK: usize = 9;

/// A run's time series, stored by column: the sink hands each column to the Parquet encoder
/// as it is (moved, never transposed), so the rows a run keeps are written once, here, and
/// read once, by the encoder — where a vector of [`SeriesRow`]s was transposed again by the
/// writer (a fifth of its CPU). An optional column ([`OPTIONAL_SERIES`]) is stored from the
/// first row that has a value (earlier rows back-filled as nulls): a run has a quantity at
/// every step or at none, so a 1D run stores 2 of the 7.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    pub step: Vec<i64>,
    pub t: Vec<f64>,
    pub u_contact: Vec<f64>,
    pub v_contact: Vec<f64>,
    pub sigma_contact: Vec<f64>,
    pub energy: Vec<f64>,
    /// Values of the optional columns (0 where null); empty for a column never given.
    pub optional: [Vec<f64>; 12],
    /// Whether each value of an optional column is given; empty for a column never given.
    pub valid: [Vec<bool>; 12],
    cap: usize,
}

impl Series {
    /// Room for `rows` rows in every column a run stores (no allocation while they are kept;
    /// an optional column takes its room at its first value).
    pub fn with_capacity(rows: usize) -> Self {
        Self {
            step: Vec::with_capacity(rows),
            t: Vec::with_capacity(rows),
            u_contact: Vec::with_capacity(rows),
            v_contact: Vec::with_capacity(rows),
            sigma_contact: Vec::with_capacity(rows),
            energy: Vec::with_capacity(rows),
            cap: rows,
            ..Self::default()
        }
    }

    pub fn len(&self) -> usize {
        self.step.len()
    }

    pub fn is_empty(&self) -> bool {
        self.step.is_empty()
    }

    /// Whether the optional column `k` ([`OPTIONAL_SERIES`]) holds any value.
    pub fn has(&self, k: usize) -> bool {
        !self.valid[k].is_empty()
    }

    pub fn push(&mut self, r: SeriesRow) {
        let n = self.step.len();
        for (k, x) in r.optional().into_iter().enumerate() {
            if self.valid[k].is_empty() {
                let Some(x) = x else { continue };
                let cap = self.cap.max(n + 1);
                self.optional[k].reserve_exact(cap);
                self.valid[k].reserve_exact(cap);
                self.optional[k].resize(n, 0.0);
                // W_f is 0 before the first step for every treatment: an engine whose friction
                // values start at step 1 (Nitsche, penalty) has W_f⁰ = 0, not a null, so E + W_f
                // covers every step (issue 42). The other columns have no value there.
                self.valid[k].resize(n, k == FRICTION_WORK);
                self.optional[k].push(x);
                self.valid[k].push(true);
            } else {
                self.optional[k].push(x.unwrap_or(0.0));
                self.valid[k].push(x.is_some());
            }
        }
        self.step.push(r.step);
        self.t.push(r.t);
        self.u_contact.push(r.u_contact);
        self.v_contact.push(r.v_contact);
        self.sigma_contact.push(r.sigma_contact);
        self.energy.push(r.energy);
    }

    /// Row `k` (panics past the end, like indexing).
    pub fn row(&self, k: usize) -> SeriesRow {
        let opt = |j: usize| (self.has(j) && self.valid[j][k]).then(|| self.optional[j][k]);
        SeriesRow {
            step: self.step[k],
            t: self.t[k],
            u_contact: self.u_contact[k],
            v_contact: self.v_contact[k],
            sigma_contact: self.sigma_contact[k],
            energy: self.energy[k],
            energy_theta: opt(0),
            u_contact_exact: opt(1),
            sigma_contact_exact: opt(2),
            energy_kinetic: opt(3),
            energy_elastic: opt(4),
            energy_gravity: opt(5),
            u_lowest: opt(6),
            sigma_t_contact: opt(7),
            v_t_contact: opt(8),
            friction_work: opt(9),
            u_contact_b: opt(10),
            momentum: opt(11),
        }
    }

    /// The last row, if any.
    pub fn last(&self) -> Option<SeriesRow> {
        self.len().checked_sub(1).map(|k| self.row(k))
    }

    /// The rows in order.
    pub fn rows(&self) -> impl ExactSizeIterator<Item = SeriesRow> + '_ {
        (0..self.len()).map(|k| self.row(k))
    }
}

impl FromIterator<SeriesRow> for Series {
    fn from_iter<I: IntoIterator<Item = SeriesRow>>(iter: I) -> Self {
        let mut s = Series::default();
        for r in iter {
            s.push(r);
        }
        s
    }
}

impl SeriesRow {
    /// The optional columns' values, in [`OPTIONAL_SERIES`] order.
    pub fn optional(&self) -> [Option<f64>; 12] {
        [
            self.energy_theta,
            self.u_contact_exact,
            self.sigma_contact_exact,
            self.energy_kinetic,
            self.energy_elastic,
            self.energy_gravity,
            self.u_lowest,
            self.sigma_t_contact,
            self.v_t_contact,
            self.friction_work,
            self.u_contact_b,
            self.momentum,
        ]
    }
}

/// The per-step values the observer needs.
#[derive(Debug, Clone, Copy)]
pub struct StepValues {
    pub step: usize,
    pub t: f64,
    pub u_contact: f64,
    pub v_contact: f64,
    pub sigma_contact: f64,
    /// Pressure the scheme applied over the step t^{n−1} → t^n, if it defines one.
    pub sigma_mid: Option<f64>,
    pub energy: f64,
    pub energy_theta: Option<f64>,
    /// The parts of E^h, where the engine has them: ½vᵀMv, ½uᵀKu, −Fᵀu (contract §1.3).
    pub energy_kinetic: Option<f64>,
    pub energy_elastic: Option<f64>,
    pub energy_gravity: Option<f64>,
    /// Vertical displacement u_d of the lowest point of the reference configuration
    /// (disc/ball).
    pub u_lowest: Option<f64>,
    /// max over the contact points the engine checks of (u_n − g)_+ at this step (contract §1.3);
    /// the run's `max_penetration` is its maximum over the steps.
    pub penetration: Option<f64>,
}

/// Exact values at a step, when the scene has a closed form.
#[derive(Debug, Clone, Copy)]
pub struct ExactValues {
    pub u_contact: f64,
    pub sigma_contact: f64,
    /// σ at t^{n−½} (n ≥ 1).
    pub sigma_contact_mid: Option<f64>,
    pub energy: f64,
    /// ‖e^n‖²_L2 and |e^n|²_H1.
    pub l2_sq: f64,
    pub h1_semi_sq: f64,
}

/// Why a run stops early at an observation.
#[derive(Debug, Clone, PartialEq)]
pub struct Divergence(pub String);

/// Accumulates [`Metrics`] and the time series.
#[derive(Debug)]
pub struct Observer {
    tau: f64,
    every: usize,
    last_step: usize,
    e0: f64,
    e0_theta: Option<f64>,
    prev_e: f64,
    prev_et: Option<f64>,
    last_e: f64,
    last_et: Option<f64>,
    max_dev: f64,
    max_inc: f64,
    max_inc_theta: Option<f64>,
    in_contact: bool,
    switches: i64,
    has_exact: bool,
    sum_l2: f64,
    sum_h1: f64,
    max_l2: f64,
    sum_sigma: f64,
    sum_sigma_mid: f64,
    prev_sigma: f64,
    sum_energy: f64,
    max_contact: f64,
    observed: usize,
    /// The scene's energy scale when it is not E⁰ (disc/sphere: E⁰ = 0, contract §1.3).
    scale: Option<f64>,
    first_contact: Option<f64>,
    phases: i64,
    /// Contact phases at full resolution (issue 12), independent of `every`.
    impacts: super::impacts::PhaseTracker,
    max_penetration: Option<f64>,
    /// The friction values of the next observed step (σ_t, slip velocity, W_f), set by a
    /// frictional engine before [`Observer::observe`] ([`Observer::set_friction`]).
    friction: Option<[f64; 3]>,
    /// The two-body series values (u_contact_b, P) of the step observed next.
    two_body: Option<[f64; 2]>,
    pub series: Series,
}

/// Energy bound above which a run is `diverged` (contract §5).
pub const DIVERGENCE_FACTOR: f64 = 1e6;

impl Observer {
    pub fn new(tau: f64, series_every: usize, last_step: usize) -> Self {
        let cap = last_step.checked_div(series_every).map_or(0, |n| n + 2);
        Self {
            tau,
            every: series_every,
            last_step,
            e0: f64::NAN,
            e0_theta: None,
            prev_e: f64::NAN,
            prev_et: None,
            last_e: f64::NAN,
            last_et: None,
            max_dev: 0.0,
            max_inc: f64::NEG_INFINITY,
            max_inc_theta: None,
            in_contact: false,
            switches: 0,
            has_exact: false,
            sum_l2: 0.0,
            sum_h1: 0.0,
            max_l2: 0.0,
            sum_sigma: 0.0,
            sum_sigma_mid: 0.0,
            prev_sigma: f64::NAN,
            sum_energy: 0.0,
            max_contact: 0.0,
            observed: 0,
            scale: None,
            first_contact: None,
            phases: 0,
            impacts: super::impacts::PhaseTracker::new(),
            max_penetration: None,
            friction: None,
            two_body: None,
            series: Series::with_capacity(cap),
        }
    }

    /// Measure relative energies (drift, deviations, increases, divergence) in `scale`
    /// instead of E⁰ (contract §1.3: m·|f|·gap for the disc and the sphere, whose E⁰ is 0).
    pub fn with_energy_scale(mut self, scale: f64) -> Self {
        self.scale = Some(scale);
        self
    }

    /// The friction series values (σ_t at the contact, its slip velocity, W_f) of the step
    /// observed next.
    pub fn set_friction(&mut self, sigma_t: f64, v_t: f64, work: f64) {
        self.friction = Some([sigma_t, v_t, work]);
    }

    /// The two-body series values (B's contact displacement, the total momentum) of the step
    /// observed next.
    pub fn set_two_body(&mut self, u_contact_b: f64, momentum: f64) {
        self.two_body = Some([u_contact_b, momentum]);
    }

    /// The energy of the last observed step (a frictional engine's E + W_f balance).
    pub fn last_energy(&self) -> f64 {
        self.last_e
    }

    /// First observed time with a negative contact pressure (a non-zero contact force).
    pub fn first_contact(&self) -> Option<f64> {
        self.first_contact
    }

    /// Times the contact pressure switched on.
    pub fn contact_phases(&self) -> i64 {
        self.phases
    }

    /// The energy relative energies are measured in: the scene's scale, else E⁰.
    fn energy_unit(&self) -> f64 {
        self.scale.unwrap_or(self.e0)
    }

    /// Record one step. Returns the reason to stop if the run diverged.
    pub fn observe(&mut self, v: StepValues, exact: Option<ExactValues>) -> Result<(), Divergence> {
        let finite = v.energy.is_finite()
            && v.u_contact.is_finite()
            && v.sigma_contact.is_finite()
            && v.energy_theta.is_none_or(f64::is_finite);
        if !finite {
            return Err(Divergence(format!(
                "non-finite value at step {} (t = {:.6})",
                v.step, v.t
            )));
        }
        if self.observed == 0 {
            self.e0 = v.energy;
            self.e0_theta = v.energy_theta;
            self.max_inc_theta = v.energy_theta.map(|_| f64::NEG_INFINITY);
        } else {
            self.max_inc = self.max_inc.max(v.energy - self.prev_e);
            if let (Some(et), Some(prev), Some(m)) =
                (v.energy_theta, self.prev_et, self.max_inc_theta.as_mut())
            {
                *m = m.max(et - prev);
            }
        }
        self.observed += 1;
        self.prev_e = v.energy;
        self.prev_et = v.energy_theta;
        self.last_e = v.energy;
        self.last_et = v.energy_theta;
        self.prev_sigma = v.sigma_contact;
        self.max_dev = self.max_dev.max((v.energy - self.e0).abs());
        if let Some(p) = v.penetration {
            self.max_penetration = Some(self.max_penetration.map_or(p, |m| m.max(p)));
        }
        let contact = v.sigma_contact < 0.0;
        if contact != self.in_contact {
            self.switches += 1;
            self.in_contact = contact;
            if contact {
                self.phases += 1;
                self.first_contact.get_or_insert(v.t);
            }
        }
        if let Some(x) = exact {
            self.has_exact = true;
            self.sum_l2 += x.l2_sq;
            self.sum_h1 += x.l2_sq + x.h1_semi_sq;
            self.max_l2 = self.max_l2.max(x.l2_sq.sqrt());
            let ds = v.sigma_contact - x.sigma_contact;
            self.sum_sigma += ds * ds;
            if let Some(mid) = x.sigma_contact_mid {
                let applied = v
                    .sigma_mid
                    .unwrap_or(0.5 * (self.prev_sigma + v.sigma_contact));
                let dm = applied - mid;
                self.sum_sigma_mid += dm * dm;
            }
            let de = v.energy - x.energy;
            self.sum_energy += de * de;
            self.max_contact = self.max_contact.max((v.u_contact - x.u_contact).abs());
        }
        self.impacts
            .step(v.step, v.t, v.sigma_contact, v.energy, v.energy_theta);
        if self.every > 0 && (v.step.is_multiple_of(self.every) || v.step == self.last_step) {
            self.series.push(SeriesRow {
                step: v.step as i64,
                t: v.t,
                u_contact: v.u_contact,
                v_contact: v.v_contact,
                sigma_contact: v.sigma_contact,
                energy: v.energy,
                energy_theta: v.energy_theta,
                u_contact_exact: exact.map(|x| x.u_contact),
                sigma_contact_exact: exact.map(|x| x.sigma_contact),
                energy_kinetic: v.energy_kinetic,
                energy_elastic: v.energy_elastic,
                energy_gravity: v.energy_gravity,
                u_lowest: v.u_lowest,
                sigma_t_contact: self.friction.map(|f| f[0]),
                v_t_contact: self.friction.map(|f| f[1]),
                friction_work: self.friction.map(|f| f[2]),
                u_contact_b: self.two_body.map(|b| b[0]),
                momentum: self.two_body.map(|b| b[1]),
            });
        }
        self.friction = None;
        self.two_body = None;
        let scale = self.energy_unit().abs().max(f64::MIN_POSITIVE);
        if v.energy > DIVERGENCE_FACTOR * scale {
            return Err(Divergence(format!(
                "energy {:.3e} exceeded 1e6·{} ({:.3e}) at step {} (t = {:.6})",
                v.energy,
                if self.scale.is_some() {
                    "energy_scale"
                } else {
                    "E0"
                },
                scale,
                v.step,
                v.t
            )));
        }
        Ok(())
    }

    /// Fill the metrics from what was observed. Error norms only for complete runs with a
    /// closed form (a partial sum is not the norm the column names).
    pub fn finish(&mut self, metrics: &mut Metrics, complete: bool) {
        if self.observed == 0 {
            return;
        }
        let e0 = self.e0;
        let unit = self.energy_unit();
        metrics.energy_initial = Some(e0);
        metrics.energy_final = Some(self.last_e);
        metrics.energy_drift = Some((self.last_e - e0) / unit);
        metrics.energy_max_dev = Some(self.max_dev / unit);
        metrics.energy_theta_drift = self
            .last_et
            .zip(self.e0_theta)
            .map(|(et, e0t)| (et - e0t, self.scale.unwrap_or(e0t)))
            .filter(|(_, unit)| *unit != 0.0)
            .map(|(d, unit)| d / unit);
        if self.observed > 1 {
            metrics.energy_max_increase = Some(self.max_inc / unit);
            metrics.energy_theta_max_increase = self
                .max_inc_theta
                .zip(self.e0_theta)
                .map(|(m, e0t)| m / self.scale.unwrap_or(e0t));
        }

        metrics.contact_switches = self.switches;
        // Every scene where contact can happen (issue 34: bar1d and the oscillator too).
        metrics.first_contact_time = self.first_contact;
        metrics.contact_phases = Some(self.phases);
        metrics.impacts = Some(self.impacts.finish());
        metrics.pressure_oscillation = self.impacts.pressure_oscillation();
        metrics.energy_theta_initial = self.e0_theta;
        metrics.max_penetration = self.max_penetration;
        if complete && self.has_exact {
            let t = self.tau;
            metrics.err_u_l2l2 = Some((t * self.sum_l2).sqrt());
            metrics.err_u_l2h1 = Some((t * self.sum_h1).sqrt());
            metrics.err_u_linfl2 = Some(self.max_l2);
            metrics.err_sigma_l2 = Some((t * self.sum_sigma).sqrt());
            metrics.err_sigma_mid_l2 = Some((t * self.sum_sigma_mid).sqrt());
            metrics.err_energy_l2 = Some((t * self.sum_energy).sqrt());
            metrics.err_u_contact_max = Some(self.max_contact);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(step: i64, theta: Option<f64>) -> SeriesRow {
        SeriesRow {
            step,
            t: step as f64,
            u_contact: -(step as f64),
            v_contact: 0.5,
            sigma_contact: 0.0,
            energy: 1.0,
            energy_theta: theta,
            u_contact_exact: None,
            sigma_contact_exact: None,
            energy_kinetic: None,
            energy_elastic: None,
            energy_gravity: None,
            u_lowest: None,
            sigma_t_contact: None,
            v_t_contact: None,
            friction_work: None,
            u_contact_b: None,
            momentum: None,
        }
    }

    /// A column stored by column gives back the rows pushed, bit for bit: an optional column
    /// whose first value comes late is back-filled with nulls, one never given stores nothing.
    #[test]
    fn series_by_column_gives_back_its_rows() {
        let rows = vec![
            row(0, None),
            row(1, None),
            row(2, Some(0.25)),
            row(3, None),
            row(4, Some(-1e-300)),
        ];
        let s: Series = rows.iter().cloned().collect();
        assert_eq!(s.len(), 5);
        assert_eq!(s.rows().collect::<Vec<_>>(), rows);
        assert!(s.has(0));
        assert_eq!(s.valid[0], [false, false, true, false, true]);
        assert!((1..12).all(|k| !s.has(k) && s.optional[k].is_empty()));
    }

    /// W_f starts at 0 for every treatment (issue 42): a `friction_work` column whose first
    /// value comes at step 1 (the Nitsche/penalty engines) has W_f⁰ = 0 at step 0, valid; the
    /// other friction columns stay null there.
    #[test]
    fn friction_work_starts_at_zero() {
        let mut r1 = row(1, None);
        (r1.sigma_t_contact, r1.v_t_contact, r1.friction_work) =
            (Some(-0.5), Some(1.0), Some(0.25));
        let s: Series = [row(0, None), r1.clone()].into_iter().collect();
        assert_eq!(s.valid[9], [true, true]);
        assert_eq!(s.optional[9], [0.0, 0.25]);
        assert_eq!(s.valid[7], [false, true]);
        assert_eq!(s.row(0).friction_work, Some(0.0));
        assert_eq!(s.row(1), r1);
    }
}
