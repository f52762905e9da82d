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
