//! The interface geometry and the mortar matrices on non-matching interfaces (issue 45,
//! done-when 3; contract §2.6): the partition of unity of D and M, D and M against an
//! independent adaptive quadrature, the dual basis's biorthogonality, the bins against a
//! brute-force projection, and the refusals.
//!
//! The independent quadrature knows nothing of the segmentation: on each face of Γ^a it
//! integrates in the face's reference coordinates, one line η ↦ … at a time (inner) and over
//! the lines' positions ξ (outer), Π located at every point by trying every face of Γ^b. An
//! inner interval whose two ends project into the same face of Γ^b lies wholly in that face's
//! preimage (a convex set, affine faces), where the integrand is a polynomial of degree ≤ 4:
//! 4-point Gauss is exact there. Otherwise the interval is bisected down to 1e-7 (of the face's
//! parameter) and the last bracket taken by its midpoint: an error ≤ (jump of the integrand's
//! slope)·δ² ~ 1e-14 per kink. The outer integral is a polynomial of degree ≤ 5 in ξ between
//! the ξ where the sequence of faces met along the line changes; intervals with the same
//! sequence at both ends and the middle take 4-point Gauss, the others are bisected likewise.

use contact_sweep::space::fe::interface::{
    Basis, FaceKind, InterfaceError, Mortar, Projector, Surface, basis_coefficients,
    face_integrals, mortar_matrices, project_brute, segment,
};

/// A deterministic pseudo-random number in [−1, 1) (a 64-bit LCG).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A 2D side on the curve x ↦ (x, y(x)), x from x0 to x1 in n segments, interior nodes moved
/// by up to `jitter`·h along x; `up` orders the nodes so the normal is +y (else −y).
fn line(
    n: usize,
    x0: f64,
    x1: f64,
    y: impl Fn(f64) -> f64,
    jitter: f64,
    up: bool,
    seed: u64,
) -> Surface {
    let mut rng = Lcg(seed);
    let h = (x1 - x0) / n as f64;
    let coords: Vec<[f64; 3]> = (0..=n)
        .map(|i| {
            let mut x = x0 + h * i as f64;
            if i > 0 && i < n {
                x += jitter * h * rng.next();
            }
            [x, y(x), 0.0]
        })
        .collect();
    let conn = (0..n)
        .flat_map(|i| if up { [i + 1, i] } else { [i, i + 1] })
        .collect();
    Surface::new('a', FaceKind::Seg2, coords, conn).expect("a valid side")
}

/// A 3D side over [x0, x1]², nx × nx cells, z = z(x, y); interior nodes jittered; quads or
/// triangles; `up` makes the normal +z.
#[allow(clippy::too_many_arguments)]
fn sheet(
    n: usize,
    x0: f64,
    x1: f64,
    z: impl Fn(f64, f64) -> f64,
    jitter: f64,
    tri: bool,
    up: bool,
    seed: u64,
) -> Surface {
    let mut rng = Lcg(seed);
    let h = (x1 - x0) / n as f64;
    let mut coords = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (mut x, mut y) = (x0 + h * i as f64, x0 + h * j as f64);
            if i > 0 && i < n && j > 0 && j < n {
                x += jitter * h * rng.next();
                y += jitter * h * rng.next();
            }
            coords.push([x, y, z(x, y)]);
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut conn = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            let mut faces = if tri {
                vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]
            } else {
                vec![q.to_vec()]
            };
            for f in &mut faces {
                if !up {
                    f.reverse();
                }
                conn.extend_from_slice(f);
            }
        }
    }
    let kind = if tri { FaceKind::Tri3 } else { FaceKind::Quad4 };
    Surface::new('a', kind, coords, conn).expect("a valid side")
}

/// The reference D, M (dense), weighted gaps: module header's adaptive quadrature.
struct Reference {
    d: Vec<Vec<f64>>,
    m: Vec<Vec<f64>>,
    gap: Vec<f64>,
}

const DELTA: f64 = 1e-7;

fn gauss4(lo: f64, hi: f64) -> [(f64, f64); 4] {
    let (p, q) = (
        (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt(),
        (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt(),
    );
    let (wp, wq) = (
        (18.0 + 30.0f64.sqrt()) / 36.0,
        (18.0 - 30.0f64.sqrt()) / 36.0,
    );
    let (c, r) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    [
        (c - r * q, r * wq),
        (c - r * p, r * wp),
        (c + r * p, r * wp),
        (c + r * q, r * wq),
    ]
}

struct Face<'s> {
    a: &'s Surface,
    b: &'s Surface,
    f: usize,
    coef: [[f64; 4]; 4],
    reach: f64,
}

impl Face<'_> {
    /// Where Π(x(ξ)) lies (brute force): a node of a 2D Γ^b (a convex corner's normal cone,
    /// where Π is constant) or the inside of a face; None if no projection.
    fn id(&self, xi: [f64; 2]) -> Option<usize> {
        let p = project_brute(self.b, self.a.point(self.f, xi), self.reach).ok()?;
        let end = p.xi[0] == 0.0 || p.xi[0] == 1.0;
        Some(if self.b.kind == FaceKind::Seg2 && end {
            self.b.face(p.face)[p.xi[0] as usize]
        } else {
            self.b.num_nodes() + p.face
        })
    }

    /// Adds w × the integrands at ξ.
    fn add(&self, xi: [f64; 2], w: f64, r: &mut Reference) {
        let x = self.a.point(self.f, xi);
        let Ok(p) = project_brute(self.b, x, self.reach) else {
            return;
        };
        let jw = w * self.a.jacobian(self.f, xi);
        let (na, nb) = (self.a.kind.shape(xi), self.b.kind.shape(p.xi));
        let n = self.a.normal(self.f);
        let g: f64 = (0..3).map(|c| (p.point[c] - x[c]) * n[c]).sum();
        let (fa, fb) = (self.a.face(self.f), self.b.face(p.face));
        for (k, &rk) in fa.iter().enumerate() {
            let psi: f64 = (0..fa.len()).map(|l| self.coef[k][l] * na[l]).sum();
            for (i, &ci) in fa.iter().enumerate() {
                r.d[rk][ci] += jw * psi * na[i];
            }
            for (j, &cj) in fb.iter().enumerate() {
                r.m[rk][cj] += jw * psi * nb[j];
            }
            r.gap[rk] += jw * psi * g;
        }
    }

    /// The η-line at ξ from 0 to `top`: integrated with weight w into r (if any); returns the
    /// sequence of Γ^b faces met along it.
    fn line(&self, xi: f64, top: f64, w: f64, mut r: Option<&mut Reference>) -> Vec<Option<usize>> {
        let mut seq = Vec::new();
        let (i0, i1) = (self.id([xi, 0.0]), self.id([xi, top]));
        self.inner(xi, 0.0, top, i0, i1, w, &mut r, &mut seq);
        seq.dedup();
        seq
    }

    #[allow(clippy::too_many_arguments)]
    fn inner(
        &self,
        xi: f64,
        lo: f64,
        hi: f64,
        ilo: Option<usize>,
        ihi: Option<usize>,
        w: f64,
        r: &mut Option<&mut Reference>,
        seq: &mut Vec<Option<usize>>,
    ) {
        if ilo == ihi || hi - lo < DELTA {
            seq.push(ilo);
            seq.push(ihi);
            if let Some(r) = r {
                if ilo == ihi {
                    for (t, wt) in gauss4(lo, hi) {
                        self.add([xi, t], w * wt, r);
                    }
                } else {
                    self.add([xi, 0.5 * (lo + hi)], w * (hi - lo), r);
                }
            }
            return;
        }
        let mid = 0.5 * (lo + hi);
        let im = self.id([xi, mid]);
        self.inner(xi, lo, mid, ilo, im, w, r, seq);
        self.inner(xi, mid, hi, im, ihi, w, r, seq);
    }

    fn top(&self, xi: f64) -> f64 {
        match self.a.kind {
            FaceKind::Tri3 => 1.0 - xi,
            _ => 1.0,
        }
    }

    fn outer(
        &self,
        lo: f64,
        hi: f64,
        slo: &[Option<usize>],
        shi: &[Option<usize>],
        r: &mut Reference,
    ) {
        let mid = 0.5 * (lo + hi);
        let smid = self.line(mid, self.top(mid), 0.0, None);
        if (slo == smid.as_slice() && shi == smid.as_slice()) || hi - lo < DELTA {
            let rule: Vec<(f64, f64)> = if hi - lo < DELTA {
                vec![(mid, hi - lo)]
            } else {
                gauss4(lo, hi).to_vec()
            };
            for (t, w) in rule {
                self.line(t, self.top(t), w, Some(r));
            }
            return;
        }
        self.outer(lo, mid, slo, &smid, r);
        self.outer(mid, hi, &smid, shi, r);
    }
}

fn reference(a: &Surface, b: &Surface, basis: Basis, reach: f64) -> Reference {
    let mut r = Reference {
        d: vec![vec![0.0; a.num_nodes()]; a.num_nodes()],
        m: vec![vec![0.0; b.num_nodes()]; a.num_nodes()],
        gap: vec![0.0; a.num_nodes()],
    };
    for f in 0..a.num_faces() {
        let face = Face {
            a,
            b,
            f,
            coef: basis_coefficients(a, f, basis),
            reach,
        };
        if a.kind == FaceKind::Seg2 {
            // A segment is one line: ξ = s, η unused (top = 1, the line runs along η… so swap).
            let seg = SegLine(&face);
            seg.run(&mut r);
            continue;
        }
        // Start from 6 intervals so that no change of topology hides between samples.
        let cuts: Vec<f64> = (0..=6).map(|k| k as f64 / 6.0).collect();
        let seqs: Vec<_> = cuts
            .iter()
            .map(|&t| face.line(t, face.top(t), 0.0, None))
            .collect();
        for k in 0..6 {
            face.outer(cuts[k], cuts[k + 1], &seqs[k], &seqs[k + 1], &mut r);
        }
    }
    r
}

/// A 2D face: the inner bisection along its one parameter.
struct SegLine<'f, 's>(&'f Face<'s>);
impl SegLine<'_, '_> {
    fn id(&self, s: f64) -> Option<usize> {
        self.0.id([s, 0.0])
    }
    fn run(&self, r: &mut Reference) {
        self.go(0.0, 1.0, self.id(0.0), self.id(1.0), r);
    }
    fn go(&self, lo: f64, hi: f64, ilo: Option<usize>, ihi: Option<usize>, r: &mut Reference) {
        if ilo == ihi {
            for (t, w) in gauss4(lo, hi) {
                self.0.add([t, 0.0], w, r);
            }
        } else if hi - lo < DELTA {
            self.0.add([0.5 * (lo + hi), 0.0], hi - lo, r);
        } else {
            let mid = 0.5 * (lo + hi);
            let im = self.id(mid);
            self.go(lo, mid, ilo, im, r);
            self.go(mid, hi, im, ihi, r);
        }
    }
}

/// Largest |D − D_ref|, |M − M_ref|, |g̃ − g̃_ref|.
fn compare(mortar: &Mortar, r: &Reference) -> f64 {
    let mut err: f64 = 0.0;
    for k in 0..r.d.len() {
        for (i, v) in r.d[k].iter().enumerate() {
            err = err.max((mortar.d.get(k, i) - v).abs());
        }
        for (j, v) in r.m[k].iter().enumerate() {
            err = err.max((mortar.m.get(k, j) - v).abs());
        }
        err = err.max((mortar.weighted_gap[k] - r.gap[k]).abs());
    }
    err
}

/// Largest |Σ_i D_ki − Σ_j M_kj| and |Σ_i D_ki − ∫ψ_k| over the rows.
fn partition_of_unity(mortar: &Mortar, full: &[f64]) -> (f64, f64) {
    let (mut dm, mut dpsi): (f64, f64) = (0.0, 0.0);
    for (k, &fk) in full.iter().enumerate() {
        let sd = mortar.d.row_sum(k);
        dm = dm.max((sd - mortar.m.row_sum(k)).abs());
        dpsi = dpsi
            .max((sd - fk).abs())
            .max((mortar.psi_integral[k] - fk).abs());
    }
    (dm, dpsi)
}

/// Largest |D_ki − δ_ki ∫φ_i| (the dual basis's biorthogonality on a covered Γ^a).
fn biorthogonality(mortar: &Mortar, full: &[f64]) -> f64 {
    let mut err: f64 = 0.0;
    for (k, &fk) in full.iter().enumerate() {
        for i in 0..full.len() {
            let want = if i == k { fk } else { 0.0 };
            err = err.max((mortar.d.get(k, i) - want).abs());
        }
    }
    err
}

/// Runs every check on one interface; `covered`: Γ^a lies wholly over Γ^b.
fn check(name: &str, a: &Surface, b: &Surface, reach: f64, covered: bool) {
    let proj = Projector::new(b, reach);
    let seg = segment(a, &proj).expect("a segmentation");
    let full = face_integrals(a);
    for basis in [Basis::Standard, Basis::Dual] {
        let mortar = mortar_matrices(a, b, &seg, basis).expect("mortar matrices");
        let (dm, dpsi) = partition_of_unity(&mortar, &full);
        let reference = reference(a, b, basis, reach);
        let quad = compare(&mortar, &reference);
        let bio = if basis == Basis::Dual {
            biorthogonality(&mortar, &full)
        } else {
            0.0
        };
        println!(
            "{name} {basis:?}: |ΣD − ΣM| {dm:.1e}, |ΣD − ∫ψ| {dpsi:.1e}, adaptive {quad:.1e}, biorthogonality {bio:.1e}"
        );
        // Partition of unity: Σ_i φ^a_i = Σ_j φ^b_j = 1 at every point to round-off, so the row
        // sums differ by the rounding of ~10² products of entries ≤ 0.2 (ψ's coefficients ≤ 4):
        // a few 1e-16, well under 1e-14.
        assert!(dm <= 1e-14, "{name} {basis:?}: ΣD − ΣM = {dm:e}");
        if covered {
            assert!(dpsi <= 1e-14, "{name} {basis:?}: ΣD − ∫ψ = {dpsi:e}");
            assert!(bio <= 1e-14, "{name} {basis:?}: biorthogonality {bio:e}");
        }
        // The adaptive quadrature's own error is ≤ ~1e-13 (module header); the segmentation's
        // rules are exact on these affine faces, so 1e-10 leaves three digits of margin.
        assert!(
            quad <= 1e-10,
            "{name} {basis:?}: D, M against the adaptive quadrature: {quad:e}"
        );
    }
}

#[test]
fn non_matching_2d_interfaces() {
    for (na, nb) in [(3, 4), (4, 3), (5, 7), (7, 5)] {
        let a = line(na, 0.0, 1.0, |_| 0.0, 0.0, true, 1);
        let b = line(nb, 0.0, 1.0, |_| 0.01, 0.0, false, 2);
        check(&format!("2D {na}/{nb}"), &a, &b, 0.05, true);
    }
    // Unstructured: jittered nodes; a tilted Γ^b (a varying gap).
    let a = line(7, 0.0, 1.0, |_| 0.0, 0.3, true, 3);
    let b = line(5, -0.2, 1.2, |x| 0.01 + 0.05 * x, 0.3, false, 4);
    check("2D jittered, tilted", &a, &b, 0.2, true);
    // A curved Γ^a (a disc's bottom arc, R = 2) over a flat Γ^b: Π vertical.
    let a = line(
        9,
        -0.5,
        0.5,
        |x| 2.0 + 0.001 - (4.0 - x * x).sqrt(),
        0.0,
        false,
        5,
    );
    let b = line(6, -0.7, 0.7, |_| 0.0, 0.2, true, 6);
    check("2D arc on a line", &a, &b, 0.2, true);
    // A flat Γ^a over a curved Γ^b (the disc is B): the corners' normal cones are pieces too.
    let a = line(7, -0.5, 0.5, |_| -0.02, 0.2, true, 7);
    let b = line(10, -0.7, 0.7, |x| 2.0 - (4.0 - x * x).sqrt(), 0.0, false, 8);
    check("2D line under an arc", &a, &b, 0.2, true);
}

#[test]
fn non_matching_3d_interfaces() {
    for (na, nb, tri) in [(3, 4, false), (4, 3, false), (5, 7, false), (3, 4, true)] {
        let a = sheet(na, 0.0, 1.0, |_, _| 0.0, 0.0, tri, true, 1);
        let b = sheet(nb, 0.0, 1.0, |_, _| 0.01, 0.0, tri, false, 2);
        check(&format!("3D {na}/{nb} tri {tri}"), &a, &b, 0.05, true);
    }
    // Unstructured triangles against quads; a tilted Γ^b larger than Γ^a.
    let a = sheet(4, 0.0, 1.0, |_, _| 0.0, 0.3, true, true, 3);
    let b = sheet(
        3,
        -0.2,
        1.2,
        |x, y| 0.01 + 0.04 * x - 0.03 * y,
        0.0,
        false,
        false,
        4,
    );
    check("3D jittered triangles on tilted quads", &a, &b, 0.2, true);
    let a = sheet(5, 0.0, 1.0, |_, _| 0.0, 0.0, false, true, 5);
    let b = sheet(7, -0.1, 1.1, |_, _| 0.02, 0.3, true, false, 6);
    check("3D quads on jittered triangles", &a, &b, 0.2, true);
}

#[test]
fn bins_find_the_brute_force_projection() {
    let b = sheet(6, 0.0, 1.0, |x, y| 0.1 * (x * y), 0.3, false, false, 7);
    let proj = Projector::new(&b, 0.3);
    let mut rng = Lcg(9);
    for _ in 0..2000 {
        let p = [
            0.5 + 0.6 * rng.next(),
            0.5 + 0.6 * rng.next(),
            0.2 * rng.next(),
        ];
        let fast = proj.project(p);
        let slow = project_brute(&b, p, 0.3);
        match (fast, slow) {
            (Ok(f), Ok(s)) => {
                // Same distance to round-off; the face may differ only on a shared edge.
                assert!(
                    (f.distance - s.distance).abs() <= 1e-13,
                    "{p:?}: {f:?} vs {s:?}"
                );
            }
            (Err(_), Err(_)) => {}
            (f, s) => panic!("{p:?}: bins {f:?}, brute force {s:?}"),
        }
    }
}

#[test]
fn refusals() {
    let b = sheet(3, 0.0, 1.0, |_, _| 0.0, 0.0, false, false, 1);
    let proj = Projector::new(&b, 0.05);
    assert!(matches!(
        proj.project([0.5, 0.5, 0.2]),
        Err(InterfaceError::NoProjection { .. })
    ));
    assert!(matches!(
        proj.project([1.5, 0.5, 0.0]),
        Err(InterfaceError::NoProjection { .. })
    ));
    let bad = Surface::new(
        'b',
        FaceKind::Tri3,
        vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        vec![0, 1, 2],
    );
    assert!(matches!(bad, Err(InterfaceError::Degenerate { .. })));
    let bad = Surface::new('b', FaceKind::Quad4, vec![[0.0; 3]; 3], vec![0, 1, 2]);
    assert!(matches!(bad, Err(InterfaceError::BadConnectivity { .. })));
    let bad = Surface::new('b', FaceKind::Tri3, vec![[0.0; 3]; 3], vec![0, 1, 3]);
    assert!(matches!(bad, Err(InterfaceError::BadNode { node: 3, .. })));
    // Γ^b folding back over itself within the reach: two layers over one face of Γ^a.
    let mut coords = b.coords.clone();
    coords.extend(b.coords.iter().map(|x| [x[0], x[1], 0.01]));
    let n = b.num_nodes();
    let mut conn = b.conn.clone();
    conn.extend(b.conn.iter().map(|&k| k + n));
    let folded = Surface::new('b', FaceKind::Quad4, coords, conn).expect("valid faces");
    let a = sheet(2, 0.0, 1.0, |_, _| -0.01, 0.0, false, true, 2);
    let proj = Projector::new(&folded, 0.05);
    assert!(matches!(
        segment(&a, &proj),
        Err(InterfaceError::Overlap { .. })
    ));
}
