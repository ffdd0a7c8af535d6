//! Delayed controls: MuJoCo 4.0's history buffers (`d->history`, `mjSTATE_HISTORY`; MJCF actuator
//! attributes `delay`, `nsample`, `interp`; MuJoCo documentation, "XML Reference → actuator",
//! and `mju_historyInsert` / `mju_historyRead` in engine_util_misc.c, read for their semantics).
//!
//! An actuator with `nsample` = n > 0 owns 2 + 2n entries of `Data::history`, laid out as
//! MuJoCo's:
//!
//! | offset | content |
//! |---|---|
//! | 0 | a user slot (0 for actuators) |
//! | 1 | the cursor: the physical index of the newest sample |
//! | 2 … 2 + n | the sample times, a ring ordered oldest to newest from cursor + 1 |
//! | 2 + n … 2 + 2n | the sample values (the control) |
//!
//! [`reset_buffers`] sets the times to −n·h … −h (h the timestep) and the values to 0.
//! Each step records the control at the step's start time (`record_controls`, MuJoCo's
//! `mj_advance`) after the forces are computed; the actuation stage of an actuator with a
//! nonzero `delay` reads its control at (stage time − delay) (`delayed_ctrl`): the oldest
//! value before the oldest sample, the newest after the newest, and between two samples the
//! older one (`interp="zoh"`), the linear interpolation (`linear`) or a cubic Hermite spline
//! with finite-difference (Catmull–Rom) slopes, zero at the ends (`cubic`). A time within
//! 1e-15 s of a sample (MuJoCo's `mjMINVAL`) reads that sample.
//!
//! So a control reaches the forces `delay` seconds later; with `delay` below the timestep it
//! still waits one step, since the current step's control is recorded after its forces.

use crate::model::{ActuatorHistory, Data, Interp, Model};

/// MuJoCo's `mjMINVAL`: times closer than this are the same sample.
const SAME_TIME: f64 = 1e-15;

/// Physical index of logical sample `logical` (0 = oldest) in a ring of `n` whose newest sample
/// is at `cursor`.
fn physical(cursor: usize, n: usize, logical: usize) -> usize {
    (cursor + 1 + logical) % n
}

/// The ring's cursor (its newest sample's physical index), read from the buffer as MuJoCo stores
/// it (a float). A corrupted cursor (the buffer is part of the state a user may set) is taken
/// modulo n.
fn cursor(buffer: &[f64], n: usize) -> usize {
    let c = buffer[1];
    if c.is_finite() && c >= 0.0 {
        (c as usize) % n
    } else {
        n - 1
    }
}

/// The logical index i with times[i−1] < t ≤ times[i]: 0 when t is at or before the oldest
/// sample, n after the newest (binary search over the ring).
fn find(times: &[f64], n: usize, cursor: usize, t: f64) -> usize {
    if t <= times[physical(cursor, n, 0)] {
        return 0;
    }
    if t > times[physical(cursor, n, n - 1)] {
        return n;
    }
    let (mut lo, mut hi) = (0, n - 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if times[physical(cursor, n, mid)] < t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Writes `value` at time `t` into the scalar ring `buffer` (2 + 2n entries): the sample at `t`
/// when there is one, else the oldest sample is dropped and the new one placed in time order.
pub fn insert(buffer: &mut [f64], n: usize, t: f64, value: f64) {
    let mut c = cursor(buffer, n);
    let (head, rest) = buffer.split_at_mut(2);
    let (times, values) = rest.split_at_mut(n);
    let i = find(times, n, c, t);
    if i < n {
        let p = physical(c, n, i);
        if (t - times[p]).abs() < SAME_TIME {
            values[p] = value;
            return;
        }
    }
    let slot = if i == 0 {
        physical(c, n, 0)
    } else if i == n {
        c = (c + 1) % n;
        head[1] = c as f64;
        c
    } else {
        // Out of order: shift the samples older than the new one down by one (dropping the
        // oldest) and insert at logical i − 1.
        for j in 0..i - 1 {
            let (dst, src) = (physical(c, n, j), physical(c, n, j + 1));
            times[dst] = times[src];
            values[dst] = values[src];
        }
        physical(c, n, i - 1)
    };
    times[slot] = t;
    values[slot] = value;
}

/// The value of the scalar ring `buffer` (2 + 2n entries) at time `t`, interpolated as `interp`
/// says (see the module documentation).
pub fn read(buffer: &[f64], n: usize, t: f64, interp: Interp) -> f64 {
    let c = cursor(buffer, n);
    let (times, values) = (&buffer[2..2 + n], &buffer[2 + n..2 + 2 * n]);
    let (oldest, newest) = (physical(c, n, 0), physical(c, n, n - 1));
    if t <= times[oldest] + SAME_TIME {
        return values[oldest];
    }
    if t >= times[newest] - SAME_TIME {
        return values[newest];
    }
    let i = find(times, n, c, t);
    let hi = physical(c, n, i);
    if (t - times[hi]).abs() < SAME_TIME {
        return values[hi];
    }
    let lo = physical(c, n, i - 1);
    let span = times[hi] - times[lo];
    let alpha = (t - times[lo]) / span;
    match interp {
        Interp::ZeroOrderHold => values[lo],
        Interp::Linear => values[lo] + alpha * (values[hi] - values[lo]),
        Interp::Cubic => {
            let slope_lo = if i > 1 {
                let before = physical(c, n, i - 2);
                (values[hi] - values[before]) / (times[hi] - times[before])
            } else {
                0.0
            };
            let slope_hi = if i < n - 1 {
                let after = physical(c, n, i + 1);
                (values[after] - values[lo]) / (times[after] - times[lo])
            } else {
                0.0
            };
            let (a2, a3) = (alpha * alpha, alpha * alpha * alpha);
            (2.0 * a3 - 3.0 * a2 + 1.0) * values[lo]
                + (a3 - 2.0 * a2 + alpha) * span * slope_lo
                + (-2.0 * a3 + 3.0 * a2) * values[hi]
                + (a3 - a2) * span * slope_hi
        }
    }
}

/// Actuator `i`'s control input to the actuation stage: `ctrl[i]`, or for an actuator with a
/// history and a nonzero `delay` its recorded control at `data.time` − delay (MuJoCo's
/// `mj_readCtrl`). Not clamped.
#[inline]
pub(crate) fn delayed_ctrl(model: &Model, data: &Data, i: usize) -> f64 {
    match &model.actuators[i].history {
        Some(h) if h.delay != 0.0 => {
            read(buffer(data.history.as_slice(), h), h.nsample, data.time - h.delay, h.interp)
        }
        _ => data.ctrl[i],
    }
}

/// Actuator history `h`'s slice of `history`.
fn buffer<'a>(history: &'a [f64], h: &ActuatorHistory) -> &'a [f64] {
    &history[h.adr..h.adr + 2 + 2 * h.nsample]
}

/// Sets `data.history` as [`crate::model::reset`] does (MuJoCo's `mj_resetData`), leaving the
/// rest of the state alone: each actuator's sample times at −n·h … −h (h the model's timestep),
/// its values 0.
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><option timestep="0.01"/><worldbody><body>
///     <joint name="j" type="slide"/><geom size="0.1"/></body></worldbody>
///     <actuator><motor joint="j" delay="0.02" nsample="2"/></actuator></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// data.ctrl[0] = 1.0;
/// lagrange::integrate::step(&model, &mut data)?; // records (t = 0, ctrl 1)
/// lagrange::forward::history::reset_buffers(&model, &mut data);
/// // [user, cursor, times −0.02 −0.01, values 0 0]
/// assert_eq!(data.history.as_slice(), &[0.0, 1.0, -0.02, -0.01, 0.0, 0.0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reset_buffers(model: &Model, data: &mut Data) {
    reset_actuator_buffers(model, data.history.as_mut_slice());
}

/// Sets every actuator's history as MuJoCo's `mj_resetData` does: sample times −n·h … −h with
/// h the model's timestep, values 0, cursor at the newest.
pub(crate) fn reset_actuator_buffers(model: &Model, history: &mut [f64]) {
    let h = model.options.timestep;
    for a in &model.actuators {
        let Some(hist) = &a.history else { continue };
        let n = hist.nsample;
        let b = &mut history[hist.adr..hist.adr + 2 + 2 * n];
        b[0] = 0.0;
        b[1] = (n - 1) as f64;
        for j in 0..n {
            b[2 + j] = -((n - j) as f64) * h;
            b[2 + n + j] = 0.0;
        }
    }
}

/// Records each actuator's control `data.ctrl` at `time` (the start of the step just taken) in
/// its history, as MuJoCo's `mj_advance` does once per step.
pub(crate) fn record_controls(model: &Model, data: &mut Data, time: f64) {
    for (i, a) in model.actuators.iter().enumerate() {
        if let Some(h) = &a.history {
            let ctrl = data.ctrl[i];
            insert(&mut data.history.as_mut_slice()[h.adr..h.adr + 2 + 2 * h.nsample], h.nsample, time, ctrl);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(n: usize, h: f64) -> Vec<f64> {
        let mut b = vec![0.0; 2 + 2 * n];
        b[1] = (n - 1) as f64;
        for j in 0..n {
            b[2 + j] = -((n - j) as f64) * h;
        }
        b
    }

    #[test]
    fn zero_order_hold_delays_by_the_delay() {
        // dt 0.01, delay 0.025, controls 1, 2, 3, … from t = 0: the forces read 0, 0, 0, 1, 2, 3
        // (MuJoCo 4.0.0's actuator_force for this sequence).
        let (n, h, delay) = (4, 0.01, 0.025);
        let mut b = ring(n, h);
        let mut read_values = Vec::new();
        for k in 0..6 {
            let t = k as f64 * h;
            read_values.push(read(&b, n, t - delay, Interp::ZeroOrderHold));
            insert(&mut b, n, t, (k + 1) as f64);
        }
        assert_eq!(read_values, vec![0.0, 0.0, 0.0, 1.0, 2.0, 3.0]);
    }

    #[test]
    fn linear_and_cubic_interpolate_between_samples() {
        let n = 4;
        let mut b = ring(n, 1.0);
        for (t, v) in [(0.0, 0.0), (1.0, 1.0), (2.0, 4.0), (3.0, 9.0)] {
            insert(&mut b, n, t, v);
        }
        assert_eq!(read(&b, n, 1.5, Interp::Linear), 2.5);
        // Catmull–Rom slopes (4 − 0)/2 = 2 and (9 − 1)/2 = 4 at t = 1 and 2: at the midpoint
        // ½(1 + 4) + ⅛(2 − 4) = 2.25.
        assert!((read(&b, n, 1.5, Interp::Cubic) - 2.25).abs() < 1e-15);
        // Before the oldest and after the newest: the end values.
        assert_eq!(read(&b, n, -5.0, Interp::Linear), 0.0);
        assert_eq!(read(&b, n, 7.0, Interp::Cubic), 9.0);
    }

    #[test]
    fn an_out_of_order_sample_drops_the_oldest() {
        let n = 3;
        let mut b = ring(n, 1.0); // times −3, −2, −1
        insert(&mut b, n, -1.5, 7.0);
        // Now −2, −1.5, −1 with values 0, 7, 0.
        assert_eq!(read(&b, n, -1.5, Interp::ZeroOrderHold), 7.0);
        assert_eq!(read(&b, n, -2.5, Interp::Linear), 0.0);
        // The same time overwrites.
        insert(&mut b, n, -1.5, 8.0);
        assert_eq!(read(&b, n, -1.5, Interp::Linear), 8.0);
    }
}
