//! The README's output schema is the one the code writes (`contact-sweep schema`).

use contact_sweep::cli::schema_markdown;

#[test]
fn readme_schema_matches_the_code() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    assert!(
        readme.contains(&schema_markdown()),
        "README.md's schema section is stale: replace it with the output of `contact-sweep schema`"
    );
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
