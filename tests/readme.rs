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

/// The README's test command: `cargo test --release` behind a virtual environment for the
/// Python tests (scripts/test.sh), because Debian's and Ubuntu's python3 refuse `pip install`.
const TEST_COMMAND: &str = "scripts/test.sh";

/// Issue 41: the README's test command is what CI runs — `.ci/run` calls that very string, in a
/// fresh clone with Debian's python3 first on PATH — and the script it names keeps the
/// environment in the tree (git-ignored), installs the requirements there, puts it first on
/// PATH and runs every test.
#[test]
fn the_readme_test_command_is_what_ci_runs() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    assert!(
        readme.contains(&format!("```sh\n{TEST_COMMAND}\n```")),
        "the README's test command is not `{TEST_COMMAND}` alone in its block"
    );
    let ci = std::fs::read_to_string(root.join(".ci/run")).unwrap();
    assert!(
        ci.contains(&format!("readme_test_command() {{\n    {TEST_COMMAND}\n}}"))
            && ci.contains("\nreadme_test_command\n"),
        ".ci/run does not run the README's test command `{TEST_COMMAND}` as printed"
    );
    for needle in [
        "git clone",
        "/usr/bin/python3",
        "tests/slurm/start-local-slurm.sh",
    ] {
        assert!(ci.contains(needle), ".ci/run lost `{needle}`");
    }
    let script = std::fs::read_to_string(root.join(TEST_COMMAND)).unwrap();
    for needle in [
        "python3 -m venv",
        "python3-venv",
        "-r analysis/requirements.txt",
        "export PATH=\"$VIRTUAL_ENV/bin:$PATH\"",
        "cargo test --release",
    ] {
        assert!(script.contains(needle), "{TEST_COMMAND} lost `{needle}`");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(root.join(TEST_COMMAND))
            .unwrap()
            .permissions()
            .mode();
        assert!(mode & 0o111 != 0, "{TEST_COMMAND} is not executable");
    }
    let ignore = std::fs::read_to_string(root.join(".gitignore")).unwrap();
    assert!(
        ignore.lines().any(|l| l == "/.venv"),
        ".venv is not ignored"
    );
}

/// Issue 41: the project stands on its own — no file of the tree (target, .git and the
/// virtual environment aside) names a path beside the checkout.
#[test]
fn nothing_names_a_path_outside_the_tree() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let needle = concat!("..", "/shared").as_bytes();
    let mut stack = vec![root.to_path_buf()];
    let mut hits = Vec::new();
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            let path = e.path();
            if e.file_type().unwrap().is_dir() {
                if !matches!(name.as_str(), "target" | ".git" | ".venv" | "out") {
                    stack.push(path);
                }
            } else if std::fs::read(&path)
                .unwrap()
                .windows(needle.len())
                .any(|w| w == needle)
            {
                hits.push(path.strip_prefix(root).unwrap().display().to_string());
            }
        }
    }
    assert!(
        hits.is_empty(),
        "files naming a path outside the tree: {hits:?}"
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
        TEST_COMMAND,
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
    // The contract's §7 example: [zip] h, dt (3 levels) override [fixed] h, dt; × 4 schemes = 12 runs.
    assert_eq!(plan.runs.len(), 12);
    assert!(
        plan.summary().contains("fixed.h is overridden by [zip]"),
        "{}",
        plan.summary()
    );
}
