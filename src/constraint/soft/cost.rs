//! The soft constraint cost of MuJoCo's convex formulation (MuJoCo documentation, "Computation →
//! Constraint model" and "Solver"; Todorov 2014, "Convex and analytically-invertible dynamics
//! with contacts and constraints"): with jar = J a − aref per row,
//!
//! s(jar) = Σ over rows of
//! - equality: ½ D jar²;
//! - friction loss f: ½ D jar² while |jar| < R f, else f |jar| − ½ R f² (force ∓f);
//! - limit, frictionless or pyramidal contact: ½ D jar² while jar < 0, else 0;
//! - elliptic contact (per contact, U₀ = μ jar₀, U_j = μ_j jar_j, N = U₀, T = |U_t|): 0 in the
//!   top zone N ≥ μ T, ½ Σ D jar² in the bottom zone μ N + T ≤ 0, and
//!   ½ D₀/(μ²(1 + μ²)) (N − μ T)² on the cone's surface between them,
//!
//! with μ the regularized cone's friction (`contact_mu`). The force of a row is −∂s/∂jar. The
//! solvers minimize ½ (a − a₀)ᵀ M (a − a₀) + s(J a − aref) over the acceleration a (a₀ =
//! `qacc_smooth`).

use crate::model::{Contact, EfcState, EfcType};
use nalgebra::DVector;

/// The rows of the soft problem, read-only.
pub struct Rows<'a> {
    /// Number of equality rows (first in the row order).
    pub ne: usize,
    /// Number of friction-loss rows (after the equality rows).
    pub nf: usize,
    /// Number of rows.
    pub nefc: usize,
    /// Each row's kind (`efc_type`).
    pub kind: &'a [EfcType],
    /// Each row's element (`efc_id`; for contact rows the index in `contacts`).
    pub id: &'a [usize],
    /// Each row's D = 1/R (`efc_D`).
    pub d: &'a DVector<f64>,
    /// Each row's regularizer R (`efc_R`).
    pub r: &'a DVector<f64>,
    /// Each friction-loss row's bound f (`efc_frictionloss`).
    pub floss: &'a DVector<f64>,
    /// The contacts of the contact rows.
    pub contacts: &'a [Contact],
    /// Per contact, the regularized cone's friction coefficient (`mjContact.mu`).
    pub mu: &'a [f64],
}

impl Rows<'_> {
    /// The number of rows of the block at row i (a whole contact for elliptic cones).
    fn block(&self, i: usize) -> usize {
        if self.kind[i] != EfcType::ContactElliptic {
            return 1;
        }
        self.contacts[self.id[i]].condim.clamp(1, 6) as usize
    }

    /// Forces and states at `jar` into `force` and `state`; returns the cost s(jar).
    pub fn update(&self, jar: &DVector<f64>, force: &mut DVector<f64>, state: &mut [EfcState]) -> f64 {
        let mut cost = 0.0;
        self.update_each(jar, force, state, |_, c| cost += c);
        cost
    }

    /// As [`Self::update`], each term of the cost given to `each` with its row (an elliptic
    /// contact's cone term with its first row) instead of summed.
    pub fn update_each(
        &self,
        jar: &DVector<f64>,
        force: &mut DVector<f64>,
        state: &mut [EfcState],
        mut each: impl FnMut(usize, f64),
    ) {
        // Slices: the per-row loops index them without nalgebra's shape checks.
        let (jar, force) = (jar.as_slice(), force.as_mut_slice());
        let (n, scalar) = (self.nefc, self.ne + self.nf);
        let d_all = self.d.as_slice();
        // The equality rows (always quadratic): `update_at`'s terms, in one tight loop; then the
        // friction-loss rows one by one.
        let ne = self.ne.min(n);
        for (t, ((&x, &d), (f, st))) in
            jar[..ne].iter().zip(&d_all[..ne]).zip(force[..ne].iter_mut().zip(&mut state[..ne])).enumerate()
        {
            (*st, *f) = (EfcState::Quadratic, -d * x);
            each(t, 0.5 * d * x * x);
        }
        let mut i = ne;
        while i < scalar.min(n) {
            i += self.update_at(i, jar, force, state, &mut each);
        }
        while i < n {
            // A run of limit, frictionless or pyramidal rows (quadratic below zero, else
            // satisfied): `update_at`'s terms, in one tight loop; then an elliptic contact.
            let end = self.scalar_run_end(i);
            for (t, ((&x, &d), (f, st))) in jar[i..end]
                .iter()
                .zip(&d_all[i..end])
                .zip(force[i..end].iter_mut().zip(&mut state[i..end]))
                .enumerate()
            {
                if x >= 0.0 {
                    (*st, *f) = (EfcState::Satisfied, 0.0);
                    each(i + t, 0.0);
                } else {
                    (*st, *f) = (EfcState::Quadratic, -d * x);
                    each(i + t, 0.5 * d * x * x);
                }
            }
            i = end;
            if i < n {
                i += self.update_at(i, jar, force, state, &mut each);
            }
        }
    }

    /// The end of the run of rows from row i ≥ ne + nf that are not elliptic contacts' (the
    /// first elliptic row after it, or nefc).
    #[inline(always)]
    fn scalar_run_end(&self, i: usize) -> usize {
        let n = self.nefc;
        self.kind[i..n].iter().position(|&k| k == EfcType::ContactElliptic).map_or(n, |p| i + p)
    }

    /// As [`Self::update_each`], over the rows `list` only (ascending, an elliptic contact's rows
    /// all in it or none: one constraint island's, `island.rs`); the other rows' forces and
    /// states are left as they are.
    pub fn update_rows(
        &self,
        jar: &DVector<f64>,
        force: &mut DVector<f64>,
        state: &mut [EfcState],
        list: &[usize],
        mut each: impl FnMut(usize, f64),
    ) {
        let (jar, force) = (jar.as_slice(), force.as_mut_slice());
        let mut t = 0;
        while t < list.len() {
            t += self.update_at(list[t], jar, force, state, &mut each);
        }
    }

    /// The state, force and cost terms of the block at row i (one row, or an elliptic
    /// contact's rows); returns the block's number of rows.
    #[inline]
    fn update_at(
        &self,
        i: usize,
        jar: &[f64],
        force: &mut [f64],
        state: &mut [EfcState],
        each: &mut impl FnMut(usize, f64),
    ) -> usize {
        let (d_all, r_all, floss) = (self.d.as_slice(), self.r.as_slice(), self.floss.as_slice());
        let (x, d) = (jar[i], d_all[i]);
        if i < self.ne || self.kind[i] != EfcType::ContactElliptic {
            // One scalar row: its state, force and cost.
            let (st, f, c) = if i < self.ne {
                (EfcState::Quadratic, -d * x, 0.5 * d * x * x)
            } else if i < self.ne + self.nf {
                let (f, r) = (floss[i], r_all[i]);
                if x <= -r * f {
                    (EfcState::LinearNeg, f, -0.5 * r * f * f - f * x)
                } else if x >= r * f {
                    (EfcState::LinearPos, -f, -0.5 * r * f * f + f * x)
                } else {
                    (EfcState::Quadratic, -d * x, 0.5 * d * x * x)
                }
            } else if x >= 0.0 {
                (EfcState::Satisfied, 0.0, 0.0)
            } else {
                (EfcState::Quadratic, -d * x, 0.5 * d * x * x)
            };
            state[i] = st;
            force[i] = f;
            each(i, c);
            return 1;
        }
        let dim = self.block(i);
        let c = &self.contacts[self.id[i]];
        let mu = self.mu[self.id[i]];
        let (n, t, _) = cone_coordinates(jar, i, dim, mu, &c.friction);
        let zone = if n >= mu * t || (t <= 0.0 && n >= 0.0) {
            EfcState::Satisfied
        } else if mu * n + t <= 0.0 || (t <= 0.0 && n < 0.0) {
            EfcState::Quadratic
        } else {
            EfcState::Cone
        };
        match zone {
            EfcState::Satisfied => force[i..i + dim].fill(0.0),
            EfcState::Quadratic => {
                for j in i..i + dim {
                    force[j] = -d_all[j] * jar[j];
                    each(j, 0.5 * d_all[j] * jar[j] * jar[j]);
                }
            }
            _ => {
                let dm = d / (mu * mu * (1.0 + mu * mu));
                let nmt = n - mu * t;
                each(i, 0.5 * dm * nmt * nmt);
                force[i] = -dm * nmt * mu;
                for j in 1..dim {
                    let u = jar[i + j] * c.friction[j - 1];
                    force[i + j] = -force[i] / t * u * c.friction[j - 1];
                }
            }
        }
        state[i..i + dim].fill(zone);
        dim
    }

    /// The first and second derivative of s(jar + α jv) in α, at α given by `jar` (already
    /// moved) along `jv`.
    pub fn directional(&self, jar: &DVector<f64>, jv: &DVector<f64>) -> (f64, f64) {
        let (jar, jv) = (jar.as_slice(), jv.as_slice());
        let (mut d1, mut d2) = (0.0, 0.0);
        let d_all = self.d.as_slice();
        let n = self.nefc;
        let ne = self.ne.min(n);
        // The equality rows (always quadratic), then the friction-loss rows: `directional_at`'s
        // sums, row by row in order.
        for ((&x, &v), &d) in jar[..ne].iter().zip(&jv[..ne]).zip(&d_all[..ne]) {
            d1 += d * x * v;
            d2 += d * v * v;
        }
        let mut i = ne;
        while i < (self.ne + self.nf).min(n) {
            i += self.directional_at(i, jar, jv, &mut d1, &mut d2);
        }
        while i < n {
            // A run of limit, frictionless or pyramidal rows (quadratic below zero), in one
            // tight loop; then an elliptic contact.
            let end = self.scalar_run_end(i);
            for ((&x, &v), &d) in jar[i..end].iter().zip(&jv[i..end]).zip(&d_all[i..end]) {
                if x < 0.0 {
                    d1 += d * x * v;
                    d2 += d * v * v;
                }
            }
            i = end;
            if i < n {
                i += self.directional_at(i, jar, jv, &mut d1, &mut d2);
            }
        }
        (d1, d2)
    }

    /// As [`Self::directional`], over the rows `list` only (ascending, an elliptic contact's
    /// rows all in it or none: one constraint island's, `island.rs`).
    pub fn directional_rows(&self, jar: &DVector<f64>, jv: &DVector<f64>, list: &[usize]) -> (f64, f64) {
        let (jar, jv) = (jar.as_slice(), jv.as_slice());
        let (mut d1, mut d2) = (0.0, 0.0);
        let mut t = 0;
        while t < list.len() {
            t += self.directional_at(list[t], jar, jv, &mut d1, &mut d2);
        }
        (d1, d2)
    }

    /// Adds the derivatives of the block at row i (one row, or an elliptic contact's rows) to
    /// d1 and d2; returns the block's number of rows.
    #[inline]
    fn directional_at(&self, i: usize, jar: &[f64], jv: &[f64], d1: &mut f64, d2: &mut f64) -> usize {
        let (d_all, r_all, floss) = (self.d.as_slice(), self.r.as_slice(), self.floss.as_slice());
        let (x, v, d) = (jar[i], jv[i], d_all[i]);
        let quadratic = if i < self.ne {
            true
        } else if i < self.ne + self.nf {
            let rf = r_all[i] * floss[i];
            if x <= -rf {
                *d1 -= floss[i] * v;
                false
            } else if x >= rf {
                *d1 += floss[i] * v;
                false
            } else {
                true
            }
        } else if self.kind[i] != EfcType::ContactElliptic {
            x < 0.0
        } else {
            let dim = self.block(i);
            let c = &self.contacts[self.id[i]];
            let mu = self.mu[self.id[i]];
            let (n, t, _) = cone_coordinates(jar, i, dim, mu, &c.friction);
            if n >= mu * t || (t <= 0.0 && n >= 0.0) {
            } else if mu * n + t <= 0.0 || (t <= 0.0 && n < 0.0) {
                for j in i..i + dim {
                    *d1 += d_all[j] * jar[j] * jv[j];
                    *d2 += d_all[j] * jv[j] * jv[j];
                }
            } else {
                let dm = d / (mu * mu * (1.0 + mu * mu));
                let dn = mu * v;
                let (mut tu, mut tt) = (0.0, 0.0);
                for j in 1..dim {
                    let f = c.friction[j - 1];
                    let (u, du) = (jar[i + j] * f, jv[i + j] * f);
                    tu += u * du;
                    tt += du * du;
                }
                let dt = tu / t;
                let ddt = (tt - dt * dt) / t;
                let nmt = n - mu * t;
                let dnmt = dn - mu * dt;
                *d1 += dm * nmt * dnmt;
                *d2 += dm * (dnmt * dnmt - nmt * mu * ddt);
            }
            return dim;
        };
        if quadratic {
            *d1 += d * x * v;
            *d2 += d * v * v;
        }
        1
    }

    /// Calls `add(i, dim, h)` for each block of the Hessian of s in jar on the rows that have
    /// one, h in the top-left dim × dim of the array: D_i on a quadratic row (dim 1, also each
    /// row of an elliptic contact in its bottom zone), and the dense block of an elliptic contact
    /// on its cone (rows i..i+dim).
    pub fn hessian(
        &self,
        jar: &DVector<f64>,
        state: &[EfcState],
        mut add: impl FnMut(usize, usize, &[[f64; 6]; 6]),
    ) {
        let (jar, d_all) = (jar.as_slice(), self.d.as_slice());
        let mut block = [[0.0; 6]; 6];
        let mut i = 0;
        while i < self.nefc {
            if self.kind[i] == EfcType::ContactElliptic && i >= self.ne + self.nf {
                let dim = self.block(i);
                match state[i] {
                    EfcState::Quadratic => {
                        for j in i..i + dim {
                            block[0][0] = d_all[j];
                            add(j, 1, &block);
                        }
                    }
                    EfcState::Cone => {
                        let c = &self.contacts[self.id[i]];
                        let mu = self.mu[self.id[i]];
                        let (n, t, u) = cone_coordinates(jar, i, dim, mu, &c.friction);
                        let dm = d_all[i] / (mu * mu * (1.0 + mu * mu));
                        let scale = |k: usize| if k == 0 { mu } else { c.friction[k - 1] };
                        // In U: (1, −μ/T U_t) outer product plus μ N/T³ U_t U_tᵀ + (μ² − μN/T) I_t.
                        for a in 0..dim {
                            for b in 0..dim {
                                let h = match (a, b) {
                                    (0, 0) => 1.0,
                                    (0, _) => -mu / t * u[b],
                                    (_, 0) => -mu / t * u[a],
                                    _ => {
                                        mu * n / (t * t * t) * u[a] * u[b]
                                            + if a == b { mu * mu - mu * n / t } else { 0.0 }
                                    }
                                };
                                block[a][b] = dm * scale(a) * scale(b) * h;
                            }
                        }
                        add(i, dim, &block);
                    }
                    _ => {}
                }
                i += dim;
                continue;
            }
            if state[i] == EfcState::Quadratic {
                block[0][0] = d_all[i];
                add(i, 1, &block);
            }
            i += 1;
        }
    }
}

/// N, T and U (U₀ = μ jar₀, U_j = μ_j jar_j) of the elliptic contact at row i.
fn cone_coordinates(jar: &[f64], i: usize, dim: usize, mu: f64, friction: &[f64; 5]) -> (f64, f64, [f64; 6]) {
    let mut u = [0.0; 6];
    u[0] = jar[i] * mu;
    let mut t2 = 0.0;
    for j in 1..dim {
        u[j] = jar[i + j] * friction[j - 1];
        t2 += u[j] * u[j];
    }
    (u[0], t2.sqrt(), u)
}
