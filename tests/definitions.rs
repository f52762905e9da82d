//! Issue 34's definition changes and the run ids: the body load of contract §1.3 (key `load`) and
//! exact quadrature on curved cells moved the numbers of every run with gravity and of every
//! run on cells that can be curved, so those runs have new ids — and a folder that holds their
//! old rows is never resumed into (two answers to one question in its tables). Runs no change
//! touched keep their ids (the bars, bar1d, the oscillator).

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::{cli, write};
use contact_sweep::model::keys::canonical_number;
use contact_sweep::scene::SceneKind;
use contact_sweep::sweep::plan::run_id;
use contact_sweep::sweep::{self, Key, Plan, SweepFile, Value};

fn plan(text: &str) -> Plan {
    let sf = SweepFile::parse(Path::new("defs.toml"), text).unwrap_or_else(|e| panic!("{e}"));
    sweep::expand(&sf).unwrap_or_else(|e| panic!("{e}"))
}

fn refused(text: &str) -> String {
    match SweepFile::parse(Path::new("defs.toml"), text) {
        Err(e) => e.to_string(),
        Ok(sf) => match sweep::expand(&sf) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {text}"),
        },
    }
}

/// The id a run had before issue 34: the documented rule (contract §8, `sweep::plan`'s header) on
/// its canonical parameters alone.
fn id_before(scene: SceneKind, canonical: &[(Key, String)]) -> String {
    let map: BTreeMap<Key, String> = canonical.iter().cloned().collect();
    run_id(scene, &map, "")
}

const DISC: &str = "name = \"d\"\nscene = \"disc2d\"\n[fixed]\nT = 1.0\nh = 4.0\ndt = 0.1\n";

#[test]
fn runs_whose_numbers_moved_have_new_ids_and_know_their_old_ones() {
    let p = plan(DISC);
    assert_eq!(p.runs.len(), 1);
    let r = &p.runs[0];
    // disc2d at h = 4 has 8 elements along a quarter circle; T, dt and the scheme family are in
    // every id (T = 1 differs from the scene's 40).
    let old = id_before(
        SceneKind::Disc2d,
        &[
            (Key::T, canonical_number(1.0)),
            (Key::Elements, "8".into()),
            (Key::Dt, canonical_number(0.1)),
            (Key::Scheme, "newmark".into()),
        ],
    );
    assert_ne!(
        r.run_id, old,
        "a disc run with gravity kept its pre-issue-34 id"
    );
    assert_eq!(r.superseded_id.as_deref(), Some(old.as_str()));
    // The default `load` is the body force, and it is a column.
    assert_eq!(r.params[&Key::Load], Value::Str("body".into()));
    // `inertial` (the former behaviour, kept to measure it) is another run.
    let both = plan(&format!("{DISC}[grid]\nload = [\"body\", \"inertial\"]\n"));
    assert_eq!(both.runs.len(), 2);
    assert_eq!(both.runs[0].run_id, r.run_id);
    assert_ne!(both.runs[1].run_id, r.run_id);
    // The bars have no load and affine cells: their ids never changed (the frozen 003 CN id
    // of tests/planner.rs, and bar2d by the rule).
    let bar1d = plan("name = \"b\"\nscene = \"bar1d\"\n[fixed]\nh = 0.01\ndt = 0.015\n");
    assert_eq!(bar1d.runs[0].run_id, "35050bcfa8862a8f");
    assert_eq!(bar1d.runs[0].superseded_id, None);
    let bar2d = plan("name = \"b\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\n");
    let old = id_before(
        SceneKind::Bar2d,
        &[
            (Key::Elements, "20".into()),
            (Key::Dt, canonical_number(0.025)),
            (Key::Scheme, "newmark".into()),
        ],
    );
    assert_eq!(bar2d.runs[0].run_id, old);
    assert_eq!(bar2d.runs[0].superseded_id, None);
}

#[test]
fn load_applies_only_with_gravity_and_is_validated() {
    // A mesh body without gravity: `load` changes nothing, so both values are one run and the
    // column is null.
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/meshes/square_tri_p1.msh");
    let text = format!(
        "name = \"m\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"{}\"\nT = 0.1\ndt = 0.01\nvelocity = -0.1\n[grid]\nload = [\"body\", \"inertial\"]\n",
        mesh.display()
    );
    let p = plan(&text);
    assert_eq!(p.runs.len(), 1, "{:?}", p.collapsed);
    assert!(!p.runs[0].params.contains_key(&Key::Load));
    // P1 triangles are affine and there is no load: nothing moved, the id is as before.
    assert_eq!(p.runs[0].superseded_id, None);
    // With gravity they are two runs.
    let p = plan(&text.replace("velocity = -0.1", "gravity = 0.1"));
    assert_eq!(p.runs.len(), 2);
    // A bad word: the file, the key, the reason.
    let bad = refused(&format!("{DISC}load = \"weightless\"\n"));
    assert!(
        bad.contains("defs.toml") && bad.contains("load") && bad.contains("expected body"),
        "{bad}"
    );
    // The bars take no load key at all.
    let e = refused(
        "name = \"b\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nload = \"body\"\n",
    );
    assert!(e.contains("defs.toml") && e.contains("load"), "{e}");
}

/// A folder written before issue 34 holds a disc run's row under its old id: resuming the same
/// sweep into it is refused (exit 2, the reason, no new row), and the same sweep into a new
/// folder runs.
#[test]
fn an_old_folder_is_never_resumed_into_with_new_numbers() {
    use polars::prelude::*;
    let tmp = tempfile::tempdir().unwrap();
    let sweep = write(
        tmp.path(),
        "disc.toml",
        "name = \"disc\"\nscene = \"disc2d\"\n[fixed]\nT = 0.3\nh = 10.0\ndt = 0.1\ndegree = 1\n",
    );
    let o = cli(
        tmp.path(),
        &[
            "run",
            sweep.to_str().unwrap(),
            "--out",
            "old",
            "--threads",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let p = {
        let sf = SweepFile::load(&sweep).unwrap();
        sweep::expand(&sf).unwrap()
    };
    let old_id = p.runs[0]
        .superseded_id
        .clone()
        .expect("a disc run has an old id");
    // Make the folder one of before: its row under the old id.
    let runs = tmp.path().join("old/runs");
    let part = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "parquet"))
        .unwrap();
    let mut df = ParquetReader::new(std::fs::File::open(&part).unwrap())
        .finish()
        .unwrap();
    let n = df.height();
    df.with_column(Column::new("run_id".into(), vec![old_id.as_str(); n]))
        .unwrap();
    ParquetWriter::new(std::fs::File::create(&part).unwrap())
        .finish(&mut df)
        .unwrap();
    let o = cli(
        tmp.path(),
        &[
            "run",
            sweep.to_str().unwrap(),
            "--out",
            "old",
            "--resume",
            "--threads",
            "1",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("issue 34") && err.contains(&old_id) && err.contains("new --out"),
        "{err}"
    );
    // Nothing was added: still the one old row.
    let parts = std::fs::read_dir(&runs)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "parquet")
        })
        .count();
    assert_eq!(parts, 1);
    // The same sweep into a new folder runs.
    let o = cli(
        tmp.path(),
        &[
            "run",
            sweep.to_str().unwrap(),
            "--out",
            "new",
            "--threads",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Issue 42: a body-loaded FE run with a massless variant starts its massless dofs quasi-static
/// (contract §1.3, §2.2), which moved its numbers: it has a new id and knows the old one, which
/// is now the id of its `contact_init = "interpolant"` twin — the u⁰ = 0 start that ran under
/// it, unchanged, so it keeps it. `contact_init` applies there and nowhere the massless dofs
/// carry no load (no gravity, `load = "inertial"`), where it is dropped and ids stay.
#[test]
fn the_quasi_static_start_moves_the_loaded_massless_runs_only() {
    let p = plan(&format!(
        "{DISC}[grid]\nmass = [\"consistent\", \"mod1\"]\ncontact_init = [\"consistent\", \"interpolant\"]\n"
    ));
    // The consistent mass: one run (the key dropped), its issue-34 id as before.
    assert_eq!(p.runs.len(), 3, "{:?}", p.collapsed);
    let consistent = &p.runs[0];
    assert!(!consistent.params.contains_key(&Key::ContactInit));
    let before_34 = id_before(
        SceneKind::Disc2d,
        &[
            (Key::T, canonical_number(1.0)),
            (Key::Elements, "8".into()),
            (Key::Dt, canonical_number(0.1)),
            (Key::Scheme, "newmark".into()),
        ],
    );
    assert_eq!(
        consistent.superseded_id.as_deref(),
        Some(before_34.as_str())
    );
    let (quasi, zero) = (&p.runs[1], &p.runs[2]);
    assert_eq!(
        quasi.params[&Key::ContactInit],
        Value::Str("consistent".into())
    );
    assert_eq!(
        zero.params[&Key::ContactInit],
        Value::Str("interpolant".into())
    );
    assert_ne!(quasi.run_id, zero.run_id);
    assert_eq!(quasi.superseded_id.as_deref(), Some(zero.run_id.as_str()));
    // The u⁰ = 0 run's id is the mod1 run's of before issue 42: the same canonical text (no
    // contact_init) and issue 34's revisions alone.
    let alone = plan(&format!(
        "{DISC}mass = \"mod1\"\ncontact_init = \"interpolant\"\n"
    ));
    assert_eq!(alone.runs[0].run_id, zero.run_id);
    // No load on the massless dofs: the key is dropped and nothing moved.
    for extra in ["load = \"inertial\"\n", "gravity = 0.0\n"] {
        let q = plan(&format!(
            "{DISC}{extra}mass = \"mod1\"\n[grid]\ncontact_init = [\"consistent\", \"interpolant\"]\n"
        ));
        assert_eq!(q.runs.len(), 1, "{extra}: {:?}", q.collapsed);
        assert!(!q.runs[0].params.contains_key(&Key::ContactInit), "{extra}");
        let why: Vec<&String> = q.collapsed.keys().collect();
        assert!(
            why.iter()
                .any(|w| w.contains("contact_init changes nothing")),
            "{extra}: {why:?}"
        );
    }
}
