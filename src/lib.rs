//! contact-sweep: parameter sweeps of dynamic Signorini-contact simulations.
//!
//! The modules form a pipeline, `space, time, contact < scene < model < run < sweep < sink <
//! exec < summary < report < cli`, and a module imports only those below it
//! (`tests/architecture.rs`). What each holds:
//!
//! - [`scene`] — the physical problems behind one trait ([`scene::Scene`]): the 1D bar with its
//!   closed forms (clamped, and the flying bar with a free end), the 2D/3D bars dropped on an
//!   obstacle, the disc and the ball, the impact oscillator with its exact solution event by
//!   event; each declares its keys, defaults, applicability and error source, and hands the
//!   engines a setup.
//! - [`space`] — meshes, mass variants, stiffness, and how each contact method enters the
//!   semi-discrete system; `space::fe` (Q1 elements, sparse assembly with the pattern built
//!   once), `space::linalg` (faer's sparse Cholesky: symbolic once, numeric per matrix),
//!   `space::cg` (Jacobi-preconditioned conjugate gradient, `solver = "cg"`) and
//!   `space::step_solver` (the per-step solve, dispatching to either).
//! - [`time`] — the time schemes as data with named presets, the methods of the comparison
//!   literature (contract §3.2: kane, contact-stabilized Newmark, generalized-α/HHT, Moreau–Jean,
//!   discrete gradient, kinematic central difference) among them.
//! - [`contact`] — the condensed contact solve: one scalar piecewise-linear equation per step,
//!   solved exactly by branch enumeration (1D); a small dense LCP on the contact dofs solved
//!   exactly by an active-set method (2D/3D); the discrete gradient's scalar equation by a
//!   safeguarded semismooth Newton iteration ([`contact::gradient`]).
//! - [`model`] — the data that crosses layers: contract §7's parameter keys and values, the
//!   column choice of the summary tables.
//! - [`run`] — one run: setup (factorisations once, shared between runs with the same matrix),
//!   the allocation-free time loop of the tridiagonal, the sparse and the one-dof engine,
//!   observables (energies, error norms against the closed form or a reference run), and the
//!   output schema
//!   ([`run::RunRecord`]).
//! - [`sweep`] — sweep files: parsing with line numbers, validation, expansion, run ids.
//! - [`exec`] — serial (reference) and rayon execution; failures become rows; reference runs
//!   computed once per output folder ([`exec::references`]); Slurm job arrays of shards
//!   ([`exec::slurm`]).
//! - [`sink`] — atomic Parquet parts, resume, manifest, several shards writing one folder.
//! - [`summary`] — convergence rates, energy drift, speed-against-error and method-class
//!   tables.
//! - [`report`] — one self-contained HTML file of a results folder: the summary's tables and
//!   figures drawn in Rust (plotters, inline SVG).
//! - [`cli`] — command-line flags and their validation into the types above.

// Index loops mirror the formulas of the papers (x_i, M_{i,i+1}); iterator chains would hide them.
#![allow(clippy::needless_range_loop)]

pub mod cli;
pub mod contact;
pub mod exec;
pub mod model;
pub mod report;
pub mod run;
pub mod scene;
pub mod sink;
pub mod space;
pub mod summary;
pub mod sweep;
pub mod time;
