//! The validated configuration of one run ([`RunConfig`]), per discretisation family, and what
//! the planner asks of it before the run (explicit step limits, work).

use crate::scene::SceneSetup;
use crate::space::{ContactInit, ContactMethod, MassVariant};
use crate::time::Scheme;

use super::bars1d;
use super::grid1d::Grid1d;
use super::{bar1d, fe, layer1d, oscillator};

/// The validated configuration of one run, per discretisation family: the tridiagonal 1D
/// engine or the sparse finite-element engine (which runs every FE scene).
#[derive(Debug, Clone, PartialEq)]
pub enum RunConfig {
    Bar1d(bar1d::Bar1dConfig),
    Fe(fe::FeConfig),
    Oscillator(oscillator::OscillatorConfig),
    Layer1d(layer1d::Layer1dConfig),
    Bars1d(bars1d::Bars1dConfig),
}

impl RunConfig {
    /// The run of a scene's setup with a contact method, mass, scheme and step.
    pub fn new(
        setup: SceneSetup,
        method: ContactMethod,
        mass: MassVariant,
        scheme: Scheme,
        dt: f64,
        steps: usize,
    ) -> RunConfig {
        match setup {
            SceneSetup::Bar1d { bar, elements } => RunConfig::Bar1d(bar1d::Bar1dConfig::new(
                bar,
                Grid1d::with_steps(elements, dt, steps, method, mass, scheme),
            )),
            SceneSetup::Fe(setup) => RunConfig::Fe(fe::FeConfig {
                setup,
                method,
                mass,
                scheme,
                dt,
                steps,
                solver: crate::space::step_solver::Solver::Direct,
                perturbation: None,
                friction: crate::contact::friction::FrictionLaw::None,
                contact_init: ContactInit::Consistent,
            }),
            // The oscillator's one dof is its mass: no mass variant to keep.
            SceneSetup::Oscillator(params) => RunConfig::Oscillator(oscillator::OscillatorConfig {
                params,
                method,
                scheme,
                dt,
                steps,
                perturbation: None,
            }),
            SceneSetup::Layer1d { layer, elements } => {
                RunConfig::Layer1d(layer1d::Layer1dConfig::new(
                    layer,
                    Grid1d::with_steps(elements, dt, steps, method, mass, scheme),
                ))
            }
            SceneSetup::Bars1d { bars, elements, .. } => {
                RunConfig::Bars1d(bars1d::Bars1dConfig::new(
                    bars,
                    Grid1d::with_steps(elements, dt, steps, method, mass, scheme),
                ))
            }
        }
    }

    /// The friction law at the contact (contract §2.5). Only the layer has a tangential direction
    /// today; the planner refuses a law ≠ none on every other scene before a config is built,
    /// so for them the law is none and nothing changes.
    pub fn with_friction(mut self, law: crate::contact::friction::FrictionLaw) -> RunConfig {
        match &mut self {
            RunConfig::Layer1d(c) => c.layer.friction = law,
            RunConfig::Fe(c) => c.friction = law,
            _ => {}
        }
        self
    }

    /// The initial value of a massless contact node (contract §2.2): the 1D bar's contact node;
    /// the FE scenes' massless dofs, which differ from u⁰ = 0 under the body load (contract
    /// §1.3). The other engines have no massless dof.
    pub fn with_contact_init(mut self, init: ContactInit) -> RunConfig {
        match &mut self {
            RunConfig::Bar1d(c) => c.contact_init = init,
            RunConfig::Fe(c) => c.contact_init = init,
            _ => {}
        }
        self
    }

    /// How the step systems of a finite-element run are solved (the 1D engines' tridiagonal
    /// solves have no choice: unchanged).
    pub fn with_solver(mut self, solver: crate::space::step_solver::Solver) -> RunConfig {
        if let RunConfig::Fe(c) = &mut self {
            c.solver = solver;
        }
        self
    }

    /// Ensemble member: relative amplitude of a perturbation of u⁰ and its seed.
    pub fn set_perturbation(&mut self, p: Option<(f64, u64)>) {
        match self {
            RunConfig::Bar1d(c) => c.perturbation = p,
            RunConfig::Fe(c) => c.perturbation = p,
            RunConfig::Oscillator(c) => c.perturbation = p,
            RunConfig::Layer1d(c) => c.perturbation = p,
            RunConfig::Bars1d(c) => c.perturbation = p,
        }
    }

    /// The largest stable dt of an explicit scheme, from the assembled operators (None for
    /// implicit schemes); `Err` names the key at fault and why the operators cannot be built
    /// or the scheme cannot run.
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        match self {
            RunConfig::Bar1d(c) => c.explicit_dt_limit(),
            RunConfig::Fe(c) => c.explicit_dt_limit(),
            RunConfig::Oscillator(c) => c.explicit_dt_limit(),
            RunConfig::Layer1d(c) => c.explicit_dt_limit(),
            RunConfig::Bars1d(c) => c.explicit_dt_limit(),
        }
    }

    /// Work estimate: steps × unknowns (saturating: a refused run may exceed u64).
    pub fn work(&self) -> u64 {
        let (steps, unknowns) = match self {
            RunConfig::Bar1d(c) => (c.grid.steps, c.grid.elements),
            RunConfig::Fe(c) => (c.steps, c.unknowns()),
            RunConfig::Oscillator(c) => (c.steps, 1),
            RunConfig::Layer1d(c) => (c.grid.steps, 2 * c.grid.elements),
            RunConfig::Bars1d(c) => (c.grid.steps, c.grid.elements + c.elements_b()),
        };
        (steps as u64).saturating_mul(unknowns as u64)
    }
}
