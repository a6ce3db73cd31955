//! Classical fourth-order Runge–Kutta (Kutta 1901; Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! §II.1): the non-geometric baseline. It preserves no Casimir, no momentum map and not the group
//! (an attitude integrated by RK4 leaves SO(3)); its energy error drifts on long runs.

use super::Result;

/// A vector field y' = f(y) on a flat state.
pub trait VectorField {
    /// Evaluates f(y) into `dy` (same length as `y`).
    fn eval(&self, y: &[f64], dy: &mut [f64]);
}

/// RK4 with its stage buffers allocated once.
pub struct Rk4 {
    h: f64,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
}

impl Rk4 {
    /// A stepper of step `h` for states of length `n`.
    pub fn new(h: f64, n: usize) -> Self {
        Rk4 {
            h,
            k: [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            tmp: vec![0.0; n],
        }
    }

    /// Advances `y` by `steps` steps of y' = f(y).
    pub fn run(&mut self, f: &impl VectorField, y: &mut [f64], steps: usize) -> Result<()> {
        let h = self.h;
        let [k1, k2, k3, k4] = &mut self.k;
        let tmp = &mut self.tmp;
        for _ in 0..steps {
            f.eval(y, k1);
            for i in 0..y.len() {
                tmp[i] = y[i] + 0.5 * h * k1[i];
            }
            f.eval(tmp, k2);
            for i in 0..y.len() {
                tmp[i] = y[i] + 0.5 * h * k2[i];
            }
            f.eval(tmp, k3);
            for i in 0..y.len() {
                tmp[i] = y[i] + h * k3[i];
            }
            f.eval(tmp, k4);
            for i in 0..y.len() {
                y[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
            }
        }
        Ok(())
    }
}
