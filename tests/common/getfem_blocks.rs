//! The comparison of the engine's `blocks2d` against tests/getfem/blocks.py (GetFEM 5.4's
//! two-body nodal brick, Newmark ¼, ½), shared by tests/getfem_blocks.rs (issue 44, a matching
//! interface with node-to-node rows) and tests/getfem_nonmatching.rs (issue 45, `mesh_ratio`
//! 4/3 with node-to-segment rows): the settings' sweep and script parameters, the node-by-node
//! field, the series and their scales. Conventions and tolerances: tests/getfem_blocks.rs's
//! header.

use std::collections::HashMap;
use std::path::PathBuf;

use super::getfem::{floats, run_script_on};
use contact_sweep::run::{Outcome, RunContext, SeriesRow};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One setting: the sweep keys shared by the engine's sweep and the script's parameters.
pub struct Setting {
    pub name: &'static str,
    /// B's elements across per A's (1: matching) and the sweep's contact lines besides
    /// `space = "mixed"` (e.g. the pairing; empty: node-to-node).
    pub mesh_ratio: f64,
    pub contact: &'static str,
    pub height_b: f64,
    pub gap: f64,
    pub velocity_tangential: f64,
    pub velocity_b: f64,
    pub density_b: f64,
    pub lame_lambda_b: f64,
    pub lame_mu_b: f64,
    pub far_end: &'static str,
    /// The runs' end time T (τ = 0.02).
    pub t_final: f64,
    /// `blocks2d` (2) or `blocks3d` (3).
    pub dim: usize,
}

/// The settings of tests/getfem_blocks.rs (issue 44) on the matching blocks: B free (A at −1,
/// sliding at 0.3, onto B rising at ½: the momentum an invariant), or B clamped at rest with a
/// smaller gap and a shorter B; per-body materials.
pub const FREE: Setting = Setting {
    name: "free",
    height_b: 1.0,
    gap: 0.1,
    velocity_tangential: 0.3,
    velocity_b: 0.5,
    density_b: 2.0,
    lame_lambda_b: 0.5,
    lame_mu_b: 1.5,
    far_end: "free",
    t_final: 4.0,
    dim: 2,
    mesh_ratio: 1.0,
    contact: "",
};

pub const CLAMPED: Setting = Setting {
    name: "clamped",
    height_b: 0.75,
    gap: 0.05,
    velocity_tangential: 0.0,
    velocity_b: 0.0,
    density_b: 1.5,
    lame_lambda_b: 2.0,
    lame_mu_b: 0.5,
    far_end: "clamped",
    t_final: 4.0,
    dim: 2,
    mesh_ratio: 1.0,
    contact: "",
};

/// A's keys (W = H_a = 1, h = 1/4: 4 × 4 squares in A; ρ = λ = μ = 1, V = −1), τ and T.
const H: f64 = 0.25;
const WIDTH: f64 = 1.0;
const HEIGHT: f64 = 1.0;
const VELOCITY: f64 = -1.0;
const DT: f64 = 0.02;

pub const MASSES: [&str; 2] = ["zero-contact", "consistent"];

impl Setting {
    /// The script's parameters (tests/getfem/blocks.py's usage) with the `extra` ones.
    pub fn params(&self, extra: serde_json::Value) -> String {
        let mut p = serde_json::json!({
            "width": WIDTH, "height": HEIGHT, "height_b": self.height_b, "h": H,
            "gap": self.gap, "velocity": VELOCITY, "velocity_tangential": self.velocity_tangential,
            "velocity_b": self.velocity_b,
            "density": 1.0, "lame_lambda": 1.0, "lame_mu": 1.0,
            "density_b": self.density_b, "lame_lambda_b": self.lame_lambda_b,
            "lame_mu_b": self.lame_mu_b, "far_end": self.far_end, "T": self.t_final, "dt": DT,
            "mesh_ratio": self.mesh_ratio, "dim": self.dim,
        });
        for (k, v) in extra.as_object().expect("an object") {
            p[k] = v.clone();
        }
        p.to_string()
    }

    /// The engine's sweep with Crank–Nicolson (Newmark β = ¼, γ = ½), the contact `method`'s
    /// lines in [fixed] and `grid`'s in [grid].
    pub fn sweep(&self, method: &str, grid: &str) -> String {
        format!(
            r#"
name = "getfem-blocks-{}"
scene = "blocks{}d"
[fixed]
width = {WIDTH}
height = {HEIGHT}
height_b = {}
h = {H}
gap = {}
velocity = {VELOCITY}
velocity_tangential = {}
velocity_b = {}
density = 1.0
lame_lambda = 1.0
lame_mu = 1.0
density_b = {}
lame_lambda_b = {}
lame_mu_b = {}
far_end = "{}"
T = {}
dt = {DT}
{method}
scheme = "crank-nicolson"
[grid]
{grid}
"#,
            self.name,
            self.dim,
            self.height_b,
            self.gap,
            self.velocity_tangential,
            self.velocity_b,
            self.density_b,
            self.lame_lambda_b,
            self.lame_mu_b,
            self.far_end,
            self.t_final,
        )
    }
}

/// Largest |a_k − b_k| over the steps `..end`.
fn max_diff(a: &[f64], b: &[f64], end: usize) -> f64 {
    a[..end]
        .iter()
        .zip(&b[..end])
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A GetFEM node's coordinates (z = 0 in 2D).
fn coords(p: &serde_json::Value) -> [f64; 3] {
    ["x", "y", "z"].map(|k| p.get(k).and_then(|x| x.as_f64()).unwrap_or(0.0))
}

/// The engine's recorded displacement of every GetFEM node at every step, in GetFEM's node
/// order (times × nodes × 3, z = 0 in 2D): A's nodes are the engine's first
/// (W/h + 1)^{d−1}(H_a/h + 1), placed on B's top (x_d − g), B's the rest.
fn engine_field(o: &Outcome, nodes: &serde_json::Value, s: &Setting) -> Vec<Vec<[f64; 3]>> {
    let d = s.dim;
    let data = o.reference.as_ref().expect("the run records its solution");
    let mesh = data.mesh.as_ref().expect("two bodies store their mesh");
    let n = mesh.coords.len();
    let across = (WIDTH / H).round() as usize;
    let n_a = (across + 1).pow(d as u32 - 1) * ((HEIGHT / H).round() as usize + 1);
    let key = |body: usize, x: [f64; 3]| (body, x.map(|c| (c / H * 1e6).round() as i64));
    let index: HashMap<_, usize> = (0..n)
        .map(|k| (key(usize::from(k >= n_a), mesh.coords[k]), k))
        .collect();
    let map: Vec<usize> = nodes
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let body = p["body"].as_u64().unwrap() as usize;
            let mut x = coords(p);
            if body == 0 {
                x[d - 1] -= s.gap;
            }
            index[&key(body, x)]
        })
        .collect();
    assert_eq!(map.len(), n, "every node matched");
    (0..data.times)
        .map(|t| {
            map.iter()
                .map(|&k| {
                    let mut u = [0.0; 3];
                    (0..d).for_each(|c| u[c] = data.u[(t * n + k) * d + c]);
                    u
                })
                .collect()
        })
        .collect()
}

/// Where the engine's `u_contact_b` reads B: at Π(x_i) below each Γ^a node x_i (the rows of
/// node-to-node, node-to-segment and mortar), or at the Γ^b node of index
/// round(i·across_b/across) (per axis) for Γ^a's node i (Nitsche on a non-matching interface,
/// whose points carry its forces: src/run/fe/bodies.rs's observable pairs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaceB {
    Projected,
    Nearest,
}

/// GetFEM's means of u_d over Γ^a with the trapezoidal weights w_i (per axis ½ at the ends; the
/// engine's `u_contact`) and of B's u_d at the points `at` gives for Γ^a's nodes with the same
/// weights (`u_contact_b`; B's displacement at Π(x_i) is multilinear on B's face cell; on a
/// matching interface both are B's own nodes) at every step.
fn face_means(
    field: &[Vec<[f64; 3]>],
    nodes: &serde_json::Value,
    s: &Setting,
    at: FaceB,
) -> [Vec<f64>; 2] {
    let d = s.dim;
    let nodes = nodes.as_array().unwrap();
    // (node, coordinates) of a body's face nodes at height `level`.
    let face = |body: usize, level: f64| -> Vec<(usize, [f64; 3])> {
        nodes
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                p["body"].as_u64().unwrap() as usize == body
                    && (coords(p)[d - 1] - level).abs() < 1e-9
            })
            .map(|(k, p)| (k, coords(p)))
            .collect()
    };
    let (face_a, face_b) = (face(0, s.height_b + s.gap), face(1, s.height_b));
    let across = (WIDTH / H).round() as usize;
    let across_b = (s.mesh_ratio * across as f64).round() as usize;
    // B's face node at lattice index j (per horizontal axis).
    let b_at: HashMap<[usize; 2], usize> = face_b
        .iter()
        .map(|&(k, x)| {
            let j = |a: usize| (x[a] / WIDTH * across_b as f64).round() as usize;
            ([0, 1].map(|a| if a < d - 1 { j(a) } else { 0 }), k)
        })
        .collect();
    let weight = |x: [f64; 3]| -> f64 {
        (0..d - 1)
            .map(|a| {
                let end = x[a].abs() < 1e-9 || (x[a] - WIDTH).abs() < 1e-9;
                if end { 0.5 } else { 1.0 }
            })
            .product()
    };
    let total: f64 = face_a.iter().map(|&(_, x)| weight(x)).sum();
    // B's u_d below x: multilinear between the lattice nodes around it, or at the engine's
    // node.
    let below = |u: &[[f64; 3]], x: [f64; 3]| -> f64 {
        let mut corners = vec![([0usize; 2], 1.0)];
        for a in 0..d - 1 {
            let r = x[a] / WIDTH * across_b as f64;
            let axis = if at == FaceB::Nearest {
                let i = (x[a] / WIDTH * across as f64).round();
                vec![((i * across_b as f64 / across as f64).round() as usize, 1.0)]
            } else {
                let j = (r.floor() as usize).min(across_b - 1);
                let t = r - j as f64;
                vec![(j, 1.0 - t), (j + 1, t)]
            };
            corners = corners
                .iter()
                .flat_map(|&(c, w)| {
                    axis.iter().map(move |&(j, wj)| {
                        let mut c = c;
                        c[a] = j;
                        (c, w * wj)
                    })
                })
                .collect();
        }
        corners.iter().map(|(c, w)| w * u[b_at[c]][d - 1]).sum()
    };
    // The weighted mean over Γ^a's nodes (k, x) of f(u, k, x) at every step.
    let mean = |f: &AtNode| -> Vec<f64> {
        field
            .iter()
            .map(|u| {
                face_a
                    .iter()
                    .map(|&(k, x)| weight(x) * f(u, k, x))
                    .sum::<f64>()
                    / total
            })
            .collect()
    };
    [mean(&|u, k, _| u[k][d - 1]), mean(&|u, _, x| below(u, x))]
}

/// A value read from one step's field at Γ^a's node k at x.
type AtNode<'a> = dyn Fn(&[[f64; 3]], usize, [f64; 3]) -> f64 + 'a;

/// GetFEM's displacement field at every step (times × nodes × 3, z = 0 in 2D).
fn getfem_field(g: &serde_json::Value) -> Vec<Vec<[f64; 3]>> {
    g["u"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            t.as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    let p = p.as_array().unwrap();
                    let mut u = [0.0; 3];
                    for (c, x) in p.iter().enumerate() {
                        u[c] = x.as_f64().unwrap();
                    }
                    u
                })
                .collect()
        })
        .collect()
}

/// The steps compared: all of them, or (consistent mass) up to the second contact — the first
/// contact phase and the free flight after it, read from GetFEM's force.
fn compared_steps(force: &[f64], whole_run: bool) -> (usize, usize) {
    let steps = force.len();
    let fmax = force.iter().cloned().fold(0.0, f64::max);
    // GetFEM's inactive multipliers are 0 or round-off (1e-96 seen): "in contact" above that.
    let in_contact = |f: f64| f > 1e-12 * fmax;
    let first = force
        .iter()
        .position(|&f| in_contact(f))
        .expect("the blocks touch");
    if whole_run {
        return (first, steps);
    }
    let off = first + force[first..].iter().position(|&f| !in_contact(f)).unwrap();
    let second = off
        + force[off..]
            .iter()
            .position(|&f| in_contact(f))
            .unwrap_or(steps - off);
    (first, second)
}

/// How a run is compared: over the whole run or (`whole_run` false) the first contact phase and
/// the flight after it ([`compared_steps`]), where `u_contact_b` reads B, and the tolerance on
/// each quantity relative to its scale.
#[derive(Debug, Clone, Copy)]
pub struct Check {
    pub whole_run: bool,
    pub at: FaceB,
    pub tol: f64,
}

/// One engine run against GetFEM's run `g` of the same method: each quantity's largest
/// difference over the compared steps, relative to its scale (the module's header), asserted
/// ≤ `check.tol`.
pub fn compare(
    s: &Setting,
    nodes: &serde_json::Value,
    g: &serde_json::Value,
    what: &str,
    o: &Outcome,
    check: Check,
) {
    let Check { whole_run, at, tol } = check;
    // GetFEM's multiplier steps meet Signorini to round-off (blocks.py's check; the gap is
    // 0.05–0.1, the forces O(10)).
    for k in ["penetration", "tension", "complementarity"] {
        if let Some(x) = g.get(k).and_then(|x| x.as_f64()) {
            assert!(x <= 1e-13, "{what}: GetFEM's {k} {x:e}");
        }
    }
    let force = floats(&g["force"]);
    let energy = floats(&g["energy"]);
    let momentum = floats(&g["momentum"]);
    let steps = force.len();
    assert_eq!(o.series.len(), steps, "{what}: steps");
    let (first, end) = compared_steps(&force, whole_run);
    let fmax = force.iter().cloned().fold(0.0, f64::max);
    let e0 = energy[0];
    let body_mass = floats(&g["body_mass"]);
    let p_scale = body_mass[0] * VELOCITY.abs() + body_mass[1] * s.velocity_b.abs();
    // 1ᵀM1 of Q1 masses, exact on both sides: round-off of ~10² summed entries.
    let (mt, gf_mt) = (
        o.metrics.mass_total.unwrap(),
        g["mass_total"].as_f64().unwrap(),
    );
    assert!(
        (mt - gf_mt).abs() <= 1e-13 * gf_mt,
        "{what}: mass_total {mt} against GetFEM's {gf_mt}"
    );
    if s.far_end == "free" {
        // GetFEM's brick acts equally and oppositely too: its P is constant to round-off
        // (contract §2.6's invariant, ~1e-15 per step over 200 steps). On a matching interface
        // its rows' coefficients are ±1 and this holds over the whole run; a non-matching
        // row's (1 − t, t) sum to 1 only to round-off, which the consistent mass's chatter
        // (forces growing with E to ~11 E⁰) accumulates to ~1.4e-12 of the scale by T
        // (measured, mesh_ratio 4/3): there GetFEM's invariant is asserted over the compared
        // steps, and the engine's over the whole run.
        let upto = if s.mesh_ratio == 1.0 { steps } else { end };
        let drift = |p: &[f64]| p.iter().map(|x| (x - p[0]).abs()).fold(0.0, f64::max);
        let gf_drift = drift(&momentum[..upto]);
        assert!(
            gf_drift <= 1e-12 * p_scale,
            "{what}: GetFEM's momentum drift {gf_drift:e} over steps ..{upto}"
        );
        let engine: Vec<f64> = o.series.rows().map(|r| r.momentum.unwrap()).collect();
        let engine_drift = drift(&engine);
        assert!(
            engine_drift <= 1e-12 * p_scale,
            "{what}: the engine's momentum drift {engine_drift:e}"
        );
        eprintln!(
            "{what}: momentum drift, of the scale: GetFEM {:.2e} (whole run {:.2e}), engine {:.2e}",
            gf_drift / p_scale,
            drift(&momentum) / p_scale,
            engine_drift / p_scale
        );
    }
    let field = engine_field(o, nodes, s);
    let gf_field = getfem_field(g);
    let u_scale = gf_field
        .iter()
        .flatten()
        .flat_map(|p| p.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let du = field[..end]
        .iter()
        .zip(&gf_field[..end])
        .flat_map(|(a, b)| a.iter().zip(b))
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max)
        / u_scale;
    let rows: Vec<_> = o.series.rows().collect();
    let col = |f: &dyn Fn(&SeriesRow) -> f64| -> Vec<f64> { rows.iter().map(f).collect() };
    let [ua, ub] = face_means(&gf_field, nodes, s, at);
    let (ef, ee) = (col(&|r| -r.sigma_contact), col(&|r| r.energy));
    // An engine column against GetFEM's series `key`.
    let series =
        |f: &dyn Fn(&SeriesRow) -> f64, key: &str| max_diff(&col(f), &floats(&g[key]), end);
    let measured = [
        ("displacement field", du),
        (
            "u_contact",
            max_diff(&col(&|r| r.u_contact), &ua, end) / u_scale,
        ),
        (
            "u_contact_b",
            max_diff(&col(&|r| r.u_contact_b.unwrap()), &ub, end) / u_scale,
        ),
        ("contact force", max_diff(&ef, &force, end) / fmax),
        ("energy", max_diff(&ee, &energy, end) / e0),
        (
            "kinetic energy",
            series(&|r| r.energy_kinetic.unwrap(), "kinetic") / e0,
        ),
        (
            "elastic energy",
            series(&|r| r.energy_elastic.unwrap(), "elastic") / e0,
        ),
        (
            "momentum",
            max_diff(&col(&|r| r.momentum.unwrap()), &momentum, end) / p_scale,
        ),
    ];
    // Where the runs part (measured and printed: the consistent mass's round-off growth).
    let part = (0..steps)
        .find(|&k| (ef[k] - force[k]).abs() > 1e-8 * fmax || (ee[k] - energy[k]).abs() > 1e-8 * e0)
        .unwrap_or(steps);
    let growth = energy[..end].iter().cloned().fold(0.0, f64::max) / e0;
    eprintln!(
        "{what}: steps 0..{end} of {steps} compared (contact from step {first}; GetFEM's E/E⁰ up to {growth:.3} there, {:.3} at T); agree to 1e-8 through step {}",
        energy[steps - 1] / e0,
        part as isize - 1
    );
    for (q, x) in measured {
        eprintln!("  {q}: {x:.2e}");
        assert!(x <= tol, "{what}: {q} off GetFEM's by {x:.3e} of its scale");
    }
}

/// Every setting's engine runs (both masses) against GetFEM's, each compared by [`compare`].
pub fn engine_equals_getfem(settings: &[Setting]) {
    let ctx = RunContext {
        reference: None,
        record_reference: Some((1, 1)),
    };
    for s in settings {
        let gf = run_script_on(
            "blocks.py",
            None,
            &[s.params(serde_json::json!({})), MASSES.join(",")],
        );
        let method = format!("space = \"mixed\"\n{}", s.contact);
        let sweep = s.sweep(&method, r#"mass = ["zero-contact", "consistent"]"#);
        let runs = super::outcomes_edited(&root().join("t.toml"), &sweep, |_| {}, &ctx);
        assert_eq!(runs.len(), 2, "{}: two masses", s.name);
        for (label, o) in &runs {
            let mass = MASSES
                .into_iter()
                .find(|m| label.contains(m))
                .expect("a mass in the label");
            let what = format!("{} · {label}", s.name);
            // The consistent mass chatters (the header): its first contact phase.
            let check = Check {
                whole_run: mass != "consistent",
                at: FaceB::Projected,
                tol: 1e-8,
            };
            compare(s, &gf["nodes"], &gf["variants"][mass], &what, o, check);
        }
    }
}
