//! Scenes: a physical problem with its geometry, material, loads and initial state (contract §1).
//!
//! A scene is *data* behind the [`Scene`] trait: it declares its physics keys with their
//! defaults, its default final time, which contact methods / masses / schemes it supports, how a
//! mesh size becomes a mesh, its wave speed (for `courant`), and whether its errors are measured
//! against a closed form or a reference run. The planner, the run ids, the executor, the sink and
//! the summaries only talk to this trait: adding a scene is a new file here (and, if its geometry
//! is new, a mesh in `space/fe`), never a change to `sweep/`, `exec/`, `sink/` or `summary/`.
//!
//! What a scene hands to the engines is a [`SceneSetup`]: the 1D bar's parameters and element
//! count, the oscillator's parameters, or a finite-element description ([`FeSetup`]:
//! geometry, material, load, initial velocity, gap) which `space::fe` meshes and `run::fe`
//! integrates, whatever the scene.

pub mod ball;
pub mod bar;
pub mod bar1d;
pub mod bars1d;
pub mod bars1d_exact;
pub mod blocks;
pub mod layer1d;
pub mod mesh;
pub mod oscillator;
pub mod two_body;

pub use ball::BallScene;
pub use bar::{BarScene, FeGeometry, FeSetup, LoadModel};
pub use bar1d::{Bar1dScene, BarExact, BarParams};
pub use bars1d::{BarMaterial, Bars1dParams, Bars1dScene};
pub use blocks::{Blocks, BlocksScene};
pub use layer1d::{Layer1dScene, LayerExact, LayerParams, PlaneWave};
pub use mesh::{MeshBodies, MeshScene};
pub use oscillator::{DryFrictionExact, OscillatorExact, OscillatorParams, OscillatorScene};
pub use two_body::{InterfaceQuadrature, MassSide, NitscheSides, Pairing, mortar_basis_from_index};

/// A physics parameter of a scene: its key name (contract §7) and default value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicsKey {
    pub name: &'static str,
    pub default: f64,
}

/// The physics values of one run, in the scene's declaration order.
#[derive(Debug, Clone, PartialEq)]
pub struct Physics(pub Vec<(&'static str, f64)>);

impl Physics {
    /// The value of a declared key (panics on an undeclared name: a programming error).
    pub fn get(&self, name: &str) -> f64 {
        self.0
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("physics key `{name}` is not declared by this scene"))
    }

    /// Replace the value of a declared key (panics on an undeclared name, as [`Physics::get`]).
    pub fn set(&mut self, name: &str, value: f64) {
        let slot = self
            .0
            .iter_mut()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("physics key `{name}` is not declared by this scene"));
        slot.1 = value;
    }
}

/// How a run's errors are measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorSource {
    /// A closed-form solution (bar1d: clamped with zero gap, or the flying bar; the oscillator).
    Exact,
    /// A reference run of the same scene on a finer nested mesh and step (contract §1.2).
    ReferenceRun,
}

/// The mesh of a run as the scene resolved it from `h` or `elements`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshChoice {
    /// The integer that identifies the mesh (`elements` column): elements along the scene's
    /// main axis (the bar's length, the height of the 2D/3D bars).
    pub elements: usize,
    /// Nominal mesh size h.
    pub h: f64,
}

/// What a scene hands to the engines.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneSetup {
    /// The 1D bar (tridiagonal engine).
    Bar1d { bar: BarParams, elements: usize },
    /// A finite-element scene (sparse engine).
    Fe(FeSetup),
    /// The impact oscillator: one mass, one spring, one obstacle (contract §1.5).
    Oscillator(OscillatorParams),
    /// The frictional layer: two P1 chains on the same nodes (contract §1.7).
    Layer1d { layer: LayerParams, elements: usize },
    /// Two bars colliding (contract §1.9): A's element count (B's follows from one h).
    Bars1d {
        bars: Bars1dParams,
        elements: usize,
        /// B takes a material value of A's other than 1 (`revision=bars1d-b-follows-a`).
        b_follows_a: bool,
    },
}

/// What [`Scene::setup_from_file`] gives for a mesh file: the mesh choice and the run's setup
/// (a name the planner can hold without naming the scenes' setup type).
pub type FileSetup = (MeshChoice, SceneSetup);

impl SceneSetup {
    /// Why `start = "static"` (contract §1.8) cannot start this setup with `friction`, if it
    /// cannot: on a mesh clamped nowhere, contact without a friction bound fixes no position
    /// along the plane (and on an incline holds no static state at all).
    pub fn static_start_refusal(
        &self,
        friction: crate::contact::friction::FrictionLaw,
    ) -> Option<String> {
        use crate::contact::friction::FrictionLaw;
        let SceneSetup::Fe(fe) = self else {
            return None;
        };
        let unclamped = matches!(
            fe.geometry,
            FeGeometry::Mesh {
                clamped_nodes: 0,
                ..
            }
        );
        let held = match friction {
            FrictionLaw::Coulomb { coefficient } => coefficient > 0.0,
            FrictionLaw::Tresca { threshold } => threshold > 0.0,
            FrictionLaw::None => false,
        };
        (fe.static_start && unclamped && !held).then(|| {
            "start = \"static\": the body is clamped nowhere and its contact has no friction, which fixes no position along the plane (and on an incline holds no static state): give the run friction (μ_f > 0 or a Tresca threshold), or start at rest".to_string()
        })
    }

    /// Whether this is a finite-element scene's setup (the sparse engine).
    pub fn is_fe(&self) -> bool {
        matches!(self, SceneSetup::Fe(_))
    }

    /// Lines every id of this run carries for definition changes that moved its numbers
    /// ([`FeSetup::id_revision`]); empty for the runs no change touched, whose ids stay.
    pub fn id_revision(&self) -> String {
        match self {
            SceneSetup::Fe(s) => s.id_revision(),
            // Dry friction's rows gained the stick/slip counts (issue 42).
            SceneSetup::Oscillator(p) if p.friction > 0.0 => {
                "revision=dry-friction-stick-slip\n".into()
            }
            // B's material keys defaulted to 1, now to A's values: the runs where the two
            // differ changed (issue 44).
            SceneSetup::Bars1d {
                b_follows_a: true, ..
            } => "revision=bars1d-b-follows-a\n".into(),
            SceneSetup::Bar1d { .. }
            | SceneSetup::Layer1d { .. }
            | SceneSetup::Bars1d { .. }
            | SceneSetup::Oscillator(_) => String::new(),
        }
    }

    /// Issue 44: whether a two-body FE run with `scheme` steps in increments where it stepped
    /// in totals (`run::fe::newmark`'s header: the Newmark/θ family, the hybrid,
    /// generalized-α/HHT; the other §3.2 methods solved for Δu or Δv already): the same
    /// equations, round-off relative to the increment, so its id gets the revision line
    /// `revision=two-body-increment`. The one-body runs keep their numbers and ids.
    pub fn two_bodies_step_in_increments(&self, scheme: &crate::time::Scheme) -> bool {
        let two_body =
            matches!(self, SceneSetup::Fe(s) if matches!(s.geometry, FeGeometry::Blocks(_)));
        let stepped =
            !scheme.is_comparison() || matches!(scheme, crate::time::Scheme::GeneralizedAlpha(_));
        two_body && stepped
    }

    /// Issue 45: whether a run's Nitsche/penalty steps between two bodies can be finished by
    /// the full-system Newton (`run::fe::full_newton`: the blocks and two-body mesh files,
    /// frictionless — a zero bound is, but for Nitsche with Θ ≠ 0 (the engine's `frictional`)
    /// —, the Newmark/θ family without the hybrid scheme),
    /// so its id gets the revision line `revision=two-body-full-newton`: where the condensed
    /// step left the refinement's tolerance, or the interface has ≥ 1024 points, its numbers
    /// moved. One-body runs and `mixed` keep their ids.
    pub fn two_bodies_full_newton(
        &self,
        contact: crate::space::ContactMethod,
        friction: &crate::contact::friction::FrictionLaw,
        scheme: &crate::time::Scheme,
    ) -> bool {
        use crate::contact::friction::FrictionLaw;
        use crate::space::ContactMethod;
        let frictional = match *friction {
            FrictionLaw::None => false,
            FrictionLaw::Coulomb { coefficient: b } | FrictionLaw::Tresca { threshold: b } => {
                b != 0.0 || matches!(contact, ContactMethod::Nitsche { theta, .. } if theta != 0.0)
            }
        };
        let two_body = matches!(self, SceneSetup::Fe(s) if matches!(
            s.geometry,
            FeGeometry::Blocks(_) | FeGeometry::Mesh { bodies: Some(_), .. }
        ));
        let treated = matches!(
            contact,
            ContactMethod::Nitsche { .. } | ContactMethod::Penalty { .. }
        );
        let stepped = !scheme.is_comparison() && !matches!(scheme, crate::time::Scheme::Hybrid);
        two_body && treated && !frictional && stepped
    }
}

/// A run's contact treatment (`space`), mass variant and scheme family, as a sweep file names
/// them: what [`Scene::supports`] judges.
#[derive(Clone, Copy, Debug)]
pub struct MethodNames<'a> {
    pub space: &'a str,
    pub mass: &'a str,
    pub scheme: &'a str,
}

/// What the interface keys are judged against ([`Scene::supports_interface`]): the contact
/// treatment (`space`), whether a friction law acts, and whether the scheme is kinematic central
/// difference (its impulses act row by row, on rows that share no dof).
#[derive(Clone, Copy, Debug)]
pub struct InterfaceUse<'a> {
    pub space: &'a str,
    pub frictional: bool,
    pub kinematic: bool,
}

/// `Ok` when `value` is one of `allowed`, else the sweep error of `key` with `why` — the one
/// shape of every scene's refusal of a method it does not take.
pub(crate) fn require(
    key: &'static str,
    value: &str,
    allowed: &[&str],
    why: impl FnOnce() -> String,
) -> Result<(), (&'static str, String)> {
    if allowed.contains(&value) {
        Ok(())
    } else {
        Err((key, why()))
    }
}

/// What names a scene and frames its runs: data, so a scene states it once.
#[derive(Clone, Copy, Debug)]
pub struct SceneFacts {
    /// The `scene` value of sweep files.
    pub name: &'static str,
    /// Physics keys this scene accepts, with their defaults (besides discretisation and method
    /// keys, which every scene accepts).
    pub physics: &'static [PhysicsKey],
    /// Default final time T.
    pub default_t: f64,
}

/// A physical problem, as the planner sees it.
pub trait Scene: Send + Sync {
    /// Its name, physics keys and default final time.
    fn facts(&self) -> SceneFacts;
    /// The `scene` value of sweep files.
    fn name(&self) -> &'static str {
        self.facts().name
    }
    /// Physics keys this scene accepts, with their defaults.
    fn physics(&self) -> &'static [PhysicsKey] {
        self.facts().physics
    }
    /// Default final time T.
    fn default_t(&self) -> f64 {
        self.facts().default_t
    }
    /// Wave speed c0 (courant → dt = ν h / c0): √(E/ρ) in 1D, the P-wave speed √((λ+2μ)/ρ)
    /// in 2D/3D.
    fn wave_speed(&self, physics: &Physics) -> f64;
    /// The mesh for a requested size h, or why h does not give one.
    fn mesh_from_h(&self, physics: &Physics, h: f64) -> Result<MeshChoice, String>;
    /// The mesh for a requested `elements` count, or why not.
    fn mesh_from_elements(&self, physics: &Physics, elements: usize) -> Result<MeshChoice, String>;
    /// The mesh of a run that gives neither `h` nor `elements`: None (the default) makes them
    /// required; a scene without a mesh (the oscillator) returns its one choice.
    fn default_mesh(&self) -> Option<MeshChoice> {
        None
    }
    /// Whether the scene implements this combination of contact method (`space`), mass variant
    /// and scheme family (`newmark`, `theta`, `paoli-schatzman`, `hybrid`); `Err` names the key
    /// at fault and the reason (a sweep error, not a silently dropped run).
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)>;
    /// Whether the start of a massless contact node (`contact_init`) changes anything with
    /// these physics: only where the quasi-static value of the massless dofs differs from the
    /// interpolant of u0 (contract §2.2) — the 1D bar (contract §1.1), and the FE scenes under
    /// gravity with the body load, whose massless dofs carry load (contract §1.3). Elsewhere
    /// (no load, or `load = inertial`, whose load vanishes on the massless rows) both starts
    /// are the same state, so the key is inapplicable and a sweep over it makes no duplicate
    /// runs.
    fn contact_init_matters(&self, physics: &Physics) -> bool {
        let _ = physics;
        false
    }
    /// Where the errors come from.
    fn error_source(&self, physics: &Physics) -> Option<ErrorSource>;
    /// Whether the meshes of two sizes are nested (a coarse node is a node of every finer
    /// mesh, h_run/h_ref whole), so a reference run stores only the coarse runs' lattice; if
    /// not, the reference stores its whole mesh and runs interpolate it at their nodes.
    fn nested_meshes(&self) -> bool {
        true
    }
    /// The dimension of a finite-element body in 2D/3D (the bars, the disc/ball, the mesh
    /// files), None for the others: a mesh file's run may take its reference from another
    /// scene of the same dimension (contract §1.6, `reference = { scene = … }`).
    fn fe_dim(&self) -> Option<usize> {
        None
    }
    /// Whether the scene takes a friction law (contract §2.5, `friction` ≠ `none`); `Err` says
    /// why not. A friction law needs a tangential direction at the contact: the 1D bar has
    /// none (its one displacement is normal to the obstacle); the finite-element scenes have
    /// one at every Γ_C point (e_1 in 2D, e_1 and e_2 in 3D, contract §1.8).
    fn supports_friction(&self) -> Result<(), String> {
        if self.fe_dim().is_some() {
            return Ok(());
        }
        Err(format!(
            "scene {} has no tangential direction at its contact (its one displacement is normal to the obstacle): friction needs layer1d (contract §1.7)",
            self.name()
        ))
    }
    /// Whether a physics value rules out a scheme (e.g. the oscillator's dry friction with a
    /// scheme that has no frictional step); `Err` names the key and says why.
    fn supports_physics(
        &self,
        _physics: &Physics,
        _scheme: &crate::time::Scheme,
    ) -> Result<(), (&'static str, String)> {
        Ok(())
    }
    /// Whether the physics values go with the run's contact treatment, friction and scheme
    /// ([`InterfaceUse`]): the two blocks' interface keys (contract §2.6, issue 45). `Err` names the
    /// keys that together rule the run out, the one at fault first, and says why.
    fn supports_interface(
        &self,
        _physics: &Physics,
        _method: InterfaceUse<'_>,
    ) -> Result<(), (&'static [&'static str], String)> {
        Ok(())
    }
    /// The description the engines run.
    fn setup(&self, physics: &Physics, mesh: MeshChoice) -> SceneSetup;
    /// Whether the body comes from a mesh file (the `mesh` key, contract §1.6) rather than from
    /// `h` or `elements`.
    fn takes_mesh_file(&self) -> bool {
        false
    }
    /// The mesh choice and the setup of a run whose body is the read and validated mesh file
    /// `path` (scenes with [`Scene::takes_mesh_file`]); `Err` says why this file does not fit.
    fn setup_from_file(
        &self,
        _physics: &Physics,
        path: &std::path::Path,
        _mesh: &crate::space::fe::GmshMesh,
    ) -> Result<(MeshChoice, SceneSetup), String> {
        Err(format!(
            "scene {} builds its own geometry and takes no mesh file ({})",
            self.name(),
            path.display()
        ))
    }
}

/// What every finite-element scene takes — the bars, the disc/ball and the mesh files alike
/// (contract §1.2: every contact method on every scene): `mixed`, `nitsche`, `penalty`; every mass
/// variant of contract §2.2 but the 1D-only two; the newmark and θ families (central difference's
/// kinematic contact needs `lumped`, the planner checks it), contract §3.2's methods
/// ([`crate::run::fe`]'s methods module, on any mesh: they act on the assembled M, K and the
/// Γ_C rows or quadrature points; the planner checks their contact methods and masses), and
/// hybrid with a contact potential (Nitsche or the penalty on Γ_C's quadrature points).
pub(crate) fn fe_supports(scene: &str, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
    let MethodNames {
        space,
        mass,
        scheme,
    } = m;
    require("space", space, &["mixed", "nitsche", "penalty"], || {
        format!("space = {space} is not available for scene {scene} (mixed, nitsche, penalty)")
    })?;
    if matches!(mass, "singular-dynamic" | "node-neighbour") {
        return Err((
            "mass",
            format!(
                "mass = {mass} is defined for the 1D bar only (contract §2.2); scene {scene} takes consistent, lumped, mod1, mod2, mod3, weights and zero-contact"
            ),
        ));
    }
    let comparison = matches!(
        scheme,
        "kane"
            | "contact-stabilized-newmark"
            | "generalized-alpha"
            | "hht"
            | "moreau-jean"
            | "discrete-gradient"
    );
    if !(matches!(scheme, "newmark" | "theta")
        || comparison
        || (scheme == "hybrid" && matches!(space, "nitsche" | "penalty")))
    {
        return Err((
            "scheme",
            format!(
                "scheme = {scheme} is not available for scene {scene} with space = {space} (newmark and theta schemes, the contract §3.2 methods kane, contact-stabilized-newmark, generalized-alpha, hht, moreau-jean, discrete-gradient; hybrid with nitsche or penalty — the reduced hybrid of mixed with a massless contact (000 §5) is 1D only)"
            ),
        ));
    }
    Ok(())
}

/// The scenes the engine can run (the registry; contract §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SceneKind {
    /// The 1D impacting bar with its closed form (contract §1.1).
    Bar1d,
    /// The 2D plane-strain bar dropped on an obstacle (contract §1.2).
    Bar2d,
    /// The 3D bar dropped on an obstacle (contract §1.2).
    Bar3d,
    /// The disc falling under gravity on a rigid plane (contract §1.3).
    Disc2d,
    /// The ball falling under gravity on a rigid plane (contract §1.3).
    Sphere3d,
    /// One mass, one spring, one obstacle (contract §1.5).
    Oscillator,
    /// The user's own 2D body, a Gmsh mesh (contract §1.6).
    Mesh2d,
    /// The user's own 3D body, a Gmsh mesh (contract §1.6).
    Mesh3d,
    /// The frictional layer with its exact solution (contract §1.7).
    Layer1d,
    /// Two bars colliding, with their exact solution (contract §1.9).
    Bars1d,
    /// Two blocks, a matching interface, plane strain (contract §1.10).
    Blocks2d,
    /// Two blocks, a matching interface, 3D (contract §1.10).
    Blocks3d,
}

static BAR1D: Bar1dScene = Bar1dScene;
static BAR2D: BarScene = BarScene { dim: 2 };
static BAR3D: BarScene = BarScene { dim: 3 };
static DISC2D: BallScene = BallScene { dim: 2 };
static SPHERE3D: BallScene = BallScene { dim: 3 };
static OSCILLATOR: OscillatorScene = OscillatorScene;
static MESH2D: MeshScene = MeshScene { dim: 2 };
static MESH3D: MeshScene = MeshScene { dim: 3 };
static LAYER1D: Layer1dScene = Layer1dScene;
static BARS1D: Bars1dScene = Bars1dScene;
static BLOCKS2D: BlocksScene = BlocksScene { dim: 2 };
static BLOCKS3D: BlocksScene = BlocksScene { dim: 3 };

impl SceneKind {
    /// Every scene name of contract §1, with whether this build implements it.
    pub const NAMES: [(&'static str, Option<SceneKind>); 12] = [
        ("bar1d", Some(SceneKind::Bar1d)),
        ("bar2d", Some(SceneKind::Bar2d)),
        ("bar3d", Some(SceneKind::Bar3d)),
        ("disc2d", Some(SceneKind::Disc2d)),
        ("sphere3d", Some(SceneKind::Sphere3d)),
        ("oscillator", Some(SceneKind::Oscillator)),
        ("mesh2d", Some(SceneKind::Mesh2d)),
        ("mesh3d", Some(SceneKind::Mesh3d)),
        ("layer1d", Some(SceneKind::Layer1d)),
        ("bars1d", Some(SceneKind::Bars1d)),
        ("blocks2d", Some(SceneKind::Blocks2d)),
        ("blocks3d", Some(SceneKind::Blocks3d)),
    ];

    /// The scene behind this name.
    pub fn get(self) -> &'static dyn Scene {
        match self {
            SceneKind::Bar1d => &BAR1D,
            SceneKind::Bar2d => &BAR2D,
            SceneKind::Bar3d => &BAR3D,
            SceneKind::Disc2d => &DISC2D,
            SceneKind::Sphere3d => &SPHERE3D,
            SceneKind::Oscillator => &OSCILLATOR,
            SceneKind::Mesh2d => &MESH2D,
            SceneKind::Mesh3d => &MESH3D,
            SceneKind::Layer1d => &LAYER1D,
            SceneKind::Bars1d => &BARS1D,
            SceneKind::Blocks2d => &BLOCKS2D,
            SceneKind::Blocks3d => &BLOCKS3D,
        }
    }

    pub fn name(self) -> &'static str {
        self.get().name()
    }

    /// Whether this scene accepts the physics key `name`.
    pub fn accepts_physics(self, name: &str) -> bool {
        self.get().physics().iter().any(|k| k.name == name)
    }

    /// The scene of a `scene` column value.
    pub fn from_name(name: &str) -> Option<SceneKind> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .and_then(|(_, k)| *k)
    }
}
