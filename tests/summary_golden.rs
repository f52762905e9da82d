//! The summary's every output, byte for byte (issue 25): `summarize` of two committed results
//! folders — the quickstart (60 runs) and the 003 Fig 10 ladder (30 runs), runs parts only —
//! must write exactly the files it wrote before the summary tables moved to one renderer: every
//! table of `DIR/summary/` (Parquet, CSV, Markdown, LaTeX) and the terminal report.
//!
//! `tests/data/golden_summary/NAME/` holds the input (`runs/`, `manifest.json`) and
//! `expected.sha256` (SHA-256 of each output; the terminal report's as `terminal.txt`, with the
//! folder's path written `DIR`). Hashes rather than copies: the ladder's impact table alone is
//! 3.6 MB of CSV. A change that means to alter an output regenerates the list from its own
//! `summarize` output (`sha256sum *` in `DIR/summary`, plus the terminal report) and says why
//! in the CHANGELOG; a dependency upgrade that changes Parquet bytes (polars writes its version
//! into each file) does the same.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::cli;
use sha2::{Digest, Sha256};

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else if e.file_name() != "expected.sha256" {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

fn sha(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn check(name: &str) {
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/golden_summary");
    let tmp = tempfile::tempdir().unwrap();
    // The folder keeps its name: the LaTeX document is titled after it.
    let dir = tmp.path().join(name);
    copy_dir(&golden.join(name), &dir);
    let o = cli(tmp.path(), &["summarize", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut got: BTreeMap<String, String> = BTreeMap::new();
    for e in std::fs::read_dir(dir.join("summary")).unwrap() {
        let e = e.unwrap();
        let bytes = std::fs::read(e.path()).unwrap();
        got.insert(e.file_name().to_string_lossy().into_owned(), sha(&bytes));
    }
    let terminal = String::from_utf8(o.stdout)
        .unwrap()
        .replace(dir.to_str().unwrap(), "DIR");
    got.insert("terminal.txt".into(), sha(terminal.as_bytes()));
    let expected: BTreeMap<String, String> =
        std::fs::read_to_string(golden.join(name).join("expected.sha256"))
            .unwrap()
            .lines()
            .map(|l| {
                let (h, f) = l.split_once("  ").expect("`HASH  FILE` lines");
                (f.to_string(), h.to_string())
            })
            .collect();
    assert!(expected.len() >= 30, "{} outputs listed", expected.len());
    let differ: Vec<&String> = expected
        .keys()
        .chain(got.keys())
        .filter(|f| expected.get(*f) != got.get(*f))
        .collect();
    assert!(
        differ.is_empty(),
        "{name}: these summary outputs changed (or appeared/vanished): {differ:?}\nterminal:\n{terminal}"
    );
}

#[test]
fn quickstart_summary_is_byte_identical() {
    check("quickstart");
}

#[test]
fn fig10_ladder_summary_is_byte_identical() {
    check("fig10");
}
