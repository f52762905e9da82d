//! The parameter keys of contract §7: their types, value ranges and the methods they apply to.

use std::fmt;

/// A sweep parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Key {
    T,
    H,
    Elements,
    Dt,
    Courant,
    Space,
    Mass,
    Scheme,
    MassWeights,
    NitscheTheta,
    NitscheGamma0,
    PenaltyGamma0,
    NewmarkBeta,
    NewmarkGamma,
    ThetaScheme,
    Restitution,
    Length,
    Young,
    Density,
    Amplitude,
    Gap,
    LameLambda,
    LameMu,
    Gravity,
    /// Ids hash parameters in key order, so new keys go at the end.
    ContactInit,
    /// Polynomial degree of the elements (disc2d/sphere3d: 1 or 2).
    Degree,
    /// bar1d's right end (contract §1.4): `clamped` (default) or `free`.
    RightEnd,
    /// Uniform initial velocity (bar1d, oscillator; negative towards the obstacle).
    Velocity,
    /// Oscillator (contract §1.5): mass m, spring stiffness k, constant force f, Newton's
    /// restitution coefficient e_x of the exact solution.
    PointMass,
    Stiffness,
    Force,
    ImpactLaw,
    /// Generalized-α spectral radius at infinity ρ∞ (contract §3.2).
    RhoInf,
    /// HHT α (contract §3.2, preset `hht` of generalized-α).
    HhtAlpha,
    /// The step solves of the 2D/3D scenes: `direct` (sparse Cholesky, default) or `cg`
    /// (Jacobi-preconditioned conjugate gradient, contract §4).
    Solver,
    /// CG's relative residual tolerance (default 1e-12; `solver = "cg"` only).
    CgTol,
    /// The Gmsh mesh file of `mesh2d`/`mesh3d` (contract §1.6), relative to the sweep file; its
    /// canonical text (the run id's) is the file's content hash, not its path.
    Mesh,
    /// The rigid plane x_d = `obstacle` of `mesh2d`/`mesh3d` (contract §1.6), exclusive with `gap`:
    /// the planner turns it into the run's gap (lowest Γ_C node − obstacle), so it never enters
    /// a run id (the same plane given by `gap` is the same run).
    Obstacle,
    /// How gravity enters the FE scenes (contract §1.3): `body` (default, F = ∫ρ f·φ whatever the
    /// mass variant) or `inertial` (F = M_run f e_d, the load following the modified inertia).
    Load,
    /// The friction law at the contact points (contract §2.5): `none` (default: today's engine,
    /// every id unchanged), `tresca` or `coulomb`.
    Friction,
    /// Coulomb's coefficient μ_f ≥ 0 (`friction = "coulomb"` only).
    FrictionCoefficient,
    /// Tresca's threshold s ≥ 0, a traction (`friction = "tresca"` only).
    TrescaThreshold,
    /// The layer's height H (contract §1.7).
    Height,
    /// The initial tangential velocity: layer1d's V_t (contract §1.7); the e_1 velocity of every
    /// node not clamped on disc2d, sphere3d, mesh2d and mesh3d (contract §1.8).
    VelocityTangential,
    /// Dry (Coulomb) friction on the oscillator's mass, F ≥ 0 (contract §1.5; default 0, so the
    /// frictionless runs keep their ids).
    FrictionForce,
    /// The plane's tilt α in degrees (mesh2d/mesh3d, contract §1.8): the volume load becomes
    /// ρ·gravity·(sin α e_1 − cos α e_d). Default 0, so every existing run keeps its id.
    Incline,
    /// Bar B of `bars1d` (contract §1.9, §7): its length, modulus, density and initial velocity.
    LengthB,
    YoungB,
    DensityB,
    VelocityB,
    /// B's far end (`bars1d`): `free` (default) or `clamped`.
    FarEnd,
    /// Which bodies a mass variant modifies (contract §2.6): `both` (default), `a` or `b`.
    MassSide,
    /// The weights of the two sides' Nitsche terms (contract §2.6): `unbiased` (default) or `a`.
    NitscheSides,
    /// Two blocks (contract §1.10, §2.6; issue 44): B's height H_b, the blocks' width W, B's
    /// elements across per A's (`mesh_ratio`, 1: a matching interface), the traction −p e_d on
    /// A's top (`pressure`) and B's Lamé constants. (`density_b`, `velocity_b`, `far_end` and
    /// `mass_side` above serve both two-body scenes.)
    HeightB,
    Width,
    MeshRatio,
    Pressure,
    LameLambdaB,
    LameMuB,
    /// The two-body pairing of `mixed` and `penalty` (contract §2.6; issue 45): `node-to-node`
    /// (default: every existing id unchanged), `node-to-segment` or `mortar`; the mortar
    /// multiplier's basis (`standard`, default, or `dual`); and where the interface integrals
    /// are computed (`segment`, default: the segmentation of Γ^a by Γ^b's projected faces, or
    /// `element`: Γ^a's own face rule).
    Pairing,
    MortarBasis,
    InterfaceQuadrature,
    /// The initial state of the FE mesh scenes (contract §1.8, issue 43): `rest` (default: u⁰ = 0,
    /// every existing id unchanged) or `static` (u⁰ the static state under the run's loads with
    /// its contact, [`crate::run`]'s static start).
    Start,
}

/// What a key's value must look like.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValueType {
    Float,
    Int,
    Str,
    FloatList,
}

/// A parameter value as written (numbers as f64 unless the key is an integer).
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Num(f64),
    Int(i64),
    Str(String),
    List(Vec<f64>),
}

impl Value {
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Num(x) => Some(*x),
            Value::Int(i) => Some(*i as f64),
            _ => None,
        }
    }
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }
}

/// Canonical text of a number for hashing and comparison: 12 significant digits, so that
/// `1`, `1.0` and a Courant-derived 0.015000000000000001 all read the same.
pub fn canonical_number(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let rounded: f64 = format!("{x:.11e}").parse().unwrap_or(x);
    format!("{rounded:e}")
}

impl Value {
    /// The text hashed into run ids and compared by filters.
    pub fn canonical(&self) -> String {
        match self {
            Value::Num(x) => canonical_number(*x),
            Value::Int(i) => i.to_string(),
            Value::Str(s) => s.clone(),
            Value::List(v) => {
                let parts: Vec<String> = v.iter().map(|x| canonical_number(*x)).collect();
                format!("[{}]", parts.join(","))
            }
        }
    }
}

/// For people: numbers at up to 6 significant digits.
impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let num = |x: f64| {
            let r: f64 = format!("{x:.5e}").parse().unwrap_or(x);
            if r != 0.0 && (r.abs() < 1e-3 || r.abs() >= 1e6) {
                format!("{r:e}")
            } else {
                format!("{r}")
            }
        };
        match self {
            Value::Num(x) => write!(f, "{}", num(*x)),
            Value::Int(i) => write!(f, "{i}"),
            Value::Str(s) => write!(f, "{s}"),
            Value::List(v) => {
                let parts: Vec<String> = v.iter().map(|x| num(*x)).collect();
                write!(f, "[{}]", parts.join(","))
            }
        }
    }
}

impl Key {
    pub const ALL: [Key; 63] = [
        Key::T,
        Key::H,
        Key::Elements,
        Key::Dt,
        Key::Courant,
        Key::Space,
        Key::Mass,
        Key::Scheme,
        Key::MassWeights,
        Key::NitscheTheta,
        Key::NitscheGamma0,
        Key::PenaltyGamma0,
        Key::NewmarkBeta,
        Key::NewmarkGamma,
        Key::ThetaScheme,
        Key::Restitution,
        Key::Length,
        Key::Young,
        Key::Density,
        Key::Amplitude,
        Key::Gap,
        Key::LameLambda,
        Key::LameMu,
        Key::Gravity,
        Key::ContactInit,
        Key::Degree,
        Key::RightEnd,
        Key::Velocity,
        Key::PointMass,
        Key::Stiffness,
        Key::Force,
        Key::ImpactLaw,
        Key::RhoInf,
        Key::HhtAlpha,
        Key::Solver,
        Key::CgTol,
        Key::Mesh,
        Key::Obstacle,
        Key::Load,
        Key::Friction,
        Key::FrictionCoefficient,
        Key::TrescaThreshold,
        Key::Height,
        Key::VelocityTangential,
        Key::FrictionForce,
        Key::Incline,
        Key::LengthB,
        Key::YoungB,
        Key::DensityB,
        Key::VelocityB,
        Key::FarEnd,
        Key::MassSide,
        Key::NitscheSides,
        Key::HeightB,
        Key::Width,
        Key::MeshRatio,
        Key::Pressure,
        Key::LameLambdaB,
        Key::LameMuB,
        Key::Pairing,
        Key::MortarBasis,
        Key::InterfaceQuadrature,
        Key::Start,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Key::T => "T",
            Key::H => "h",
            Key::Elements => "elements",
            Key::Dt => "dt",
            Key::Courant => "courant",
            Key::Space => "space",
            Key::Mass => "mass",
            Key::Scheme => "scheme",
            Key::MassWeights => "mass_weights",
            Key::NitscheTheta => "nitsche_theta",
            Key::NitscheGamma0 => "nitsche_gamma0",
            Key::PenaltyGamma0 => "penalty_gamma0",
            Key::NewmarkBeta => "newmark_beta",
            Key::NewmarkGamma => "newmark_gamma",
            Key::ThetaScheme => "theta_scheme",
            Key::Restitution => "restitution",
            Key::Length => "length",
            Key::Young => "young",
            Key::Density => "density",
            Key::Amplitude => "amplitude",
            Key::Gap => "gap",
            Key::LameLambda => "lame_lambda",
            Key::LameMu => "lame_mu",
            Key::Gravity => "gravity",
            Key::ContactInit => "contact_init",
            Key::Degree => "degree",
            Key::RightEnd => "right_end",
            Key::Velocity => "velocity",
            Key::PointMass => "point_mass",
            Key::Stiffness => "stiffness",
            Key::Force => "force",
            Key::ImpactLaw => "impact_law",
            Key::RhoInf => "rho_inf",
            Key::HhtAlpha => "hht_alpha",
            Key::Solver => "solver",
            Key::CgTol => "cg_tol",
            Key::Mesh => "mesh",
            Key::Obstacle => "obstacle",
            Key::Load => "load",
            Key::Friction => "friction",
            Key::FrictionCoefficient => "friction_coefficient",
            Key::TrescaThreshold => "tresca_threshold",
            Key::Height => "height",
            Key::VelocityTangential => "velocity_tangential",
            Key::FrictionForce => "friction_force",
            Key::Incline => "incline",
            Key::LengthB => "length_b",
            Key::YoungB => "young_b",
            Key::DensityB => "density_b",
            Key::VelocityB => "velocity_b",
            Key::FarEnd => "far_end",
            Key::MassSide => "mass_side",
            Key::NitscheSides => "nitsche_sides",
            Key::HeightB => "height_b",
            Key::Width => "width",
            Key::MeshRatio => "mesh_ratio",
            Key::Pressure => "pressure",
            Key::LameLambdaB => "lame_lambda_b",
            Key::LameMuB => "lame_mu_b",
            Key::Pairing => "pairing",
            Key::MortarBasis => "mortar_basis",
            Key::InterfaceQuadrature => "interface_quadrature",
            Key::Start => "start",
        }
    }

    /// Scene physics (material, geometry, load), as opposed to discretisation and method keys.
    pub fn is_physics(self) -> bool {
        matches!(
            self,
            Key::Length
                | Key::Young
                | Key::Density
                | Key::Amplitude
                | Key::Gap
                | Key::LameLambda
                | Key::LameMu
                | Key::Gravity
                | Key::Degree
                | Key::RightEnd
                | Key::Velocity
                | Key::PointMass
                | Key::Stiffness
                | Key::Force
                | Key::ImpactLaw
                | Key::Load
                | Key::Height
                | Key::VelocityTangential
                | Key::FrictionForce
                | Key::Incline
                | Key::LengthB
                | Key::YoungB
                | Key::HeightB
                | Key::Width
                | Key::MeshRatio
                | Key::Pressure
                | Key::LameLambdaB
                | Key::LameMuB
                | Key::DensityB
                | Key::VelocityB
                | Key::FarEnd
                | Key::MassSide
                | Key::NitscheSides
                | Key::Pairing
                | Key::MortarBasis
                | Key::InterfaceQuadrature
                | Key::Start
        )
    }

    /// The named values of a physics key that takes one of a few words (`right_end`): a
    /// scene holds the value as its index in this list (its [`crate::scene::PhysicsKey`]
    /// default is an index too), the sweep file and the columns hold the word.
    pub fn choices(self) -> Option<&'static [&'static str]> {
        match self {
            Key::RightEnd => Some(&["clamped", "free"]),
            Key::Load => Some(&["body", "inertial"]),
            Key::FarEnd => Some(&["free", "clamped"]),
            Key::MassSide => Some(&["both", "a", "b"]),
            Key::NitscheSides => Some(&["unbiased", "a"]),
            Key::Pairing => Some(&["node-to-node", "node-to-segment", "mortar"]),
            Key::MortarBasis => Some(&["standard", "dual"]),
            Key::InterfaceQuadrature => Some(&["segment", "element"]),
            Key::Start => Some(&["rest", "static"]),
            _ => None,
        }
    }

    pub fn from_name(name: &str) -> Option<Key> {
        Key::ALL.into_iter().find(|k| k.name() == name)
    }

    pub fn value_type(self) -> ValueType {
        match self {
            Key::Elements => ValueType::Int,
            Key::Space
            | Key::Mass
            | Key::Scheme
            | Key::ContactInit
            | Key::RightEnd
            | Key::Load
            | Key::Solver
            | Key::Mesh
            | Key::Friction
            | Key::FarEnd
            | Key::MassSide
            | Key::NitscheSides
            | Key::Pairing
            | Key::MortarBasis
            | Key::InterfaceQuadrature
            | Key::Start => ValueType::Str,
            Key::MassWeights => ValueType::FloatList,
            _ => ValueType::Float,
        }
    }

    /// Value-level range check (independent of the other parameters of a run), by the kind
    /// of value: a count, a weight list, a word, a number.
    pub fn check(self, v: &Value) -> Result<(), String> {
        match (self, v) {
            (Key::Elements, Value::Int(i)) => {
                if *i >= 2 {
                    Ok(())
                } else {
                    Err(format!("must be an integer ≥ 2, got {i}"))
                }
            }
            (Key::MassWeights, Value::List(w)) => {
                if w.is_empty() {
                    return Err("must list at least one weight (w1, w2, …)".into());
                }
                for (i, x) in w.iter().enumerate() {
                    positive(*x).map_err(|e| format!("weight {} {e}", i + 1))?;
                }
                Ok(())
            }
            (k, Value::Str(s)) => k.check_word(s),
            (k, Value::Num(x)) => k.check_number(*x),
            _ => Err("wrong type".into()),
        }
    }

    /// The word of a string key: one of the names it takes (a mesh file: any path).
    fn check_word(self, s: &str) -> Result<(), String> {
        match self {
            Key::Space => match s {
                "mixed" | "nitsche" | "penalty" => Ok(()),
                _ => Err(format!(
                    "unknown space `{s}` (expected mixed, nitsche or penalty)"
                )),
            },
            Key::Mass => {
                if crate::space::MassVariant::NAMES.contains(&s) {
                    Ok(())
                } else {
                    Err(format!(
                        "unknown mass `{s}` (expected one of {})",
                        crate::space::MassVariant::NAMES.join(", ")
                    ))
                }
            }
            Key::ContactInit => {
                if crate::space::ContactInit::from_name(s).is_some() {
                    Ok(())
                } else {
                    Err(format!(
                        "unknown contact_init `{s}` (expected consistent or interpolant: the massless contact node starts at its quasi-static value or at the interpolant u0(0))"
                    ))
                }
            }
            Key::Scheme => {
                if SCHEME_NAMES.contains(&s) {
                    Ok(())
                } else {
                    Err(format!(
                        "unknown scheme `{s}` (expected one of {})",
                        SCHEME_NAMES.join(", ")
                    ))
                }
            }
            Key::RightEnd => match s {
                "clamped" | "free" => Ok(()),
                _ => Err(format!(
                    "unknown right_end `{s}` (expected clamped or free: the bar's end x = L held at u = 0 or traction-free)"
                )),
            },
            Key::Load => match s {
                "body" | "inertial" => Ok(()),
                _ => Err(format!(
                    "unknown load `{s}` (expected body — the body force ∫ρ f·φ, contract §1.3 — or inertial — M_run f e_d, the weight following the run's modified mass)"
                )),
            },
            Key::Solver => {
                if crate::space::step_solver::Solver::NAMES.contains(&s) {
                    Ok(())
                } else {
                    Err(format!(
                        "unknown solver `{s}` (expected direct — sparse Cholesky — or cg — preconditioned conjugate gradient)"
                    ))
                }
            }
            Key::Mesh => {
                if s.trim().is_empty() {
                    Err("must name a Gmsh .msh file (a path relative to the sweep file)".into())
                } else {
                    Ok(())
                }
            }
            Key::Friction => {
                if crate::contact::friction::FrictionKind::from_name(s).is_some() {
                    Ok(())
                } else {
                    Err(format!(
                        "unknown friction `{s}` (expected none, tresca — a fixed threshold — or coulomb — proportional to the normal force)"
                    ))
                }
            }
            Key::FarEnd
            | Key::MassSide
            | Key::NitscheSides
            | Key::Pairing
            | Key::MortarBasis
            | Key::InterfaceQuadrature
            | Key::Start => {
                let words = self.choices().expect("choice keys");
                if words.contains(&s) {
                    Ok(())
                } else {
                    Err(format!(
                        "unknown {} `{s}` (expected {}; contract {})",
                        self.name(),
                        words.join(" or "),
                        if self == Key::Start {
                            "§1.8: at rest, or from the static state under the run's loads"
                        } else {
                            "§1.9, §2.6"
                        }
                    ))
                }
            }
            _ => Err("wrong type".into()),
        }
    }

    /// A number of a real-valued key: finite, and within the key's range.
    fn check_number(self, x: f64) -> Result<(), String> {
        match self {
            Key::T | Key::H | Key::Dt | Key::Courant => positive(x),
            Key::NitscheGamma0 | Key::PenaltyGamma0 => positive(x),
            Key::Length | Key::Young | Key::Density | Key::Height => positive(x),
            Key::LengthB | Key::YoungB | Key::DensityB => positive(x),
            Key::HeightB | Key::Width | Key::MeshRatio | Key::LameMuB => positive(x),
            Key::VelocityB | Key::Pressure => finite(x).map(|_| ()),
            Key::VelocityTangential => finite(x).map(|_| ()),
            // λ = 0 is Poisson's ν = 0 (no lateral strain under a uniaxial load), a material
            // the tests use to keep a body's motion in a plane; μ > 0 keeps K's null space the
            // rigid motions.
            Key::LameLambda | Key::LameLambdaB => {
                finite(x)?;
                if x >= 0.0 {
                    Ok(())
                } else {
                    Err(format!("must be ≥ 0, got {x}"))
                }
            }
            Key::LameMu => positive(x),
            Key::PointMass | Key::Stiffness => positive(x),
            // A relative residual: at 1 and above CG would stop before iterating. Values below
            // round-off (≈ 1e-15) are accepted but buy nothing: CG's recursively updated
            // residual keeps shrinking while the true one stays at round-off, so such a run
            // iterates longer for the same solution (measured: cg_tol = 1e-18 runs).
            Key::CgTol => {
                finite(x)?;
                if x > 0.0 && x < 1.0 {
                    Ok(())
                } else {
                    Err(format!("must lie in (0, 1) (a relative residual), got {x}"))
                }
            }
            Key::Velocity | Key::Force => finite(x).map(|_| ()),
            // A coefficient and a traction: zero is frictionless (the same numbers as none),
            // a negative bound would push the body along its slip.
            Key::FrictionCoefficient | Key::TrescaThreshold | Key::FrictionForce => {
                finite(x)?;
                if x >= 0.0 {
                    Ok(())
                } else {
                    Err(format!(
                        "must be ≥ 0 (a friction bound; a negative one would drive the slip), got {x}"
                    ))
                }
            }
            Key::ImpactLaw => within(x, 0.0, 1.0),
            // A tilt in degrees: at ±90° the plane is a wall, the weight has no component
            // pressing the body on it (cos α = 0) and the body falls along it, never resting on
            // the plane the scene is about; beyond, gravity pulls the body away from the plane.
            Key::Incline => {
                finite(x)?;
                if x.abs() < 90.0 {
                    Ok(())
                } else {
                    Err(format!(
                        "must lie in (-90, 90) degrees (the plane's tilt; at |α| ≥ 90° the weight no longer presses the body on the plane), got {x}"
                    ))
                }
            }
            // A zero amplitude is the flying bar's unstrained start (contract §1.4).
            Key::Gap | Key::Amplitude => {
                finite(x)?;
                if x >= 0.0 {
                    Ok(())
                } else {
                    Err(format!("must be ≥ 0, got {x}"))
                }
            }
            Key::NewmarkBeta => within(x, 0.0, 0.5),
            Key::NewmarkGamma | Key::ThetaScheme | Key::Restitution => within(x, 0.0, 1.0),
            Key::RhoInf => within(x, 0.0, 1.0),
            Key::HhtAlpha => within(x, 0.0, 1.0 / 3.0),
            // A height: any finite value (the planner refuses one above the body's lowest Γ_C
            // node, where the body would start inside the obstacle).
            Key::NitscheTheta | Key::Gravity | Key::Obstacle => finite(x).map(|_| ()),
            Key::Degree => {
                if x == 1.0 || x == 2.0 {
                    Ok(())
                } else {
                    Err(format!("must be 1 or 2 (Q1 or Q2 elements), got {x}"))
                }
            }
            _ => Err("wrong type".into()),
        }
    }
}

/// A finite number, or why not.
fn finite(x: f64) -> Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("must be a finite number, got {x}"))
    }
}

/// A finite number > 0, or why not.
fn positive(x: f64) -> Result<(), String> {
    finite(x)?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(format!("must be > 0, got {x}"))
    }
}

/// A finite number in [lo, hi], or why not.
fn within(x: f64, lo: f64, hi: f64) -> Result<(), String> {
    finite(x)?;
    if (lo..=hi).contains(&x) {
        Ok(())
    } else {
        Err(format!("must lie in [{lo}, {hi}], got {x}"))
    }
}

/// Scheme names and aliases accepted in sweep files (contract §3).
pub const SCHEME_NAMES: [&str; 14] = [
    "newmark",
    "crank-nicolson",
    "newmark-dissipative",
    "central-difference",
    "theta",
    "backward-euler",
    "paoli-schatzman",
    "hybrid",
    "kane",
    "contact-stabilized-newmark",
    "generalized-alpha",
    "hht",
    "moreau-jean",
    "discrete-gradient",
];
