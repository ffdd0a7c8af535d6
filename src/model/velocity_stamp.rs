//! Which state the body velocities `v_body` in [`Data`](super::Data) belong to, so that the
//! stages of one evaluation form them once (docs/architecture.md, "Kinematics once per
//! evaluation", as [`PosesStamp`](super::poses_stamp::PosesStamp) for the poses).
//!
//! RNEA (the velocity stage) or ABA (the acceleration stage without constraint rows) forms every
//! body's velocity at (q, v); the sensor stage of the same evaluation needs them again at the
//! same (q, v) for its velocity sensors and `mj_rnePostConstraint`'s accelerations. The
//! velocities are a function of (q, v) alone (the joint transforms and motion subspaces at q,
//! then X⁻¹ v_parent + S v per body, the same expression in RNEA, ABA and `forward_velocities`),
//! so RNEA and ABA record the state they formed them at, and a later pass at a bit-identical
//! (q, v) reuses them. Every other pass that writes `v_body`
//! clears the stamp, and so does every evaluation's start (with the poses stamp: a model edited
//! between two calls is never read through stale velocities).

use super::poses_stamp::same_bits;

/// The state (q, v) the body velocities were last formed at by a pass that records it.
#[derive(Clone, Debug, Default)]
pub(crate) struct VelocityStamp {
    q: Vec<f64>,
    v: Vec<f64>,
    valid: bool,
}

impl VelocityStamp {
    /// A clear stamp with room for `nq` coordinates and `nv` velocities (no allocation when set
    /// later).
    pub fn with_capacity(nq: usize, nv: usize) -> Self {
        Self { q: Vec::with_capacity(nq), v: Vec::with_capacity(nv), valid: false }
    }

    /// Whether the body velocities are those of the state (`q`, `v`) (bit for bit).
    #[inline]
    pub fn matches(&self, q: &[f64], v: &[f64]) -> bool {
        self.valid && same_bits(&self.q, q) && same_bits(&self.v, v)
    }

    /// The body velocities now hold the state (`q`, `v`).
    #[inline]
    pub fn set(&mut self, q: &[f64], v: &[f64]) {
        self.q.clear();
        self.q.extend_from_slice(q);
        self.v.clear();
        self.v.extend_from_slice(v);
        self.valid = true;
    }

    /// The body velocities may hold anything.
    #[inline]
    pub fn clear(&mut self) {
        self.valid = false;
    }
}

#[cfg(test)]
mod tests {
    use super::VelocityStamp;

    #[test]
    fn a_stamp_holds_for_its_own_state_only() {
        let mut s = VelocityStamp::with_capacity(2, 1);
        assert!(!s.matches(&[0.0, 1.0], &[2.0]));
        s.set(&[0.0, 1.0], &[2.0]);
        assert!(s.matches(&[0.0, 1.0], &[2.0]));
        assert!(!s.matches(&[0.0, 1.0], &[-2.0]));
        assert!(!s.matches(&[-0.0, 1.0], &[2.0])); // bit for bit
        assert!(!s.matches(&[0.0, 1.0], &[]));
        s.clear();
        assert!(!s.matches(&[0.0, 1.0], &[2.0]));
    }
}
