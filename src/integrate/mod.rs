//! Integrators
