#!/usr/bin/python3
"""Two elastic blocks, A falling on B, with GetFEM 5.4's nodal contact brick between two bodies
(`add_nodal_contact_between_nonmatching_meshes_brick`, Debian's python3-getfem) and Newmark
β = ¼, γ = ½ — an implementation of contract §1.10/§2.1/§2.2/§2.6/§3 that shares no code with
the engine, for tests/getfem_blocks.rs (issue 44).

The bodies (contract §1.10): B = [0, W] × [0, H_b] and A = [0, W] × [H_b + g, H_b + g + H_a],
each a GetFEM mesh of its own (two displacement variables u_a, u_b), Q1 squares of side h
(GT_QK(2,1), FEM_QK(2,1)), W/h across both (a matching interface), plane strain, each with its
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
                "far_end" ("free" | "clamped"), "T", "dt"}
  VARIANTS: comma-separated masses.
Writes per variant the series (force, energy, kinetic, elastic, momentum, Newton iterations),
the whole displacement field at every step (node by node; `nodes` gives each node's body and
coordinates), the masses, and how exactly the steps met Signorini (`check`).
"""
import json
import sys

import getfem as gf
import numpy as np

from common import stiffness

BETA = 0.25
# GetFEM's Newton stops when min(‖residual‖₁/‖load‖₁, ‖Δx‖₁/‖x‖₁) ≤ TOL
# (getfem_model_solvers.h): once its active set is right one Newton step solves the step's
# linear system to round-off, so every converged step here took 1–3 iterations (measured). A
# tighter TOL is below that round-off: the Newton then wanders to `max_iter` and leaves a wrong
# state (1e-13 did), so each step's exactness is checked instead (`check`).
TOL = 1e-11
MAX_ITER = 100
RG_A, RG_B = 1, 2

out_path, params, variants = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3].split(',')
gf.util_trace_level(0)
W, H_a, H_b, h, gap = (params[k] for k in ('width', 'height', 'height_b', 'h', 'gap'))
TAU = params['dt']
STEPS = int(round(params['T'] / TAU))
across = int(round(W / h))
# B's cells across: round(mesh_ratio·W/h), the engine's blocks (contract §1.10; 1: matching).
across_b = max(1, int(round(params.get('mesh_ratio', 1.0) * across)))


class Body:
    """One block: its mesh, Q1 space, K, consistent M, its contact face and the dofs kept."""

    def __init__(self, y0, height, cells, rho, lam, mu, face_normal, region, clamp_base):
        up = int(round(height / h))
        self.m = gf.Mesh('cartesian', np.linspace(0.0, W, cells + 1),
                         np.linspace(y0, y0 + height, up + 1))
        self.mf = gf.MeshFem(self.m, 2)
        self.mf.set_fem(gf.Fem('FEM_QK(2,1)'))
        self.mim = gf.MeshIm(self.m, gf.Integ('IM_GAUSS_PARALLELEPIPED(2,5)'))
        self.n = self.mf.nbdof()
        u0 = np.zeros(self.n)
        self.M = rho * gf.asm('generic', self.mim, 2, 'Test_u.Test2_u', -1, 'u', 1, self.mf,
                              u0).full()
        self.K = stiffness(self.mf, self.mim, lam, mu)
        faces = self.m.outer_faces_with_direction(face_normal, 0.01)
        self.m.set_region(region, faces)
        self.region = region
        self.xy = self.mf.basic_dof_nodes()
        self.face_dofs = [d for d in range(self.n)
                          if abs(self.xy[1, d] - (y0 if face_normal[1] < 0 else y0 + height))
                          < 1e-9]
        base = [d for d in range(self.n) if abs(self.xy[1, d] - y0) < 1e-9]
        self.clamped = sorted(base) if clamp_base else []
        # The e_y dofs whose (M v) the momentum sums: the engine's free ones (a clamped row's
        # reaction is not momentum of the body).
        self.kept_y = [d for d in range(1, self.n, 2) if d not in set(self.clamped)]

    def nodes(self):
        """(x, y) of each node, with the index of its x and y dofs."""
        pts = {}
        for d in range(self.n):
            key = (round(self.xy[0, d], 12), round(self.xy[1, d], 12))
            pts.setdefault(key, []).append(d)
        return [(x, y, sorted(ds)) for (x, y), ds in sorted(pts.items())]


rho_a, lam_a, mu_a = params['density'], params['lame_lambda'], params['lame_mu']
A = Body(H_b + gap, H_a, across, rho_a, lam_a, mu_a, [0.0, -1.0], RG_A, False)
B = Body(0.0, H_b, across_b, params['density_b'], params['lame_lambda_b'], params['lame_mu_b'],
         [0.0, 1.0], RG_B, params['far_end'] == 'clamped')
young_a = mu_a * (3 * lam_a + 2 * mu_a) / (lam_a + mu_a)


def masses(name):
    """Each body's M for the variant (contract §2.2, mass_side = both)."""
    Ms = []
    for body in (A, B):
        M = body.M.copy()
        if name == 'zero-contact':
            M[body.face_dofs, :] = 0.0
            M[:, body.face_dofs] = 0.0
        elif name != 'consistent':
            raise ValueError(f'mass {name}: not in this script')
        Ms.append(M)
    return Ms


def model(Ms):
    """GetFEM's model of one step: u_a, u_b with the explicit (M/(βτ²) + K) of each body, an
    explicit right-hand side per body (its bricks returned) and the nodal contact brick; B's
    clamped dofs held at 0 by a simplified Dirichlet condition."""
    md = gf.Model('real')
    md.add_fem_variable('ua', A.mf)
    md.add_fem_variable('ub', B.mf)
    rhs = []
    for name, body, M in (('ua', A, Ms[0]), ('ub', B, Ms[1])):
        mat = M / (BETA * TAU**2) + body.K
        sp = gf.Spmat('empty', body.n, body.n)
        sp.add(np.arange(body.n), np.arange(body.n), mat)
        md.add_explicit_matrix(name, name, sp)
        rhs.append(md.add_explicit_rhs(name, np.zeros(body.n)))
    if B.clamped:
        B.m.set_region(3, B.m.outer_faces_with_direction([0.0, -1.0], 0.01))
        md.add_initialized_data('zero', [0.0, 0.0])
        md.add_Dirichlet_condition_with_simplification('ub', 3, 'zero')
    md.add_initialized_data('r', [young_a])
    md.add_nodal_contact_between_nonmatching_meshes_brick(A.mim, B.mim, 'ua', 'ub', 'lam_n',
                                                          'r', RG_A, RG_B, 1, 0, 1)
    return md, rhs


def below(d):
    """The B face dofs (e_x) at the ends of the B face straight below A's face dof d (e_x),
    with the linear weights of the point below d: the brick's projection of a slave node on a
    flat master face (its nearest master node's faces hold that point)."""
    x = A.xy[0, d]
    ends = sorted((e for e in B.face_dofs if e % 2 == 0), key=lambda e: B.xy[0, e])
    for e0, e1 in zip(ends, ends[1:]):
        x0, x1 = B.xy[0, e0], B.xy[0, e1]
        if x0 - 1e-12 <= x <= x1 + 1e-12:
            t = (x - x0) / (x1 - x0)
            return [(e0, 1.0 - t), (e1, t)]
    raise ValueError(f'A node at x = {x} above no B face')


# The brick's rows in its order (A's face nodes by increasing dof: getfem's
# contact_node_list_from_region) with the B face below each and its weights.
ROWS = [(d, below(d)) for d in sorted(A.face_dofs) if d % 2 == 0]


def check(u, lam, worst):
    """How exactly the step meets Signorini on each row, δ_i = u_b,y(proj) − u_a,y ≤ g,
    λ_N ≤ 0, λ_N(δ − g) = 0: the largest penetration (δ − g)_+, tension λ_+ and |λ(δ − g)| so
    far."""
    for i, (da, pairs) in enumerate(ROWS):
        s = sum(w * u[1][e + 1] for e, w in pairs) - u[0][da + 1] - gap
        worst['penetration'] = max(worst['penetration'], max(s, 0.0))
        worst['tension'] = max(worst['tension'], max(lam[i], 0.0))
        worst['complementarity'] = max(worst['complementarity'], abs(lam[i] * s))


def run(name):
    Ms = masses(name)
    md, rhs = model(Ms)
    bodies = (A, B)
    u = [np.zeros(b.n) for b in bodies]
    v = [np.zeros(b.n) for b in bodies]
    for vb, V in zip(v, (params['velocity'], params['velocity_b'])):
        vb[1::2] = V
    v[0][0::2] = params['velocity_tangential']
    v[1][B.clamped] = 0.0
    a = [np.zeros(b.n) for b in bodies]
    lam = np.zeros(len(md.variable('lam_n')))
    series = {k: [] for k in ('force', 'energy', 'kinetic', 'elastic', 'momentum', 'iterations')}
    fields = []

    def observe(force, iterations):
        kin = sum(0.5 * vb @ M @ vb for vb, M in zip(v, Ms))
        ela = sum(0.5 * ub @ b.K @ ub for ub, b in zip(u, bodies))
        series['force'].append(float(force))
        series['kinetic'].append(float(kin))
        series['elastic'].append(float(ela))
        series['energy'].append(float(kin + ela))
        series['momentum'].append(float(sum((M @ vb)[b.kept_y].sum()
                                            for vb, M, b in zip(v, Ms, bodies))))
        series['iterations'].append(iterations)
        fields.append([[float(ub[ds[0]]), float(ub[ds[1]])]
                       for ub, b in zip(u, bodies) for (_, _, ds) in b.nodes()])

    observe(0.0, 0)
    exact = {'penetration': 0.0, 'tension': 0.0, 'complementarity': 0.0}
    for _ in range(STEPS):
        p = [ub + TAU * vb + TAU**2 * (0.5 - BETA) * ab for ub, vb, ab in zip(u, v, a)]
        for brick, M, pb in zip(rhs, Ms, p):
            md.set_private_rhs(brick, M @ pb / (BETA * TAU**2))
        md.set_variable('ua', u[0])
        md.set_variable('ub', u[1])
        md.set_variable('lam_n', lam)
        it = md.solve('max_res', TOL, 'max_iter', MAX_ITER)
        iterations = int(np.ravel(it)[0])
        if iterations >= MAX_ITER:
            raise RuntimeError(f'{name}: GetFEM\'s Newton did not converge at step {len(fields)}')
        un = [np.asarray(md.variable('ua')).copy(), np.asarray(md.variable('ub')).copy()]
        lam = np.asarray(md.variable('lam_n')).copy()
        check(un, lam, exact)
        an = [(x - pb) / (BETA * TAU**2) for x, pb in zip(un, p)]
        v = [vb + TAU * (0.5 * ab + 0.5 * anb) for vb, ab, anb in zip(v, a, an)]
        u, a = un, an
        observe(-lam.sum(), iterations)
    return {**series, **exact, 'u': fields,
            'mass_total': float(sum(M[0::2, 0::2].sum() for M in Ms)),
            'body_mass': [float(M[1::2, 1::2].sum()) for M in Ms]}


nodes = [{'body': k, 'x': x, 'y': y} for k, b in enumerate((A, B)) for (x, y, _) in b.nodes()]
out = {'nodes': nodes, 'contact_rows': len(A.face_dofs) // 2, 'variants': {}}
for name in variants:
    out['variants'][name] = run(name)
with open(out_path, 'w') as f:
    json.dump(out, f)
