//! The planner (contract §7): product, zip, bundles, exclude, applicability collapse, courant,
//! and run ids that are stable and canonical.

use std::path::Path;

use contact_sweep::sweep::{self, Key, Plan, SweepFile, Value};

fn plan(text: &str) -> Plan {
    let sf = SweepFile::parse(Path::new("test.toml"), text).unwrap_or_else(|e| panic!("{e}"));
    sweep::expand(&sf).unwrap_or_else(|e| panic!("{e}"))
}

fn num(p: &Plan, i: usize, k: Key) -> f64 {
    p.runs[i].params[&k].as_f64().unwrap()
}

fn ids(p: &Plan) -> Vec<String> {
    p.runs.iter().map(|r| r.run_id.clone()).collect()
}

const HEAD: &str = "name = \"t\"\nscene = \"bar1d\"\n";

#[test]
fn grid_is_a_cartesian_product_last_axis_fastest() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nT = 1.0\n[grid]\nh = [0.5, 0.25]\ndt = [0.1, 0.05, 0.025]\n"
    ));
    assert_eq!(p.combinations, 6);
    assert_eq!(p.runs.len(), 6);
    let pairs: Vec<(f64, f64)> = (0..6)
        .map(|i| (num(&p, i, Key::H), num(&p, i, Key::Dt)))
        .collect();
    assert_eq!(
        pairs,
        vec![
            (0.5, 0.1),
            (0.5, 0.05),
            (0.5, 0.025),
            (0.25, 0.1),
            (0.25, 0.05),
            (0.25, 0.025)
        ]
    );
}

#[test]
fn zip_advances_together_and_crosses_the_grid() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nT = 1.0\n[zip]\nh = [0.5, 0.25, 0.125]\ndt = [0.5, 0.25, 0.125]\n[grid]\nmass = [\"mod1\", \"mod3\"]\n"
    ));
    assert_eq!(p.runs.len(), 6);
    for i in 0..6 {
        assert_eq!(
            num(&p, i, Key::H),
            num(&p, i, Key::Dt),
            "zipped pairs stay paired"
        );
    }
    // zip varies slowest
    assert_eq!(num(&p, 0, Key::H), 0.5);
    assert_eq!(num(&p, 1, Key::H), 0.5);
    assert_eq!(p.runs[1].params[&Key::Mass], Value::Str("mod3".into()));
}

#[test]
fn bundles_set_several_parameters_and_label_axes_are_not_parameters() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nT = 1.0\nh = 0.1\ndt = 0.1\n[grid]\nmethod = [\n  {{ space = \"nitsche\", nitsche_gamma0 = 0.1, nitsche_theta = -1.0 }},\n  {{ space = \"mixed\", mass = \"mod3\" }},\n]\nscheme = [\"backward-euler\", {{ scheme = \"newmark\", newmark_beta = 0.5, newmark_gamma = 1.0 }}]\n"
    ));
    assert_eq!(p.runs.len(), 4);
    let r = &p.runs[0];
    assert_eq!(r.params[&Key::Space], Value::Str("nitsche".into()));
    assert_eq!(r.params[&Key::NitscheTheta], Value::Num(-1.0));
    assert_eq!(r.params[&Key::Scheme], Value::Str("theta".into()));
    assert_eq!(r.params[&Key::ThetaScheme], Value::Num(1.0));
    let r = &p.runs[1];
    assert_eq!(r.params[&Key::NewmarkBeta], Value::Num(0.5));
    assert_eq!(r.params[&Key::NewmarkGamma], Value::Num(1.0));
    assert_eq!(r.scheme_label, "newmark-dissipative");
    assert!(!p.runs[2].params.contains_key(&Key::NitscheGamma0));
}

#[test]
fn exclude_filters_match_resolved_values_and_aliases() {
    let p = plan(&format!(
        "{HEAD}exclude = [ {{ space = \"mixed\", scheme = \"crank-nicolson\" }}, {{ h = 0.25, mass = \"mod1\" }} ]\n[fixed]\nT = 1.0\ndt = 0.05\n[grid]\nh = [0.5, 0.25]\nmass = [\"mod1\", \"mod3\"]\nscheme = [\"crank-nicolson\", \"hybrid\", {{ scheme = \"newmark\", newmark_beta = 0.25, newmark_gamma = 0.5 }}]\n"
    ));
    // 12 combinations; the CN alias and the explicit (¼, ½) bundle are the same scheme, so 8
    // are excluded by the first filter, the hybrid at h = 0.25 with mod1 by the second.
    assert_eq!(p.combinations, 12);
    assert_eq!(p.excluded_by_filter, 9);
    assert_eq!(p.runs.len(), 3);
    assert!(
        p.runs
            .iter()
            .all(|r| r.params[&Key::Scheme] == Value::Str("hybrid".into()))
    );
}

#[test]
fn inapplicable_parameters_collapse_with_their_reason() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nT = 1.0\nh = 0.1\ndt = 0.1\n[grid]\nspace = [\"mixed\", \"nitsche\"]\nnitsche_gamma0 = [1e-6, 0.1, 1.0]\n"
    ));
    // mixed × 3 γ0 collapse into one run; nitsche keeps 3.
    assert_eq!(p.combinations, 6);
    assert_eq!(p.runs.len(), 4);
    let reasons: Vec<(&String, &usize)> = p.collapsed.iter().collect();
    assert_eq!(reasons.len(), 1);
    assert!(
        reasons[0]
            .0
            .contains("nitsche_gamma0 applies to space = nitsche only"),
        "{reasons:?}"
    );
    assert_eq!(*reasons[0].1, 2);
    assert!(p.summary().contains("2 collapsed"));
}

#[test]
fn meaningless_combinations_are_left_out_with_reason() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nT = 1.0\nh = 0.1\ndt = 0.1\nnitsche_gamma0 = 1e-6\n[grid]\nspace = [\"mixed\", \"nitsche\"]\nmass = [\"consistent\", \"mod3\"]\nscheme = [\"paoli-schatzman\", \"hybrid\"]\n"
    ));
    // PS with Nitsche (2) and hybrid with mixed + consistent (1) are meaningless.
    assert_eq!(p.runs.len(), 5);
    assert_eq!(p.inapplicable.values().sum::<usize>(), 3);
    assert!(
        p.inapplicable
            .keys()
            .any(|k| k.contains("paoli-schatzman is defined for space = mixed only"))
    );
    assert!(
        p.inapplicable
            .keys()
            .any(|k| k.contains("massless contact node"))
    );
}

#[test]
fn courant_and_elements_derive_dt_and_h_and_keep_ids() {
    let a = plan(&format!("{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n"));
    let b = plan(&format!("{HEAD}[fixed]\nelements = 100\ncourant = 1.5\n"));
    assert_eq!(num(&b, 0, Key::Dt), 1.5 * 0.01);
    assert_eq!(num(&a, 0, Key::Courant), 1.5);
    assert_eq!(
        ids(&a),
        ids(&b),
        "the same run, however its discretisation was written"
    );
}

#[test]
fn run_ids_are_canonical_and_stable() {
    let base = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n[grid]\nmass = [\"mod3\", \"consistent\"]\n"
    ));
    // 1 vs 1.0, explicit defaults, a default-valued extra axis, another sweep name and order:
    let other = plan(
        "name = \"another\"\nscene = \"bar1d\"\n[fixed]\nT = 12\ndt = 0.015\nlength = 1\n[grid]\ngap = [0.0]\nmass = [\"consistent\", \"mod3\"]\nh = [0.01]\nscheme = [\"crank-nicolson\"]\n",
    );
    let mut a = ids(&base);
    let mut b = ids(&other);
    a.sort();
    b.sort();
    assert_eq!(a, b);
    // Changing a value changes the id.
    let c = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\ngap = 0.1\n[grid]\nmass = [\"mod3\", \"consistent\"]\n"
    ));
    assert!(ids(&c).iter().all(|id| !a.contains(id)));
    // Frozen: the id of the 003 default CN run must never change across versions (it names
    // rows in users' folders; resume and cross-sweep joins depend on it).
    assert_eq!(base.runs[1].run_id, "35050bcfa8862a8f");
}

#[test]
fn contact_init_applies_to_a_massless_contact_node_only() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n[grid]\nmass = [\"consistent\", \"mod3\"]\ncontact_init = [\"consistent\", \"interpolant\"]\n"
    ));
    // consistent mass × 2 starts collapse into one run, with the reason; mod3 keeps both.
    assert_eq!(p.combinations, 4);
    assert_eq!(p.runs.len(), 3);
    let reasons: Vec<(&String, &usize)> = p.collapsed.iter().collect();
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    assert!(
        reasons[0]
            .0
            .contains("contact_init applies to a massless contact node only"),
        "{reasons:?}"
    );
    assert_eq!(*reasons[0].1, 1);
    // The column is absent where it does not apply, present (default included) where it does.
    assert!(!p.runs[0].params.contains_key(&Key::ContactInit));
    assert_eq!(
        p.runs[1].params[&Key::ContactInit],
        Value::Str("consistent".into())
    );
    assert_eq!(
        p.runs[2].params[&Key::ContactInit],
        Value::Str("interpolant".into())
    );
    assert!(
        p.runs[2].label.contains("interpolant"),
        "{}",
        p.runs[2].label
    );
    // Frozen ids (contract §7): explicit `consistent` is the default and enters no id, so runs
    // written before the key existed keep theirs — the 003 CN run with the consistent mass
    // and with mod3 (see run_ids_are_canonical_and_stable).
    assert_eq!(p.runs[0].run_id, "35050bcfa8862a8f");
    assert_eq!(p.runs[1].run_id, "0475aa43696174b7");
    let omitted = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n[grid]\nmass = [\"consistent\", \"mod3\"]\n"
    ));
    assert_eq!(ids(&omitted), ids(&p)[..2].to_vec());
    // The interpolant start is another run.
    assert!(!ids(&omitted).contains(&p.runs[2].run_id));
}

#[test]
fn aliases_and_explicit_parameters_are_the_same_run() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.1\ndt = 0.1\n[grid]\nscheme = [\"crank-nicolson\", {{ scheme = \"newmark\", newmark_beta = 0.25, newmark_gamma = 0.5 }}, \"backward-euler\", {{ scheme = \"theta\", theta_scheme = 1.0 }}]\n"
    ));
    assert_eq!(p.runs.len(), 2);
    assert_eq!(p.collapsed.values().sum::<usize>(), 2);
}

#[test]
fn ensembles_expand_into_distinct_members() {
    let p = plan(&format!(
        "{HEAD}ensemble = {{ perturbation = 1e-14, samples = 4, seed = 7 }}\n[fixed]\nh = 0.1\ndt = 0.1\n"
    ));
    assert_eq!(p.runs.len(), 4);
    let mut v = ids(&p);
    v.dedup();
    assert_eq!(v.len(), 4);
    assert_eq!(p.runs[3].sample, Some((3, 1e-14)));
}

#[test]
fn an_axis_overrides_a_fixed_value() {
    // contract §7's own example sets h and dt in [fixed] and again in [zip]: [fixed] is a baseline.
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\nmass = \"mod3\"\n[grid]\nmass = [\"mod1\", \"mod2\"]\n[zip]\nh = [0.25, 0.125]\ndt = [0.25, 0.125]\n"
    ));
    assert_eq!(p.runs.len(), 4);
    assert!(p.runs.iter().all(|r| num_of(r, Key::H) >= 0.125));
    assert!(
        p.runs
            .iter()
            .all(|r| r.params[&Key::Mass] != Value::Str("mod3".into()))
    );
    let s = p.summary();
    assert!(
        s.contains("fixed.h is overridden by [zip]")
            && s.contains("fixed.mass is overridden by [grid] mass"),
        "{s}"
    );
}

fn num_of(r: &contact_sweep::sweep::RunSpec, k: Key) -> f64 {
    r.params[&k].as_f64().unwrap()
}

/// The sweep examples of the project's own docs plan verbatim: the guide's (4 schemes × 3 zipped
/// levels) and the numerical contract's §7 example (two explicit Newmark bundles, backward
/// Euler, CN and hybrid: 5 schemes × 3 levels), each the first TOML block of its page.
#[test]
fn the_sweep_examples_of_the_docs_are_accepted_verbatim() {
    for (page, runs) in [("docs/guide.md", 12), ("docs/contract.md", 15)] {
        let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(page))
            .unwrap_or_else(|e| panic!("{page}: {e}"));
        let start = text.find("```toml\n").expect("a toml block") + "```toml\n".len();
        let end = start + text[start..].find("```").unwrap();
        let p = plan(&text[start..end]);
        assert_eq!(p.runs.len(), runs, "{page}");
        assert_eq!(p.sweep.name, "nitsche-energy", "{page}");
    }
}

fn plan_err(text: &str) -> String {
    let sf = match SweepFile::parse(Path::new("test.toml"), text) {
        Ok(sf) => sf,
        Err(e) => return e.to_string(),
    };
    match sweep::expand(&sf) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

const BAR2D: &str = "name = \"b\"\nscene = \"bar2d\"\n";

#[test]
fn bar2d_runs_share_one_reference_stored_on_the_coarsest_common_lattice() {
    let p = plan(&format!(
        "{BAR2D}reference = {{ h = 0.0015625, dt = 0.00078125, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n\
         [zip]\nh = [0.05, 0.025, 0.0125]\ndt = [0.025, 0.0125, 0.00625]\n[grid]\nmass = [\"consistent\", \"mod1\"]\nscheme = [\"crank-nicolson\", \"backward-euler\"]\n"
    ));
    assert_eq!(p.runs.len(), 12);
    // One reference whatever the run's mass and scheme: the reference's keys override them.
    assert_eq!(p.references.len(), 1);
    let r = &p.references[0];
    // Ratios 32, 16, 8 in space and time: everything the runs need is every 8th node and step.
    assert_eq!((r.space_stride, r.time_stride), (8, 8));
    assert!(
        p.runs
            .iter()
            .all(|x| x.reference.as_deref() == Some(r.spec.run_id.as_str()))
    );
    // Defaults of bar2d (contract §1.2) fill the columns; elements counts the height (1/h).
    assert_eq!(num(&p, 0, Key::T), 2.0);
    assert_eq!(num(&p, 0, Key::Gap), 0.2);
    assert_eq!(num(&p, 0, Key::LameMu), 0.5);
    assert_eq!(p.runs[0].params[&Key::Elements], Value::Int(20));
    // courant = c_p τ / h with c_p = √((λ+2μ)/ρ) = √1.25.
    assert!((num(&p, 0, Key::Courant) - 0.5 * 1.25f64.sqrt()).abs() < 1e-12);
    // The reference is part of a run's identity: another reference, another id.
    let q = plan(&format!(
        "{BAR2D}reference = {{ h = 0.003125, dt = 0.0015625, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n\
         [zip]\nh = [0.05, 0.025, 0.0125]\ndt = [0.025, 0.0125, 0.00625]\n[grid]\nmass = [\"consistent\", \"mod1\"]\nscheme = [\"crank-nicolson\", \"backward-euler\"]\n"
    ));
    assert_ne!(ids(&p), ids(&q));
}

/// Regression: the FE scenes used to expand `contact_init` although both starts coincide where
/// the massless dofs carry no load (the bars: no gravity), so a sweep over it ran every run
/// twice. Under gravity with the body load (the disc) they differ and both run (issue 42,
/// contract §1.3).
#[test]
fn contact_init_over_an_fe_scene_makes_no_duplicate_runs() {
    for scene in ["bar2d", "disc2d"] {
        let h = if scene == "bar2d" { 0.05 } else { 4.0 };
        let p = plan(&format!(
            "name = \"b\"\nscene = \"{scene}\"\n[fixed]\nh = {h}\ndt = 0.025\nmass = \"mod3\"\n[grid]\ncontact_init = [\"consistent\", \"interpolant\"]\n"
        ));
        if scene == "disc2d" {
            assert_eq!((p.combinations, p.runs.len()), (2, 2), "{scene}");
            continue;
        }
        assert_eq!((p.combinations, p.runs.len()), (2, 1), "{scene}");
        let reasons: Vec<&String> = p.collapsed.keys().collect();
        assert!(
            reasons.len() == 1
                && reasons[0].contains("contact_init changes nothing without gravity"),
            "{scene}: {reasons:?}"
        );
        assert!(!p.runs[0].params.contains_key(&Key::ContactInit));
    }
}

#[test]
fn bar2d_refuses_what_it_cannot_model_with_the_key_and_reason() {
    let base = "[fixed]\nh = 0.05\ndt = 0.025\n";
    let e = plan_err(&format!(
        "{BAR2D}reference = {{ h = 0.02, dt = 0.0125 }}\n{base}"
    ));
    assert!(
        e.contains("test.toml") && e.contains("key `reference.h`"),
        "{e}"
    );
    let e = plan_err(&format!(
        "{BAR2D}reference = {{ h = 0.00625, dt = 0.01 }}\n{base}"
    ));
    assert!(
        e.contains("key `reference.dt`") && e.contains("whole number"),
        "{e}"
    );
    // Nitsche and the penalty run on the bars (the bottom face's quadrature points); the hybrid
    // scheme needs their contact potential, so with mixed it is refused, with the reason.
    let p = plan(&format!(
        "{BAR2D}{base}space = \"nitsche\"\nnitsche_gamma0 = 1e-3\nscheme = \"hybrid\"\n"
    ));
    assert_eq!(p.runs.len(), 1);
    let e = plan_err(&format!("{BAR2D}{base}scheme = \"hybrid\"\n"));
    assert!(
        e.contains("key `fixed.scheme`") && e.contains("bar2d") && e.contains("space = mixed"),
        "{e}"
    );
    let e = plan_err(&format!("{BAR2D}{base}space = \"dual\"\n"));
    assert!(e.contains("key `fixed.space`"), "{e}");
    let e = plan_err(&format!("{BAR2D}{base}mass = \"singular-dynamic\"\n"));
    assert!(
        e.contains("key `fixed.mass`") && e.contains("1D bar only"),
        "{e}"
    );
    let e = plan_err(&format!("{BAR2D}[fixed]\nh = 0.03\ndt = 0.01\n"));
    assert!(e.contains("key `fixed.h`") && e.contains("width"), "{e}");
    let e = plan_err(&format!("{BAR2D}{base}amplitude = 0.5\n"));
    assert!(e.contains("not a parameter of scene bar2d"), "{e}");
    let e = plan_err(&format!(
        "{BAR2D}{base}scheme = \"central-difference\"\nmass = \"mod1\"\n"
    ));
    assert!(
        e.contains("key `fixed.scheme`") && e.contains("explicit"),
        "{e}"
    );
    // bar1d has a closed form: a reference is refused there.
    let e = plan_err(&format!(
        "{HEAD}reference = {{ h = 0.01 }}\n[fixed]\nh = 0.1\ndt = 0.1\n"
    ));
    assert!(
        e.contains("key `reference`") && e.contains("closed-form"),
        "{e}"
    );
}

/// contract §3.2's keys (`rho_inf`, `hht_alpha`, and `theta_scheme`/`restitution` now also read by
/// moreau-jean) do not apply to the existing schemes: crossing the 003 CN run with them
/// collapses to that run, with its frozen id; the new schemes drop what does not apply to them.
#[test]
fn comparison_method_keys_collapse_and_keep_existing_ids() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n[grid]\nmass = [\"consistent\"]\nrho_inf = [0.5, 1.0]\nhht_alpha = [0.1, 0.2]\n"
    ));
    assert_eq!(p.runs.len(), 1);
    assert_eq!(p.runs[0].run_id, "35050bcfa8862a8f");
    assert!(
        p.collapsed
            .keys()
            .any(|k| k.contains("rho_inf applies to generalized-alpha only")),
        "{:?}",
        p.collapsed
    );
    // The methods with their parameters: distinct runs, distinct ids; ρ∞ applies to
    // generalized-alpha, α to hht, θ and e to moreau-jean.
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\n[grid]\nmethod = [\n  {{ scheme = \"kane\" }},\n  {{ scheme = \"contact-stabilized-newmark\" }},\n  {{ scheme = \"generalized-alpha\", rho_inf = 0.5 }},\n  {{ scheme = \"hht\", hht_alpha = 0.1 }},\n  {{ scheme = \"moreau-jean\", restitution = 1.0 }},\n  {{ scheme = \"moreau-jean\" }},\n  {{ scheme = \"discrete-gradient\", space = \"penalty\", penalty_gamma0 = 1.0 }},\n]\n"
    ));
    assert_eq!(p.runs.len(), 7);
    let mut all = ids(&p);
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 7);
    assert_eq!(p.runs[2].params[&Key::RhoInf].as_f64(), Some(0.5));
    assert_eq!(p.runs[3].params[&Key::HhtAlpha].as_f64(), Some(0.1));
    assert!(!p.runs[3].params.contains_key(&Key::RhoInf));
    // Moreau–Jean's own defaults: θ = ½, e = 0.
    assert_eq!(p.runs[5].params[&Key::ThetaScheme].as_f64(), Some(0.5));
    assert_eq!(p.runs[5].params[&Key::Restitution].as_f64(), Some(0.0));
}

/// Where the methods of contract §3.2 do not apply, the planner leaves the run out with its reason.
#[test]
fn comparison_methods_are_left_out_where_they_do_not_apply() {
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\nnitsche_gamma0 = 1e-6\npenalty_gamma0 = 1.0\n[grid]\nspace = [\"mixed\", \"nitsche\", \"penalty\"]\nmass = [\"consistent\", \"lumped\", \"mod3\"]\nscheme = [\"kane\", \"contact-stabilized-newmark\", \"generalized-alpha\", \"moreau-jean\", \"discrete-gradient\"]\n"
    ));
    let reasons: Vec<&String> = p.inapplicable.keys().collect();
    let has = |s: &str| reasons.iter().any(|k| k.contains(s));
    assert!(has("kane is defined for space = mixed only"), "{reasons:?}");
    assert!(has("moreau-jean is defined for space = mixed only"));
    assert!(has(
        "contact-stabilized-newmark needs inertia on the contact dof"
    ));
    assert!(has("generalized-alpha needs inertia on the contact dof"));
    assert!(has("discrete-gradient needs a contact potential"));
    // kane: mixed × 3 masses; CSN, MJ: mixed × 2 masses with inertia; GA: 3 spaces × 2; DG:
    // nitsche, penalty × 3 masses — 3 + 2 + 2 + 6 + 6 = 19 of 45.
    assert_eq!(p.runs.len(), 19);
    let labels: Vec<&str> = p.runs.iter().map(|r| r.label.as_str()).collect();
    assert!(labels.contains(&"mixed · mod3 · kane"), "{labels:?}");
    // Central difference with the mixed method: kinematic contact with the lumped mass only.
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.009\nscheme = \"central-difference\"\n[grid]\nmass = [\"consistent\", \"lumped\"]\n"
    ));
    let labels: Vec<&str> = p.runs.iter().map(|r| r.label.as_str()).collect();
    assert_eq!(labels, ["mixed · lumped · central-difference"]);
}

/// `sweeps/comparison_bar1d.toml` plans every method of contract §3.2 applicable to the bar on the
/// h = τ ladder and at ν = 1.5: 14 methods × 6 levels, nothing collapsed or left out, and its
/// CN run at the 003 setting is the frozen run of `run_ids_are_canonical_and_stable`.
#[test]
fn comparison_sweep_plans_every_method_on_its_ladder() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/sweeps/comparison_bar1d.toml"
    ));
    let sf = SweepFile::load(path).unwrap_or_else(|e| panic!("{e}"));
    let p = sweep::expand(&sf).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(p.runs.len(), 84);
    assert!(p.inapplicable.is_empty() && p.collapsed.is_empty());
    assert!(ids(&p).contains(&"35050bcfa8862a8f".to_string()));
}

/// contract §2.5: `friction = "none"` is today's engine. Given explicitly (as `--set` puts it on
/// top of a file), it keeps every run id of every 1D and 2D sweep file — the key's default
/// never enters the canonical text — and the 003 CN run keeps its frozen id.
#[test]
fn friction_none_keeps_every_run_id() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        // The 3D and large-mesh files plan slowly and name the same keys.
        if !["bar1d", "oscillator", "bar2d"]
            .iter()
            .any(|s| text.contains(&format!("scene = \"{s}\"")))
        {
            continue;
        }
        let base = SweepFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let with = SweepFile::load_with(&path, &["friction=\"none\"".to_string()])
            .unwrap_or_else(|e| panic!("{e}"));
        let a = sweep::expand(&base).unwrap_or_else(|e| panic!("{e}"));
        let b = sweep::expand(&with).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(ids(&a), ids(&b), "{}", path.display());
        assert!(
            a.runs
                .iter()
                .all(|r| !r.params.contains_key(&Key::FrictionCoefficient)),
            "{}",
            path.display()
        );
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} sweep files checked");
    let p = plan(&format!(
        "{HEAD}[fixed]\nh = 0.01\ndt = 0.015\nfriction = \"none\"\n[grid]\nmass = [\"consistent\"]\n"
    ));
    assert_eq!(p.runs[0].run_id, "35050bcfa8862a8f");
}

/// contract §1.8's keys at their defaults keep every run id: `velocity_tangential = 0` on every
/// disc2d/sphere3d/mesh2d/mesh3d sweep file and `incline = 0` on the mesh files, set on top of
/// the file as `--set` does (a physics key at its default never enters the canonical text), and
/// the 003 disc's CN run keeps the id main gives it. Files that already set a key are skipped
/// for it (overriding would change their runs).
#[test]
fn velocity_tangential_and_incline_at_zero_keep_every_run_id() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps");
    let mut checked = 0;
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml"))
        .collect();
    paths.sort();
    for path in paths {
        let text = std::fs::read_to_string(&path).unwrap();
        let scene = ["disc2d", "sphere3d", "mesh2d", "mesh3d"]
            .into_iter()
            .find(|s| text.contains(&format!("scene = \"{s}\"")));
        let Some(scene) = scene else { continue };
        let mut sets = Vec::new();
        if !text.contains("velocity_tangential") {
            sets.push("velocity_tangential=0.0".to_string());
        }
        if scene.starts_with("mesh") && !text.contains("incline") {
            sets.push("incline=0.0".to_string());
        }
        if sets.is_empty() {
            continue;
        }
        let base = SweepFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let with = SweepFile::load_with(&path, &sets).unwrap_or_else(|e| panic!("{e}"));
        let a = sweep::expand(&base).unwrap_or_else(|e| panic!("{e}"));
        let b = sweep::expand(&with).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(ids(&a), ids(&b), "{}", path.display());
        checked += 1;
    }
    // 9 files today: the five 003 disc and sphere sweeps, comparison_disc, disc_p2_load,
    // bar2d_triangles and hertz_halfdisc (the sliding-block and friction files set the keys).
    assert!(checked >= 9, "only {checked} sweep files checked");
    let p = plan(
        "name = \"t\"\nscene = \"disc2d\"\n[fixed]\nh = 8.0\ndt = 0.1\nT = 1.0\nvelocity_tangential = 0.0\n",
    );
    // The id of this run on main before the key existed (`contact-sweep plan`).
    assert_eq!(p.runs[0].run_id, "831b1028f988a386");
    let moving = plan(
        "name = \"t\"\nscene = \"disc2d\"\n[fixed]\nh = 8.0\ndt = 0.1\nT = 1.0\nvelocity_tangential = 1.0\n",
    );
    assert_ne!(moving.runs[0].run_id, "831b1028f988a386");
}

/// The friction keys on the layer (contract §2.5, §7): a bound applies to its own law only, so
/// across a `friction` axis the frictionless runs (and Tresca's runs crossed with Coulomb's
/// coefficients) collapse, with the reason; `none` never enters an id, each bound does.
#[test]
fn friction_keys_apply_to_their_law_and_collapse() {
    let p = plan(
        "name = \"t\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\n[grid]\nfriction = [\"none\", \"coulomb\", \"tresca\"]\nfriction_coefficient = [0.1, 0.3]\ntresca_threshold = [0.5]\n",
    );
    assert_eq!(p.runs.len(), 4);
    let labels: Vec<&str> = p.runs.iter().map(|r| r.label.as_str()).collect();
    assert!(labels[1].ends_with("coulomb(μ_f=0.1)"), "{labels:?}");
    assert!(labels[3].ends_with("tresca(s=0.5)"), "{labels:?}");
    assert!(
        p.collapsed
            .keys()
            .any(|k| k.contains("friction_coefficient applies to friction = coulomb only")),
        "{:?}",
        p.collapsed
    );
    assert!(
        p.collapsed
            .keys()
            .any(|k| k.contains("tresca_threshold applies to friction = tresca only")),
        "{:?}",
        p.collapsed
    );
    assert_eq!(p.runs[0].params[&Key::Friction].as_str(), Some("none"));
    assert!(!p.runs[0].params.contains_key(&Key::FrictionCoefficient));
    assert_eq!(
        p.runs[2].params[&Key::FrictionCoefficient].as_f64(),
        Some(0.3)
    );
    // The frictionless layer run is the one without the axis, with the same id.
    let bare = plan("name = \"u\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\n");
    assert_eq!(bare.runs[0].run_id, p.runs[0].run_id);
    let mut all = ids(&p);
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 4);
    // Hybrid across a friction axis: refused by the scene with the literature's reason.
    let sf = SweepFile::parse(
        Path::new("t.toml"),
        "name = \"t\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\nmass = \"mod3\"\nscheme = \"hybrid\"\n",
    )
    .unwrap();
    let err = sweep::expand(&sf).unwrap_err().to_string();
    assert!(
        err.contains("has no frictional version in the literature"),
        "{err}"
    );
}
