//! Composite-rigid-body algorithm for M(q) (RBDA §6.2, Table 6.2) and the tree-sparse LᵀDL
//! factorization and solve (RBDA §6.3, Tables 6.3–6.4).

use crate::error::{check, InputError};
use crate::kinematics::{body_world_pose, posed_world_pose};
use crate::model::warning::MIN_PIVOT;
use crate::model::{Data, HingeAxis, JointKind, Model, NO_DOF};
#[cfg(target_arch = "x86_64")]
use crate::spatial::fused::Fused;
use crate::spatial::fused::{self, MulAdd, Separate};
use crate::spatial::{Motion, RigidInertia, Transform};
use nalgebra::{DMatrix, DVector, Vector3};

/// Joint-space inertia matrix M(q), armature included, into `data.mass_matrix` (and returned).
///
/// The composite-rigid-body algorithm (RBDA §6.2, Table 6.2) evaluated in world axes: composite
/// inertias then add without change of frame, and the entry `M[i][j]` for j an ancestor degree of
/// freedom is the plain product S_jᵀ (Iᶜ_i S_i) of world-axis vectors, so the walk up the tree
/// transforms nothing.
///
/// The moments are taken about each tree's own origin (its root body's position,
/// `data.p_world_tree`), not the world origin, as MuJoCo's `mj_crb` works about each tree's centre
/// of mass (`subtree_com` of the root, engine_core_smooth.c): the poses of a tree are composed from
/// its root placed at zero, so M does not depend on where the tree stands. About the world origin
/// a body at distance d has moments of size m d² whose differences make M's entries: at d = 1e6 m
/// and a 0.1 m link, 12 of the 16 digits were lost. `data.x_world_body` holds the world poses on
/// return.
///
/// On x86-64 CPUs with AVX2 and FMA3 the kernel runs compiled for them (chosen at run time), its
/// products and sums fused into multiply–adds ([`fused`]): one rounding instead of two, fewer and
/// shorter dependent instructions on this flop-dense pass. Elsewhere the same formulas run with
/// separate multiplies and adds; the two agree to round-off
/// (`fma_kernel_matches_separate_multiply_adds`).
///
/// # Errors
/// [`InputError::Length`] when q is not nq long or `data` was made for another model.
///
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/ur5/ur5.urdf")?;
/// let mut data = Data::new(&model);
/// let m = lagrange::dynamics::crba(&model, &mut data, &[0.1; 6])?;
/// assert_eq!((m.nrows(), m.ncols()), (6, 6));
/// assert!((m[(1, 2)] - m[(2, 1)]).abs() < 1e-12); // symmetric
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>, InputError> {
    check::data("crba", model, data)?;
    check::q("crba", model, q)?;
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    Ok(crba_unchecked(model, data, q))
}

/// [`crba`] without the argument checks.
pub(crate) fn crba_unchecked<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d DMatrix<f64> {
    crba_dispatch::<true>(model, data, q);
    &data.mass_matrix
}

/// [`crba`] writing only the upper triangle of `data.mass_matrix` (the entries `M[l][k]`, l ≤ k, on
/// the tree's ancestor chains), as Pinocchio's `crba` does: what [`factorize_mass_matrix`] reads.
/// The strictly lower triangle keeps whatever it held (after [`crba`], an older M's mirror).
///
/// # Errors
/// As [`crba`].
pub fn crba_upper<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>, InputError> {
    check::data("crba_upper", model, data)?;
    check::q("crba_upper", model, q)?;
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    crba_dispatch::<false>(model, data, q);
    Ok(&data.mass_matrix)
}

#[inline(always)]
fn crba_dispatch<const MIRROR: bool>(model: &Model, data: &mut Data, q: &[f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has AVX2 and FMA (checked just above), all `crba_fma` requires.
        unsafe { crba_fma::<MIRROR>(model, data, q) };
        return;
    }
    crba_kernel::<Separate, MIRROR>(model, data, q);
}

/// [`crba_kernel`] compiled for AVX2 and FMA3, its multiply–adds fused (rounded once).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn crba_fma<const MIRROR: bool>(model: &Model, data: &mut Data, q: &[f64]) {
    crba_kernel::<Fused, MIRROR>(model, data, q);
}

#[inline(always)]
fn crba_kernel<A: MulAdd, const MIRROR: bool>(model: &Model, data: &mut Data, q: &[f64]) {
    // The passes below compose the poses about each tree's origin in `x_tree_body` (swapped in
    // for `x_world_body`, whose world poses of this q, if it holds them, survive).
    let world_current = data.poses_stamp.matches(q);
    std::mem::swap(&mut data.x_world_body, &mut data.x_tree_body);
    crba_passes::<A, MIRROR>(model, data, q, world_current);
    std::mem::swap(&mut data.x_world_body, &mut data.x_tree_body);
    if !world_current {
        // The world poses: the tree's origin added back.
        for b in 1..model.nbody() {
            let x = &data.x_tree_body[b];
            data.x_world_body[b] = Transform::new(x.rot, x.pos + data.p_world_tree[b]);
        }
        data.poses_stamp.clear();
        data.velocity_stamp.clear();
    }
}

/// `posed`: the joint transforms and subspaces (`x_parent_body`, `s_body`) are already q's
/// (`Data::poses_stamp`), so pass 1 composes the poses from them instead of forming them again.
#[inline(always)]
fn crba_passes<A: MulAdd, const MIRROR: bool>(model: &Model, data: &mut Data, q: &[f64], posed: bool) {
    // A floating base (a free joint on the world, numbered first, with an unrotated placement):
    // its six columns are (0, eᵢ) and (R eᵢ, p × R eᵢ) in world coordinates (R, p its pose), so
    // the six entries of a descendant's F are F_lin and Rᵀ (F_ang − p × F_lin), the moment about
    // the base origin in base axes: one block instead of six products along the chain; and its
    // own 6×6 block comes from the whole robot's composite inertia ([`floating_base_block`]).
    let floating_base = matches!(model.joints.first(), Some(j) if matches!(j.kind, JointKind::Free)
        && j.dof_adr == 0
        && model.bodies[1].parent == 0
        && model.placement_unrotated[1]);
    // Pass 1, root to leaves: body poses, then world-frame motion subspaces and body inertias
    // (the 10 parameters moved by RBDA eq. 2.66; a hinge's column is (R a, p × R a)).
    for b in 1..model.nbody() {
        // Hinges apart, each arm with its own copy of the body's work: a shared body with a
        // branch in the middle spills the pose to the stack.
        if model.hinge_axis[b] != HingeAxis::Other {
            body_pass::<A, true>(model, data, b, q, false, posed);
        } else {
            body_pass::<A, false>(model, data, b, q, floating_base && b == 1, posed);
        }
    }
    let nv = model.nv;
    // The base's pose about its tree's origin: its rotation, at zero.
    let x_world_base = if floating_base { data.x_world_body[1] } else { Transform::identity() };
    // Only the entries (k, l) of l on the ancestor chain of k (and their mirror) are written: the
    // others are zero from `Data::new` and never change (RBDA §6.3, the tree's sparsity).
    let m = data.mass_matrix.as_mut_slice();
    let (s_world, dof_parent) = (&data.s_world[..nv], &model.dof_parent[..nv]);
    // Pass 2, leaves to root: F = Iᶜ S for each dof of b, dotted with the S of b and its ancestors;
    // then the finished composite inertia of b joins its parent's (RBDA Table 6.2).
    for b in (1..model.nbody()).rev() {
        let j = model.joint_of(b);
        let i_c = data.i_composite[b];
        if floating_base && b == 1 {
            let block = floating_base_block::<A>(&i_c, &x_world_base);
            for (k, col) in block.iter().enumerate() {
                m[k * nv..k * nv + k + 1].copy_from_slice(&col[..=k]);
                m[k * nv + k] += model.dof_armature[k];
                if MIRROR {
                    for l in 0..k {
                        m[k + l * nv] = col[l];
                    }
                }
            }
            continue;
        }
        // A hinge or slide (one column) apart: the loop's set-up around a single column costs as
        // much as the column.
        let base = if floating_base { Some(&x_world_base) } else { None };
        let (k0, n) = (j.dof_adr, j.kind.nv());
        if n == 1 {
            column::<A, MIRROR>(k0, &i_c, s_world, dof_parent, m, nv, model.dof_armature[k0], base);
        } else {
            for k in k0..k0 + n {
                column::<A, MIRROR>(k, &i_c, s_world, dof_parent, m, nv, model.dof_armature[k], base);
            }
        }
        let p = model.bodies[b].parent;
        if p != 0 {
            data.i_composite[p] += &i_c;
        }
    }
}

/// Pass 1 of [`crba_kernel`] for body b: its joint, its pose about its tree's origin (world axes;
/// a tree's root body is placed at zero and its world position kept in `data.p_world_tree`), the
/// columns of its degrees of freedom in those coordinates (none for a floating base,
/// `no_columns`) and its inertia in them. `HINGE`: b's joint is a hinge about a coordinate axis,
/// whose column is (R a, p × R a). `posed`: b's joint transform is already q's
/// ([`posed_world_pose`]).
#[inline(always)]
fn body_pass<A: MulAdd, const HINGE: bool>(
    model: &Model,
    data: &mut Data,
    b: usize,
    q: &[f64],
    no_columns: bool,
    posed: bool,
) {
    let mut x_world_body = if posed {
        posed_world_pose::<A, HINGE>(model, data, b)
    } else {
        body_world_pose::<A, HINGE>(model, data, b, q)
    };
    let parent = model.bodies[b].parent;
    if parent == 0 {
        data.p_world_tree[b] = x_world_body.pos;
        x_world_body.pos = Vector3::zeros();
    } else {
        data.p_world_tree[b] = data.p_world_tree[parent];
    }
    data.x_world_body[b] = x_world_body;
    let j = model.joint_of(b);
    if HINGE {
        data.s_world[j.dof_adr] = fused::act_rotation::<A>(&x_world_body, &data.s_body[j.dof_adr].ang);
    } else if !no_columns {
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            data.s_world[k] = fused::act_motion::<A>(&x_world_body, &data.s_body[k]);
        }
    }
    data.i_composite[b] = fused::transformed::<A>(&model.bodies[b].inertia, &x_world_body);
}

/// Column k of M (and with `MIRROR` row k): F = Iᶜ S_k, then S_l · F for k and the ancestors l
/// of k (the diagonal with the armature `armature`); at a floating base (`base`, its pose) the
/// base's six entries as one block.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn column<A: MulAdd, const MIRROR: bool>(
    k: usize,
    i_c: &RigidInertia,
    s_world: &[Motion],
    dof_parent: &[usize],
    m: &mut [f64],
    nv: usize,
    armature: f64,
    base: Option<&Transform>,
) {
    let f_world = fused::mul_motion::<A>(i_c, &s_world[k]);
    // Column-major storage: (row l, col k) at l + k·nv; column k holds the chain of k.
    let (before, rest) = m.split_at_mut(k * nv);
    let col_k = &mut rest[..nv];
    col_k[k] = fused::dot::<A>(&s_world[k], &f_world) + armature;
    let mut l = dof_parent[k];
    while l != NO_DOF {
        if let (Some(x_world_base), 5) = (base, l) {
            let moment = fused::cross_add::<A>(&f_world.lin, &x_world_base.pos, &f_world.ang);
            let base_axes = fused::mat_tr_vec::<A>(&x_world_base.rot, &moment);
            let entries =
                [f_world.lin.x, f_world.lin.y, f_world.lin.z, base_axes.x, base_axes.y, base_axes.z];
            col_k[..6].copy_from_slice(&entries);
            if MIRROR {
                for (i, m_ki) in entries.iter().enumerate() {
                    before[k + i * nv] = *m_ki;
                }
            }
            break;
        }
        let m_lk = fused::dot::<A>(&s_world[l], &f_world);
        col_k[l] = m_lk;
        if MIRROR {
            // Row k of the earlier column l (M is symmetric).
            before[k + l * nv] = m_lk;
        }
        l = dof_parent[l];
    }
}

/// The 6×6 block of M on a floating base's own degrees of freedom, from the whole robot's
/// composite inertia `i_c` (world axes: mass m, first moment h and rotational inertia I_O about
/// the reference point O) and the base pose (R, p) about O; `block[k][l]` = M[l][k] (l ≤ k
/// filled). [`crba_kernel`] takes O at the base's own origin (its tree's), so p = 0 there.
///
/// The base's columns are (0, eᵢ) (linear velocity, world axes) and (uᵢ, p × uᵢ) with uᵢ = R eᵢ
/// (angular velocity, base axes). With h_p = h − m p the first moment about the base origin and
/// I_p = I_O + p h_pᵀ + h pᵀ − (h + h_p)·p 1 the rotational inertia about it (RBDA eq. 2.66, the
/// shift by −p), the block is m 1 (linear–linear), (uᵢ × h_p)ₖ (linear k, angular i) and
/// uᵢᵀ I_p uⱼ (angular–angular): ~100 multiply–adds instead of forming six world columns, six
/// products I S and 21 dot products.
#[inline(always)]
fn floating_base_block<A: MulAdd>(i_c: &RigidInertia, x_world_base: &Transform) -> [[f64; 6]; 6] {
    let (r, p, m, h) = (&x_world_base.rot, &x_world_base.pos, i_c.mass, &i_c.h);
    let h_p = Vector3::new(A::madd(-m, p.x, h.x), A::madd(-m, p.y, h.y), A::madd(-m, p.z, h.z));
    // Rᵀ p, Rᵀ h_p, Rᵀ h: the rank-two shift in base axes.
    let a = fused::mat_tr_vec::<A>(r, p);
    let b = fused::mat_tr_vec::<A>(r, &h_p);
    let c = fused::mat_tr_vec::<A>(r, h);
    let diag = -(fused::dot3::<A>(h, p) + fused::dot3::<A>(&h_p, p));
    // T = I_O R, then (Rᵀ I_O R)(i, j) = column i of R · column j of T.
    let t = [
        fused::mat_vec::<A>(&i_c.i_origin, &r.column(0).into_owned()),
        fused::mat_vec::<A>(&i_c.i_origin, &r.column(1).into_owned()),
        fused::mat_vec::<A>(&i_c.i_origin, &r.column(2).into_owned()),
    ];
    let mut block = [[0.0; 6]; 6];
    for i in 0..3 {
        block[i][i] = m;
        let u_i = r.column(i).into_owned();
        let n = fused::cross_add::<A>(&u_i, &h_p, &Vector3::zeros());
        block[3 + i][..3].copy_from_slice(n.as_slice());
        for j in 0..=i {
            let g = fused::dot3::<A>(&r.column(j).into_owned(), &t[i]);
            block[3 + i][3 + j] = A::madd(a[j], b[i], A::madd(c[j], a[i], g));
        }
        block[3 + i][3 + i] += diag;
    }
    block
}

/// Calls `run(s, e)` for the runs `s..=e` of consecutive indices that make up the ancestor chain
/// `from, λ(from), λ(λ(from)), …` (`from` included): along a branch the dofs are numbered one
/// after the other, so the chain is a few runs, each a contiguous slice of a factor column
/// (`Model::dof_run_start`).
#[inline(always)]
fn for_each_run(model: &Model, from: usize, mut run: impl FnMut(usize, usize)) {
    let mut e = from;
    while e != NO_DOF {
        let s = model.dof_run_start[e];
        run(s, e);
        e = model.dof_parent[s];
    }
}

/// Factorizes `data.mass_matrix` as M = Lᵀ D L into `data.mass_factor`, exploiting the tree's
/// sparsity: fill-in stays on the ancestor paths λ (RBDA §6.3, Table 6.3). Run [`crba`] first.
///
/// Storage: column k of `mass_factor` holds row k of L, `L[k][j]` at (j, k) for j an ancestor of
/// k, and D on the diagonal. Row k of L is zero off the ancestor chain of k, and the chain of an
/// ancestor i of k is the part of k's chain below i, so the update `L[i][j] −= a L[k][j]` over
/// the chain of i (RBDA Table 6.3) may run over all j from the chain's first dof to i: one
/// contiguous, vectorizable slice of two columns instead of a walk through λ; the extra terms
/// (other branches of the same tree) subtract zeros, and other trees' dofs are skipped, so a
/// scene of many bodies costs O(nv), not O(nv²). (Walking the chain's runs of consecutive dofs
/// instead, `Model::dof_run_start`, skips those zeros but costs more on robots: 7.7M against
/// 6.5M instructions for the humanoid's 359 factorizations of a 1 s run.)
///
/// A pivot below [`MIN_PIVOT`] (a mass matrix singular at this state: duplicated joints, a moving
/// body without mass or inertia, or not positive) is raised to it, as MuJoCo 4.0's `mj_factorI`
/// does, and recorded in `data.warnings` (`inertia`, with the dofs): the solve then gives
/// MuJoCo's regularized accelerations instead of NaN.
pub fn factorize_mass_matrix(model: &Model, data: &mut Data) {
    factorize_shifted(model, data, None);
}

/// [`factorize_mass_matrix`] of M + h·diag(`damping`) (MuJoCo's `mj_factorI` of M + h D in its
/// implicitly damped Euler step), formed in the factor's storage: M itself is not touched. The
/// diagonal entries are M[k][k] + h·damping[k], the same bits as adding the shift to M first.
pub(crate) fn factorize_mass_matrix_damped(model: &Model, data: &mut Data, h: f64, damping: &[f64]) {
    factorize_shifted(model, data, Some((h, damping)));
}

fn factorize_shifted(model: &Model, data: &mut Data, shift: Option<(f64, &[f64])>) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `factorize_avx2` requires.
        unsafe { factorize_avx2(model, data, shift) };
        return;
    }
    factorize_kernel::<false>(model, data, shift);
}

/// [`factorize_kernel`] compiled for AVX2: its updates four entries wide ([`sub_scaled`]). Rust
/// never fuses a product and a sum unasked, so the factor has the same bits as the portable
/// kernel's.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn factorize_avx2(model: &Model, data: &mut Data, shift: Option<(f64, &[f64])>) {
    factorize_kernel::<true>(model, data, shift);
}

/// The factorization; `AVX2`: the caller is compiled for AVX2 (its updates through
/// [`sub_scaled`]'s vector arm).
#[inline(always)]
fn factorize_kernel<const AVX2: bool>(model: &Model, data: &mut Data, shift: Option<(f64, &[f64])>) {
    let lambda = &model.dof_parent[..model.nv];
    let nv = model.nv;
    let Data { mass_matrix, mass_factor, warnings, .. } = data;
    let m = mass_matrix.as_slice();
    let h = mass_factor.as_mut_slice();
    let mut singular = None;
    // The upper triangle of M (column k of M holds M[j][k] = M[k][j], j ≤ k), from the first dof
    // of k's chain on (`Model::dof_tree_start`): the entries above it are off the chain, never read, so
    // copying them, O(nv²) over many bodies, is not needed.
    for k in 0..nv {
        let lo = model.dof_tree_start[k];
        h[k * nv + lo..=k * nv + k].copy_from_slice(&m[k * nv + lo..=k * nv + k]);
    }
    if let Some((step, damping)) = shift {
        for (k, d) in damping[..nv].iter().enumerate() {
            h[k * nv + k] += step * d;
        }
    }
    for k in (0..nv).rev() {
        let (before, rest) = h.split_at_mut(k * nv);
        let col_k = &mut rest[..nv];
        let mut d_k = col_k[k];
        if d_k < MIN_PIVOT {
            if singular.is_none() {
                warnings.inertia_dofs.fill(false);
                singular = Some(k);
            }
            warnings.pivot_raised(k);
            d_k = MIN_PIVOT;
            col_k[k] = d_k;
        }
        // The ratios L[k][i] = M[k][i] / d_k as products with 1/d_k (as MuJoCo's `mj_factorI`):
        // one division per dof instead of one per pair (k, ancestor i), a humanoid's ~250.
        let inv_d = 1.0 / d_k;
        // Every ancestor of k starts its chain where k's does (the tree's root dof).
        let lo = model.dof_tree_start[k];
        let mut i = lambda[k];
        #[cfg(target_arch = "x86_64")]
        if AVX2 {
            // The loop below through raw pointers: for a humanoid the pairs (k, ancestor i)
            // are many and their updates short, and the slices' bounds checks and the
            // remainder's mask set-up cost more than the arithmetic.
            assert!(k < nv && lo <= k && before.len() == k * nv);
            let (hp, yk) = (before.as_mut_ptr(), col_k.as_mut_ptr());
            let run_start = &model.dof_run_start[..nv];
            while i != NO_DOF {
                assert!(i < k && lo <= i);
                if run_start[i] == lo && i - lo < MAX_TAIL {
                    // SAFETY: as below, for each of the ancestors i, i − 1, …, lo (the rest of
                    // k's chain: one run of consecutive dofs from the tree's first).
                    unsafe { tail_updates(hp, yk, lo, i + 1 - lo, nv, inv_d) };
                    break;
                }
                // SAFETY: i < k (checked), so column i lies in `before` (k · nv entries) and
                // rows lo ..= i < nv of it, and rows lo ..= i of column k (`col_k`, nv long),
                // are inside their slices, which are disjoint; the caller is compiled for AVX2.
                unsafe {
                    let a = *yk.add(i) * inv_d;
                    sub_scaled_avx2(hp.add(i * nv + lo), yk.add(lo), i + 1 - lo, a);
                    *yk.add(i) = a;
                }
                i = lambda[i];
            }
            continue;
        }
        while i != NO_DOF {
            let a = col_k[i] * inv_d;
            // Column k is nonzero only on k's chain, whose rows up to i are i's chain: the
            // update runs over i's span from its chain's first dof (the same bits on the chain
            // as the whole column, without the products with zeros of other trees).
            sub_scaled::<AVX2>(&mut before[i * nv + lo..=i * nv + i], &col_k[lo..=i], a);
            col_k[i] = a;
            i = lambda[i];
        }
    }
    if let Some(first) = singular {
        warnings.singular_factor(first);
    }
}

/// The longest tail of a chain that [`factorize_kernel`] updates in one unrolled block
/// ([`tail_updates`]).
#[cfg(target_arch = "x86_64")]
const MAX_TAIL: usize = 16;

/// The updates of [`factorize_kernel`] for the pairs (k, i) of the last `n` ancestors of k when
/// they are the dofs lo + n − 1, …, lo (the chain's last run, which starts at its tree's first
/// dof: a floating base's six, a serial arm's whole chain), n ≤ [`MAX_TAIL`]: with n known at
/// compile time the triangle of updates (column i's rows lo ..= i for each i) is straight-line
/// code, where the pair-by-pair loop spends more on each short update's set-up than on its
/// arithmetic (a humanoid's 21 dofs below its free joint end their chains with the same six
/// pairs of one to six entries). Each entry gets the same product and difference, the ratio
/// L[k][i] the same product with 1/d_k, in the same order per column: the same bits.
///
/// # Safety
/// Columns lo ..= lo + n − 1 of the factor (rows lo ..= lo + n − 1 of each, `nv` entries apart,
/// from `h`) and rows lo ..= lo + n − 1 of column k (`yk`) are valid and do not overlap.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn tail_updates(h: *mut f64, yk: *mut f64, lo: usize, n: usize, nv: usize, inv_d: f64) {
    // SAFETY: the caller's contract, for each arm.
    unsafe {
        match n {
            1 => tail_block::<1>(h, yk, lo, nv, inv_d),
            2 => tail_block::<2>(h, yk, lo, nv, inv_d),
            3 => tail_block::<3>(h, yk, lo, nv, inv_d),
            4 => tail_block::<4>(h, yk, lo, nv, inv_d),
            5 => tail_block::<5>(h, yk, lo, nv, inv_d),
            6 => tail_block::<6>(h, yk, lo, nv, inv_d),
            7 => tail_block::<7>(h, yk, lo, nv, inv_d),
            8 => tail_block::<8>(h, yk, lo, nv, inv_d),
            9 => tail_block::<9>(h, yk, lo, nv, inv_d),
            10 => tail_block::<10>(h, yk, lo, nv, inv_d),
            11 => tail_block::<11>(h, yk, lo, nv, inv_d),
            12 => tail_block::<12>(h, yk, lo, nv, inv_d),
            13 => tail_block::<13>(h, yk, lo, nv, inv_d),
            14 => tail_block::<14>(h, yk, lo, nv, inv_d),
            15 => tail_block::<15>(h, yk, lo, nv, inv_d),
            _ => tail_block::<MAX_TAIL>(h, yk, lo, nv, inv_d),
        }
    }
}

/// [`tail_updates`] for n = `N`: rows lo ..= lo + N − 1 of column k read once (the updates read
/// them before their ratios replace them: each pair (k, i) reads rows lo ..= i, all below the
/// ratios already written), then for i from the last to lo: a = L[k][i] · inv_d (1/d_k), column i −= a ·
/// (rows lo ..= i of column k), and L[k][i] ← a.
///
/// # Safety
/// As [`tail_updates`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn tail_block<const N: usize>(h: *mut f64, yk: *mut f64, lo: usize, nv: usize, inv_d: f64) {
    // SAFETY: the caller's contract: rows lo ..= lo + N − 1 of column k and of columns
    // lo ..= lo + N − 1 are valid, and distinct.
    unsafe {
        let mut y = [0.0; N];
        for (t, y_t) in y.iter_mut().enumerate() {
            *y_t = *yk.add(lo + t);
        }
        for t in (0..N).rev() {
            let a = y[t] * inv_d;
            let col = h.add((lo + t) * nv + lo);
            for (j, y_j) in y[..=t].iter().enumerate() {
                *col.add(j) -= a * y_j;
            }
            *yk.add(lo + t) = a;
        }
    }
}

/// `x −= a · y` entry by entry over the shorter of the two. With `AVX2` (only in code compiled
/// for AVX2) four entries per instruction and the last one to three one at a time
/// ([`sub_scaled_avx2`]): the factorization's updates are short (a few entries on each of a few
/// hundred pairs for a humanoid), where the compiler's own loop spends more on its set-up (a
/// run-time check that the slices do not overlap, a scalar remainder) than on the arithmetic.
/// Each entry gets the same two operations, a product then a difference, rounded once each: the
/// same bits either way.
#[inline(always)]
fn sub_scaled<const AVX2: bool>(x: &mut [f64], y: &[f64], a: f64) {
    let n = x.len().min(y.len());
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: `AVX2` is set only where the caller is compiled for AVX2 (`factorize_avx2`,
        // `solve_span_avx2`); x and y hold at least n entries each and are distinct borrows.
        unsafe { sub_scaled_avx2(x.as_mut_ptr(), y.as_ptr(), n, a) };
        return;
    }
    for (xj, yj) in x[..n].iter_mut().zip(&y[..n]) {
        *xj -= a * yj;
    }
}

/// [`sub_scaled`]'s vector arm on raw pointers: x[0..n] −= a · y[0..n], four entries per
/// instruction, the last two two-wide and the last one alone (the same product then difference per
/// entry, the same bits). Not through a masked load and store: on AMD Zen a masked store is
/// several times slower than a plain one, and a masked load of entries a masked store has just
/// written is not forwarded from the store buffer (it waits for the store to reach the cache,
/// about 25 cycles) — and these updates rewrite the same few entries again and again (a
/// factor column once per descendant dof, the solve's x once per dof below it).
///
/// # Safety
/// The CPU has AVX2; x and y point to n valid entries each, not overlapping.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn sub_scaled_avx2(x: *mut f64, y: *const f64, n: usize, a: f64) {
    use std::arch::x86_64::{
        _mm256_castpd256_pd128, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_storeu_pd,
        _mm256_sub_pd, _mm_loadu_pd, _mm_mul_pd, _mm_storeu_pd, _mm_sub_pd,
    };
    // SAFETY: the caller's contract (n valid entries at x and y, AVX2).
    unsafe {
        let av = _mm256_set1_pd(a);
        let mut j = 0;
        while j + 4 <= n {
            let (xv, yv) = (_mm256_loadu_pd(x.add(j)), _mm256_loadu_pd(y.add(j)));
            _mm256_storeu_pd(x.add(j), _mm256_sub_pd(xv, _mm256_mul_pd(av, yv)));
            j += 4;
        }
        if j + 2 <= n {
            let (xv, yv) = (_mm_loadu_pd(x.add(j)), _mm_loadu_pd(y.add(j)));
            _mm_storeu_pd(x.add(j), _mm_sub_pd(xv, _mm_mul_pd(_mm256_castpd256_pd128(av), yv)));
            j += 2;
        }
        if j < n {
            *x.add(j) -= a * *y.add(j);
        }
    }
}

/// Solves M x = b in place (`x` holds b on entry) with the factor of [`factorize_mass_matrix`]
/// (RBDA §6.3, Table 6.4): x ← L⁻¹ D⁻¹ L⁻ᵀ b.
///
/// # Errors
/// [`InputError::Length`] when x is not nv long or `data` was made for another model.
pub fn solve_mass_matrix(model: &Model, data: &Data, x: &mut DVector<f64>) -> Result<(), InputError> {
    check::data("solve_mass_matrix", model, data)?;
    check::v("solve_mass_matrix", "x", model, x.as_slice())?;
    solve_with_factor_unchecked(model, &data.mass_factor, x.as_mut_slice());
    Ok(())
}

/// [`solve_mass_matrix`] on a slice, with the factor passed explicitly (so that the right-hand
/// side may be another buffer of the same `Data`).
///
/// # Errors
/// [`InputError::Length`] when x is not nv long or the factor not nv × nv.
pub fn solve_with_factor(model: &Model, factor: &DMatrix<f64>, x: &mut [f64]) -> Result<(), InputError> {
    check::v("solve_with_factor", "x", model, x)?;
    InputError::check_len("solve_with_factor", "factor (rows)", factor.nrows(), model.nv, "nv")?;
    InputError::check_len("solve_with_factor", "factor (columns)", factor.ncols(), model.nv, "nv")?;
    solve_with_factor_unchecked(model, factor, x);
    Ok(())
}

/// [`solve_with_factor`] without the argument checks.
pub(crate) fn solve_with_factor_unchecked(model: &Model, factor: &DMatrix<f64>, x: &mut [f64]) {
    solve_with_factor_span_unchecked(model, factor, x, (0, model.nv));
}

/// The dofs [lo, hi) of the kinematic trees that dofs `first` ..= `last` belong to: M is
/// block-diagonal over trees (M_ij ≠ 0 only on one ancestor chain) and each tree's dofs are
/// contiguous in depth-first order, so M⁻¹ b for a b that is zero outside [first, last] is zero
/// outside [lo, hi) ([`solve_with_factor_span_unchecked`]).
pub(crate) fn tree_span(model: &Model, first: usize, last: usize) -> (usize, usize) {
    let parent = &model.dof_parent[..model.nv];
    let mut lo = first;
    while parent[lo] != NO_DOF {
        lo = parent[lo];
    }
    let mut hi = last + 1;
    while hi < model.nv && parent[hi] != NO_DOF {
        hi += 1;
    }
    (lo, hi)
}

/// [`solve_with_factor_unchecked`] for a right-hand side that is zero outside the trees' span
/// [lo, hi) of [`tree_span`]: the same arithmetic on those dofs (the others stay zero), in
/// time proportional to the span instead of nv. Lᵀ z = b from the leaves up (x[chain of λ(i)]
/// −= L[i][·] x[i]), D w = z, then L x = w from the root down (x[i] −= L[i][·] · x[chain of
/// λ(i)]).
pub(crate) fn solve_with_factor_span_unchecked(
    model: &Model,
    factor: &DMatrix<f64>,
    x: &mut [f64],
    span: (usize, usize),
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `solve_span_avx2` requires.
        unsafe { solve_span_avx2(model, factor, x, span) };
        return;
    }
    solve_span_kernel::<false>(model, factor, x, span);
}

/// [`solve_span_kernel`] compiled for AVX2: the updates of Lᵀ z = b four entries wide
/// ([`sub_scaled`]), the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn solve_span_avx2(model: &Model, factor: &DMatrix<f64>, x: &mut [f64], span: (usize, usize)) {
    solve_span_kernel::<true>(model, factor, x, span);
}

/// [`solve_with_factor_span_unchecked`]; `AVX2`: the caller is compiled for AVX2.
#[inline(always)]
fn solve_span_kernel<const AVX2: bool>(
    model: &Model,
    factor: &DMatrix<f64>,
    x: &mut [f64],
    (lo, hi): (usize, usize),
) {
    let lambda = &model.dof_parent[..model.nv];
    let nv = model.nv;
    let h = factor.as_slice();
    let x = &mut x[..nv];
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        solve_span_runs_avx2(model, h, x, (lo, hi));
        return;
    }
    for i in (lo..hi).rev() {
        let (col_i, x_i) = (&h[i * nv..(i + 1) * nv], x[i]);
        if lambda[i] != NO_DOF {
            for_each_run(model, lambda[i], |s, e| sub_scaled::<AVX2>(&mut x[s..=e], &col_i[s..=e], x_i));
        }
    }
    for i in lo..hi {
        x[i] /= h[i + i * nv];
    }
    for i in lo..hi {
        let col_i = &h[i * nv..(i + 1) * nv];
        let mut acc = 0.0;
        if lambda[i] != NO_DOF {
            for_each_run(model, lambda[i], |s, e| {
                acc += x[s..=e].iter().zip(&col_i[s..=e]).map(|(xj, l)| xj * l).sum::<f64>();
            });
        }
        x[i] -= acc;
    }
}

/// [`solve_span_kernel`]'s AVX2 arm: the same runs, products, differences and sums in the same
/// order (the same bits), with the runs walked through raw pointers — for a humanoid a solve is
/// a few hundred short runs, where the slices' bounds checks cost more than the arithmetic.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn solve_span_runs_avx2(model: &Model, h: &[f64], x: &mut [f64], (lo, hi): (usize, usize)) {
    let nv = model.nv;
    let (lambda, run_start) = (&model.dof_parent[..nv], &model.dof_run_start[..nv]);
    assert!(h.len() >= nv * nv && x.len() == nv && hi <= nv);
    let (hp, xp) = (h.as_ptr(), x.as_mut_ptr());
    // The run s ..= e that ends at dof e, checked inside x and a factor column.
    let run = |e: usize| {
        let s = run_start[e];
        assert!(s <= e && e < nv);
        s
    };
    for i in (lo..hi).rev() {
        // SAFETY: i < hi ≤ nv, so x[i] and column i (nv entries from i · nv) are inside x and h.
        let (col, x_i) = unsafe { (hp.add(i * nv), *xp.add(i)) };
        let mut e = lambda[i];
        while e != NO_DOF {
            let s = run(e);
            // SAFETY: s ≤ e < nv (checked): entries s ..= e of x and of column i, which do not
            // overlap (x and h are distinct borrows); the caller is compiled for AVX2.
            unsafe { sub_scaled_run(xp.add(s), col.add(s), e + 1 - s, x_i) };
            e = lambda[s];
        }
    }
    for i in lo..hi {
        x[i] /= h[i + i * nv];
    }
    for i in lo..hi {
        let col = &h[i * nv..(i + 1) * nv];
        let mut acc = 0.0;
        let mut e = lambda[i];
        while e != NO_DOF {
            let s = run(e);
            // SAFETY: s ≤ e < nv (checked), inside both slices of nv entries.
            acc += unsafe { dot_run(x.as_ptr().add(s), col.as_ptr().add(s), e + 1 - s) };
            e = lambda[s];
        }
        x[i] -= acc;
    }
}

/// [`sub_scaled_avx2`] for a run of the solve: runs of up to eight dofs (a robot's chains are
/// made of such: a floating base's six, a limb's two or three) with their length known at
/// compile time, straight-line code instead of the general loop's branches. Each entry gets the
/// same product then difference: the same bits.
///
/// # Safety
/// As [`sub_scaled_avx2`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn sub_scaled_run(x: *mut f64, y: *const f64, n: usize, a: f64) {
    /// x[0..N] −= a · y[0..N].
    #[inline(always)]
    unsafe fn fixed<const N: usize>(x: *mut f64, y: *const f64, a: f64) {
        // SAFETY: the caller's contract (N valid entries at x and y, not overlapping).
        unsafe {
            let (x, y) = (&mut *(x as *mut [f64; N]), &*(y as *const [f64; N]));
            for (xj, yj) in x.iter_mut().zip(y) {
                *xj -= a * yj;
            }
        }
    }
    // SAFETY: the caller's contract, for each arm.
    unsafe {
        match n {
            1 => fixed::<1>(x, y, a),
            2 => fixed::<2>(x, y, a),
            3 => fixed::<3>(x, y, a),
            4 => fixed::<4>(x, y, a),
            5 => fixed::<5>(x, y, a),
            6 => fixed::<6>(x, y, a),
            7 => fixed::<7>(x, y, a),
            8 => fixed::<8>(x, y, a),
            _ => sub_scaled_avx2(x, y, n, a),
        }
    }
}

/// Σ x[j] · l[j] over a run of n entries, summed in order from the first (as the iterator sum of
/// [`solve_span_kernel`]: the same bits), runs of up to eight unrolled.
///
/// # Safety
/// x and l point to n valid entries each.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn dot_run(x: *const f64, l: *const f64, n: usize) -> f64 {
    /// The sum over N entries.
    #[inline(always)]
    unsafe fn fixed<const N: usize>(x: *const f64, l: *const f64) -> f64 {
        // SAFETY: the caller's contract (N valid entries at x and l).
        let (x, l) = unsafe { (&*(x as *const [f64; N]), &*(l as *const [f64; N])) };
        x.iter().zip(l).map(|(xj, lj)| xj * lj).sum::<f64>()
    }
    // SAFETY: the caller's contract, for each arm.
    unsafe {
        match n {
            1 => fixed::<1>(x, l),
            2 => fixed::<2>(x, l),
            3 => fixed::<3>(x, l),
            4 => fixed::<4>(x, l),
            5 => fixed::<5>(x, l),
            6 => fixed::<6>(x, l),
            7 => fixed::<7>(x, l),
            8 => fixed::<8>(x, l),
            _ => {
                let (xs, ls) = (std::slice::from_raw_parts(x, n), std::slice::from_raw_parts(l, n));
                xs.iter().zip(ls).map(|(xj, lj)| xj * lj).sum::<f64>()
            }
        }
    }
}

/// Solves M X = B for many right-hand sides at once, with the factor of
/// [`factorize_mass_matrix`], on the transposes: `y` (n × nv, column-major) holds Bᵀ on entry and
/// Xᵀ on return, so that each step of the tree-sparse solve is an update of whole contiguous
/// columns (one per dof) across every right-hand side — the same arithmetic per right-hand side
/// as [`solve_with_factor_unchecked`], vectorized across them.
pub(crate) fn solve_transposed_with_factor_unchecked(
    model: &Model,
    factor: &DMatrix<f64>,
    y: &mut DMatrix<f64>,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `solve_transposed_avx2` requires.
        unsafe { solve_transposed_avx2(model, factor, y) };
        return;
    }
    solve_transposed_kernel(model, factor, y);
}

/// [`solve_transposed_kernel`] compiled for AVX2: the same operations in the same order (no
/// fused multiply–adds), four right-hand sides per instruction, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn solve_transposed_avx2(model: &Model, factor: &DMatrix<f64>, y: &mut DMatrix<f64>) {
    solve_transposed_kernel(model, factor, y);
}

#[inline(always)]
fn solve_transposed_kernel(model: &Model, factor: &DMatrix<f64>, y: &mut DMatrix<f64>) {
    let lambda = &model.dof_parent[..model.nv];
    let nv = model.nv;
    let n = y.nrows();
    let h = factor.as_slice();
    let y = y.as_mut_slice();
    // Lᵀ Z = B: column j of Y (row j of X) −= L[i][j] · column i, from the leaves up.
    for i in (0..nv).rev() {
        if lambda[i] == NO_DOF {
            continue;
        }
        let col_l = &h[i * nv..(i + 1) * nv];
        let (before, rest) = y.split_at_mut(i * n);
        let y_i = &rest[..n];
        // The ancestor chain run by run, written out (not through the closure helper) so that
        // the loop is compiled with the caller's target features.
        let mut e = lambda[i];
        while e != NO_DOF {
            let s = model.dof_run_start[e];
            for j in s..=e {
                let l = col_l[j];
                if l != 0.0 {
                    for (a, b) in before[j * n..(j + 1) * n].iter_mut().zip(y_i) {
                        *a -= l * b;
                    }
                }
            }
            e = model.dof_parent[s];
        }
    }
    // D W = Z.
    for i in 0..nv {
        let d = 1.0 / h[i + i * nv];
        for a in &mut y[i * n..(i + 1) * n] {
            *a *= d;
        }
    }
    // L X = W, from the root down: column i −= Σ L[i][j] · column j.
    for i in 0..nv {
        if lambda[i] == NO_DOF {
            continue;
        }
        let col_l = &h[i * nv..(i + 1) * nv];
        let (before, rest) = y.split_at_mut(i * n);
        let y_i = &mut rest[..n];
        // The ancestor chain run by run, written out (not through the closure helper) so that
        // the loop is compiled with the caller's target features.
        let mut e = lambda[i];
        while e != NO_DOF {
            let s = model.dof_run_start[e];
            for j in s..=e {
                let l = col_l[j];
                if l != 0.0 {
                    for (a, b) in y_i.iter_mut().zip(&before[j * n..(j + 1) * n]) {
                        *a -= l * b;
                    }
                }
            }
            e = model.dof_parent[s];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `crba_upper` writes exactly `crba`'s upper triangle and leaves the lower one alone.
    #[test]
    fn upper_triangle_is_crbas() {
        for (file, model, q) in crate::kernel_test_states::robots() {
            let mut data = Data::new(&model);
            let full = crba(&model, &mut data, &q).unwrap().clone();
            data.mass_matrix.fill(7.0);
            let upper = crba_upper(&model, &mut data, &q).unwrap();
            for k in 0..model.nv {
                let mut chain = vec![k];
                while let Some(&l) = chain.last().filter(|&&l| model.dof_parent[l] != NO_DOF) {
                    chain.push(model.dof_parent[l]);
                }
                for l in 0..model.nv {
                    let want = if chain.contains(&l) { full[(l, k)] } else { 7.0 };
                    assert_eq!(upper[(l, k)].to_bits(), want.to_bits(), "{file} ({l}, {k})");
                }
            }
        }
    }

    /// The kernel tests' robots and the humanoid (free joint, legs of one and two runs of dofs)
    /// with its hinges away from zero (the free joint's unit quaternion kept).
    #[cfg(target_arch = "x86_64")]
    fn robots_and_humanoid() -> Vec<(&'static str, Model, Vec<f64>)> {
        let mut cases = crate::kernel_test_states::robots();
        let file = "models/mjcf/humanoid/humanoid.xml";
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let humanoid = crate::io::load(&path, &Default::default()).unwrap();
        let mut q = humanoid.neutral();
        for (i, x) in q.iter_mut().enumerate().skip(7) {
            *x += 0.1 + 0.37 * (i as f64).sin();
        }
        cases.push((file, humanoid, q));
        cases
    }

    /// The AVX2 build of the factorization (its pair-by-pair updates and straight-line tails,
    /// `tail_updates`) gives the portable build's factor bit for bit, of M and of M + h·diag(d),
    /// on the panda (one run), solo12 and the humanoid (free joints, legs of one and two runs).
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2) build of the kernel with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn avx2_factor_is_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: this CPU has no AVX2, the AVX2 factorization is never used here");
            return;
        }
        for (file, model, q) in robots_and_humanoid() {
            let damping: Vec<f64> = (0..model.nv).map(|k| 0.5 + 0.1 * k as f64).collect();
            for shift in [None, Some((0.002, damping.as_slice()))] {
                let mut portable = Data::new(&model);
                crba_unchecked(&model, &mut portable, &q);
                let mut avx2 = portable.clone();
                factorize_kernel::<false>(&model, &mut portable, shift);
                // SAFETY: the CPU has AVX2 (checked above).
                unsafe { factorize_avx2(&model, &mut avx2, shift) };
                let (a, b) = (portable.mass_factor.as_slice(), avx2.mass_factor.as_slice());
                assert!(a.iter().any(|&x| x != 0.0), "{file}: an empty factor");
                for (i, (x, y)) in a.iter().zip(b).enumerate() {
                    assert_eq!(x.to_bits(), y.to_bits(), "{file} {shift:?}: entry {i}");
                }
            }
        }
    }

    /// The AVX2 solve (runs of up to eight dofs unrolled, `sub_scaled_run`, `dot_run`) gives the
    /// portable solve's bits, on the robots and the humanoid, for a right-hand side with signed
    /// zeros and mixed magnitudes.
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2) build of the kernel with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn avx2_solve_is_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: this CPU has no AVX2, the AVX2 solve is never used here");
            return;
        }
        for (file, model, q) in robots_and_humanoid() {
            let mut data = Data::new(&model);
            crba_unchecked(&model, &mut data, &q);
            factorize_mass_matrix(&model, &mut data);
            let b: Vec<f64> = (0..model.nv)
                .map(
                    |k| if k % 7 == 3 { -0.0 } else { (k as f64 * 1.7).sin() * 10f64.powi(k as i32 % 4 - 2) },
                )
                .collect();
            let (mut portable, mut avx2) = (b.clone(), b);
            solve_span_kernel::<false>(&model, &data.mass_factor, &mut portable, (0, model.nv));
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { solve_span_avx2(&model, &data.mass_factor, &mut avx2, (0, model.nv)) };
            for (i, (x, y)) in portable.iter().zip(&avx2).enumerate() {
                assert_eq!(x.to_bits(), y.to_bits(), "{file}: entry {i}");
            }
        }
    }

    /// The FMA build of the kernel gives the M of the separate multiply–adds to round-off
    /// (cross-check tolerance), and M stays symmetric bit for bit.
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2/FMA) build of the kernel with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn fma_kernel_matches_separate_multiply_adds() {
        if !crate::kernel_test_states::fma_available() {
            return;
        }
        for (file, model, q) in crate::kernel_test_states::robots() {
            let mut data = Data::new(&model);
            crba_kernel::<Separate, true>(&model, &mut data, &q);
            let baseline = data.mass_matrix.clone();
            data.mass_matrix.fill(0.0);
            // SAFETY: AVX2 and FMA are present (checked above).
            unsafe { crba_fma::<true>(&model, &mut data, &q) };
            let m = &data.mass_matrix;
            let scale = baseline.amax();
            assert!((m - &baseline).amax() <= 1e-12 * scale, "{file}: {:e}", (m - &baseline).amax());
            assert_eq!(m, &m.transpose(), "{file}");
        }
    }
}
