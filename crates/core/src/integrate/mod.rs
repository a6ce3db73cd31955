//! TODO
pub mod verlet;
