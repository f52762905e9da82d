"""What tests/getfem/blocks.py (GetFEM's nodal brick) and tests/getfem/nitsche_blocks.py
(Nitsche in GWFL) share: the engine's two blocks meshed by GetFEM 5.4 (contract §1.10), each
body's K and M, the mass variants, and the Newmark β = ¼, γ = ½ loop in numpy around a step
the caller solves with GetFEM, observing the series and the displacement field.

The bodies (d = 2, or 3 with "dim": 3): B = [0, W]^{d−1} × [0, H_b] and
A = [0, W]^{d−1} × [H_b + g, H_b + g + H_a], each a GetFEM mesh of its own (two displacement
variables u_a, u_b), Q1 cells (GT_QK(d,1), FEM_QK(d,1)): A W/h
squares across and H_a/h up, B round(mesh_ratio·W/h) across (`mesh_ratio` 1: a matching
interface) and round(H_b/h) up — the engine's lattice (x = kW/n, y = y0 + jH/m). Plane strain
in 2D, each with its own ρ, λ, μ. K and M per body with a 3^d Gauss rule (exact for Q1 on boxes:
the mass's and the stiffness' integrands have degree ≤ 2 per axis); no load. B's base is free or
clamped (the caller holds its dofs). Each body's contact face is a region of its mesh (A's
bottom `RG_A`, B's top `RG_B`).

The vertical axis is the last, e_d; A moves with (V_t, 0, V) and B with V_b e_d.

Newmark: predictor p = u + τv + τ²(½ − β)a; the step's model (the caller's) solves
(M/(βτ²) + K) u = M p/(βτ²) + the contact forces; then a = (u − p)/(βτ²),
v ← v + τ(½a_old + ½a). v⁰ = (V_t, V) on A, (0, V_b) on B, u⁰ = 0, a⁰ = 0 (no load).
Energy E = ½vᵀMv + ½uᵀKu (both bodies), momentum P = Σ (M v)_y over the free e_y dofs, each
body's mass 1ᵀM_i1 (e_y component) and mass_total = Σ_i 1ᵀM_i1 (e_x component, clamped nodes
included: the engine's `mass_total`).
"""
import getfem as gf
import numpy as np

from common import stiffness

BETA = 0.25
RG_A, RG_B, RG_BASE = 1, 2, 3


class Body:
    """One block: its mesh, Q1 space, K, consistent M, its contact face and the dofs kept."""

    def __init__(self, width, cells, y0, height, up, material, face_normal, region,
                 clamp_base):
        rho, lam, mu = material
        self.lam, self.mu = lam, mu
        d = self.dim = len(face_normal)
        across = [np.linspace(0.0, width, cells + 1)] * (d - 1)
        self.m = gf.Mesh('cartesian', *across, np.linspace(y0, y0 + height, up + 1))
        # The cells' diameter (all equal): the engine's h_K (contract §2.3).
        self.diameter = float(np.sqrt((d - 1) * (width / cells)**2 + (height / up)**2))
        self.mf = gf.MeshFem(self.m, d)
        self.mf.set_fem(gf.Fem(f'FEM_QK({d},1)'))
        self.mim = gf.MeshIm(self.m, gf.Integ(f'IM_GAUSS_PARALLELEPIPED({d},5)'))
        self.n = self.mf.nbdof()
        u0 = np.zeros(self.n)
        self.M = rho * gf.asm('generic', self.mim, 2, 'Test_u.Test2_u', -1, 'u', 1, self.mf,
                              u0).full()
        self.K = stiffness(self.mf, self.mim, lam, mu)
        faces = self.m.outer_faces_with_direction(face_normal, 0.01)
        self.m.set_region(region, faces)
        self.region = region
        self.xy = self.mf.basic_dof_nodes()
        up_xy = self.xy[d - 1]
        face_y = y0 if face_normal[-1] < 0 else y0 + height
        self.face_dofs = [k for k in range(self.n) if abs(up_xy[k] - face_y) < 1e-9]
        base = [k for k in range(self.n) if abs(up_xy[k] - y0) < 1e-9]
        self.clamped = sorted(base) if clamp_base else []
        if clamp_base:
            self.m.set_region(RG_BASE, self.m.outer_faces_with_direction(
                [0.0] * (d - 1) + [-1.0], 0.01))
        # The e_d dofs whose (M v) the momentum sums: the engine's free ones (a clamped row's
        # reaction is not momentum of the body).
        self.kept_y = [k for k in range(d - 1, self.n, d) if k not in set(self.clamped)]

    def nodes(self):
        """The coordinates of each node, with the indices of its dofs (by component)."""
        pts = {}
        for k in range(self.n):
            key = tuple(round(self.xy[c, k], 12) for c in range(self.dim))
            pts.setdefault(key, []).append(k)
        return [(x, sorted(ds)) for x, ds in sorted(pts.items())]


class Blocks:
    """The setting of one script call: the parameters (the usage of blocks.py), A and B."""

    def __init__(self, params):
        gf.util_trace_level(0)
        self.params = params
        W, H_a, H_b, h = (params[k] for k in ('width', 'height', 'height_b', 'h'))
        self.gap = params['gap']
        self.tau = params['dt']
        self.steps = int(round(params['T'] / self.tau))
        across = int(round(W / h))
        across_b = max(1, int(round(params.get('mesh_ratio', 1.0) * across)))
        up = lambda height: max(1, int(round(height / h)))
        d = self.dim = params.get('dim', 2)
        e = [0.0] * (d - 1)
        self.A = Body(W, across, H_b + self.gap, H_a, up(H_a),
                      (params['density'], params['lame_lambda'], params['lame_mu']),
                      e + [-1.0], RG_A, False)
        self.B = Body(W, across_b, 0.0, H_b, up(H_b),
                      (params['density_b'], params['lame_lambda_b'], params['lame_mu_b']),
                      e + [1.0], RG_B, params['far_end'] == 'clamped')
        self.bodies = (self.A, self.B)

    def masses(self, name):
        """Each body's M for the variant (contract §2.2, mass_side = both)."""
        Ms = []
        for body in self.bodies:
            M = body.M.copy()
            if name == 'zero-contact':
                M[body.face_dofs, :] = 0.0
                M[:, body.face_dofs] = 0.0
            elif name != 'consistent':
                raise ValueError(f'mass {name}: not in this script')
            Ms.append(M)
        return Ms

    def model(self, Ms):
        """GetFEM's model of one step without contact: u_a, u_b with the explicit
        (M/(βτ²) + K) of each body, an explicit right-hand side per body (its bricks
        returned); B's clamped dofs held at 0 by a simplified Dirichlet condition (the dofs
        leave the system, as the engine's clamped dofs do)."""
        md = gf.Model('real')
        md.add_fem_variable('ua', self.A.mf)
        md.add_fem_variable('ub', self.B.mf)
        rhs = []
        for name, body, M in (('ua', self.A, Ms[0]), ('ub', self.B, Ms[1])):
            mat = M / (BETA * self.tau**2) + body.K
            sp = gf.Spmat('empty', body.n, body.n)
            sp.add(np.arange(body.n), np.arange(body.n), mat)
            md.add_explicit_matrix(name, name, sp)
            rhs.append(md.add_explicit_rhs(name, np.zeros(body.n)))
        if self.B.clamped:
            md.add_initialized_data('zero', [0.0] * self.dim)
            md.add_Dirichlet_condition_with_simplification('ub', RG_BASE, 'zero')
        return md, rhs

    def nodes(self):
        """Every node's body and coordinates, A's then B's (the order of the fields)."""
        keys = ('x', 'y', 'z')[:self.dim]
        return [{'body': k, **dict(zip(keys, x))}
                for k, b in enumerate(self.bodies) for (x, _) in b.nodes()]

    def run(self, Ms, md, rhs, solve):
        """The Newmark loop on the step model (md, rhs): `solve(md)` solves one step from the
        variables set and returns (the total contact force, GetFEM's iteration count); the
        series, the fields and the masses."""
        bodies, tau, p_ = self.bodies, self.tau, self.params
        u = [np.zeros(b.n) for b in bodies]
        v = [np.zeros(b.n) for b in bodies]
        d = self.dim
        for vb, V in zip(v, (p_['velocity'], p_['velocity_b'])):
            vb[d - 1::d] = V
        v[0][0::d] = p_['velocity_tangential']
        v[1][self.B.clamped] = 0.0
        a = [np.zeros(b.n) for b in bodies]
        series = {k: [] for k in ('force', 'energy', 'kinetic', 'elastic', 'momentum',
                                  'iterations')}
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
            fields.append([[float(ub[k]) for k in ds]
                           for ub, b in zip(u, bodies) for (_, ds) in b.nodes()])

        observe(0.0, 0)
        for _ in range(self.steps):
            p = [ub + tau * vb + tau**2 * (0.5 - BETA) * ab for ub, vb, ab in zip(u, v, a)]
            for brick, M, pb in zip(rhs, Ms, p):
                md.set_private_rhs(brick, M @ pb / (BETA * tau**2))
            md.set_variable('ua', u[0])
            md.set_variable('ub', u[1])
            force, iterations = solve(md)
            un = [np.asarray(md.variable('ua')).copy(), np.asarray(md.variable('ub')).copy()]
            an = [(x - pb) / (BETA * tau**2) for x, pb in zip(un, p)]
            v = [vb + tau * (0.5 * ab + 0.5 * anb) for vb, ab, anb in zip(v, a, an)]
            u, a = un, an
            observe(force, iterations)
        return {**series, 'u': fields,
                'mass_total': float(sum(M[0::d, 0::d].sum() for M in Ms)),
                'body_mass': [float(M[d - 1::d, d - 1::d].sum()) for M in Ms]}
