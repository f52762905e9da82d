//! A run's parameters as the planner resolved them: its id, its label, every parameter column
//! (contract §7's keys with defaults filled), the engine configuration and where its errors are
//! measured against.
//!
//! Why here and not with the planner: a run builds its row from these ([`super::RunRecord`]),
//! and a layer imports only those below it; the planner (`sweep`) makes them, the executor runs
//! them.

use std::collections::BTreeMap;

use super::config::RunConfig;
use crate::model::{Key, Value};
use crate::scene::SceneKind;

/// One run of the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    pub run_id: String,
    /// Human label: method · mass · scheme.
    pub label: String,
    /// Every parameter column of the run (defaults filled, derived ones included, keys that do
    /// not apply absent).
    pub params: BTreeMap<Key, Value>,
    pub scheme_label: String,
    pub config: RunConfig,
    pub repeats: usize,
    /// Ensemble member (sample index, relative perturbation).
    pub sample: Option<(usize, f64)>,
    pub scene: SceneKind,
    /// The run_id of the reference run its errors are measured against (contract §1.2, §7).
    pub reference: Option<String>,
    /// The `[search]` this run is a probe of ([`crate::sweep::plan::search_tag`]); None for grid runs.
    pub search: Option<String>,
    /// The id this run had before a definition change moved its numbers (issue 34: the body
    /// load, exact quadrature on curved cells; or a change to its reference run): a folder
    /// holding a row under it holds the old numbers, and `--resume` refuses to add this run's
    /// new ones beside them. None for runs no change touched (their ids never changed).
    pub superseded_id: Option<String>,
}
