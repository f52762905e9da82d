"""What tests/getfem/disc_mixed.py and tests/getfem/disc_nitsche_friction.py share: the 003 disc
on a Gmsh P2 mesh as GetFEM 5.4 (Debian's python3-getfem) discretises it, Crank–Nicolson's
Newmark update, and the Nitsche terms in GetFEM's weak form language (GWFL).

The bulk: the isoparametric P2 mesh of the file (curved boundary triangles, GT_PK(2,2)), the P2
vector FEM, a degree-13 triangle rule (exact for the curved cells' mass, whose integrand has
degree 6); K isotropic linearized elasticity (plane strain, λ = μ = 20); M = ρ ∫ w φ_a·φ_b
(w = 1 unless the caller gives element weights); F = ∫ρ f·φ, f = −0.1 e_y (contract §1.3).
Γ_C: the boundary faces whose nodes all lie at y ≤ y_centre (the lower half circle, the
engine's `contact` group), integrated by IM_TRIANGLE(5)'s face rule — 3 Gauss points per face,
the engine's Γ_C rule. The rigid plane y = y_min − gap, its normal N = −e_y; Nitsche's
γ = γ0·h_K with h_K the cell's diameter (its largest node-to-node distance).

Crank–Nicolson as Newmark β = ¼, γ = ½: predictor p = u + τv + τ²(½ − β)a, the step solves
(M + βτ²K) u^{n+1} (+ βτ² R_c) = M p + βτ² F, then a^{n+1} = (u^{n+1} − p)/(βτ²) and
v^{n+1} = v + τ(½a + ½a^{n+1}). Energy ½vᵀMv + ½uᵀKu − Fᵀu.

`stiffness` is shared with tests/getfem/blocks.py. Imported by the scripts beside it (Python
puts a script's folder first on sys.path).
"""
import getfem as gf
import numpy as np

RHO, LAM, MU, GRAV = 1.0, 20.0, 20.0, 0.1
BETA = 0.25
CONTACT_REGION = 101


def stiffness(mf, mim, lam, mu):
    """K of isotropic linearized elasticity (plane strain in 2D) on the vector space mf with the
    rule mim, GetFEM's brick, symmetrised (dense)."""
    md = gf.Model('real')
    md.add_fem_variable('u', mf)
    md.add_initialized_data('lambda', [lam])
    md.add_initialized_data('mu', [mu])
    md.add_isotropic_linearized_elasticity_brick(mim, 'u', 'lambda', 'mu')
    md.assembly('build_matrix')
    K = md.tangent_matrix().full()
    return 0.5 * (K + K.T)


class Disc:
    """The mesh, the P2 space, K, F, Γ_C (faces, points, region) and the P0 space of γ."""

    def __init__(self, mesh_path):
        gf.util_trace_level(0)
        m = gf.Mesh('import', 'gmsh', mesh_path)
        self.m = m
        self.mfu = gf.MeshFem(m, 2)
        self.mfu.set_classical_fem(2)
        self.mim = gf.MeshIm(m, gf.Integ('IM_TRIANGLE(13)'))
        self.n = self.mfu.nbdof()
        self.pts = m.pts()
        self.ymin, self.ymax = self.pts[1].min(), self.pts[1].max()
        ycentre = 0.5 * (self.ymin + self.ymax)
        self.U0 = np.zeros(self.n)

        self.K = stiffness(self.mfu, self.mim, LAM, MU)
        F = gf.asm('generic', self.mim, 1, f'{RHO}*[0,{-GRAV}].Test_u', -1, 'u', 1, self.mfu,
                   self.U0)
        self.F = np.asarray(F).ravel()

        outer = m.outer_faces()
        below = [k for k in range(outer.shape[1])
                 if all(self.pts[1][p] <= ycentre + 1e-9
                        for p in m.pid_in_faces(outer[:, k:k + 1]))]
        self.contact_pids = sorted({int(p) for k in below
                                    for p in m.pid_in_faces(outer[:, k:k + 1])})
        m.set_region(CONTACT_REGION, np.array([outer[:, k] for k in below]).T)
        self.mim_c = gf.MeshIm(m, gf.Integ('IM_TRIANGLE(5)'))
        self.mf0 = gf.MeshFem(m, 1)
        self.mf0.set_classical_discontinuous_fem(0)
        self.dof_xy = self.mfu.basic_dof_nodes()

    def dofs_at(self, p):
        """The vector dofs at point p, increasing: component c is the (c+1)-th."""
        x = self.pts[:, p]
        return [d for d in range(self.n)
                if abs(self.dof_xy[0, d] - x[0]) < 1e-9 and abs(self.dof_xy[1, d] - x[1]) < 1e-9]

    def p0(self, weights):
        """The P0 field of one value per convex."""
        w = np.zeros(self.mf0.nbdof())
        for cv in range(self.m.nbcvs()):
            w[self.mf0.basic_dof_from_cv(cv)[0]] = weights[cv]
        return w

    def mass(self, weights=None):
        """ρ ∫ w φ_a·φ_b, w the element weights `weights` (one per convex; None: w = 1)."""
        if weights is None:
            expr, args = f'{RHO}*(Test_u.Test2_u)', ()
        else:
            expr, args = f'{RHO}*w*(Test_u.Test2_u)', ('w', 0, self.mf0, self.p0(weights))
        return gf.asm('generic', self.mim, 2, expr, -1, 'u', 1, self.mfu, self.U0, *args).full()

    def gamma(self, gamma0):
        """γ = γ0·h_K per cell (P0 field), h_K the largest distance between two of its nodes."""
        hk = []
        for cv in range(self.m.nbcvs()):
            x = self.pts[:, self.m.pid_from_cvid(cv)[0]]
            hk.append(max(np.hypot(*(x[:, a] - x[:, b]))
                          for a in range(x.shape[1]) for b in range(a)))
        return self.p0([gamma0 * h for h in hk])

    def nitsche_model(self, A, gamma0, theta, data=()):
        """GetFEM's model of a Nitsche step: the unknown u with the explicit matrix A (the
        step's M + βτ²K), an explicit right-hand side (returned: its brick), the data γ, Θ, λ,
        μ, βτ² and `data` (name, value) pairs; the caller adds its contact term."""
        md = gf.Model('real')
        md.add_fem_variable('u', self.mfu)
        md.add_initialized_fem_data('gam', self.mf0, self.gamma(gamma0))
        md.add_initialized_data('theta', [theta])
        md.add_initialized_data('lam', [LAM])
        md.add_initialized_data('mu', [MU])
        for name, value in data:
            md.add_initialized_data(name, value)
        A_sp = gf.Spmat('empty', self.n, self.n)
        A_sp.add(np.arange(self.n), np.arange(self.n), A)
        md.add_explicit_matrix('u', 'u', A_sp)
        return md, md.add_explicit_rhs('u', np.zeros(self.n))

    def plane(self, gap):
        return self.ymin - gap


# GWFL: σ(w), σ_n(w) = N·σ(w)N and the e_x component of σ(w)N (the tangential traction, a
# scalar in 2D), N = −e_y.
def sig(w):
    return f'(lam*Trace(Grad_{w})*Id(2) + mu*(Grad_{w} + Grad_{w}\'))'


def sn(w):
    return f'([0,-1].({sig(w)}*[0,-1]))'


def st(w):
    return f'([1,0].({sig(w)}*[0,-1]))'


def normal_force(u, plane):
    """f_n = (1/γ)[u·N − g − γσ_n(u)]_+, g = y − y_plane, at the field u (GWFL)."""
    pn = f'({u}.[0,-1] - gam*{sn(u)} - (X(2) - ({plane!r})))'
    return f'((1/gam)*pos_part({pn}))'


def nitsche_normal_terms(plane):
    """contract §2.3's normal Nitsche residual, −Θγσ_n(u)σ_n(v) + f_n(v·N − Θγσ_n(v)) (GWFL)."""
    return (f'-theta*gam*{sn("u")}*{sn("Test_u")} '
            f'+ {normal_force("u", plane)}*(Test_u.[0,-1] - theta*gam*{sn("Test_u")})')


def predictor(u, v, a, tau):
    return u + tau * v + tau**2 * (0.5 - BETA) * a


def advance(un, p, v, a, tau):
    """Newmark's update: (u, v, a) at the new step from its solution un and predictor p."""
    an = (un - p) / (BETA * tau**2)
    return un, v + tau * (0.5 * a + 0.5 * an), an


def energy(M, K, F, u, v):
    return float(0.5 * v @ M @ v + 0.5 * u @ K @ u - F @ u)


def nitsche_solve(md, rhs_brick, rhs, u, *options):
    """One step of a Nitsche model: GetFEM's Newton from u with `options`; the new u and the
    iteration count."""
    md.set_private_rhs(rhs_brick, rhs)
    md.set_variable('u', u)
    it = md.solve(*options)
    return np.asarray(md.variable('u')).copy(), int(np.ravel(it)[0])
