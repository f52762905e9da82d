//! Scenes: a physical problem with its geometry, material, loads and initial state.
//!
//! A scene declares which parameters it accepts (SPEC §1); the planner refuses every other key,
//! so nothing is expanded, modelled or stored that the scene does not use.

pub mod bar1d;

pub use bar1d::{BarExact, BarParams};

/// The scenes the engine can run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SceneKind {
    /// The 1D impacting bar with its closed form (SPEC §1.1).
    Bar1d,
}

impl SceneKind {
    /// Every scene name of SPEC §1, with whether this build implements it.
    pub const NAMES: [(&'static str, Option<SceneKind>); 5] = [
        ("bar1d", Some(SceneKind::Bar1d)),
        ("bar2d", None),
        ("bar3d", None),
        ("disc2d", None),
        ("sphere3d", None),
    ];

    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Bar1d => "bar1d",
        }
    }

    /// Physics keys this scene accepts (besides the discretisation and method keys).
    pub fn physics_keys(self) -> &'static [&'static str] {
        match self {
            SceneKind::Bar1d => &["length", "young", "density", "amplitude", "gap"],
        }
    }
}
