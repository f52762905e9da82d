//! The data that crosses layers, below every layer that exchanges it (run and up): what a sweep's parameters are
//! ([`keys::Key`], [`keys::Value`]: contract §7's keys, their types and ranges) and what the
//! convergence tables are asked to print ([`summary_options::SummaryOptions`]).
//!
//! Why a layer of its own: the planner (`sweep`) parses these, a run (`run`) writes them into its
//! row, the summaries (`summary`) read them back, and the pipeline's order
//! (space, time, contact < scene < model < run < sweep < sink < exec < summary < report <
//! cli) lets a module import only those below it. Plain data and its parsing live here, so that every one of
//! those layers can name it without importing a layer above itself (`tests/architecture.rs`).

pub mod keys;
pub mod summary_options;

pub use keys::{Key, Value, ValueType};
pub use summary_options::{
    DEFAULT_ERRORS, ERROR_COLUMNS, SummaryOptions, TANGENTIAL_ERRORS, parse_errors,
};
