//! The output schema, defined once: [`RunRecord`] is one row of `DIR/runs/*.parquet`,
//! [`SeriesRow`](super::SeriesRow) one row of `DIR/series/*.parquet`. The sink derives the
//! Parquet schema from these declarations ([`RunRecord::COLUMNS`], [`SERIES_COLUMNS`]), and the
//! docs/guide.md's schema table is generated from the same docs (`contact-sweep schema`).

use std::collections::BTreeMap;

use super::observe::Series;
use super::outcome::Outcome;
use super::spec::RunSpec;
use crate::model::{Key, Value};

/// A finished run: its row and its (possibly decimated) time series — what the executor hands
/// the sink.
#[derive(Debug, Clone)]
pub struct RunResult {
    pub record: RunRecord,
    pub series: Series,
}

/// A typed column ready for the sink.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    F64(Vec<Option<f64>>),
    I64(Vec<Option<i64>>),
    Str(Vec<Option<String>>),
    /// A List(Int64) column: one list per row (null: the row has none).
    ListI64(Vec<Option<Vec<i64>>>),
    /// A List(Float64) column whose elements may be null.
    ListF64(Vec<Option<Vec<Option<f64>>>>),
}

/// Rust types that can fill a column.
pub trait ColumnValue: Clone {
    fn column(values: Vec<Self>) -> ColumnData;
}

impl ColumnValue for f64 {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::F64(v.into_iter().map(Some).collect())
    }
}
impl ColumnValue for Option<f64> {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::F64(v)
    }
}
impl ColumnValue for i64 {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::I64(v.into_iter().map(Some).collect())
    }
}
impl ColumnValue for Option<i64> {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::I64(v)
    }
}
impl ColumnValue for String {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::Str(v.into_iter().map(Some).collect())
    }
}
impl ColumnValue for Option<String> {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::Str(v)
    }
}

impl ColumnValue for Option<Vec<i64>> {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::ListI64(v)
    }
}
impl ColumnValue for Option<Vec<f64>> {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::ListF64(
            v.into_iter()
                .map(|l| l.map(|l| l.into_iter().map(Some).collect()))
                .collect(),
        )
    }
}
impl ColumnValue for Option<Vec<Option<f64>>> {
    fn column(v: Vec<Self>) -> ColumnData {
        ColumnData::ListF64(v)
    }
}

macro_rules! schema {
    ($(#[$meta:meta])* $name:ident, $consts:ident { $($field:ident : $ty:ty => $unit:literal, $doc:literal;)* }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Default)]
        #[allow(non_snake_case)] // `T` is the column name of contract §7
        pub struct $name {
            $(#[doc = $doc] pub $field: $ty,)*
        }

        impl $name {
            /// (column, type, unit, meaning) for every column, in order.
            pub const $consts: &'static [(&'static str, &'static str, &'static str, &'static str)] = &[
                $((stringify!($field), stringify!($ty), $unit, $doc),)*
            ];

            /// The rows as typed columns, in schema order.
            pub fn to_columns(rows: &[$name]) -> Vec<(&'static str, ColumnData)> {
                vec![$((
                    stringify!($field),
                    <$ty as ColumnValue>::column(rows.iter().map(|r| r.$field.clone()).collect()),
                ),)*]
            }
        }
    };
}

schema! {
    /// One row of `DIR/runs`: the full parameter set of a run (null where a parameter does not
    /// apply to its method) and what it measured (contract §5, §8).
    RunRecord, COLUMNS {
        run_id: String => "", "stable hash of the run's canonical parameters (same run, same id, everywhere)";
        sweep: String => "", "name of the sweep that produced the row";
        scene: String => "", "scene (bar1d, …)";
        label: String => "", "human label: contact method · mass · scheme";
        status: String => "", "ok | diverged | solver-failed | invalid | timeout";
        message: Option<String> => "", "why the run did not end ok (null if ok)";
        T: f64 => "s", "final time requested";
        h: f64 => "m", "mesh size (derived from elements when the sweep gave elements)";
        elements: i64 => "", "number of elements m (h = length/m; 2D/3D: elements across the height)";
        dt: f64 => "s", "time step τ (derived from courant when the sweep gave courant)";
        courant: f64 => "", "Courant number ν = c0 τ / h";
        space: String => "", "contact treatment: mixed | nitsche | penalty";
        mass: String => "", "mass variant (contract §2.2)";
        mass_weights: Option<String> => "", "user element weights w1,w2,… (mass = weights)";
        contact_init: Option<String> => "", "start of the massless dofs: consistent (their quasi-static value) or interpolant (u0); null where both are the same state (the contact node has mass; an FE scene without gravity and the body load)";
        scheme: String => "", "scheme family: newmark | theta | paoli-schatzman | hybrid | kane | contact-stabilized-newmark | generalized-alpha | hht | moreau-jean | discrete-gradient";
        scheme_label: String => "", "preset name when the parameters are a preset's (crank-nicolson, backward-euler, …)";
        nitsche_theta: Option<f64> => "", "Nitsche Θ";
        nitsche_gamma0: Option<f64> => "", "Nitsche γ0 (γ_h = γ0 h)";
        penalty_gamma0: Option<f64> => "", "penalty γ0 (κ = E γ0 / h)";
        newmark_beta: Option<f64> => "", "Newmark / Paoli–Schatzman β";
        newmark_gamma: Option<f64> => "", "Newmark γ";
        theta_scheme: Option<f64> => "", "θ of the θ-scheme";
        restitution: Option<f64> => "", "Paoli–Schatzman restitution e";
        rho_inf: Option<f64> => "", "generalized-α spectral radius at infinity ρ∞ (contract §3.2)";
        hht_alpha: Option<f64> => "", "HHT α (scheme = hht, contract §3.2)";
        length: Option<f64> => "m", "bar length L";
        young: Option<f64> => "Pa", "Young modulus E";
        density: Option<f64> => "kg/m", "density ρ";
        amplitude: Option<f64> => "m", "initial displacement amplitude a (u0 = a(1 − x/L))";
        gap: Option<f64> => "m", "initial gap g";
        lame_lambda: Option<f64> => "Pa", "Lamé λ (2D/3D scenes)";
        lame_mu: Option<f64> => "Pa", "Lamé μ (2D/3D scenes)";
        gravity: Option<f64> => "m/s²", "volume load (2D/3D scenes)";
        degree: Option<i64> => "", "polynomial degree of the elements, 1 (Q1) or 2 (Q2) (disc2d, sphere3d)";
        ensemble_sample: Option<i64> => "", "ensemble member index (null outside ensembles)";
        ensemble_perturbation: Option<f64> => "", "relative amplitude of the perturbation of u⁰";
        search: Option<String> => "", "the [search] this run is a probe of (name, key, criterion, bracket, method index; null for grid runs)";
        wall_time_s: f64 => "s", "wall time of the run (median over repeats)";
        wall_time_min_s: f64 => "s", "fastest of the repeats";
        wall_time_max_s: f64 => "s", "slowest of the repeats";
        repeats: i64 => "", "timing repeats (results are identical across repeats)";
        steps: i64 => "", "time steps completed";
        dofs: i64 => "", "unknowns of the space discretisation";
        iterations: i64 => "", "contact solves (1D: one exact branch enumeration per step; two with contact-stabilized-newmark; the Newton iterations of discrete-gradient); 2D/3D: the contact solver's iterations summed over the steps (LCP pivots, or the semismooth Newton's iterations with friction and with Nitsche/penalty)";
        factorizations: i64 => "", "matrix factorisations performed (0 with solver = cg, which factors nothing)";
        solver_failures: i64 => "", "steps whose contact problem had no or several solutions";
        contact_switches: i64 => "", "times the contact pressure switched on or off";
        mass_total: Option<f64> => "kg", "1ᵀM1, the total mass the mass matrix represents";
        energy_initial: Option<f64> => "J", "E⁰ of the initial discrete state (the massless dofs as contact_init says)";
        energy_final: Option<f64> => "J", "E^N";
        energy_drift: Option<f64> => "", "(E^N − E⁰)/E⁰";
        energy_max_dev: Option<f64> => "", "max_n |E^n − E⁰|/E⁰";
        energy_max_increase: Option<f64> => "", "max_n (E^{n+1} − E^n)/E⁰";
        energy_theta_max_increase: Option<f64> => "", "same for the augmented energy E_Θ (Nitsche)";
        energy_theta_drift: Option<f64> => "", "(E_Θ^N − E_Θ⁰)/E_Θ⁰, the drift of the augmented energy (Nitsche)";
        err_u_l2l2: Option<f64> => "m·s^½", "(τ Σ_n ‖u^n − u(t^n)‖²_L2)^½, n = 0…N";
        err_u_l2h1: Option<f64> => "", "same with the full H1 norm";
        err_u_linfl2: Option<f64> => "m^{3/2}", "max_n ‖u^n − u(t^n)‖_L2";
        err_sigma_l2: Option<f64> => "Pa·s^½", "l2(τ) error of the contact pressure σ_C^n at t^n";
        err_sigma_mid_l2: Option<f64> => "Pa·s^½", "l2(τ) error of the pressure at midpoint, σ_C(u^{n−½}) against σ(t^{n−½}) (003 §4.1.2e; a multiplier of a node with mass: mean of two)";
        err_energy_l2: Option<f64> => "", "l2(τ) error of the energy";
        err_u_contact_max: Option<f64> => "m", "max_n |u^n(contact) − u(contact, t^n)| (2D/3D: mean u_d over Γ_C against the reference)";
        energy_scale: Option<f64> => "J", "the scene's energy scale relative energies are measured in (E⁰ for the bars)";
        length_scale: Option<f64> => "m", "the body's size L mesh sizes are compared with (bar: its length; disc/ball: the diameter)";
        err_force_l2: Option<f64> => "N·s^½", "l2(τ) error of the total contact force against the reference run (2D/3D)";
        contact_dofs: Option<i64> => "", "unknowns the contact problem is condensed onto (2D/3D: vertical dofs of Γ_C)";
        contact_toggles: Option<i64> => "", "times the total contact force switched between zero and non-zero (2D/3D; 002's chatter)";
        factor_cache_hits: Option<i64> => "", "factorisations reused from an earlier run of the sweep with the same matrix (2D/3D; null with solver = cg)";
        setup_time_s: Option<f64> => "s", "setup: assembly, factorisation, condensation onto the contact set, initial state (first repeat)";
        stepping_time_s: Option<f64> => "s", "time loop, observables included (first repeat)";
        observe_time_s: Option<f64> => "s", "part of stepping_time_s spent on energies and error norms (timed on one step in 64, extrapolated); the Parquet output is not in any run's time (encoded once the run is done; its total is in the end-of-sweep line)";
        first_contact_time: Option<f64> => "s", "first t^n with a non-zero contact force or pressure (every scene; null if none)";
        contact_phases: Option<i64> => "", "number of contact intervals, i.e. times the contact force or pressure switched on (every scene)";
        impact_step_first: Option<Vec<i64>> => "", "contact phases found at every step (σ_C < 0; a one-step gap without pressure does not end a phase), one list element per phase: first contact step (null if no step ran; explode the impact_* lists together for one row per phase)";
        impact_step_last: Option<Vec<i64>> => "", "per phase: last contact step";
        impact_t_first: Option<Vec<f64>> => "s", "per phase: time of the first contact step";
        impact_t_last: Option<Vec<f64>> => "s", "per phase: time of the last contact step";
        impact_energy_before: Option<Vec<Option<f64>>> => "J", "per phase: E at the step before the phase (null for a phase open at step 0)";
        impact_energy_after: Option<Vec<Option<f64>>> => "J", "per phase: E at the step after the phase (null for a phase open at the last step)";
        impact_energy_theta_before: Option<Vec<Option<f64>>> => "J", "per phase: E_Θ at the step before the phase (Nitsche; else null)";
        impact_energy_theta_after: Option<Vec<Option<f64>>> => "J", "per phase: E_Θ at the step after the phase (Nitsche; else null)";
        energy_theta_initial: Option<f64> => "J", "E_Θ⁰, the augmented energy of the initial state (Nitsche; the unit of the impacts' E_Θ losses)";
        free_fall_error: Option<f64> => "m", "largest deviation of the centre of mass's vertical displacement from the free fall −½ g t² (g = gravity) over the steps before the first contact (scenes with gravity)";
        iterations_max_step: Option<i64> => "", "most contact-solver iterations in one step: LCP pivots (mixed), semismooth Newton iterations (mixed with friction: the Alart–Curnier Newton; Nitsche, penalty) (2D/3D)";
        max_penetration: Option<f64> => "m", "max over the steps n = 0…N and the contact nodes of (u_n − g)_+ with u_n = −u_d, g the node's gap (2D/3D: the Γ_C nodes, g = x_d; bar1d: the contact node x = 0); a Nitsche/penalty run measured at the nodes, not at its quadrature points";
        right_end: Option<String> => "", "bar1d's end x = L: clamped (contract §1.1) or free (the flying bar, contract §1.4)";
        velocity: Option<f64> => "m/s", "initial normal velocity, negative towards the obstacle: bar1d and the oscillator's uniform v0; layer1d's V_n; disc2d, sphere3d, mesh2d, mesh3d: the e_d velocity of every node not clamped";
        point_mass: Option<f64> => "kg", "oscillator mass m (contract §1.5)";
        stiffness: Option<f64> => "N/m", "oscillator spring stiffness k";
        force: Option<f64> => "N", "oscillator constant force f (negative towards the obstacle)";
        impact_law: Option<f64> => "", "oscillator: Newton's restitution e_x of the exact solution the run is measured against";
        err_v_l2: Option<f64> => "m·s^-½", "oscillator: (τ Σ_n |v^n − v(t^n)|²)^½ (velocities jump at impacts: the l2(τ) norm is the meaningful one)";
        err_impact_time: Option<f64> => "s", "oscillator: max over the exact impacts in [0, T] of the distance to the nearest discrete contact start";
        exit_velocity: Option<f64> => "m/s", "bar1d with a free end: the bar's mean velocity 1ᵀMv/1ᵀM1 at T (the flying bar leaves with −v0)";
        pressure_oscillation: Option<f64> => "", "max over the contact phases (impact_*) of TV/(2·max|σ_C|), TV the total variation of σ_C (1D) or of the total contact force (2D/3D) over the phase's steps, rise from and fall to zero included: 1 for a pressure that rises once and falls once, larger when it chatters (contract §3.2); null without contact";
        solver: Option<String> => "", "step solves of the 2D/3D scenes (contract §4): direct (sparse Cholesky) | cg (Jacobi-preconditioned conjugate gradient); null for bar1d and the oscillator";
        cg_tol: Option<f64> => "", "CG's relative residual tolerance, ‖r‖ ≤ cg_tol·‖b‖ in the D⁻¹ norm, D = diag(A) (solver = cg)";
        solver_iterations: Option<i64> => "", "CG iterations of the step solves of the time loop, summed over the steps (solver = cg; null for direct)";
        solver_iterations_max_step: Option<i64> => "", "most CG iterations of one step's solve (solver = cg)";
        load: Option<String> => "", "how gravity enters (contract §1.3): body (F = ∫ρ f·φ whatever the mass variant, the papers' model) or inertial (F = M_run f e_d, the weight following the modified mass); null without gravity";
        lockstep: Option<i64> => "", "members of the lockstep group the run was stepped in (runs sharing the step matrix make one multi-column solve per step; its numbers equal the run alone bit for bit, and its timings are the group's divided among the members); null: stepped alone";
        friction: Option<String> => "", "friction law at the contact (contract §2.5): none | tresca | coulomb (null on scenes without a tangential direction)";
        friction_coefficient: Option<f64> => "", "Coulomb's μ_f (friction = coulomb)";
        tresca_threshold: Option<f64> => "Pa", "Tresca's threshold s, a traction (friction = tresca)";
        height: Option<f64> => "m", "layer1d: the layer's height H";
        velocity_tangential: Option<f64> => "m/s", "initial tangential velocity: layer1d's V_t (contract §1.7); disc2d, sphere3d, mesh2d, mesh3d: the e_1 velocity of every node not clamped (contract §1.8; the disc thrown obliquely, the sliding block)";
        incline: Option<f64> => "°", "mesh2d, mesh3d: the plane's tilt α in degrees, the volume load ρ·gravity·(sin α e_1 − cos α e_d) (contract §1.8)";
        friction_work: Option<f64> => "", "friction: W_f(T)/energy_scale, the work the friction force took from the body (contract §5; null without friction)";
        energy_balance_drift: Option<f64> => "", "friction: (E^N + W_f^N − E⁰)/energy_scale — the normal contact's work over the run";
        energy_balance_max_increase: Option<f64> => "", "friction: max_n of the one-step rise of E + W_f, over energy_scale (≤ 0 up to round-off for kane and moreau-jean θ = ½)";
        stick_steps: Option<i64> => "", "friction: contact node-steps in stick (|u_t^{n+1} − u_t^n| ≤ 1e-12·h)";
        slip_steps: Option<i64> => "", "friction: contact node-steps in slip";
        friction_ratio_max: Option<f64> => "", "friction: max over the contact steps of |Σf_t|/Σf_n (sums over the contact points, 3D: the norm of Σf_t), the apparent friction coefficient";
        friction_newton_iterations: Option<i64> => "", "friction: the frictional contact solve's primary semismooth Newton iterations summed over the steps (mixed: the Alart–Curnier Newton with Tresca's closure; Nitsche, penalty: from the previous forces, then from rest); null without friction";
        friction_continuation_iterations: Option<i64> => "", "friction: Newton iterations of the rescue's continuation in the friction bound (μ_f or s scaled from 0 to 1), summed over the steps where the primary Newton failed";
        friction_fallback_iterations: Option<i64> => "", "friction: the last fallback's work where the continuation failed too: projected block Gauss–Seidel sweeps plus its Newton polish iterations, then (Nitsche and penalty, 2D) Lemke pivots plus their Newton polish iterations, summed over the steps";
        tangential_velocity_final: Option<f64> => "m/s", "friction: the tangential component of the mean velocity 1ᵀMv/1ᵀM1 at T (layer1d; FE scenes: e_1 in 2D, the tangential norm in 3D; two bodies: A's)";
        normal_velocity_final: Option<f64> => "m/s", "friction: the normal (e_d) component of the mean velocity 1ᵀMv/1ᵀM1 at T (layer1d, FE scenes; two bodies: A's)";
        err_sigma_t_l2: Option<f64> => "Pa·s^½", "layer1d: l2(τ) error of the base's tangential stress σ_t against the exact solution";
        err_vt_final: Option<f64> => "m/s", "layer1d: |mean tangential velocity at T − exact| (the exact one after the impact is V_t − 2σ_t*/Z_p)";
        friction_force: Option<f64> => "N", "oscillator: the dry (Coulomb) friction force F on the mass (contract §1.5; 0: frictionless)";
        stop_time: Option<f64> => "s", "oscillator with friction_force > 0: the time of the first step after which the mass never moves again (every later step moves it by at most 1e-12·max(abs(x0), gap)); FE scenes with friction (contract §1.8): the first time the mean tangential velocity 1ᵀMv_1/1ᵀM1 (two bodies: A's) reaches 0, interpolated between the two steps where it changes sign; null if it never does";
        stop_time_exact: Option<f64> => "s", "oscillator with friction_force > 0: the exact rest time, the first turning point where the friction holds the mass, abs(k x − f) ≤ F (null if after T)";
        length_b: Option<f64> => "m", "bars1d: bar B's length L_b (contract §1.9; null when it is A's)";
        young_b: Option<f64> => "Pa", "bars1d: bar B's Young modulus E_b (null when it is A's)";
        density_b: Option<f64> => "kg/m^d", "two bodies: body B's density ρ_b (kg/m in 1D; null when it is A's)";
        velocity_b: Option<f64> => "m/s", "two bodies: body B's initial velocity V_b along e_x (1D; A's is `velocity`, towards B) or e_d";
        far_end: Option<String> => "", "two bodies: B's far end (its base in 2D/3D), free or clamped (contract §1.9, §1.10)";
        mass_side: Option<String> => "", "two bodies: the bodies whose contact layers the mass variant modifies: both, a or b (contract §2.6)";
        nitsche_sides: Option<String> => "", "two bodies: the Nitsche sides' weights, unbiased (w_a = w_b = ½) or a (A the slave) (contract §2.6)";
        height_b: Option<f64> => "m", "blocks2d, blocks3d: body B's height H_b (contract §1.10)";
        width: Option<f64> => "m", "blocks2d, blocks3d: the blocks' width W";
        mesh_ratio: Option<f64> => "", "blocks2d, blocks3d: B's elements across per A's (1: a matching interface)";
        pressure: Option<f64> => "Pa", "blocks2d, blocks3d: the traction −p e_d on A's top face (the patch test's p)";
        lame_lambda_b: Option<f64> => "Pa", "blocks2d, blocks3d: body B's λ (null: A's)";
        lame_mu_b: Option<f64> => "Pa", "blocks2d, blocks3d: body B's μ (null: A's)";
        pairing: Option<String> => "", "blocks2d, blocks3d, two-body mesh files: how mixed and penalty pair the faces: node-to-node, node-to-segment (one pass, A the slave) or mortar (contract §2.6)";
        mortar_basis: Option<String> => "", "blocks2d, blocks3d, two-body mesh files: the mortar multiplier's basis, standard or dual (Wohlmuth's biorthogonal; contract §2.6)";
        interface_quadrature: Option<String> => "", "blocks2d, blocks3d, two-body mesh files: where mortar's and Nitsche's interface integrals are computed: segment (the segmentation of Γ^a by Γ^b's projected faces) or element (Γ^a's own face rule; contract §2.6)";
        start: Option<String> => "", "mesh2d, mesh3d: the initial state (contract §1.8): rest (u⁰ = 0, the default) or static (u⁰ the static state under the run's loads with its contact, a⁰ = 0: a resting body without the spurious gravity bounce)";
        momentum_drift: Option<f64> => "", "two bodies: max_n abs(Pⁿ − P⁰ − tⁿF) / (Σ_i m_i·abs(V_i) + T·abs(F)), P = Σ_i 1ᵀM_iv along e_x (1D) or e_d (with friction: the largest over every axis, V_i the full velocity), m_i = 1ᵀM_i1 the run's masses, F the total load along that axis (both bodies' weight and the pressure; 0 without) (contract §5; null when a clamp or an obstacle acts, or when the velocities and the load all vanish)";
        velocity_a_final: Option<f64> => "m/s", "two bodies: body A's mean velocity 1ᵀM_av/1ᵀM_a1 at T along e_x (1D) or e_d";
        velocity_b_final: Option<f64> => "m/s", "two bodies: body B's mean velocity 1ᵀM_bv/1ᵀM_b1 at T along e_x (1D) or e_d";
        err_velocity_a_final: Option<f64> => "m/s", "bars1d: abs(velocity_a_final − the exact mean velocity of A at T) (contract §1.9)";
        err_velocity_b_final: Option<f64> => "m/s", "bars1d: abs(velocity_b_final − the exact mean velocity of B at T)";
        patch_stress_error: Option<f64> => "", "two bodies with pressure (contract §1.10): max over the 2^d Gauss points of every cell of both bodies of the largest entry of abs(σ_h + p e_d⊗e_d)/p";
        patch_pressure_error: Option<f64> => "", "two bodies with pressure (contract §1.10): max over the interface rows of abs(p_h − p)/p (a node's multiplier over its weight ∫φ_i; the penalty's κ[δ_i − g_i]_+)";
        tool_version: String => "", "contact-sweep version that computed the row";
    }
}

/// (column, type, unit, meaning) of the time series, in order.
pub const SERIES_COLUMNS: &[(&str, &str, &str, &str)] = &[
    ("run_id", "String", "", "run the row belongs to"),
    ("step", "i64", "", "time step n"),
    ("t", "f64", "s", "time t^n"),
    (
        "u_contact",
        "f64",
        "m",
        "displacement of the contact node (2D/3D: mean u_d over Γ_C)",
    ),
    (
        "v_contact",
        "f64",
        "m/s",
        "velocity of the contact node (2D/3D: mean v_d over Γ_C)",
    ),
    (
        "sigma_contact",
        "f64",
        "Pa",
        "contact pressure σ_C (≤ 0 in contact; 2D/3D: minus the total contact force)",
    ),
    (
        "energy",
        "f64",
        "J",
        "E^h (plus the penalty potential for penalty)",
    ),
    (
        "energy_theta",
        "Option<f64>",
        "J",
        "augmented energy E_Θ (Nitsche)",
    ),
    (
        "u_contact_exact",
        "Option<f64>",
        "m",
        "closed-form (or reference-run) contact displacement",
    ),
    (
        "sigma_contact_exact",
        "Option<f64>",
        "Pa",
        "closed-form (or reference-run) contact stress",
    ),
    (
        "energy_kinetic",
        "Option<f64>",
        "J",
        "kinetic part ½vᵀMv of E^h (2D/3D; null for bar1d)",
    ),
    (
        "energy_elastic",
        "Option<f64>",
        "J",
        "elastic part ½uᵀKu of E^h (2D/3D; null for bar1d)",
    ),
    (
        "energy_gravity",
        "Option<f64>",
        "J",
        "gravity potential −Fᵀu of E^h, zero at the initial position (scenes with gravity: disc2d, sphere3d, mesh2d/mesh3d with `gravity`; null without a load). kinetic + elastic + gravity = energy (penalty: plus its potential)",
    ),
    (
        "u_lowest",
        "Option<f64>",
        "m",
        "vertical displacement u_d of the lowest point of the reference configuration, the lowest Γ_C node (disc2d, sphere3d, mesh2d, mesh3d; null on the bars, whose Γ_C is flat)",
    ),
    (
        "sigma_t_contact",
        "Option<f64>",
        "Pa",
        "friction (contract §2.5): the base's tangential stress σ_t (layer1d; the force the scheme applied at t^n, impulses over τ); null without a tangential direction",
    ),
    (
        "v_t_contact",
        "Option<f64>",
        "m/s",
        "friction: the contact node's tangential velocity (its slip velocity while in contact); 2D/3D: the Γ_C mean of v_1 (over the Γ_C nodes, Nitsche/penalty: over the contact quadrature points)",
    ),
    (
        "friction_work",
        "Option<f64>",
        "J",
        "friction: the frictional work W_f^n = −Σ f̄_t·Δu_t so far (contract §2.5); energy + friction_work − its initial value is the normal contact's work",
    ),
    (
        "u_contact_b",
        "Option<f64>",
        "m",
        "two bodies: B's contact end's displacement along x (bars1d: u_b(L_a + g); 2D/3D: the mean normal displacement of Γ^b); u_contact is A's",
    ),
    (
        "momentum",
        "Option<f64>",
        "kg·m/s",
        "two bodies: the total momentum Pⁿ = Σ_i 1ᵀM_iv (contract §2.6)",
    ),
];

/// Timing of a run over its repeats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    pub repeats: usize,
}

impl RunRecord {
    /// Assemble the row of a run.
    pub fn new(sweep: &str, spec: &RunSpec, out: &Outcome, timing: Timing) -> RunRecord {
        let m = &out.metrics;
        RunRecord {
            run_id: spec.run_id.clone(),
            sweep: sweep.to_string(),
            scene: spec.scene.name().to_string(),
            label: spec.label.clone(),
            status: out.status.as_str().to_string(),
            message: out.message.clone(),
            scheme_label: spec.scheme_label.clone(),
            ensemble_sample: spec.sample.map(|(k, _)| k as i64),
            ensemble_perturbation: spec.sample.map(|(_, p)| p),
            search: spec.search.clone(),
            wall_time_s: timing.median_s,
            wall_time_min_s: timing.min_s,
            wall_time_max_s: timing.max_s,
            repeats: timing.repeats as i64,
            steps: m.steps,
            dofs: m.dofs,
            iterations: m.iterations,
            factorizations: m.factorizations,
            solver_failures: m.solver_failures,
            contact_switches: m.contact_switches,
            mass_total: m.mass_total,
            energy_initial: m.energy_initial,
            energy_final: m.energy_final,
            energy_drift: m.energy_drift,
            energy_max_dev: m.energy_max_dev,
            energy_max_increase: m.energy_max_increase,
            energy_theta_max_increase: m.energy_theta_max_increase,
            energy_theta_drift: m.energy_theta_drift,
            err_u_l2l2: m.err_u_l2l2,
            err_u_l2h1: m.err_u_l2h1,
            err_u_linfl2: m.err_u_linfl2,
            err_sigma_l2: m.err_sigma_l2,
            err_sigma_mid_l2: m.err_sigma_mid_l2,
            err_energy_l2: m.err_energy_l2,
            err_u_contact_max: m.err_u_contact_max,
            energy_scale: m.energy_scale,
            length_scale: m.length_scale,
            err_force_l2: m.err_force_l2,
            contact_dofs: m.contact_dofs,
            contact_toggles: m.contact_toggles,
            factor_cache_hits: m.factor_cache_hits,
            setup_time_s: m.setup_time_s,
            stepping_time_s: m.stepping_time_s,
            observe_time_s: m.observe_time_s,
            first_contact_time: m.first_contact_time,
            contact_phases: m.contact_phases,
            impact_step_first: phase_list(m, |p| p.step_first),
            impact_step_last: phase_list(m, |p| p.step_last),
            impact_t_first: phase_list(m, |p| p.t_first),
            impact_t_last: phase_list(m, |p| p.t_last),
            impact_energy_before: phase_list(m, |p| p.energy_before),
            impact_energy_after: phase_list(m, |p| p.energy_after),
            impact_energy_theta_before: phase_list(m, |p| p.energy_theta_before),
            impact_energy_theta_after: phase_list(m, |p| p.energy_theta_after),
            energy_theta_initial: m.energy_theta_initial,
            free_fall_error: m.free_fall_error,
            iterations_max_step: m.iterations_max_step,
            max_penetration: m.max_penetration,
            err_v_l2: m.err_v_l2,
            err_impact_time: m.err_impact_time,
            exit_velocity: m.exit_velocity,
            pressure_oscillation: m.pressure_oscillation,
            solver_iterations: m.solver_iterations,
            solver_iterations_max_step: m.solver_iterations_max_step,
            lockstep: m.lockstep,
            friction_work: m.friction_work,
            energy_balance_drift: m.energy_balance_drift,
            energy_balance_max_increase: m.energy_balance_max_increase,
            stick_steps: m.stick_steps,
            slip_steps: m.slip_steps,
            friction_ratio_max: m.friction_ratio_max,
            friction_newton_iterations: m.friction_newton_iterations,
            friction_continuation_iterations: m.friction_continuation_iterations,
            friction_fallback_iterations: m.friction_fallback_iterations,
            tangential_velocity_final: m.tangential_velocity_final,
            normal_velocity_final: m.normal_velocity_final,
            err_sigma_t_l2: m.err_sigma_t_l2,
            err_vt_final: m.err_vt_final,
            stop_time: m.stop_time,
            stop_time_exact: m.stop_time_exact,
            momentum_drift: m.momentum_drift,
            velocity_a_final: m.velocity_a_final,
            velocity_b_final: m.velocity_b_final,
            err_velocity_a_final: m.err_velocity_a_final,
            err_velocity_b_final: m.err_velocity_b_final,
            patch_stress_error: m.patch_stress_error,
            patch_pressure_error: m.patch_pressure_error,
            tool_version: env!("CARGO_PKG_VERSION").to_string(),
            ..Self::parameters(&spec.params)
        }
    }

    /// The run's parameter columns (the rest left at their defaults for [`RunRecord::new`]).
    fn parameters(p: &BTreeMap<Key, Value>) -> RunRecord {
        RunRecord {
            T: num(p, Key::T).unwrap_or(f64::NAN),
            h: num(p, Key::H).unwrap_or(f64::NAN),
            elements: elements_of(p),
            dt: num(p, Key::Dt).unwrap_or(f64::NAN),
            courant: num(p, Key::Courant).unwrap_or(f64::NAN),
            space: text(p, Key::Space),
            mass: text(p, Key::Mass),
            mass_weights: p.get(&Key::MassWeights).map(weights_text),
            contact_init: p.get(&Key::ContactInit).map(|v| v.to_string()),
            scheme: text(p, Key::Scheme),
            nitsche_theta: num(p, Key::NitscheTheta),
            nitsche_gamma0: num(p, Key::NitscheGamma0),
            penalty_gamma0: num(p, Key::PenaltyGamma0),
            newmark_beta: num(p, Key::NewmarkBeta),
            newmark_gamma: num(p, Key::NewmarkGamma),
            theta_scheme: num(p, Key::ThetaScheme),
            restitution: num(p, Key::Restitution),
            rho_inf: num(p, Key::RhoInf),
            hht_alpha: num(p, Key::HhtAlpha),
            length: num(p, Key::Length),
            young: num(p, Key::Young),
            density: num(p, Key::Density),
            amplitude: num(p, Key::Amplitude),
            gap: num(p, Key::Gap),
            lame_lambda: num(p, Key::LameLambda),
            lame_mu: num(p, Key::LameMu),
            gravity: num(p, Key::Gravity),
            degree: num(p, Key::Degree).map(|x| x as i64),
            right_end: p.get(&Key::RightEnd).map(|v| v.to_string()),
            velocity: num(p, Key::Velocity),
            point_mass: num(p, Key::PointMass),
            stiffness: num(p, Key::Stiffness),
            force: num(p, Key::Force),
            impact_law: num(p, Key::ImpactLaw),
            solver: p.get(&Key::Solver).map(|v| v.to_string()),
            cg_tol: num(p, Key::CgTol),
            load: p.get(&Key::Load).map(|v| v.to_string()),
            friction: p.get(&Key::Friction).map(|v| v.to_string()),
            friction_coefficient: num(p, Key::FrictionCoefficient),
            tresca_threshold: num(p, Key::TrescaThreshold),
            height: num(p, Key::Height),
            velocity_tangential: num(p, Key::VelocityTangential),
            incline: num(p, Key::Incline),
            friction_force: num(p, Key::FrictionForce),
            length_b: num(p, Key::LengthB).filter(|x| !x.is_nan()),
            young_b: num(p, Key::YoungB).filter(|x| !x.is_nan()),
            density_b: num(p, Key::DensityB).filter(|x| !x.is_nan()),
            velocity_b: num(p, Key::VelocityB),
            far_end: p.get(&Key::FarEnd).map(|v| v.to_string()),
            mass_side: p.get(&Key::MassSide).map(|v| v.to_string()),
            nitsche_sides: p.get(&Key::NitscheSides).map(|v| v.to_string()),
            height_b: num(p, Key::HeightB),
            width: num(p, Key::Width),
            mesh_ratio: num(p, Key::MeshRatio),
            pressure: num(p, Key::Pressure),
            lame_lambda_b: num(p, Key::LameLambdaB).filter(|x| !x.is_nan()),
            lame_mu_b: num(p, Key::LameMuB).filter(|x| !x.is_nan()),
            pairing: p.get(&Key::Pairing).map(|v| v.to_string()),
            mortar_basis: p.get(&Key::MortarBasis).map(|v| v.to_string()),
            interface_quadrature: p.get(&Key::InterfaceQuadrature).map(|v| v.to_string()),
            start: p.get(&Key::Start).map(|v| v.to_string()),
            ..RunRecord::default()
        }
    }
}

/// A numeric parameter of the run (None where it does not apply).
fn num(p: &BTreeMap<Key, Value>, k: Key) -> Option<f64> {
    p.get(&k).and_then(Value::as_f64)
}

/// A text parameter of the run ("" where it does not apply).
fn text(p: &BTreeMap<Key, Value>, k: Key) -> String {
    p.get(&k).map(|v| v.to_string()).unwrap_or_default()
}

/// The `elements` column: the run's element count (0 where none was resolved).
fn elements_of(p: &BTreeMap<Key, Value>) -> i64 {
    p.get(&Key::Elements)
        .and_then(|v| match v {
            Value::Int(i) => Some(*i),
            _ => None,
        })
        .unwrap_or(0)
}

/// The `mass_weights` column: the weights joined by commas.
fn weights_text(v: &Value) -> String {
    match v {
        Value::List(w) => w
            .iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(","),
        other => other.to_string(),
    }
}

/// One field of every contact phase of a run, as a list column value.
fn phase_list<T>(
    m: &super::observe::Metrics,
    f: impl Fn(&super::impacts::Phase) -> T,
) -> Option<Vec<T>> {
    m.impacts.as_ref().map(|ps| ps.iter().map(f).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{RunOptions, simulate};
    use crate::sweep::{SweepFile, expand};

    #[test]
    fn contact_init_column_is_null_where_the_contact_node_has_mass() {
        let text = "name = \"t\"\nscene = \"bar1d\"\n[fixed]\nT = 0.1\nh = 0.25\ndt = 0.05\ncontact_init = \"interpolant\"\n[grid]\nmass = [\"consistent\", \"zero-contact\"]\n";
        let plan =
            expand(&SweepFile::parse(std::path::Path::new("t.toml"), text).unwrap()).unwrap();
        let timing = Timing {
            median_s: 0.0,
            min_s: 0.0,
            max_s: 0.0,
            repeats: 1,
        };
        let rows: Vec<RunRecord> = plan
            .runs
            .iter()
            .map(|spec| {
                let out = simulate(&spec.config, &RunOptions::default());
                RunRecord::new("t", spec, &out, timing)
            })
            .collect();
        assert_eq!(rows[0].contact_init, None);
        assert_eq!(rows[1].contact_init.as_deref(), Some("interpolant"));
        // The massless node started at the interpolant: E⁰ is the exact energy a²E/(2L) = 1/8
        // (four squared strains, round-off only).
        assert!((rows[1].energy_initial.unwrap() - 0.125).abs() < 1e-15);
    }
}
