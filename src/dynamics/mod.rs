//! Dynamics
