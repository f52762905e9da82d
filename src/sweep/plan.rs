//! Expansion of a sweep file into runs.
//!
//! Order: the zipped lists (if any) vary slowest, then the `[grid]` axes in file order, the last
//! fastest. Each combination is resolved: scheme aliases become a family plus parameters
//! (`crank-nicolson` = newmark with β = ¼, γ = ½), `courant` becomes dt = ν h / c0, `elements`
//! becomes h = L/m, defaults are filled in, and a parameter that does not apply to the run's
//! method (contract §3) is dropped. Combinations that are meaningless (Paoli–Schatzman with
//! Nitsche, …) are left out with their reason. Runs whose canonical parameters coincide merge.
//!
//! `run_id` is the first 16 hex digits of SHA-256 over the canonical parameter text: scene plus
//! every applicable parameter whose value differs from its default, sorted by key, numbers at 12
//! significant digits. Adding an axis whose value is the default leaves ids unchanged, and the
//! same run has the same id in every sweep, shard and machine.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::Path;

use sha2::{Digest, Sha256};

use super::keys::canonical_number;
use super::{Axis, Entry, Issue, Key, Origin, SweepError, SweepFile, Value};
use crate::contact::friction::{FrictionKind, FrictionLaw};
use crate::run::RunConfig;
use crate::run::estimate::human_bytes;
use crate::scene::{FileSetup, InterfaceUse, MeshChoice, MethodNames, Physics, Scene, SceneKind};
use crate::space::step_solver::Solver;
use crate::space::{ContactInit, ContactMethod, MassVariant};
use crate::time::{
    AlphaPreset, GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, PaoliSchatzmanParams,
    Scheme, ThetaParams,
};

/// One run of the plan: defined with the runs ([`crate::run::RunSpec`]), which build their row
/// from it; the planner makes it.
pub use crate::run::RunSpec;

/// One method of a sweep with a `[search]`: the grid combination without the searched key.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchBase {
    /// Index among the bases (grid order).
    pub index: usize,
    pub label: String,
    pub entries: Vec<Entry>,
    /// The tag of its probes.
    pub tag: String,
}

/// A reference run of the plan and the lattice its solution is stored on: every
/// `space_stride`-th reference node along each axis and every `time_stride`-th reference step
/// (the greatest common divisor of its consumers' ratios, so every consumer's nodes and times
/// are stored and nothing else).
#[derive(Debug, Clone, PartialEq)]
pub struct ReferencePlan {
    pub spec: RunSpec,
    pub space_stride: usize,
    pub time_stride: usize,
}

/// The expanded sweep.
#[derive(Debug, Clone)]
pub struct Plan {
    pub sweep: SweepFile,
    /// The limits it was expanded under (its search probes are checked against them too).
    pub limits: PlanLimits,
    pub runs: Vec<RunSpec>,
    /// Number of raw combinations (before filters and merging).
    pub combinations: usize,
    pub excluded_by_filter: usize,
    /// Meaningless combinations left out, by reason.
    pub inapplicable: BTreeMap<String, usize>,
    /// Combinations merged into an earlier identical run, by reason.
    pub collapsed: BTreeMap<String, usize>,
    /// The distinct reference runs, in order of first use.
    pub references: Vec<ReferencePlan>,
    /// With a `[search]`: the methods searched (their probes at lo and hi are in `runs`).
    pub searches: Vec<SearchBase>,
}

/// The tag of the probes of one search base: `name=…;key=…;criterion=…[;tol=…|;error=…;eps=…];
/// lo=…;hi=…;rel_tol=…;base=…` — everything the summary needs to re-judge the probes and find
/// the boundary from the rows alone.
pub fn search_tag(s: &super::Search, base: usize) -> String {
    let crit = match &s.criterion {
        super::Criterion::NoDivergence => String::new(),
        super::Criterion::EnergyRatioBelow(t) => format!(";tol={t}"),
        super::Criterion::ErrorBelow { column, eps } => format!(";error={column};eps={eps}"),
    };
    format!(
        "name={};key={};criterion={}{crit};lo={};hi={};rel_tol={};base={base}",
        s.name,
        s.key.name(),
        s.criterion.name(),
        s.lo,
        s.hi,
        s.rel_tol
    )
}

/// Resolved parameters of one combination.
struct Resolved {
    params: BTreeMap<Key, Value>,
    canonical: BTreeMap<Key, String>,
    /// Lines of the id for definition changes that moved this run's numbers
    /// ([`crate::scene::SceneSetup::id_revision`]).
    revision: String,
    /// The revision lines of its id before the latest change that moved it: empty (the ids of
    /// before issue 34), or, for a run a change of this version moved (issue 42), its lines
    /// without this version's ([`previous_revision`]) — the id a folder of the previous
    /// version holds.
    revision_before: String,
    config: RunConfig,
    label: String,
    scheme_label: String,
    scheme_names: [String; 2],
    dropped: Vec<String>,
    /// (h, dt, T) for the nesting check of a reference run.
    h: f64,
    dt: f64,
    t_final: f64,
}

enum Outcome {
    Run(Box<Resolved>),
    Inapplicable(String),
    Invalid(Vec<Issue>),
}

/// Defaults: the method and scheme keys are the same for every scene (003 §4.1: mixed,
/// consistent mass, Crank–Nicolson, Θ = 1, Newmark ¼/½, e = 1); T and physics are the scene's.
fn default_of(scene: &dyn Scene, key: Key) -> Option<Value> {
    Some(match key {
        Key::T => Value::Num(scene.default_t()),
        Key::Space => Value::Str("mixed".into()),
        Key::Mass => Value::Str("consistent".into()),
        Key::Scheme => Value::Str("crank-nicolson".into()),
        Key::NitscheTheta => Value::Num(1.0),
        Key::NewmarkBeta => Value::Num(0.25),
        Key::NewmarkGamma => Value::Num(0.5),
        Key::Restitution => Value::Num(1.0),
        Key::RhoInf => Value::Num(1.0),
        Key::ContactInit => Value::Str(ContactInit::Consistent.name().into()),
        Key::Solver => Value::Str(Solver::Direct.name().into()),
        Key::Friction => Value::Str(FrictionKind::None.name().into()),
        Key::CgTol => Value::Num(Solver::DEFAULT_CG_TOL),
        k if k.is_physics() => physics_value(
            k,
            scene.physics().iter().find(|p| p.name == k.name())?.default,
        ),
        _ => return None,
    })
}

/// A scene's physics value as a parameter: a number, or the word a choice key's index names
/// (`right_end`: 0 → clamped).
/// A NaN default ("not given": the two-body keys of a mesh file) stays NaN, a choice key's too.
fn physics_value(key: Key, x: f64) -> Value {
    match key.choices() {
        Some(words) if !x.is_nan() => Value::Str(words[x as usize].into()),
        _ => Value::Num(x),
    }
}

fn same(a: &Value, b: &Value) -> bool {
    a.canonical() == b.canonical()
}

/// The folder mesh files are relative to (contract §1.6): the sweep file's.
fn sweep_dir(sweep: &SweepFile) -> &Path {
    sweep.path.parent().unwrap_or(Path::new(""))
}

/// The Gmsh file of a mesh scene's run, read and validated (cached per file): (its path as
/// written, the resolved path, the mesh).
type MeshFile = (
    String,
    std::path::PathBuf,
    std::sync::Arc<crate::space::fe::GmshMesh>,
);

/// `obstacle` (contract §1.6) as the gap it names: the plane x_d = obstacle lies
/// g = (lowest contact node's x_d) − obstacle below the body ([`GmshMesh::contact_floor`], the
/// engine's plane is that height minus the gap), so the run is the one `gap = g` gives, with
/// the same id. Exclusive with `gap` (one plane given twice could disagree); a plane above the
/// lowest contact node (g < 0: the body would start inside the obstacle) is refused. None when
/// the sweep gives no `obstacle`.
///
/// [`GmshMesh::contact_floor`]: crate::space::fe::GmshMesh::contact_floor
fn gap_from_obstacle(
    mesh: &crate::space::fe::GmshMesh,
    user: &BTreeMap<Key, (Value, Origin)>,
) -> Result<Option<f64>, Issue> {
    let Some((v, o)) = user.get(&Key::Obstacle) else {
        return Ok(None);
    };
    let obstacle = v.as_f64().expect("obstacle is a checked number");
    if mesh.bodies.is_some() {
        return Err(Issue::at(
            o,
            format!(
                "{} holds two bodies (contract §1.10): there is no obstacle; `gap` is the initial distance between them",
                mesh.file
            ),
        ));
    }
    if let Some((_, g)) = user.get(&Key::Gap) {
        return Err(Issue::at(
            o,
            format!(
                "give either `gap` (the distance from the lowest contact node, set at `{}`) or `obstacle` (the height x_d of the plane), not both: they name the same plane",
                g.path
            ),
        ));
    }
    let Some(floor) = mesh.contact_floor() else {
        // The scene refuses such a file with its own reason.
        return Ok(None);
    };
    let gap = floor - obstacle;
    if gap < 0.0 {
        return Err(Issue::at(
            o,
            format!(
                "obstacle = {obstacle} lies above the lowest contact node of {} (x_d = {floor}): the body would start {:e} inside the obstacle; the plane must be at x_d ≤ {floor}",
                mesh.file, -gap
            ),
        ));
    }
    Ok(Some(gap))
}

/// The values one combination gives (its entries and where they were written), with the
/// scene's defaults behind them: what every phase of [`resolve`] reads.
struct Given {
    scene: &'static dyn Scene,
    user: BTreeMap<Key, (Value, Origin)>,
}

impl Given {
    fn new(scene: &'static dyn Scene, entries: &[&Entry]) -> Given {
        let mut user: BTreeMap<Key, (Value, Origin)> = BTreeMap::new();
        for e in entries {
            user.insert(e.key, (e.value.clone(), e.origin.clone()));
        }
        Given { scene, user }
    }

    /// The value of `k`: the combination's, else its default.
    fn get(&self, k: Key) -> Option<Value> {
        self.user
            .get(&k)
            .map(|(v, _)| v.clone())
            .or_else(|| default_of(self.scene, k))
    }

    fn num(&self, k: Key) -> Option<f64> {
        self.get(k).and_then(|v| v.as_f64())
    }

    /// The word of a key that always has one (`space`, `mass`, `scheme`: defaulted, checked).
    fn word(&self, k: Key) -> String {
        self.get(k)
            .and_then(|v| v.as_str().map(String::from))
            .unwrap()
    }

    /// Where `k` was set; `(default k)` for a default.
    fn origin(&self, k: Key) -> Origin {
        self.user.get(&k).map(|(_, o)| o.clone()).unwrap_or(Origin {
            path: format!("(default {})", k.name()),
            line: None,
        })
    }

    fn has(&self, k: Key) -> bool {
        self.user.contains_key(&k)
    }

    /// Whether `k` varies along an axis (`[grid]`, `[zip]`): a value that rules a run out is
    /// then one meaningless combination, not a mistake in the file.
    fn on_axis(&self, k: Key) -> bool {
        self.user
            .get(&k)
            .is_some_and(|(_, o)| o.path.starts_with("grid") || o.path.starts_with("zip"))
    }
}

/// What a combination's method keys resolve to (contract §2–§3): contact treatment, mass variant,
/// time scheme and friction law, with the words they were named by.
struct Method {
    space_name: String,
    contact: ContactMethod,
    mass_name: String,
    mass: MassVariant,
    scheme: Scheme,
    friction_kind: FrictionKind,
    friction: FrictionLaw,
}

/// Resolve one combination of entries for `scene`; a run whose estimated memory exceeds
/// `limits.max_run_bytes` is invalid (refused before anything is allocated for it).
fn resolve(
    sweep_dir: &Path,
    scene_kind: SceneKind,
    entries: &[&Entry],
    allow_unstable: bool,
    limits: &PlanLimits,
) -> Outcome {
    let given = Given::new(scene_kind.get(), entries);
    match resolve_given(sweep_dir, &given, allow_unstable, limits) {
        Ok(r) => Outcome::Run(Box::new(r)),
        Err(outcome) => outcome,
    }
}

/// [`resolve`]'s phases in order: the method, the keys that do not apply to it, the
/// meaningless combinations, physics, mesh and step, the memory and CFL checks, then the
/// columns, the canonical text and the label. `Err` is the outcome of a combination that is
/// no run.
fn resolve_given(
    sweep_dir: &Path,
    given: &Given,
    allow_unstable: bool,
    limits: &PlanLimits,
) -> Result<Resolved, Outcome> {
    let scene = given.scene;
    let mut issues = Vec::new();
    let mut dropped = Vec::new();
    let m = method_of(given, &mut dropped, &mut issues)?;
    // Whether `contact_init` changes this run: a massless contact with the scene's physics
    // loading the massless dofs (contract §2.2).
    let init_matters =
        m.mass.massless_contact() && scene.contact_init_matters(&physics_values(given));
    for k in given.user.keys() {
        if let Err(why) = applies(*k, &m, scene, init_matters) {
            dropped.push(format!("{} {why}", k.name()));
        }
    }
    if let Some((why, keys)) = meaningless(&m) {
        return Err(refuse_meaningless(given, why, keys));
    }
    // The start the run makes: the given one where it matters, else the default (the same
    // state), so the label and the columns say what ran.
    let contact_init = if init_matters {
        given
            .get(Key::ContactInit)
            .and_then(|v| v.as_str().and_then(ContactInit::from_name))
            .expect("checked")
    } else {
        ContactInit::Consistent
    };

    // Physics, mesh and time step: the scene's.
    let mut physics = physics_of(given, &m.scheme)?;
    interface_of(given, &m, &physics)?;
    let c0 = scene.wave_speed(&physics);
    let mut mesh_file: Option<MeshFile> = None;
    let mut file_setup = None;
    if scene.takes_mesh_file() {
        (mesh_file, file_setup) = read_mesh_file(sweep_dir, given, &mut physics, &mut issues);
        if !issues.is_empty() {
            return Err(Outcome::Invalid(issues));
        }
    }
    let mesh = mesh_of(
        given,
        &physics,
        file_setup.as_ref().map(|(c, _)| *c),
        &mut issues,
    );
    let dt = dt_of(given, mesh.map(|m| m.h), c0, &mut issues);
    let t_final = given.num(Key::T).unwrap();
    if !issues.is_empty() {
        return Err(Outcome::Invalid(issues));
    }
    let (mesh, dt) = (mesh.unwrap(), dt.unwrap());
    let h = mesh.h;
    let dt_origin = given.origin(if given.has(Key::Dt) {
        Key::Dt
    } else {
        Key::Courant
    });
    let steps = steps_of(t_final, dt, &dt_origin)?;
    let courant = c0 * dt / h;
    let setup = match file_setup {
        Some((_, setup)) => setup,
        None => scene.setup(&physics, mesh),
    };
    static_start_of(given, setup.static_start_refusal(m.friction))?;
    let mut revision = setup.id_revision();
    let increments = setup.two_bodies_step_in_increments(&m.scheme);
    method_revisions(scene, &m, increments, &mut revision);
    if setup.two_bodies_full_newton(m.contact, &m.friction, &m.scheme) {
        revision.push_str("revision=two-body-full-newton\n");
    }
    if init_matters && contact_init == ContactInit::Consistent && setup.is_fe() {
        // contract §1.3: the massless dofs of a body-loaded FE run start quasi-static (issue
        // 42); before, at u⁰ = 0, which `contact_init = "interpolant"` keeps with its id.
        revision.push_str("revision=quasi-static-start\n");
        // The mixed Newmark/θ runs among them step in increments (`run::fe::newmark`'s
        // header): the same equations, round-off relative to the step's increment.
        if m.contact == ContactMethod::Mixed && !m.scheme.is_comparison() {
            revision.push_str("revision=increment-step\n");
        }
    }
    let revision_before = previous_revision(&revision);
    let scheme = m.scheme;
    let config = RunConfig::new(setup, m.contact, m.mass.clone(), scheme, dt, steps)
        .with_friction(m.friction)
        .with_contact_init(contact_init);
    let fe = matches!(config, RunConfig::Fe(_));
    let solver = solver_of(given, fe, &mut dropped);
    let config = config.with_solver(solver);
    check_memory(given, limits, &config, fe, solver)?;

    // CFL of explicit schemes (contract §3): τ ω_max ≤ the scheme's bound, checked on the
    // assembled operators (contact-free and contact-active stiffness).
    match config.explicit_dt_limit() {
        Ok(Some(dt_max)) if dt > dt_max * (1.0 + 1e-12) && !allow_unstable => {
            return Err(Outcome::Invalid(vec![Issue::at(
                &dt_origin,
                format!(
                    "dt = {dt:.6e} is above the CFL limit of {} for this mesh, mass and contact (dt ≤ {dt_max:.6e}, courant ≤ {:.6})",
                    scheme.label(),
                    c0 * dt_max / h
                ),
            )]));
        }
        Ok(_) => {}
        Err((key, e)) => {
            let k = Key::from_name(key).expect("engines name sweep keys");
            return Err(Outcome::Invalid(vec![Issue::at(&given.origin(k), e)]));
        }
    }

    // Columns and canonical text.
    let mut columns = Columns::new(scene);
    columns.put(Key::T, Value::Num(t_final), false);
    columns.put(Key::Elements, Value::Int(mesh.elements as i64), true);
    columns.put(Key::Dt, Value::Num(dt), true);
    columns.put_method(&m, contact_init, init_matters);
    columns.put_physics(given, &physics, &mut dropped);
    columns.put_friction(&m);
    columns.put_solver(solver, fe);
    columns.put_mesh_file(mesh_file.as_ref(), &physics);
    let Columns {
        mut params,
        canonical,
        ..
    } = columns;
    params.insert(Key::H, Value::Num(h));
    params.insert(Key::Courant, Value::Num(courant));

    let scheme_label = scheme.label();
    Ok(Resolved {
        params,
        canonical,
        revision,
        revision_before,
        label: run_label(&m, contact_init, &scheme_label),
        scheme_names: [scheme.family().to_string(), scheme_label.clone()],
        scheme_label,
        config,
        dropped,
        h,
        dt,
        t_final,
    })
}

/// The method keys of a combination: scheme, contact treatment and mass variant (the scene
/// must implement the three together), then the friction law. A missing parameter joins
/// `issues`; `Err` is a combination refused or left out outright.
fn method_of(
    given: &Given,
    dropped: &mut Vec<String>,
    issues: &mut Vec<Issue>,
) -> Result<Method, Outcome> {
    let scheme = scheme_of(given, dropped, issues)?;
    let (space_name, contact) = contact_method_of(given, issues);
    let (mass_name, mass) = mass_of(given, issues);
    let names = MethodNames {
        space: &space_name,
        mass: &mass_name,
        scheme: scheme.family(),
    };
    if let Err((key, why)) = given.scene.supports(names) {
        let k = Key::from_name(key).expect("scenes name sweep keys");
        // contract §7: the value an axis crosses (the blocks' hybrid beside a `space` axis
        // holding mixed) is one combination left out; fixed, it is the file's mistake.
        if given.on_axis(k) || given.origin(k).path.starts_with("search") {
            return Err(Outcome::Inapplicable(why));
        }
        return Err(Outcome::Invalid(vec![Issue::at(&given.origin(k), why)]));
    }
    let (friction_kind, friction) = friction_of(given, &scheme, issues)?;
    Ok(Method {
        space_name,
        contact,
        mass_name,
        mass,
        scheme,
        friction_kind,
        friction,
    })
}

/// The scheme: family and its parameters (aliases fix them, and a parameter given beside an
/// alias is dropped with the reason).
fn scheme_of(
    given: &Given,
    dropped: &mut Vec<String>,
    issues: &mut Vec<Issue>,
) -> Result<Scheme, Outcome> {
    let num = |k: Key| given.num(k);
    let scheme_name = given.word(Key::Scheme);
    let preset: Option<(Scheme, &[Key])> = match scheme_name.as_str() {
        "crank-nicolson" => Some((
            Scheme::Newmark(NewmarkParams::crank_nicolson()),
            &[Key::NewmarkBeta, Key::NewmarkGamma],
        )),
        "newmark-dissipative" => Some((
            Scheme::Newmark(NewmarkParams::dissipative()),
            &[Key::NewmarkBeta, Key::NewmarkGamma],
        )),
        "central-difference" => Some((
            Scheme::Newmark(NewmarkParams::central_difference()),
            &[Key::NewmarkBeta, Key::NewmarkGamma],
        )),
        "backward-euler" => Some((
            Scheme::Theta(ThetaParams::backward_euler()),
            &[Key::ThetaScheme],
        )),
        _ => None,
    };
    Ok(match (preset, scheme_name.as_str()) {
        (Some((s, fixed_keys)), _) => {
            for k in fixed_keys {
                if given.has(*k) {
                    dropped.push(format!("{} is fixed by scheme = {scheme_name}", k.name()));
                }
            }
            s
        }
        (None, "newmark") => Scheme::Newmark(NewmarkParams {
            beta: num(Key::NewmarkBeta).unwrap(),
            gamma: num(Key::NewmarkGamma).unwrap(),
        }),
        (None, "theta") => match num(Key::ThetaScheme) {
            Some(0.0) => {
                return Err(Outcome::Invalid(vec![Issue::at(
                    &given.origin(Key::ThetaScheme),
                    "theta_scheme = 0 is forward Euler, unstable for every dt on the undamped wave equation",
                )]));
            }
            Some(theta) => Scheme::Theta(ThetaParams { theta }),
            None => {
                issues.push(Issue::at(
                    &given.origin(Key::Scheme),
                    "scheme = theta needs theta_scheme (θ ∈ (0, 1]); backward-euler is θ = 1",
                ));
                Scheme::Theta(ThetaParams::backward_euler())
            }
        },
        (None, "paoli-schatzman") => Scheme::PaoliSchatzman(PaoliSchatzmanParams {
            beta: num(Key::NewmarkBeta).unwrap(),
            restitution: num(Key::Restitution).unwrap(),
        }),
        (None, "kane") => Scheme::Kane,
        (None, "contact-stabilized-newmark") => Scheme::ContactStabilizedNewmark,
        (None, "generalized-alpha") => Scheme::GeneralizedAlpha(
            GeneralizedAlphaParams::from_rho_inf(num(Key::RhoInf).unwrap()),
        ),
        (None, "hht") => match num(Key::HhtAlpha) {
            Some(alpha) => Scheme::GeneralizedAlpha(GeneralizedAlphaParams::hht(alpha)),
            None => {
                issues.push(Issue::at(
                    &given.origin(Key::Scheme),
                    "scheme = hht needs hht_alpha (α ∈ [0, ⅓]; α = 0 is Crank–Nicolson)",
                ));
                Scheme::GeneralizedAlpha(GeneralizedAlphaParams::hht(0.0))
            }
        },
        // Moreau–Jean's own defaults (contract §3.2): θ = ½, e = 0 — not Paoli–Schatzman's e = 1.
        (None, "moreau-jean") => Scheme::MoreauJean(MoreauJeanParams {
            theta: given
                .user
                .get(&Key::ThetaScheme)
                .and_then(|(v, _)| v.as_f64())
                .unwrap_or(0.5),
            restitution: given
                .user
                .get(&Key::Restitution)
                .and_then(|(v, _)| v.as_f64())
                .unwrap_or(0.0),
        }),
        (None, "discrete-gradient") => Scheme::DiscreteGradient,
        (None, _) => Scheme::Hybrid,
    })
}

/// The contact treatment (`space`) and its parameters.
fn contact_method_of(given: &Given, issues: &mut Vec<Issue>) -> (String, ContactMethod) {
    let num = |k: Key| given.num(k);
    let space_name = given.word(Key::Space);
    let method = match space_name.as_str() {
        "nitsche" => match num(Key::NitscheGamma0) {
            Some(gamma0) => ContactMethod::Nitsche {
                theta: num(Key::NitscheTheta).unwrap(),
                gamma0,
            },
            None => {
                issues.push(Issue::at(
                    &given.origin(Key::Space),
                    "space = nitsche needs nitsche_gamma0 (γ0 > 0; the papers use 1e-6 … 1)",
                ));
                ContactMethod::Nitsche {
                    theta: 1.0,
                    gamma0: 1.0,
                }
            }
        },
        "penalty" => match num(Key::PenaltyGamma0) {
            Some(gamma0) => ContactMethod::Penalty { gamma0 },
            None => {
                issues.push(Issue::at(
                    &given.origin(Key::Space),
                    "space = penalty needs penalty_gamma0 (κ = E·penalty_gamma0/h)",
                ));
                ContactMethod::Penalty { gamma0: 1.0 }
            }
        },
        _ => ContactMethod::Mixed,
    };
    (space_name, method)
}

/// The mass variant (`mass`; `weights` takes its list from `mass_weights`).
fn mass_of(given: &Given, issues: &mut Vec<Issue>) -> (String, MassVariant) {
    let mass_name = given.word(Key::Mass);
    let mass = if mass_name == "weights" {
        match given.get(Key::MassWeights) {
            Some(Value::List(w)) => MassVariant::Weights(w),
            _ => {
                issues.push(Issue::at(
                    &given.origin(Key::Mass),
                    "mass = weights needs mass_weights = [w1, w2, …]",
                ));
                MassVariant::Mod1
            }
        }
    } else {
        MassVariant::from_name(&mass_name).expect("checked")
    };
    (mass_name, mass)
}

/// Friction (contract §2.5): the law and its parameter; `none` is today's engine (no key of
/// it enters the id). A bound given while friction is fixed at `none` (by default or in
/// [fixed]) is a mistake, refused; across a `friction` axis it applies to its law only and
/// the frictionless runs collapse, as every other key.
fn friction_of(
    given: &Given,
    scheme: &Scheme,
    issues: &mut Vec<Issue>,
) -> Result<(FrictionKind, FrictionLaw), Outcome> {
    let friction_kind = given
        .get(Key::Friction)
        .and_then(|v| v.as_str().and_then(FrictionKind::from_name))
        .expect("checked");
    let friction_fixed = !given.on_axis(Key::Friction);
    let friction = match friction_kind {
        FrictionKind::None => {
            for k in [Key::FrictionCoefficient, Key::TrescaThreshold] {
                if given.has(k) && friction_fixed {
                    issues.push(Issue::at(
                        &given.origin(k),
                        format!(
                            "{} sets a friction bound but friction = \"none\"{} for this run: set friction = \"coulomb\" (with friction_coefficient) or \"tresca\" (with tresca_threshold)",
                            k.name(),
                            if given.has(Key::Friction) { "" } else { " (the default)" }
                        ),
                    ));
                }
            }
            FrictionLaw::None
        }
        FrictionKind::Coulomb | FrictionKind::Tresca => {
            // The other law's bound beside a fixed law would be dropped and change nothing:
            // a mistake, as a bound beside `none` is.
            let (other, other_law, own) = if friction_kind == FrictionKind::Coulomb {
                (Key::TrescaThreshold, "tresca", Key::FrictionCoefficient)
            } else {
                (Key::FrictionCoefficient, "coulomb", Key::TrescaThreshold)
            };
            if given.has(other) && friction_fixed {
                issues.push(Issue::at(
                    &given.origin(other),
                    format!(
                        "{} is the bound of friction = \"{other_law}\", but friction = \"{}\" for this run (its bound is {}): it would be ignored; drop it, or set friction = \"{other_law}\"",
                        other.name(),
                        friction_kind.name(),
                        own.name(),
                    ),
                ));
            }
            law_of(given, friction_kind, issues)
        }
    };
    if friction_kind != FrictionKind::None {
        if let Err(why) = given.scene.supports_friction() {
            issues.push(Issue::at(&given.origin(Key::Friction), why));
        }
        // Where the literature defines no frictional version (contract §2.5).
        let undefined = match scheme {
            Scheme::PaoliSchatzman(_) => Some("paoli-schatzman"),
            Scheme::Hybrid => Some("the hybrid schemes"),
            Scheme::DiscreteGradient => Some("discrete-gradient"),
            _ => None,
        };
        if let Some(what) = undefined {
            let why = format!(
                "{what} has no frictional version in the literature (contract §2.5): friction = {} runs with the newmark and theta families, kane, contact-stabilized-newmark, generalized-alpha, hht, moreau-jean and central-difference",
                friction_kind.name()
            );
            if friction_fixed {
                issues.push(Issue::at(&given.origin(Key::Scheme), why));
            } else {
                return Err(Outcome::Inapplicable(why));
            }
        }
    }
    Ok((friction_kind, friction))
}

/// The revision lines of this version's definition changes (issue 42): a run that carries one
/// had, in the previous version, the id of its other lines.
const THIS_VERSION: [&str; 10] = [
    "revision=energy-scale-continuous",
    "revision=friction-balance-step-1",
    "revision=dry-friction-stick-slip",
    "revision=quasi-static-start",
    "revision=increment-step",
    "revision=mixed-friction-chord",
    "revision=bars1d-b-follows-a",
    "revision=mixed-friction-slip-elimination",
    "revision=two-body-increment",
    "revision=two-body-full-newton",
];

/// The revision lines that depend on the method. Issue 42: a frictional Nitsche/penalty run's
/// E + W_f starts from E⁰ (its step 1 had been left out of `energy_balance_max_increase`) and
/// its series has W_f⁰ = 0 (was null). Issue 43: mixed friction in 3D takes chord steps on a
/// kept LU while the node kinds repeat (`contact::coulomb`'s header), and its Newton steps
/// eliminate a slipping node's tangential component along the slip on faer's blocked LU: the
/// same solution to the same tolerance, not the same round-off, so such a run gets a revision
/// line for each. Issue 44: `increments`, a two-body run that now steps in increments (the
/// scene setup's `two_bodies_step_in_increments`).
fn method_revisions(scene: &dyn Scene, m: &Method, increments: bool, revision: &mut String) {
    let fe_scene = scene.fe_dim().is_some();
    if fe_scene && m.friction_kind != FrictionKind::None && m.contact != ContactMethod::Mixed {
        revision.push_str("revision=friction-balance-step-1\n");
    }
    if scene.fe_dim() == Some(3)
        && m.friction_kind != FrictionKind::None
        && m.contact == ContactMethod::Mixed
    {
        revision.push_str("revision=mixed-friction-chord\n");
        revision.push_str("revision=mixed-friction-slip-elimination\n");
    }
    if increments {
        revision.push_str("revision=two-body-increment\n");
    }
}

/// The revision lines of a run's id in the previous version: its lines without this version's
/// when it carries one of them; else empty — the ids of before issue 34, which a folder of any
/// earlier version may hold.
fn previous_revision(revision: &str) -> String {
    if !revision.lines().any(|l| THIS_VERSION.contains(&l)) {
        return String::new();
    }
    revision
        .lines()
        .filter(|l| !THIS_VERSION.contains(l))
        .map(|l| format!("{l}\n"))
        .collect()
}

/// The law of a `coulomb` or `tresca` run with its bound (a missing bound joins `issues`).
fn law_of(given: &Given, kind: FrictionKind, issues: &mut Vec<Issue>) -> FrictionLaw {
    match kind {
        FrictionKind::Coulomb => match given.num(Key::FrictionCoefficient) {
            Some(coefficient) => FrictionLaw::Coulomb { coefficient },
            None => {
                issues.push(Issue::at(
                    &given.origin(Key::Friction),
                    "friction = coulomb needs friction_coefficient (μ_f ≥ 0: |f_t| ≤ μ_f f_n)",
                ));
                FrictionLaw::None
            }
        },
        FrictionKind::Tresca => match given.num(Key::TrescaThreshold) {
            Some(threshold) => FrictionLaw::Tresca { threshold },
            None => {
                issues.push(Issue::at(
                    &given.origin(Key::Friction),
                    "friction = tresca needs tresca_threshold (s ≥ 0, a traction: |f_t| ≤ s while in contact)",
                ));
                FrictionLaw::None
            }
        },
        FrictionKind::None => FrictionLaw::None,
    }
}

/// Applicability (contract §3): whether a run of method `m` uses key `k`; `Err` says why not (the
/// key is then dropped from the run, and runs that differ only by it merge).
fn applies(k: Key, m: &Method, scene: &dyn Scene, init_matters: bool) -> Result<(), &'static str> {
    let scheme = m.scheme;
    let ok = match k {
        Key::FrictionCoefficient => m.friction_kind == FrictionKind::Coulomb,
        Key::TrescaThreshold => m.friction_kind == FrictionKind::Tresca,
        Key::NitscheTheta | Key::NitscheGamma0 => m.space_name == "nitsche",
        Key::PenaltyGamma0 => m.space_name == "penalty",
        Key::NewmarkBeta => matches!(scheme, Scheme::Newmark(_) | Scheme::PaoliSchatzman(_)),
        Key::NewmarkGamma => matches!(scheme, Scheme::Newmark(_)),
        Key::ThetaScheme => matches!(scheme, Scheme::Theta(_) | Scheme::MoreauJean(_)),
        Key::Restitution => {
            matches!(scheme, Scheme::PaoliSchatzman(_) | Scheme::MoreauJean(_))
        }
        Key::RhoInf => matches!(
            scheme,
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams {
                preset: AlphaPreset::RhoInf(_),
                ..
            })
        ),
        Key::HhtAlpha => matches!(
            scheme,
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams {
                preset: AlphaPreset::Hht(_),
                ..
            })
        ),
        Key::MassWeights => m.mass_name == "weights",
        Key::ContactInit => init_matters,
        _ => true,
    };
    if ok {
        return Ok(());
    }
    Err(match k {
        Key::NitscheTheta | Key::NitscheGamma0 => "applies to space = nitsche only",
        Key::PenaltyGamma0 => "applies to space = penalty only",
        Key::NewmarkBeta => "applies to newmark and paoli-schatzman only",
        Key::NewmarkGamma => "applies to newmark only",
        Key::ThetaScheme => "applies to the theta scheme (and moreau-jean) only",
        Key::Restitution => "applies to paoli-schatzman (and moreau-jean) only",
        Key::RhoInf => "applies to generalized-alpha only",
        Key::HhtAlpha => "applies to hht only",
        Key::FrictionCoefficient => "applies to friction = coulomb only",
        Key::TrescaThreshold => "applies to friction = tresca only",
        Key::ContactInit => {
            if !m.mass.massless_contact() {
                "applies to a massless contact node only (mass = mod1/mod2/mod3/weights/zero-contact/singular-dynamic/node-neighbour)"
            } else if scene.fe_dim().is_some() {
                "changes nothing without gravity and the body load (the massless dofs carry no load: the quasi-static and interpolant starts coincide)"
            } else {
                "changes nothing in this scene (its contact nodes start at rest or in free flight, where the quasi-static and interpolant starts coincide)"
            }
        }
        _ => "applies to mass = weights only",
    })
}

/// Meaningless combinations (contract §3): why method `m` is no method at all, if it is not,
/// with the method keys whose values together make it so (for the refusal of a combination
/// the file fixes, [`refuse_meaningless`]).
fn meaningless(m: &Method) -> Option<(String, &'static [Key])> {
    const SCHEME_SPACE: &[Key] = &[Key::Scheme, Key::Space];
    const SCHEME_SPACE_MASS: &[Key] = &[Key::Scheme, Key::Space, Key::Mass];
    let (scheme, method) = (m.scheme, m.contact);
    let massless = m.mass.massless_contact();
    if matches!(scheme, Scheme::PaoliSchatzman(_)) && method != ContactMethod::Mixed {
        return Some((
            "paoli-schatzman is defined for space = mixed only".into(),
            SCHEME_SPACE,
        ));
    }
    if matches!(scheme, Scheme::Hybrid) && method == ContactMethod::Mixed && !massless {
        return Some((
            "hybrid with space = mixed needs a massless contact node (mod1/mod2/mod3/weights/zero-contact/singular-dynamic/node-neighbour)".into(),
            SCHEME_SPACE_MASS,
        ));
    }
    // contract §3.2: where each method of the comparison literature applies.
    let family = scheme.family();
    if matches!(
        scheme,
        Scheme::Kane | Scheme::ContactStabilizedNewmark | Scheme::MoreauJean(_)
    ) && method != ContactMethod::Mixed
    {
        return Some((
            format!("{family} is defined for space = mixed only"),
            SCHEME_SPACE,
        ));
    }
    if scheme.needs_contact_mass() && massless {
        return Some((
            format!("{family} needs inertia on the contact dof (mass = consistent or lumped)"),
            &[Key::Scheme, Key::Mass],
        ));
    }
    if scheme == Scheme::DiscreteGradient {
        match method {
            ContactMethod::Mixed => {
                return Some((
                    "discrete-gradient needs a contact potential (space = penalty, or nitsche with Θ = 1)".into(),
                    SCHEME_SPACE,
                ));
            }
            ContactMethod::Nitsche { theta, .. } if theta != 1.0 => {
                return Some((
                    "discrete-gradient with space = nitsche needs nitsche_theta = 1 (only then is the Nitsche term a potential)".into(),
                    &[Key::Scheme, Key::NitscheTheta],
                ));
            }
            _ => {}
        }
    }
    // Central difference with `mixed` and a diagonal mass: kinematic contact (contract §3.2).
    let kinematic = scheme == Scheme::Newmark(NewmarkParams::central_difference())
        && m.mass == MassVariant::Lumped;
    if scheme.is_explicit() && method == ContactMethod::Mixed && !massless && !kinematic {
        return Some((
            "an explicit scheme cannot enforce the multiplier constraint on a contact node with mass".into(),
            SCHEME_SPACE_MASS,
        ));
    }
    None
}

/// A meaningless method (`why`, from the keys `keys`) is one combination left out when one of
/// those keys varies along an axis or a search — the axis crosses values that do not go
/// together —, and a mistake in the file when none does: every run would be left out, so it
/// is refused at each key the file gives, with its line (a key left at its default is named in
/// the reason).
fn refuse_meaningless(given: &Given, why: String, keys: &[Key]) -> Outcome {
    let varies = |k: Key| given.on_axis(k) || given.origin(k).path.starts_with("search");
    if keys.iter().any(|&k| varies(k)) {
        return Outcome::Inapplicable(why);
    }
    let (set, defaulted): (Vec<Key>, Vec<Key>) = keys.iter().partition(|&&k| given.has(k));
    let values = |ks: &[Key]| -> String {
        ks.iter()
            .map(|&k| {
                let v = given.get(k).map_or_else(String::new, |v| v.to_string());
                format!("{} = {v}", k.name())
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut reason = format!("{} together make no method: {why}", values(keys));
    if !defaulted.is_empty() {
        reason.push_str(&format!(" ({} by default)", values(&defaulted)));
    }
    let at: Vec<Key> = if set.is_empty() { keys.to_vec() } else { set };
    Outcome::Invalid(
        at.iter()
            .map(|&k| Issue::at(&given.origin(k), reason.clone()))
            .collect(),
    )
}

/// The scene's physics values of a combination (a choice key's word as its index, a key not
/// given at its default). A physics value that rules out this scheme (the oscillator's dry
/// friction) is refused where the value is fixed, skipped as a meaningless combination across
/// an axis.
fn physics_of(given: &Given, scheme: &Scheme) -> Result<Physics, Outcome> {
    let scene = given.scene;
    let physics = physics_values(given);
    if let Err((key, why)) = scene.supports_physics(&physics, scheme) {
        let k = Key::from_name(key).expect("scenes name sweep keys");
        if given.on_axis(k) {
            return Err(Outcome::Inapplicable(why));
        }
        return Err(Outcome::Invalid(vec![Issue::at(&given.origin(k), why)]));
    }
    let issues = physics_magnitudes(given, &physics);
    if !issues.is_empty() {
        return Err(Outcome::Invalid(issues));
    }
    incline_without_gravity(given, &physics)?;
    Ok(physics)
}

/// The interface keys against the treatment and friction ([`Scene::supports_interface`]:
/// the blocks' `pairing`, `mortar_basis`, `interface_quadrature`, `mesh_ratio`): one
/// combination left out where any of the keys at stake varies along an axis or a search, a
/// mistake refused at each of them the file gives (the first at stake where it gives none).
fn interface_of(given: &Given, m: &Method, physics: &Physics) -> Result<(), Outcome> {
    let kinematic = m.scheme == Scheme::Newmark(NewmarkParams::central_difference())
        && m.mass == MassVariant::Lumped
        && m.contact == ContactMethod::Mixed;
    let method = InterfaceUse {
        space: &m.space_name,
        frictional: m.friction_kind != FrictionKind::None,
        kinematic,
    };
    let Err((names, why)) = given.scene.supports_interface(physics, method) else {
        return Ok(());
    };
    let keys: Vec<Key> = names
        .iter()
        .map(|n| Key::from_name(n).expect("scenes name sweep keys"))
        .collect();
    let varies = |k: Key| given.on_axis(k) || given.origin(k).path.starts_with("search");
    if keys.iter().any(|&k| varies(k)) {
        return Err(Outcome::Inapplicable(why));
    }
    let set: Vec<Key> = keys.iter().copied().filter(|&k| given.has(k)).collect();
    let at = if set.is_empty() { vec![keys[0]] } else { set };
    Err(Outcome::Invalid(
        at.iter()
            .map(|&k| Issue::at(&given.origin(k), why.clone()))
            .collect(),
    ))
}

/// The scene's physics keys as given (a choice key as its index), defaults elsewhere; not
/// yet checked.
fn physics_values(given: &Given) -> Physics {
    let scene = given.scene;
    Physics(
        scene
            .physics()
            .iter()
            .map(|k| {
                let key = Key::from_name(k.name).expect("scenes declare sweep keys");
                let word = |v: Value| {
                    let w = key.choices()?.iter().position(|c| Some(*c) == v.as_str())?;
                    Some(w as f64)
                };
                (
                    k.name,
                    given
                        .num(key)
                        .or_else(|| given.get(key).and_then(word))
                        .unwrap_or(k.default),
                )
            })
            .collect(),
    )
}

/// The largest kinetic energy density ½ρ|v⁰|² a run may start with (contract §7): √MAX / 1e6,
/// MAX the largest double. Every energy the engines report is a quadratic form of the state
/// summed over the body (vᵀMv, uᵀKu once the body has moved by v⁰t), and a run is stopped as
/// diverged above 1e6·energy_scale (`run::observe::DIVERGENCE_FACTOR`). Below this bound the
/// squares of the state and the divergence threshold stay representable with a margin of
/// √MAX for the body's size and the operators' entries; above it the first step can already
/// overflow (`velocity_tangential = 1e200` ended "non-finite value at step 0"). It allows any
/// physical speed: |v⁰| ≤ 1.6e74 at ρ = 1.
pub const MAX_KINETIC_DENSITY: f64 =
    1.3407807929942596e154 / crate::run::observe::DIVERGENCE_FACTOR;

/// Initial speeds whose energy the run could not represent ([`MAX_KINETIC_DENSITY`]), refused
/// at each velocity key the file gives: both components count, |v⁰|² = v_n² + v_t², with the
/// scene's density (the oscillator's point mass).
fn physics_magnitudes(given: &Given, physics: &Physics) -> Vec<Issue> {
    let value = |name: &str| physics.0.iter().find(|(n, _)| *n == name).map(|p| p.1);
    let keys = [Key::Velocity, Key::VelocityTangential];
    let speed = keys
        .iter()
        .filter_map(|k| value(k.name()))
        .fold(0.0, f64::hypot);
    let rho = value("density")
        .or_else(|| value("point_mass"))
        .unwrap_or(1.0);
    let density = 0.5 * rho * speed * speed;
    if density <= MAX_KINETIC_DENSITY {
        return Vec::new();
    }
    keys.iter()
        .filter(|k| given.has(**k) && value(k.name()).is_some_and(|v| v != 0.0))
        .map(|k| {
            Issue::at(
                &given.origin(*k),
                format!(
                    "{} = {:e} starts the body with a kinetic energy density ½ρ|v⁰|² = {density:.3e} (ρ = {rho}, |v⁰| = {speed:.3e}), above the {MAX_KINETIC_DENSITY:.3e} a run can represent: its energies (quadratic in the state, judged against 1e6·energy_scale) would overflow (contract §7)",
                    k.name(),
                    value(k.name()).unwrap_or(0.0),
                ),
            )
        })
        .collect()
}

/// `incline` tilts the volume load (contract §1.8): without gravity there is none, and the tilt
/// would change nothing. A mistake where both are fixed; one combination left out where
/// either varies along an axis.
fn incline_without_gravity(given: &Given, physics: &Physics) -> Result<(), Outcome> {
    let value = |name: &str| physics.0.iter().find(|(n, _)| *n == name).map(|p| p.1);
    let (Some(incline), Some(gravity)) = (value("incline"), value("gravity")) else {
        return Ok(());
    };
    if incline == 0.0 || gravity != 0.0 {
        return Ok(());
    }
    let why = format!(
        "incline = {incline} tilts the volume load, but gravity = 0{} for this run: without a load the tilt changes nothing; set gravity > 0 or drop incline",
        if given.has(Key::Gravity) {
            ""
        } else {
            " (the default)"
        }
    );
    if given.on_axis(Key::Incline) || given.on_axis(Key::Gravity) {
        return Err(Outcome::Inapplicable(why));
    }
    Err(Outcome::Invalid(vec![Issue::at(
        &given.origin(Key::Incline),
        why,
    )]))
}

/// `start = "static"` (contract §1.8) where the setup has no static state to start from
/// ([`crate::scene::SceneSetup::static_start_refusal`]): a mistake where the keys are fixed; one
/// combination left out across an axis.
fn static_start_of(given: &Given, why: Option<String>) -> Result<(), Outcome> {
    let Some(why) = why else {
        return Ok(());
    };
    let keys = [
        Key::Start,
        Key::Friction,
        Key::FrictionCoefficient,
        Key::TrescaThreshold,
    ];
    if keys.iter().any(|&k| given.on_axis(k)) {
        return Err(Outcome::Inapplicable(why));
    }
    Err(Outcome::Invalid(vec![Issue::at(
        &given.origin(Key::Start),
        why,
    )]))
}

/// A mesh scene's body: the file of the `mesh` key, read and validated before any run, with
/// the scene's setup of it (`obstacle` sets the gap it names in `physics`). Its problems join
/// `issues`.
fn read_mesh_file(
    sweep_dir: &Path,
    given: &Given,
    physics: &mut Physics,
    issues: &mut Vec<Issue>,
) -> (Option<MeshFile>, Option<FileSetup>) {
    let scene = given.scene;
    let mut mesh_file: Option<MeshFile> = None;
    let mut file_setup = None;
    for k in [Key::H, Key::Elements] {
        if let Some((_, o)) = given.user.get(&k) {
            issues.push(Issue::at(
                o,
                format!(
                    "scene {} takes its mesh from the `mesh` key (h is the file's largest element diameter), not from `{}`",
                    scene.name(),
                    k.name()
                ),
            ));
        }
    }
    match given.user.get(&Key::Mesh) {
        None => issues.push(Issue {
            line: None,
            key: "mesh".into(),
            reason: format!(
                "required: scene {} needs `mesh = \"FILE.msh\"` (a Gmsh MSH 4.1 file, relative to the sweep file) in [fixed], [grid] or [zip]",
                scene.name()
            ),
        }),
        Some((v, o)) => {
            let written = v.as_str().unwrap_or_default().to_string();
            // Absolute, so the runs find it from any working directory (a cluster job's).
            let joined = sweep_dir.join(&written);
            let path = std::path::absolute(&joined).unwrap_or(joined);
            let read = crate::space::fe::GmshMesh::read_shared(&path)
                .map_err(|e| Issue::at(o, e.to_string()))
                .and_then(|m| {
                    // `obstacle` is the gap under another name (contract §1.6).
                    if let Some(gap) = gap_from_obstacle(&m, &given.user)? {
                        physics.set("gap", gap);
                    }
                    Ok(m)
                });
            match read {
                Err(issue) => issues.push(issue),
                Ok(m) => match scene.setup_from_file(physics, &path, &m) {
                    Err(why) => issues.push(Issue::at(o, why)),
                    Ok((choice, setup)) => {
                        issues.extend(nitsche_friction_on_bodies_file(&m, given));
                        issues.extend(node_to_node_on_nonmatching_file(&m, given));
                        file_setup = Some((choice, setup));
                        mesh_file = Some((written, path, m));
                    }
                },
            }
        }
    }
    (mesh_file, file_setup)
}

/// Friction with `space = nitsche` on a two-body file: the file's interface points
/// (`run::fe::nitsche_interface`) carry no tangential rows yet — the relative slip's Nitsche
/// rows are built on the matching blocks only.
fn nitsche_friction_on_bodies_file(m: &crate::space::fe::GmshMesh, given: &Given) -> Option<Issue> {
    let (v, _) = given.user.get(&Key::Space)?;
    let (f, o) = given.user.get(&Key::Friction)?;
    let frictional = f.as_str().is_some_and(|f| f != "none");
    (m.bodies.is_some() && v.as_str() == Some("nitsche") && frictional).then(|| {
        Issue::at(
            o,
            format!(
                "friction with space = nitsche on the two-body mesh {}: the relative slip's Nitsche rows are built for blocks2d/blocks3d with a matching interface only (mixed and penalty take friction on a file)",
                m.file
            ),
        )
    })
}

/// `pairing = "node-to-node"` (the default) with `mixed` or `penalty` on a two-body file whose
/// interface does not match node to node (issue 45): refused at `pairing` (or at `mesh` where
/// the sweep gives no pairing), naming the node at fault and the keys that take the file.
fn node_to_node_on_nonmatching_file(
    m: &crate::space::fe::GmshMesh,
    given: &Given,
) -> Option<Issue> {
    let why = m.bodies.as_ref()?.unmatched.as_ref()?;
    let space = given.get(Key::Space);
    if space.as_ref().and_then(|v| v.as_str()) == Some("nitsche") {
        return None;
    }
    let pairing = given.get(Key::Pairing);
    let word = pairing
        .as_ref()
        .and_then(|v| v.as_str())
        .unwrap_or("node-to-node");
    (word == "node-to-node").then(|| {
        let key = if given.has(Key::Pairing) {
            Key::Pairing
        } else {
            Key::Mesh
        };
        Issue::at(
            &given.origin(key),
            format!(
                "{}: {why}; pairing = \"{word}\" needs every Γ^a node above a Γ^b node: set `pairing` to \"node-to-segment\" or \"mortar\" (or space = \"nitsche\") for a non-matching interface",
                m.file
            ),
        )
    })
}

/// The mesh: a mesh file's (`from_file`), else from `h` or `elements` (one of the two), else
/// the scene's default; a missing or refused size joins `issues`.
fn mesh_of(
    given: &Given,
    physics: &Physics,
    from_file: Option<MeshChoice>,
    issues: &mut Vec<Issue>,
) -> Option<MeshChoice> {
    let scene = given.scene;
    match (given.user.get(&Key::H), given.user.get(&Key::Elements)) {
        _ if from_file.is_some() => from_file,
        (Some(_), Some((_, o))) => {
            issues.push(Issue::at(o, "give either h or elements, not both"));
            None
        }
        (Some((v, o)), None) => match scene.mesh_from_h(physics, v.as_f64().unwrap()) {
            Ok(m) => Some(m),
            Err(why) => {
                issues.push(Issue::at(o, why));
                None
            }
        },
        (None, Some((v, o))) => match v {
            Value::Int(i) => match scene.mesh_from_elements(physics, *i as usize) {
                Ok(m) => Some(m),
                Err(why) => {
                    issues.push(Issue::at(o, why));
                    None
                }
            },
            _ => None,
        },
        (None, None) if scene.default_mesh().is_some() => scene.default_mesh(),
        (None, None) => {
            issues.push(Issue {
                line: None,
                key: "h".into(),
                reason:
                    "required: the mesh size h (or elements) is not set in [fixed], [grid] or [zip]"
                        .into(),
            });
            None
        }
    }
}

/// The time step: `dt`, or `courant` ν as dt = ν h / c0 (one of the two); a missing one joins
/// `issues`.
fn dt_of(given: &Given, h: Option<f64>, c0: f64, issues: &mut Vec<Issue>) -> Option<f64> {
    match (given.user.get(&Key::Dt), given.user.get(&Key::Courant), h) {
        (Some(_), Some((_, o)), _) => {
            issues.push(Issue::at(o, "give either dt or courant, not both"));
            None
        }
        (Some((v, _)), None, _) => v.as_f64(),
        (None, Some((v, _)), Some(h)) => v.as_f64().map(|nu| nu * h / c0),
        (None, Some(_), None) => None,
        (None, None, _) => {
            issues.push(Issue {
                line: None,
                key: "dt".into(),
                reason:
                    "required: the time step dt (or courant) is not set in [fixed], [grid] or [zip]"
                        .into(),
            });
            None
        }
    }
}

/// The number of steps to T: T/dt when whole within round-off, else rounded up; refused
/// outside 1 … 1e8 (at `dt_origin`).
fn steps_of(t_final: f64, dt: f64, dt_origin: &Origin) -> Result<usize, Outcome> {
    let ratio = t_final / dt;
    let steps = if (ratio - ratio.round()).abs() <= 1e-9 * ratio {
        ratio.round() as usize
    } else {
        ratio.ceil() as usize
    };
    if steps == 0 || steps > 100_000_000 {
        return Err(Outcome::Invalid(vec![Issue::at(
            dt_origin,
            format!("T/dt = {ratio:.3e} steps is out of range (1 … 1e8)"),
        )]));
    }
    Ok(steps)
}

/// The step solver (contract §4) is the finite-element engine's choice (`fe`); the 1D engines
/// solve tridiagonal systems, and drop the keys.
fn solver_of(given: &Given, fe: bool, dropped: &mut Vec<String>) -> Solver {
    let solver = match given.get(Key::Solver).as_ref().and_then(Value::as_str) {
        Some("cg") if fe => Solver::Cg {
            tol: given.num(Key::CgTol).expect("cg_tol has a default"),
        },
        _ => Solver::Direct,
    };
    if given.has(Key::Solver) && !fe {
        dropped.push(
            "solver applies to the finite-element scenes only (their sparse step matrix)".into(),
        );
    }
    if given.has(Key::CgTol) && solver == Solver::Direct {
        dropped.push("cg_tol applies to solver = cg only".into());
    }
    solver
}

/// Memory before anything is built (the CFL check assembles the operators): a run above
/// `limits.max_run_bytes` is refused at the key whose change cures it, with the cure.
fn check_memory(
    given: &Given,
    limits: &PlanLimits,
    config: &RunConfig,
    fe: bool,
    solver: Solver,
) -> Result<(), Outcome> {
    let Some(budget) = limits.max_run_bytes else {
        return Ok(());
    };
    let series_every = limits.series_every.unwrap_or(1);
    let est = config.estimate(series_every);
    if est.bytes() > budget {
        let mesh_key = if given.scene.takes_mesh_file() {
            Key::Mesh
        } else if given.has(Key::Elements) {
            Key::Elements
        } else {
            Key::H
        };
        // Fewer unknowns is the cure: fewer elements, a larger h, a coarser mesh file.
        let advice = match mesh_key {
            Key::Mesh => "use a coarser mesh file".to_string(),
            Key::Elements => "lower `elements`".to_string(),
            _ => "raise `h`".to_string(),
        };
        let (at, advice) = if est.state_bytes >= est.series_bytes {
            // Without a factor the same run may fit: say so, with its figure.
            let cg = (fe && solver == Solver::Direct).then(|| {
                config
                    .clone()
                    .with_solver(Solver::Cg {
                        tol: Solver::DEFAULT_CG_TOL,
                    })
                    .estimate(series_every)
                    .bytes()
            });
            let advice = match cg {
                Some(b) => format!(
                    "{advice}, or set solver = \"cg\" (conjugate gradient, no factor: an estimated {}{})",
                    human_bytes(b),
                    if b > budget {
                        ", also above the budget"
                    } else {
                        ""
                    }
                ),
                None => advice,
            };
            (given.origin(mesh_key), advice)
        } else {
            (
                Origin {
                    path: "series_every".into(),
                    line: None,
                },
                format!(
                    "raise `series_every` (now {series_every}) or `dt` ({} steps)",
                    config.steps()
                ),
            )
        };
        return Err(Outcome::Invalid(vec![Issue::at(
            &at,
            format!(
                "the run needs an estimated {} ({:.3e} unknowns, {} steps: {} of operators and state, {} of kept series), above the per-run memory budget of {} (--max-run-memory): {advice}",
                human_bytes(est.bytes()),
                est.unknowns,
                config.steps(),
                human_bytes(est.state_bytes),
                human_bytes(est.series_bytes),
                human_bytes(budget),
            ),
        )]));
    }
    Ok(())
}

/// A run's columns (`params`) and the canonical text of its id (`canonical`): a parameter
/// enters the text when it is always part of the identity or differs from its default.
struct Columns {
    scene: &'static dyn Scene,
    params: BTreeMap<Key, Value>,
    canonical: BTreeMap<Key, String>,
}

impl Columns {
    fn new(scene: &'static dyn Scene) -> Columns {
        Columns {
            scene,
            params: BTreeMap::new(),
            canonical: BTreeMap::new(),
        }
    }

    fn put(&mut self, k: Key, v: Value, always: bool) {
        let is_default = default_of(self.scene, k).is_some_and(|d| same(&d, &v));
        if always || !is_default {
            self.canonical.insert(k, v.canonical());
        }
        self.params.insert(k, v);
    }

    /// The method's keys: space, mass and scheme family, and the parameters of each.
    fn put_method(&mut self, m: &Method, contact_init: ContactInit, init_matters: bool) {
        self.put(Key::Space, Value::Str(m.space_name.clone()), false);
        self.put(Key::Mass, Value::Str(m.mass_name.clone()), false);
        self.put(Key::Scheme, Value::Str(m.scheme.family().into()), true);
        if let MassVariant::Weights(w) = &m.mass {
            self.put(Key::MassWeights, Value::List(w.clone()), true);
        }
        if init_matters {
            let v = Value::Str(contact_init.name().into());
            if contact_init == ContactInit::Interpolant && self.scene.fe_dim().is_some() {
                // An FE run's u⁰ = 0 start is what ran under its id before the key applied
                // there (issue 42): the id stays (its column says which start it made).
                self.params.insert(Key::ContactInit, v);
            } else {
                self.put(Key::ContactInit, v, false);
            }
        }
        match m.contact {
            ContactMethod::Nitsche { theta, gamma0 } => {
                self.put(Key::NitscheTheta, Value::Num(theta), false);
                self.put(Key::NitscheGamma0, Value::Num(gamma0), true);
            }
            ContactMethod::Penalty { gamma0 } => {
                self.put(Key::PenaltyGamma0, Value::Num(gamma0), true)
            }
            ContactMethod::Mixed => {}
        }
        match m.scheme {
            Scheme::Newmark(p) => {
                self.put(Key::NewmarkBeta, Value::Num(p.beta), false);
                self.put(Key::NewmarkGamma, Value::Num(p.gamma), false);
            }
            Scheme::Theta(p) => self.put(Key::ThetaScheme, Value::Num(p.theta), true),
            Scheme::PaoliSchatzman(p) => {
                self.put(Key::NewmarkBeta, Value::Num(p.beta), false);
                self.put(Key::Restitution, Value::Num(p.restitution), false);
            }
            Scheme::Hybrid
            | Scheme::Kane
            | Scheme::ContactStabilizedNewmark
            | Scheme::DiscreteGradient => {}
            // New schemes: their parameters always in the id (their defaults are their own).
            Scheme::GeneralizedAlpha(p) => match p.preset {
                AlphaPreset::RhoInf(r) => self.put(Key::RhoInf, Value::Num(r), true),
                AlphaPreset::Hht(a) => self.put(Key::HhtAlpha, Value::Num(a), true),
            },
            Scheme::MoreauJean(p) => {
                self.put(Key::ThetaScheme, Value::Num(p.theta), true);
                self.put(Key::Restitution, Value::Num(p.restitution), true);
            }
        }
    }

    /// The scene's physics values. `load` says how gravity enters (contract §1.3): without
    /// gravity it changes nothing, so it is no parameter of the run (null column, never in
    /// the id) and both values are one run.
    fn put_physics(&mut self, given: &Given, physics: &Physics, dropped: &mut Vec<String>) {
        let weightless = physics.0.iter().any(|(n, g)| *n == "gravity" && *g == 0.0);
        for (name, value) in &physics.0 {
            let key = Key::from_name(name).unwrap();
            // A key whose default is "not given" (NaN: B's material on the blocks, the
            // two-body keys of a mesh file) has no column and no part in the id.
            if value.is_nan() {
                continue;
            }
            if key == Key::Load && weightless {
                if given.has(Key::Load) {
                    dropped.push("load applies only with gravity ≠ 0".into());
                }
                continue;
            }
            self.put(key, physics_value(key, *value), false);
        }
    }

    /// The friction column where a law can act (null on the scenes that take none); `none`
    /// is the default and never enters the id.
    fn put_friction(&mut self, m: &Method) {
        if self.scene.supports_friction().is_ok() {
            self.put(
                Key::Friction,
                Value::Str(m.friction_kind.name().into()),
                false,
            );
        }
        match m.friction {
            FrictionLaw::None => {}
            FrictionLaw::Coulomb { coefficient } => {
                self.put(Key::FrictionCoefficient, Value::Num(coefficient), true)
            }
            FrictionLaw::Tresca { threshold } => {
                self.put(Key::TrescaThreshold, Value::Num(threshold), true)
            }
        }
    }

    /// `direct` is the default: its runs keep the ids they had before the key existed.
    fn put_solver(&mut self, solver: Solver, fe: bool) {
        match solver {
            Solver::Cg { tol } => {
                self.put(Key::Solver, Value::Str(solver.name().into()), false);
                self.put(Key::CgTol, Value::Num(tol), false);
            }
            Solver::Direct if fe => self.put(Key::Solver, Value::Str(solver.name().into()), false),
            Solver::Direct => {}
        }
    }

    /// The mesh file: its content is its identity (a moved or renamed file keeps its runs'
    /// ids), the column shows the path as written. Derived, not part of the identity: a mesh
    /// run's plane x_d = `obstacle` whether the sweep gave it or `gap` (contract §1.6), so
    /// filters and the plan table see both.
    fn put_mesh_file(&mut self, mesh_file: Option<&MeshFile>, physics: &Physics) {
        if let Some((written, _, m)) = mesh_file {
            self.canonical
                .insert(Key::Mesh, format!("sha256:{}", m.content_hash));
            self.params.insert(Key::Mesh, Value::Str(written.clone()));
        }
        if let Some((_, _, m)) = mesh_file
            && let Some(floor) = m.contact_floor()
        {
            self.params
                .insert(Key::Obstacle, Value::Num(floor - physics.get("gap")));
        }
    }
}

/// A run's label: `space · mass · scheme[ · friction]`, each with its parameters.
fn run_label(m: &Method, contact_init: ContactInit, scheme_label: &str) -> String {
    let space_label = match m.contact {
        ContactMethod::Mixed => "mixed".to_string(),
        ContactMethod::Nitsche { theta, gamma0 } => format!("nitsche(Θ={theta}, γ0={gamma0:e})"),
        ContactMethod::Penalty { gamma0 } => format!("penalty(γ0={gamma0:e})"),
    };
    let mass_label = match &m.mass {
        MassVariant::Weights(w) => format!(
            "weights[{}]",
            w.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(",")
        ),
        other => other.name().to_string(),
    };
    let mass_label = match (m.mass.massless_contact(), contact_init) {
        (true, ContactInit::Interpolant) => format!("{mass_label} (interpolant start)"),
        _ => mass_label,
    };
    let friction_label = match m.friction {
        FrictionLaw::None => String::new(),
        FrictionLaw::Coulomb { coefficient } => format!(" · coulomb(μ_f={coefficient})"),
        FrictionLaw::Tresca { threshold } => format!(" · tresca(s={threshold})"),
    };
    format!("{space_label} · {mass_label} · {scheme_label}{friction_label}")
}

/// Whether an exclude filter matches a resolved run.
fn matches_filter(filter: &[Entry], r: &Resolved) -> bool {
    filter.iter().all(|e| match (e.key, &e.value) {
        (Key::Scheme, Value::Str(s)) => {
            r.scheme_names.contains(s)
                || resolve_scheme_alias(s).is_some_and(|lab| r.scheme_names[1] == lab)
        }
        (Key::H, v) => r.params.get(&Key::H).is_some_and(|x| same(x, v)),
        (Key::Courant, v) => r.params.get(&Key::Courant).is_some_and(|x| same(x, v)),
        (k, v) => r.params.get(&k).is_some_and(|x| same(x, v)),
    })
}

fn resolve_scheme_alias(name: &str) -> Option<&'static str> {
    match name {
        "crank-nicolson" => Some("crank-nicolson"),
        "newmark-dissipative" => Some("newmark-dissipative"),
        "central-difference" => Some("central-difference"),
        "backward-euler" => Some("backward-euler"),
        _ => None,
    }
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// The reference run of one combination: its entries overridden by `reference = {…}` (keys not
/// given are the run's; a reference giving h or elements replaces both, likewise dt or
/// courant, gap or obstacle). Returns the reference's spec and the run's (space, time) refinement ratios; the
/// reference must be nested in time (dt_run/dt_ref whole) and last as long; in space nested
/// (h_run/h_ref whole) where the scene's meshes are, otherwise at least as fine, stored whole
/// and interpolated at the run's nodes (contract §1.6).
///
/// `reference = { scene = …, … }` (a mesh file's body against the built-in scene it meshes):
/// the reference is resolved as a run of that scene, with the run's keys that scene accepts
/// (not `mesh` nor `velocity`); its physics (density, Lamé constants, gap, gravity, initial
/// velocity) must be the run's, or the errors would compare two problems.
fn reference_of(
    sweep: &SweepFile,
    limits: &PlanLimits,
    entries: &[&Entry],
    over: &[Entry],
    run: &Resolved,
) -> Result<(RunSpec, usize, usize), Vec<Issue>> {
    // Keys that name one thing two ways: a reference giving either replaces both.
    let pairs = [
        [Key::H, Key::Elements],
        [Key::Dt, Key::Courant],
        [Key::Gap, Key::Obstacle],
    ];
    let replaced = |k: Key| {
        over.iter().any(|o| o.key == k)
            || pairs
                .iter()
                .any(|p| p.contains(&k) && over.iter().any(|o| p.contains(&o.key)))
    };
    let mut combined: Vec<&Entry> = entries
        .iter()
        .copied()
        .filter(|e| !replaced(e.key))
        .collect();
    let ref_scene = sweep.reference_scene.unwrap_or(sweep.scene);
    let other_scene = ref_scene != sweep.scene;
    if other_scene {
        combined.retain(|e| super::accepted(ref_scene, e.key));
    }
    combined.extend(over.iter());
    let r = match resolve(sweep_dir(sweep), ref_scene, &combined, false, limits) {
        Outcome::Run(r) => r,
        Outcome::Inapplicable(why) => {
            return Err(vec![Issue::at(
                &reference_origin(over, &[Key::H, Key::Elements, Key::Mesh]),
                format!("the reference run is meaningless: {why}"),
            )]);
        }
        Outcome::Invalid(is) => {
            return Err(is
                .into_iter()
                .map(|i| Issue {
                    reason: format!("in the reference run: {}", i.reason),
                    ..i
                })
                .collect());
        }
    };
    if other_scene {
        same_problem(sweep, ref_scene, run, &r)?;
    }
    // Meshes that are not nested: any reference at least as fine, stored whole (stride 1).
    let nested = !other_scene && sweep.scene.get().nested_meshes();
    let (sx, st) = strides(over, nested, run, &r)?;
    let id = r.id(ref_scene, "");
    let spec = RunSpec {
        run_id: id,
        superseded_id: r.superseded_id(ref_scene, "", false),
        label: if other_scene {
            format!("reference: {} {}", ref_scene.name(), r.label)
        } else {
            format!("reference: {}", r.label)
        },
        params: r.params.clone(),
        scheme_label: r.scheme_label.clone(),
        config: r.config.clone(),
        repeats: 1,
        sample: None,
        scene: ref_scene,
        reference: None,
        search: None,
    };
    Ok((spec, sx, st))
}

/// Where a reference problem is reported: the first of `keys` the reference gives, else
/// `reference`.
fn reference_origin(over: &[Entry], keys: &[Key]) -> Origin {
    over.iter()
        .find(|e| keys.contains(&e.key))
        .map(|e| e.origin.clone())
        .unwrap_or(Origin {
            path: "reference".into(),
            line: None,
        })
}

/// A reference of another scene (`ref_scene`) must pose the run's problem: the same
/// density, Lamé constants, gap, gravity and initial velocity, or the errors would compare
/// two problems.
fn same_problem(
    sweep: &SweepFile,
    ref_scene: SceneKind,
    run: &Resolved,
    r: &Resolved,
) -> Result<(), Vec<Issue>> {
    if let (RunConfig::Fe(a), RunConfig::Fe(b)) = (&run.config, &r.config) {
        let (a, b) = (&a.setup, &b.setup);
        let differ: Vec<String> = [
            ("density", a.density, b.density),
            ("lame_lambda", a.lame_lambda, b.lame_lambda),
            ("lame_mu", a.lame_mu, b.lame_mu),
            ("gap", a.gap, b.gap),
            ("gravity", a.gravity, b.gravity),
            ("velocity", a.v0, b.v0),
        ]
        .into_iter()
        .filter(|(_, x, y)| (x - y).abs() > 1e-12 * x.abs().max(y.abs()))
        .map(|(name, x, y)| format!("{name} = {x} in the run, {y} in the reference"))
        .collect();
        if !differ.is_empty() {
            return Err(vec![Issue::at(
                &Origin {
                    path: "reference.scene".into(),
                    line: None,
                },
                format!(
                    "the reference (scene {}) is another problem than the run (scene {}): {}",
                    ref_scene.name(),
                    sweep.scene.name(),
                    differ.join(", ")
                ),
            )]);
        }
    }
    Ok(())
}

/// The run's (space, time) refinement ratios against its reference `r`: the reference must be
/// nested in time (dt_run/dt_ref whole) and last as long; in space nested (h_run/h_ref whole)
/// where the meshes are (`nested`), otherwise at least as fine (stride 1).
fn strides(
    over: &[Entry],
    nested: bool,
    run: &Resolved,
    r: &Resolved,
) -> Result<(usize, usize), Vec<Issue>> {
    let at = |keys: &[Key]| reference_origin(over, keys);
    let step_keys = [Key::Dt, Key::Courant];
    let ratio = |coarse: f64, fine: f64| {
        let q = coarse / fine;
        let n = q.round();
        (n >= 1.0 && (q - n).abs() <= 1e-9 * n).then_some(n as usize)
    };
    if !nested && r.h > run.h * (1.0 + 1e-12) {
        return Err(vec![Issue::at(
            &at(&[Key::H, Key::Elements, Key::Mesh]),
            format!(
                "the reference mesh (h = {}) is coarser than the run's (h = {})",
                r.h, run.h
            ),
        )]);
    }
    let sx = if nested { ratio(run.h, r.h) } else { Some(1) };
    let sx = sx.ok_or_else(|| {
        vec![Issue::at(
            &at(&[Key::H, Key::Elements, Key::Mesh]),
            format!(
                "the reference mesh (h = {}) is not nested in the run's (h = {}): h_run/h_ref = {} must be a whole number ≥ 1",
                r.h,
                run.h,
                run.h / r.h
            ),
        )]
    })?;
    let st = ratio(run.dt, r.dt).ok_or_else(|| {
        vec![Issue::at(
            &at(&step_keys),
            format!(
                "the reference step (dt = {}) does not divide the run's (dt = {}): dt_run/dt_ref = {} must be a whole number ≥ 1",
                r.dt,
                run.dt,
                run.dt / r.dt
            ),
        )]
    })?;
    if r.t_final < run.t_final * (1.0 - 1e-12) {
        return Err(vec![Issue::at(
            &at(&[Key::T]),
            format!(
                "the reference run ends at T = {} before the run (T = {})",
                r.t_final, run.t_final
            ),
        )]);
    }
    Ok((sx, st))
}

impl Resolved {
    /// The run's id: its canonical parameters, its definition revisions, then `extra`
    /// (ensemble member, reference).
    fn id(&self, scene: SceneKind, extra: &str) -> String {
        run_id(scene, &self.canonical, &format!("{}{extra}", self.revision))
    }

    /// The id before the definition changes of its revision lines (with `old_extra`, whose
    /// reference is the reference's own superseded id); None when neither the run nor its
    /// reference changed.
    fn superseded_id(
        &self,
        scene: SceneKind,
        old_extra: &str,
        reference_changed: bool,
    ) -> Option<String> {
        (!self.revision.is_empty() || reference_changed).then(|| {
            run_id(
                scene,
                &self.canonical,
                &format!("{}{old_extra}", self.revision_before),
            )
        })
    }
}

/// Hash of the canonical text.
pub fn run_id(scene: SceneKind, canonical: &BTreeMap<Key, String>, extra: &str) -> String {
    let mut text = format!("contact-sweep/run/v1\nscene={}\n", scene.name());
    for (k, v) in canonical {
        let _ = writeln!(text, "{}={v}", k.name());
    }
    text.push_str(extra);
    let digest = Sha256::digest(text.as_bytes());
    digest[..8].iter().map(|b| format!("{b:02x}")).collect()
}

/// What the planner refuses before expanding or running anything.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanLimits {
    /// Most combinations a plan may have (counted before filters and merging).
    pub max_runs: u64,
    /// Most bytes one run may need (its [`crate::run::estimate::Estimate`]); `None`: no check.
    pub max_run_bytes: Option<f64>,
    /// The series decimation the runs will use (the sweep's `series_every` unless overridden).
    pub series_every: Option<usize>,
    /// Most bytes the expanded plan may hold ([`PLAN_BYTES_PER_RUN`] per combination);
    /// `None`: no check.
    pub max_plan_bytes: Option<f64>,
}

/// Memory of a plan per combination: its spec, parameters, label and id, and the row of the
/// printed plan table (measured: `plan` of 2·10⁵ runs peaks at 500 MB).
pub const PLAN_BYTES_PER_RUN: f64 = 2560.0;

/// The default plan-size limit: ten million runs (a plan holds about 1 KiB per run).
pub const DEFAULT_MAX_RUNS: u64 = 10_000_000;

impl Default for PlanLimits {
    fn default() -> Self {
        PlanLimits {
            max_runs: DEFAULT_MAX_RUNS,
            max_run_bytes: None,
            series_every: None,
            max_plan_bytes: None,
        }
    }
}

/// The size of a plan, computed from the parsed file without expanding it: the product of
/// the axis lengths (zipped lists count once) times the ensemble samples. In u128, saturating:
/// thirteen axes of 1000 values already exceed it, and the count only decides a refusal.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSize {
    pub combinations: u128,
    /// (axis as written, its length), the zipped lists first.
    pub axes: Vec<(String, usize)>,
}

impl PlanSize {
    pub fn of(sweep: &SweepFile) -> PlanSize {
        let mut axes: Vec<(String, usize)> = Vec::new();
        if let Some(z) = &sweep.zip {
            let names = z
                .name
                .split('+')
                .map(|n| format!("zip.{n}"))
                .collect::<Vec<_>>()
                .join("+");
            axes.push((names, z.items.len()));
        }
        axes.extend(
            sweep
                .grid
                .iter()
                .map(|a| (format!("grid.{}", a.name), a.items.len())),
        );
        if let Some(e) = sweep.ensemble {
            axes.push(("ensemble.samples".into(), e.samples));
        }
        if sweep.search.is_some() {
            // Every combination becomes the two bracket probes of a search.
            axes.push(("search (2 probes)".into(), 2));
        }
        let combinations = axes
            .iter()
            .fold(1u128, |p, (_, n)| p.saturating_mul(*n as u128));
        PlanSize { combinations, axes }
    }

    /// "grid.a (1000) × grid.b (1000)".
    pub fn describe(&self) -> String {
        self.axes
            .iter()
            .map(|(a, n)| format!("{a} ({n})"))
            .collect::<Vec<_>>()
            .join(" × ")
    }
}

/// Expand a checked sweep file into its plan with the default limits (no memory check).
pub fn expand(sweep: &SweepFile) -> Result<Plan, SweepError> {
    expand_with(sweep, &PlanLimits::default())
}

/// Expand a checked sweep file into its plan. The plan's size is checked first, from the file
/// alone (a plan above `limits.max_runs` is refused before anything is allocated for it);
/// errors found in any combination are reported together, once each, before anything runs.
pub fn expand_with(sweep: &SweepFile, limits: &PlanLimits) -> Result<Plan, SweepError> {
    let limits = &PlanLimits {
        series_every: Some(limits.series_every.unwrap_or(sweep.series_every)),
        ..*limits
    };
    check_size(sweep, limits)?;
    let mut axes: Vec<&Axis> = Vec::new();
    if let Some(z) = &sweep.zip {
        axes.push(z);
    }
    axes.extend(sweep.grid.iter());
    let sizes: Vec<usize> = axes.iter().map(|a| a.items.len()).collect();
    let combinations: usize = sizes.iter().product();
    let combos = combinations_of(sweep, &axes, &sizes, combinations);
    let (work, mut searches) = search_work(sweep, limits, combos);
    let allow_unstable = sweep.allow_unstable || sweep.search.is_some();
    let mut ex = Expansion::default();
    for (owned, search) in &work {
        let entries: Vec<&Entry> = owned.iter().collect();
        let outcome = resolve(
            sweep_dir(sweep),
            sweep.scene,
            &entries,
            allow_unstable,
            limits,
        );
        ex.add(sweep, limits, &entries, search, outcome);
    }
    let Expansion {
        runs,
        mut issues,
        excluded_by_filter,
        inapplicable,
        collapsed,
        references,
        ..
    } = ex;
    // A base none of whose probes is a run (meaningless, excluded) is no search.
    searches.retain(|b| runs.iter().any(|r| r.search.as_deref() == Some(&b.tag)));
    if !issues.is_empty() {
        issues.sort();
        issues.dedup();
        return Err(SweepError::Invalid {
            file: sweep.path.clone(),
            issues,
            sets: sweep.sets.clone(),
        });
    }
    if runs.is_empty() {
        return Err(SweepError::Invalid {
            file: sweep.path.clone(),
            sets: sweep.sets.clone(),
            issues: vec![Issue {
                line: None,
                key: "grid".into(),
                reason: format!(
                    "the sweep expands to no runs ({combinations} combinations: {excluded_by_filter} excluded by filters, {} inapplicable)",
                    inapplicable.values().sum::<usize>()
                ),
            }],
        });
    }
    Ok(Plan {
        sweep: sweep.clone(),
        limits: *limits,
        runs,
        combinations,
        excluded_by_filter,
        inapplicable,
        collapsed,
        references,
        searches,
    })
}

/// The plan's size, checked from the file alone: a plan above `limits.max_runs` (or above
/// the memory a plan may hold) is refused before anything is allocated for it, at its longest
/// axis.
fn check_size(sweep: &SweepFile, limits: &PlanLimits) -> Result<(), SweepError> {
    let size = PlanSize::of(sweep);
    let plan_bytes = size.combinations as f64 * PLAN_BYTES_PER_RUN;
    let too_big = limits.max_plan_bytes.is_some_and(|b| plan_bytes > b);
    if size.combinations > limits.max_runs as u128 || too_big {
        let count = if size.combinations == u128::MAX {
            "more than 3.4e38".to_string()
        } else {
            format!("{} ({:.1e})", size.combinations, size.combinations as f64)
        };
        let (key, line) = sweep
            .grid
            .iter()
            .chain(sweep.zip.iter())
            .max_by_key(|a| a.items.len())
            .map(|a| {
                let line = a.items.iter().flatten().find_map(|e| e.origin.line);
                let section = if sweep.zip.as_ref().is_some_and(|z| z.name == a.name) {
                    "zip"
                } else {
                    "grid"
                };
                (format!("{section}.{}", a.name), line)
            })
            .unwrap_or(("ensemble.samples".into(), None));
        return Err(SweepError::Invalid {
            file: sweep.path.clone(),
            sets: sweep.sets.clone(),
            issues: vec![Issue {
                line,
                key,
                reason: if size.combinations > limits.max_runs as u128 {
                    format!(
                        "the sweep has {count} combinations ({}), above the limit of {} runs; shorten the axes, or raise the limit with --max-runs N",
                        size.describe(),
                        limits.max_runs
                    )
                } else {
                    format!(
                        "the sweep has {count} combinations ({}): its plan would hold about {} in memory, more than the {} available to it; split the sweep into several files",
                        size.describe(),
                        human_bytes(plan_bytes),
                        human_bytes(limits.max_plan_bytes.unwrap_or(0.0))
                    )
                },
            }],
        });
    }
    Ok(())
}

/// The entries of every combination: [fixed], then one item of each axis; the first axis
/// (the zipped lists, if any) varies slowest, the last fastest.
fn combinations_of(
    sweep: &SweepFile,
    axes: &[&Axis],
    sizes: &[usize],
    combinations: usize,
) -> Vec<Vec<Entry>> {
    let mut out = Vec::new();
    let mut idx = vec![0usize; axes.len()];
    for _ in 0..combinations {
        let mut entries: Vec<Entry> = sweep.fixed.clone();
        for (a, &i) in axes.iter().zip(&idx) {
            entries.extend(a.items[i].iter().cloned());
        }
        out.push(entries);
        for d in (0..idx.len()).rev() {
            idx[d] += 1;
            if idx[d] < sizes[d] {
                break;
            }
            idx[d] = 0;
        }
    }
    out
}

/// The combinations to resolve, each with the tag of its search (probes only).
type Work = Vec<(Vec<Entry>, Option<String>)>;

/// The combinations to resolve, each with its search tag: as they are, or — with a
/// `[search]` — every combination a base and its two bracket probes (lo, hi).
fn search_work(
    sweep: &SweepFile,
    limits: &PlanLimits,
    combos: Vec<Vec<Entry>>,
) -> (Work, Vec<SearchBase>) {
    let mut searches: Vec<SearchBase> = Vec::new();
    let mut work: Work = Vec::new();
    for entries in combos {
        match &sweep.search {
            None => work.push((entries, None)),
            Some(sr) => {
                let base = searches.len();
                let tag = search_tag(sr, base);
                let label = match resolve(
                    sweep_dir(sweep),
                    sweep.scene,
                    &probe_entries(&entries, sr.key, sr.lo)
                        .iter()
                        .collect::<Vec<_>>(),
                    true,
                    limits,
                ) {
                    Outcome::Run(r) => r.label.clone(),
                    _ => String::new(),
                };
                // Bases that are meaningless or excluded are dropped with their probes below.
                for v in [sr.lo, sr.hi] {
                    work.push((probe_entries(&entries, sr.key, v), Some(tag.clone())));
                }
                searches.push(SearchBase {
                    index: base,
                    label,
                    entries,
                    tag,
                });
            }
        }
    }
    (work, searches)
}

/// What the expansion gathers, combination by combination: the runs (by id, the first of
/// identical ones), the problems, the combinations left out (by reason) and the reference
/// runs.
#[derive(Default)]
struct Expansion {
    runs: Vec<RunSpec>,
    seen: HashMap<String, usize>,
    issues: Vec<Issue>,
    excluded_by_filter: usize,
    inapplicable: BTreeMap<String, usize>,
    collapsed: BTreeMap<String, usize>,
    references: Vec<ReferencePlan>,
}

impl Expansion {
    /// One resolved combination: refused, left out, excluded by a filter, or its runs (with
    /// their reference) added.
    fn add(
        &mut self,
        sweep: &SweepFile,
        limits: &PlanLimits,
        entries: &[&Entry],
        search: &Option<String>,
        outcome: Outcome,
    ) {
        match outcome {
            Outcome::Invalid(mut is) => self.issues.append(&mut is),
            Outcome::Inapplicable(why) => *self.inapplicable.entry(why).or_default() += 1,
            Outcome::Run(r) => {
                if sweep.exclude.iter().any(|f| matches_filter(f, &r)) {
                    self.excluded_by_filter += 1;
                } else {
                    let reference = match &sweep.reference {
                        None => None,
                        Some(over) => self.reference(sweep, limits, entries, over, &r),
                    };
                    self.add_members(sweep, &r, reference, search);
                }
            }
        }
    }

    /// The reference run of a run (merged with an identical one already planned, its
    /// strides the greatest common divisor of its consumers'): its id and superseded id.
    fn reference(
        &mut self,
        sweep: &SweepFile,
        limits: &PlanLimits,
        entries: &[&Entry],
        over: &[Entry],
        r: &Resolved,
    ) -> Option<(String, Option<String>)> {
        match reference_of(sweep, limits, entries, over, r) {
            Ok((spec, sx, st)) => {
                let id = spec.run_id.clone();
                let old = spec.superseded_id.clone();
                match self.references.iter_mut().find(|p| p.spec.run_id == id) {
                    Some(p) => {
                        p.space_stride = gcd(p.space_stride, sx);
                        p.time_stride = gcd(p.time_stride, st);
                    }
                    None => self.references.push(ReferencePlan {
                        spec,
                        space_stride: sx,
                        time_stride: st,
                    }),
                }
                Some((id, old))
            }
            Err(mut is) => {
                self.issues.append(&mut is);
                None
            }
        }
    }

    /// The runs of a resolved combination: one per ensemble member, each id over its member
    /// and its reference; a run identical to an earlier one collapses into it.
    fn add_members(
        &mut self,
        sweep: &SweepFile,
        r: &Resolved,
        reference: Option<(String, Option<String>)>,
        search: &Option<String>,
    ) {
        let samples: Vec<Option<(usize, f64)>> = match sweep.ensemble {
            None => vec![None],
            Some(e) => (0..e.samples).map(|k| Some((k, e.perturbation))).collect(),
        };
        for sample in samples {
            let mut extra = match (sample, sweep.ensemble) {
                (Some((k, p)), Some(e)) => {
                    format!("ensemble={},{},{k}\n", canonical_number(p), e.seed)
                }
                _ => String::new(),
            };
            let mut old_extra = extra.clone();
            // The errors depend on the reference: a run measured against another
            // reference is another run.
            if let Some((rid, old)) = &reference {
                let _ = writeln!(extra, "reference={rid}");
                let _ = writeln!(old_extra, "reference={}", old.as_ref().unwrap_or(rid));
            }
            let id = r.id(sweep.scene, &extra);
            let superseded_id = r.superseded_id(
                sweep.scene,
                &old_extra,
                reference.as_ref().is_some_and(|(_, old)| old.is_some()),
            );
            if self.seen.contains_key(&id) {
                let why = if r.dropped.is_empty() {
                    "identical parameters after alias resolution".to_string()
                } else {
                    r.dropped.join("; ")
                };
                *self.collapsed.entry(why).or_default() += 1;
                continue;
            }
            self.seen.insert(id.clone(), self.runs.len());
            let mut config = r.config.clone();
            if let (Some((k, p)), Some(e)) = (sample, sweep.ensemble) {
                let seed = e.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (k as u64 + 1);
                config.set_perturbation(Some((p, seed)));
            }
            self.runs.push(RunSpec {
                run_id: id,
                label: r.label.clone(),
                params: r.params.clone(),
                scheme_label: r.scheme_label.clone(),
                config,
                repeats: sweep.repeats,
                sample,
                scene: sweep.scene,
                reference: reference.as_ref().map(|(rid, _)| rid.clone()),
                search: search.clone(),
                superseded_id,
            });
        }
    }
}

/// A combination's entries with the searched key set to `value`.
fn probe_entries(entries: &[Entry], key: Key, value: f64) -> Vec<Entry> {
    let mut out: Vec<Entry> = entries.iter().filter(|e| e.key != key).cloned().collect();
    out.push(Entry {
        key,
        value: Value::Num(value),
        origin: Origin {
            path: format!("search.{}", key.name()),
            line: None,
        },
    });
    out
}

/// The probe of a search base at `value`: an ordinary run (same parameters, same run_id as
/// anywhere else), tagged with its search, allowed past a CFL limit.
pub fn probe(plan: &Plan, base: &SearchBase, value: f64) -> Result<RunSpec, SweepError> {
    let sweep = &plan.sweep;
    let sr = sweep
        .search
        .as_ref()
        .expect("a plan with search bases has a search");
    let owned = probe_entries(&base.entries, sr.key, value);
    let entries: Vec<&Entry> = owned.iter().collect();
    let invalid = |issues: Vec<Issue>| SweepError::Invalid {
        file: sweep.path.clone(),
        issues,
        sets: sweep.sets.clone(),
    };
    match resolve(sweep_dir(sweep), sweep.scene, &entries, true, &plan.limits) {
        Outcome::Run(r) => {
            let reference = match &sweep.reference {
                None => None,
                Some(over) => {
                    let spec = reference_of(sweep, &plan.limits, &entries, over, &r)
                        .map_err(invalid)?
                        .0;
                    Some((spec.run_id, spec.superseded_id))
                }
            };
            let extra = reference
                .as_ref()
                .map(|(rid, _)| format!("reference={rid}\n"))
                .unwrap_or_default();
            let old_extra = reference
                .as_ref()
                .map(|(rid, old)| format!("reference={}\n", old.as_ref().unwrap_or(rid)))
                .unwrap_or_default();
            let changed = reference.as_ref().is_some_and(|(_, old)| old.is_some());
            let reference = reference.map(|(rid, _)| rid);
            Ok(RunSpec {
                run_id: r.id(sweep.scene, &extra),
                superseded_id: r.superseded_id(sweep.scene, &old_extra, changed),
                label: r.label.clone(),
                params: r.params.clone(),
                scheme_label: r.scheme_label.clone(),
                config: r.config.clone(),
                repeats: sweep.repeats,
                sample: None,
                scene: sweep.scene,
                reference,
                search: Some(base.tag.clone()),
            })
        }
        Outcome::Inapplicable(why) => Err(invalid(vec![Issue {
            line: None,
            key: format!("search.{}", sr.key.name()),
            reason: format!("the probe at {value} is meaningless: {why}"),
        }])),
        Outcome::Invalid(is) => Err(invalid(is)),
    }
}

impl Plan {
    /// Parameter keys whose value differs between runs (the plan table's columns).
    pub fn varying_keys(&self) -> Vec<Key> {
        Key::ALL
            .into_iter()
            .filter(|k| {
                let first = self.runs[0].params.get(k).map(Value::canonical);
                self.runs
                    .iter()
                    .any(|r| r.params.get(k).map(Value::canonical) != first)
            })
            .collect()
    }

    /// The plan as a table of the parameters that vary between runs.
    pub fn table(&self) -> String {
        let plan = self;
        let keys = plan.varying_keys();
        let mut header: Vec<String> = vec!["#".into(), "run_id".into(), "label".into()];
        header.extend(keys.iter().map(|k| k.name().to_string()));
        // steps × unknowns: what a run costs, to see where the time of a sweep goes before running it
        header.push("work".into());
        let mut total = 0u64;
        let mut rows: Vec<Vec<String>> = plan
            .runs
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let mut row = vec![i.to_string(), r.run_id.clone(), r.label.clone()];
                row.extend(keys.iter().map(|k| {
                    r.params
                        .get(k)
                        .map(|v| v.to_string())
                        .unwrap_or_else(|| "—".into())
                }));
                let work = r.config.work() * r.repeats as u64;
                total += work;
                row.push(format!("{work:.2e}", work = work as f64));
                row
            })
            .collect();
        let mut last = vec![String::new(); header.len()];
        last[2] = "total".into();
        *last.last_mut().expect("a column") = format!("{:.2e}", total as f64);
        rows.push(last);
        super::render_table(&header, &rows)
    }

    /// Human summary: counts, merges and reasons.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "sweep `{}` (scene {}): {} combinations → {} runs",
            self.sweep.name,
            self.sweep.scene.name(),
            self.combinations,
            self.runs.len()
        );
        if self.sweep.ensemble.is_some() {
            s.push_str(" (ensemble members included)");
        }
        s.push('\n');
        for set in &self.sweep.sets {
            let _ = writeln!(s, "  --set {set}");
        }
        for note in &self.sweep.overridden {
            let _ = writeln!(s, "  {note}");
        }
        if self.excluded_by_filter > 0 {
            let _ = writeln!(
                s,
                "  {} excluded by `exclude` filters",
                self.excluded_by_filter
            );
        }
        for (why, n) in &self.inapplicable {
            let _ = writeln!(s, "  {n} left out as meaningless: {why}");
        }
        for (why, n) in &self.collapsed {
            let _ = writeln!(s, "  {n} collapsed into identical runs: {why}");
        }
        s
    }
}
