//! The condensed frictional contact problem of m contact nodes (contract §2.5, §4): Coulomb's or
//! Tresca's law on a dense, symmetric positive semi-definite W.
//!
//! Each node i carries d forces on the body, node-major f_i = (f_n, f_t) with f_t ∈ ℝ^{d−1}
//! (the tangential directions e_1, and e_2 in 3D), and once a step is condensed onto the
//! contact nodes the gaps and slips are affine in all of them:
//!
//!   gap  = q_n + (W f)_n ≥ 0  ⊥  f_n ≥ 0,
//!   slip = q_t + (W f)_t,   |f_t| ≤ b_i,   f_t = −b_i slip/|slip| where slip ≠ 0,
//!
//! b_i = μ_f f_n (Coulomb: the disc in 3D, not a pyramid) or s·w_i while in contact (Tresca,
//! w_i = ∫_ΓC φ_i the node's weight). What "gap" and "slip" are is the caller's: the gap and
//! the slip increment u_t^{n+1} − u_t^n of a position-level scheme, the normal and tangential
//! velocities of Moreau–Jean (`active` then masks the index set).
//!
//! Coulomb's problem is not a convex program (the bound moves with f_n): it is solved by
//! semismooth Newton on the Alart–Curnier functions, with r_i = 1/W_{(i,n),(i,n)} per node,
//!
//!   Φ_n = f_n − [f_n − r gap]₊,   Φ_t = f_t − proj_{B(b)}(f_t − r slip),  b = slope·[f_n − r gap]₊ + offset,
//!
//! (slope, offset) = (μ_f, 0) for Coulomb, (0, s·w_i) for Tresca (offset only while the node is
//! closed, f_n − r gap > 0). The generalised Jacobian of Φ is piecewise constant in 2D, so each
//! Newton step is the primal–dual active-set step: from the iterate, each node is open
//! (f_n − r gap ≤ 0: f = 0), stick (|x| ≤ b with x = f_t − r slip: gap = 0 and slip = 0) or
//! slipping (gap = 0 and f_t = b·x/|x|). In 2D the slip direction σ = sign x is a constant of
//! the step and the slipping node's f_t = σ(μ_f f_n + offset) is eliminated; in 3D the disc's
//! projection is linearised, t = x/|x|, P = I − t tᵀ, α = b/|x| < 1:
//!
//!   f_t − μ_f t f_n − α P (f_t − r slip(f)) = offset·t
//!
//! (the Newton equation Φ(f^k) + J(f − f^k) = 0 rewritten with P x^k = 0). In the frame
//! (t, s), s = (−t_1, t_0), P = s sᵀ, its two rows are tᵀf_t − μ_f f_n = offset, local to the
//! node, and (1 − α) sᵀf_t + α r sᵀ slip(f) = 0: the first eliminates f_t's component along the
//! axis of the larger |t_a| (f_t,a = (μ_f f_n + offset − t_b f_t,b)/t_a, |t_a| ≥ 1/√2) as 2D
//! eliminates f_t, the second is the node's one tangential row — the same step ([t s] is a
//! rotation), two unknowns per slipping node instead of three: a block all sliding factors an
//! LU of 2m, not 3m, unknowns (0.30 of the flops). Each step is one
//! dense LU with partial pivoting on the unknowns of the closed nodes (small: the contact set):
//! faer's blocked LU (recursive, its updates on gemm kernels) for a 3D system with such an
//! eliminated slipping node — whose round-off the elimination changed anyway — the hand loop
//! for the others, whose numbers (2D, 3D without slip) it keeps bit for bit;
//! in buffers allocated once by [`FrictionalContact::new`]; no allocation per solve. A 2D
//! system, or a 3D one without a slipping node, depends only on the node states (and μ_f), so
//! its LU is kept and reused while the states repeat — from one time step to the next during a
//! steady contact phase a step then costs two triangular solves. A 3D system with slipping
//! nodes changes with their directions t and ratios α at every iterate, but slowly: while the
//! node kinds (open, stick, slip; a slipping node's eliminated axis) are those of the kept LU,
//! the step is first a chord step on
//! it, f ← f − J_old⁻¹ (J f − rhs) with the current rows (the exact Newton residual, so its
//! fixed points are the law's solutions), kept where it divides ‖Φ‖ by at least 10 (else a
//! Newton step on a fresh factor follows, with the line search below) — on the 3D block of
//! issue 43, 273 unknowns all sliding, a dense LU (k³/3 flops) per iteration had been most of
//! the frictional step; a chord step costs a few k² products. Convergence: the natural
//! residual ‖Φ‖_∞ below `tol` relative to the problem's force scale max(|f|, r|q|) (contract §4:
//! 1e-12); not converged within `max_iter` steps is an error ([`FrictionalContactError`]), which
//! an engine reports as a `solver-failed` run. Warm-started from the caller's forces (the
//! previous step's): a phase whose states do not change costs one Newton step.
//!
//! Tresca's bound is discontinuous: s·w_i while f_n − r gap > 0, 0 otherwise. With coupled rows
//! (W_nt ≠ 0) the tangential force can lift its own node, and then the literal law may have no
//! solution at all (issue 33: bar3d's four corners with the mod3 mass, the force holding back
//! the spreading face opens them — stick and slip both need f_n < 0, open penetrates), and the
//! Newton iteration cycles. Where it does not converge, Tresca falls back to the law's closure
//! (the Heaviside of "in contact" taken as its maximal monotone graph, H(0) = [0, 1], as for any
//! discontinuous law — Filippov's convexification): at gap = 0 and f_n = 0 the node is still in
//! contact and its bound is any b ∈ [0, s·w_i] — a grazing node whose tangential force is
//! exactly what keeps it on the plane. Its natural residual is continuous: Φ_t with
//!
//!   b̂ = proj_[0, s·w](|f_t| + f_n − r gap),
//!
//! whose zeros are the literal law's solutions and the grazing ones (f_n > 0 forces b̂ = s·w
//! where the node slips; gap > 0 forces f_t = 0). Where b̂ is strictly inside, the Newton row
//! carries b̂'s linearisation (|f_t| ≈ t_fᵀ f_t, t_f = f_t/|f_t|, or the slip's direction where
//! f_t = 0) in place of the constant s·w, and a node with f_n − r gap ≤ 0 but b̂ > 0 keeps its
//! tangential rows with f_n = 0. The fallback runs from the warm start, then from zero; the
//! steps reported count the literal attempt's. Every problem the literal Newton solves keeps
//! its numbers bit for bit.
//!
//! The rescue (issue 43). Where the primary Newton (and, for Tresca, its closure) does not
//! converge, the step is not yet declared failed: the damped active-set Newton can cycle between
//! states on a strongly coupled W (large μ_f, stick at contact onset, Tresca's jump), although
//! the problem has a solution. Two further stages run, each to the same natural residual `tol`:
//! (1) continuation in the bound, b_θ = θ·b: from the frictionless problem (θ = 0, the LCP the
//! Newton always solves) to θ = 1 with an adaptive step (doubled after a success, halved after a
//! failure, given up below 1/1024), each Newton warm-started from the previous θ's solution —
//! the path the solution follows as friction is switched on, on which each step starts near its
//! answer; Tresca in its closure; (2) projected block Gauss–Seidel on the law itself from the
//! last point the continuation solved (else the warm start): node by node, the others held, the
//! local projections f_n ← [f_n − r y_n]₊, f_t ← proj_B(b)(f_t − r_t y_t) (r_t = 1/λ_max of
//! the node's tangential block) — each sweep a descent on the stick problem, slow but not
//! cycling — with a Newton polish from its iterate every [`GS_POLISH_EVERY`] sweeps. Only a
//! step none of them solves is an error. The rescue runs only where the primary Newton failed,
//! so every step it solves keeps its numbers bit for bit; [`FrictionalContact::stages`] says
//! what each stage spent, and the steps returned are their sum.
//!
//! With μ_f = 0 (or s = 0) every closed node's tangential force is 0 and the problem is the
//! frictionless LCP of [`super::lcp`] (same solution, tested); for one node it is
//! [`super::friction::solve_point`]'s exact case analysis (tested).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{MatMut, MatRef, Par};

use super::friction::FrictionLaw;

/// Why the frictional contact problem was not solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrictionalContactError {
    #[error(
        "frictional contact: semismooth Newton did not converge in {iterations} iterations (natural residual {residual:.3e} relative)"
    )]
    NoConvergence { iterations: usize, residual: f64 },
    #[error("frictional contact: the Newton system on the active set is singular")]
    Singular,
    #[error("frictional contact: non-finite data")]
    NonFinite,
    #[error(
        "frictional contact: the condensed operator is not positive at node {node} (W_nn = {w_nn:.3e})"
    )]
    NonPositive { node: usize, w_nn: f64 },
}

/// The state of one node in a Newton step.
#[derive(Debug, Clone, Copy, PartialEq)]
enum NodeState {
    Open,
    Stick,
    /// Slipping; 2D: the direction σ = ±1 of x (f_t = σ b).
    Slip2 {
        sigma: f64,
    },
    /// Slipping in 3D: t = x/|x| and α = b/|x| (linearised disc projection).
    Slip3 {
        t: [f64; 2],
        alpha: f64,
    },
}

/// One step's problem as every stage of the solve sees it (the primary Newton, Tresca's
/// closure, the continuation, Gauss–Seidel and its polish): the free gaps and slips, Tresca's
/// node weights, the nodes allowed to carry force, the iteration budget and the tolerance
/// relative to max(`scale`, |f|).
#[derive(Clone, Copy)]
struct Problem<'a> {
    weights: &'a [f64],
    q_n: &'a [f64],
    q_t: &'a [f64],
    kept: &'a dyn Fn(usize) -> bool,
    max_iter: usize,
    tol: f64,
    scale: f64,
}

/// The frictional contact problem of m nodes in dimension d, with its workspace.
#[derive(Debug, Clone)]
pub struct FrictionalContact {
    m: usize,
    d: usize,
    /// W, dm × dm, row-major, node-major rows and columns.
    w: Vec<f64>,
    /// r_i = 1/W_(i,n),(i,n).
    r: Vec<f64>,
    /// gap and slip of the iterate, node-major (dm).
    y: Vec<f64>,
    state: Vec<NodeState>,
    /// Tresca's states beyond [`NodeState`] (all default for Coulomb).
    extra: Vec<Extra>,
    /// Unknown index of each force component (`NONE`: eliminated), the component of each
    /// unknown (`unk[..k]`, ascending), and the nodes with an eliminated tangential force
    /// (`elim[..n_elim]`, ascending: a slipping node's, [`eliminated`]).
    col: Vec<usize>,
    unk: Vec<usize>,
    elim: Vec<usize>,
    n_elim: usize,
    /// Per node of `elim` (the step's [`Self::substitutions`]): the eliminated component's
    /// index in f, the unknowns of f_n and of the kept f_t,b (`NONE` in 2D), and the
    /// substitution f_elim = c_n f_n + c_b f_t,b + c_0 as (c_n, c_b, c_0).
    sub_at: Vec<[usize; 3]>,
    sub_coef: Vec<[f64; 3]>,
    /// Dense system (k × k, row-major), its right-hand side, a full row, the pivots (the
    /// blocked LU's row permutation and its inverse).
    mat: Vec<f64>,
    rhs: Vec<f64>,
    row: Vec<f64>,
    piv: Vec<usize>,
    piv_inv: Vec<usize>,
    /// `mat` holds faer's blocked LU of Jᵀ rather than the hand loop's of J (module header,
    /// the LU), with its scratch.
    lu_blocked: bool,
    scratch: LuScratch,
    /// The states (and μ_f) the LU in `mat` factors, if it may be reused.
    lu_state: Vec<NodeState>,
    lu_extra: Vec<Extra>,
    lu_slope: f64,
    lu_k: usize,
    lu_valid: bool,
    /// `mat` holds an LU of a 3D system with `lu_state`'s node kinds: a chord step may use it
    /// (module header, the chord steps).
    lu_chord: bool,
    /// The rows being reduced are the residual of the Newton equation at `trial` (a chord step).
    residual_form: bool,
    /// Tresca's closure (the fallback, module header) in force.
    closure: bool,
    /// The caller's warm start, kept for the fallback.
    warm: Vec<f64>,
    /// Unknowns of the current Newton step.
    k: usize,
    /// The Newton point and the step's start (line search).
    trial: Vec<f64>,
    start: Vec<f64>,
    /// 1/λ_max of each node's tangential block of W (block Gauss–Seidel's tangential step).
    r_t: Vec<f64>,
    /// The last solved point of the continuation (the rescue, module header).
    best: Vec<f64>,
    /// Newton steps and sweeps per stage of the last solve.
    stages: Stages,
}

/// What the last [`FrictionalContact::solve`] spent in each stage (module header): Newton steps
/// of the primary Newton, of Tresca's closure and of the continuation in the bound, block
/// Gauss–Seidel sweeps, and Newton steps of the polish that ends the Gauss–Seidel stage. Every
/// stage that was tried counts; a stage that failed counts its whole budget.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stages {
    pub newton: usize,
    pub closure: usize,
    pub continuation: usize,
    pub gauss_seidel: usize,
    pub polish: usize,
}

impl Stages {
    /// The sum over the stages (the `iterations` a run reports for the step).
    pub fn total(&self) -> usize {
        self.newton + self.closure + self.continuation + self.gauss_seidel + self.polish
    }

    /// The run record's three stage columns: the primary Newton with Tresca's closure, the
    /// continuation, Gauss–Seidel with its polish.
    pub fn columns(&self) -> [usize; 3] {
        [
            self.newton + self.closure,
            self.continuation,
            self.gauss_seidel + self.polish,
        ]
    }

    /// Whether a stage beyond the primary Newton (and Tresca's closure) was needed.
    pub fn rescued(&self) -> bool {
        self.continuation + self.gauss_seidel + self.polish > 0
    }
}

const NONE: usize = usize::MAX;

/// What a Tresca node's Newton step adds to its [`NodeState`] (the closure of the bound,
/// module header): its normal row is f_n = 0 while the tangential force is still active
/// (`free`), and its bound is b̂ = |f_t| + f_n − r·gap, linearised with |f_t| ≈ t_fᵀ f_t
/// (`graze`: t_f, in 2D t_f[0] = ±1), rather than a constant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Extra {
    free: bool,
    graze: Option<[f64; 2]>,
}

impl FrictionalContact {
    /// The problem of `m` nodes in dimension `d` (2 or 3) with W (dm × dm, row-major, node-major:
    /// row i·d is node i's normal, rows i·d + 1 … its tangential directions).
    pub fn new(m: usize, d: usize, w: Vec<f64>) -> Self {
        assert!(d == 2 || d == 3, "d = 2 or 3");
        let n = m * d;
        assert_eq!(w.len(), n * n, "W must be dm × dm");
        let r = (0..m)
            .map(|i| {
                let wnn = w[i * d * n + i * d];
                if wnn > 0.0 { 1.0 / wnn } else { f64::NAN }
            })
            .collect();
        FrictionalContact {
            m,
            d,
            r,
            y: vec![0.0; n],
            state: vec![NodeState::Open; m],
            extra: vec![Extra::default(); m],
            col: vec![NONE; n],
            unk: vec![0; n],
            elim: vec![0; m],
            n_elim: 0,
            sub_at: vec![[0; 3]; m],
            sub_coef: vec![[0.0; 3]; m],
            mat: vec![0.0; n * n],
            rhs: vec![0.0; n],
            row: vec![0.0; n],
            piv: vec![0; n],
            piv_inv: vec![0; n],
            lu_blocked: false,
            scratch: LuScratch::new(n),
            lu_state: vec![NodeState::Open; m],
            lu_extra: vec![Extra::default(); m],
            lu_slope: 0.0,
            lu_k: 0,
            lu_valid: false,
            lu_chord: false,
            residual_form: false,
            k: 0,
            closure: false,
            warm: vec![0.0; n],
            trial: vec![0.0; n],
            start: vec![0.0; n],
            r_t: (0..m).map(|i| tangential_step(&w, m, d, i)).collect(),
            best: vec![0.0; n],
            stages: Stages::default(),
            w,
        }
    }

    /// The stages of the last solve.
    pub fn stages(&self) -> Stages {
        self.stages
    }

    /// Nodes.
    pub fn nodes(&self) -> usize {
        self.m
    }

    /// Rows per node (the dimension).
    pub fn dim(&self) -> usize {
        self.d
    }

    /// W (row-major).
    pub fn w(&self) -> &[f64] {
        &self.w
    }

    /// Solve for the free gaps `q_n` (m) and slips `q_t` (m(d−1), node-major). `weights`: each
    /// node's ∫_ΓC φ_i (Tresca's bound s·w_i; unread otherwise). `active`: the nodes allowed to
    /// carry force (None: all). `forces` (m·d, node-major [f_n, f_t…]): warm start in, solution
    /// out. Returns the Newton steps made (dense solves); 0 if the warm start solves it.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        law: &FrictionLaw,
        weights: &[f64],
        q_n: &[f64],
        q_t: &[f64],
        active: Option<&[bool]>,
        forces: &mut [f64],
        max_iter: usize,
        tol: f64,
    ) -> Result<usize, FrictionalContactError> {
        let (m, d) = (self.m, self.d);
        let n = m * d;
        assert_eq!(q_n.len(), m, "one gap per node");
        assert_eq!(q_t.len(), m * (d - 1), "d − 1 slips per node");
        assert_eq!(forces.len(), n, "d forces per node");
        if let Some(a) = active {
            assert_eq!(a.len(), m, "one flag per node");
        }
        let kept = |i: usize| active.is_none_or(|a| a[i]);
        for i in 0..m {
            if !kept(i) {
                continue;
            }
            if !self.r[i].is_finite() {
                return Err(FrictionalContactError::NonPositive {
                    node: i,
                    w_nn: self.w[i * d * n + i * d],
                });
            }
            if !q_n[i].is_finite()
                || q_t[i * (d - 1)..(i + 1) * (d - 1)]
                    .iter()
                    .any(|x| !x.is_finite())
            {
                return Err(FrictionalContactError::NonFinite);
            }
        }
        // Force scale: the forces that close the free gaps and slips one node at a time.
        let mut scale = f64::MIN_POSITIVE;
        for i in (0..m).filter(|&i| kept(i)) {
            scale = scale.max(self.r[i] * q_n[i].abs());
            for c in 0..d - 1 {
                scale = scale.max(self.r[i] * q_t[i * (d - 1) + c].abs());
            }
        }
        for i in (0..m).filter(|&i| !kept(i)) {
            forces[i * d..(i + 1) * d].iter_mut().for_each(|x| *x = 0.0);
        }
        let p = Problem {
            weights,
            q_n,
            q_t,
            kept: &kept,
            max_iter,
            tol,
            scale,
        };
        let tresca = matches!(*law, FrictionLaw::Tresca { threshold } if threshold > 0.0);
        self.closure = false;
        self.stages = Stages::default();
        self.warm.copy_from_slice(forces);
        let e = match self.newton(law, &p, forces) {
            Ok(it) => {
                self.stages.newton = it;
                return Ok(it);
            }
            Err(
                e @ (FrictionalContactError::NoConvergence { .. }
                | FrictionalContactError::Singular),
            ) => e,
            Err(e) => return Err(e),
        };
        self.stages.newton = max_iter;
        if tresca && matches!(e, FrictionalContactError::NoConvergence { .. }) {
            // Tresca's closure (module header): from the warm start, then from zero.
            self.closure = true;
            for cold in [false, true] {
                if cold {
                    forces.iter_mut().for_each(|x| *x = 0.0);
                } else {
                    forces.copy_from_slice(&self.warm);
                }
                match self.newton(law, &p, forces) {
                    Ok(it) => {
                        self.closure = false;
                        self.stages.closure = it + max_iter * usize::from(cold);
                        return Ok(it + max_iter * (1 + usize::from(cold)));
                    }
                    Err(
                        FrictionalContactError::NoConvergence { .. }
                        | FrictionalContactError::Singular,
                    ) => self.stages.closure += max_iter,
                    Err(e) => {
                        self.closure = false;
                        return Err(e);
                    }
                }
            }
        }
        // The rescue (module header): continuation in the bound, then block Gauss–Seidel.
        let r = self.rescue(law, &p, forces);
        self.closure = false;
        r.map(|_| self.stages.total())
    }

    /// The damped semismooth Newton iteration from `forces` (the law's form as `closure`
    /// says), to `tol` relative to max(`scale`, |f|).
    fn newton(
        &mut self,
        law: &FrictionLaw,
        p: &Problem,
        forces: &mut [f64],
    ) -> Result<usize, FrictionalContactError> {
        let (max_iter, tol, scale) = (p.max_iter, p.tol, p.scale);
        let eps_scale = |f: &[f64]| f.iter().fold(scale, |s, x| s.max(x.abs()));
        let (mut residual, mut merit) = self.states_and_residual(law, p, forces);
        for it in 0..=max_iter {
            if !residual.is_finite() {
                return Err(FrictionalContactError::NonFinite);
            }
            if residual <= tol * eps_scale(forces) {
                return Ok(it);
            }
            if it == max_iter {
                break;
            }
            // The Newton point into `trial`, then the damped step f + α(trial − f): the first
            // α = 1, ½, ¼, … that decreases ‖Φ‖² (a plain active-set iteration can cycle on a
            // coupled Coulomb problem); if none does, the full step.
            self.trial.copy_from_slice(forces);
            if self.newton_step(law, p.weights, p.q_n, p.q_t, true)? {
                // A chord step (module header): taken whole where it contracts ‖Φ‖ at least
                // 1/CHORD_RATE-fold, else replaced by a Newton step on a fresh factor.
                let trial = std::mem::take(&mut self.trial);
                let (r, mr) = self.states_and_residual(law, p, &trial);
                self.trial = trial;
                if mr <= CHORD_RATE * CHORD_RATE * merit {
                    forces.copy_from_slice(&self.trial);
                    (residual, merit) = (r, mr);
                    continue;
                }
                self.states_and_residual(law, p, forces);
                self.trial.copy_from_slice(forces);
                self.newton_step(law, p.weights, p.q_n, p.q_t, false)?;
            }
            self.start.copy_from_slice(forces);
            let mut alpha = 1.0;
            loop {
                for ((f, s), t) in forces.iter_mut().zip(&self.start).zip(&self.trial) {
                    *f = s + alpha * (t - s);
                }
                let (r, mr) = self.states_and_residual(law, p, forces);
                if mr <= (1.0 - 1e-4 * alpha) * merit || alpha < 1e-3 {
                    if alpha < 1e-3 && mr > merit {
                        forces.copy_from_slice(&self.trial);
                        (residual, merit) = self.states_and_residual(law, p, forces);
                    } else {
                        (residual, merit) = (r, mr);
                    }
                    break;
                }
                alpha *= 0.5;
            }
        }
        Err(FrictionalContactError::NoConvergence {
            iterations: max_iter,
            residual: residual / eps_scale(forces),
        })
    }

    /// gap and slip of `f` into `y`, each node's state for the next Newton step, and the
    /// natural residual ‖Φ(f)‖_∞.
    fn states_and_residual(&mut self, law: &FrictionLaw, p: &Problem, f: &[f64]) -> (f64, f64) {
        let Problem {
            weights,
            q_n,
            q_t,
            kept,
            ..
        } = *p;
        let (m, d) = (self.m, self.d);
        w_times(&self.w, f, &mut self.y);
        for (k, yk) in self.y.iter_mut().enumerate() {
            let (i, c) = (k / d, k % d);
            let q = if c == 0 {
                q_n[i]
            } else {
                q_t[i * (d - 1) + c - 1]
            };
            *yk += q;
        }
        let (mut res, mut sq) = (0.0f64, 0.0);
        for i in 0..m {
            let fi = &f[i * d..(i + 1) * d];
            self.extra[i] = Extra::default();
            if !kept(i) {
                self.state[i] = NodeState::Open;
                continue;
            }
            let r = self.r[i];
            let aug = fi[0] - r * self.y[i * d];
            let phi = fi[0] - aug.max(0.0);
            res = res.max(phi.abs());
            sq += phi * phi;
            let (slope, offset) = bound_affine(law, weights, i);
            // Tresca's bound is the closure b̂ = proj_[0, s·w](|f_t| + aug) (module header);
            // `interior`: strictly between, where b̂ moves with f.
            let mut interior = false;
            let mut nft = 0.0;
            let b = if self.closure && slope == 0.0 && offset > 0.0 {
                nft = fi[1..d].iter().map(|v| v * v).sum::<f64>().sqrt();
                let raw = nft + aug;
                if raw >= offset {
                    offset
                } else if raw > 0.0 {
                    interior = true;
                    raw
                } else {
                    0.0
                }
            } else if aug > 0.0 {
                slope * aug + offset
            } else {
                0.0
            };
            // x = f_t − r slip, its norm.
            let mut x = [0.0; 2];
            let mut nx = 0.0;
            for c in 0..d - 1 {
                x[c] = fi[1 + c] - r * self.y[i * d + 1 + c];
                nx += x[c] * x[c];
            }
            let nx = nx.sqrt();
            // Φ_t = f_t − proj_B(b)(x).
            let shrink = if nx > b { b / nx } else { 1.0 };
            for c in 0..d - 1 {
                let phi = fi[1 + c] - shrink * x[c];
                res = res.max(phi.abs());
                sq += phi * phi;
            }
            self.state[i] = if aug <= 0.0 && b == 0.0 {
                NodeState::Open
            } else if nx <= b && b > 0.0 {
                NodeState::Stick
            } else if d == 2 {
                NodeState::Slip2 {
                    sigma: if x[0] >= 0.0 { 1.0 } else { -1.0 },
                }
            } else if nx > 0.0 {
                NodeState::Slip3 {
                    t: [x[0] / nx, x[1] / nx],
                    alpha: b / nx,
                }
            } else {
                // b = 0 and x = 0: no tangential force, any direction.
                NodeState::Slip3 {
                    t: [1.0, 0.0],
                    alpha: 0.0,
                }
            };
            // Only Tresca's closure reaches these: a tangential force on an open normal row
            // (b̂ > 0 with aug ≤ 0), a slipping node whose bound moves with f. t_f = f_t/|f_t|,
            // or the slip direction where f_t = 0 (a consistent choice: |f_t|'s generalised
            // gradient holds it).
            let free = aug <= 0.0 && self.state[i] != NodeState::Open;
            let graze = match self.state[i] {
                NodeState::Slip2 { sigma } if interior => {
                    Some([if nft > 0.0 { fi[1].signum() } else { sigma }, 0.0])
                }
                NodeState::Slip3 { t, .. } if interior => Some(if nft > 0.0 {
                    [fi[1] / nft, fi[2] / nft]
                } else {
                    t
                }),
                _ => None,
            };
            self.extra[i] = Extra { free, graze };
        }
        (res, sq)
    }

    /// One Newton (active-set) step from the states of [`Self::states_and_residual`]: the
    /// linear system on the closed nodes' unknowns, solved into `trial` (the iterate on entry).
    /// With `chord_ok`, a 3D step whose node kinds are those of the kept LU is a chord step on
    /// it (returns true).
    fn newton_step(
        &mut self,
        law: &FrictionLaw,
        weights: &[f64],
        q_n: &[f64],
        q_t: &[f64],
        chord_ok: bool,
    ) -> Result<bool, FrictionalContactError> {
        let slope = match *law {
            FrictionLaw::Coulomb { coefficient } => coefficient,
            _ => 0.0,
        };
        let k = self.number_unknowns();
        let has_slip3 = self
            .state
            .iter()
            .any(|s| matches!(s, NodeState::Slip3 { .. }));
        let has_graze = self.extra.iter().any(|x| x.graze.is_some());
        let reuse = self.lu_valid
            && !has_slip3
            && !has_graze
            && self.lu_slope == slope
            && self.lu_k == k
            && self.lu_state == self.state
            && self.lu_extra == self.extra;
        let chord = !reuse
            && chord_ok
            && self.lu_chord
            && !has_graze
            && self.lu_slope == slope
            && self.lu_k == k
            && self.lu_extra == self.extra
            && self
                .state
                .iter()
                .zip(&self.lu_state)
                .all(|(a, b)| same_kind(a, b));
        self.residual_form = chord;
        self.assemble_rows(law, weights, q_n, q_t, slope, reuse || chord);
        self.residual_form = false;
        if !reuse && !chord {
            self.lu_valid = false;
            self.lu_chord = false;
            // The systems the 3D slip elimination makes (module header, the LU) on faer's
            // blocked LU; the others on the hand loop, whose bits they keep.
            self.lu_blocked = self.d == 3 && self.n_elim > 0;
            let (a, piv) = (&mut self.mat[..k * k], &mut self.piv[..k]);
            if self.lu_blocked {
                blocked_factor(a, k, piv, &mut self.piv_inv[..k], &mut self.scratch)?;
            } else {
                lu_factor(a, k, piv)?;
            }
            self.lu_state.copy_from_slice(&self.state);
            self.lu_slope = slope;
            self.lu_k = k;
            self.lu_extra.copy_from_slice(&self.extra);
            self.lu_valid = !has_slip3 && !has_graze;
            self.lu_chord = self.d == 3 && !has_graze;
        }
        let (a, piv, b) = (&self.mat[..k * k], &self.piv[..k], &mut self.rhs[..k]);
        if self.lu_blocked {
            blocked_solve(a, piv, &self.piv_inv[..k], b, &mut self.scratch);
        } else {
            lu_solve(a, k, piv, b);
        }
        if chord {
            // The correction δ = −J_old⁻¹ (J f − rhs) onto the iterate's unknowns.
            for (j, &c) in self.col.iter().enumerate() {
                if c != NONE {
                    self.rhs[c] += self.trial[j];
                }
            }
        }
        self.write_trial(law, weights, slope);
        Ok(chord)
    }

    /// Unknowns: f_n of every closed node, f_t but for a slipping node's eliminated component
    /// ([`eliminated`]); their indices into `col`, the components into `unk`, the slipping
    /// nodes into `elim`, their number into `k` (returned).
    fn number_unknowns(&mut self) -> usize {
        let (m, d) = (self.m, self.d);
        let (mut k, mut ne) = (0, 0);
        for i in 0..m {
            let gone = eliminated(&self.state[i], &self.extra[i]);
            if gone.is_some() {
                self.elim[ne] = i;
                ne += 1;
            }
            for c in 0..d {
                let j = i * d + c;
                self.col[j] = if self.state[i] == NodeState::Open || gone == Some(c) {
                    NONE
                } else {
                    self.unk[k] = j;
                    k += 1;
                    k - 1
                };
            }
        }
        self.k = k;
        self.n_elim = ne;
        k
    }

    /// The rows of the Newton system, one per unknown, node by node (the normal row, then
    /// the tangential ones of the node's state): each equation built over the full f
    /// (coefficients into `row`), then reduced through the unknowns and eliminations.
    fn assemble_rows(
        &mut self,
        law: &FrictionLaw,
        weights: &[f64],
        q_n: &[f64],
        q_t: &[f64],
        slope: f64,
        reuse: bool,
    ) {
        self.substitutions(law, weights, slope);
        let (m, d) = (self.m, self.d);
        let n = m * d;
        let mut e = 0;
        for i in 0..m {
            let st = self.state[i];
            if st == NodeState::Open {
                continue;
            }
            let (_, offset) = bound_affine(law, weights, i);
            let Extra { free, graze } = self.extra[i];
            // Normal: gap = 0, or f_n = 0 on Tresca's open normal row.
            let rhs = if free {
                self.row.iter_mut().for_each(|x| *x = 0.0);
                self.row[i * d] = 1.0;
                0.0
            } else {
                self.row
                    .copy_from_slice(&self.w[i * d * n..(i * d + 1) * n]);
                -q_n[i]
            };
            self.reduce_row(e, rhs, reuse);
            e += 1;
            match st {
                NodeState::Open => unreachable!(),
                NodeState::Slip2 { sigma } if let Some(tf) = graze => {
                    // f_t = σ b̂, b̂ = τ_f f_t + f_n − r (q_n + W_n f).
                    let r = self.r[i];
                    for (x, wv) in self.row.iter_mut().zip(&self.w[i * d * n..(i * d + 1) * n]) {
                        *x = sigma * r * wv;
                    }
                    self.row[i * d] -= sigma;
                    self.row[i * d + 1] += 1.0 - sigma * tf[0];
                    let rhs = -sigma * r * q_n[i];
                    self.reduce_row(e, rhs, reuse);
                    e += 1;
                }
                NodeState::Stick => {
                    for c in 1..d {
                        let r0 = (i * d + c) * n;
                        self.row.copy_from_slice(&self.w[r0..r0 + n]);
                        let rhs = -q_t[i * (d - 1) + c - 1];
                        self.reduce_row(e, rhs, reuse);
                        e += 1;
                    }
                }
                NodeState::Slip2 { .. } => {}
                NodeState::Slip3 { t, alpha } if graze.is_none() => {
                    // The disc's rows projected on s ⊥ t (module header, 3D slip): one row.
                    let rhs = self.slip_row(i, t, alpha, q_t);
                    self.reduce_row(e, rhs, reuse);
                    e += 1;
                }
                // Tresca's closure (graze): both rows, with b̂ linearised.
                NodeState::Slip3 { t, alpha } => {
                    let r = self.r[i];
                    let p = [
                        [1.0 - t[0] * t[0], -t[0] * t[1]],
                        [-t[1] * t[0], 1.0 - t[1] * t[1]],
                    ];
                    for a in 0..2 {
                        // (I − αP) f_t − μ t f_n + α r P W_t f = offset t − α r P q_t.
                        let row = &mut self.row;
                        row.iter_mut().for_each(|x| *x = 0.0);
                        let mut rhs = offset * t[a];
                        for b in 0..2 {
                            let coef = alpha * r * p[a][b];
                            if coef != 0.0 {
                                let r0 = (i * d + 1 + b) * n;
                                for (x, wv) in row.iter_mut().zip(&self.w[r0..r0 + n]) {
                                    *x += coef * wv;
                                }
                            }
                            rhs -= coef * q_t[i * 2 + b];
                            row[i * d + 1 + b] += f64::from(u8::from(a == b)) - alpha * p[a][b];
                        }
                        if let Some(tf) = graze {
                            // The bound b̂ = t_fᵀ f_t + f_n − r (q_n + W_n f) in place of
                            // offset: −t_a b̂ moves to the left.
                            rhs = -coef_rq(alpha, r, &p[a], q_t, i) - t[a] * r * q_n[i];
                            let r0 = i * d * n;
                            for (x, wv) in row.iter_mut().zip(&self.w[r0..r0 + n]) {
                                *x += t[a] * r * wv;
                            }
                            row[i * d] -= t[a];
                            row[i * d + 1] -= t[a] * tf[0];
                            row[i * d + 2] -= t[a] * tf[1];
                        } else {
                            row[i * d] -= slope * t[a];
                        }
                        self.reduce_row(e, rhs, reuse);
                        e += 1;
                    }
                }
            }
        }
        debug_assert_eq!(e, self.k);
    }

    /// The forces of the solved system into `trial`: open nodes 0, a 2D slipping node's f_t
    /// from its f_n, a 3D one's eliminated component from its other forces ([`eliminated`]),
    /// every other force its unknown.
    fn write_trial(&mut self, law: &FrictionLaw, weights: &[f64], slope: f64) {
        let (m, d) = (self.m, self.d);
        let f = &mut self.trial;
        for i in 0..m {
            match self.state[i] {
                NodeState::Open => f[i * d..(i + 1) * d].iter_mut().for_each(|x| *x = 0.0),
                NodeState::Slip2 { sigma } if self.col[i * d + 1] == NONE => {
                    let (_, offset) = bound_affine(law, weights, i);
                    let fnn = self.rhs[self.col[i * d]];
                    f[i * d] = fnn;
                    f[i * d + 1] = sigma * (slope * fnn + offset);
                }
                NodeState::Slip3 { t, .. } if self.extra[i].graze.is_none() => {
                    let (a, b) = slip_axes(&t);
                    let (fnn, fb) = (self.rhs[self.col[i * d]], self.rhs[self.col[i * d + 1 + b]]);
                    let e = self.elim[..self.n_elim].partition_point(|&x| x < i);
                    let [c_n, c_b, c_0] = self.sub_coef[e];
                    f[i * d] = fnn;
                    f[i * d + 1 + b] = fb;
                    f[i * d + 1 + a] = c_n * fnn + c_b * fb + c_0;
                }
                _ => {
                    for c in 0..d {
                        f[i * d + c] = self.rhs[self.col[i * d + c]];
                    }
                }
            }
        }
    }

    /// Reduce the full equation `row`·f = `rhs` into row `e` of the system: unknowns keep their
    /// coefficient (gathered through `unk`), open nodes' forces are 0, a slipping node's
    /// eliminated f_t is substituted (2D: f_t = σ(μ_f f_n + offset); 3D: [`eliminated`]).
    /// With `reuse` only the right-hand side is made; with `residual_form` it is the residual
    /// at `trial` (a chord step).
    fn reduce_row(&mut self, e: usize, mut rhs: f64, reuse: bool) {
        let k = self.k;
        let (row, unk, trial) = (&self.row, &self.unk[..k], &self.trial);
        let mat = &mut self.mat[e * k..(e + 1) * k];
        if !reuse {
            mat.iter_mut().for_each(|x| *x = 0.0);
            for (x, &j) in mat.iter_mut().zip(unk) {
                *x += row[j];
            }
        }
        if self.residual_form {
            for &j in unk {
                rhs -= row[j] * trial[j];
            }
        }
        let subs = self.sub_at[..self.n_elim].iter().zip(&self.sub_coef);
        for (&[ja, cn, cb], &[c_n, c_b, c_0]) in subs {
            let ct = row[ja];
            rhs -= ct * c_0;
            if !reuse {
                mat[cn] += ct * c_n;
                if cb != NONE {
                    mat[cb] += ct * c_b;
                }
            }
            if self.residual_form && cb != NONE {
                rhs -= ct * (c_n * trial[self.unk[cn]] + c_b * trial[self.unk[cb]]);
            }
        }
        self.rhs[e] = rhs;
    }

    /// The substitutions of the step's eliminated forces (module header), once per assembly
    /// rather than per row: 2D f_t = σ μ_f f_n + σ offset, 3D f_t,a = (μ_f f_n + offset −
    /// t_b f_t,b)/t_a. (σ = ±1: ct·(σ x) is ct·σ·x to the bit.)
    fn substitutions(&mut self, law: &FrictionLaw, weights: &[f64], slope: f64) {
        let d = self.d;
        for (e, &i) in self.elim[..self.n_elim].iter().enumerate() {
            let (_, off) = bound_affine(law, weights, i);
            let cn = self.col[i * d];
            (self.sub_at[e], self.sub_coef[e]) = match self.state[i] {
                NodeState::Slip2 { sigma } => {
                    ([i * d + 1, cn, NONE], [sigma * slope, 0.0, sigma * off])
                }
                NodeState::Slip3 { t, .. } => {
                    let (a, b) = slip_axes(&t);
                    let at = [i * d + 1 + a, cn, self.col[i * d + 1 + b]];
                    (at, [slope / t[a], -t[b] / t[a], off / t[a]])
                }
                _ => unreachable!("`elim` holds slipping nodes"),
            };
        }
    }

    /// A 3D slipping node's Newton row along s = (−t_1, t_0) ⊥ t (module header): with
    /// sᵀP = sᵀ, sᵀ(the two rows) is (1 − α) sᵀf_t + α r sᵀ W_t f = −α r sᵀq_t; its
    /// coefficients over the full f into `row`, the right-hand side returned.
    fn slip_row(&mut self, i: usize, t: [f64; 2], alpha: f64, q_t: &[f64]) -> f64 {
        let (m, d) = (self.m, self.d);
        let n = m * d;
        let r = self.r[i];
        let s = [-t[1], t[0]];
        let row = &mut self.row;
        row.iter_mut().for_each(|x| *x = 0.0);
        let mut rhs = 0.0;
        for b in 0..2 {
            let coef = alpha * r * s[b];
            if coef != 0.0 {
                let r0 = (i * d + 1 + b) * n;
                for (x, wv) in row.iter_mut().zip(&self.w[r0..r0 + n]) {
                    *x += coef * wv;
                }
            }
            rhs -= coef * q_t[i * 2 + b];
            row[i * d + 1 + b] += (1.0 - alpha) * s[b];
        }
        rhs
    }
}

/// A chord step (module header) is kept where it divides ‖Φ‖ by at least 1/CHORD_RATE: a
/// digit per step, so that a slowly contracting chord does not outlast the Newton steps.
const CHORD_RATE: f64 = 0.1;

/// The continuation's first step in the bound's factor θ (then doubled after each success,
/// halved after each failure) and its smallest step before it gives up.
const CONTINUATION_STEP: f64 = 0.125;
const CONTINUATION_MIN_STEP: f64 = 1.0 / 1024.0;
/// Block Gauss–Seidel: sweeps at most per Newton step allowed (40 × 100 = 4 000 sweeps at the
/// engines' budget; none with a budget of 0, which stays an error), local projections per node
/// and sweep, and the sweeps between two Newton polishes.
const GS_SWEEPS_PER_STEP: usize = 40;
const GS_LOCAL: usize = 8;
const GS_POLISH_EVERY: usize = 100;

impl FrictionalContact {
    /// The rescue of a step the primary Newton (and Tresca's closure) did not solve (module
    /// header): Newton continued in the bound's factor θ from the frictionless problem (θ = 0)
    /// to the law (θ = 1), with an adaptive step; then projected block Gauss–Seidel on the law
    /// itself from the last point solved, polished by Newton. Each stage stops at the same
    /// natural residual `tol` as the primary Newton.
    fn rescue(
        &mut self,
        law: &FrictionLaw,
        p: &Problem,
        forces: &mut [f64],
    ) -> Result<(), FrictionalContactError> {
        // Tresca is continued and relaxed in its closure (the literal law's solutions are the
        // closure's too; the closure has one where the law has none).
        self.closure = matches!(*law, FrictionLaw::Tresca { threshold } if threshold > 0.0);
        forces.iter_mut().for_each(|x| *x = 0.0);
        let max_iter = p.max_iter;
        let (mut solved, mut step) = (None::<f64>, CONTINUATION_STEP);
        loop {
            let theta = solved.map_or(0.0, |t| (t + step).min(1.0));
            let scaled = scaled_law(law, theta);
            match self.newton(&scaled, p, forces) {
                Ok(it) => {
                    self.stages.continuation += it;
                    if theta == 1.0 {
                        return Ok(());
                    }
                    self.best.copy_from_slice(forces);
                    solved = Some(theta);
                    step = (2.0 * step).min(0.5);
                }
                Err(
                    FrictionalContactError::NoConvergence { .. } | FrictionalContactError::Singular,
                ) => {
                    self.stages.continuation += max_iter;
                    step *= 0.5;
                    if solved.is_none() || step < CONTINUATION_MIN_STEP {
                        break;
                    }
                    forces.copy_from_slice(&self.best);
                }
                Err(e) => return Err(e),
            }
        }
        if solved.is_some() {
            forces.copy_from_slice(&self.best);
        } else {
            forces.copy_from_slice(&self.warm);
        }
        self.gauss_seidel(law, p, forces)
    }

    /// Projected block Gauss–Seidel on the law (module header): node by node, the others held,
    /// [`GS_LOCAL`] projections f_n ← [f_n − r y_n]₊, f_t ← proj_B(b)(f_t − r_t y_t) with y the
    /// node's gap and slip kept current; every [`GS_POLISH_EVERY`] sweeps a Newton polish from
    /// a copy. Converged when the natural residual meets `tol` (as Newton's).
    fn gauss_seidel(
        &mut self,
        law: &FrictionLaw,
        p: &Problem,
        forces: &mut [f64],
    ) -> Result<(), FrictionalContactError> {
        let Problem {
            weights,
            kept,
            max_iter,
            tol,
            scale,
            ..
        } = *p;
        let eps_scale = |f: &[f64]| f.iter().fold(scale, |s, x| s.max(x.abs()));
        let mut residual = f64::INFINITY;
        for sweep in 1..=GS_SWEEPS_PER_STEP * max_iter {
            // y = q + W f afresh each sweep (no drift of the incremental updates).
            self.states_and_residual(law, p, forces);
            for i in (0..self.m).filter(|&i| kept(i)) {
                for _ in 0..GS_LOCAL {
                    if !self.relax_node(law, weights, i, forces) {
                        break;
                    }
                }
            }
            self.stages.gauss_seidel = sweep;
            (residual, _) = self.states_and_residual(law, p, forces);
            if !residual.is_finite() {
                return Err(FrictionalContactError::NonFinite);
            }
            if residual <= tol * eps_scale(forces) {
                return Ok(());
            }
            if sweep % GS_POLISH_EVERY == 0 {
                self.best.copy_from_slice(forces);
                match self.newton(law, p, forces) {
                    Ok(it) => {
                        self.stages.polish += it;
                        return Ok(());
                    }
                    Err(
                        FrictionalContactError::NoConvergence { .. }
                        | FrictionalContactError::Singular,
                    ) => {
                        self.stages.polish += max_iter;
                        forces.copy_from_slice(&self.best);
                    }
                    Err(e) => return Err(e),
                }
            }
        }
        Err(FrictionalContactError::NoConvergence {
            iterations: self.stages.total(),
            residual: residual / eps_scale(forces),
        })
    }

    /// One local projection of node `i` (the others held), `y` kept equal to q + W f; returns
    /// whether the node's forces changed.
    fn relax_node(&mut self, law: &FrictionLaw, weights: &[f64], i: usize, f: &mut [f64]) -> bool {
        let (m, d) = (self.m, self.d);
        let n = m * d;
        let (r, rt) = (self.r[i], self.r_t[i]);
        let old = [
            f[i * d],
            f[i * d + 1],
            if d == 3 { f[i * d + 2] } else { 0.0 },
        ];
        let aug = old[0] - r * self.y[i * d];
        let f_n = aug.max(0.0);
        let (slope, offset) = bound_affine(law, weights, i);
        let b = if self.closure && slope == 0.0 && offset > 0.0 {
            // Tresca's closure: b̂ = proj_[0, s·w](|f_t| + aug).
            let nft = old[1..d].iter().map(|v| v * v).sum::<f64>().sqrt();
            (nft + aug).clamp(0.0, offset)
        } else if aug > 0.0 {
            slope * f_n + offset
        } else {
            0.0
        };
        let mut x = [0.0; 2];
        for c in 0..d - 1 {
            x[c] = old[1 + c] - rt * self.y[i * d + 1 + c];
        }
        let nx = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let shrink = if nx > b { b / nx } else { 1.0 };
        let new = [f_n, shrink * x[0], shrink * x[1]];
        let mut changed = false;
        for c in 0..d {
            let delta = new[c] - old[c];
            if delta != 0.0 {
                changed = true;
                f[i * d + c] = new[c];
                // y += W[:, (i, c)] δ.
                let col = i * d + c;
                for (k, yk) in self.y.iter_mut().enumerate() {
                    *yk += self.w[k * n + col] * delta;
                }
            }
        }
        changed
    }
}

/// The law with its bound scaled by θ ∈ [0, 1] (the continuation's homotopy).
fn scaled_law(law: &FrictionLaw, theta: f64) -> FrictionLaw {
    match *law {
        FrictionLaw::None => FrictionLaw::None,
        FrictionLaw::Coulomb { coefficient } => FrictionLaw::Coulomb {
            coefficient: theta * coefficient,
        },
        FrictionLaw::Tresca { threshold } => FrictionLaw::Tresca {
            threshold: theta * threshold,
        },
    }
}

/// 1/λ_max of node i's tangential block of W (d − 1 square; symmetric part in 3D): the step
/// of its projected tangential relaxation, a contraction on the block.
fn tangential_step(w: &[f64], m: usize, d: usize, i: usize) -> f64 {
    let n = m * d;
    let at = |a: usize, b: usize| w[(i * d + a) * n + i * d + b];
    let lmax = if d == 2 {
        at(1, 1)
    } else {
        let (a, c) = (at(1, 1), at(2, 2));
        let b = 0.5 * (at(1, 2) + at(2, 1));
        0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt()
    };
    if lmax > 0.0 { 1.0 / lmax } else { 0.0 }
}

/// α r (P q_t)_a of node i: the slip's constant part in a 3D slipping node's row a.
fn coef_rq(alpha: f64, r: f64, p_a: &[f64; 2], q_t: &[f64], i: usize) -> f64 {
    alpha * r * (p_a[0] * q_t[i * 2] + p_a[1] * q_t[i * 2 + 1])
}

/// The tangential component a slipping node's Newton step eliminates, if any (module header):
/// in 2D its f_t = σ(μ_f f_n + offset); in 3D the component a of the larger |t_a| (slip_axes),
/// by the row along t, tᵀf_t − μ_f f_n = offset (tᵀP = 0). Not under Tresca's graze, whose
/// bound moves with f_t. Some(c): force component c of the node.
fn eliminated(state: &NodeState, extra: &Extra) -> Option<usize> {
    match state {
        _ if extra.graze.is_some() => None,
        NodeState::Slip2 { .. } => Some(1),
        NodeState::Slip3 { t, .. } => Some(1 + slip_axes(t).0),
        _ => None,
    }
}

/// (a, b): the tangential axis a of the larger |t_a| (|t_a| ≥ 1/√2, the eliminated one) and
/// the other.
fn slip_axes(t: &[f64; 2]) -> (usize, usize) {
    if t[0].abs() >= t[1].abs() {
        (0, 1)
    } else {
        (1, 0)
    }
}

/// Whether a chord step may use an LU made at state `b` for state `a`: the same kind of node,
/// and for a 3D slipping node the same eliminated axis (the same unknowns).
fn same_kind(a: &NodeState, b: &NodeState) -> bool {
    match (a, b) {
        (NodeState::Slip3 { t: ta, .. }, NodeState::Slip3 { t: tb, .. }) => {
            slip_axes(ta) == slip_axes(tb)
        }
        _ => std::mem::discriminant(a) == std::mem::discriminant(b),
    }
}

/// b = slope·f_n + offset of node i (Tresca's offset s·w_i).
fn bound_affine(law: &FrictionLaw, weights: &[f64], i: usize) -> (f64, f64) {
    match *law {
        FrictionLaw::None => (0.0, 0.0),
        FrictionLaw::Coulomb { coefficient } => (coefficient, 0.0),
        FrictionLaw::Tresca { threshold } => (0.0, threshold * weights[i]),
    }
}

/// y = W f (W row-major, n × n), each y_k summed in column order from −0.0 as `Iterator::sum`
/// does (the same bits), four rows at a time: four independent sums keep the adder busy
/// where one row's chain of dependent additions would wait on each.
fn w_times(w: &[f64], f: &[f64], y: &mut [f64]) {
    let n = f.len();
    let mut blocks = w.chunks_exact(4 * n);
    let mut ys = y.chunks_exact_mut(4);
    for (rows, yb) in (&mut blocks).zip(&mut ys) {
        let (r0, r1, r2, r3) = (
            &rows[..n],
            &rows[n..2 * n],
            &rows[2 * n..3 * n],
            &rows[3 * n..],
        );
        let mut acc = [-0.0f64; 4];
        for j in 0..n {
            let fj = f[j];
            acc[0] += r0[j] * fj;
            acc[1] += r1[j] * fj;
            acc[2] += r2[j] * fj;
            acc[3] += r3[j] * fj;
        }
        yb.copy_from_slice(&acc);
    }
    let rest = blocks.remainder().chunks_exact(n);
    for (yk, row) in ys.into_remainder().iter_mut().zip(rest) {
        *yk = row.iter().zip(f).map(|(a, b)| a * b).sum::<f64>();
    }
}

/// faer's scratch for its blocked LU and solves of at most n unknowns (allocated once; faer's
/// buffer is neither `Clone` nor `Debug`: a clone allocates its own).
struct LuScratch {
    mem: MemBuffer,
    n: usize,
}

impl LuScratch {
    fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            solve::solve_transpose_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        LuScratch {
            mem: MemBuffer::new(req),
            n,
        }
    }
}

impl Clone for LuScratch {
    fn clone(&self) -> Self {
        LuScratch::new(self.n)
    }
}

impl std::fmt::Debug for LuScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LuScratch({})", self.n)
    }
}

/// faer's blocked LU with partial pivoting (recursive, its products on gemm kernels) of the
/// row-major k × k `a` read column-major — of Jᵀ, in faer's preferred layout: Jᵀ = Pᵀ L U,
/// in place, the permutation into `perm` and `perm_inv`.
fn blocked_factor(
    a: &mut [f64],
    k: usize,
    perm: &mut [usize],
    perm_inv: &mut [usize],
    scratch: &mut LuScratch,
) -> Result<(), FrictionalContactError> {
    let jt = MatMut::from_column_major_slice_mut(a, k, k);
    let stack = MemStack::new(&mut scratch.mem);
    factor::lu_in_place(jt, perm, perm_inv, Par::Seq, stack, Default::default());
    // faer does not stop at a zero pivot: U's diagonal says whether J is singular.
    if (0..k).all(|i| a[i * k + i] != 0.0 && a[i * k + i].is_finite()) {
        Ok(())
    } else {
        Err(FrictionalContactError::Singular)
    }
}

/// Solve J x = b with [`blocked_factor`]'s factors of Jᵀ (faer's transposed solve), `b`
/// overwritten by x.
fn blocked_solve(
    a: &[f64],
    perm: &[usize],
    perm_inv: &[usize],
    b: &mut [f64],
    scratch: &mut LuScratch,
) {
    let k = b.len();
    let lu = MatRef::from_column_major_slice(a, k, k);
    let perm = PermRef::new_checked(perm, perm_inv, k);
    let rhs = MatMut::from_column_major_slice_mut(b, k, 1);
    let stack = MemStack::new(&mut scratch.mem);
    solve::solve_transpose_in_place(lu, lu, perm, rhs, Par::Seq, stack);
}

/// In-place LU with partial pivoting of the k × k row-major `a` (L unit lower, U upper).
fn lu_factor(a: &mut [f64], k: usize, piv: &mut [usize]) -> Result<(), FrictionalContactError> {
    for col in 0..k {
        let mut p = col;
        let mut best = a[col * k + col].abs();
        for r in col + 1..k {
            let v = a[r * k + col].abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        // NaN fails this test too.
        if best.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(FrictionalContactError::Singular);
        }
        piv[col] = p;
        if p != col {
            for c in 0..k {
                a.swap(col * k + c, p * k + c);
            }
        }
        let d = a[col * k + col];
        for r in col + 1..k {
            let l = a[r * k + col] / d;
            a[r * k + col] = l;
            if l != 0.0 {
                let (top, bottom) = a.split_at_mut(r * k);
                let prow = &top[col * k + col + 1..col * k + k];
                for (x, y) in bottom[col + 1..k].iter_mut().zip(prow) {
                    *x -= l * y;
                }
            }
        }
    }
    Ok(())
}

/// Solve with the factors of [`lu_factor`], `b` overwritten by the solution.
fn lu_solve(a: &[f64], k: usize, piv: &[usize], b: &mut [f64]) {
    for col in 0..k {
        b.swap(col, piv[col]);
    }
    for r in 0..k {
        let s: f64 = a[r * k..r * k + r]
            .iter()
            .zip(&b[..r])
            .map(|(x, y)| x * y)
            .sum();
        b[r] -= s;
    }
    for r in (0..k).rev() {
        let s: f64 = a[r * k + r + 1..(r + 1) * k]
            .iter()
            .zip(&b[r + 1..k])
            .map(|(x, y)| x * y)
            .sum();
        b[r] = (b[r] - s) / a[r * k + r];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Lcp;
    use crate::contact::friction::{Condensed, solve_point};

    /// xorshift in [0, 1): reproducible draws without a dependency.
    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// W = G Gᵀ/n + δ I with G uniform in [−½, ½]: symmetric positive definite, coupled rows
    /// (as the FE's C A⁻¹ Cᵀ), diagonal O(δ + 1/12).
    fn spd(rng: &mut Rng, n: usize, delta: f64) -> Vec<f64> {
        let g: Vec<f64> = (0..n * n).map(|_| rng.f() - 0.5).collect();
        let mut w = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                w[i * n + j] = (0..n).map(|k| g[i * n + k] * g[j * n + k]).sum::<f64>() / n as f64
                    + if i == j { delta } else { 0.0 };
            }
        }
        w
    }

    /// Check the law at a solution: gap ≥ 0 ⊥ f_n ≥ 0, |f_t| ≤ b, f_t = −b slip/|slip| where
    /// the node slips, to `tol` (forces and gaps here are O(1)).
    #[allow(clippy::too_many_arguments)]
    fn check_law(
        w: &[f64],
        d: usize,
        law: &FrictionLaw,
        weights: &[f64],
        q_n: &[f64],
        q_t: &[f64],
        f: &[f64],
        tol: f64,
    ) -> (usize, usize, usize) {
        let n = f.len();
        let m = n / d;
        let y: Vec<f64> = (0..n)
            .map(|k| {
                let (i, c) = (k / d, k % d);
                let q = if c == 0 {
                    q_n[i]
                } else {
                    q_t[i * (d - 1) + c - 1]
                };
                q + (0..n).map(|j| w[k * n + j] * f[j]).sum::<f64>()
            })
            .collect();
        let (mut open, mut stick, mut slip) = (0, 0, 0);
        let fmax = f.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // Forces up to O(10) where μ_f is small: slack relative to them.
        let tol = tol * (1.0 + fmax);
        for i in 0..m {
            let (fnn, gap) = (f[i * d], y[i * d]);
            assert!(
                fnn >= -tol && gap >= -tol,
                "node {i}: f_n = {fnn}, gap = {gap}"
            );
            assert!(
                (fnn * gap).abs() <= tol,
                "node {i}: complementarity {}",
                fnn * gap
            );
            let ft = &f[i * d + 1..(i + 1) * d];
            let s = &y[i * d + 1..(i + 1) * d];
            let nft = ft.iter().map(|x| x * x).sum::<f64>().sqrt();
            let ns = s.iter().map(|x| x * x).sum::<f64>().sqrt();
            // Tresca's closure (module header): f_n = 0 with gap = 0 is still contact, its
            // bound any b ∈ [0, s·w] — the tangential force's own size.
            let grazing = fnn <= tol && nft > tol;
            if grazing {
                assert!(
                    matches!(law, FrictionLaw::Tresca { .. }) && gap.abs() <= tol,
                    "node {i}: open (gap = {gap}) with |f_t| = {nft}"
                );
            } else if fnn <= tol {
                // Open (Tresca acts only in contact; Coulomb's bound is 0).
                open += 1;
                continue;
            }
            let bound = law.bound(fnn.max(0.0), weights[i]);
            assert!(nft <= bound + tol, "node {i}: |f_t| = {nft} > b = {bound}");
            let b = if grazing { nft } else { bound };
            if ns > tol {
                // The slip's direction is known to the solver's residual over the slip: a
                // residual ε on f gives a direction error ~ε/(r|slip|), so the slack grows as
                // the slip vanishes (measured worst 3.4e-10 at |slip| = 2.8e-3, f = O(5)).
                let dir_tol = tol / ns.min(1.0);
                for c in 0..d - 1 {
                    assert!(
                        (ft[c] + b * s[c] / ns).abs() <= dir_tol,
                        "node {i}: f_t = {ft:?} does not oppose the slip {s:?} (b = {b})"
                    );
                }
                slip += 1;
            } else {
                stick += 1;
            }
        }
        (open, stick, slip)
    }

    /// Every solution of a small 2D problem by enumerating the 4^m node cases (open, stick,
    /// slip ±), each a linear system; admissible ones kept (slack 1e-11 on O(1) data).
    fn enumerate_2d(
        w: &[f64],
        law: &FrictionLaw,
        weights: &[f64],
        q_n: &[f64],
        q_t: &[f64],
    ) -> Vec<Vec<f64>> {
        let m = q_n.len();
        let n = 2 * m;
        let mut found: Vec<Vec<f64>> = Vec::new();
        for code in 0..4usize.pow(m as u32) {
            let cases: Vec<usize> = (0..m).map(|i| (code / 4usize.pow(i as u32)) % 4).collect();
            let mut a = vec![0.0; n * n];
            let mut b = vec![0.0; n];
            for i in 0..m {
                let (slope, offset) = bound_affine(law, weights, i);
                let (rn, rt) = (2 * i, 2 * i + 1);
                match cases[i] {
                    0 => {
                        a[rn * n + rn] = 1.0;
                        a[rt * n + rt] = 1.0;
                    }
                    1 => {
                        a[rn * n..(rn + 1) * n].copy_from_slice(&w[rn * n..(rn + 1) * n]);
                        b[rn] = -q_n[i];
                        a[rt * n..(rt + 1) * n].copy_from_slice(&w[rt * n..(rt + 1) * n]);
                        b[rt] = -q_t[i];
                    }
                    c => {
                        let sigma = if c == 2 { 1.0 } else { -1.0 };
                        a[rn * n..(rn + 1) * n].copy_from_slice(&w[rn * n..(rn + 1) * n]);
                        b[rn] = -q_n[i];
                        a[rt * n + rt] = 1.0;
                        a[rt * n + rn] = -sigma * slope;
                        b[rt] = sigma * offset;
                    }
                }
            }
            let mut piv = vec![0; n];
            if lu_factor(&mut a, n, &mut piv).is_err() {
                continue;
            }
            lu_solve(&a, n, &piv, &mut b);
            let f = b;
            let y: Vec<f64> = (0..n)
                .map(|k| {
                    let q = if k % 2 == 0 { q_n[k / 2] } else { q_t[k / 2] };
                    q + (0..n).map(|j| w[k * n + j] * f[j]).sum::<f64>()
                })
                .collect();
            let tol = 1e-11;
            let ok = (0..m).all(|i| {
                let (fnn, ft, gap, slip) = (f[2 * i], f[2 * i + 1], y[2 * i], y[2 * i + 1]);
                let b = law.bound(fnn, weights[i]);
                match cases[i] {
                    0 => gap >= -tol,
                    1 => fnn >= -tol && ft.abs() <= b + tol,
                    c => {
                        let sigma = if c == 2 { 1.0 } else { -1.0 };
                        fnn >= -tol && -sigma * slip >= -tol
                    }
                }
            });
            if ok
                && !found
                    .iter()
                    .any(|g| g.iter().zip(&f).all(|(x, z)| (x - z).abs() < 1e-9))
            {
                found.push(f);
            }
        }
        found
    }

    /// Small 2D problems against the enumeration of every case: where the problem has a
    /// solution the solver finds one of them (to 1e-10: both stop at round-off on O(1)
    /// data). Where it has none (Tresca's bound vanishes when a node opens, so with coupled
    /// rows a tangential force may open its own node) the solver may return its closure's
    /// grazing solution (module header; the enumeration lists the literal law's cases only):
    /// then the closure's law holds.
    #[test]
    fn small_problems_agree_with_enumeration() {
        let mut rng = Rng(0xdead_beef_cafe_f00d);
        let (mut solved, mut none) = (0, 0);
        for k in 0..300 {
            let m = 1 + k % 4;
            let w = spd(&mut rng, 2 * m, 0.05);
            let law = if k % 2 == 0 {
                FrictionLaw::Coulomb {
                    coefficient: 0.6 * rng.f(),
                }
            } else {
                FrictionLaw::Tresca {
                    threshold: 0.5 * rng.f(),
                }
            };
            let weights: Vec<f64> = (0..m).map(|_| 0.5 + rng.f()).collect();
            let q_n: Vec<f64> = (0..m).map(|_| rng.f() - 0.7).collect();
            let q_t: Vec<f64> = (0..m).map(|_| 0.4 * (rng.f() - 0.5)).collect();
            let all = enumerate_2d(&w, &law, &weights, &q_n, &q_t);
            let mut f = vec![0.0; 2 * m];
            let r = FrictionalContact::new(m, 2, w.clone())
                .solve(&law, &weights, &q_n, &q_t, None, &mut f, 100, 1e-12);
            if all.is_empty() {
                if r.is_ok() {
                    check_law(&w, 2, &law, &weights, &q_n, &q_t, &f, 1e-10);
                }
                none += 1;
            } else {
                r.unwrap_or_else(|e| panic!("{k} ({law:?}, {} solutions): {e}", all.len()));
                assert!(
                    all.iter()
                        .any(|g| g.iter().zip(&f).all(|(x, z)| (x - z).abs() < 1e-10)),
                    "{k}: {f:?} not among {all:?}"
                );
                solved += 1;
            }
        }
        // Measured: all 300 draws have a solution.
        assert!(solved >= 250, "{solved} solved, {none} without solution");
    }

    /// One node in 2D is `solve_point`'s exact case analysis: both are exact up to the
    /// rounding of a 2 × 2 solve on O(1) data, so 1e-13 relative.
    #[test]
    fn one_node_is_the_exact_case_analysis() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        let (mut compared, mut grazing) = (0, 0);
        for k in 0..2000 {
            let (w_nn, w_tt) = (0.5 + rng.f(), 0.5 + rng.f());
            let w_nt = (rng.f() - 0.5) * 0.4;
            let c = Condensed {
                gap_free: rng.f() * 2.0 - 1.5,
                slip_free: rng.f() * 2.0 - 1.0,
                w_nn,
                w_nt,
                w_tn: w_nt,
                w_tt,
            };
            let law = if k % 2 == 0 {
                FrictionLaw::Coulomb {
                    coefficient: rng.f(),
                }
            } else {
                FrictionLaw::Tresca { threshold: rng.f() }
            };
            let weight = 0.5 + rng.f();
            let mut fc = FrictionalContact::new(1, 2, vec![w_nn, w_nt, w_nt, w_tt]);
            let mut f = [0.0; 2];
            let r = fc.solve(
                &law,
                &[weight],
                &[c.gap_free],
                &[c.slip_free],
                None,
                &mut f,
                50,
                1e-12,
            );
            let Ok(exact) = solve_point(&law, weight, &c) else {
                // Tresca with coupled rows can have no solution of the literal law (the bound
                // vanishes when the node opens): the solver returns its closure's grazing one
                // (module header), unique for one node: f_n = 0, gap = q_n + w_nt f_t = 0,
                // |f_t| ≤ s·w against the slip (exact up to one division: 1e-13).
                r.unwrap_or_else(|e| panic!("{c:?} {law:?}: {e}"));
                let f_t = -c.gap_free / w_nt;
                let slip = c.slip_free + w_tt * f_t;
                assert!(
                    f[0].abs() <= 1e-13 && (f[1] - f_t).abs() <= 1e-13 * (1.0 + f_t.abs()),
                    "{c:?} {law:?}: {f:?} against the grazing f_t = {f_t}"
                );
                assert!(f_t.abs() <= law.bound(0.0, weight) && f_t * slip <= 0.0);
                grazing += 1;
                continue;
            };
            r.unwrap();
            let scale = 1.0 + exact.f_n.abs() + exact.f_t.abs();
            assert!(
                (f[0] - exact.f_n).abs() <= 1e-13 * scale
                    && (f[1] - exact.f_t).abs() <= 1e-13 * scale,
                "{c:?} {law:?}: {f:?} against {exact:?}"
            );
            compared += 1;
        }
        // Coulomb's draws are all well posed (|w_nt|μ_f < w_nn): only Tresca's may lack a
        // solution, and they are rare.
        assert!(compared >= 1900, "{compared} of 2000 compared");
        eprintln!("one node: {compared} compared, {grazing} grazing");
        assert!(grazing > 0, "no grazing draw");
    }

    /// Random SPD problems of up to 8 nodes, 2D and 3D, Coulomb and Tresca, cold and warm
    /// started: every solution satisfies the law to 1e-10 (data O(1); the solver stops at a
    /// natural residual of 1e-12 relative, and W's condition number is ≤ ~50 with δ = 0.05).
    /// faer's blocked LU (the 3D slipping systems, module header) solves what the hand loop
    /// solves: a random nonsymmetric 70 × 70 system (past faer's recursion threshold, so its
    /// blocked path runs) with a dominant diagonal (entries in [−½, ½] plus 8 on it: condition
    /// ~10, so each solution's round-off is ~1e-14 of |x|), the two equal to 1e-12 relative;
    /// a zero row or column of J is `Singular` for both.
    #[test]
    fn blocked_lu_agrees_with_the_hand_loop() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        let k = 70;
        let a: Vec<f64> = (0..k * k)
            .map(|i| rng.f() - 0.5 + if i % (k + 1) == 0 { 8.0 } else { 0.0 })
            .collect();
        let b: Vec<f64> = (0..k).map(|_| rng.f() - 0.5).collect();
        let mut scratch = LuScratch::new(k);
        let (mut perm, mut perm_inv) = (vec![0; k], vec![0; k]);
        let blocked =
            |a: &[f64], scratch: &mut LuScratch, perm: &mut [usize], pinv: &mut [usize]| {
                let (mut lu, mut x) = (a.to_vec(), b.clone());
                blocked_factor(&mut lu, k, perm, pinv, scratch)?;
                blocked_solve(&lu, perm, pinv, &mut x, scratch);
                Ok::<_, FrictionalContactError>(x)
            };
        let hand = |a: &[f64]| {
            let (mut lu, mut x, mut piv) = (a.to_vec(), b.clone(), vec![0; k]);
            lu_factor(&mut lu, k, &mut piv)?;
            lu_solve(&lu, k, &piv, &mut x);
            Ok::<_, FrictionalContactError>(x)
        };
        let x1 = blocked(&a, &mut scratch, &mut perm, &mut perm_inv).unwrap();
        let x2 = hand(&a).unwrap();
        let scale = x2.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        for (u, v) in x1.iter().zip(&x2) {
            assert!((u - v).abs() <= 1e-12 * scale, "{u} against {v}");
        }
        // The residual of the blocked solution, J x − b, at round-off.
        for r in 0..k {
            let jx: f64 = (0..k).map(|c| a[r * k + c] * x1[c]).sum();
            assert!((jx - b[r]).abs() <= 1e-12 * scale, "row {r}: {}", jx - b[r]);
        }
        for zero_row in [true, false] {
            let mut s = a.clone();
            for i in 0..k {
                s[if zero_row { 17 * k + i } else { i * k + 17 }] = 0.0;
            }
            let singular = Err(FrictionalContactError::Singular);
            assert_eq!(
                blocked(&s, &mut scratch, &mut perm, &mut perm_inv),
                singular
            );
            assert_eq!(hand(&s), singular);
        }
    }

    /// A 3D contact set sliding (m = 60 closed nodes pushed sideways: |q_t| ≫ μ_f |q_n|), about
    /// 2m unknowns after the slip elimination — faer's blocked path: the law holds at every
    /// node (1e-10, as [`check_law`] for the random problems), and a warm start from the
    /// solution costs one Newton step at most.
    #[test]
    fn sliding_3d_contact_set_on_the_blocked_lu() {
        let mut rng = Rng(0x51f15eed);
        let (m, d) = (60, 3);
        let n = m * d;
        let w = spd(&mut rng, n, 0.05);
        let law = FrictionLaw::Coulomb { coefficient: 0.3 };
        let weights = vec![1.0; m];
        let q_n: Vec<f64> = (0..m).map(|_| -0.5 - 0.5 * rng.f()).collect();
        let q_t: Vec<f64> = (0..2 * m).map(|_| 4.0 * (rng.f() - 0.5)).collect();
        let mut fc = FrictionalContact::new(m, d, w.clone());
        let mut f = vec![0.0; n];
        fc.solve(&law, &weights, &q_n, &q_t, None, &mut f, 100, 1e-12)
            .unwrap();
        let (open, stick, slip) = check_law(&w, d, &law, &weights, &q_n, &q_t, &f, 1e-10);
        // Measured: 57 of the 60 slip, three stick (their coupled neighbours hold them).
        assert_eq!((open, stick, slip), (0, 3, 57));
        let again = fc
            .solve(&law, &weights, &q_n, &q_t, None, &mut f, 100, 1e-12)
            .unwrap();
        assert!(again <= 1, "{again} Newton steps from the solution");
    }

    #[test]
    fn random_problems_satisfy_the_law() {
        let mut rng = Rng(0x2545f4914f6cdd1d);
        let mut counts = [0usize; 3];
        let (mut max_it, mut tresca_none) = (0, 0);
        for k in 0..400 {
            let d = 2 + k % 2;
            let m = 1 + k % 8;
            let n = m * d;
            let tresca = (k / 2) % 2 == 1;
            let w = spd(&mut rng, n, 0.05);
            let law = if !tresca {
                FrictionLaw::Coulomb {
                    coefficient: 0.6 * rng.f(),
                }
            } else {
                FrictionLaw::Tresca {
                    threshold: 0.5 * rng.f(),
                }
            };
            let weights: Vec<f64> = (0..m).map(|_| 0.5 + rng.f()).collect();
            let q_n: Vec<f64> = (0..m).map(|_| rng.f() - 0.7).collect();
            let q_t: Vec<f64> = (0..m * (d - 1)).map(|_| 0.4 * (rng.f() - 0.5)).collect();
            let mut fc = FrictionalContact::new(m, d, w.clone());
            let mut f = vec![0.0; n];
            let it = match fc.solve(&law, &weights, &q_n, &q_t, None, &mut f, 100, 1e-12) {
                Ok(it) => it,
                Err(_) if tresca => {
                    tresca_none += 1;
                    continue;
                }
                Err(e) => panic!("problem {k} (m = {m}, d = {d}, {law:?}): {e}"),
            };
            max_it = max_it.max(it);
            let c = check_law(&w, d, &law, &weights, &q_n, &q_t, &f, 1e-10);
            counts[0] += c.0;
            counts[1] += c.1;
            counts[2] += c.2;
            // A perturbed problem warm-started from this solution: the law again.
            let q_n2: Vec<f64> = q_n.iter().map(|x| x + 0.05 * (rng.f() - 0.5)).collect();
            match fc.solve(&law, &weights, &q_n2, &q_t, None, &mut f, 100, 1e-12) {
                Ok(_) => {}
                // Tresca may have no solution (module tests above: the enumeration finds
                // none where this fails); Coulomb's draws are well posed.
                Err(_) if tresca => {
                    tresca_none += 1;
                    continue;
                }
                Err(e) => panic!("warm problem {k} (m = {m}, d = {d}, {law:?}): {e}"),
            }
            check_law(&w, d, &law, &weights, &q_n2, &q_t, &f, 1e-10);
        }
        eprintln!("random: counts {counts:?} max_it {max_it} tresca_none {tresca_none}");
        // Every case occurs among the draws, and the Newton steps stay few.
        assert!(counts.iter().all(|&c| c > 50), "open/stick/slip {counts:?}");
        assert!(max_it <= 20, "at most {max_it} Newton steps");
        assert!(
            tresca_none <= 20,
            "{tresca_none} Tresca problems without a solution"
        );
    }

    /// Issue 43: coupled problems with μ_f from 1 to 5 and Tresca thresholds up to the force
    /// scale, on which the primary Newton cycles (W nearly singular, δ = 0.01). The rescue
    /// (continuation, then Gauss–Seidel) solves every 2D problem the enumeration of all cases
    /// says has a solution; at every answer the law holds to 1e-10 (check_law, as above: the
    /// natural residual is 1e-12 of forces and gaps up to O(100) here); a problem the primary
    /// Newton solves never reaches the rescue (its stages say so).
    #[test]
    fn rescue_solves_what_the_primary_newton_does_not() {
        let mut rng = Rng(0x0043_0043_0043_0043);
        let (mut rescued, mut unsolved, mut most) = (0, 0, Stages::default());
        for k in 0..600 {
            let d = 2 + k % 2;
            let m = 2 + k % 3;
            let n = m * d;
            let w = spd(&mut rng, n, 0.01);
            let law = if k % 4 == 3 {
                FrictionLaw::Tresca { threshold: rng.f() }
            } else {
                FrictionLaw::Coulomb {
                    coefficient: 1.0 + 4.0 * rng.f(),
                }
            };
            let weights: Vec<f64> = (0..m).map(|_| 0.5 + rng.f()).collect();
            let q_n: Vec<f64> = (0..m).map(|_| rng.f() - 0.7).collect();
            let q_t: Vec<f64> = (0..m * (d - 1)).map(|_| rng.f() - 0.5).collect();
            let mut f = vec![0.0; n];
            let mut fc = FrictionalContact::new(m, d, w.clone());
            let r = fc.solve(&law, &weights, &q_n, &q_t, None, &mut f, 100, 1e-12);
            let st = fc.stages();
            match r {
                Ok(it) => {
                    assert_eq!(it, st.total());
                    if st.rescued() {
                        rescued += 1;
                        most.continuation = most.continuation.max(st.continuation);
                        most.gauss_seidel = most.gauss_seidel.max(st.gauss_seidel);
                        most.polish = most.polish.max(st.polish);
                    } else {
                        assert!(st.continuation + st.gauss_seidel + st.polish == 0);
                    }
                    check_law(&w, d, &law, &weights, &q_n, &q_t, &f, 1e-10);
                }
                Err(e) => {
                    // 2D: only where the literal law has no solution at all.
                    if d == 2 {
                        let all = enumerate_2d(&w, &law, &weights, &q_n, &q_t);
                        assert!(all.is_empty(), "{k} ({law:?}, m = {m}): {e}, yet {all:?}");
                    }
                    unsolved += 1;
                }
            }
        }
        eprintln!("rescued {rescued}, unsolved {unsolved}, most per stage {most:?}");
        // The draws exercise the rescue (measured: see the message above).
        assert!(rescued >= 10, "{rescued} problems needed the rescue");
    }

    /// μ_f = 0: no tangential force and the normal forces of the frictionless LCP (both solve
    /// the same SPD linear system on the same active set: 1e-12 relative).
    #[test]
    fn frictionless_law_gives_the_lcp_solution() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        for k in 0..100 {
            let d = 2 + k % 2;
            let m = 2 + k % 6;
            let n = m * d;
            let w = spd(&mut rng, n, 0.05);
            let q_n: Vec<f64> = (0..m).map(|_| rng.f() - 0.6).collect();
            let q_t: Vec<f64> = (0..m * (d - 1)).map(|_| rng.f() - 0.5).collect();
            let mut f = vec![0.0; n];
            FrictionalContact::new(m, d, w.clone())
                .solve(
                    &FrictionLaw::Coulomb { coefficient: 0.0 },
                    &vec![1.0; m],
                    &q_n,
                    &q_t,
                    None,
                    &mut f,
                    100,
                    1e-12,
                )
                .unwrap();
            // The normal block of W.
            let h: Vec<f64> = (0..m * m)
                .map(|ij| w[(ij / m) * d * n + (ij % m) * d])
                .collect();
            let mut lambda = vec![0.0; m];
            Lcp::new(m, h).solve(&q_n, &mut lambda, 100, 1e-12).unwrap();
            let scale = 1.0 + lambda.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            for i in 0..m {
                assert!(
                    (f[i * d] - lambda[i]).abs() <= 1e-12 * scale,
                    "{k}: {f:?} {lambda:?}"
                );
                assert!(f[i * d + 1..(i + 1) * d].iter().all(|&x| x == 0.0));
            }
        }
    }

    /// One decoupled node pushed along more and more: stick while r|slip_free| ≤ μ_f f_n, then
    /// slip with |f_t| = μ_f f_n, and back. Hand values: W = diag(2, 4), gap_free = −0.5 so
    /// f_n = 0.25, b = 0.075; stick holds while |slip_free| ≤ 4·0.075 = 0.3. Exact binary
    /// data and one division: 1e-15.
    #[test]
    fn stick_slip_transitions_of_one_node() {
        let law = FrictionLaw::Coulomb { coefficient: 0.3 };
        let mut fc = FrictionalContact::new(1, 2, vec![2.0, 0.0, 0.0, 4.0]);
        let mut f = [0.0; 2];
        for (slip_free, want_ft) in [
            (0.1, -0.025),
            (0.29, -0.0725),
            (0.31, -0.075),
            (1.0, -0.075),
            (-1.0, 0.075),
            (-0.2, 0.05),
        ] {
            fc.solve(&law, &[1.0], &[-0.5], &[slip_free], None, &mut f, 20, 1e-12)
                .unwrap();
            assert!((f[0] - 0.25).abs() < 1e-15, "{slip_free}: {f:?}");
            assert!((f[1] - want_ft).abs() < 1e-15, "{slip_free}: {f:?}");
        }
        // 3D: the disc, not a pyramid. Slip along (3, 4)/5 with |slip_free| = 5: f_t =
        // −0.075·(0.6, 0.8) (a pyramid would bound each component by 0.075 separately).
        let mut fc =
            FrictionalContact::new(1, 3, vec![2.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 4.0]);
        let mut f = [0.0; 3];
        let it = fc
            .solve(&law, &[1.0], &[-0.5], &[3.0, 4.0], None, &mut f, 20, 1e-12)
            .unwrap();
        assert!((f[0] - 0.25).abs() < 1e-15);
        assert!(
            (f[1] + 0.045).abs() < 1e-15 && (f[2] + 0.06).abs() < 1e-15,
            "{f:?}"
        );
        assert!(it <= 3, "{it} Newton steps");
    }

    /// A warm start on the solution of a problem whose node states do not change costs one
    /// Newton step (the LU of the previous solve reused in 2D) and gives the cold answer to
    /// round-off (1e-13 on O(1) forces); `active` forces masked nodes open.
    #[test]
    fn warm_start_reuse_and_mask() {
        let mut rng = Rng(77);
        let (m, d) = (6, 2);
        let w = spd(&mut rng, m * d, 0.05);
        let law = FrictionLaw::Coulomb { coefficient: 0.2 };
        let q_n = vec![-0.3; m];
        let q_t: Vec<f64> = (0..m).map(|i| 0.02 * i as f64 - 0.05).collect();
        let mut fc = FrictionalContact::new(m, d, w.clone());
        let mut f = vec![0.0; m * d];
        fc.solve(&law, &[1.0; 6], &q_n, &q_t, None, &mut f, 100, 1e-12)
            .unwrap();
        let q_n2: Vec<f64> = q_n.iter().map(|x| x * 1.001).collect();
        let q_t2: Vec<f64> = q_t.iter().map(|x| x * 1.001).collect();
        let it = fc
            .solve(&law, &[1.0; 6], &q_n2, &q_t2, None, &mut f, 100, 1e-12)
            .unwrap();
        assert_eq!(it, 1);
        let mut cold = vec![0.0; m * d];
        FrictionalContact::new(m, d, w.clone())
            .solve(&law, &[1.0; 6], &q_n2, &q_t2, None, &mut cold, 100, 1e-12)
            .unwrap();
        for (a, b) in f.iter().zip(&cold) {
            assert!((a - b).abs() < 1e-13, "{f:?} {cold:?}");
        }
        let mask = [true, false, true, true, false, true];
        fc.solve(
            &law,
            &[1.0; 6],
            &q_n2,
            &q_t2,
            Some(&mask),
            &mut f,
            100,
            1e-12,
        )
        .unwrap();
        assert_eq!(&f[2..4], &[0.0, 0.0]);
        assert_eq!(&f[8..10], &[0.0, 0.0]);
        assert!(f[0] > 0.0);
        // Too few steps is an error, never a wrong answer.
        let mut f = vec![0.0; m * d];
        assert!(matches!(
            fc.solve(&law, &[1.0; 6], &q_n, &q_t, None, &mut f, 0, 1e-12),
            Err(FrictionalContactError::NoConvergence { .. })
        ));
    }

    /// Issue 33's failing step, bar3d (h = 0.1, four Γ_C corner nodes) with the mod3 mass,
    /// backward Euler, Tresca s = 0.05, τ = 0.005: the step 189 (t = 0.945) of the run, W,
    /// q and the warm start dumped from it. The bottom face spreads outwards; the Tresca
    /// force holding it back lifts the corners (W_nt < 0), and the literal law (bound s·w
    /// only while f_n > 0) has no solution: stick needs f_n = −2.8e-6, slip f_n = −1.0e-6,
    /// open a penetration of 6.5e-4 (measured on the symmetric reduction of this W). The
    /// semismooth Newton cycled for its 100 steps (natural residual 8.5e-2 relative, a
    /// `solver-failed` row). Its closure has the grazing solution: f_n = 0, gap = 0 and a
    /// tangential force 1.18800424e-4 < s·w = 1.25e-4 against the slip at every corner
    /// (the symmetric reduction: f_t = −q_n/W_n·t̂, exact), which the fallback finds.
    #[test]
    fn tresca_bar3d_mod3_backward_euler_grazing_corners() {
        const W: [f64; 144] = [
            61.843722838117486,
            -22.40283512563686,
            -22.40283512563691,
            -9.914987248008975,
            -17.027601752400066,
            -14.844698170024943,
            -9.914987248009009,
            -14.84469817002494,
            -17.027601752400113,
            -8.268182001463027,
            -16.372868482652787,
            -16.372868482652795,
            -22.40283512563686,
            89.61957249610589,
            -23.954406760071635,
            17.027601752400063,
            53.61749209632373,
            25.579531986974835,
            -14.844698170024927,
            -2.1322565157693143,
            -25.57953198697482,
            16.37286848265278,
            10.797330588868032,
            30.8571397634759,
            -22.40283512563691,
            -23.954406760071635,
            89.61957249610597,
            -14.844698170024937,
            -25.57953198697482,
            -2.132256515769288,
            17.02760175240011,
            25.57953198697487,
            53.61749209632382,
            16.37286848265281,
            30.857139763475935,
            10.797330588868068,
            -9.914987248008975,
            17.027601752400063,
            -14.844698170024937,
            61.84372283811748,
            22.402835125636848,
            -22.402835125636905,
            -8.268182001463027,
            16.37286848265279,
            -16.372868482652777,
            -9.914987248009,
            14.844698170024955,
            -17.027601752400127,
            -17.027601752400066,
            53.61749209632373,
            -25.57953198697482,
            22.402835125636848,
            89.61957249610587,
            23.954406760071645,
            -16.372868482652773,
            10.797330588868025,
            -30.857139763475885,
            14.844698170024936,
            -2.132256515769317,
            25.579531986974835,
            -14.844698170024943,
            25.579531986974835,
            -2.132256515769288,
            -22.402835125636905,
            23.954406760071645,
            89.61957249610597,
            16.372868482652812,
            -30.85713976347593,
            10.79733058886805,
            17.027601752400095,
            -25.579531986974878,
            53.61749209632386,
            -9.914987248009009,
            -14.844698170024927,
            17.02760175240011,
            -8.268182001463027,
            -16.372868482652773,
            16.372868482652812,
            61.84372283811752,
            -22.402835125636898,
            22.40283512563689,
            -9.914987248008995,
            -17.027601752400116,
            14.844698170024978,
            -14.84469817002494,
            -2.1322565157693143,
            25.57953198697487,
            16.37286848265279,
            10.797330588868025,
            -30.85713976347593,
            -22.402835125636898,
            89.619572496106,
            23.954406760071677,
            17.027601752400113,
            53.61749209632386,
            -25.57953198697489,
            -17.027601752400113,
            -25.57953198697482,
            53.61749209632382,
            -16.372868482652777,
            -30.857139763475885,
            10.79733058886805,
            22.40283512563689,
            23.954406760071677,
            89.61957249610597,
            14.844698170024959,
            25.57953198697487,
            -2.132256515769294,
            -8.268182001463027,
            16.37286848265278,
            16.37286848265281,
            -9.914987248009,
            14.844698170024936,
            17.027601752400095,
            -9.914987248008995,
            17.027601752400113,
            14.844698170024959,
            61.84372283811752,
            22.402835125636905,
            22.402835125636894,
            -16.372868482652787,
            10.797330588868032,
            30.857139763475935,
            14.844698170024955,
            -2.132256515769317,
            -25.579531986974878,
            -17.027601752400116,
            53.61749209632386,
            25.57953198697487,
            22.402835125636905,
            89.61957249610603,
            -23.95440676007171,
            -16.372868482652795,
            30.8571397634759,
            10.797330588868068,
            -17.027601752400127,
            25.579531986974835,
            53.61749209632386,
            14.844698170024978,
            -25.57953198697489,
            -2.132256515769294,
            22.402835125636894,
            -23.95440676007171,
            89.61957249610604,
        ];
        const Q_N: [f64; 4] = [
            -0.0006463418745153993,
            -0.0006463418743713478,
            -0.0006463418744482863,
            -0.0006463418743089255,
        ];
        const Q_T: [f64; 8] = [
            0.001862353661427914,
            0.001862353661496275,
            -0.0018623536612696458,
            0.0018623536614936712,
            0.0018623536615045234,
            -0.0018623536612819716,
            -0.0018623536613490202,
            -0.0018623536612795647,
        ];
        const F0: [f64; 12] = [
            4.7324380747851815e-05,
            -8.838834764756744e-05,
            -8.83883476490696e-05,
            4.732438074597666e-05,
            8.838834764732547e-05,
            -8.838834764931142e-05,
            4.732438074848417e-05,
            -8.838834764930569e-05,
            8.838834764733122e-05,
            4.732438074669859e-05,
            8.838834764906876e-05,
            8.838834764756818e-05,
        ];
        let law = FrictionLaw::Tresca { threshold: 0.05 };
        let weights = [0.0025; 4];
        let mut fc = FrictionalContact::new(4, 3, W.to_vec());
        let mut f = F0;
        let it = fc
            .solve(&law, &weights, &Q_N, &Q_T, None, &mut f, 100, 1e-12)
            .expect("the closure's grazing solution");
        // The literal law's 100 Newton steps come first (it has no solution here): the count
        // says the fallback ran (measured 100 + 3).
        eprintln!("grazing corners: {it} Newton steps, f = {f:?}");
        assert!(it > 100 && it <= 120, "{it} Newton steps");
        // The law (its closure) at the solution: forces are O(1e-4) and gaps O(1e-3) here, the
        // solver's residual 1e-12 of 1.25e-4: 1e-14 absolute is ~100 times that.
        let (open, _, slip) = check_law(&W, 3, &law, &weights, &Q_N, &Q_T, &f, 1e-14);
        assert_eq!((open, slip), (0, 4));
        for i in 0..4 {
            let nft = (f[i * 3 + 1].powi(2) + f[i * 3 + 2].powi(2)).sqrt();
            assert!(f[i * 3].abs() <= 1e-14, "node {i}: f_n = {}", f[i * 3]);
            // The symmetric reduction's value (from node 0's rows; the dumped W is symmetric
            // under the corners' reflections to 5e-10 relative only: measured 3.4e-10 off).
            assert!(
                (nft - 1.188_004_238_577_078e-4).abs() <= 2e-9 * nft,
                "node {i}: |f_t| = {nft:e}"
            );
        }
    }
}
