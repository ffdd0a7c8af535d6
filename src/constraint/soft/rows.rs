//! The rows of the soft (MuJoCo-compatible) mode, in MuJoCo's order and with MuJoCo's activation
//! rules (MuJoCo documentation, "Computation → Constraint model"; MuJoCo's
//! `mj_instantiateEquality`, `mj_instantiateFriction`, `mj_instantiateLimit`,
//! `mj_instantiateContact`):
//!
//! - equality: the rows of the exact mode, except that a weld's rotation rows are MuJoCo's
//!   quaternion error r = s · imag(q_B⁻¹ q_A) with J = s · ½ imag(q_B⁻¹ (0, ω_A − ω_B) q_A)
//!   (s = `torquescale`, q_A the orientation frame A must have, q_B that of frame B);
//! - friction loss: one row per dof, always present, its bound in `efc_frictionloss`;
//! - limits: a hinge or slide row for each bound with distance below the joint's `margin` (both
//!   bounds can be active at once), a ball joint's cone row likewise; `efc_margin` = margin;
//! - contacts: every contact closer than its `includemargin` (the pair's margin). condim 1 gives one
//!   frictionless row; with friction, the pyramidal cone (`<option cone="pyramidal">`, MuJoCo's
//!   default) gives 2(d − 1) rows J_n ± μ_i J_i, the elliptic cone d rows (normal, tangents,
//!   torsion, rolling). The normal (or every pyramidal) row has `efc_pos` = dist.
//!
//! `efc_vel` = J v for every row; `efc_jdotv` is J̇ v of connect and weld rows (MuJoCo 4
//! subtracts it from their reference acceleration), 0 elsewhere.

use super::contact_columns::contact_jacobian_columns;
use crate::constraint::limits::{quat_angle_axis, LimitKind, LimitRow};
use crate::constraint::rows::EqualityRows;
use crate::constraint::rows::{point_motion, RowGeometry};
use crate::constraint::ConstraintModel;
use crate::kinematics::bias_accelerations_unchecked;
use crate::model::{options::Cone, Data, EfcType, Model};
use crate::spatial::{Mat3, Transform, Vec3};

/// A quaternion [w, x, y, z] and the Hamilton product.
pub(crate) type Quat = [f64; 4];

fn qmul(a: &Quat, b: &Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

pub(crate) fn conj(q: &Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

fn pure(v: &Vec3) -> Quat {
    [0.0, v[0], v[1], v[2]]
}

/// The world orientations (quaternions) of a weld's frames A (where frame B must be) and B.
pub(crate) fn weld_quats(
    data: &Data,
    e: &EqualityRows,
    a: usize,
    x_a: &Transform,
    b: usize,
    x_b: &Transform,
) -> (Quat, Quat) {
    let qa = (e.side_pose(data, 0, a) * *x_a).quat_wxyz();
    let qb = (e.side_pose(data, 1, b) * *x_b).quat_wxyz();
    (qa, qb)
}

/// The 3 × 3 map ω ↦ ½ imag(q_B⁻¹ (0, ω) q_A) of a weld's rotation Jacobian.
pub(crate) fn weld_rotation_map(qa: &Quat, qb_inv: &Quat) -> Mat3 {
    let mut t = Mat3::zeros();
    for k in 0..3 {
        let mut e = Vec3::zeros();
        e[k] = 1.0;
        let p = qmul(&qmul(qb_inv, &pure(&e)), qa);
        for i in 0..3 {
            t[(i, k)] = 0.5 * p[i + 1];
        }
    }
    t
}

/// Upper bound on the soft rows at the current contacts.
fn row_bound(cm: &ConstraintModel, model: &Model, data: &Data) -> usize {
    let eq: usize = cm
        .equalities
        .iter()
        .filter(|e| data.sleep.equality_has_rows(model, e.id, data.eq_active[e.id]))
        .map(|e| model.equalities[e.id].kind.nrow())
        .sum();
    let contacts: usize = data.contacts.iter().map(|c| 2 * (c.condim.clamp(1, 6) as usize)).sum();
    eq + cm.friction.len()
        + cm.tendon_friction.len()
        + 2 * cm.limits.len()
        + 2 * cm.tendon_limits.len()
        + contacts
}

/// Writes the soft rows at configuration `q` (body poses and motion subspaces at q, and
/// `Data::contacts` from a collision pass at q): `nefc`, `ne`, `nf`, `efc_type`, `efc_id`,
/// `efc_j`, `efc_pos`, `efc_margin`, `efc_frictionloss`.
pub(crate) fn soft_positions(cm: &ConstraintModel, model: &Model, data: &mut Data, q: &[f64], cone: Cone) {
    let bound = row_bound(cm, model, data);
    data.reserve_soft_rows(bound);
    let ne = cm.equality_rows(model, data, q);
    // Rows ne..bound start at zero: the last position stage's nonzeros cleared when they are
    // recorded (`jacobian.rs`: every other entry is zero already), else every row from ne on,
    // column by column (contiguous in J's storage) rather than row by row (strided).
    if data.soft.j_recorded {
        let Data { efc_j, soft, .. } = &mut *data;
        super::jacobian::clear_recorded(efc_j, ne, &soft.nz_start, &soft.nz_index, &soft.contact_blocks);
    } else {
        let stride = data.efc_j.nrows();
        let nv = model.nv;
        let j = data.efc_j.as_mut_slice();
        for c in 0..nv {
            j[c * stride + ne..(c + 1) * stride].fill(0.0);
        }
    }
    data.efc_margin.rows_mut(0, ne).fill(0.0);
    data.efc_frictionloss.rows_mut(0, ne).fill(0.0);
    // MuJoCo's weld rotation rows.
    let mut r = 0;
    for e in &cm.equalities {
        if !data.sleep.equality_has_rows(model, e.id, data.eq_active[e.id]) {
            continue;
        }
        let n = model.equalities[e.id].kind.nrow();
        if let RowGeometry::Frames { a, x_a, b, x_b, torquescale } = &e.geometry {
            if n == 6 {
                let (qa, qb) = weld_quats(data, e, *a, x_a, *b, x_b);
                let qb_inv = conj(&qb);
                let err = qmul(&qb_inv, &qa);
                for k in 0..3 {
                    data.efc_pos[r + 3 + k] = torquescale * err[k + 1];
                }
                // The rows hold s (J_ω,A − J_ω,B): map each column.
                let t = weld_rotation_map(&qa, &qb_inv);
                for c in 0..model.nv {
                    let w = Vec3::new(data.efc_j[(r + 3, c)], data.efc_j[(r + 4, c)], data.efc_j[(r + 5, c)]);
                    if w != Vec3::zeros() {
                        let m = t * w;
                        for k in 0..3 {
                            data.efc_j[(r + 3 + k, c)] = m[k];
                        }
                    }
                }
            }
        }
        r += n;
    }
    let mut r = ne;
    // Sleeping islands: a sleeping tree's own rows are left out (`forward::sleep`).
    for f in &cm.friction {
        if data.sleep.dof_asleep(model, f.dof) {
            continue;
        }
        f.write_row(data, r);
        data.efc_margin[r] = 0.0;
        data.efc_frictionloss[r] = f.loss;
        r += 1;
    }
    for &t in &cm.tendon_friction {
        data.efc_id[r] = t;
        data.efc_type[r] = EfcType::FrictionTendon;
        data.efc_j.row_mut(r).copy_from(&data.ten_j.row(t));
        data.efc_pos[r] = 0.0;
        data.efc_margin[r] = 0.0;
        data.efc_frictionloss[r] = model.tendons[t].frictionloss;
        r += 1;
    }
    let nf = r - ne;
    // With no row before the joint limits and no tendon limit after them, the limit rows are
    // recorded as they are written (their nonzeros, ascending: what `record`'s scan of J's
    // columns would list) instead of by that scan.
    let direct = r == 0 && cm.tendon_limits.is_empty();
    if direct {
        let soft = &mut data.soft;
        soft.nz_start.clear();
        soft.nz_start.push(0);
        soft.nz_index.clear();
        soft.nz_value.clear();
    }
    for l in &cm.limits {
        if data.sleep.dof_asleep(model, l.dof_adr) {
            continue;
        }
        let margin = model.joints[l.joint].soft.margin;
        let ndof = if matches!(l.kind, LimitKind::Cone { .. }) { 3 } else { 1 };
        for (dist, dir) in joint_limit_sides(l, q, margin).into_iter().flatten() {
            data.efc_id[r] = l.joint;
            data.efc_type[r] = EfcType::LimitJoint;
            for k in 0..ndof {
                data.efc_j[(r, l.dof_adr + k)] = dir[k];
                if direct && dir[k] != 0.0 {
                    data.soft.nz_index.push(l.dof_adr + k);
                    data.soft.nz_value.push(dir[k]);
                }
            }
            if direct {
                let end = data.soft.nz_index.len();
                data.soft.nz_start.push(end);
            }
            data.efc_pos[r] = dist;
            data.efc_margin[r] = margin;
            data.efc_frictionloss[r] = 0.0;
            r += 1;
        }
    }
    r = tendon_limit_rows(model, &cm.tendon_limits, data, r);
    // J's nonzeros, for the velocity stage, the solvers and the next clear (`jacobian.rs`): the
    // rows so far by a scan of their columns (unless recorded above), each contact's rows as
    // they are written.
    if !direct {
        let Data { efc_j, soft, .. } = &mut *data;
        super::jacobian::record(
            efc_j,
            r,
            &mut soft.nz_start,
            &mut soft.nz_index,
            &mut soft.nz_value,
            &mut soft.nz_scratch,
        );
    }
    data.nefc = contact_rows(model, data, r, cone);
    data.ne = ne;
    data.nf = nf;
    data.soft.j_recorded = true;
}

/// The limit rows of the limited tendons `tendons` (`ConstraintModel::tendon_limits`) from
/// row `r` on (MuJoCo's `mj_instantiateLimit`: a row per bound closer than the tendon's margin,
/// J = ±∂L/∂q = ±`ten_J`); returns the next free row.
fn tendon_limit_rows(model: &Model, tendons: &[usize], data: &mut Data, mut r: usize) -> usize {
    for &t in tendons {
        let tendon = &model.tendons[t];
        for (dist, sign) in tendon_limit_sides(model, data, t).into_iter().flatten() {
            data.efc_id[r] = t;
            data.efc_type[r] = EfcType::LimitTendon;
            for c in 0..model.nv {
                data.efc_j[(r, c)] = sign * data.ten_j[(t, c)];
            }
            data.efc_pos[r] = dist;
            data.efc_margin[r] = tendon.soft.margin;
            data.efc_frictionloss[r] = 0.0;
            r += 1;
        }
    }
    r
}

/// The bounds of joint limit `l` closer than `margin` at `q` (MuJoCo's `mj_instantiateLimit`),
/// each as (distance, J over the joint's dofs): hinge/slide (q − lower, +1) and (upper − q, −1),
/// the first entry of the vector used; a ball its cone, (θmax − θ, −n) over its three dofs.
fn joint_limit_sides(l: &LimitRow, q: &[f64], margin: f64) -> [Option<(f64, Vec3)>; 2] {
    let within = |dist: f64, dir: Vec3| (dist < margin).then_some((dist, dir));
    match l.kind {
        LimitKind::Scalar { range } => {
            let x = q[l.qpos_adr];
            [within(x - range[0], Vec3::x()), within(range[1] - x, -Vec3::x())]
        }
        LimitKind::Cone { max_angle } => {
            let qq = &q[l.qpos_adr..l.qpos_adr + 4];
            let norm = qq.iter().map(|x| x * x).sum::<f64>().sqrt();
            let (angle, axis) = quat_angle_axis(&[qq[0] / norm, qq[1] / norm, qq[2] / norm, qq[3] / norm]);
            [within(max_angle - angle, -axis), None]
        }
    }
}

/// The bounds of tendon `t`'s length limit closer than its margin at the evaluation's
/// `ten_length`, each as (distance, sign of J = ±∂L/∂q); none for an unlimited tendon.
fn tendon_limit_sides(model: &Model, data: &Data, t: usize) -> [Option<(f64, f64)>; 2] {
    let tendon = &model.tendons[t];
    let Some(range) = tendon.range else {
        return [None, None];
    };
    let length = data.ten_length[t];
    let within = |dist: f64, sign: f64| (dist < tendon.soft.margin).then_some((dist, sign));
    [within(length - range[0], 1.0), within(range[1] - length, -1.0)]
}

/// The contact rows from row `r` on, their nonzeros appended to the record of J's
/// (`jacobian.rs`, rows 0..r recorded) and written to `efc_j`; returns the next free row.
///
/// Each contact's frame rows (normal, tangents, torsion, rolling) are formed compactly over the
/// dofs that move one body and not the other (`contact_jacobian_columns`); a pyramidal cone's
/// rows are the edges J_n ± μ_i J_i of those. A row's record holds the columns where any of the
/// contact's rows is nonzero (its rows share their columns, as the Hessian's grouping expects),
/// exact zeros included.
fn contact_rows(model: &Model, data: &mut Data, mut r: usize, cone: Cone) -> usize {
    let Data {
        contacts,
        efc_j,
        efc_id,
        efc_type,
        efc_pos,
        efc_margin,
        efc_frictionloss,
        x_world_body,
        s_body,
        soft,
        ..
    } = &mut *data;
    let stride = efc_j.nrows();
    let j = efc_j.as_mut_slice();
    let (efc_pos, efc_margin, efc_frictionloss) =
        (efc_pos.as_mut_slice(), efc_margin.as_mut_slice(), efc_frictionloss.as_mut_slice());
    soft.dof_axes.forget();
    soft.contact_blocks.clear();
    for (c, contact) in contacts.iter().enumerate() {
        if contact.dist >= contact.includemargin {
            continue;
        }
        let dim = contact.condim.clamp(1, 6) as usize;
        let pyramidal = dim > 1 && cone != Cone::Elliptic;
        let (rows, kind) = if dim == 1 {
            (1, EfcType::ContactFrictionless)
        } else if pyramidal {
            (2 * (dim - 1), EfcType::ContactPyramidal)
        } else {
            (dim, EfcType::ContactElliptic)
        };
        let (columns, values) = (&mut soft.columns, &mut soft.column_values);
        contact_jacobian_columns(
            model,
            x_world_body,
            s_body,
            &mut soft.dof_axes,
            contact,
            dim,
            columns,
            values,
        );
        if pyramidal && dim == 3 {
            // condim 3 (MJCF's default): the four edges of `pyramidal3`, written to J and the
            // record in one pass.
            let friction = [contact.friction[0], contact.friction[1]];
            pyramidal3(
                columns,
                values,
                friction,
                &mut soft.edge4,
                j,
                stride,
                r,
                &mut soft.nz_index,
                &mut soft.nz_value,
            );
        } else {
            if pyramidal {
                // The edges J_n ± μ_k J_k (pair k − 1 in rows 2k − 2, 2k − 1) in place of the
                // frame rows, and only the columns where an edge is nonzero. Each column's edges
                // are written in the next free slot, which moves on only when one of them is
                // nonzero.
                let mut kept = 0;
                for t in 0..columns.len() {
                    let v = &values[t];
                    let e = &mut soft.edge_values[kept];
                    for k in 1..dim {
                        let mu = contact.friction[k - 1];
                        e[2 * k - 2] = v[0] + mu * v[k];
                        e[2 * k - 1] = v[0] - mu * v[k];
                    }
                    if e[..rows].iter().any(|&x| x != 0.0) {
                        columns[kept] = columns[t];
                        kept += 1;
                    }
                }
                columns.truncate(kept);
            }
            // J is stored by columns: each column's rows r..r + rows are contiguous.
            let n = columns.len();
            for t in 0..n {
                let column = &mut j[columns[t] * stride + r..][..rows];
                if pyramidal {
                    column.copy_from_slice(&soft.edge_values[t][..rows]);
                } else {
                    column.copy_from_slice(&soft.column_values[t][..rows]);
                }
            }
            // The record: each row over the same columns (exact-size extends, one capacity
            // check per row).
            for i in 0..rows {
                soft.nz_index.extend_from_slice(columns);
                if pyramidal {
                    soft.nz_value.extend(soft.edge_values[..n].iter().map(|e| e[i]));
                } else {
                    soft.nz_value.extend(soft.column_values.iter().map(|v| v[i]));
                }
                soft.nz_start.push(soft.nz_index.len());
            }
        }
        // The record's row ends (`pyramidal3` appends no starts), and the rows as one block for
        // the next clear.
        if pyramidal && dim == 3 {
            let n = columns.len();
            for _ in 0..rows {
                let end = soft.nz_start.last().copied().unwrap_or(0) + n;
                soft.nz_start.push(end);
            }
        }
        soft.contact_blocks.push((r, rows));
        for i in 0..rows {
            let row = r + i;
            efc_id[row] = c;
            efc_type[row] = kind;
            let first = i == 0 || pyramidal;
            efc_pos[row] = if first { contact.dist } else { 0.0 };
            efc_margin[row] = if first { contact.includemargin } else { 0.0 };
            efc_frictionloss[row] = 0.0;
        }
        r += rows;
    }
    r
}

/// A pyramidal contact of condim 3 from its frame rows' compact columns (`columns`, `values`:
/// normal, two tangents): the edges J_n + μ₁ J_t1, J_n − μ₁ J_t1, J_n + μ₂ J_t2, J_n − μ₂ J_t2
/// (the products and sums of the general loop in `contact_rows`, the same bits), only the
/// columns where an edge is nonzero kept in `columns`; each kept column's four values written
/// to rows r..r + 4 of J (stored by columns, `stride` rows) and the four rows appended to the
/// record's `index` and `value` (row by row over the kept columns; the caller appends the row
/// starts). `edges` is scratch of at least `columns.len()` entries.
#[allow(clippy::too_many_arguments)]
fn pyramidal3(
    columns: &mut Vec<usize>,
    values: &[[f64; 6]],
    friction: [f64; 2],
    edges: &mut [[f64; 4]],
    j: &mut [f64],
    stride: usize,
    r: usize,
    index: &mut Vec<usize>,
    value: &mut Vec<f64>,
) {
    let [mu1, mu2] = friction;
    let mut kept = 0;
    for t in 0..columns.len().min(values.len()).min(edges.len()) {
        let v = &values[t];
        let e = [v[0] + mu1 * v[1], v[0] - mu1 * v[1], v[0] + mu2 * v[2], v[0] - mu2 * v[2]];
        // Each column's edges go to the next free slot, which moves on only when one is nonzero.
        edges[kept] = e;
        if (e[0] != 0.0) | (e[1] != 0.0) | (e[2] != 0.0) | (e[3] != 0.0) {
            if let Some(column) = j.get_mut(columns[t] * stride + r..columns[t] * stride + r + 4) {
                column.copy_from_slice(&e);
            }
            columns[kept] = columns[t];
            kept += 1;
        }
    }
    columns.truncate(kept);
    let n = kept;
    for _ in 0..4 {
        index.extend_from_slice(columns);
    }
    let base = value.len();
    value.resize(base + 4 * n, 0.0);
    let (v0, rest) = value[base..].split_at_mut(n);
    let (v1, rest) = rest.split_at_mut(n);
    let (v2, v3) = rest.split_at_mut(n);
    for ((((e, a), b), c), d) in edges[..n].iter().zip(v0).zip(v1).zip(v2).zip(v3) {
        (*a, *b, *c, *d) = (e[0], e[1], e[2], e[3]);
    }
}

/// `efc_vel` = J v of every row and `efc_jdotv` of connect and weld rows (0 elsewhere), at the
/// state of [`soft_positions`]. Needs the body velocities (`v_body`).
pub(crate) fn soft_velocities(cm: &ConstraintModel, model: &Model, data: &mut Data, v: &[f64]) {
    // Each row's sum over its nonzeros in ascending dof order (`jacobian.rs`, recorded by the
    // position stage), or over every column when the record is stale.
    let nefc = data.nefc;
    if data.soft.j_recorded {
        let Data { efc_vel, soft, .. } = &mut *data;
        let (start, index, value) = (&soft.nz_start, &soft.nz_index, &soft.nz_value);
        let vel = &mut efc_vel.as_mut_slice()[..nefc];
        let row = |i: usize| {
            let mut s = 0.0;
            for (&k, &j_ik) in index[start[i]..start[i + 1]].iter().zip(&value[start[i]..start[i + 1]]) {
                s += j_ik * v[k];
            }
            s
        };
        // A contact's rows share their columns (`contact_blocks`): v is gathered on them once
        // and each row's sum runs over two contiguous vectors, in the same order.
        let gathered = &mut soft.gathered;
        let mut i = 0;
        for &(first, rows) in &soft.contact_blocks {
            while i < first.min(nefc) {
                vel[i] = row(i);
                i += 1;
            }
            let columns = &index[start[first]..start[first + 1]];
            let m = columns.len();
            for (g, &k) in gathered.iter_mut().zip(columns) {
                *g = v[k];
            }
            for r in first..(first + rows).min(nefc) {
                let mut s = 0.0;
                for (&j_rk, &v_k) in value[start[r]..start[r] + m].iter().zip(&gathered[..m]) {
                    s += j_rk * v_k;
                }
                vel[r] = s;
            }
            i = i.max(first + rows);
        }
        while i < nefc {
            vel[i] = row(i);
            i += 1;
        }
    } else {
        let stride = data.efc_j.nrows();
        let j = data.efc_j.as_slice();
        let vel = &mut data.efc_vel.as_mut_slice()[..nefc];
        vel.fill(0.0);
        for (k, &vk) in v.iter().enumerate().take(model.nv) {
            for (r, &jrk) in j[k * stride..k * stride + nefc].iter().enumerate() {
                if jrk != 0.0 {
                    vel[r] += jrk * vk;
                }
            }
        }
    }
    data.efc_jdotv.rows_mut(0, data.nefc).fill(0.0);
    if data.ne == 0 {
        return;
    }
    bias_accelerations_unchecked(model, data, v);
    let mut r = 0;
    for e in &cm.equalities {
        if !data.sleep.equality_has_rows(model, e.id, data.eq_active[e.id]) {
            continue;
        }
        let n = model.equalities[e.id].kind.nrow();
        match &e.geometry {
            RowGeometry::Points { a, r_a, b, r_b } => {
                let (_, aa, _) = point_motion(data, *a, r_a);
                let (_, ab, _) = point_motion(data, *b, r_b);
                for k in 0..3 {
                    data.efc_jdotv[r + k] = aa[k] - ab[k];
                }
            }
            RowGeometry::Frames { a, x_a, b, x_b, torquescale } => {
                let (_, aa, (wa, alpha_a)) = point_motion(data, *a, &x_a.pos);
                let (_, ab, (wb, alpha_b)) = point_motion(data, *b, &x_b.pos);
                for k in 0..3 {
                    data.efc_jdotv[r + k] = aa[k] - ab[k];
                }
                if n == 6 {
                    // d/dt of ½ imag(q_B⁻¹ (ω_A − ω_B) q_A), the quaternion rates of world
                    // angular velocities being q̇ = ½ (0, ω) q (MuJoCo 4.0's J̇v is this exact
                    // derivative: it matches central differences of its Jacobian).
                    let (qa, qb) = weld_quats(data, e, *a, x_a, *b, x_b);
                    let qb_inv = conj(&qb);
                    let dw = pure(&(wa - wb));
                    let dalpha = pure(&(alpha_a - alpha_b));
                    let half = |q: &Quat, w: &Vec3| qmul(&pure(&(w * 0.5)), q);
                    let qa_dot = half(&qa, &wa);
                    let qb_inv_dot = conj(&half(&qb, &wb));
                    let t1 = qmul(&qmul(&qb_inv_dot, &dw), &qa);
                    let t2 = qmul(&qmul(&qb_inv, &dalpha), &qa);
                    let t3 = qmul(&qmul(&qb_inv, &dw), &qa_dot);
                    for k in 0..3 {
                        data.efc_jdotv[r + 3 + k] = 0.5 * torquescale * (t1[k + 1] + t2[k + 1] + t3[k + 1]);
                    }
                }
            }
            RowGeometry::Scalar { .. } => {}
        }
        r += n;
    }
}

/// Collision at `q` with MuJoCo's reach (contacts within each pair's margin) and whether any soft
/// row exists there: an active equality, a friction-loss dof, a joint within its margin of a
/// bound, or a contact closer than its `includemargin`. `forward` takes the ABA path when none
/// does.
pub(crate) fn soft_active(cm: &ConstraintModel, model: &Model, data: &mut Data, q: &[f64]) -> bool {
    let mut active = !cm.friction.is_empty()
        || !cm.tendon_friction.is_empty()
        || cm.equalities.iter().any(|e| data.sleep.equality_has_rows(model, e.id, data.eq_active[e.id]));
    if cm.has_collision() {
        crate::kinematics::body_poses(model, data, q);
        crate::collision::collide(model, &cm.collision, data, 0.0);
        active |= data.contacts.iter().any(|c| c.dist < c.includemargin);
    }
    let tendon_limit =
        cm.tendon_limits.iter().any(|&t| tendon_limit_sides(model, data, t).iter().any(Option::is_some));
    active
        || tendon_limit
        || cm
            .limits
            .iter()
            .any(|l| joint_limit_sides(l, q, model.joints[l.joint].soft.margin).iter().any(Option::is_some))
}
