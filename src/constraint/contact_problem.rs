//! The exact mode's constraint problem taken out of [`Data`] after a solve, as a self-contained
//! object another solver can be given (`docs/constraints.md`, "Exporting the exact mode's
//! problem"): the Delassus matrix G = J M⁻¹ Jᵀ of the rows in the exact solver's own order, the
//! free row acceleration g (σ = G λ + g is the row acceleration the forces λ give), the law of each
//! block of rows, and the solver's λ, iterations and residual.
//!
//! The problem is the acceleration-level one of `forward`'s constraint stage (docs/physics.md §1.6):
//! find λ with, per block,
//! - equality rows: λ free, σ = 0;
//! - a limit or a frictionless contact: λ ≥ 0, σ ≥ 0, λ σ = 0;
//! - a dof's friction loss: lo ≤ λ ≤ hi, σ ≥ 0 where λ > lo and σ ≤ 0 where λ < hi (at rest
//!   [−f, f]; while the dof slides lo = hi = −f sign(q̇));
//! - a contact at rest (its slip within [`SLIP_VELOCITY`]): the normal and friction rows in the
//!   elliptic cone Σ (λ_k/μ_k)² ≤ λ_n², with the De Saxcé correction s_n = ‖(μ_k σ_k)‖: the cone
//!   complementarity problem K ∋ λ̂ ⊥ σ̂ + s ∈ K* (λ̂_k = λ_k/μ_k, σ̂_k = μ_k σ_k, K the unit
//!   second-order cone) whose solution is Coulomb's law with maximal dissipation — the problem
//!   Pinocchio's ADMM and PGS contact solvers take, its cone a `CoulombFrictionCone` per contact
//!   with the normal as the last of the three rows;
//! - a contact slipping: λ_n ≥ 0 ⊥ σ_n ≥ 0 and the friction on the ray λ_k = λ_n d_k against the
//!   slip (maximal dissipation, d in [`ProblemBlock::direction`]);
//! - a limit or contact separating (J v > [`SEPARATING_VELOCITY`]) or whose diagonal is round-off:
//!   no force, not part of the problem.
//!
//! [`ContactProblem::residual`] measures how well a λ solves it, the same measure for any solver's
//! answer; [`ContactProblem::solve`] runs the exact mode's own solvers on it again from a cold
//! start (what `lagrange eval --dump-contact-problem` times).

use super::active_set::solve_mixed;
use super::admm::{solve_admm, ExactContactSolver};
use super::coulomb::{has_friction, solve_coulomb, Level, SolverSettings, SEPARATING_VELOCITY};
use crate::error::{check, InputError};
use crate::model::{Data, EfcType, Model, SLIP_VELOCITY};
use nalgebra::{DMatrix, DVector};

/// The law a block of rows obeys in a [`ContactProblem`] (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockLaw {
    /// Equality rows: λ free, σ = 0.
    Equality,
    /// A joint limit or a frictionless contact: λ ≥ 0 ⊥ σ ≥ 0.
    Unilateral,
    /// A dof's friction loss: λ in [lo, hi] with σ in the normal cone of the box.
    Box,
    /// A contact at rest: Coulomb's elliptic cone with the De Saxcé correction.
    Cone,
    /// A slipping contact: λ_n ≥ 0 ⊥ σ_n ≥ 0, friction λ_n d against the slip.
    Sliding,
    /// Separating, or a diagonal that is round-off: no force, outside the problem.
    Inactive,
}

impl BlockLaw {
    /// `equality`, `unilateral`, `box`, `cone`, `sliding` or `inactive`.
    pub fn name(self) -> &'static str {
        match self {
            BlockLaw::Equality => "equality",
            BlockLaw::Unilateral => "unilateral",
            BlockLaw::Box => "box",
            BlockLaw::Cone => "cone",
            BlockLaw::Sliding => "sliding",
            BlockLaw::Inactive => "inactive",
        }
    }
}

/// One block of rows of a [`ContactProblem`]: a contact's rows (normal first, then its friction
/// rows), or one scalar row.
#[derive(Clone, Debug, PartialEq)]
pub struct ProblemBlock {
    /// Its first row.
    pub first: usize,
    /// Its number of rows.
    pub len: usize,
    /// The row kind (`Data::efc_type`).
    pub kind: EfcType,
    /// The element (`Data::efc_id`: the contact's index in `Data::contacts`, the joint, dof or
    /// equality).
    pub id: usize,
    /// The law it obeys.
    pub law: BlockLaw,
    /// A contact's friction coefficient per friction row (`len − 1` values; empty otherwise).
    pub friction: Vec<f64>,
    /// The bounds of a scalar row's λ: [lo, hi] of a friction loss, [0, ∞) of a limit or
    /// frictionless contact, (−∞, ∞) of an equality, [0, ∞) for a contact's normal.
    pub lo: f64,
    /// See [`lo`](Self::lo).
    pub hi: f64,
    /// A sliding contact's friction per unit normal force, d_k = −μ_k² u_k / ‖μ ∘ u‖ (u the slip
    /// velocity), one per friction row; empty otherwise.
    pub direction: Vec<f64>,
}

/// The residual of a λ on a [`ContactProblem`]: the largest violation over the blocks of each
/// condition (see [`ContactProblem::residual`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProblemResidual {
    /// Primal feasibility: λ's distance to its set (the cone in the scaled variables λ̂, the box,
    /// λ ≥ 0, the sliding ray, zero for inactive rows), N.
    pub primal: f64,
    /// Dual feasibility: the distance of σ (+ De Saxcé) to the dual set (σ = 0 for equalities,
    /// σ ≥ 0 for unilateral rows, the dual cone for contacts), m/s².
    pub dual: f64,
    /// Complementarity: |⟨λ, σ + s⟩| per block (λ σ for scalar rows; for a friction loss, the
    /// force of a σ pushing λ off a bound times its distance to that bound), N·m/s².
    pub complementarity: f64,
    /// The three relative to the problem's size: max(primal / (1 + ‖λ‖∞), dual / (1 + ‖g‖∞),
    /// complementarity / ((1 + ‖λ‖∞)(1 + ‖g‖∞))).
    pub relative: f64,
}

/// A solve of a [`ContactProblem`] by one of the exact mode's solvers.
#[derive(Clone, Debug, PartialEq)]
pub struct ProblemSolution {
    /// The forces, one per row (zero on inactive rows).
    pub lambda: DVector<f64>,
    /// The solver's iterations (Gauss–Seidel sweeps, ADMM iterations, or active-set changes).
    pub iterations: u32,
    /// The solver's own stopping residual (`Data::efc_residual`).
    pub residual: f64,
    /// Whether it met its tolerance.
    pub converged: bool,
}

/// The exact mode's constraint problem at the last `forward` (see the module documentation).
///
/// # Example
/// ```
/// use lagrange::constraint::{ConstraintMode, ContactProblem, ExactContactSolver};
/// use lagrange::{forward::forward, Data, Model};
///
/// // A box resting on the floor: four corner contacts, each a normal and two friction rows.
/// let mut model = Model::from_str(
///     "<mujoco><worldbody><geom type='plane' size='0 0 1'/>\
///      <body pos='0 0 0.05'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
///      </worldbody></mujoco>",
/// )?;
/// model.set_constraint_mode(ConstraintMode::Exact);
/// let mut data = Data::new(&model);
/// forward(&model, &mut data);
/// let problem = ContactProblem::from_data(&model, &data)?;
/// assert_eq!(problem.nrows(), 12);
/// // The forward's λ solves it; so does the ADMM run again on a copy of the data.
/// assert!(problem.residual(problem.lambda.as_slice())?.relative < 1e-9);
/// let mut scratch = data.clone();
/// let admm = problem.solve(&model, &mut scratch, ExactContactSolver::Admm)?;
/// assert!(problem.residual(admm.lambda.as_slice())?.relative < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ContactProblem {
    /// G = J M⁻¹ Jᵀ, nrows × nrows, the rows in the exact solver's order (`Data::efc_*`).
    pub delassus: DMatrix<f64>,
    /// g = J q̈_smooth + J̇ v (+ α J v + β φ with Baumgarte gains): σ = G λ + g.
    pub free: DVector<f64>,
    /// The blocks of rows, in row order.
    pub blocks: Vec<ProblemBlock>,
    /// The forces of the solve `Data` holds (`Data::efc_force`).
    pub lambda: DVector<f64>,
    /// That solve's iterations, stopping residual and convergence (`Data::efc_iterations`,
    /// `efc_residual`, `efc_converged`).
    pub iterations: u32,
    /// See [`iterations`](Self::iterations).
    pub residual: f64,
    /// See [`iterations`](Self::iterations).
    pub converged: bool,
}

impl ContactProblem {
    /// The problem of the constraint stage of the last [`forward`](crate::forward::forward) on
    /// `data`, a model in exact mode. An empty problem when that state had no rows.
    ///
    /// # Errors
    /// [`InputError::Value`] when the model is in soft mode or `data`'s last exact solve is not
    /// the acceleration-level solve of its current rows (after `step`, the drift correction's
    /// projection solved other problems: call `forward` first); [`InputError::Length`] when
    /// `data` was made for another model.
    pub fn from_data(model: &Model, data: &Data) -> Result<Self, InputError> {
        const F: &str = "ContactProblem::from_data";
        check::data(F, model, data)?;
        let Some(exact) = model.plan.solver.exact() else {
            return Err(InputError::Value {
                function: F,
                argument: "model",
                detail: "is in soft mode: the problem is the exact mode's (Model::set_constraint_mode)"
                    .into(),
            });
        };
        let n = data.nefc;
        let nv = model.nv;
        let work = &data.exact;
        // The last exact solve was an acceleration-level one of these rows (it stored its forces
        // as the next warm start, and they are still `efc_force`) at this J (the copy of J the
        // Delassus matrix was formed from is `efc_j`: a drift correction since then moved q and
        // re-evaluated the rows).
        let jt = work.jt.as_slice();
        let solved = n == 0
            || (work.delassus.nrows() >= n
                && jt.len() >= n * nv
                && work.warm_rows.len() == n
                && (0..n).all(|i| {
                    work.warm_rows[i] == (data.efc_type[i], data.efc_id[i])
                        && work.warm[i] == data.efc_force[i]
                        && (0..nv).all(|k| jt[k + i * nv] == data.efc_j[(i, k)])
                }));
        if !solved {
            return Err(InputError::Value {
                function: F,
                argument: "data",
                detail: "holds no acceleration-level solve of its current rows: call forward first".into(),
            });
        }
        let [alpha, beta] = exact.drift.baumgarte.unwrap_or([0.0, 0.0]);
        let free = DVector::from_fn(n, |i, _| {
            let j_qacc: f64 = (0..nv).map(|k| data.efc_j[(i, k)] * data.qacc_smooth[k]).sum();
            j_qacc + data.efc_jdotv[i] + alpha * data.efc_vel[i] + beta * data.efc_pos[i]
        });
        let delassus = work.delassus.view((0, 0), (n, n)).into_owned();
        let a_floor = 1e-12 * (0..n).map(|i| delassus[(i, i)]).fold(0.0, f64::max);
        let mut blocks = Vec::new();
        let mut i = 0;
        while i < n {
            let len = data.efc_block_len(i);
            blocks.push(block(model, data, i, len, a_floor));
            i += len;
        }
        Ok(Self {
            delassus,
            free,
            blocks,
            lambda: DVector::from_column_slice(&data.efc_force.as_slice()[..n]),
            iterations: data.efc_iterations,
            residual: data.efc_residual,
            converged: data.efc_converged,
        })
    }

    /// The number of rows.
    pub fn nrows(&self) -> usize {
        self.free.len()
    }

    /// How well `lambda` (one force per row) solves the problem: per block, the primal and dual
    /// feasibility and the complementarity of its law (module documentation), the largest of each
    /// over the blocks. Contacts are measured in the scaled variables λ̂_k = λ_k/μ_k, σ̂_k = μ_k σ_k
    /// (the cone becomes the unit second-order cone K, self-dual; ⟨λ̂, σ̂⟩ = ⟨λ, σ⟩): primal
    /// dist(λ̂, K), dual dist(σ̂ + s, K) with s_n = ‖σ̂_t‖, complementarity |⟨λ̂, σ̂ + s⟩|.
    ///
    /// # Errors
    /// [`InputError::Length`] when `lambda` is not [`nrows`](Self::nrows) long.
    pub fn residual(&self, lambda: &[f64]) -> Result<ProblemResidual, InputError> {
        let n = self.nrows();
        InputError::check_len("ContactProblem::residual", "lambda", lambda.len(), n, "rows")?;
        let sigma = &self.delassus * DVector::from_column_slice(lambda) + &self.free;
        let mut r = ProblemResidual::default();
        let mut add = |p: f64, d: f64, c: f64| {
            r.primal = r.primal.max(p);
            r.dual = r.dual.max(d);
            r.complementarity = r.complementarity.max(c);
        };
        for b in &self.blocks {
            let (l, s) = (&lambda[b.first..b.first + b.len], &sigma.as_slice()[b.first..b.first + b.len]);
            match b.law {
                BlockLaw::Equality => add(0.0, s[0].abs(), 0.0),
                BlockLaw::Unilateral => add((-l[0]).max(0.0), (-s[0]).max(0.0), (l[0] * s[0]).abs()),
                BlockLaw::Box => {
                    let p = (b.lo - l[0]).max(l[0] - b.hi).max(0.0);
                    let c = (s[0].max(0.0) * (l[0] - b.lo)).max((-s[0]).max(0.0) * (b.hi - l[0])).max(0.0);
                    add(p, 0.0, c)
                }
                BlockLaw::Inactive => add(l.iter().fold(0.0, |m, x| m.max(x.abs())), 0.0, 0.0),
                BlockLaw::Sliding => {
                    let ray = (1..b.len)
                        .map(|k| (l[k] - l[0].max(0.0) * b.direction[k - 1]).abs())
                        .fold(0.0, f64::max);
                    add((-l[0]).max(0.0).max(ray), (-s[0]).max(0.0), (l[0] * s[0]).abs())
                }
                BlockLaw::Cone => {
                    let (p, d, c) = cone_residual(l, s, &b.friction);
                    add(p, d, c)
                }
            }
        }
        let lmax = lambda.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let gmax = self.free.amax();
        r.relative = (r.primal / (1.0 + lmax))
            .max(r.dual / (1.0 + gmax))
            .max(r.complementarity / ((1.0 + lmax) * (1.0 + gmax)));
        Ok(r)
    }

    /// Solves the problem again with the exact mode's solver `solver`, from a cold start (no warm
    /// start from the last solve), on `data`: the data the problem was taken from or a copy of it
    /// (its rows, Delassus matrix and factor of M are read). Problems without dry friction are
    /// solved by the active-set method whatever `solver` is, as `forward` does. Overwrites
    /// `data`'s constraint forces and the exact solver's workspace (not `qacc`): pass a copy to
    /// keep the original. No allocation beyond the returned λ.
    ///
    /// # Errors
    /// [`InputError::Value`] when `data` holds other rows than the problem's (another state, or
    /// the drift correction's rows after a step).
    pub fn solve(
        &self,
        model: &Model,
        data: &mut Data,
        solver: ExactContactSolver,
    ) -> Result<ProblemSolution, InputError> {
        const F: &str = "ContactProblem::solve";
        check::data(F, model, data)?;
        let n = self.nrows();
        // The same rows (kinds, elements, Delassus diagonal): a check in O(n), not timed apart.
        let same = data.nefc == n
            && data.exact.delassus.nrows() >= n
            && self.blocks.iter().all(|b| data.efc_type[b.first] == b.kind && data.efc_id[b.first] == b.id)
            && (0..n).all(|i| data.exact.delassus[(i, i)] == self.delassus[(i, i)]);
        if !same {
            return Err(InputError::Value {
                function: F,
                argument: "data",
                detail: "holds other rows than the problem's: pass the data it was taken from (or a copy)"
                    .into(),
            });
        }
        let settings =
            SolverSettings { solver, ..model.plan.solver.exact().map(|e| e.settings).unwrap_or_default() };
        // The right-hand side b = −g, and no warm start.
        for i in 0..n {
            data.exact.rhs[i] = -self.free[i];
        }
        data.exact.warm_rows.clear();
        data.exact.pressing[..n].fill(false);
        if has_friction(data) {
            if solver == ExactContactSolver::Admm {
                solve_admm(model, data, settings);
            } else {
                let scale = data.qacc_smooth.amax();
                solve_coulomb(model, data, Level::Acceleration, settings, scale);
            }
        } else {
            data.efc_iterations =
                solve_mixed(data, |d, i| !d.rows_frozen() && d.efc_vel[i] > SEPARATING_VELOCITY);
            data.efc_residual = 0.0;
            data.efc_converged = true;
        }
        for i in 0..n {
            data.efc_force[i] = data.exact.rhs[i];
        }
        Ok(ProblemSolution {
            lambda: DVector::from_column_slice(&data.efc_force.as_slice()[..n]),
            iterations: data.efc_iterations,
            residual: data.efc_residual,
            converged: data.efc_converged,
        })
    }
}

/// The block of rows i..i+len: its law as the exact solver decides it at the acceleration level
/// (`coulomb::contact_block`, `friction_dof`, `separating`).
fn block(model: &Model, data: &Data, i: usize, len: usize, a_floor: f64) -> ProblemBlock {
    let kind = data.efc_type[i];
    let id = data.efc_id[i];
    let separating = !data.rows_frozen() && data.efc_vel[i] > SEPARATING_VELOCITY;
    let roundoff = data.exact.delassus[(i, i)] <= a_floor;
    let mut b = ProblemBlock {
        first: i,
        len,
        kind,
        id,
        law: BlockLaw::Unilateral,
        friction: Vec::new(),
        lo: 0.0,
        hi: f64::INFINITY,
        direction: Vec::new(),
    };
    match kind {
        EfcType::Equality | EfcType::FrictionTendon => {
            b.law = BlockLaw::Equality;
            b.lo = f64::NEG_INFINITY;
        }
        EfcType::FrictionDof => {
            let loss = model.joint_of(model.dof_body[id]).friction;
            let speed = data.efc_vel[i];
            b.law = if roundoff { BlockLaw::Inactive } else { BlockLaw::Box };
            if speed.abs() > SLIP_VELOCITY && !data.efc_frozen_at_rest(i) {
                b.lo = -loss * speed.signum();
                b.hi = b.lo;
            } else {
                b.lo = -loss;
                b.hi = loss;
            }
        }
        EfcType::LimitJoint
        | EfcType::LimitTendon
        | EfcType::ContactFrictionless
        | EfcType::ContactPyramidal => {
            if separating || roundoff {
                b.law = BlockLaw::Inactive;
            }
        }
        EfcType::ContactElliptic => {
            let friction = data.contacts[id].friction;
            b.friction = (1..len).map(|k| friction[k - 1]).collect();
            let slip = (1..len).map(|k| data.efc_vel[i + k].powi(2)).sum::<f64>().sqrt();
            b.law = if separating || roundoff {
                BlockLaw::Inactive
            } else if slip > SLIP_VELOCITY && !data.efc_frozen_at_rest(i) {
                BlockLaw::Sliding
            } else {
                BlockLaw::Cone
            };
            if b.law == BlockLaw::Sliding {
                let norm =
                    (1..len).map(|k| (friction[k - 1] * data.efc_vel[i + k]).powi(2)).sum::<f64>().sqrt();
                b.direction = (1..len)
                    .map(|k| {
                        let m = friction[k - 1];
                        if norm > 0.0 {
                            -m * m * data.efc_vel[i + k] / norm
                        } else {
                            0.0
                        }
                    })
                    .collect();
            }
        }
    }
    b
}

/// (primal, dual, complementarity) of a contact at rest: forces `l` and accelerations `s` (normal
/// first), friction coefficients `mu`, in the scaled variables of the unit second-order cone. A
/// friction row with μ = 0 carries no force (primal |λ_k|) and has no dual condition.
fn cone_residual(l: &[f64], s: &[f64], mu: &[f64]) -> (f64, f64, f64) {
    let (mut lt, mut st, mut dot, mut zero) = (0.0, 0.0, l[0] * s[0], 0.0f64);
    for k in 1..l.len() {
        let m = mu[k - 1];
        if m > 0.0 {
            lt += (l[k] / m).powi(2);
            st += (m * s[k]).powi(2);
            dot += l[k] * s[k];
        } else {
            zero = zero.max(l[k].abs());
        }
    }
    let (lt, st) = (lt.sqrt(), st.sqrt());
    let primal = soc_distance(l[0], lt).max(zero);
    // σ̂ + s: the normal shifted by ‖σ̂_t‖.
    let dual = soc_distance(s[0] + st, st);
    (primal, dual, (dot + l[0] * st).abs())
}

/// The distance of (x_n, x_t) (x_t = ‖tangential part‖ ≥ 0) to the unit second-order cone
/// {‖x_t‖ ≤ x_n}.
fn soc_distance(xn: f64, xt: f64) -> f64 {
    if xt <= xn {
        0.0
    } else if xt <= -xn {
        xn.hypot(xt)
    } else {
        (xt - xn) / std::f64::consts::SQRT_2
    }
}
