//! The docs hold what the code does: the guide's output schema is the one the code writes
//! (`contact-sweep schema`), the README's sweep file plans, the README stays short and links
//! every doc page.

use contact_sweep::cli::schema_markdown;

#[test]
fn readme_schema_matches_the_code() {
    let guide =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/guide.md")).unwrap();
    assert!(
        guide.contains(&schema_markdown()),
        "docs/guide.md's schema section is stale: replace it with the output of `contact-sweep schema`"
    );
}

/// Issue 25: a newcomer reaches the two commands within the first screen, the README stays
/// under 250 lines, and every page of docs/ (and CONTRIBUTING.md) is linked from it; every
/// relative link of the README and the docs points at a file that exists.
#[test]
fn readme_is_short_and_links_every_doc_page() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let lines: Vec<&str> = readme.lines().collect();
    assert!(lines.len() <= 250, "README.md has {} lines", lines.len());
    let first_screen = lines[..lines.len().min(50)].join("\n");
    for cmd in [
        "cargo run --release -- run sweeps/quickstart.toml",
        "python3 -m pip install -r analysis/requirements.txt && cargo test --release",
    ] {
        assert!(
            first_screen.contains(cmd),
            "`{cmd}` is not on the README's first screen"
        );
    }
    let mut pages: Vec<String> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md"))
        .map(|n| format!("docs/{n}"))
        .collect();
    pages.push("CONTRIBUTING.md".into());
    assert!(pages.len() >= 5, "{pages:?}");
    for p in &pages {
        assert!(
            readme.contains(&format!("]({p}")),
            "README.md does not link {p}"
        );
    }
    // Relative links resolve (a moved section must not leave a dead link behind).
    for (file, text) in std::iter::once(("README.md".to_string(), readme.clone())).chain(
        pages
            .iter()
            .map(|p| (p.clone(), std::fs::read_to_string(root.join(p)).unwrap())),
    ) {
        let dir = root.join(&file).parent().unwrap().to_path_buf();
        let mut rest = text.as_str();
        while let Some(k) = rest.find("](") {
            let after = &rest[k + 2..];
            let end = after.find(')').unwrap_or(after.len());
            let target = after[..end].split('#').next().unwrap();
            if !target.is_empty() && !target.contains("://") && !target.contains(' ') {
                assert!(
                    dir.join(target).exists(),
                    "{file}: the link target `{target}` does not exist"
                );
            }
            rest = &after[end..];
        }
    }
}

#[test]
fn readme_sweep_example_is_a_valid_sweep() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let start = readme.find("```toml\n").expect("a toml example") + "```toml\n".len();
    let end = start + readme[start..].find("```").unwrap();
    let sf = contact_sweep::sweep::SweepFile::parse(
        std::path::Path::new("README.md"),
        &readme[start..end],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let plan = contact_sweep::sweep::expand(&sf).unwrap_or_else(|e| panic!("{e}"));
    // SPEC §7's example: [zip] h, dt (3 levels) override [fixed] h, dt; × 4 schemes = 12 runs.
    assert_eq!(plan.runs.len(), 12);
    assert!(
        plan.summary().contains("fixed.h is overridden by [zip]"),
        "{}",
        plan.summary()
    );
}
