//! The rolling bodies of 003 (`lieflow::systems::rolling`): two rolling disks, two rolling spheres.

pub(crate) mod disks;
pub(crate) mod spheres;
