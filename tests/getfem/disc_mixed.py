#!/usr/bin/python3
"""The 003 disc on a Gmsh P2 mesh, assembled by GetFEM 5.4 (Debian's python3-getfem), stepped by
Crank–Nicolson with nodal Signorini contact on the vertical dofs of Γ_C, or with Nitsche's
contact on the faces of Γ_C — an implementation of contract §1.3/§2.1/§2.2/§2.3/§3 that shares no
code with the engine, for tests/getfem_disc.rs (issue 34).

What GetFEM computes: the isoparametric P2 mesh of the file (curved boundary triangles, GT_PK(2,2)),
the P2 vector FEM, and on it, with a degree-13 triangle rule (exact for the curved cells' mass,
whose integrand has degree 6):
- K: isotropic linearized elasticity (plane strain), λ = μ = 20;
- M: ρ ∫ w φ_a·φ_b with w the mass variant's element weight (layers by topology: layer 0 the
  cells with a node on Γ_C, layer k + 1 their neighbours; mod1 w₀ = 0; mod2 w₀ = 0, w_k =
  m/(m − m₀); mod3 w₀ = 0, w₁ = 1 + m₀/m₁; zero-contact: the Γ_C nodes' rows and columns of M
  zeroed);
- F: the body force ∫ρ f·φ, f = −0.1 e_y (contract §1.3: whatever the mass variant).
Time stepping in numpy: Newmark β = ¼, γ = ½ (Crank–Nicolson), v⁰ = 0. The start (contract §1.3,
§2.2): with a mass that has zero rows the massless dofs c (M's zero diagonal) carry load, and
start quasi-static — u⁰_c solves K_cc u⁰_c = F_c here, with the dofs with inertia at 0 (the
disc starts 5 above the plane: no contact at t = 0, checked), so E⁰ = −½F_cᵀK_cc⁻¹F_c; the
variant `NAME@zero` starts them at u⁰ = 0 instead (the engine's contact_init = "interpolant").
Every variant's a⁰ from M_ff a⁰_f = (F − K u⁰)_f on the dofs with inertia. Each step (M + τ²/4 K) u = M(u + τv + τ²/4 a) + τ²/4 (F + Bᵀλ) with the
LCP 0 ≤ λ ⊥ u_y + g ≥ 0 on the Γ_C nodes (g = the node's height above the plane y = −gap),
condensed onto Γ_C and solved exactly (active set, Murty's least-index rule). Energy
E = ½vᵀMv + ½uᵀKu − Fᵀu, contact force Σλ.

Nitsche (variant `nitsche`, consistent mass, Θ = 1, γ0 = 1e-3 as 003 §4.2): GetFEM's model
solves each step (M + τ²/4 K) u + τ²/4 R_c(u) = M(u + τv + τ²/4 a) + τ²/4 F by its Newton
method, R_c the Nitsche terms written in GetFEM's weak form language on Γ_C,
  −Θ γ σ_n(u) σ_n(v) + (1/γ) [P_γ(u) − g]_+ (v·N − Θ γ σ_n(v)),
with N = −e_y the obstacle's normal, σ_n(u) = N·σ(u)N, P_γ(u) = u·N − γ σ_n(u), g = y − y_plane
(the point's height above the plane), γ = γ0·h_K with h_K the cell's diameter (its largest
node-to-node distance), integrated by the face rule of IM_TRIANGLE(5): 3 Gauss points per face,
as the engine's Γ_C rule. The contact force reported is ∫_ΓC (1/γ)[P_γ(u) − g]_+.

The mesh, K, M, F, Γ_C, γ, the Nitsche model and the Newmark update: tests/getfem/common.py
(shared with tests/getfem/disc_nitsche_friction.py).

Usage: disc_mixed.py MESH OUT.json [T dt gap [VARIANTS]] (a variant: a mass, `MASS@zero`, or nitsche)
"""
import json
import sys

import getfem as gf
import numpy as np
import scipy.linalg as sla

import common as c

mesh_path, out_path = sys.argv[1], sys.argv[2]
T = float(sys.argv[3]) if len(sys.argv) > 3 else 40.0
TAU = float(sys.argv[4]) if len(sys.argv) > 4 else 0.1
GAP = float(sys.argv[5]) if len(sys.argv) > 5 else 5.0
STEPS = int(round(T / TAU))

disc = c.Disc(mesh_path)
m, n, pts, K, F = disc.m, disc.n, disc.pts, disc.K, disc.F
contact_pids = disc.contact_pids

# Layers by topology over the cells' points (midside nodes included, as the engine's).
cv_pids = [set(int(p) for p in m.pid_from_cvid(cv)[0]) for cv in range(m.nbcvs())]
layer = [None] * m.nbcvs()
reached = set(contact_pids)
k = 0
while any(l is None for l in layer):
    now = [cv for cv in range(m.nbcvs()) if layer[cv] is None and cv_pids[cv] & reached]
    if not now:
        break
    for cv in now:
        layer[cv] = k
    for cv in now:
        reached |= cv_pids[cv]
    k += 1
layer = [k if l is None else l for l in layer]

# The dofs of each point: the vector dof 2i + c is component c of basic dof i.
contact_dofs = [disc.dofs_at(p) for p in contact_pids]
vertical = [sorted(ds)[1] for ds in contact_dofs]
gaps = np.array([pts[1][p] - disc.ymin + GAP for p in contact_pids])

mass = disc.mass
M_full = mass(np.ones(m.nbcvs()))
layer_mass = lambda l: mass(np.array([1.0 if x == l else 0.0 for x in layer]))[0::2, 0::2].sum()
total = M_full[0::2, 0::2].sum()
m0, m1 = layer_mass(0), layer_mass(1)


def variant(name):
    if name == 'consistent':
        return M_full.copy()
    if name == 'zero-contact':
        M = M_full.copy()
        for ds in contact_dofs:
            M[ds, :] = 0.0
            M[:, ds] = 0.0
        return M
    w = {'mod1': lambda l: 0.0 if l == 0 else 1.0,
         'mod2': lambda l: 0.0 if l == 0 else total / (total - m0),
         'mod3': lambda l: 0.0 if l == 0 else (1.0 + m0 / m1 if l == 1 else 1.0)}[name]
    return mass(np.array([w(l) for l in layer]))


def lcp(H, q, active, tol):
    """0 ≤ λ ⊥ q + Hλ ≥ 0 for symmetric positive definite H: Murty's least-index principal
    pivoting from the previous step's active set (finite for P-matrices)."""
    A = set(active)
    for _ in range(10000):
        lam = np.zeros(len(q))
        idx = sorted(A)
        if idx:
            lam[idx] = np.linalg.solve(H[np.ix_(idx, idx)], -q[idx])
        w = q + H @ lam
        bad = [i for i in range(len(q)) if (i in A and lam[i] < -tol) or (i not in A and w[i] < -tol)]
        if not bad:
            return lam, sorted(A)
        j = bad[0]
        A.symmetric_difference_update({j})
    raise RuntimeError('LCP: no convergence')


def start(M):
    """The quasi-static start of the massless dofs (the module's docstring): u⁰, and
    −½F_cᵀK_cc⁻¹F_c (0 without massless dofs)."""
    massless = np.where(np.diag(M) == 0.0)[0]
    u = np.zeros(n)
    if len(massless) == 0:
        return u, 0.0
    u[massless] = sla.cho_solve(sla.cho_factor(K[np.ix_(massless, massless)]), F[massless])
    if np.any(u[vertical] + gaps < 0.0):
        raise RuntimeError('the quasi-static start touches the plane: not this script\'s case')
    return u, float(-0.5 * F[massless] @ u[massless])


def run(name):
    name, _, how = name.partition('@')
    M = variant(name)
    beta = c.BETA
    A = M + beta * TAU**2 * K
    cho = sla.cho_factor(A)
    B = np.zeros((len(vertical), n))
    for i, d in enumerate(vertical):
        B[i, d] = 1.0
    Z = sla.cho_solve(cho, B.T)
    H = beta * TAU**2 * (B @ Z)
    diag = np.diag(M)
    free = np.where(diag != 0.0)[0]
    u, e0 = (np.zeros(n), 0.0) if how == 'zero' else start(M)
    v = np.zeros(n)
    a = np.zeros(n)
    a[free] = np.linalg.solve(M[np.ix_(free, free)], (F - K @ u)[free])
    energy = [c.energy(M, K, F, u, v)]
    force = [0.0]
    active = []
    for _ in range(STEPS):
        p = c.predictor(u, v, a, TAU)
        ufree = sla.cho_solve(cho, M @ p + beta * TAU**2 * F)
        q = B @ ufree + gaps
        lam, active = lcp(H, q, active, 1e-13 * max(1.0, np.abs(q).max()))
        u, v, a = c.advance(ufree + beta * TAU**2 * (Z @ lam), p, v, a, TAU)
        energy.append(c.energy(M, K, F, u, v))
        force.append(float(lam.sum()))
    return {'mass_total': float(M[0::2, 0::2].sum()), 'energy': energy, 'force': force,
            'energy_initial': e0}


def run_nitsche(theta=1.0, gamma0=1e-3):
    M = M_full
    A = M + c.BETA * TAU**2 * K
    md, rhs_brick = disc.nitsche_model(A, gamma0, theta, [('btau2', [c.BETA * TAU**2])])
    plane = disc.plane(GAP)
    md.add_nonlinear_term(disc.mim_c, f'btau2*({c.nitsche_normal_terms(plane)})',
                          c.CONTACT_REGION)
    force_expr = c.normal_force('u', plane)
    u = np.zeros(n)
    v = np.zeros(n)
    a = np.linalg.solve(M, F)
    energy = [0.0]
    force = [0.0]
    for _ in range(STEPS):
        p = c.predictor(u, v, a, TAU)
        un, _ = c.nitsche_solve(md, rhs_brick, M @ p + c.BETA * TAU**2 * F, u,
                                'max_res', 1e-10, 'max_iter', 100)
        u, v, a = c.advance(un, p, v, a, TAU)
        energy.append(c.energy(M, K, F, u, v))
        force.append(float(gf.asm('generic', disc.mim_c, 0, force_expr, c.CONTACT_REGION, md)))
    return {'mass_total': float(M[0::2, 0::2].sum()), 'energy': energy, 'force': force}


out = {'body_mass': float(total), 'dofs': n, 'contact_nodes': len(contact_pids),
       'layers': int(max(layer)) + 1, 'variants': {}}
for name in (sys.argv[6].split(',') if len(sys.argv) > 6 else
             ['consistent', 'zero-contact', 'mod1', 'mod2', 'mod3']):
    out['variants'][name] = run_nitsche() if name == 'nitsche' else run(name)
with open(out_path, 'w') as f:
    json.dump(out, f)
