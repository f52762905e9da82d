//! The two-bar engine (contract §1.9, §2.6): a list of 1D bodies and the contact rows between
//! them, stepped by the one-bar engine's schemes.
//!
//! A second body is data, not a branch. Each body is a [`Bar1dSpace`] in its own frame — the
//! contact end at ξ = 0, the body in ξ > 0, so A is mirrored (ξ = L_a − x, ũ_a = −u_a) and B
//! shifted (ξ = x − L_a − g, ũ_b = u_b) — with its mass variant, its far end and its initial
//! velocity. The bodies' unknowns are stacked into one vector; M and K are then block-diagonal
//! tridiagonal matrices (the coupling entries between two blocks are zero), factored once per
//! run. The contact pair adds rows s_r = p_r·U + p0_r with force Σ_r φ_r q_r, each p_r and q_r a
//! few (index, value) entries that may touch both bodies:
//! - mixed (node-to-node): s = ũ_a0 + ũ_b0 + g = the gap d ≥ 0, q = −e_a0 − e_b0, φ = λ ≤ 0
//!   (complementarity);
//! - penalty: s = −(ũ_a0 + ũ_b0) − g, q as above, φ = −κ[s]₊, κ = E_a·γ0/h_a (row weight 1);
//! - nitsche: one row per side i with weight w_i > 0 (w_a = w_b = ½ unbiased, w_a = 1 one-sided),
//!   s_i = P^i_γ − g = −ũ_a0 − ũ_b0 − γ0E_i(ũ_i1 − ũ_i0) − g, q_i = w_i ∂P^i_Θγ/∂v, φ_i = −[s_i]₊/γ^i,
//!   and K_Θ = K − Σ_i w_i Θγ0E_i²/h_i (e_i1 − e_i0)(e_i1 − e_i0)ᵀ.
//!
//! Every q_r pushes the two bodies equally and oppositely (its entries on A and on B have the
//! same sum in the local frames, whose x-directions are opposite), and K_Θ's rows sum to zero on
//! a free body: the total momentum P = Σ_i 1ᵀM_i v is an invariant of every scheme here (contract
//! §2.6), which `momentum_drift` measures.
//!
//! The step is the one-bar engine's ([`super::bar1d`]) with more rows: a block tridiagonal
//! solve y = A⁻¹b, the condensed rows s = s_free + Wφ(s) with W = p_r·A⁻¹q̃_c precomputed —
//! one scalar equation ([`contact::solve`]) or two ([`contact::solve_pair`], unbiased Nitsche),
//! each solved exactly by its branches — and U = y + Σ φ_r z_r. A contact end without inertia
//! (a zero mass row) is quasi-static as in one bar: with both ends massless the mixed row's W
//! is the two ends' springs in series, k_a k_b/(k_a + k_b) (contract §2.6), without a case of
//! its own. The schemes: Newmark (β > 0) and θ (θ > 0), whose massless rows hold at t^{n+1};
//! `hybrid` (Nitsche, penalty) and `kane` (mixed), incremental with the massless rows at the
//! midpoint; `generalized-alpha`/`hht`, which need inertia on the contact ends.

use std::time::Instant;

use super::grid1d::Grid1d;
use super::observe::{Divergence, ExactValues, Observer, StepValues};
use super::stepping::{failed, finished, time_loop};
use super::{Metrics, Outcome, RunOptions, Status, Stop};
use crate::contact::{self, ContactLaw, ContactSolveError};
use crate::scene::bars1d_exact::{Body as Side, TwoBarsExact};
use crate::scene::{BarParams, Bars1dParams, MassSide};
use crate::space::{Bar1dSpace, ContactMethod, MassVariant, Tridiag, TridiagLu};
use crate::time::{GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, Scheme, ThetaParams};

/// A validated bars1d run.
#[derive(Debug, Clone, PartialEq)]
pub struct Bars1dConfig {
    pub bars: Bars1dParams,
    /// A's elements (B's follow from one h), the step and the method triple.
    pub grid: Grid1d,
    /// Ensemble member: relative amplitude of a uniform perturbation of the initial velocities
    /// and its seed (the bars start unstrained).
    pub perturbation: Option<(f64, u64)>,
}

impl Bars1dConfig {
    pub fn new(bars: Bars1dParams, grid: Grid1d) -> Self {
        Self {
            bars,
            grid,
            perturbation: None,
        }
    }

    /// The explicit schemes have no two-body step here: refused at plan time.
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        if self.grid.scheme.is_explicit() {
            return Err((
                "scheme",
                format!(
                    "scheme = {} is explicit: bars1d steps the implicit schemes only (central difference's kinematic contact is stated for one body against an obstacle)",
                    self.grid.scheme.label()
                ),
            ));
        }
        Ok(None)
    }

    /// B's element count.
    pub fn elements_b(&self) -> usize {
        self.bars.elements_b(self.grid.elements)
    }
}

/// One body in the stacked system: its space in its own frame and where its unknowns start;
/// `sign` maps its frame's displacement to x (A: −1, B: +1).
pub(super) struct Body {
    pub sp: Bar1dSpace,
    pub off: usize,
    pub sign: f64,
}

impl Body {
    fn range(&self) -> std::ops::Range<usize> {
        self.off..self.off + self.sp.m
    }

    /// Momentum along x of the body: sign·1ᵀMv over its unknowns.
    fn momentum(&self, v: &[f64]) -> f64 {
        let v = &v[self.range()];
        let mut p = 0.0;
        for (i, vi) in v.iter().enumerate() {
            let (l, d, u) = self.sp.mass.row(i);
            p += (l + d + u) * vi;
        }
        self.sign * p
    }
}

/// A sparse vector of the stacked system.
type Sparse = Vec<(usize, f64)>;

fn dot(p: &Sparse, x: &[f64]) -> f64 {
    p.iter().map(|&(i, c)| c * x[i]).sum()
}

/// A contact row: s = p·U + p0, force φ(s) q, the state law φ, its side weight (σ_c and the
/// Nitsche energy are weighted sums over the rows) and its γ_h (Nitsche).
pub(super) struct Row {
    p: Sparse,
    p0: f64,
    q: Sparse,
    law: ContactLaw,
    weight: f64,
    /// Nitsche: (γ_h of the side, σ_n's body offset, E_i/h_i).
    nitsche: Option<(f64, usize, f64)>,
}

/// The bodies, their stacked operators and the contact rows.
pub(super) struct System {
    pub bodies: Vec<Body>,
    pub n: usize,
    pub mass: Tridiag,
    /// The linear part's stiffness (K_Θ with Nitsche).
    pub klin: Tridiag,
    pub massless: Vec<usize>,
    pub rows: Vec<Row>,
    pub method: ContactMethod,
    pub gap: f64,
}

/// Copy `block` into `into` at offset `off` (a block of a block-diagonal tridiagonal matrix).
fn place(into: &mut Tridiag, block: &Tridiag, off: usize) {
    let m = block.len();
    into.diag[off..off + m].copy_from_slice(&block.diag);
    into.lower[off..off + m - 1].copy_from_slice(&block.lower);
    into.upper[off..off + m - 1].copy_from_slice(&block.upper);
}

impl System {
    /// The two bars of `cfg` as bodies and the pair's rows for the run's contact treatment.
    pub fn new(cfg: &Bars1dConfig) -> Result<Self, String> {
        let b = &cfg.bars;
        let mass_of = |side: MassSide| match (b.mass_side, side) {
            (MassSide::Both, _) => cfg.grid.mass.clone(),
            (s, t) if s == t => cfg.grid.mass.clone(),
            _ => MassVariant::Consistent,
        };
        let bar = |m: crate::scene::BarMaterial, free_end: bool, velocity: f64| BarParams {
            length: m.length,
            young: m.young,
            density: m.density,
            amplitude: 0.0,
            gap: 0.0,
            free_end,
            velocity,
        };
        let specs = [
            (
                bar(b.a, true, -b.a.velocity),
                cfg.grid.elements,
                mass_of(MassSide::A),
                -1.0,
            ),
            (
                bar(b.b, !b.clamped, b.b.velocity),
                cfg.elements_b(),
                mass_of(MassSide::B),
                1.0,
            ),
        ];
        let mut bodies = Vec::with_capacity(specs.len());
        let mut off = 0;
        for (params, elements, mass, sign) in specs {
            let sp = Bar1dSpace::new(params, elements, &mass, ContactMethod::Mixed)
                .map_err(|e| e.to_string())?;
            let m = sp.m;
            bodies.push(Body { sp, off, sign });
            off += m;
        }
        let n = off;
        let (mut mass, mut klin) = (Tridiag::zeros(n), Tridiag::zeros(n));
        let mut massless = Vec::new();
        for body in &bodies {
            place(&mut mass, &body.sp.mass, body.off);
            place(&mut klin, &body.sp.stiffness_lin, body.off);
            if body.sp.massless_contact {
                massless.push(body.off);
            }
        }
        let method = cfg.grid.method;
        let rows = contact_rows(&bodies, method, b, &mut klin);
        Ok(Self {
            bodies,
            n,
            mass,
            klin,
            massless,
            rows,
            method,
            gap: b.gap,
        })
    }

    /// The state's contact pressure σ_c: the weighted sum of the rows' laws (penalty, Nitsche);
    /// the multiplier of the step for `mixed` (`phi`).
    pub fn sigma(&self, u: &[f64], phi: &[f64; 2]) -> f64 {
        match self.method {
            ContactMethod::Mixed => phi[0],
            _ => self
                .rows
                .iter()
                .map(|r| match r.law {
                    ContactLaw::PositivePart { k } => r.weight * k * (dot(&r.p, u) + r.p0).max(0.0),
                    _ => 0.0,
                })
                .sum(),
        }
    }

    /// E^h = Σ_i ½vᵀM_iv + ½uᵀK_iu (plus the penalty potential), and E_Θ (Nitsche).
    pub fn energies(&self, u: &[f64], v: &[f64]) -> (f64, Option<f64>) {
        let mut eh: f64 = self
            .bodies
            .iter()
            .map(|b| b.sp.energies(&u[b.range()], &v[b.range()]).0)
            .sum();
        match self.method {
            ContactMethod::Mixed => (eh, None),
            ContactMethod::Penalty { .. } => {
                let r = &self.rows[0];
                let (ContactLaw::PositivePart { k }, s) = (r.law, dot(&r.p, u) + r.p0) else {
                    unreachable!("penalty rows are positive parts")
                };
                eh += -0.5 * k * s.max(0.0).powi(2);
                (eh, None)
            }
            ContactMethod::Nitsche { theta, .. } => {
                let mut extra = 0.0;
                for r in &self.rows {
                    let (gh, o, eh_i) = r.nitsche.expect("nitsche rows");
                    let sig = eh_i * (u[o + 1] - u[o]);
                    let sp = (dot(&r.p, u) + r.p0).max(0.0);
                    extra += r.weight * 0.5 * (gh * sig * sig - sp * sp / gh);
                }
                (eh, Some(eh - theta * extra))
            }
        }
    }

    /// P = Σ_i 1ᵀM_i v along x.
    pub fn momentum(&self, v: &[f64]) -> f64 {
        self.bodies.iter().map(|b| b.momentum(v)).sum()
    }

    /// Each body's mean velocity 1ᵀM_iv/1ᵀM_i1 along x.
    pub fn mean_velocity(&self, body: usize, v: &[f64]) -> f64 {
        let b = &self.bodies[body];
        b.sign * b.sp.mean_velocity(&v[b.range()])
    }
}

/// The pair's rows (contract §2.6) for `method`; Nitsche's Θ terms go into `klin`.
fn contact_rows(
    bodies: &[Body],
    method: ContactMethod,
    b: &Bars1dParams,
    klin: &mut Tridiag,
) -> Vec<Row> {
    let (oa, ob) = (bodies[0].off, bodies[1].off);
    let g = b.gap;
    let both = |c: f64| vec![(oa, c), (ob, c)];
    let plain = |p: Sparse, p0, law| Row {
        p,
        p0,
        q: both(-1.0),
        law,
        weight: 1.0,
        nitsche: None,
    };
    match method {
        ContactMethod::Mixed => vec![plain(both(1.0), g, ContactLaw::Complementarity)],
        ContactMethod::Penalty { gamma0 } => {
            let kappa = bodies[0].sp.penalty_stiffness(gamma0);
            vec![plain(
                both(-1.0),
                -g,
                ContactLaw::PositivePart { k: -kappa },
            )]
        }
        ContactMethod::Nitsche { theta, gamma0 } => {
            let weights = b.nitsche_sides.weights();
            let mut rows = Vec::new();
            for (i, &w) in weights.iter().enumerate() {
                if w == 0.0 {
                    continue;
                }
                let (me, other) = (&bodies[i], &bodies[1 - i]);
                let (o, oj) = (me.off, other.off);
                let (e, h) = (me.sp.bar.young, me.sp.h);
                let (ge, tge) = (gamma0 * e, theta * gamma0 * e);
                let c = w * theta * gamma0 * e * e / h;
                klin.add_element(o, [[-c, c], [c, -c]]);
                rows.push(Row {
                    p: vec![(o, -1.0 + ge), (o + 1, -ge), (oj, -1.0)],
                    p0: -g,
                    q: vec![(o, w * (-1.0 + tge)), (o + 1, -w * tge), (oj, -w)],
                    law: ContactLaw::PositivePart {
                        k: -1.0 / (gamma0 * h),
                    },
                    weight: w,
                    nitsche: Some((gamma0 * h, o, e / h)),
                });
            }
            rows
        }
    }
}

/// The per-run constant part: the system, the factored step matrix and the condensed rows.
pub(super) struct Engine {
    pub sys: System,
    scheme: Scheme,
    tau: f64,
    a_lu: TridiagLu,
    /// z_r = A⁻¹(c_f q_r) and W[r][c] = p_r·z_c.
    z: Vec<Vec<f64>>,
    w: [[f64; 2]; 2],
    /// Contact-stabilized Newmark's M-projection: M⁻¹q of its one row and p·M⁻¹q (empty
    /// otherwise).
    zm: Vec<f64>,
    wm: f64,
}

/// State: u, v, a (stacked, local frames) and the rows' previous arguments and forces.
pub(super) struct State {
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    a: Vec<f64>,
    s_prev: [f64; 2],
    phi_prev: [f64; 2],
}

/// Vectors reused by every step (no allocation in the time loop).
pub(super) struct Work {
    b: Vec<f64>,
    y: Vec<f64>,
    pred: Vec<f64>,
}

impl Engine {
    pub fn new(sys: System, scheme: Scheme, tau: f64) -> Result<Self, String> {
        let (c, cf) = scheme.coefficients(tau);
        let a = sys.mass.axpy(c, &sys.klin);
        let a_lu = a
            .factor()
            .ok_or("the iteration matrix M + cK of the two bars is singular")?;
        let z: Vec<Vec<f64>> = sys
            .rows
            .iter()
            .map(|r| {
                let mut z = vec![0.0; sys.n];
                for &(i, qv) in &r.q {
                    z[i] += cf * qv;
                }
                a_lu.solve_in_place(&mut z);
                z
            })
            .collect();
        let mut w = [[0.0; 2]; 2];
        for (r, row) in sys.rows.iter().enumerate() {
            for (col, zc) in z.iter().enumerate() {
                w[r][col] = dot(&row.p, zc);
            }
        }
        let (zm, wm) = if scheme == Scheme::ContactStabilizedNewmark {
            // The M-projection onto the admissible set (one mixed row, contact ends with mass:
            // the planner's), M⁻¹q once per run.
            let m_lu = sys
                .mass
                .factor()
                .ok_or("the mass matrix of the two bars is singular")?;
            let mut zm = vec![0.0; sys.n];
            for &(i, qv) in &sys.rows[0].q {
                zm[i] += qv;
            }
            m_lu.solve_in_place(&mut zm);
            let wm = dot(&sys.rows[0].p, &zm);
            (zm, wm)
        } else {
            (Vec::new(), 0.0)
        };
        Ok(Self {
            sys,
            scheme,
            tau,
            a_lu,
            z,
            w,
            zm,
            wm,
        })
    }

    /// Solve A y = b in place (wk.y), the condensed rows with `laws` and arguments shifted by
    /// `shift` (the incremental schemes' p·uⁿ), then y ← y + Σ φ_r z_r. Returns φ.
    fn solve(
        &self,
        wk: &mut Work,
        laws: [ContactLaw; 2],
        shift: [f64; 2],
    ) -> Result<[f64; 2], ContactSolveError> {
        self.a_lu.solve_in_place(&mut wk.b);
        std::mem::swap(&mut wk.b, &mut wk.y);
        let rows = &self.sys.rows;
        let free = |r: usize| dot(&rows[r].p, &wk.y) + rows[r].p0 + shift[r];
        let phi = if rows.len() == 1 {
            [contact::solve(&laws[0], free(0), self.w[0][0])?.phi, 0.0]
        } else {
            let sol = contact::solve_pair([&laws[0], &laws[1]], [free(0), free(1)], self.w)?;
            [sol[0].phi, sol[1].phi]
        };
        for (r, z) in self.z.iter().enumerate() {
            if phi[r] != 0.0 {
                for (y, z) in wk.y.iter_mut().zip(z) {
                    *y += phi[r] * z;
                }
            }
        }
        Ok(phi)
    }

    /// The rows' state laws (and, for the hybrid scheme, 003's switch on each row's sⁿ).
    fn laws(&self, st: &State) -> [ContactLaw; 2] {
        let law = |r: usize| {
            let Some(row) = self.sys.rows.get(r) else {
                return ContactLaw::Complementarity;
            };
            match (self.scheme, row.law) {
                (Scheme::Hybrid, ContactLaw::PositivePart { k }) => ContactLaw::HybridNitsche {
                    k,
                    s_prev: st.s_prev[r],
                },
                (_, law) => law,
            }
        };
        [law(0), law(1)]
    }

    /// p_r·u of each row (the incremental schemes' shift).
    fn p_dot(&self, u: &[f64]) -> [f64; 2] {
        let r = &self.sys.rows;
        [dot(&r[0].p, u), r.get(1).map_or(0.0, |row| dot(&row.p, u))]
    }

    /// One step; returns the rows' φ.
    ///
    /// Every scheme solves for the increment Δu = u^{n+1} − uⁿ, not for u^{n+1}: the
    /// acceleration (Δu − τvⁿ − k aⁿ)/(βτ²) is then a difference of increments, not of
    /// displacements, and its round-off — which is what moves P, since Σ_rows M a^{n+1} = 0
    /// holds only up to it — stays of the size of the velocities' (the u^{n+1} form, the
    /// one-bar engine's, drifted by 2.5e-12 of Σm|V| over 150 CN steps at |u|/τV ≈ 150).
    pub fn step(&self, st: &mut State, wk: &mut Work) -> Result<[f64; 2], ContactSolveError> {
        let tau = self.tau;
        let sys = &self.sys;
        let laws = self.laws(st);
        let shift = self.p_dot(&st.u);
        let phi = match self.scheme {
            Scheme::Newmark(NewmarkParams { beta, gamma }) => {
                // A Δu = M(τvⁿ + k aⁿ) − βτ² K uⁿ + βτ² Σ φ q; a massless row (M row 0) is then
                // (K u^{n+1})_i = (Σ φ q)_i, its equation at t^{n+1}.
                let k = tau * tau / 2.0 * (1.0 - 2.0 * beta);
                self.increment_rhs(st, wk, k, beta * tau * tau);
                let phi = self.solve(wk, laws, shift)?;
                let ib = 1.0 / (beta * tau * tau);
                for (((v, a), y), pred) in st.v.iter_mut().zip(&mut st.a).zip(&wk.y).zip(&wk.pred) {
                    let an = (y - pred) * ib;
                    *v += tau * ((1.0 - gamma) * *a + gamma * an);
                    *a = an;
                }
                phi
            }
            Scheme::Theta(ThetaParams { theta }) => {
                let k = tau * tau * theta * (1.0 - theta);
                self.increment_rhs(st, wk, k, theta * theta * tau * tau);
                let phi = self.solve(wk, laws, shift)?;
                let it = 1.0 / (tau * theta);
                for i in 0..sys.n {
                    let vn = (wk.y[i] - tau * (1.0 - theta) * st.v[i]) * it;
                    st.a[i] = (vn - st.v[i] - tau * (1.0 - theta) * st.a[i]) * it;
                    st.v[i] = vn;
                }
                phi
            }
            Scheme::Hybrid | Scheme::Kane => {
                // A Δu = τ M vⁿ − (τ²/2) K uⁿ + (τ²/2) Σ φ q (one bar's form; a massless row
                // holds at the midpoint).
                self.increment_rhs(st, wk, 0.0, tau * tau / 2.0);
                let phi = self.solve(wk, laws, shift)?;
                for (v, y) in st.v.iter_mut().zip(&wk.y) {
                    *v = 2.0 * y / tau - *v;
                }
                phi
            }
            Scheme::GeneralizedAlpha(ga) => self.gen_alpha(st, wk, ga, laws, shift)?,
            Scheme::ContactStabilizedNewmark => self.stabilized(st, wk)?,
            Scheme::MoreauJean(mj) => self.moreau_jean(st, wk, mj)?,
            _ => unreachable!("refused at plan time (scene bars1d)"),
        };
        for &i in &sys.massless {
            st.v[i] = wk.y[i] / tau;
            st.a[i] = 0.0;
        }
        for (y, u) in wk.y.iter_mut().zip(&st.u) {
            *y += u;
        }
        std::mem::swap(&mut st.u, &mut wk.y);
        let s = self.p_dot(&st.u);
        for (r, row) in sys.rows.iter().enumerate() {
            st.s_prev[r] = s[r] + row.p0;
        }
        st.phi_prev = phi;
        Ok(phi)
    }

    /// The predicted increment τvⁿ + k aⁿ into `pred` and the right-hand side
    /// M·pred − c K uⁿ of the increment's system into `b`.
    fn increment_rhs(&self, st: &State, wk: &mut Work, k: f64, c: f64) {
        for ((p, v), a) in wk.pred.iter_mut().zip(&st.v).zip(&st.a) {
            *p = self.tau * v + k * a;
        }
        self.sys.mass.mul_into(&wk.pred, &mut wk.b);
        self.sys.klin.mul_into(&st.u, &mut wk.y);
        for (b, ku) in wk.b.iter_mut().zip(&wk.y) {
            *b -= c * ku;
        }
    }

    /// Contact-stabilized Newmark (one mixed row), as the one-bar engine: the M-projection of
    /// the free flight uⁿ + τvⁿ onto the admissible set, then kane's step from it,
    /// S Δ = −τ²/4 K(uⁿ + u^pred) + τ²/2 φ q with Δ = u^{n+1} − u^pred, v^{n+1} = vⁿ + 2Δ/τ.
    /// Leaves the increment u^{n+1} − uⁿ in wk.y (as every step).
    fn stabilized(&self, st: &mut State, wk: &mut Work) -> Result<[f64; 2], ContactSolveError> {
        let tau = self.tau;
        let sys = &self.sys;
        let row = &sys.rows[0];
        for ((p, u), v) in wk.pred.iter_mut().zip(&st.u).zip(&st.v) {
            *p = u + tau * v;
        }
        let pred = contact::solve(
            &ContactLaw::Complementarity,
            dot(&row.p, &wk.pred) + row.p0,
            self.wm,
        )?;
        if pred.phi != 0.0 {
            for (x, z) in wk.pred.iter_mut().zip(&self.zm) {
                *x += pred.phi * z;
            }
        }
        for ((y, u), p) in wk.y.iter_mut().zip(&st.u).zip(&wk.pred) {
            *y = u + p;
        }
        sys.klin.mul_into(&wk.y, &mut wk.b);
        let c = 0.25 * tau * tau;
        for b in wk.b.iter_mut() {
            *b *= -c;
        }
        let shift = [dot(&row.p, &wk.pred), 0.0];
        let phi = self.solve(wk, [ContactLaw::Complementarity; 2], shift)?;
        for i in 0..sys.n {
            st.v[i] += 2.0 * wk.y[i] / tau;
            // The increment from uⁿ: u^pred − uⁿ + Δ.
            wk.y[i] += wk.pred[i] - st.u[i];
        }
        Ok(phi)
    }

    /// Moreau–Jean (one mixed row), as the one-bar engine: (M + θ²τ²K)Δv = −τK(uⁿ + θτvⁿ) + p q,
    /// the row active when its predicted gap (p·uⁿ + g) + ½τ p·vⁿ closes, and then
    /// 0 ≤ p·v^{n+1} + e p·vⁿ ⊥ impulse; u^{n+1} = uⁿ + τ(vⁿ + θΔv). Returns the impulse
    /// (σ_c is it over τ) and leaves the increment in wk.y.
    fn moreau_jean(
        &self,
        st: &mut State,
        wk: &mut Work,
        MoreauJeanParams { theta, restitution }: MoreauJeanParams,
    ) -> Result<[f64; 2], ContactSolveError> {
        let tau = self.tau;
        let sys = &self.sys;
        let row = &sys.rows[0];
        for ((y, u), v) in wk.y.iter_mut().zip(&st.u).zip(&st.v) {
            *y = u + theta * tau * v;
        }
        sys.klin.mul_into(&wk.y, &mut wk.b);
        for b in wk.b.iter_mut() {
            *b *= -tau;
        }
        let vn = dot(&row.p, &st.v);
        let law = if dot(&row.p, &st.u) + row.p0 + 0.5 * tau * vn <= 0.0 {
            ContactLaw::Complementarity
        } else {
            ContactLaw::PositivePart { k: 0.0 }
        };
        // The row's argument is p·Δv + (1 + e) p·vⁿ: no gap in it.
        let phi = self.solve(wk, [law; 2], [(1.0 + restitution) * vn - row.p0, 0.0])?;
        for i in 0..sys.n {
            let dv = wk.y[i];
            wk.y[i] = tau * (st.v[i] + theta * dv);
            st.v[i] += dv;
        }
        Ok(phi)
    }

    /// Generalized-α (HHT), the one-bar engine's equation at t^{n+1−α} for the increment:
    /// (M + cK)Δu = M(τvⁿ + k_p aⁿ − κ_m aⁿ) − (κ_f + c) K uⁿ + κ_f Σ φⁿ q + c Σ φ^{n+1} q.
    fn gen_alpha(
        &self,
        st: &mut State,
        wk: &mut Work,
        ga: GeneralizedAlphaParams,
        laws: [ContactLaw; 2],
        shift: [f64; 2],
    ) -> Result<[f64; 2], ContactSolveError> {
        let GeneralizedAlphaParams { beta, gamma, .. } = ga;
        let tau = self.tau;
        let sys = &self.sys;
        let kp = tau * tau * (0.5 - beta);
        let (km, kf) = ga.history_coefficients(tau);
        let c = ga.stiffness_coefficient(tau);
        // M(pred − κ_m aⁿ) − (κ_f + c) K uⁿ, pred = τvⁿ + k_p aⁿ kept for the update.
        self.increment_rhs(st, wk, kp - km, kf + c);
        for ((p, v), a) in wk.pred.iter_mut().zip(&st.v).zip(&st.a) {
            *p = tau * v + kp * a;
        }
        for (row, phi) in sys.rows.iter().zip(st.phi_prev) {
            for &(i, q) in &row.q {
                wk.b[i] += kf * phi * q;
            }
        }
        let phi = self.solve(wk, laws, shift)?;
        let ib = 1.0 / (beta * tau * tau);
        for (((v, a), y), pred) in st.v.iter_mut().zip(&mut st.a).zip(&wk.y).zip(&wk.pred) {
            let an = (y - pred) * ib;
            *v += tau * ((1.0 - gamma) * *a + gamma * an);
            *a = an;
        }
        Ok(phi)
    }

    /// The initial state: unstrained bars (u⁰ = 0, which is every massless end's quasi-static
    /// value: the gap g ≥ 0 is open or closed without force), each body at its velocity
    /// (perturbed for ensembles), a⁰ = 0 (no force acts).
    fn initial_state(&self, perturbation: Option<(f64, u64)>) -> State {
        let n = self.sys.n;
        let mut v = vec![0.0; n];
        let mut rng = perturbation.map(|(_, seed)| fastrand::Rng::with_seed(seed));
        for b in &self.sys.bodies {
            for x in &mut v[b.range()] {
                *x = b.sp.bar.velocity;
                if let (Some(rng), Some((delta, _))) = (rng.as_mut(), perturbation) {
                    *x *= 1.0 + delta * (2.0 * rng.f64() - 1.0);
                }
            }
        }
        let mut s_prev = [0.0; 2];
        for (r, row) in self.sys.rows.iter().enumerate() {
            s_prev[r] = row.p0;
        }
        State {
            u: vec![0.0; n],
            v,
            a: vec![0.0; n],
            s_prev,
            phi_prev: [0.0; 2],
        }
    }
}

/// What a run observes besides the one-body observables: P⁰, max|Pⁿ − P⁰|, the momentum unit.
struct Momentum {
    p0: f64,
    max_dev: f64,
    unit: f64,
}

/// What the observation of a step needs besides the state: the exact solution, the step and a
/// buffer for one body's nodal values in x order (no allocation per step but the exact
/// solution's kink lists).
struct View {
    exact: TwoBarsExact,
    tau: f64,
    nodal: Vec<f64>,
}

impl View {
    /// Body `i`'s nodal displacements in the global frame, in increasing x, into `nodal`
    /// (a clamped far node included, at 0), as [`TwoBarsExact::error_sq`] takes them.
    fn fill_nodal(&mut self, sys: &System, i: usize, x: &[f64]) {
        let b = &sys.bodies[i];
        let local = &x[b.range()];
        self.nodal.clear();
        if b.sign < 0.0 {
            // A, mirrored: its node m (far end x = 0) first.
            self.nodal.extend(local.iter().rev().map(|u| -u));
        } else {
            self.nodal.extend_from_slice(local);
            if !b.sp.bar.free_end {
                self.nodal.push(0.0);
            }
        }
    }

    /// The exact values at step `step` for the state u: the contact end, σ_c (and at the
    /// midpoint), the energy, and the error norms summed over both bars.
    fn exact_values(&mut self, sys: &System, step: usize, u: &[f64]) -> ExactValues {
        let t = step as f64 * self.tau;
        let (mut l2_sq, mut h1_semi_sq) = (0.0, 0.0);
        for (i, side) in [Side::A, Side::B].into_iter().enumerate() {
            self.fill_nodal(sys, i, u);
            let (l2, h1) = self.exact.error_sq(side, &self.nodal, t);
            l2_sq += l2;
            h1_semi_sq += h1;
        }
        let ex = &self.exact;
        ExactValues {
            u_contact: ex.u(Side::A, ex.interval(Side::A).1, t),
            sigma_contact: ex.contact_stress(t),
            sigma_contact_mid: (step > 0).then(|| ex.contact_stress(t - 0.5 * self.tau)),
            energy: ex.energy(),
            l2_sq,
            h1_semi_sq,
        }
    }
}

/// Observe one state (with its contact pressure); returns its momentum.
fn record(
    eng: &Engine,
    obs: &mut Observer,
    view: &mut View,
    step: usize,
    (st, sigma): (&State, f64),
) -> Result<f64, Divergence> {
    let sys = &eng.sys;
    let (oa, ob) = (sys.bodies[0].off, sys.bodies[1].off);
    let (energy, energy_theta) = sys.energies(&st.u, &st.v);
    let p = sys.momentum(&st.v);
    let exact = view.exact_values(sys, step, &st.u);
    obs.set_two_body(st.u[ob], p);
    obs.observe(
        StepValues {
            step,
            t: step as f64 * view.tau,
            u_contact: -st.u[oa],
            v_contact: -st.v[oa],
            sigma_contact: sigma,
            sigma_mid: None,
            energy,
            energy_theta,
            energy_kinetic: None,
            energy_elastic: None,
            energy_gravity: None,
            u_lowest: None,
            penetration: Some((-(st.u[oa] + st.u[ob] + sys.gap)).max(0.0)),
        },
        Some(exact),
    )?;
    Ok(p)
}

/// How often the wall clock is read (as the one-bar engine).
const CLOCK_EVERY: usize = 64;

/// Run one bars1d simulation.
pub fn simulate(cfg: &Bars1dConfig, opts: &RunOptions) -> Outcome {
    let start = Instant::now();
    let mut metrics = Metrics {
        dofs: 0,
        length_scale: Some(cfg.bars.a.length),
        ..Metrics::default()
    };
    let sys = match System::new(cfg) {
        Ok(s) => s,
        Err(e) => return failed(Status::Invalid, e, metrics),
    };
    metrics.dofs = sys.n as i64;
    metrics.mass_total = Some(sys.bodies.iter().map(|b| b.sp.mass_total).sum());
    let tau = cfg.grid.dt;
    let eng = match Engine::new(sys, cfg.grid.scheme, tau) {
        Ok(e) => e,
        Err(e) => return failed(Status::SolverFailed, e, metrics),
    };
    metrics.factorizations = 1;
    if let Some((status, msg)) = opts.setup_stop(start, "the factorisation") {
        return failed(status, msg, metrics);
    }
    let n = eng.sys.n;
    let mut wk = Work {
        b: vec![0.0; n],
        y: vec![0.0; n],
        pred: vec![0.0; n],
    };
    let mut st = eng.initial_state(cfg.perturbation);
    let mut obs = Observer::new(tau, opts.series_every, cfg.grid.steps);
    let steps = cfg.grid.steps;
    let mut view = View {
        exact: TwoBarsExact::new(cfg.bars.exact_spec(), steps as f64 * tau),
        tau,
        nodal: Vec::with_capacity(n + 1),
    };
    // Σ m_i|V_i| with the run's masses: the unit of the drift (null without motion or with a
    // clamp, contract §5).
    let unit: f64 = eng
        .sys
        .bodies
        .iter()
        .map(|b| (b.momentum(&st.v)).abs())
        .sum();
    let mut mom = Momentum {
        p0: 0.0,
        max_dev: 0.0,
        unit,
    };
    let end = time_loop(
        opts,
        start,
        (CLOCK_EVERY, tau, steps),
        &mut metrics,
        |clock, metrics| {
            mom.p0 = record(&eng, &mut obs, &mut view, 0, (&st, 0.0)).map_err(Stop::Diverged)?;
            for k in 1..=steps {
                let phi = eng.step(&mut st, &mut wk).map_err(|e| Stop::Solver(k, e))?;
                metrics.iterations += 1;
                let sigma = match cfg.grid.scheme {
                    // The impulse of the step: the force is p/τ (contract §3.2).
                    Scheme::MoreauJean(_) => phi[0] / tau,
                    _ => eng.sys.sigma(&st.u, &phi),
                };
                let p = eng.sys.momentum(&st.v);
                mom.max_dev = mom.max_dev.max((p - mom.p0).abs());
                clock.observe(k, || {
                    record(&eng, &mut obs, &mut view, k, (&st, sigma)).map(|_| ())
                })?;
                clock.completed(k)?;
            }
            Ok(())
        },
    );
    obs.finish(&mut metrics, end.status == Status::Ok);
    if !cfg.bars.clamped && mom.unit > 0.0 {
        metrics.momentum_drift = Some(mom.max_dev / mom.unit);
    }
    let (va, vb) = (
        eng.sys.mean_velocity(0, &st.v),
        eng.sys.mean_velocity(1, &st.v),
    );
    metrics.velocity_a_final = Some(va);
    metrics.velocity_b_final = Some(vb);
    if end.status == Status::Ok {
        // The exact mean velocities at the last step's time (contract §1.9).
        let t = end.done as f64 * tau;
        let ex = &view.exact;
        metrics.err_velocity_a_final = Some((va - ex.mean_velocity(Side::A, t)).abs());
        metrics.err_velocity_b_final = Some((vb - ex.mean_velocity(Side::B, t)).abs());
    }
    finished(end.status, end.message, metrics, &mut obs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{BarMaterial, NitscheSides};

    /// Two massless contact ends (`zero-contact` on both bars) are quasi-static: in contact the
    /// multiplier is the two end elements' springs in series, contract §2.6's closed form
    /// λ = −[δ₁ − g]₊·k_a k_b/(k_a + k_b) with δ₁ = u_a(L_a − h_a) − u_b(L_a + g + h_b) the
    /// neighbours' approach and k_i = E_i/h_i — at every step of the run, without a case of its
    /// own in the solve. Round-off of a few O(1) operations on O(1) values: 1e-12 relative.
    #[test]
    fn two_massless_ends_are_springs_in_series() {
        let bar = |length, young, density, velocity| BarMaterial {
            length,
            young,
            density,
            velocity,
        };
        let bars = Bars1dParams {
            a: bar(1.0, 1.0, 1.0, 1.0),
            b: bar(1.5, 3.0, 0.7, -0.2),
            gap: 0.01,
            clamped: false,
            mass_side: MassSide::Both,
            nitsche_sides: NitscheSides::Unbiased,
        };
        let tau = 0.02;
        let scheme = Scheme::Newmark(NewmarkParams::crank_nicolson());
        let grid = Grid1d::new(
            20,
            tau,
            2.0,
            ContactMethod::Mixed,
            MassVariant::ZeroContact,
            scheme,
        );
        let cfg = Bars1dConfig::new(bars, grid);
        let eng = Engine::new(System::new(&cfg).unwrap(), scheme, tau).unwrap();
        let (a, b) = (&eng.sys.bodies[0], &eng.sys.bodies[1]);
        let (ka, kb) = (a.sp.bar.young / a.sp.h, b.sp.bar.young / b.sp.h);
        let mut st = eng.initial_state(None);
        let n = eng.sys.n;
        let mut wk = Work {
            b: vec![0.0; n],
            y: vec![0.0; n],
            pred: vec![0.0; n],
        };
        let mut contact_steps = 0;
        for _ in 0..100 {
            let phi = eng.step(&mut st, &mut wk).unwrap();
            // δ₁ − g in the local frames: −(ũ_a1 + ũ_b1) − g.
            let approach = -(st.u[a.off + 1] + st.u[b.off + 1]) - bars.gap;
            let series = -approach.max(0.0) * ka * kb / (ka + kb);
            assert!(
                (phi[0] - series).abs() <= 1e-12 * series.abs().max(1.0),
                "λ = {} against the series springs' {series}",
                phi[0]
            );
            if phi[0] < 0.0 {
                contact_steps += 1;
            }
        }
        assert!(contact_steps > 10, "the bars met for {contact_steps} steps");
    }
}
