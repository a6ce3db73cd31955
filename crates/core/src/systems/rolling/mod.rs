//! 003: rolling contact. Two disks rolling against each other (§1, [`disks`]) and two spheres
//! rolling against each other (§2, [`spheres`]).

pub mod disks;
pub mod spheres;

pub use disks::RollingDisks;
pub use spheres::RollingSpheres;
