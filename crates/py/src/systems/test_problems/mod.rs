//! The test problems of the mechanics core (`lieflow::systems::test_problems`): the pendulum, the
//! particle on a sphere (holonomic) and the rolling disk (nonholonomic).

pub(crate) mod pendulum;
pub(crate) mod rolling_disk;
