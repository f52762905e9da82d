//! contact-sweep: parameter sweeps of dynamic Signorini-contact simulations.
//!
//! The modules form a pipeline and depend on each other in this order only:
//!
//! - [`scene`] — the physical problems (the 1D bar with its closed form, …).
//! - [`space`] — meshes, mass variants, stiffness, and how each contact method enters the
//!   semi-discrete system (its operators and contact direction vectors).
//! - [`time`] — the time schemes as data with named presets.
//! - [`contact`] — the condensed contact solve: one scalar piecewise-linear equation per step,
//!   solved exactly by branch enumeration.
//! - [`run`] — one run: setup (factorisations once), the allocation-free time loop,
//!   observables (energies, exact error norms), and the output schema ([`run::RunRecord`]).
//! - [`sweep`] — sweep files: parsing with line numbers, validation, expansion, run ids.
//! - [`exec`] — serial (reference) and rayon execution; failures become rows; Slurm job arrays
//!   of shards ([`exec::slurm`]).
//! - [`sink`] — atomic Parquet parts, resume, manifest, several shards writing one folder.
//! - [`summary`] — convergence rates, energy drift and speed-against-error tables.
//! - [`cli`] — command-line flags and their validation into the types above.

// Index loops mirror the formulas of the papers (x_i, M_{i,i+1}); iterator chains would hide them.
#![allow(clippy::needless_range_loop)]

pub mod cli;
pub mod contact;
pub mod exec;
pub mod run;
pub mod scene;
pub mod sink;
pub mod space;
pub mod summary;
pub mod sweep;
pub mod time;
