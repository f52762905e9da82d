//! What the Markdown and LaTeX convergence tables print: which error columns, and whether the
//! observed rates, the least-squares slopes and the flags appear.
//!
//! Every error norm with its rate makes a table of 17 columns, wider than a landscape page; a
//! paper prints a few norms. The default is what the papers print for the impacting bar
//! (003 §4.1.2e, Fig 10): the displacement in l2(τ;L2) and l2(τ;H1), the contact pressure at
//! the midpoint and the energy error. A `[summary]` table in the sweep file chooses otherwise;
//! the sweep file's text is stored in `DIR/manifest.json`, so `summarize DIR` finds the choice
//! again, and `summarize --errors` overrides it. The Parquet and CSV tables always hold every
//! column: the choice only decides what the text tables show.

/// Every error column the tables can show (contract §5's error norms of a run's row), in output
/// order.
pub const ERROR_COLUMNS: &[&str] = &[
    "err_u_l2l2",
    "err_u_l2h1",
    "err_u_linfl2",
    "err_sigma_l2",
    "err_sigma_mid_l2",
    "err_energy_l2",
    "err_u_contact_max",
    "err_sigma_t_l2",
    "err_vt_final",
];

/// The tangential errors of a frictional scene (contract §5: the layer's σ_t in L2 over both
/// components, the mean tangential velocity at T). Null for every frictionless scene, so a
/// folder has them only when its scene computes them: the text tables then show them after
/// the chosen columns unless `--errors` or `[summary]` chose otherwise — a frictional rate
/// table without its tangential errors would not answer its question.
pub const TANGENTIAL_ERRORS: &[&str] = &["err_sigma_t_l2", "err_vt_final"];

/// The default selection: what the papers print.
pub const DEFAULT_ERRORS: &[&str] = &[
    "err_u_l2l2",
    "err_u_l2h1",
    "err_sigma_mid_l2",
    "err_energy_l2",
];

/// The column choice of the Markdown and LaTeX convergence tables.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SummaryOptions {
    /// The error columns, in the order given; `None`: [`DEFAULT_ERRORS`].
    pub errors: Option<Vec<&'static str>>,
    /// A rate column after each error column.
    pub rates: bool,
    /// The LSQ slope rows (all usable levels, finest three).
    pub slopes: bool,
    /// The flags row.
    pub flags: bool,
}

impl Default for SummaryOptions {
    fn default() -> Self {
        SummaryOptions {
            errors: None,
            rates: true,
            slopes: true,
            flags: true,
        }
    }
}

impl SummaryOptions {
    /// The error columns asked for (the default when none were named).
    pub fn chosen(&self) -> &[&'static str] {
        self.errors.as_deref().unwrap_or(DEFAULT_ERRORS)
    }
}

/// Validate a list of error column names: `all` alone stands for every column. The reason of a
/// refusal names the offending entry and lists the valid names.
pub fn parse_errors<S: AsRef<str>>(names: &[S]) -> Result<Vec<&'static str>, String> {
    let valid = || format!("valid: {}, or all", ERROR_COLUMNS.join(", "));
    if names.is_empty() {
        return Err(format!(
            "empty list: name at least one error column ({})",
            valid()
        ));
    }
    if names.len() == 1 && names[0].as_ref().trim() == "all" {
        return Ok(ERROR_COLUMNS.to_vec());
    }
    let mut out: Vec<&'static str> = Vec::with_capacity(names.len());
    for n in names {
        let n = n.as_ref().trim();
        let Some(&col) = ERROR_COLUMNS.iter().find(|c| **c == n) else {
            let hint = ERROR_COLUMNS
                .iter()
                .find(|c| c.eq_ignore_ascii_case(n) || c.trim_start_matches("err_") == n)
                .map(|c| format!(" (did you mean `{c}`?)"))
                .unwrap_or_default();
            let what = if n == "all" {
                "`all` must stand alone".to_string()
            } else {
                format!("unknown error column `{n}`{hint}")
            };
            return Err(format!("{what}; {}", valid()));
        };
        if out.contains(&col) {
            return Err(format!("`{col}` is listed twice"));
        }
        out.push(col);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked_and_all_expands() {
        assert_eq!(
            parse_errors(&["err_u_l2h1", "err_u_l2l2"]).unwrap(),
            ["err_u_l2h1", "err_u_l2l2"]
        );
        assert_eq!(parse_errors(&["all"]).unwrap(), ERROR_COLUMNS);
        let e = parse_errors(&["u_l2h1"]).unwrap_err();
        assert!(
            e.contains("unknown error column `u_l2h1`")
                && e.contains("did you mean `err_u_l2h1`")
                && e.contains("err_u_contact_max"),
            "{e}"
        );
        assert!(
            parse_errors(&["err_u_l2l2", "err_u_l2l2"])
                .unwrap_err()
                .contains("twice")
        );
        assert!(
            parse_errors::<&str>(&[])
                .unwrap_err()
                .contains("empty list")
        );
        assert!(
            parse_errors(&["all", "err_u_l2l2"])
                .unwrap_err()
                .contains("alone")
        );
    }

    #[test]
    fn the_default_is_a_subset_of_the_columns() {
        for e in DEFAULT_ERRORS {
            assert!(ERROR_COLUMNS.contains(e), "{e}");
        }
        assert_eq!(SummaryOptions::default().chosen(), DEFAULT_ERRORS);
    }
}
