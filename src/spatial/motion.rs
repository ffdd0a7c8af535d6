//! Spatial motion and force vectors and their cross products (RBDA §2.9, eq. 2.31–2.33).

use super::Vec3;
use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// Spatial motion vector (velocity or acceleration): angular part `ang`, linear part `lin`
/// (velocity of the body-fixed point at the frame origin), in the coordinates of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Motion {
    /// Angular part (rad/s, or rad/s² for an acceleration).
    pub ang: Vec3,
    /// Linear part: of the body-fixed point at the frame origin (m/s, or m/s²).
    pub lin: Vec3,
}

/// Spatial force vector: moment `ang` about the frame origin and force `lin`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Force {
    /// Moment about the frame origin (N·m).
    pub ang: Vec3,
    /// Force (N).
    pub lin: Vec3,
}

impl Motion {
    /// The motion with angular part `ang` and linear part `lin`.
    pub const fn new(ang: Vec3, lin: Vec3) -> Self {
        Self { ang, lin }
    }
    /// The zero motion.
    pub fn zero() -> Self {
        Self::default()
    }
    /// Motion cross motion `self ×  m` (RBDA eq. 2.31): the rate of change of `m` carried by a frame
    /// moving with velocity `self`.
    #[inline]
    pub fn cross_motion(&self, m: &Motion) -> Motion {
        Motion { ang: self.ang.cross(&m.ang), lin: self.ang.cross(&m.lin) + self.lin.cross(&m.ang) }
    }
    /// Motion cross force `self ×* f` (RBDA eq. 2.32).
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force { ang: self.ang.cross(&f.ang) + self.lin.cross(&f.lin), lin: self.ang.cross(&f.lin) }
    }
    /// Scalar product with a force: the power `m · f`.
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        self.ang.dot(&f.ang) + self.lin.dot(&f.lin)
    }
}

impl Force {
    /// The force with moment `ang` and force `lin`.
    pub const fn new(ang: Vec3, lin: Vec3) -> Self {
        Self { ang, lin }
    }
    /// The zero force.
    pub fn zero() -> Self {
        Self::default()
    }
}

macro_rules! vector_ops {
    ($t:ident) => {
        impl Add for $t {
            type Output = $t;
            #[inline]
            fn add(self, o: $t) -> $t {
                $t { ang: self.ang + o.ang, lin: self.lin + o.lin }
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline]
            fn sub(self, o: $t) -> $t {
                $t { ang: self.ang - o.ang, lin: self.lin - o.lin }
            }
        }
        impl AddAssign for $t {
            #[inline]
            fn add_assign(&mut self, o: $t) {
                self.ang += o.ang;
                self.lin += o.lin;
            }
        }
        impl Neg for $t {
            type Output = $t;
            #[inline]
            fn neg(self) -> $t {
                $t { ang: -self.ang, lin: -self.lin }
            }
        }
        impl Mul<f64> for $t {
            type Output = $t;
            #[inline]
            fn mul(self, s: f64) -> $t {
                $t { ang: self.ang * s, lin: self.lin * s }
            }
        }
    };
}
vector_ops!(Motion);
vector_ops!(Force);
