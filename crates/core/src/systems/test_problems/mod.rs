//! Test problems of the problem kinds that the source texts' systems do not cover: the planar
//! pendulum (canonical, separable; [`pendulum`]), a particle on a sphere (holonomic constraint;
//! [`sphere_particle`]) and the vertical rolling disk (nonholonomic; [`rolling_disk`]).

pub mod pendulum;
pub mod rolling_disk;
pub mod sphere_particle;

pub use pendulum::Pendulum;
pub use rolling_disk::RollingDisk;
pub use sphere_particle::SphereParticle;
