//! The time loop of the contract §3.2 methods: the set-up ([`MethodRun::new`]), the observation of
//! t = 0, then per step the method's own step (one file of this folder each), the periodic
//! refresh of the carried products, the friction's bookkeeping and the observation; the
//! outcome ([`MethodRun::finish`]).

use super::run::MethodRun;
use super::state::Method;
use crate::run::fe::config::{CLOCK_EVERY, FeConfig};
use crate::run::{Outcome, RunContext, RunOptions, Stop};

/// Run one finite-element simulation with a method of contract §3.2 (module header of [`super`]).
pub(in crate::run::fe) fn simulate(cfg: &FeConfig, opts: &RunOptions, ctx: &RunContext) -> Outcome {
    let mut run = match MethodRun::new(cfg, opts, ctx) {
        Ok(run) => run,
        Err(out) => return *out,
    };
    let stop = time_loop(&mut run);
    run.finish(stop)
}

/// Observe t = 0, then step to the last step or the first stop.
fn time_loop(run: &mut MethodRun) -> Result<(), Stop<String>> {
    let tau = run.tau;
    {
        let g = &*run.geo;
        g.k.matvec_into(&run.u, &mut run.ku);
        g.k.matvec_into(&run.v, &mut run.kv);
    }
    // The state's own contact force at t = 0 (zero unless the body starts in contact).
    let nitsche_force = run
        .fac
        .as_ref()
        .and_then(|f| f.nitsche.as_ref())
        .map(|ops| ops.energy_terms_and_force(&run.u).2);
    if let Some(f) = nitsche_force {
        run.e_last = run.observe(0, f, None).map_err(Stop::Diverged)?;
        if let Some(st) = run.nit_fric.as_mut() {
            st.start(&run.mv);
        }
    } else {
        let fv = run.fric.as_ref().map(|fr| fr.series(&run.v));
        // The nodal forces of a quasi-static start in contact (zero otherwise).
        let force = run.lambda.iter().sum();
        let e = run.observe(0, force, fv).map_err(Stop::Diverged)?;
        if let Some(fr) = run.fric.as_mut() {
            fr.observed(0, tau, e, &run.mv);
        }
    }
    for step in 1..=run.cfg.steps {
        if let Some(fr) = run.fric.as_mut() {
            fr.begin(&run.u);
        }
        let force = match run.meth {
            Method::Kinematic => run.kinematic_step(step)?,
            Method::Kane => run.kane_step(step)?,
            Method::Csn => run.csn_step(step)?,
            Method::Alpha(ga) if run.fac.as_ref().is_some_and(|f| f.nitsche.is_some()) => {
                run.alpha_nitsche_step(step, ga)?
            }
            Method::Alpha(ga) => run.alpha_mixed_step(step, ga)?,
            Method::MoreauJean(mj) => run.moreau_jean_step(step, mj)?,
            Method::Gradient => run.gradient_step(step)?,
        };
        run.refresh(step);
        if let Some(fr) = run.fric.as_mut() {
            fr.end(&run.u);
        }
        let mut fv = run.fric.as_ref().map(|fr| fr.series(&run.v));
        if let (Some(st), Some(ops)) = (
            run.nit_fric.as_mut(),
            run.fac.as_ref().and_then(|f| f.nitsche.as_ref()),
        ) {
            // W_f with generalized-α's f̄_t = (1 − α_f) f_t^{n+1} + α_f f_tⁿ (contract §2.5).
            let (ft, vt, wf) =
                st.after_step(ops, &run.u, &run.v, &run.mv, &run.lambda, step as f64 * tau);
            fv = Some([ft, vt, wf]);
        }
        let mut timer = std::mem::take(&mut run.observe_timer);
        let e = timer.time(step, || run.observe(step, force, fv));
        run.observe_timer = timer;
        let e = e.map_err(Stop::Diverged)?;
        if let Some(fr) = run.fric.as_mut() {
            fr.observed(step, tau, e, &run.mv);
        }
        if let Some(st) = run.nit_fric.as_mut() {
            st.balance(run.e_last, e);
        }
        run.e_last = e;
        run.done = step;
        run.opts.step_stop(step, CLOCK_EVERY, run.start)?;
    }
    Ok(())
}
