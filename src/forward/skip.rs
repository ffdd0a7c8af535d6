//! Stage skipping for finite differences (MuJoCo's `mj_forwardSkip` and `mj_stepSkip`,
//! engine_forward.c and engine_derivative_fd.c): a request, kept in `Data`, that the next
//! forward evaluation reuse the outputs of its leading stages from the last one at the same
//! configuration (and velocity), and that the steps skip the sensors. Set by the transition
//! Jacobians (`derivatives::transition_jacobians`) only; a plain `forward` or `step` never skips.

/// Which leading stages the next forward evaluation reuses (MuJoCo's `skipstage`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum SkipStage {
    /// Run every stage (MuJoCo's `mjSTAGE_NONE`).
    #[default]
    None,
    /// Reuse the position stage: body poses, M and its factor, collision and the rows' `efc_j`,
    /// `efc_pos` (MuJoCo's `mjSTAGE_POS`: the velocity may have changed, not the configuration).
    Position,
    /// Reuse the position, velocity and passive stages: also `qfrc_bias`, `efc_vel`,
    /// `efc_jdotv`, `qfrc_passive` (MuJoCo's `mjSTAGE_VEL`: only `ctrl` or `act` changed).
    Velocity,
}

/// The skip request and what the forward evaluations record for it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ForwardSkip {
    /// The stages the next `forward_at` reuses; it resets this to [`SkipStage::None`], so that
    /// only the first evaluation of a step skips (MuJoCo's RK4 stages run in full).
    pub stage: SkipStage,
    /// Skip the sensors of every step while set (MuJoCo's `skipsensor`).
    pub sensors: bool,
    /// Whether the last `forward_at` took the M path (rows existed): a skipped position stage
    /// keeps its answer.
    pub m_path: bool,
    /// A stepper's request that the next `forward_at` form M and its factor even where no row
    /// exists (the M path without the solver) instead of ABA: the implicitly damped Euler step
    /// factors M again anyway, and CRBA, the factor and RNEA cost less than ABA followed by
    /// CRBA. Set and cleared around the call by the stepper (`integrate::euler`).
    pub mass_wanted: bool,
    /// Whether the last `forward_at` formed M and its factor at its q (rows existed, or
    /// [`mass_wanted`](Self::mass_wanted)): a skipped position stage keeps this answer too.
    pub mass_formed: bool,
}
