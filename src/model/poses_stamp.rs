//! Which configuration the body poses in [`Data`](super::Data) belong to, so that the stages of
//! one evaluation form them once (docs/architecture.md, "Kinematics once per evaluation").
//!
//! A forward evaluation reads the body poses (`x_parent_body`, `x_world_body`, `s_body`) in
//! several stages: the collision pass, the constraint rows, passive and applied forces, the
//! sensors and `mj_rnePostConstraint`'s accelerations. Each used to recompute them at the same `q`
//! (MuJoCo computes them once, in `mj_kinematics`). The stamp records the `q` of the last full
//! pose pass; a later pass at a bit-identical `q` reuses the buffers. Every pass that writes the
//! buffers at another configuration clears the stamp, and every evaluation starts with it clear
//! (a model edited between two calls is never read through stale poses).

/// Whether two states are the same to the bit (their lengths included): what "the buffers hold
/// this state" means for the stamps (−0.0 and 0.0 differ, a NaN never matches a NaN of
/// another payload).
#[inline]
pub(super) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The configuration the body poses were last formed at, when they still hold.
#[derive(Clone, Debug, Default)]
pub(crate) struct PosesStamp {
    q: Vec<f64>,
    valid: bool,
}

impl PosesStamp {
    /// A clear stamp with room for `nq` coordinates (no allocation when set later).
    pub fn with_capacity(nq: usize) -> Self {
        Self { q: Vec::with_capacity(nq), valid: false }
    }

    /// Whether the body poses are those of configuration `q` (bit for bit).
    #[inline]
    pub fn matches(&self, q: &[f64]) -> bool {
        self.valid && same_bits(&self.q, q)
    }

    /// The body poses now hold configuration `q`.
    #[inline]
    pub fn set(&mut self, q: &[f64]) {
        self.q.clear();
        self.q.extend_from_slice(q);
        self.valid = true;
    }

    /// The body poses may hold anything.
    #[inline]
    pub fn clear(&mut self) {
        self.valid = false;
    }

    /// A pass is about to write the joint transforms at `q`: the stamp holds only if `q` is its own.
    #[inline]
    pub fn keep_if(&mut self, q: &[f64]) {
        if !self.matches(q) {
            self.valid = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::PosesStamp;

    #[test]
    fn a_stamp_holds_for_its_own_configuration_only() {
        let mut s = PosesStamp::with_capacity(2);
        assert!(!s.matches(&[0.0, 1.0]));
        s.set(&[0.0, 1.0]);
        assert!(s.matches(&[0.0, 1.0]));
        assert!(!s.matches(&[-0.0, 1.0])); // bit for bit: −0 is another configuration
        assert!(!s.matches(&[0.0]));
        s.keep_if(&[0.0, 1.0]);
        assert!(s.matches(&[0.0, 1.0]));
        s.keep_if(&[0.0, 2.0]);
        assert!(!s.matches(&[0.0, 1.0]));
        s.set(&[f64::NAN, 1.0]);
        assert!(s.matches(&[f64::NAN, 1.0]));
        s.clear();
        assert!(!s.matches(&[f64::NAN, 1.0]));
    }
}
