//! Non-matching interfaces between the two blocks (contract §1.10, §2.6, §6; issue 45): the keys
//! `pairing`, `mortar_basis`, `interface_quadrature` and `mesh_ratio` ≠ 1 at plan time.

mod common;

use std::path::Path;

use contact_sweep::sweep::{SweepFile, expand};

/// The sweep's plan error, or a panic if the planner accepted it.
fn plan_error(text: &str) -> String {
    match SweepFile::parse(Path::new("pairing.toml"), text).map(|s| expand(&s)) {
        Err(e) => e.to_string(),
        Ok(Err(e)) => e.to_string(),
        Ok(Ok(_)) => panic!("the sweep was accepted:\n{text}"),
    }
}

/// The planned runs' ids and labels.
fn plan_ids(text: &str) -> Vec<String> {
    let plan =
        expand(&SweepFile::parse(Path::new("pairing.toml"), text).expect("parses")).expect("plans");
    plan.runs.iter().map(|r| r.run_id.clone()).collect()
}

const BASE: &str = "name = \"p\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.1\nh = 0.25\ndt = 0.05\n";

/// The keys at their defaults change no id (the matching blocks' runs keep theirs), and the
/// words each key takes are checked.
#[test]
fn interface_keys_at_their_defaults_keep_the_ids() {
    let plain = plan_ids(BASE);
    let given = plan_ids(&format!(
        "{BASE}pairing = \"node-to-node\"\nmortar_basis = \"standard\"\ninterface_quadrature = \"segment\"\nmesh_ratio = 1.0\n"
    ));
    assert_eq!(plain, given);
    let mortar = plan_ids(&format!(
        "{BASE}pairing = \"mortar\"\nmesh_ratio = 1.3333333333333333\n"
    ));
    assert_ne!(plain, mortar);
    for (key, word) in [
        ("pairing", "node-to-face"),
        ("mortar_basis", "biorthogonal"),
        ("interface_quadrature", "gauss"),
    ] {
        let e = plan_error(&format!("{BASE}{key} = \"{word}\"\n"));
        assert!(e.contains(key) && e.contains(word), "{e}");
    }
}

/// Each refusal names the file's key and says why (the brief's list).
#[test]
fn interface_keys_are_refused_where_they_do_not_apply() {
    // A one-body scene and the bars take none of them.
    for (scene, extra) in [
        ("bar2d", "h = 0.1\n"),
        ("bars1d", "h = 0.1\n"),
        ("disc2d", "h = 2.0\n"),
    ] {
        for key in [
            "pairing = \"mortar\"",
            "mortar_basis = \"dual\"",
            "interface_quadrature = \"element\"",
        ] {
            let text = format!(
                "name = \"p\"\nscene = \"{scene}\"\n[fixed]\nT = 0.1\n{extra}dt = 0.05\n{key}\n"
            );
            let e = plan_error(&text);
            let name = key.split(' ').next().unwrap();
            assert!(
                e.contains(name) && e.contains("not a parameter of scene"),
                "{scene} {key}: {e}"
            );
        }
    }
    let cases = [
        // A non-matching interface needs a pairing that projects.
        (
            "mesh_ratio = 1.3333333333333333\n",
            &["mesh_ratio", "node-to-segment or mortar, or nitsche"][..],
        ),
        (
            "mesh_ratio = 1.4\nspace = \"mixed\"\npairing = \"node-to-node\"\n",
            &["mesh_ratio", "non-matching interface"][..],
        ),
        // Nitsche on non-matching faces: not yet built.
        (
            "mesh_ratio = 1.4\nspace = \"nitsche\"\n",
            &["mesh_ratio", "not yet built"][..],
        ),
        // A pairing is mixed's and penalty's.
        (
            "space = \"nitsche\"\npairing = \"mortar\"\n",
            &["pairing", "nitsche"][..],
        ),
        // The dual basis needs mortar rows.
        (
            "pairing = \"node-to-segment\"\nmortar_basis = \"dual\"\n",
            &["mortar_basis", "pairing = \"mortar\""][..],
        ),
        ("mortar_basis = \"dual\"\n", &["mortar_basis"][..]),
        // Node rows carry no interface integral.
        (
            "pairing = \"node-to-segment\"\ninterface_quadrature = \"element\"\n",
            &["interface_quadrature", "node rows"][..],
        ),
        // Friction acts on node-to-node pairs only.
        (
            "pairing = \"mortar\"\nfriction = \"coulomb\"\nfriction_coefficient = 0.3\n",
            &["pairing", "friction"][..],
        ),
    ];
    for (lines, words) in cases {
        let e = plan_error(&format!("{BASE}{lines}"));
        for w in words {
            assert!(e.contains(w), "{lines}: `{w}` missing from {e}");
        }
        assert!(e.contains("pairing.toml"), "{lines}: no file in {e}");
    }
}

/// Across an axis the combinations that do not go together are left out, not refused: a grid
/// over every pairing × basis × quadrature on a non-matching interface plans the mortar runs
/// (4: two bases × two quadratures) and node-to-segment once.
#[test]
fn an_axis_over_the_pairings_leaves_out_what_does_not_apply() {
    let text = format!(
        "{BASE}mesh_ratio = 1.4\n[grid]\npairing = [\"node-to-node\", \"node-to-segment\", \"mortar\"]\nmortar_basis = [\"standard\", \"dual\"]\ninterface_quadrature = [\"segment\", \"element\"]\n"
    );
    assert_eq!(plan_ids(&text).len(), 5);
}
