#!/usr/bin/python3
"""Two elastic blocks, A falling on B, with GetFEM 5.4's nodal contact brick between two bodies
(`add_nodal_contact_between_nonmatching_meshes_brick`, Debian's python3-getfem) and Newmark
β = ¼, γ = ½ — an implementation of contract §1.10/§2.1/§2.2/§2.6/§3 that shares no code with
the engine, for tests/getfem_blocks.rs (issue 44) and tests/getfem_nonmatching.rs (issue 45).
The blocks, K, M, the masses and the Newmark loop are tests/getfem/two_blocks.py's (shared with
tests/getfem/nitsche_blocks.py).

The bodies (contract §1.10): B = [0, W] × [0, H_b] and A = [0, W] × [H_b + g, H_b + g + H_a],
each a GetFEM mesh of its own (two displacement variables u_a, u_b), Q1 squares of side h
(GT_QK(2,1), FEM_QK(2,1)), W/h across A and round(mesh_ratio·W/h) across B (1, the default: a
matching interface), plane strain, each with its
own ρ, λ, μ. K and M per body with a 3 × 3 Gauss rule (exact for Q1 on rectangles: the mass's
and the stiffness' integrands have degree ≤ 2 per axis); no load. B's base is free or clamped
(u_b = 0 on y = 0 by GetFEM's Dirichlet condition with simplification: the dofs leave the
system, as the engine's clamped dofs do).

The contact (GetFEM's brick, read in getfem_contact_and_friction_nodal.cc): slave = A's bottom
face (region 1 of u_a), master = B's top face (region 2 of u_b). For each slave node the brick
takes the nearest master node, projects the slave node on that node's faces and builds one row
B_N u = (u_b(proj) − u_a(slave))·n_B with n_B = +e_y B's outward normal, and the gap
g_i = (x_slave − proj)·n_B = g. On a matching interface the projection is the master node
itself, so B_N's row is e_{b,π(i),y} − e_{a,i,y}: the engine's δ_i = (u^a_i − u^b_π(i))·n with
n = −e_y (A's outward normal), the same number. The brick's condition is B_N u ≤ g, λ_N ≤ 0,
λ_N(B_N u − g) = 0, with B_Nᵀλ_N added to the bodies' forces (λ_N ≤ 0 pushes A up): its
multiplier is minus the engine's row force, so the total contact force reported here is −Σλ_N
(≥ 0, the engine's Σλ = −σ_C). Non-symmetric Alart–Curnier (augmented_version 1), r = A's
Young modulus (GetFEM's advice; the converged solution does not depend on r).

Newmark β = ¼, γ = ½ in numpy around GetFEM's solve: predictor p = u + τv + τ²(½ − β)a; the
step's model is (M/(βτ²) + K) u = M p/(βτ²) + B_Nᵀλ_N (explicit matrices and right-hand sides
per body, so λ_N is a force, not a force times βτ²) with the brick, solved by GetFEM's Newton
from the previous step's (u, λ_N) to a residual of `TOL`; then a = (u − p)/(βτ²),
v ← v + τ(½a_old + ½a). v⁰ = (V_t, V) on A, (0, V_b) on B, u⁰ = 0 (the massless dofs' quasi-static
start K_cc u_c = −K_cf u_f = 0: nothing loads them), a⁰ = 0 (M_ff a⁰_f = −(K u⁰)_f = 0).
Energy E = ½vᵀMv + ½uᵀKu (both bodies), momentum P = Σ (M v)_y over the free e_y dofs, each
body's mass 1ᵀM_i1 (e_y component) and mass_total = Σ_i 1ᵀM_i1 (e_x component, clamped nodes
included: the engine's `mass_total`).

Masses (contract §2.2, §2.6, `mass_side = "both"`): `consistent`, and `zero-contact` — the
rows and columns of both components of every Γ^a node and every Γ^b node zeroed in M (those
dofs become quasi-static: the step's rows read K u = B_Nᵀλ_N there).

Usage: blocks.py OUT.json PARAMS_JSON VARIANTS
  PARAMS_JSON: {"width", "height", "height_b", "h", "gap", "velocity", "velocity_tangential",
                "velocity_b",
                "density", "lame_lambda", "lame_mu", "density_b", "lame_lambda_b", "lame_mu_b",
                "far_end" ("free" | "clamped"), "T", "dt", optionally "mesh_ratio" and
                "dim" (2 or 3: the vertical axis the last; the rows along e_d, the projection
                multilinear on B's face cell)}
  VARIANTS: comma-separated masses.
Writes per variant the series (force, energy, kinetic, elastic, momentum, Newton iterations),
the whole displacement field at every step (node by node; `nodes` gives each node's body and
coordinates), the masses, and how exactly the steps met Signorini (`check`).
"""
import json
import sys

import numpy as np

from two_blocks import Blocks

# GetFEM's Newton stops when min(‖residual‖₁/‖load‖₁, ‖Δx‖₁/‖x‖₁) ≤ TOL
# (getfem_model_solvers.h): once its active set is right one Newton step solves the step's
# linear system to round-off, so every converged step here took 1–3 iterations (measured). A
# tighter TOL is below that round-off: the Newton then wanders to `max_iter` and leaves a wrong
# state (1e-13 did), so each step's exactness is checked instead (`check`).
TOL = 1e-11
MAX_ITER = 100

out_path, params, variants = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3].split(',')
S = Blocks(params)
A, B, gap = S.A, S.B, S.gap
lam_a, mu_a = params['lame_lambda'], params['lame_mu']
young_a = mu_a * (3 * lam_a + 2 * mu_a) / (lam_a + mu_a)


def model(Ms):
    """The step's model (two_blocks.Blocks.model) with the nodal contact brick."""
    md, rhs = S.model(Ms)
    md.add_initialized_data('r', [young_a])
    md.add_nodal_contact_between_nonmatching_meshes_brick(A.mim, B.mim, 'ua', 'ub', 'lam_n',
                                                          'r', A.region, B.region, 1, 0, 1)
    return md, rhs


D = S.dim
# B's face lattice along each horizontal axis (the same along each) and its e_1 dof at each
# face node.
LATTICE = np.unique(np.round(B.xy[0, B.face_dofs], 12))
B_AT = {tuple(np.round(B.xy[:D - 1, e], 12)): e for e in B.face_dofs if e % D == 0}


def below(k):
    """The B face dofs (e_1) at the corners of the B face straight below A's face dof k (e_1),
    with the (multi)linear weights of the point below k: the brick's projection of a slave node
    on a flat master face (its nearest master node's faces hold that point)."""
    axes = []
    for c in range(D - 1):
        x = A.xy[c, k]
        j = min(max(int(np.searchsorted(LATTICE, x + 1e-12)) - 1, 0), len(LATTICE) - 2)
        x0, x1 = LATTICE[j], LATTICE[j + 1]
        if not x0 - 1e-12 <= x <= x1 + 1e-12:
            raise ValueError(f'A node at {A.xy[:, k]} above no B face')
        t = (x - x0) / (x1 - x0)
        axes.append([(x0, 1.0 - t), (x1, t)])
    corners = [([], 1.0)]
    for ax in axes:
        corners = [(p + [x], w * wx) for p, w in corners for x, wx in ax]
    return [(B_AT[tuple(np.round(p, 12))], w) for p, w in corners]


# The brick's rows in its order (A's face nodes by increasing dof: getfem's
# contact_node_list_from_region) with the B face below each and its weights.
ROWS = [(k, below(k)) for k in sorted(A.face_dofs) if k % D == 0]


def check(u, lam, worst):
    """How exactly the step meets Signorini on each row, δ_i = u_b,d(proj) − u_a,d ≤ g,
    λ_N ≤ 0, λ_N(δ − g) = 0: the largest penetration (δ − g)_+, tension λ_+ and |λ(δ − g)| so
    far."""
    for i, (da, pairs) in enumerate(ROWS):
        s = sum(w * u[1][e + D - 1] for e, w in pairs) - u[0][da + D - 1] - gap
        worst['penetration'] = max(worst['penetration'], max(s, 0.0))
        worst['tension'] = max(worst['tension'], max(lam[i], 0.0))
        worst['complementarity'] = max(worst['complementarity'], abs(lam[i] * s))


def run(name):
    Ms = S.masses(name)
    md, rhs = model(Ms)
    state = {'lam': np.zeros(len(md.variable('lam_n')))}
    exact = {'penetration': 0.0, 'tension': 0.0, 'complementarity': 0.0}

    def solve(md):
        md.set_variable('lam_n', state['lam'])
        it = md.solve('max_res', TOL, 'max_iter', MAX_ITER)
        iterations = int(np.ravel(it)[0])
        if iterations >= MAX_ITER:
            raise RuntimeError(f'{name}: GetFEM\'s Newton did not converge')
        lam = np.asarray(md.variable('lam_n')).copy()
        check([np.asarray(md.variable(x)) for x in ('ua', 'ub')], lam, exact)
        state['lam'] = lam
        return -lam.sum(), iterations

    return {**S.run(Ms, md, rhs, solve), **exact}


out = {'nodes': S.nodes(), 'contact_rows': len(A.face_dofs) // D, 'variants': {}}
for name in variants:
    out['variants'][name] = run(name)
with open(out_path, 'w') as f:
    json.dump(out, f)
