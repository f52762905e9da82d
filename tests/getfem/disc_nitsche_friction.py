#!/usr/bin/python3
"""The 003 disc on a Gmsh P2 mesh thrown obliquely onto a rigid plane with Coulomb friction,
Nitsche's contact in GetFEM 5.4's weak form language (Debian's python3-getfem): an
implementation of contract §2.5's frictional Nitsche that shares no code with the engine, for
tests/friction_nitsche.rs (issue 33).

The bulk as tests/getfem/disc_mixed.py (tests/getfem/common.py): the isoparametric P2 mesh of
the file, P2 vector FEM, IM_TRIANGLE(13) (exact for the curved cells' mass), K (λ = μ = 20,
plane strain), the consistent M, the body force F = ∫ρ f·φ with f = −0.1 e_y. Initial state u⁰ = 0, v⁰ = V e_x on every node,
a⁰ from M a⁰ = F. Crank–Nicolson (Newmark β = ¼, γ = ½): each step solves
  (M + τ²/4 K) u + τ²/4 R_c(u) = M(u^n + τv^n + τ²/4 a^n) + τ²/4 F
by GetFEM's Newton method, with R_c contract §2.5's contact residual (GetFEM's
add_Nitsche_contact_with_rigid_obstacle_brick's full-vector form, Chouly et al.) written out:
  −Θγ σ_n(u)σ_n(v) + f_n (v·N − Θγ σ_n(v)) − Θγ σ_t(u)·σ_t(v) + f_t·(Θγ σ_t(v) − v_t),
  f_n = (1/γ)[u·N − g − γ σ_n(u)]_+,  f_t = proj onto [−μ f_n, μ f_n] of σ_t(u) − (u_t − u_t^n)/(γτ),
with N = −e_y the obstacle's normal, σ_n = N·σN, σ_t = σN − σ_n N, u_t = u − (u·N)N (in 2D the
tangential parts are scalars along e_x and the projection is the clamp x − [x − r]_+ + [−x − r]_+,
whose derivative GetFEM's Newton takes from pos_part's), g = y − y_plane, γ = γ0·h_K with h_K
the cell's diameter (its largest node-to-node distance), on Γ_C's faces with IM_TRIANGLE(5)'s
face rule (3 Gauss points per face, the engine's rule).

Reported per step: the energy ½vᵀMv + ½uᵀKu − Fᵀu, the normal force ∫f_n, the tangential
force ∫f_t (e_x component of the traction on the body, integrated), the slip ∫(u_t − u_t^n),
the frictional work W_f = −Σ ∫((1−γ)f_t^n + γ f_t^{n+1})(u_t^{n+1} − u_t^n) (contract §2.5), the
mean tangential velocity 1ᵀMv_x / 1ᵀM1_x (and, at T, the normal one 1ᵀMv_y / 1ᵀM1_y), the
Γ_C mean of the tangential velocity ∫_ΓC v_x / ∫_ΓC 1 (on Γ_C's face rule, as the forces;
contract §5's `v_t_contact` for Nitsche), the Gauss points of Γ_C in contact (f_n > 0) that
stick (|p_t| ≤ μ f_n, p_t the argument of the projection) and that slip, and the displacement
(u_x, u_y) of every Γ_C node (the vertices and edge midpoints of its faces; their coordinates
once, as `contact_xy`, since GetFEM numbers its dofs otherwise than the file its nodes).
The slip is written out in GWFL, (u_t − u_t^n)/(γτ) in full, so GetFEM 5.4's brick's missing
parenthesis in that expression (contract §2.5) does not enter.

The mesh, K, M, F, Γ_C, γ, the Nitsche model and the Newmark update: tests/getfem/common.py
(shared with tests/getfem/disc_mixed.py).

Usage: disc_nitsche_friction.py MESH OUT.json T dt gap V mu theta gamma0
"""
import json
import sys

import getfem as gf
import numpy as np

import common as c

mesh_path, out_path = sys.argv[1], sys.argv[2]
T, TAU, GAP, VT, MUF, THETA, GAMMA0 = (float(x) for x in sys.argv[3:10])
STEPS = int(round(T / TAU))

disc = c.Disc(mesh_path)
n, K, F = disc.n, disc.K, disc.F
M = disc.mass()
plane = disc.plane(GAP)
beta = c.BETA

A = M + beta * TAU**2 * K
md, rhs_brick = disc.nitsche_model(A, GAMMA0, THETA, [
    ('muf', [MUF]), ('tau', [TAU]), ('btau2', [beta * TAU**2])])
md.add_initialized_fem_data('uo', disc.mfu, disc.U0)
md.add_initialized_fem_data('uoo', disc.mfu, disc.U0)
# The velocity v^{n+1}, for its Γ_C mean (data only: no term uses it).
md.add_initialized_fem_data('vel', disc.mfu, disc.U0)


def forces(u, w):
    """(f_n, p_t, f_t) at the field u with slip reference w (GWFL expressions): f_t is p_t
    clamped to [−μ_f f_n, μ_f f_n]."""
    fn = c.normal_force(u, plane)
    pt = f'({c.st(u)} - ({u}(1) - {w}(1))/(gam*tau))'
    r = f'(muf*{fn})'
    ft = f'({pt} - pos_part({pt} - {r}) + pos_part(-{pt} - {r}))'
    return fn, pt, ft


fn, pt, ft = forces('u', 'uo')
expr = (f'btau2*({c.nitsche_normal_terms(plane)} '
        f'- theta*gam*{c.st("u")}*{c.st("Test_u")} '
        f'+ {ft}*(theta*gam*{c.st("Test_u")} - Test_u(1)))')
md.add_nonlinear_term(disc.mim_c, expr, c.CONTACT_REGION)
# f_t^n: the previous state uo against its own reference uoo.
_, _, ft_old = forces('uo', 'uoo')
# Γ_C's Gauss points, where f_n and p_t are sampled for the stick/slip count.
gauss = gf.MeshImData(disc.mim_c, c.CONTACT_REGION)
# Γ_C's nodes (vertices and edge midpoints) and their dofs (e_x, e_y).
contact_dofs = [sorted(disc.dofs_at(p)) for p in disc.contact_pids]
dx = np.array([d[0] for d in contact_dofs])
dy = np.array([d[1] for d in contact_dofs])
xy = disc.pts[:, disc.contact_pids]

u = np.zeros(n)
v = np.zeros(n)
v[0::2] = VT
a = np.linalg.solve(M, F)
ones_x = np.zeros(n)
ones_x[0::2] = 1.0
mx = ones_x @ M @ ones_x
ones_y = np.zeros(n)
ones_y[1::2] = 1.0
my = ones_y @ M @ ones_y
# |Γ_C| = ∫_ΓC 1 on the face rule, the divisor of the Γ_C mean.
gamma_c = float(gf.asm('generic', disc.mim_c, 0, '1', c.CONTACT_REGION, md))
out = {'energy': [0.5 * v @ M @ v], 'force_n': [0.0], 'force_t': [0.0], 'slip': [0.0],
       'friction_work': [0.0], 'vt': [float(ones_x @ M @ v / mx)], 'vt_contact': [VT],
       'iterations': [],
       'stick_points': [0], 'slip_points': [0],
       'contact_xy': [[float(x), float(y)] for x, y in xy.T],
       'contact_u': [[[0.0, 0.0] for _ in dx]]}
work = 0.0
u_old = np.zeros(n)
for step in range(STEPS):
    p = c.predictor(u, v, a, TAU)
    md.set_variable('uo', u)
    md.set_variable('uoo', u_old)
    # The 'systematic' line search: 'simplest' and 'default' cycle at the sign changes of the
    # 2D slip (100 iterations, residual ~5e-3, from the 8th contact step on this run).
    un, it = c.nitsche_solve(md, rhs_brick, M @ p + beta * TAU**2 * F, u,
                             'max_res', 1e-11, 'max_iter', 100, 'lsearch', 'systematic')
    md.assembly('build_rhs')
    res = float(np.abs(md.rhs()).max())
    if res > 1e-9:
        sys.exit(f'step {step + 1}: GetFEM\'s Newton stopped at residual {res:.3e}')
    out['iterations'].append([it, res])
    asm = lambda e: float(gf.asm('generic', disc.mim_c, 0, e, c.CONTACT_REGION, md))
    # W_f: CN's f̄ = ½(f_t^n + f_t^{n+1}) against u_t^{n+1} − u_t^n (f_t⁰ = 0: no contact at t = 0).
    fbar = f'(0.5*{ft}' + (f' + 0.5*{ft_old})' if step > 0 else ')')
    work -= asm(f'{fbar}*(u(1) - uo(1))')
    out['force_n'].append(asm(fn))
    out['force_t'].append(asm(ft))
    out['slip'].append(asm('u(1) - uo(1)'))
    out['friction_work'].append(work)
    # Stick/slip at the Gauss points in contact (f_n > 0): slip where |p_t| > μ_f f_n.
    gn = np.ravel(md.interpolation(fn, gauss, c.CONTACT_REGION))
    gt = np.ravel(md.interpolation(pt, gauss, c.CONTACT_REGION))
    on = gn > 0.0
    slides = on & (np.abs(gt) > MUF * gn)
    out['stick_points'].append(int(on.sum() - slides.sum()))
    out['slip_points'].append(int(slides.sum()))
    out['contact_u'].append([[float(un[i]), float(un[j])] for i, j in zip(dx, dy)])
    u_old = u
    u, v, a = c.advance(un, p, v, a, TAU)
    out['energy'].append(c.energy(M, K, F, u, v))
    out['vt'].append(float(ones_x @ M @ v / mx))
    md.set_variable('vel', v)
    out['vt_contact'].append(asm('vel(1)') / gamma_c)
out['vn_final'] = float(ones_y @ M @ v / my)
out['body_mass'] = float(mx)
with open(out_path, 'w') as f:
    json.dump(out, f)
