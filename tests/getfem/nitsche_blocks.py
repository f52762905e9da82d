#!/usr/bin/python3
"""Two elastic blocks with contract §2.6's unbiased (or one-sided) Nitsche between them, written
in GetFEM 5.4's weak form language (GWFL) on its interpolate transformations — an implementation
of the engine's `nitsche` with `interface_quadrature = "element"` that shares no code with it,
for tests/getfem_nonmatching.rs (issue 45, done-when 4).

The blocks, K, M and the Newmark β = ¼, γ = ½ loop: tests/getfem/two_blocks.py. The contact
terms, on Γ^i (i = a: A's bottom, n^a = −e_y; i = b: B's top, n^b = +e_y), j the other body:

  − w_i ∫_Γi Θ γ^i σ_n^i(u^i) σ_n^i(v^i)
  + w_i ∫_Γi (1/γ^i) [P^i_γ(u) − g]_+ (δ^i(v) − Θ γ^i σ_n^i(v^i)),
  P^i_γ(u) = δ^i(u) − γ^i σ_n^i(u^i),  δ^i(u) = (u^i − Interpolate(u^j, Π^i))·n^i,

σ^i of body i's own λ_i, μ_i (plane strain), σ_n^i = n^i·σ^i n^i, γ^i = γ0·h_K with h_K the
diameter of a Γ^i cell (√(h_x² + h_y²) of its rectangles), g the gap (Π^i(x) − x)·n^i — the
blocks' faces are flat and parallel — and w_a = w_b = ½ (`unbiased`) or w_a = 1, w_b = 0 (`a`).
Π^i(x), the other body's point, is taken in the reference configuration (the engine's Π,
contract §2.6: small deformations), two ways (the variant's suffix):
- by default GetFEM's `add_interpolate_transformation_from_expression` with Π^i(x) = x − g n^i
  (the blocks' faces are flat and parallel: the exact projection), nudged 1e-13 into the other
  body — a point exactly on the other mesh's boundary is "No valid element for the
  transformation" in 5.4;
- `:projection`: GetFEM's projection transformation (`add_projection_transformation`, Γ^i the
  slave boundary, Γ^j the master, their displacements zero data). Its Newton stalls at a
  residual of ~6e-8 on the first contact step in 5.4 (line-search cycling, measured), so it
  is solved to `PROJECTION_TOL`.
The terms are integrated with Γ^i's own face rule — IM_GAUSS_PARALLELEPIPED(2,5)'s faces, 3
Gauss points per face, the engine's `element` rule. Each step's equations,
(M/(βτ²) + K) u + R_c(u) = M p/(βτ²), are solved by GetFEM's Newton (the generalised
derivative of pos_part: a semismooth Newton) to `TOL`.

Reported besides two_blocks' series: the total contact force f = Σ_i w_i ∫_Γi (1/γ^i)
[P^i_γ(u) − g]_+ (the engine's −σ_C) at every step.

Usage: nitsche_blocks.py OUT.json PARAMS_JSON VARIANTS
  PARAMS_JSON: blocks.py's, with "gamma0" and "mass" (one of two_blocks' masses).
  VARIANTS: comma-separated SIDES:THETA[:projection] (SIDES `unbiased` or `a`, THETA a number).
"""
import json
import sys

import getfem as gf
import numpy as np

from two_blocks import Blocks

# GetFEM's Newton's stop `max_res` (blocks.py's note on its criterion): the step's residual
# starts at ~460 (M p/(βτ²), τ = 0.02) and, once the semismooth Newton's active set is right,
# ends on a linear solve at 2e-13 to 6e-13 (measured with 'noisy', 1–4 iterations) — round-off.
TOL = 1e-10
# The projection transformation's Newton stalls at a residual of ~6e-8 (module header): the
# tightest tolerance it meets at every step.
PROJECTION_TOL = 1e-6
MAX_ITER = 100

out_path, params, variants = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3].split(',')
S = Blocks(params)
A, B = S.A, S.B


def side(body, normal, trans, weight):
    """(the residual's GWFL on Γ^i, the force's) for body i = `body` ('a' or 'b')."""
    other = 'b' if body == 'a' else 'a'
    n = f'[0,{normal}]'
    u, ut = f'u{body}', f'Test_u{body}'

    def sn(w):
        sig = (f'(lam{body}*Trace(Grad_{w})*Id(2) + mu{body}*(Grad_{w} + Grad_{w}\'))')
        return f'({n}.({sig}*{n}))'

    def delta(w, wj):
        return f'(({w} - Interpolate({wj}, {trans})).{n})'

    g = f'gam{body}'
    pos = f'pos_part({delta(u, "u" + other)} - {g}*{sn(u)} - gap)'
    residual = (f'{weight}*(-theta*{g}*{sn(u)}*{sn(ut)} + (1/{g})*{pos}*'
                f'({delta(ut, "Test_u" + other)} - theta*{g}*{sn(ut)}))')
    return residual, f'{weight}*(1/{g})*{pos}'


def model(Ms, sides, theta, gamma0, projection):
    md, rhs = S.model(Ms)
    for name, b in (('a', A), ('b', B)):
        # The projection transformation's displacements: zero (the reference configuration).
        md.add_initialized_fem_data(f'z{name}', b.mf, np.zeros(b.n))
        md.add_initialized_data(f'lam{name}', [b.lam])
        md.add_initialized_data(f'mu{name}', [b.mu])
        md.add_initialized_data(f'gam{name}', [gamma0 * b.diameter])
    md.add_initialized_data('theta', [theta])
    md.add_initialized_data('gap', [S.gap])
    weights = {'unbiased': (0.5, 0.5), 'a': (1.0, 0.0)}[sides]
    forces = []
    for (name, body, other, other_name, normal), w in zip(
            (('a', A, B, 'b', -1), ('b', B, A, 'a', 1)), weights):
        if w == 0.0:
            continue
        trans = f'to{other_name}'
        if projection:
            md.add_projection_transformation(trans, 10 * S.gap)
            md.add_slave_contact_boundary_to_projection_transformation(
                trans, body.m, f'z{name}', body.region)
            md.add_master_contact_boundary_to_projection_transformation(
                trans, other.m, f'z{other_name}', other.region)
        else:
            # Π^i(x) = x − g n^i on the other face, nudged 1e-13 inside the other body (module
            # header).
            md.add_interpolate_transformation_from_expression(
                trans, body.m, other.m, f'X + [0, {normal}*(gap + 1e-13)]')
        residual, force = side(name, normal, trans, w)
        md.add_nonlinear_term(body.mim, residual, body.region)
        forces.append((body, force))
    return md, rhs, forces


def run(variant):
    sides, theta, *how = variant.split(':')
    projection = how == ['projection']
    tol = PROJECTION_TOL if projection else TOL
    Ms = S.masses(params['mass'])
    md, rhs, forces = model(Ms, sides, float(theta), params['gamma0'], projection)

    def solve(md):
        it = md.solve('max_res', tol, 'max_iter', MAX_ITER)
        iterations = int(np.ravel(it)[0])
        if iterations >= MAX_ITER:
            raise RuntimeError(f'{variant}: GetFEM\'s Newton did not converge')
        force = sum(float(gf.asm('generic', b.mim, 0, f, b.region, md)) for b, f in forces)
        return force, iterations

    return S.run(Ms, md, rhs, solve)


out = {'nodes': S.nodes(), 'variants': {}}
for name in variants:
    out['variants'][name] = run(name)
with open(out_path, 'w') as f:
    json.dump(out, f)
