//! The exact solution of two elastic bars colliding (contract §1.9, the `bars1d` scene; Code_Aster's
//! SDNL111): event-driven characteristics at the interface, evaluated anywhere in closed form.
//!
//! **Maths.** Bar A occupies (0, L_a), bar B (L_a + g, L_a + g + L_b); in each ρ u_tt = E u_xx,
//! c = √(E/ρ), Z = ρc, transit time T = L/c, σ = E u_x, v = u_t. The invariant σ − Zv travels at
//! +c and σ + Zv at −c. Measure η ≥ 0 from the bar's contact end into the bar. In each bar the
//! wave leaving the contact end carries one signal f_i(s) — the value it had when it left the end
//! at time s (A: f_a = σ + Z_a v, B: f_b = σ − Z_b v) — and the wave coming back is the same signal
//! reflected by the far end after the round trip: a free end (σ = 0) gives k = −1, a clamp
//! (v = 0) k = +1. So at (η, t)
//!
//!   away p = f(t − η/c),  back q = k f(t − (2L − η)/c),  σ = (p + q)/2,  v = −n (p − q)/(2Z),
//!
//! with n = −1 in A (η = L_a − x) and n = +1 in B (η = x − L_a − g), and, since u(·, 0) = 0,
//!
//!   u = ∫₀ᵗ v = −n/(2Z) [F(t − η/c) − F(−η/c) − k (F(t − (2L − η)/c) − F(−(2L − η)/c))],
//!
//! F(s) = ∫₀ˢ f. Before t = 0 each f is the constant of the bars' rigid start (f_a = Z_a V_a,
//! f_b = −Z_b V_b; the clamp needs V_b = 0), so the same formulas hold from t = 0 on, before
//! the first echo included. The whole solution is thus two piecewise-constant signals, stored as
//! their breakpoints with F and ∫f² there: u, u_x = σ/E, u_t = v, the kinks of u(·, t) (one per
//! breakpoint younger than 2T), the mean velocity (1/L)∫v = −n/(2ρL)[F(t) − F(t−T) −
//! k(F(t−T) − F(t−2T))] and the energy ∫½ρv² + ½σ²/E = (1/(4Z))∫_{t−2T}^t f² follow exactly.
//!
//! **The interface** makes the signals. Its incoming invariants are R = k_a f_a(t − 2T_a) (A's
//! σ − Z_a v) and L = k_b f_b(t − 2T_b) (B's σ + Z_b v). Open: each end is free, f_a = −R, f_b = −L,
//! the ends move at −R/Z_a and L/Z_b and the gap d = g + u_b(L_a + g) − u_a(L_a) at the rate
//! d' = L/Z_b + R/Z_a. Closed (d = 0): one velocity and one stress,
//! v_c = (L − R)/(Z_a + Z_b), σ_c = (Z_b R + Z_a L)/(Z_a + Z_b), f_a = σ_c + Z_a v_c,
//! f_b = σ_c − Z_b v_c. Since σ_c = Z_aZ_b/(Z_a + Z_b)·d'_open, the contact holds while σ_c < 0,
//! opens (d' > 0) as soon as it would turn tensile, and a closed gap with σ_c = 0 is the marginal
//! touching with zero force (both laws agree there; no phase is recorded). The state changes only
//! when R or L changes (an earlier breakpoint back from a far end) or when an open gap closes
//! (d = 0 with d' < 0): the events, visited in time order from a queue of arrivals.
//!
//! **Round-off (why a tolerance, not rationals).** Event times are sums such as s_k + 2T_a and
//! s_j + 2T_b; when two are equal in exact arithmetic they differ by a few ulps in floating
//! point, and handled apart they make a spurious instant in which R has changed and L not: a
//! tensile σ_c, a false opening, pulses that echo for ever (contract §1.9: one implementation
//! lost 24 % of the energy that way). Exact rationals would need c = √(E/ρ) rational, which
//! SDNL111's steel is not, so arrivals and gap closures within 1e-10 of the time scale
//! max(T_a, T_b, t_final) are merged into one event (round-off of the sums is ~1e-15 of it;
//! distinct events of a physical problem are not that close), a stress within 1e-12 of the
//! scale max(Z_a, Z_b)·max|V| is zero (the touching case), and a signal change within that
//! stress tolerance is not a breakpoint. Point look-ups snap a time within 1e-12 of the time
//! scale onto a breakpoint (right-continuous, as [`super::bar1d::BarExact`] does): a time level
//! t^n = nτ meant to land on a front does not fall before it by round-off. Integrals (u, F) are
//! continuous and never snapped.

use std::collections::VecDeque;

use super::bar1d::integrate_error;

/// B's far end (A's, x = 0, is always free).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FarEnd {
    Free,
    Clamped,
}

/// One of the two bars.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Body {
    A,
    B,
}

/// One bar: length, Young's modulus, density and initial (uniform) velocity along +x.
#[derive(Debug, Clone, Copy)]
pub struct BarSpec {
    pub length: f64,
    pub young: f64,
    pub density: f64,
    pub velocity: f64,
}

impl BarSpec {
    /// c = √(E/ρ).
    pub fn wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }
    /// Z = ρc.
    pub fn impedance(&self) -> f64 {
        self.density * self.wave_speed()
    }
    /// T = L/c, the one-way transit time.
    pub fn transit(&self) -> f64 {
        self.length / self.wave_speed()
    }
}

/// The two-bar problem of contract §1.9.
#[derive(Debug, Clone, Copy)]
pub struct TwoBarsSpec {
    pub a: BarSpec,
    pub b: BarSpec,
    pub gap: f64,
    pub far_end: FarEnd,
}

/// Relative tolerances of the module header: merged event times (of the time scale), zero
/// stresses and signal changes (of the stress scale), snapped point look-ups (of the time scale).
const EVENT_TOL: f64 = 1e-10;
const STRESS_TOL: f64 = 1e-12;
const SNAP_TOL: f64 = 1e-12;
/// A bound on the events before t_final: far above any physical case (a few per transit), it
/// turns a runaway into a clear panic.
const MAX_EVENTS: usize = 1_000_000;

/// A breakpoint of a signal: from `time` on the signal is `value`; `int` = F(time) = ∫₀^time f,
/// `int_sq` = ∫₀^time f².
#[derive(Debug, Clone, Copy)]
struct Break {
    time: f64,
    value: f64,
    int: f64,
    int_sq: f64,
}

/// A piecewise-constant signal on (−∞, ∞): `init` before the first breakpoint (all at s ≥ 0).
#[derive(Debug, Clone)]
struct Signal {
    init: f64,
    breaks: Vec<Break>,
}

impl Signal {
    fn last_value(&self) -> f64 {
        self.breaks.last().map_or(self.init, |b| b.value)
    }

    fn push(&mut self, time: f64, value: f64) {
        let (int, int_sq) = self.integrals(time);
        self.breaks.push(Break {
            time,
            value,
            int,
            int_sq,
        });
    }

    /// The last breakpoint at or before s (none: before the first).
    fn before(&self, s: f64) -> Option<&Break> {
        let k = self.breaks.partition_point(|b| b.time <= s);
        k.checked_sub(1).map(|k| &self.breaks[k])
    }

    /// f(s), right-continuous, with s snapped forward onto a breakpoint within `snap`.
    fn value(&self, s: f64, snap: f64) -> f64 {
        self.before(s + snap).map_or(self.init, |b| b.value)
    }

    /// (F(s), ∫₀ˢ f²), exact: the integrals are continuous, so no snapping.
    fn integrals(&self, s: f64) -> (f64, f64) {
        match self.before(s) {
            None => (self.init * s, self.init * self.init * s),
            Some(b) => {
                let ds = s - b.time;
                (b.int + b.value * ds, b.int_sq + b.value * b.value * ds)
            }
        }
    }

    fn int(&self, s: f64) -> f64 {
        self.integrals(s).0
    }
}

/// One bar as the characteristics see it (module header): its signal and geometry.
#[derive(Debug, Clone)]
struct Side {
    spec: BarSpec,
    c: f64,
    z: f64,
    transit: f64,
    /// n: −1 for A (η = L_a − x), +1 for B (η = x − L_a − g).
    inward: f64,
    /// k: −1 free far end, +1 clamped.
    far: f64,
    /// x of the contact end.
    iface: f64,
    signal: Signal,
}

impl Side {
    fn new(spec: BarSpec, inward: f64, far: f64, iface: f64) -> Self {
        let (c, z) = (spec.wave_speed(), spec.impedance());
        Side {
            spec,
            c,
            z,
            transit: spec.length / c,
            inward,
            far,
            iface,
            // The rigid start: p = −n Z V (module header).
            signal: Signal {
                init: -inward * z * spec.velocity,
                breaks: Vec::new(),
            },
        }
    }

    /// (x_min, x_max) of the bar.
    fn interval(&self) -> (f64, f64) {
        let other = self.iface + self.inward * self.spec.length;
        (self.iface.min(other), self.iface.max(other))
    }

    /// (u, u_x, u_t) at x, t (module header's formulas).
    fn eval(&self, x: f64, t: f64, snap: f64) -> (f64, f64, f64) {
        let eta = (self.inward * (x - self.iface)).clamp(0.0, self.spec.length);
        let (d1, d2) = (eta / self.c, (2.0 * self.spec.length - eta) / self.c);
        let p = self.signal.value(t - d1, snap);
        let q = self.far * self.signal.value(t - d2, snap);
        let f = |s: f64| self.signal.int(s);
        let u = -self.inward / (2.0 * self.z)
            * ((f(t - d1) - f(-d1)) - self.far * (f(t - d2) - f(-d2)));
        let sigma = 0.5 * (p + q);
        let v = -self.inward * (p - q) / (2.0 * self.z);
        (u, sigma / self.spec.young, v)
    }

    /// The kinks of u(·, t) strictly inside the bar, ascending in x: one per breakpoint of age
    /// in (0, 2T), on the way out (η = c·age) or back (η = 2L − c·age).
    fn kinks(&self, t: f64) -> Vec<f64> {
        let l = self.spec.length;
        let mut xs: Vec<f64> = self
            .signal
            .breaks
            .iter()
            .filter_map(|b| {
                let reach = self.c * (t - b.time);
                let eta = if reach <= l { reach } else { 2.0 * l - reach };
                (eta > 0.0 && eta < l).then_some(self.iface + self.inward * eta)
            })
            .collect();
        xs.sort_by(f64::total_cmp);
        xs
    }

    /// (1/L)∫ u_t dx (module header).
    fn mean_velocity(&self, t: f64) -> f64 {
        let f = |s: f64| self.signal.int(s);
        let (t1, t2) = (t - self.transit, t - 2.0 * self.transit);
        -self.inward / (2.0 * self.spec.density * self.spec.length)
            * (f(t) - f(t1) - self.far * (f(t1) - f(t2)))
    }

    /// ∫ ½ρu_t² + ½E u_x² dx = (1/(4Z)) ∫_{t−2T}^t f².
    fn energy(&self, t: f64) -> f64 {
        let q = |s: f64| self.signal.integrals(s).1;
        (q(t) - q(t - 2.0 * self.transit)) / (4.0 * self.z)
    }
}

/// The state of the interface between two events.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    /// d > 0, or d = 0 and separating: both ends free.
    Open,
    /// d = 0 with zero force (the marginal case): both laws agree, no phase.
    Touch,
    /// d = 0, σ_c < 0.
    Contact,
}

/// The interface from `start` to the next event.
#[derive(Debug, Clone, Copy)]
struct Segment {
    start: f64,
    mode: Mode,
    stress: f64,
    gap: f64,
    gap_rate: f64,
}

/// The exact solution of contract §1.9 on [0, t_final] (module header).
#[derive(Debug, Clone)]
pub struct TwoBarsExact {
    spec: TwoBarsSpec,
    t_final: f64,
    sides: [Side; 2],
    segments: Vec<Segment>,
    phases: Vec<(f64, f64)>,
    /// Tolerances (module header): merged events, zero stress, snapped look-ups.
    tol_t: f64,
    tol_s: f64,
    snap: f64,
}

/// What the interface does under the incoming invariants (R, L) with the gap d: its segment
/// (from `start`) and the signals it sends into A and B.
fn interface(
    za: f64,
    zb: f64,
    start: f64,
    gap: f64,
    (r, l): (f64, f64),
    tol_s: f64,
) -> (Segment, f64, f64) {
    let zs = za + zb;
    let stress = (zb * r + za * l) / zs;
    let seg = |mode, stress, gap_rate| Segment {
        start,
        mode,
        stress,
        gap,
        gap_rate,
    };
    if gap <= 0.0 && stress < -tol_s {
        let v = (l - r) / zs;
        (
            seg(Mode::Contact, stress, 0.0),
            stress + za * v,
            stress - zb * v,
        )
    } else if gap <= 0.0 && stress <= tol_s {
        (seg(Mode::Touch, 0.0, 0.0), -r, -l)
    } else {
        (seg(Mode::Open, 0.0, l / zb + r / za), -r, -l)
    }
}

impl TwoBarsExact {
    /// The events on [0, t_final] (A's far end x = 0 free; A on (0, L_a), B on
    /// (L_a + g, L_a + g + L_b), reference coordinates; velocities along +x, A moving towards B
    /// when velocity_a > velocity_b). Panics on a non-positive length, modulus or density, a
    /// negative gap, a clamped B with a velocity, or a non-finite value.
    pub fn new(spec: TwoBarsSpec, t_final: f64) -> Self {
        for (name, bar) in [("a", spec.a), ("b", spec.b)] {
            for (key, v) in [
                ("length", bar.length),
                ("young", bar.young),
                ("density", bar.density),
            ] {
                assert!(
                    v.is_finite() && v > 0.0,
                    "bar {name}: {key} = {v} must be positive"
                );
            }
            assert!(
                bar.velocity.is_finite(),
                "bar {name}: velocity = {} must be finite",
                bar.velocity
            );
        }
        assert!(
            spec.gap.is_finite() && spec.gap >= 0.0,
            "gap = {} must be ≥ 0",
            spec.gap
        );
        assert!(
            spec.far_end == FarEnd::Free || spec.b.velocity == 0.0,
            "a clamped B starts at rest (velocity_b = {})",
            spec.b.velocity
        );
        assert!(t_final.is_finite() && t_final >= 0.0, "t_final = {t_final}");
        let far_b = match spec.far_end {
            FarEnd::Free => -1.0,
            FarEnd::Clamped => 1.0,
        };
        let a = Side::new(spec.a, -1.0, -1.0, spec.a.length);
        let b = Side::new(spec.b, 1.0, far_b, spec.a.length + spec.gap);
        let t_scale = a.transit.max(b.transit).max(t_final);
        let (va, vb) = (spec.a.velocity, spec.b.velocity);
        let v_scale = va.abs().max(vb.abs()).max((va - vb).abs());
        let mut exact = TwoBarsExact {
            spec,
            t_final,
            tol_t: EVENT_TOL * t_scale,
            tol_s: STRESS_TOL * a.z.max(b.z) * v_scale,
            snap: SNAP_TOL * t_scale,
            sides: [a, b],
            segments: Vec::new(),
            phases: Vec::new(),
        };
        exact.run_events();
        exact.phases = exact.collect_phases();
        exact
    }

    /// Visit the events in time order (module header), recording the interface's segments and
    /// the two signals' breakpoints.
    fn run_events(&mut self) {
        let (za, zb) = (self.sides[0].z, self.sides[1].z);
        // Arrivals at the interface: (time, new incoming invariant) for R (from A) and L (from B).
        let mut queues: [VecDeque<(f64, f64)>; 2] = [VecDeque::new(), VecDeque::new()];
        let mut incoming = [
            self.sides[0].far * self.sides[0].signal.init,
            self.sides[1].far * self.sides[1].signal.init,
        ];
        let (mut t, mut gap) = (0.0, self.spec.gap);
        loop {
            let (seg, fa, fb) = interface(za, zb, t, gap, (incoming[0], incoming[1]), self.tol_s);
            for (k, f) in [(0, fa), (1, fb)] {
                let side = &mut self.sides[k];
                if (f - side.signal.last_value()).abs() > self.tol_s {
                    side.signal.push(t, f);
                    queues[k].push_back((t + 2.0 * side.transit, side.far * f));
                }
            }
            self.segments.push(seg);
            assert!(
                self.segments.len() <= MAX_EVENTS,
                "two bars: more than {MAX_EVENTS} events before t = {t} (t_final = {})",
                self.t_final
            );
            let close = if seg.mode == Mode::Open && seg.gap_rate < 0.0 {
                t + gap / -seg.gap_rate
            } else {
                f64::INFINITY
            };
            let next = queues
                .iter()
                .filter_map(|q| q.front().map(|e| e.0))
                .fold(close, f64::min);
            if next > self.t_final + self.tol_t {
                break;
            }
            for (k, q) in queues.iter_mut().enumerate() {
                while let Some(&(at, value)) = q.front() {
                    if at > next + self.tol_t {
                        break;
                    }
                    incoming[k] = value;
                    q.pop_front();
                }
            }
            if seg.mode == Mode::Open {
                gap = if close <= next + self.tol_t {
                    0.0
                } else {
                    (gap + seg.gap_rate * (next - t)).max(0.0)
                };
            }
            t = next;
        }
    }

    /// Maximal runs of `Contact` segments, closed, clipped to [0, t_final], none of zero length.
    fn collect_phases(&self) -> Vec<(f64, f64)> {
        let mut phases: Vec<(f64, f64)> = Vec::new();
        let mut open: Option<f64> = None;
        for seg in &self.segments {
            match (seg.mode == Mode::Contact, open) {
                (true, None) => open = Some(seg.start),
                (false, Some(s)) => {
                    phases.push((s, seg.start.min(self.t_final)));
                    open = None;
                }
                _ => {}
            }
        }
        if let Some(s) = open {
            phases.push((s, self.t_final));
        }
        phases.retain(|(s, e)| e - s > self.tol_t);
        phases
    }

    fn side(&self, body: Body) -> &Side {
        match body {
            Body::A => &self.sides[0],
            Body::B => &self.sides[1],
        }
    }

    /// The problem.
    pub fn spec(&self) -> &TwoBarsSpec {
        &self.spec
    }

    /// The final time the events were followed to.
    pub fn t_final(&self) -> f64 {
        self.t_final
    }

    /// The body's reference interval: (0, L_a) or (L_a + g, L_a + g + L_b).
    pub fn interval(&self, body: Body) -> (f64, f64) {
        self.side(body).interval()
    }

    /// u(x, t), x a global reference coordinate inside that body's interval.
    pub fn u(&self, body: Body, x: f64, t: f64) -> f64 {
        self.side(body).eval(x, t, self.snap).0
    }

    /// ∂u/∂x (x, t) = σ/E (right-continuous in the signals at a front).
    pub fn u_x(&self, body: Body, x: f64, t: f64) -> f64 {
        self.side(body).eval(x, t, self.snap).1
    }

    /// ∂u/∂t (x, t).
    pub fn u_t(&self, body: Body, x: f64, t: f64) -> f64 {
        self.side(body).eval(x, t, self.snap).2
    }

    /// The interface segment at t (right-continuous: an event within the snap tolerance
    /// after t counts as reached).
    fn segment(&self, t: f64) -> &Segment {
        let k = self.segments.partition_point(|s| s.start <= t + self.snap);
        &self.segments[k.saturating_sub(1)]
    }

    /// σ_c as a step function: (start, σ_c) from each event on, the last piece up to t_final
    /// (for an exact ∫(σ_h − σ_c)² dt).
    pub fn stress_history(&self) -> Vec<(f64, f64)> {
        self.segments.iter().map(|s| (s.start, s.stress)).collect()
    }

    /// σ_c(t) ≤ 0 in contact, 0 otherwise (right-continuous at the events).
    pub fn contact_stress(&self, t: f64) -> f64 {
        self.segment(t).stress
    }

    /// The gap d(t) = g + u_b(L_a + g, t) − u_a(L_a, t) ≥ 0.
    pub fn gap(&self, t: f64) -> f64 {
        let s = self.segment(t);
        (s.gap + s.gap_rate * (t - s.start)).max(0.0)
    }

    /// Closed intervals of contact with nonzero force, within [0, t_final] (touching with zero
    /// force is not contact).
    pub fn contact_phases(&self) -> &[(f64, f64)] {
        &self.phases
    }

    /// The start of the first contact phase, if any before t_final.
    pub fn first_contact(&self) -> Option<f64> {
        self.phases.first().map(|p| p.0)
    }

    /// The times of the interface events (the changes of its incoming invariants and the gap
    /// closures), ascending from 0.
    pub fn event_times(&self) -> Vec<f64> {
        self.segments.iter().map(|s| s.start).collect()
    }

    /// (1/L_i)∫u_t dx of the continuous bar.
    pub fn mean_velocity(&self, body: Body, t: f64) -> f64 {
        self.side(body).mean_velocity(t)
    }

    /// The body's energy at t, ∫½ρu_t² + ½E u_x² dx.
    pub fn body_energy(&self, body: Body, t: f64) -> f64 {
        self.side(body).energy(t)
    }

    /// E⁰ = ½ρ_a L_a V_a² + ½ρ_b L_b V_b² (conserved).
    pub fn energy(&self) -> f64 {
        let e = |b: BarSpec| 0.5 * b.density * b.length * b.velocity * b.velocity;
        e(self.spec.a) + e(self.spec.b)
    }

    /// ρ_a L_a V_a + ρ_b L_b V_b (conserved with a free far end; a clamp is an external force).
    pub fn momentum(&self) -> f64 {
        let p = |b: BarSpec| b.density * b.length * b.velocity;
        p(self.spec.a) + p(self.spec.b)
    }

    /// The kinks of u(·, t) strictly inside the body, ascending (the fronts where u_x and u_t
    /// jump).
    pub fn kinks(&self, body: Body, t: f64) -> Vec<f64> {
        self.side(body).kinks(t)
    }

    /// Squared L2 norm and squared H1 seminorm of (u_h − u(·, t)) on body `body`, u_h the P1
    /// field with nodal values `nodal` on the uniform mesh of `nodal.len() − 1` elements covering
    /// the body's interval (a clamped B: `nodal` includes the clamped node, value 0). Exact:
    /// elements are split at every kink of u(·, t), between which the error is affine.
    pub fn error_sq(&self, body: Body, nodal: &[f64], t: f64) -> (f64, f64) {
        let side = self.side(body);
        let (x0, _) = side.interval();
        let (m, h, kinks) = self.mesh_kinks(side, nodal.len(), t);
        integrate_error(
            m,
            |i| nodal[i],
            h,
            &kinks,
            |x| side.eval(x0 + x, t, self.snap).0,
        )
    }

    /// The elements, the element size and the kinks of u(·, t) in the body's local coordinate
    /// (from its left end) for a mesh of `nodes` nodes. A kink within the snap distance c·snap of
    /// a node is that node's (module header): dropped, so that no piece of round-off length
    /// remains whose side of the front would be decided by round-off.
    fn mesh_kinks(&self, side: &Side, nodes: usize, t: f64) -> (usize, f64, Vec<f64>) {
        let (x0, _) = side.interval();
        let m = nodes - 1;
        let h = side.spec.length / m as f64;
        let near = side.c * self.snap;
        let kinks = side
            .kinks(t)
            .iter()
            .map(|k| k - x0)
            .filter(|k| (k - (k / h).round() * h).abs() > near)
            .collect();
        (m, h, kinks)
    }

    /// ∫(v_h − u_t(·, t))² over the body, v_h the P1 field with nodal values `nodal_v` on the
    /// same mesh as [`TwoBarsExact::error_sq`]. Exact: u_t is constant between the kinks, so the
    /// error is affine on each piece, whose ∫ e² over length d is d (e_l² + e_l e_r + e_r²)/3.
    pub fn velocity_error_sq(&self, body: Body, nodal_v: &[f64], t: f64) -> f64 {
        let side = self.side(body);
        let (x0, _) = side.interval();
        let (m, h, kinks) = self.mesh_kinks(side, nodal_v.len(), t);
        let mut next_kink = 0;
        let mut sum = 0.0;
        for i in 0..m {
            let (xa, xb) = (i as f64 * h, (i + 1) as f64 * h);
            let (va, vb) = (nodal_v[i], nodal_v[i + 1]);
            let vh = |x: f64| va + (vb - va) * (x - xa) / h;
            while next_kink < kinks.len() && kinks[next_kink] <= xa {
                next_kink += 1;
            }
            let mut xl = xa;
            let inner = kinks[next_kink..].iter().take_while(|k| **k < xb).copied();
            for xr in inner.chain(std::iter::once(xb)) {
                let d = xr - xl;
                if d > 0.0 {
                    let w = side.eval(x0 + 0.5 * (xl + xr), t, 0.0).2;
                    let (el, er) = (vh(xl) - w, vh(xr) - w);
                    sum += d * (el * el + el * er + er * er) / 3.0;
                    xl = xr;
                }
            }
        }
        sum
    }
}
