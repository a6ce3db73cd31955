//! TODO
pub mod dynamics;
pub mod potential;
