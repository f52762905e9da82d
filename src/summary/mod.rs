//! Summaries of a results folder (placeholder until the summary tables land).
use std::path::Path;

/// What `summarize` produced.
pub struct Summary {
    pub terminal: String,
}

/// Summarize DIR.
pub fn summarize(dir: &Path) -> anyhow::Result<Summary> {
    let df = crate::sink::read_runs(dir)?;
    Ok(Summary {
        terminal: format!("{} runs in {}\n", df.height(), dir.display()),
    })
}
