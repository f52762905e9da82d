//! M⁻¹Bᵀ and W_M = BM⁻¹Bᵀ of one geometry and mass: the predictor of contact-stabilized
//! Newmark, made once per (geometry, mass) with M's own Cholesky factor and cached.

use crate::run::fe::cache::Cache;
use crate::run::fe::geometry::Geometry;
use crate::space::fe::SymMatrix;
use crate::space::linalg::Cholesky;

/// M⁻¹Bᵀ (n × n_c, column-major) and W_M = B M⁻¹ Bᵀ (row-major) of one geometry and mass: the
/// predictor of contact-stabilized Newmark.
#[derive(Debug)]
pub(super) struct MassInverse {
    pub(super) zm: Vec<f64>,
    pub(super) wm: Vec<f64>,
    /// K M⁻¹Bᵀ (n × n_c): the predictor's K u^pred from carried products.
    pub(super) kzm: Vec<f64>,
}

pub(super) static MASS_INVERSES: Cache<MassInverse> = Cache::new();

pub(super) fn mass_inverse(g: &Geometry, m: &SymMatrix) -> Result<MassInverse, String> {
    // M's own factor (also under `solver = "cg"`: the predictor's W = B M⁻¹ Bᵀ is made once).
    let symbolic = g.symbolic().map_err(|e| e.to_string())?;
    let chol = Cholesky::new(&symbolic, m)
        .map_err(|e| format!("the mass matrix is not positive definite: {e}"))?;
    let (n, nc) = (g.dofs.n_free(), g.rows.len());
    let mut zm = vec![0.0; n * nc];
    for j in 0..nc {
        g.rows.add(j, 1.0, &mut zm[j * n..(j + 1) * n]);
    }
    let mut work = chol.work_for(nc);
    chol.solve_many_in_place(&mut zm, nc, &mut work);
    let mut wm = vec![0.0; nc * nc];
    for i in 0..nc {
        for j in 0..nc {
            wm[i * nc + j] = g.rows.dot(i, &zm[j * n..(j + 1) * n]);
        }
    }
    for i in 0..nc {
        for j in 0..i {
            let s = 0.5 * (wm[i * nc + j] + wm[j * nc + i]);
            wm[i * nc + j] = s;
            wm[j * nc + i] = s;
        }
    }
    let mut kzm = vec![0.0; n * nc];
    for j in 0..nc {
        g.k.matvec_into(&zm[j * n..(j + 1) * n], &mut kzm[j * n..(j + 1) * n]);
    }
    Ok(MassInverse { zm, wm, kzm })
}
