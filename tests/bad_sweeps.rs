//! Bad sweep files: each is refused before anything runs, with exit status 2, a message naming
//! the file and the key (and the line where the parser gives one), no panic, and no output
//! folder created.

mod common;

use common::{cli, write};

/// (file body, key the message must name, a phrase of the reason)
const CASES: &[(&str, &str, &str)] = &[
    (
        "name = \"x\"\nscene = \"disc2d\"\nreference = { h = 8.0, dt = 0.05 }\n[fixed]\nh = 4.0\ndt = 0.1\n",
        "reference.h",
        "the reference mesh (h = 8) is coarser than the run's (h = 4)",
    ),
    (
        "name = \"x\"\nscene = \"disc2d\"\n[fixed]\nh = 4.0\ndt = 0.1\n[grid]\ndegree = [2, 3]\n",
        "grid.degree[1]",
        "must be 1 or 2",
    ),
    (
        "name = \"x\"\nscene = \"disc2d\"\n[fixed]\nh = 4.0\ndt = 0.1\nmass = \"zero-contact\"\nscheme = \"hybrid\"\n",
        "fixed.scheme",
        "reduced hybrid of mixed with a massless contact (000 §5) is 1D only",
    ),
    (
        "name = \"x\"\nscene = \"sphere3d\"\n[fixed]\nh = 8.0\ndt = 0.1\nmass = \"singular-dynamic\"\n",
        "fixed.mass",
        "defined for the 1D bar only",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.1\ndegree = 2\n",
        "degree",
        "bar2d",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nmass = \"mod3\"\n[grid]\ncontact_init = [\"consistent\", \"exact\"]\n",
        "grid.contact_init[1]",
        "unknown contact_init `exact` (expected consistent or interpolant",
    ),
    (
        "name = \"x\"\nscene = \"bar3d\"\n[fixed]\nh = 0.05\ndt = 0.025\nsolver = \"gmres\"\n",
        "fixed.solver",
        "unknown solver `gmres` (expected direct",
    ),
    (
        "name = \"x\"\nscene = \"bar3d\"\n[fixed]\nh = 0.05\ndt = 0.025\nsolver = \"cg\"\n[grid]\ncg_tol = [1e-12, 0.0]\n",
        "grid.cg_tol[1]",
        "must lie in (0, 1)",
    ),
    (
        "name = \"x\"\nscene = \"bar3d\"\n[fixed]\nh = 0.05\ndt = 0.025\nsolver = \"cg\"\ncg_tol = -1e-12\n",
        "fixed.cg_tol",
        "must lie in (0, 1)",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\nnmae = 1\n[fixed]\nh = 0.1\ndt = 0.1\n",
        "nmae",
        "unknown top-level key",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[grid]\nnitsche_gama0 = [1.0]\n",
        "grid.nitsche_gama0",
        "did you mean `nitsche_gamma0`",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = \"0.1\"\ndt = 0.1\n",
        "fixed.h",
        "expected a number, found a string",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = -0.01\ndt = 0.1\n",
        "fixed.h",
        "must be > 0",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.0\n",
        "fixed.dt",
        "must be > 0",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nspace = \"nitsche\"\n[grid]\nnitsche_gamma0 = [1e-6, 0.0]\n",
        "grid.nitsche_gamma0[1]",
        "must be > 0",
    ),
    // λ = 0 (ν = 0) is a material; λ < 0 is refused, μ = 0 too (K would have more than the
    // rigid motions in its null space).
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.25\ndt = 0.01\nlame_lambda = -1.0\n",
        "fixed.lame_lambda",
        "must be ≥ 0",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.25\ndt = 0.01\nlame_mu = 0.0\n",
        "fixed.lame_mu",
        "must be > 0",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nmass = \"weights\"\nmass_weights = [2.0, -1.0]\n",
        "fixed.mass_weights",
        "weight 2 must be > 0",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nmass = \"weights\"\nmass_weights = [nan]\n",
        "fixed.mass_weights",
        "finite",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"newmark\"\nnewmark_beta = 0.7\n",
        "fixed.newmark_beta",
        "must lie in [0, 0.5]",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"newmark\"\nnewmark_gamma = 1.5\n",
        "fixed.newmark_gamma",
        "must lie in [0, 1]",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"theta\"\ntheta_scheme = 2.0\n",
        "fixed.theta_scheme",
        "must lie in [0, 1]",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"paoli-schatzman\"\nrestitution = -0.1\n",
        "fixed.restitution",
        "must lie in [0, 1]",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.01\ndt = 0.02\nmass = \"mod3\"\nscheme = \"central-difference\"\n",
        "fixed.dt",
        "above the CFL limit",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[zip]\nh = [0.1, 0.05]\ndt = [0.1, 0.05, 0.025]\n",
        "zip.dt",
        "equal lengths",
    ),
    (
        "scene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n",
        "name",
        "required key missing",
    ),
    (
        "name = \"x\"\nscene = \"bar9d\"\n[fixed]\nh = 0.1\ndt = 0.1\n",
        "scene",
        "unknown scene",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = = 0.1\n",
        "(syntax)",
        "invalid TOML",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.3\ndt = 0.1\n",
        "fixed.h",
        "does not divide length",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nlame_mu = 0.5\n",
        "fixed.lame_mu",
        "not a parameter of scene bar1d",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\nelements = 10\ndt = 0.1\n",
        "fixed.elements",
        "either h or elements",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"crank-nicholson\"\n",
        "fixed.scheme",
        "unknown scheme",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\ndt = 0.1\n[grid]\nh = 0.1\n",
        "grid.h",
        "expected a list of values",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\ndt = 0.1\n[grid]\nh = []\n",
        "grid.h",
        "empty list",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"theta\"\n",
        "fixed.scheme",
        "needs theta_scheme",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nspace = \"nitsche\"\n",
        "fixed.space",
        "needs nitsche_gamma0",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\ndt = 0.1\n[zip]\nh = [0.1, 0.2]\n[grid]\nh = [0.1, 0.2]\n",
        "zip.h[0]",
        "two axes may not set one parameter",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\nreference = { h = 0.01 }\n[fixed]\nh = 0.1\ndt = 0.1\n",
        "reference",
        "closed-form",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"theta\"\ntheta_scheme = 0.0\n",
        "fixed.theta_scheme",
        "forward Euler",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\n",
        "dt",
        "required",
    ),
    (
        "name = \"../evil\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n",
        "name",
        "folder-safe",
    ),
    // [summary]: the column choice of the convergence tables.
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[summary]\nerrors = [\"err_u_l2h1\", \"err_u_h1\"]\n",
        "summary.errors",
        "unknown error column `err_u_h1`; valid: err_u_l2l2, err_u_l2h1, err_u_linfl2, err_sigma_l2, err_sigma_mid_l2, err_energy_l2, err_u_contact_max, err_sigma_t_l2, err_vt_final, or all",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[summary]\nerrors = []\n",
        "summary.errors",
        "empty list",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[summary]\nerrors = [\"err_u_l2h1\", 3]\n",
        "summary.errors[1]",
        "expected an error column name (a string), found a integer",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[summary]\nrates = \"no\"\n",
        "summary.rates",
        "expected true or false, found a string",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[summary]\ncolumns = [\"err_u_l2h1\"]\n",
        "summary.columns",
        "unknown key (expected errors, rates, slopes, flags)",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\nsummary = 1\n[fixed]\nh = 0.1\ndt = 0.1\n",
        "summary",
        "expected a table",
    ),
    // Friction (contract §2.5): bounds, a law without its parameter, a bound without a law, and
    // the scenes and methods that cannot take one.
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"coulomb\"\nfriction_coefficient = -0.1\n",
        "fixed.friction_coefficient",
        "must be ≥ 0 (a friction bound",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"coulomb\"\n[grid]\nfriction_coefficient = [0.1, nan]\n",
        "grid.friction_coefficient[1]",
        "must be a finite number",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"tresca\"\ntresca_threshold = -2.0\n",
        "fixed.tresca_threshold",
        "must be ≥ 0 (a friction bound",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"tresca\"\n",
        "fixed.friction",
        "friction = tresca needs tresca_threshold",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"coulomb\"\n",
        "fixed.friction",
        "friction = coulomb needs friction_coefficient",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[grid]\nfriction_coefficient = [0.1, 0.3]\n",
        "grid.friction_coefficient[0]",
        "sets a friction bound but friction = \"none\" (the default) for this run",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"none\"\ntresca_threshold = 1.0\n",
        "fixed.tresca_threshold",
        "sets a friction bound but friction = \"none\" for this run",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"dry\"\n",
        "fixed.friction",
        "unknown friction `dry` (expected none, tresca",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n",
        "fixed.friction",
        "scene bar1d has no tangential direction",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n",
        "fixed.friction",
        "the oscillator's one dof is normal to the obstacle",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nscheme = \"discrete-gradient\"\nspace = \"penalty\"\nfriction = \"tresca\"\ntresca_threshold = 0.1\n",
        "fixed.scheme",
        "discrete-gradient has no frictional version in the literature (contract §2.5)",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nscheme = \"paoli-schatzman\"\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n",
        "fixed.scheme",
        "paoli-schatzman has no frictional version in the literature (contract §2.5)",
    ),
    (
        "name = \"x\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\nfriction_coefficient = 0.3\n",
        "fixed.friction_coefficient",
        "sets a friction bound but friction = \"none\" (the default) for this run",
    ),
    (
        "name = \"x\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\nspace = \"penalty\"\npenalty_gamma0 = 10.0\nscheme = \"discrete-gradient\"\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n",
        "fixed.scheme",
        "scheme = discrete-gradient has no frictional version in the literature (contract §2.5)",
    ),
    (
        "name = \"x\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\nfriction = \"tresca\"\ntresca_threshold = inf\n",
        "fixed.tresca_threshold",
        "must be a finite number",
    ),
    // The oscillator's dry friction (contract §1.5): F ≥ 0 and finite, the oscillator's key only,
    // and only with a scheme that has a frictional step.
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nfriction_force = -1.0\n",
        "fixed.friction_force",
        "must be ≥ 0 (a friction bound",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nfriction_force = inf\n",
        "fixed.friction_force",
        "must be a finite number, got inf",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\n[grid]\nfriction_force = [1.0, nan]\n",
        "grid.friction_force[1]",
        "must be a finite number, got NaN",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nfriction_force = 1.0\n",
        "fixed.friction_force",
        "`friction_force` is not a parameter of scene bar1d",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nfriction_force = 1.0\nscheme = \"paoli-schatzman\"\n",
        "fixed.friction_force",
        "paoli-schatzman has no frictional version in the literature",
    ),
    // contract §1.8: the tilt of the plane under a mesh body (|α| < 90°: at 90° the weight no
    // longer presses the body on it), the initial tangential velocity (finite), and each key
    // only on the scenes that take it (velocity_tangential: layer1d, disc2d, sphere3d, mesh2d,
    // mesh3d; incline: mesh2d, mesh3d). The range checks come before the mesh file is read.
    (
        "name = \"x\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"block2d.msh\"\ndt = 0.01\nincline = 90.0\n",
        "fixed.incline",
        "must lie in (-90, 90) degrees",
    ),
    (
        "name = \"x\"\nscene = \"mesh3d\"\n[fixed]\nmesh = \"block3d.msh\"\ndt = 0.01\n[grid]\nincline = [10.0, -120.0]\n",
        "grid.incline[1]",
        "must lie in (-90, 90) degrees",
    ),
    (
        "name = \"x\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"block2d.msh\"\ndt = 0.01\n[grid]\nincline = [10.0, nan]\n",
        "grid.incline[1]",
        "must be a finite number, got NaN",
    ),
    (
        "name = \"x\"\nscene = \"mesh3d\"\n[fixed]\nmesh = \"block3d.msh\"\ndt = 0.01\nincline = -inf\n",
        "fixed.incline",
        "must be a finite number, got -inf",
    ),
    (
        "name = \"x\"\nscene = \"disc2d\"\n[fixed]\nh = 8.0\ndt = 0.1\nvelocity_tangential = inf\n",
        "fixed.velocity_tangential",
        "must be a finite number, got inf",
    ),
    (
        "name = \"x\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"block2d.msh\"\ndt = 0.01\n[grid]\nvelocity_tangential = [1.0, nan]\n",
        "grid.velocity_tangential[1]",
        "must be a finite number, got NaN",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nvelocity_tangential = 1.0\n",
        "fixed.velocity_tangential",
        "`velocity_tangential` is not a parameter of scene bar2d",
    ),
    (
        "name = \"x\"\nscene = \"bar3d\"\n[fixed]\nh = 0.05\ndt = 0.025\n[grid]\nvelocity_tangential = [0.0, 1.0]\n",
        "grid.velocity_tangential[1]",
        "`velocity_tangential` is not a parameter of scene bar3d",
    ),
    (
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nvelocity_tangential = 1.0\n",
        "fixed.velocity_tangential",
        "`velocity_tangential` is not a parameter of scene bar1d",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nvelocity_tangential = 1.0\n",
        "fixed.velocity_tangential",
        "`velocity_tangential` is not a parameter of scene oscillator",
    ),
    (
        "name = \"x\"\nscene = \"disc2d\"\n[fixed]\nh = 8.0\ndt = 0.1\nincline = 10.0\n",
        "fixed.incline",
        "`incline` is not a parameter of scene disc2d",
    ),
    (
        "name = \"x\"\nscene = \"sphere3d\"\n[fixed]\nh = 8.0\ndt = 0.1\nincline = 10.0\n",
        "fixed.incline",
        "`incline` is not a parameter of scene sphere3d",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nincline = 10.0\n",
        "fixed.incline",
        "`incline` is not a parameter of scene bar2d",
    ),
    (
        "name = \"x\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\nincline = 10.0\n",
        "fixed.incline",
        "`incline` is not a parameter of scene layer1d",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nincline = 10.0\n",
        "fixed.incline",
        "`incline` is not a parameter of scene oscillator",
    ),
    // Issue 42: input never dropped without a word. The other law's bound beside a fixed law
    // (both ways: it would be ignored), a tilt without the load it tilts, a speed whose
    // energy the run cannot represent, a fixed method that is no method.
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\ntresca_threshold = 0.1\n",
        "fixed.tresca_threshold",
        "tresca_threshold is the bound of friction = \"tresca\", but friction = \"coulomb\" for this run (its bound is friction_coefficient): it would be ignored",
    ),
    (
        "name = \"x\"\nscene = \"layer1d\"\n[fixed]\nelements = 20\ncourant = 0.5\nfriction = \"tresca\"\ntresca_threshold = 0.1\n[grid]\nfriction_coefficient = [0.1, 0.3]\n",
        "grid.friction_coefficient[0]",
        "friction_coefficient is the bound of friction = \"coulomb\", but friction = \"tresca\" for this run",
    ),
    (
        "name = \"x\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"block2d.msh\"\ndt = 0.01\nincline = 10.0\n",
        "fixed.incline",
        "incline = 10 tilts the volume load, but gravity = 0 (the default) for this run: without a load the tilt changes nothing",
    ),
    (
        "name = \"x\"\nscene = \"mesh3d\"\n[fixed]\nmesh = \"block3d.msh\"\ndt = 0.01\ngravity = 0.0\nincline = -5.0\n",
        "fixed.incline",
        "incline = -5 tilts the volume load, but gravity = 0 for this run",
    ),
    (
        "name = \"x\"\nscene = \"disc2d\"\n[fixed]\nh = 8.0\ndt = 0.1\nvelocity_tangential = 1e200\n",
        "fixed.velocity_tangential",
        "above the 1.341e148 a run can represent",
    ),
    (
        "name = \"x\"\nscene = \"oscillator\"\n[fixed]\ndt = 0.01\nvelocity = -1e100\n",
        "fixed.velocity",
        "kinetic energy density ½ρ|v⁰|² = 5.000e199",
    ),
    (
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nscheme = \"kane\"\nspace = \"nitsche\"\nnitsche_gamma0 = 1.0\n",
        "fixed.space",
        "scheme = kane, space = nitsche together make no method: kane is defined for space = mixed only",
    ),
    (
        "name = \"x\"\nscene = \"disc2d\"\n[fixed]\nh = 8.0\ndt = 0.1\nscheme = \"discrete-gradient\"\n",
        "fixed.scheme",
        "scheme = discrete-gradient, space = mixed together make no method: discrete-gradient needs a contact potential (space = penalty, or nitsche with Θ = 1) (space = mixed by default)",
    ),
];

#[test]
fn every_bad_sweep_is_refused_with_the_key_and_exit_2() {
    assert!(CASES.len() >= 12);
    let tmp = tempfile::tempdir().unwrap();
    for (i, (body, key, reason)) in CASES.iter().enumerate() {
        let file = format!("bad{i}.toml");
        write(tmp.path(), &file, body);
        let out_dir = format!("out{i}");
        for cmd in ["plan", "run"] {
            let mut args = vec![cmd, file.as_str()];
            if cmd == "run" {
                args.extend(["--out", out_dir.as_str()]);
            }
            let o = cli(tmp.path(), &args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(
                o.status.code(),
                Some(2),
                "case {i} ({cmd}): exit {:?}, stderr:\n{err}",
                o.status.code()
            );
            assert!(!err.contains("panicked"), "case {i}: panic\n{err}");
            assert!(err.contains(&file), "case {i}: file not named\n{err}");
            assert!(
                err.contains(&format!("`{key}`")),
                "case {i}: key `{key}` not named\n{err}"
            );
            assert!(
                err.contains(reason),
                "case {i}: reason `{reason}` missing\n{err}"
            );
            assert!(
                !tmp.path().join(&out_dir).exists(),
                "case {i}: output written for a bad sweep"
            );
        }
    }
}

#[test]
fn a_bad_summary_table_names_its_line() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\n[summary]\nflags = true\nerrors = [\"l2h1\"]\n",
    );
    let o = cli(tmp.path(), &["plan", "s.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("s.toml:8: key `summary.errors`: unknown error column `l2h1`"),
        "{err}"
    );
}

#[test]
fn line_numbers_are_reported_where_the_parser_knows_them() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nnewmark_beta = 0.9\n",
    );
    let o = cli(tmp.path(), &["plan", "s.toml"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("s.toml:6: key `fixed.newmark_beta`"), "{err}");
}

/// A fixed combination that is no method (issue 42) is refused at every key that makes it, each
/// with its line and the reason — where it was once "key `grid`: the sweep expands to no runs",
/// naming a key the file lacks, without a line or a reason.
#[test]
fn a_meaningless_fixed_method_names_its_keys_and_lines() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nscheme = \"kane\"\nspace = \"nitsche\"\nnitsche_gamma0 = 1.0\n",
    );
    let o = cli(tmp.path(), &["plan", "s.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let why = "scheme = kane, space = nitsche together make no method: kane is defined for space = mixed only";
    assert!(
        err.contains(&format!("s.toml:6: key `fixed.scheme`: {why}")),
        "{err}"
    );
    assert!(
        err.contains(&format!("s.toml:7: key `fixed.space`: {why}")),
        "{err}"
    );
    assert!(!err.contains("`grid`"), "{err}");
    // Across an axis the same pair is one combination left out, and the others run.
    write(
        tmp.path(),
        "t.toml",
        "name = \"x\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nscheme = \"kane\"\nnitsche_gamma0 = 1.0\n[grid]\nspace = [\"mixed\", \"nitsche\"]\n",
    );
    let o = cli(tmp.path(), &["plan", "t.toml"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn unreadable_file_and_bad_flags_exit_2() {
    let tmp = tempfile::tempdir().unwrap();
    let o = cli(tmp.path(), &["plan", "missing.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.toml"));
    write(
        tmp.path(),
        "s.toml",
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.5\ndt = 0.5\nT = 1.0\n",
    );
    let o = cli(tmp.path(), &["run", "s.toml", "--run-timeout", "-3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--run-timeout"));
}
