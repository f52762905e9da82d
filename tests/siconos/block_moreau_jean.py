"""Siconos 4.4's Moreau–Jean (MoreauJeanOSI, θ = ½, Newton's impact law e = 0 with Coulomb
friction: NewtonImpactFrictionNSL, the 2D frictional contact problem solved by Lemke) on the
sliding block of contract §1.8 (tests/friction_campaign.rs): the 1 × 0.5 rectangle as 8 × 4 Q1
quadrilaterals (the mesh of sweeps/meshes/block2d.msh, built here node by node), plane strain
with λ = μ = 10, ρ = 1, the consistent mass, gravity 0.1 along −e_2, resting on the plane y = 0
(gap 0) and thrown at V along e_1. The engine's E + W_f: E = ½vᵀMv + ½uᵀKu − Fᵀu and
W_f^{n+1} = W_f^n − f_t^{n+1}·(u_t^{n+1} − u_t^n) with f_t = p_t/τ at the Γ_C nodes.

The optional GAP lifts the block by GAP above the plane at rest (it lands, then rests): Siconos'
q starts at GAP·e_2 where the engine's u starts at 0, so its potential −Fᵀq is the engine's plus
the constant −Fᵀq⁰, written as `gap_shift` (the engine's E + W_f = Siconos' − gap_shift).

Usage: python3 block_moreau_jean.py MU V DT T OUT.json [GAP] — writes
{"t": [...], "e_plus_wf": [...], "gap_shift": ...}.
"""
import json
import sys

import numpy as np
import siconos.kernel as sk
import siconos.numerics as sn

mu_f, V, dt, T, out = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
gap = float(sys.argv[6]) if len(sys.argv) > 6 else 0.0
NX, NY, LX, LY = 8, 4, 1.0, 0.5
lam, mu, rho, g = 10.0, 10.0, 1.0, 0.1

nodes = [(i * LX / NX, j * LY / NY) for j in range(NY + 1) for i in range(NX + 1)]
nn = len(nodes)
ndof = 2 * nn
M = np.zeros((ndof, ndof))
K = np.zeros((ndof, ndof))
F = np.zeros(ndof)
D = np.array([[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, mu]])
gp = [-1 / np.sqrt(3), 1 / np.sqrt(3)]
hx, hy = LX / NX, LY / NY
for j in range(NY):
    for i in range(NX):
        ids = [j * (NX + 1) + i, j * (NX + 1) + i + 1, (j + 1) * (NX + 1) + i + 1, (j + 1) * (NX + 1) + i]
        dofs = [d for a in ids for d in (2 * a, 2 * a + 1)]
        me, ke, fe = np.zeros((8, 8)), np.zeros((8, 8)), np.zeros(8)
        for xi in gp:
            for eta in gp:
                s = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
                N = np.array([(1 + a * xi) * (1 + b * eta) / 4 for a, b in s])
                dN = np.array([[a * (1 + b * eta) / 4 * 2 / hx, b * (1 + a * xi) / 4 * 2 / hy] for a, b in s])
                w = hx * hy / 4
                Nm = np.zeros((2, 8))
                B = np.zeros((3, 8))
                for a in range(4):
                    Nm[0, 2 * a] = Nm[1, 2 * a + 1] = N[a]
                    B[0, 2 * a] = dN[a, 0]
                    B[1, 2 * a + 1] = dN[a, 1]
                    B[2, 2 * a] = dN[a, 1]
                    B[2, 2 * a + 1] = dN[a, 0]
                me += rho * w * Nm.T @ Nm
                ke += w * B.T @ D @ B
                fe += -rho * g * w * Nm[1]
        M[np.ix_(dofs, dofs)] += me
        K[np.ix_(dofs, dofs)] += ke
        F[dofs] += fe

q0 = np.zeros(ndof)
q0[1::2] = gap
v0 = np.zeros(ndof)
v0[0::2] = V
block = sk.LagrangianLinearTIDS(q0, v0, M, K, np.zeros((ndof, ndof)))
block.setFExtPtr(F)
model = sk.NonSmoothDynamicalSystem(0.0, T)
model.insertDynamicalSystem(block)
contact = list(range(NX + 1))  # the bottom row y = 0
for a in contact:
    H = np.zeros((2, ndof))
    H[0, 2 * a + 1] = 1.0  # normal e_2: the gap q_2 = GAP + u_2
    H[1, 2 * a] = 1.0  # tangential e_1
    rel = sk.LagrangianLinearTIR(H)
    nsl = sk.NewtonImpactFrictionNSL(0.0, 0.0, mu_f, 2)
    model.link(sk.Interaction(nsl, rel), block)

td = sk.TimeDiscretisation(0.0, dt)
osi = sk.MoreauJeanOSI(0.5)
lcp = sk.FrictionContact(2, sn.SICONOS_FRICTION_2D_LEMKE)
lcp.numericsSolverOptions().dparam[sn.SICONOS_DPARAM_TOL] = 1e-16
sim = sk.TimeStepping(model, td, osi, lcp)


def energy(q, v):
    return 0.5 * v @ M @ v + 0.5 * q @ K @ q - F @ q


ts, es = [0.0], [energy(np.array(block.q()), np.array(block.velocity()))]
wf = 0.0
q_prev = np.array(block.q())
while sim.hasNextEvent():
    sim.computeOneStep()
    q = np.array(block.q())
    v = np.array(block.velocity())
    # The contact impulses p = Hᵀλ on the body (Siconos' p(1)); tangential at the Γ_C dofs.
    p = np.array(block.p(1))
    for a in contact:
        wf -= (p[2 * a] / dt) * (q[2 * a] - q_prev[2 * a])
    q_prev = q
    ts.append(sim.nextTime())
    es.append(energy(q, v) + wf)
    sim.nextStep()

with open(out, "w") as f:
    json.dump({"t": ts, "e_plus_wf": es, "gap_shift": float(-F @ q0)}, f)
