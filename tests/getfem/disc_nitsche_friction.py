#!/usr/bin/python3
"""The 003 disc on a Gmsh P2 mesh thrown obliquely onto a rigid plane with Coulomb friction,
Nitsche's contact in GetFEM 5.4's weak form language (Debian's python3-getfem): an
implementation of SPEC §2.5's frictional Nitsche that shares no code with the engine, for
tests/friction_nitsche.rs (issue 33).

The bulk as tests/getfem/disc_mixed.py: the isoparametric P2 mesh of the file, P2 vector FEM,
IM_TRIANGLE(13) (exact for the curved cells' mass), K (λ = μ = 20, plane strain), the consistent
M, the body force F = ∫ρ f·φ with f = −0.1 e_y. Initial state u⁰ = 0, v⁰ = V e_x on every node,
a⁰ from M a⁰ = F. Crank–Nicolson (Newmark β = ¼, γ = ½): each step solves
  (M + τ²/4 K) u + τ²/4 R_c(u) = M(u^n + τv^n + τ²/4 a^n) + τ²/4 F
by GetFEM's Newton method, with R_c SPEC §2.5's contact residual (GetFEM's
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
the frictional work W_f = −Σ ∫((1−γ)f_t^n + γ f_t^{n+1})(u_t^{n+1} − u_t^n) (SPEC §2.5) and the
mean tangential velocity 1ᵀMv_x / 1ᵀM1_x.

Usage: disc_nitsche_friction.py MESH OUT.json T dt gap V mu theta gamma0
"""
import json
import sys

import getfem as gf
import numpy as np

RHO, LAM, MU, GRAV = 1.0, 20.0, 20.0, 0.1
gf.util_trace_level(0)
mesh_path, out_path = sys.argv[1], sys.argv[2]
T, TAU, GAP, VT, MUF, THETA, GAMMA0 = (float(x) for x in sys.argv[3:10])
STEPS = int(round(T / TAU))

m = gf.Mesh('import', 'gmsh', mesh_path)
mfu = gf.MeshFem(m, 2)
mfu.set_classical_fem(2)
mim = gf.MeshIm(m, gf.Integ('IM_TRIANGLE(13)'))
n = mfu.nbdof()
pts = m.pts()
ymin, ymax = pts[1].min(), pts[1].max()
ycentre = 0.5 * (ymin + ymax)
outer = m.outer_faces()
U0 = np.zeros(n)

md0 = gf.Model('real')
md0.add_fem_variable('u', mfu)
md0.add_initialized_data('lambda', [LAM])
md0.add_initialized_data('mu', [MU])
md0.add_isotropic_linearized_elasticity_brick(mim, 'u', 'lambda', 'mu')
md0.assembly('build_matrix')
K = md0.tangent_matrix().full()
K = 0.5 * (K + K.T)
M = gf.asm('generic', mim, 2, f'{RHO}*(Test_u.Test2_u)', -1, 'u', 1, mfu, U0).full()
F = np.asarray(gf.asm('generic', mim, 1, f'{RHO}*[0,{-GRAV}].Test_u', -1, 'u', 1, mfu, U0)).ravel()

CONTACT_REGION = 101
faces = [outer[:, k] for k in range(outer.shape[1])
         if all(pts[1][p] <= ycentre + 1e-9 for p in m.pid_in_faces(outer[:, k:k + 1]))]
m.set_region(CONTACT_REGION, np.array(faces).T)
mim_c = gf.MeshIm(m, gf.Integ('IM_TRIANGLE(5)'))

mf0 = gf.MeshFem(m, 1)
mf0.set_classical_discontinuous_fem(0)
gam = np.zeros(mf0.nbdof())
for cv in range(m.nbcvs()):
    x = pts[:, m.pid_from_cvid(cv)[0]]
    hk = max(np.hypot(*(x[:, a] - x[:, b])) for a in range(x.shape[1]) for b in range(a))
    gam[mf0.basic_dof_from_cv(cv)[0]] = GAMMA0 * hk
plane = ymin - GAP
beta = 0.25

md = gf.Model('real')
md.add_fem_variable('u', mfu)
md.add_initialized_fem_data('gam', mf0, gam)
md.add_initialized_fem_data('uo', mfu, U0)
md.add_initialized_fem_data('uoo', mfu, U0)
md.add_initialized_data('theta', [THETA])
md.add_initialized_data('lam', [LAM])
md.add_initialized_data('mu', [MU])
md.add_initialized_data('muf', [MUF])
md.add_initialized_data('tau', [TAU])
md.add_initialized_data('btau2', [beta * TAU**2])
A = M + beta * TAU**2 * K
A_sp = gf.Spmat('empty', n, n)
A_sp.add(np.arange(n), np.arange(n), A)
md.add_explicit_matrix('u', 'u', A_sp)
rhs_brick = md.add_explicit_rhs('u', np.zeros(n))


def sig(w):
    return f'(lam*Trace(Grad_{w})*Id(2) + mu*(Grad_{w} + Grad_{w}\'))'


def sn(w):
    return f'([0,-1].({sig(w)}*[0,-1]))'


def st(w):
    # e_x component of σ(w)N: the tangential traction (a scalar in 2D).
    return f'([1,0].({sig(w)}*[0,-1]))'


def forces(u, w):
    """(f_n, f_t) at the field u with slip reference w (GWFL expressions)."""
    pn = f'({u}.[0,-1] - gam*{sn(u)} - (X(2) - ({plane!r})))'
    fn = f'((1/gam)*pos_part({pn}))'
    pt = f'({st(u)} - ({u}(1) - {w}(1))/(gam*tau))'
    r = f'(muf*{fn})'
    ft = f'({pt} - pos_part({pt} - {r}) + pos_part(-{pt} - {r}))'
    return fn, ft


fn, ft = forces('u', 'uo')
expr = (f'btau2*(-theta*gam*{sn("u")}*{sn("Test_u")} '
        f'+ {fn}*(Test_u.[0,-1] - theta*gam*{sn("Test_u")}) '
        f'- theta*gam*{st("u")}*{st("Test_u")} '
        f'+ {ft}*(theta*gam*{st("Test_u")} - Test_u(1)))')
md.add_nonlinear_term(mim_c, expr, CONTACT_REGION)
# f_t^n: the previous state uo against its own reference uoo.
_, ft_old = forces('uo', 'uoo')

u = np.zeros(n)
v = np.zeros(n)
v[0::2] = VT
a = np.linalg.solve(M, F)
ones_x = np.zeros(n)
ones_x[0::2] = 1.0
mx = ones_x @ M @ ones_x
out = {'energy': [0.5 * v @ M @ v], 'force_n': [0.0], 'force_t': [0.0], 'slip': [0.0],
       'friction_work': [0.0], 'vt': [float(ones_x @ M @ v / mx)], 'iterations': []}
work = 0.0
u_old = np.zeros(n)
for step in range(STEPS):
    p = u + TAU * v + TAU**2 * (0.5 - beta) * a
    md.set_private_rhs(rhs_brick, M @ p + beta * TAU**2 * F)
    md.set_variable('uo', u)
    md.set_variable('uoo', u_old)
    md.set_variable('u', u)
    # The 'systematic' line search: 'simplest' and 'default' cycle at the sign changes of the
    # 2D slip (100 iterations, residual ~5e-3, from the 8th contact step on this run).
    it = md.solve('max_res', 1e-11, 'max_iter', 100, 'lsearch', 'systematic')
    md.assembly('build_rhs')
    res = float(np.abs(md.rhs()).max())
    if res > 1e-9:
        sys.exit(f'step {step + 1}: GetFEM\'s Newton stopped at residual {res:.3e}')
    out['iterations'].append([int(np.ravel(it)[0]), res])
    un = np.asarray(md.variable('u')).copy()
    # W_f: CN's f̄ = ½(f_t^n + f_t^{n+1}) against u_t^{n+1} − u_t^n (f_t⁰ = 0: no contact at t = 0).
    fbar = f'(0.5*{ft}' + (f' + 0.5*{ft_old})' if step > 0 else ')')
    work -= float(gf.asm('generic', mim_c, 0, f'{fbar}*(u(1) - uo(1))', CONTACT_REGION, md))
    out['force_n'].append(float(gf.asm('generic', mim_c, 0, fn, CONTACT_REGION, md)))
    out['force_t'].append(float(gf.asm('generic', mim_c, 0, ft, CONTACT_REGION, md)))
    out['slip'].append(float(gf.asm('generic', mim_c, 0, 'u(1) - uo(1)', CONTACT_REGION, md)))
    out['friction_work'].append(work)
    an = (un - p) / (beta * TAU**2)
    v = v + TAU * (0.5 * a + 0.5 * an)
    u_old, u, a = u, un, an
    out['energy'].append(float(0.5 * v @ M @ v + 0.5 * u @ K @ u - F @ u))
    out['vt'].append(float(ones_x @ M @ v / mx))
out['body_mass'] = float(mx)
with open(out_path, 'w') as f:
    json.dump(out, f)
