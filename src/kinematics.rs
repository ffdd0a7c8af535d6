//! Kinematics
