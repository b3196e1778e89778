//! Low-rank factors of a far block and their truncation (Bebendorf,
//! *Hierarchical Matrices*, 2008, §1.1.5; Hackbusch 2015, §2.6): a block
//! `B` (m/N) is kept as `L Rᵀ`, truncated by the thin SVD `B = U Σ Vᵀ` to
//! the smallest rank `r` whose discarded tail
//! `(Σ_{l>r} σ_l²)^{1/2} = ‖B − U_r Σ_r V_rᵀ‖_F` is within a threshold.
//! The sum of two factorizations is recompressed without forming the
//! block: `L = Q_L R_L`, `R = Q_R R_R` (thin QR), the core
//! `R_L R_Rᵀ = U' Σ V'ᵀ` (its SVD), `L Rᵀ = (Q_L U') Σ (Q_R V')ᵀ`.

use faer::{Mat, MatRef};

/// A truncated SVD `U Σ Vᵀ`: `u` (rows × r) and `v` (cols × r) with
/// orthonormal columns, `s` the `r` singular values, descending (m/N).
#[derive(Clone, Debug)]
pub struct TruncatedSvd {
    /// Left singular vectors, by column.
    pub u: Mat<f64>,
    /// Singular values, descending.
    pub s: Vec<f64>,
    /// Right singular vectors, by column.
    pub v: Mat<f64>,
}

/// The smallest rank whose discarded singular values (`s` descending) have
/// a root sum of squares `≤ threshold`.
pub fn truncation_rank(s: &[f64], threshold: f64) -> usize {
    let mut tail = 0.0f64;
    let threshold2 = threshold * threshold;
    for r in (0..s.len()).rev() {
        tail += s[r] * s[r];
        if tail > threshold2 {
            return r + 1;
        }
    }
    0
}

impl TruncatedSvd {
    /// The SVD of `a`, truncated at `threshold` (m/N, Frobenius norm of the
    /// discarded part). `None` if the SVD does not converge.
    pub fn of(a: MatRef<'_, f64>, threshold: f64) -> Option<Self> {
        let svd = a.thin_svd().ok()?;
        let s: Vec<f64> = svd.S().column_vector().iter().copied().collect();
        let r = truncation_rank(&s, threshold);
        Some(Self {
            u: svd.U().subcols(0, r).to_owned(),
            s: s[..r].to_vec(),
            v: svd.V().subcols(0, r).to_owned(),
        })
    }

    /// The truncated SVD of `l rᵀ` (module docs), at `threshold`.
    pub fn of_product(l: MatRef<'_, f64>, r: MatRef<'_, f64>, threshold: f64) -> Option<Self> {
        let (ql, rl) = thin_qr(l);
        let (qr, rr) = thin_qr(r);
        let core = &rl * rr.transpose();
        let small = Self::of(core.as_ref(), threshold)?;
        Some(Self {
            u: &ql * &small.u,
            s: small.s,
            v: &qr * &small.v,
        })
    }

    /// The rank kept.
    pub fn rank(&self) -> usize {
        self.s.len()
    }

    /// `(U Σ, V)`: the factors accumulated while a block is incomplete.
    pub fn weighted_left(&self) -> (Mat<f64>, Mat<f64>) {
        let mut l = self.u.clone();
        for (c, &s) in self.s.iter().enumerate() {
            l.col_mut(c).iter_mut().for_each(|x| *x *= s);
        }
        (l, self.v.clone())
    }

    /// `(U √Σ, V √Σ)`: the stored factors, balanced so that both have the
    /// same magnitude (`‖L‖_F = ‖R‖_F = (Σ σ)^{1/2}`) and neither over- nor
    /// underflows in `f32` where the block does not.
    pub fn balanced(&self) -> (Mat<f64>, Mat<f64>) {
        let (mut l, mut r) = (self.u.clone(), self.v.clone());
        for (c, &s) in self.s.iter().enumerate() {
            let root = s.sqrt();
            l.col_mut(c).iter_mut().for_each(|x| *x *= root);
            r.col_mut(c).iter_mut().for_each(|x| *x *= root);
        }
        (l, r)
    }
}

/// The thin QR of `a` (m × k): `Q` (m × min(m, k)) and `R` (min(m, k) × k).
fn thin_qr(a: MatRef<'_, f64>) -> (Mat<f64>, Mat<f64>) {
    let qr = a.qr();
    (qr.compute_thin_Q(), qr.thin_R().to_owned())
}
