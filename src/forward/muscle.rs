//! MuJoCo's muscle model (MuJoCo documentation "Modeling → Muscles"; engine_util_misc.c
//! `mju_muscleGain`, `mju_muscleBias`, `mju_muscleDynamics`), written from its definition.
//!
//! The parameters `gainprm` = `biasprm` = (range₀, range₁, force, scale, lmin, lmax, vmax, fpmax,
//! fvmax). With the length range [l₋, l₊] (`actuator_lengthrange`), the optimal length
//! L₀ = (l₊ − l₋) / (range₁ − range₀) normalizes the length to L = range₀ + (l − l₋) / L₀ and the
//! velocity to V = v / (L₀ vmax). The peak force F is `force`, or `scale` / `acc0` when `force`
//! is negative. Then
//!
//! - gain = −F · FL(L) · FV(V): FL is a bell of four half-parabolas that is 0 outside
//!   [lmin, lmax] and 1 at L = 1; FV is 0 for V ≤ −1, (V + 1)² up to 0, rises as a parabola to
//!   fvmax at V = fvmax − 1 and stays there;
//! - bias = −F · FP(L): the passive force, 0 for L ≤ 1, fpmax · ½ x² with x = (L − 1)/(b − 1) up to
//!   b = ½ (1 + lmax), then linear fpmax · (½ + x) with x = (L − b)/(b − 1);
//! - ẇ = (u − w) / τ with u the control clamped to [0, 1], the activation time constant
//!   τ₊ = `dynprm[0]` (½ + 1.5 w̄) when u > w and the deactivation one τ₋ = `dynprm[1]` / (½ + 1.5 w̄)
//!   otherwise (w̄ = w clamped to [0, 1]; Millard et al. 2013); with `tausmooth` = `dynprm[2]` > 0
//!   the switch is smooth: τ = τ₋ + (τ₊ − τ₋) s((u − w)/tausmooth + ½), s the quintic smoothstep.
//!
//! Every divisor is kept at least 10⁻¹⁵ (MuJoCo's `mjMINVAL`).

/// MuJoCo's `mjMINVAL`: the smallest divisor.
const MIN_VALUE: f64 = 1e-15;

/// The peak force, normalized length and normalized length scale L₀ of a muscle at `length`.
fn normalized(length: f64, lengthrange: [f64; 2], acc0: f64, prm: &[f64; 10]) -> (f64, f64, f64) {
    let force = if prm[2] < 0.0 { prm[3] / acc0.max(MIN_VALUE) } else { prm[2] };
    let l0 = (lengthrange[1] - lengthrange[0]) / (prm[1] - prm[0]).max(MIN_VALUE);
    let l = prm[0] + (length - lengthrange[0]) / l0.max(MIN_VALUE);
    (force, l, l0)
}

/// The active force–length curve FL(L) on [lmin, lmax] (MuJoCo's `mju_muscleGainLength`).
pub fn force_length(l: f64, lmin: f64, lmax: f64) -> f64 {
    if !(lmin <= l && l <= lmax) {
        return 0.0;
    }
    let a = 0.5 * (lmin + 1.0);
    let b = 0.5 * (1.0 + lmax);
    if l <= a {
        let x = (l - lmin) / (a - lmin).max(MIN_VALUE);
        0.5 * x * x
    } else if l <= 1.0 {
        let x = (1.0 - l) / (1.0 - a).max(MIN_VALUE);
        1.0 - 0.5 * x * x
    } else if l <= b {
        let x = (l - 1.0) / (b - 1.0).max(MIN_VALUE);
        1.0 - 0.5 * x * x
    } else {
        let x = (lmax - l) / (lmax - b).max(MIN_VALUE);
        0.5 * x * x
    }
}

/// The force–velocity curve FV(V) with plateau `fvmax`.
fn force_velocity(v: f64, fvmax: f64) -> f64 {
    let y = fvmax - 1.0;
    if v <= -1.0 {
        0.0
    } else if v <= 0.0 {
        (v + 1.0) * (v + 1.0)
    } else if v <= y {
        fvmax - (y - v) * (y - v) / y.max(MIN_VALUE)
    } else {
        fvmax
    }
}

/// The muscle gain −F · FL · FV at actuator `length` and `velocity` (MuJoCo's `mju_muscleGain`).
pub fn muscle_gain(length: f64, velocity: f64, lengthrange: [f64; 2], acc0: f64, prm: &[f64; 10]) -> f64 {
    let (force, l, l0) = normalized(length, lengthrange, acc0, prm);
    let v = velocity / (l0 * prm[6]).max(MIN_VALUE);
    -force * force_length(l, prm[4], prm[5]) * force_velocity(v, prm[8])
}

/// The passive muscle force −F · FP at actuator `length` (MuJoCo's `mju_muscleBias`).
pub fn muscle_bias(length: f64, lengthrange: [f64; 2], acc0: f64, prm: &[f64; 10]) -> f64 {
    let (force, l, _) = normalized(length, lengthrange, acc0, prm);
    let (lmax, fpmax) = (prm[5], prm[7]);
    let b = 0.5 * (1.0 + lmax);
    if l <= 1.0 {
        0.0
    } else if l <= b {
        let x = (l - 1.0) / (b - 1.0).max(MIN_VALUE);
        -force * fpmax * 0.5 * x * x
    } else {
        let x = (l - b) / (b - 1.0).max(MIN_VALUE);
        -force * fpmax * (0.5 + x)
    }
}

/// The quintic smoothstep 6x⁵ − 15x⁴ + 10x³ on [0, 1], 0 below and 1 above (MuJoCo's `mju_sigmoid`).
fn smoothstep(x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x >= 1.0 {
        1.0
    } else {
        x * x * x * (3.0 * x * (2.0 * x - 5.0) + 10.0)
    }
}

/// The activation rate ẇ of a muscle at control `ctrl` and activation `act`, `dynprm` =
/// (τ_act, τ_deact, tausmooth) (MuJoCo's `mju_muscleDynamics`).
pub fn muscle_activation_rate(ctrl: f64, act: f64, dynprm: &[f64; 10]) -> f64 {
    let u = ctrl.clamp(0.0, 1.0);
    let w = act.clamp(0.0, 1.0);
    let tau_act = dynprm[0] * (0.5 + 1.5 * w);
    let tau_deact = dynprm[1] / (0.5 + 1.5 * w);
    let width = dynprm[2];
    let excess = u - act;
    let tau = if width < MIN_VALUE {
        if excess > 0.0 {
            tau_act
        } else {
            tau_deact
        }
    } else {
        tau_deact + (tau_act - tau_deact) * smoothstep(excess / width + 0.5)
    };
    excess / tau.max(MIN_VALUE)
}
