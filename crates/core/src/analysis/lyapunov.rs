//! Lyapunov exponents of a discrete flow: the whole spectrum by repeated QR (Benettin, Galgani,
//! Giorgilli and Strelcyn 1980; Shimada and Nagashima 1979). Generic: it knows no system, only a
//! [`System`], its tangent lift for the method ([`System::tangent_for`],
//! [`crate::integrate::tangent`]) and the method's name.
//!
//! The run is cut into segments of `renormalise_every` steps. The base states are those of the
//! system's plain run ([`Run`]), bit for bit those of [`crate::integrate::integrate`] with the
//! same method and step. At each segment's start the lift is restarted at the plain run's state
//! with the identity as directions ([`TangentSystem::seed`], [`Run::restart_from`]: one run of
//! the lift, with the plain run's clock and retraction schedule), so that its end gives the
//! segment's Jacobian J, exact to round-off: the derivative of the method's own map over the
//! segment (not finite differences, not the continuous variational equations). The lift's own
//! base state is not carried on: it equals the plain run's bit for bit within one lifted run,
//! but a restarted splitting (Strang and its compositions fuse the half-steps of consecutive
//! steps; a processed one applies its processor again) reaches it by other roundings, which a
//! chaotic orbit would amplify; the plain run costs 1/(1 + e + p) of the lift.
//!
//! With Q₀ = I, each segment factors J·Q_{k−1} = Q_k R_k (Householder) and adds
//! log abs((R_k)_ii) to sum_i; after the segment ending at time t_k the estimate is
//! λ_i(t_k) = sum_i / t_k (the run starts at t₀ = 0).
//!
//! Order: column i of Q follows the i-th fastest growth of volumes, so the estimates come out
//! ordered by their limits (λ₁ ≥ λ₂ ≥ …); at finite times the estimates of exponents equal in
//! the limit (the zeros of a Hamiltonian system) can cross. [`Lyapunov::running`] keeps the QR's
//! column order (each column a continuous curve in time); [`Lyapunov::exponents`] is its last
//! row sorted descending.
//!
//! Cost: a lifted step costs about 1 + e + p plain steps (e directions, p parameter directions
//! the lift carries), the plain run one more; the QR is O(e³) per segment. Allocation: the
//! buffers once, when the run starts (the running estimate for every segment included); per
//! segment only the seed of the lift ([`TangentSystem::seed`] returns a new vector); none per
//! step.

use std::sync::Arc;

use crate::check;
use crate::error::{fmt_num, Error, Result};
use crate::integrate::tangent::TangentSystem;
use crate::integrate::{Run, System};

/// The Lyapunov spectrum of a run ([`lyapunov`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Lyapunov {
    /// The e exponents at the end of the run (the last row of `running`), sorted descending.
    pub exponents: Vec<f64>,
    /// The end time t_k of every segment (t₀ = 0), increasing.
    pub times: Vec<f64>,
    /// The estimate after every segment (segments × e, row-major), in the QR's column order.
    pub running: Vec<f64>,
    /// The base state at the end of the run (user frame, d values).
    pub state: Vec<f64>,
}

/// A Lyapunov computation in progress (resumable: a binding advances it by chunks of segments,
/// between which it can notice an interruption). It holds the lift, not the system (as [`Run`]
/// does not): every call takes the system again, and it must be the one it was started with.
pub struct LyapunovRun {
    tangent: Arc<dyn TangentSystem>,
    /// The plain run of the system: the base states.
    base: Run,
    /// The run of the lift, restarted at each segment's start.
    lift: Run,
    every: u64,
    steps: u64,
    segments: usize,
    /// The segments done.
    k: usize,
    /// The lifted state at a segment's end (user frame).
    lifted: Vec<f64>,
    /// The plain run's state at the end of the segments done.
    z: Vec<f64>,
    /// Scratch: the lift's base state at a segment's end (not carried on).
    zl: Vec<f64>,
    /// The segment's Jacobian (e × e, row-major) and the parameter Jacobian (unused).
    jac: Vec<f64>,
    pjac: Vec<f64>,
    /// Q (e × e, row-major): the orthonormal directions carried from segment to segment.
    q: Vec<f64>,
    /// Scratch: J·Q, then R (Householder in place); the Householder vectors.
    a: Vec<f64>,
    house: Vec<f64>,
    sums: Vec<f64>,
    times: Vec<f64>,
    running: Vec<f64>,
    /// The states the runs save (none: save_every beyond the last step), kept for reuse.
    out: Vec<f64>,
}

/// The Lyapunov spectrum of `system` run by its method `method` from `z0` (user frame, d
/// values) for `steps` steps of size `dt`, renormalised every `renormalise_every` steps (the
/// last segment shorter when `steps` is not a multiple of it); see the module docs.
///
/// Errors: `steps` < 1, `renormalise_every` < 1, dt ≤ 0 or non-finite, a system without a
/// tangent lift for `method` ([`Error::InvalidArgument`]); an unknown method
/// ([`Error::UnsupportedMethod`]); a state of the wrong length ([`Error::Shape`]), non-finite
/// or off its space; the run's errors ([`Error::LeftDomain`], a solver's
/// [`Error::NotConverged`], a user function's [`Error::Raised`]); a segment Jacobian that is not
/// finite ([`Error::NonFinite`]) or singular to working precision ([`Error::InvalidArgument`]:
/// renormalise more often).
pub fn lyapunov(
    system: &dyn System,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
    renormalise_every: usize,
) -> Result<Lyapunov> {
    let mut l = LyapunovRun::new(system, method, z0, dt, steps, renormalise_every)?;
    l.advance(system, usize::MAX)?;
    Ok(l.finish())
}

impl LyapunovRun {
    /// Starts the computation of [`lyapunov`] (same arguments and errors).
    pub fn new(
        system: &dyn System,
        method: &str,
        z0: &[f64],
        dt: f64,
        steps: usize,
        renormalise_every: usize,
    ) -> Result<Self> {
        if steps < 1 {
            return Err(Error::invalid("steps", "expected steps ≥ 1, got 0"));
        }
        if renormalise_every < 1 {
            return Err(Error::invalid(
                "renormalise_every",
                "expected renormalise_every ≥ 1, got 0",
            ));
        }
        check::positive("dt", dt)?;
        let plain = system.resolve(method)?;
        let tangent = system.tangent_for(method).ok_or_else(|| {
            Error::invalid(
                "method",
                format!(
                    "{} has no tangent maps for {method:?} (its methods with Jacobians: {})",
                    system.name(),
                    system.tangent_methods().join(", ")
                ),
            )
        })?;
        let lifted_method = tangent.resolve(method)?;
        let (d, e) = (tangent.base_dim(), tangent.tangent_dim());
        let np = tangent.parameter_names().len();
        check::len_of("state0", z0, d)?;
        check::finite_slice("state0", z0)?;
        let segments = steps.div_ceil(renormalise_every);
        let running = check::zeros("running", &[segments, e])?;
        let times = check::zeros("times", &[segments])?;
        // The runs save nothing (save_every beyond the last step): the states are read at the
        // segments' ends.
        let never = steps.saturating_add(1);
        let base = Run::resolved(system, &plain, z0, dt, never, 0.0)?;
        let seed = tangent.seed(z0)?;
        let lift = Run::resolved(tangent.as_ref(), &lifted_method, &seed, dt, never, 0.0)?;
        let mut q = vec![0.0; e * e];
        for i in 0..e {
            q[i * e + i] = 1.0;
        }
        Ok(LyapunovRun {
            tangent,
            base,
            lift,
            every: renormalise_every as u64,
            steps: steps as u64,
            segments,
            k: 0,
            lifted: seed,
            z: z0.to_vec(),
            zl: z0.to_vec(),
            jac: vec![0.0; e * e],
            pjac: vec![0.0; e * np],
            q,
            a: vec![0.0; e * e],
            house: vec![0.0; e * e],
            sums: vec![0.0; e],
            times,
            running,
            out: Vec::new(),
        })
    }

    /// The number of segments of the whole run.
    pub fn segments(&self) -> usize {
        self.segments
    }

    /// The segments done so far.
    pub fn segments_done(&self) -> usize {
        self.k
    }

    /// The number e of exponents.
    pub fn dim(&self) -> usize {
        self.tangent.tangent_dim()
    }

    /// Advances `system` (the one the computation was started with) by at most `segments`
    /// segments (fewer at the end of the run); returns how many were done. After an error the
    /// estimates of the segments done before it stay ([`LyapunovRun::finish`] gives them).
    pub fn advance(&mut self, system: &dyn System, segments: usize) -> Result<usize> {
        let tangent = self.tangent.clone();
        let mut done = 0;
        while done < segments && self.k < self.segments {
            let k = self.k;
            let n = self.every.min(self.steps - self.base.steps_done());
            if k > 0 {
                // The directions restart at the identity at the plain run's state.
                self.lifted = tangent.seed(&self.z)?;
                self.lift.restart_from(tangent.as_ref(), &self.lifted)?;
            }
            self.lift.advance(tangent.as_ref(), n, &mut self.out)?;
            self.base.advance(system, n, &mut self.out)?;
            self.out.clear();
            self.base.checked_state_into(system, &mut self.z);
            self.lift
                .checked_state_into(tangent.as_ref(), &mut self.lifted);
            tangent.jacobian(&self.lifted, &mut self.zl, &mut self.jac, &mut self.pjac);
            let t = self.base.time();
            self.renormalise(k, t)?;
            self.k += 1;
            done += 1;
        }
        Ok(done)
    }

    /// Q, R = qr(J·Q), the logarithms of R's diagonal added up, the estimate of segment `k`
    /// (ending at time `t`) written.
    fn renormalise(&mut self, k: usize, t: f64) -> Result<()> {
        let e = self.dim();
        let at = || format!("segment {k} (t = {})", fmt_num(t));
        if let Some(i) = self.jac.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFinite {
                what: "the Jacobian of a segment".into(),
                location: format!("({}, {}) of {}", i / e, i % e, at()),
            });
        }
        // A = J·Q.
        for i in 0..e {
            for j in 0..e {
                let mut s = 0.0;
                for l in 0..e {
                    s += self.jac[i * e + l] * self.q[l * e + j];
                }
                self.a[i * e + j] = s;
            }
        }
        if let Some(i) = self.a.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFinite {
                what: "the product J·Q of a segment's Jacobian and the directions (renormalise \
                       more often)"
                    .into(),
                location: format!("({}, {}) of {}", i / e, i % e, at()),
            });
        }
        householder(&mut self.a, &mut self.house, &mut self.q, e);
        for i in 0..e {
            let r = self.a[i * e + i].abs();
            if r == 0.0 || !r.is_finite() {
                return Err(Error::invalid(
                    "renormalise_every",
                    format!(
                        "the Jacobian of {} is singular to working precision (R[{i}, {i}] = {}); \
                         renormalise more often",
                        at(),
                        fmt_num(r)
                    ),
                ));
            }
            self.sums[i] += r.ln();
        }
        // t₀ = 0: the elapsed time is t.
        self.times[k] = t;
        for i in 0..e {
            self.running[k * e + i] = self.sums[i] / t;
        }
        Ok(())
    }

    /// The spectrum of the segments done so far (all of them after a complete run).
    pub fn finish(mut self) -> Lyapunov {
        let k = self.segments_done();
        let e = self.dim();
        self.times.truncate(k);
        self.running.truncate(k * e);
        let mut exponents = match k {
            0 => vec![0.0; e],
            _ => self.running[(k - 1) * e..k * e].to_vec(),
        };
        exponents.sort_by(|x, y| y.total_cmp(x));
        let state = self.z;
        Lyapunov {
            exponents,
            times: self.times,
            running: self.running,
            state,
        }
    }
}

/// Householder QR of the e × e row-major `a` in place: R on and above the diagonal (below it
/// zeros), Q written to `q` (e × e), the reflectors kept in `house`. Norms are scaled by the
/// column's largest entry so that no square overflows or underflows.
fn householder(a: &mut [f64], house: &mut [f64], q: &mut [f64], e: usize) {
    for k in 0..e {
        let scale = (k..e).fold(0.0f64, |m, i| m.max(a[i * e + k].abs()));
        let v = &mut house[k * e..(k + 1) * e];
        v.fill(0.0);
        if scale == 0.0 {
            continue;
        }
        let norm = scale
            * (k..e)
                .map(|i| (a[i * e + k] / scale).powi(2))
                .sum::<f64>()
                .sqrt();
        let x0 = a[k * e + k];
        let alpha = if x0 >= 0.0 { -norm } else { norm };
        // v = x − α e₁, normalised; H = I − 2vvᵀ maps x to α e₁.
        for i in k..e {
            v[i] = a[i * e + k] / scale;
        }
        v[k] -= alpha / scale;
        let vn = v[k..].iter().map(|x| x * x).sum::<f64>().sqrt();
        if vn == 0.0 {
            v.fill(0.0);
            continue;
        }
        for x in v[k..].iter_mut() {
            *x /= vn;
        }
        for j in k..e {
            let s: f64 = (k..e).map(|i| v[i] * a[i * e + j]).sum();
            for i in k..e {
                a[i * e + j] -= 2.0 * s * v[i];
            }
        }
        a[k * e + k] = alpha;
        for i in k + 1..e {
            a[i * e + k] = 0.0;
        }
    }
    // Q = H₀ H₁ ⋯ H_{e−1}, accumulated from the right onto the identity.
    q.fill(0.0);
    for i in 0..e {
        q[i * e + i] = 1.0;
    }
    for k in (0..e).rev() {
        let v = &house[k * e..(k + 1) * e];
        if v[k..].iter().all(|&x| x == 0.0) {
            continue;
        }
        for j in 0..e {
            let s: f64 = (k..e).map(|i| v[i] * q[i * e + j]).sum();
            for i in k..e {
                q[i * e + j] -= 2.0 * s * v[i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::householder;

    #[test]
    fn householder_factors() {
        let e = 4;
        let a0: Vec<f64> = (0..16)
            .map(|i| ((i * 7 + 3) % 11) as f64 - 5.0 + 0.1 * i as f64)
            .collect();
        let (mut a, mut h, mut q) = (a0.clone(), vec![0.0; 16], vec![0.0; 16]);
        householder(&mut a, &mut h, &mut q, e);
        for i in 0..e {
            for j in 0..e {
                // QR = A, QᵀQ = I, R upper triangular.
                let qr: f64 = (0..e).map(|l| q[i * e + l] * a[l * e + j]).sum();
                assert!((qr - a0[i * e + j]).abs() < 1e-13, "{qr} {}", a0[i * e + j]);
                let qtq: f64 = (0..e).map(|l| q[l * e + i] * q[l * e + j]).sum();
                assert!((qtq - f64::from(u8::from(i == j))).abs() < 1e-14);
                if i > j {
                    assert_eq!(a[i * e + j], 0.0);
                }
            }
        }
    }
}
