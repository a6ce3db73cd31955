//! Classical fourth-order Runge–Kutta (Kutta 1901; Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! §II.1) for a [`VectorField`]: the non-geometric baseline. It preserves no Casimir, no momentum
//! map and not the group (an attitude integrated by RK4 leaves SO(3)); its energy error drifts on
//! long runs.

use crate::error::Result;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::problem::VectorField;

/// Classical RK4.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Rk4;

impl<P: VectorField + Clone + 'static> Integrator<P> for Rk4 {
    fn properties(&self) -> Properties {
        Properties::plain(4)
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let n = problem.space().dim();
        Ok(Box::new(Rk4Stepper {
            problem: problem.clone(),
            h: dt,
            y: vec![0.0; n],
            k: [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            tmp: vec![0.0; n],
        }))
    }
}

struct Rk4Stepper<P> {
    problem: P,
    h: f64,
    y: Vec<f64>,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
}

impl<P: VectorField> Stepper for Rk4Stepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.y.copy_from_slice(z);
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        z.copy_from_slice(&self.y);
    }

    fn advance(&mut self, steps: usize, _clock: Clock) -> Result<()> {
        let Rk4Stepper {
            problem: f,
            h,
            y,
            k: [k1, k2, k3, k4],
            tmp,
        } = self;
        let h = *h;
        let stage = |tmp: &mut [f64], y: &[f64], k: &[f64], c: f64| {
            for i in 0..y.len() {
                tmp[i] = y[i] + c * k[i];
            }
        };
        for _ in 0..steps {
            f.field(y, k1);
            stage(tmp, y, k1, 0.5 * h);
            f.field(tmp, k2);
            stage(tmp, y, k2, 0.5 * h);
            f.field(tmp, k3);
            stage(tmp, y, k3, h);
            f.field(tmp, k4);
            for i in 0..y.len() {
                y[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
            }
        }
        Ok(())
    }
}
