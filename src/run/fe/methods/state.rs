//! Which contract §3.2 method a configuration runs, the checks the planner also makes (an engine
//! entry point gets the same reasons), and the c of its step matrix M + cK.

use crate::run::fe::config::{FeConfig, kinematic};
use crate::space::ContactMethod;
use crate::time::{GeneralizedAlphaParams, MoreauJeanParams, Scheme};

/// Steps between two recomputations of the carried products Mv, Ku (, Kv, Mu).
pub(super) const REFRESH: usize = 64;

/// The method of a run of this module.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Method {
    Kane,
    Csn,
    Alpha(GeneralizedAlphaParams),
    MoreauJean(MoreauJeanParams),
    Gradient,
    Kinematic,
}

pub(super) fn method(cfg: &FeConfig) -> Result<Method, String> {
    let m = match cfg.scheme {
        _ if kinematic(cfg) => Method::Kinematic,
        Scheme::Kane => Method::Kane,
        Scheme::ContactStabilizedNewmark => Method::Csn,
        Scheme::GeneralizedAlpha(p) => Method::Alpha(p),
        Scheme::MoreauJean(p) => Method::MoreauJean(p),
        Scheme::DiscreteGradient => Method::Gradient,
        s => {
            return Err(format!(
                "scheme {} is not a contract §3.2 method",
                s.label()
            ));
        }
    };
    // The scene and the planner refuse these first; an engine entry point (tests, benches)
    // gets the same reasons.
    let mixed = cfg.method == ContactMethod::Mixed;
    let bad = match m {
        Method::Kane | Method::Csn | Method::MoreauJean(_) | Method::Kinematic if !mixed => {
            Some("is defined for space = mixed only")
        }
        Method::Gradient => match cfg.method {
            ContactMethod::Mixed => {
                Some("needs a contact potential (penalty, or nitsche with Θ = 1)")
            }
            ContactMethod::Nitsche { theta, .. } if theta != 1.0 => {
                Some("with space = nitsche needs nitsche_theta = 1")
            }
            _ => None,
        },
        _ => None,
    };
    if let Some(why) = bad {
        return Err(format!("scheme {} {why}", cfg.scheme.label()));
    }
    let needs_mass = matches!(m, Method::Csn | Method::Alpha(_) | Method::MoreauJean(_));
    if needs_mass && cfg.mass.massless_contact() {
        return Err(format!(
            "scheme {} needs inertia on the contact dofs (mass = consistent or lumped)",
            cfg.scheme.label()
        ));
    }
    Ok(m)
}

/// c of the step matrix M + cK (None: the explicit kinematic step has none).
pub(super) fn step_coefficient(m: Method, tau: f64) -> Option<f64> {
    let t2 = tau * tau;
    match m {
        Method::Kane | Method::Csn | Method::Gradient => Some(0.25 * t2),
        Method::Alpha(p) => Some(p.stiffness_coefficient(tau)),
        Method::MoreauJean(p) => Some(p.theta * p.theta * t2),
        Method::Kinematic => None,
    }
}
