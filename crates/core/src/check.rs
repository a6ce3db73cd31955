//! Input validation shared by every module: finiteness, squareness, sizes.

use crate::error::{Error, Result};
use crate::Mat;

/// Checks that every entry of `m` is finite.
pub fn finite_mat(what: &str, m: &Mat) -> Result<()> {
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if !m[(i, j)].is_finite() {
                return Err(Error::NonFinite {
                    what: what.into(),
                    location: format!("({i}, {j})"),
                });
            }
        }
    }
    Ok(())
}

/// Checks that every entry of a slice is finite.
pub fn finite_slice(what: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(Error::NonFinite {
            what: what.into(),
            location: format!("index {i}"),
        }),
        None => Ok(()),
    }
}

/// Checks that every entry of a batch of items is finite: `data` holds the items of shape `item`
/// one after another (row-major). The first non-finite entry is `Err((k, e))`: it lies in item k,
/// and `e` names its place in the item ("index i" in a vector, "(i, j)" in a matrix, numpy's
/// index otherwise), so that the caller names the item its own way (a batch member, `R[k]`),
/// never by a flat index.
pub fn finite_items(
    what: &str,
    data: &[f64],
    item: &[usize],
) -> std::result::Result<(), (usize, Error)> {
    let Some(at) = data.iter().position(|x| !x.is_finite()) else {
        return Ok(());
    };
    let len: usize = item.iter().product();
    let (k, mut r) = (at / len.max(1), at % len.max(1));
    let mut place = vec![0; item.len()];
    for (p, &n) in place.iter_mut().zip(item).rev() {
        (*p, r) = (r % n.max(1), r / n.max(1));
    }
    let location = match place.as_slice() {
        [i] => format!("index {i}"),
        p => format!(
            "({})",
            p.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    Err((
        k,
        Error::NonFinite {
            what: what.into(),
            location,
        },
    ))
}

/// Checks that `m` is square n×n with n ≥ `min_n` and finite; returns n.
pub fn square(what: &str, m: &Mat, min_n: usize) -> Result<usize> {
    let (r, c) = (m.nrows(), m.ncols());
    if r != c || r < min_n {
        return Err(Error::shape(
            what,
            format!("a square (n, n) matrix with n ≥ {min_n}"),
            format!("({r}, {c})"),
        ));
    }
    finite_mat(what, m)?;
    Ok(r)
}

/// Checks that `m` is n×n (n given) and finite.
pub fn square_of(what: &str, m: &Mat, n: usize) -> Result<()> {
    if m.nrows() != n || m.ncols() != n {
        return Err(Error::shape(
            what,
            format!("({n}, {n})"),
            format!("({}, {})", m.nrows(), m.ncols()),
        ));
    }
    finite_mat(what, m)
}

/// Checks that a slice has length `len` and is finite.
pub fn len_of(what: &str, v: &[f64], len: usize) -> Result<()> {
    if v.len() != len {
        return Err(Error::shape(
            what,
            format!("({len},)"),
            format!("({},)", v.len()),
        ));
    }
    finite_slice(what, v)
}

/// Checks a d×d matrix (row-major) `a` described as `expected` in errors: d² values, finite,
/// symmetric to 10⁻¹² of its largest entry (the error names the worst pair).
pub fn symmetric(what: &str, expected: &str, a: &[f64], d: usize) -> Result<()> {
    if a.len() != d * d {
        return Err(Error::shape(
            what,
            format!("{expected} ({d}, {d})"),
            format!("{} values", a.len()),
        ));
    }
    finite_slice(what, a)?;
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for i in 0..d {
        for j in i + 1..d {
            let s = (a[i * d + j] - a[j * d + i]).abs();
            if s > 1e-12 * scale {
                return Err(Error::invalid(
                    what,
                    format!("must be symmetric: |A[{i}, {j}] − A[{j}, {i}]| = {s:.3e}"),
                ));
            }
        }
    }
    Ok(())
}

/// Checks that a scalar is finite and strictly positive.
pub fn positive(what: &str, x: f64) -> Result<()> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            what,
            format!(
                "expected a finite number > 0, got {}",
                crate::error::fmt_num(x)
            ),
        ))
    }
}

/// Largest dense array lieflow allocates on request: 2²⁸ entries (2 GiB of f64). Larger requests
/// (e.g. the n(n−1)×n(n−1) bi-inertia matrix at n ≳ 130) are refused with a clear error instead
/// of aborting the process when the allocation fails.
pub const MAX_DENSE_ENTRIES: usize = 1 << 28;

/// Checks that a dense `rows × cols` array fits [`MAX_DENSE_ENTRIES`] (without overflow).
pub fn dense_size(what: &str, rows: usize, cols: usize) -> Result<()> {
    match rows.checked_mul(cols) {
        Some(k) if k <= MAX_DENSE_ENTRIES => Ok(()),
        _ => Err(Error::invalid(
            what,
            format!(
                "a dense {rows}×{cols} array exceeds the limit of {MAX_DENSE_ENTRIES} entries \
                 (2 GiB); use the operator form or a smaller n"
            ),
        )),
    }
}

/// Largest array of a mapped or batched call (its output, or an input read into memory): 2³² − 1
/// entries (32 GiB of f64), and never more than the memory available (see [`array_size`]).
/// Larger requests (e.g. a broadcast input of 10¹⁰ items) are refused with a clear error instead
/// of aborting the process when the allocation fails or being killed when it is used.
pub const MAX_ARRAY_ENTRIES: usize = u32::MAX as usize;

/// Arrays up to this many bytes are allocated without asking the system how much memory is left.
const CHECKED_BYTES: u64 = 1 << 30;

/// The memory available for new allocations in bytes (Linux: the smaller of `MemAvailable` of
/// /proc/meminfo and the room left under the process's address-space limit, `ulimit -v`),
/// `None` where unknown.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    let free = kib.saturating_mul(1024);
    Some(address_space_room().map_or(free, |room| room.min(free)))
}

/// The bytes left under the soft address-space limit (`RLIMIT_AS`: /proc/self/limits against
/// `VmSize` of /proc/self/status), `None` without a limit.
fn address_space_room() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let limit: u64 = line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(limit.saturating_sub(kib.saturating_mul(1024)))
}

/// Watches the memory that building `total` items one after another takes (the runs of a
/// batch, whose size per item no formula gives: it depends on the system and the method): after
/// `built` items, [`BuildBudget::check`] refuses to go on when the items left, at the average
/// cost so far, would not fit in what is still available, instead of letting an allocation
/// abort the process.
pub struct BuildBudget {
    what: &'static str,
    total: usize,
    start: Option<u64>,
}

impl BuildBudget {
    /// Below this much memory taken so far no estimate is made (other processes' noise).
    const MIN_MEASURED: u64 = 256 << 20;

    /// A budget for `total` items, named `what` in errors.
    pub fn new(what: &'static str, total: usize) -> Self {
        BuildBudget {
            what,
            total,
            start: available_memory(),
        }
    }

    /// Ok unless the `total − built` items left, at the cost per item measured over the first
    /// `built`, need more than 7/8 of the memory still available ([`Error::InvalidArgument`]).
    pub fn check(&self, built: usize) -> Result<()> {
        let (Some(start), Some(now)) = (self.start, available_memory()) else {
            return Ok(());
        };
        let used = start.saturating_sub(now);
        if built == 0 || used < Self::MIN_MEASURED {
            return Ok(());
        }
        let per = used as f64 / built as f64;
        let need = per * self.total.saturating_sub(built) as f64;
        if need <= (now / 8 * 7) as f64 {
            return Ok(());
        }
        let gib = |b: f64| b / (1u64 << 30) as f64;
        Err(Error::invalid(
            self.what,
            format!(
                "the {} members need about {:.1} GiB ({:.1} KiB each, measured over the first \
                 {built}), more than the memory available; integrate fewer at a time",
                self.total,
                gib(per * self.total as f64),
                per / 1024.0
            ),
        ))
    }
}

/// A shape as numpy prints it: "(3,)", "(2, 3)".
fn shape_text(shape: &[usize]) -> String {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    }
}

/// The number of entries of an f64 array of shape `shape` (a product without overflow), refused
/// above [`MAX_ARRAY_ENTRIES`] or when its bytes exceed the memory available (where known):
/// allocating it would abort the process, or get it killed by the system when the memory is
/// used. `what` names the argument the array comes from.
pub fn array_size(what: &str, shape: &[usize]) -> Result<usize> {
    let gib = |bytes: f64| bytes / (1u64 << 30) as f64;
    let len = shape
        .iter()
        .try_fold(1usize, |k, &d| k.checked_mul(d))
        .filter(|&k| k <= MAX_ARRAY_ENTRIES)
        .ok_or_else(|| {
            let total = shape.iter().map(|&d| d as f64).product::<f64>();
            Error::invalid(
                what,
                format!(
                    "an array of shape {} ({total:.2e} entries) exceeds the limit of \
                     {MAX_ARRAY_ENTRIES} entries (32 GiB)",
                    shape_text(shape)
                ),
            )
        })?;
    let bytes = len as u64 * 8;
    if bytes > CHECKED_BYTES {
        // 7/8 of what is available: the call allocates a little more (its other arrays).
        if let Some(free) = available_memory().filter(|&free| bytes > free / 8 * 7) {
            return Err(Error::invalid(
                what,
                format!(
                    "an array of shape {} needs {:.1} GiB, more than the {:.1} GiB one array \
                     may take (7/8 of the {:.1} GiB of memory available)",
                    shape_text(shape),
                    gib(bytes as f64),
                    gib((free / 8 * 7) as f64),
                    gib(free as f64)
                ),
            ));
        }
    }
    Ok(len)
}

/// A zero-filled buffer for an f64 array of shape `shape` (checked by [`array_size`]),
/// allocated fallibly: a refused or failed allocation is [`Error::InvalidArgument`] naming
/// `what`, never an abort.
pub fn zeros(what: &str, shape: &[usize]) -> Result<Vec<f64>> {
    let len = array_size(what, shape)?;
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        Error::invalid(
            what,
            format!(
                "cannot allocate an array of shape {} ({:.1} GiB)",
                shape_text(shape),
                len as f64 * 8.0 / (1u64 << 30) as f64
            ),
        )
    })?;
    v.resize(len, 0.0);
    Ok(v)
}

// ---------------------------------------------------------------------------------------------
// Scale-aware evaluation (issue 16: no NaN or inf from finite input). A homogeneous formula is
// evaluated on arguments divided by exact powers of two 2^e (largest entry in [1, 2)), and its
// result multiplied back by 2^(Σ degree·e) once, with an overflow error where the result is not
// representable. Moderate arguments (largest entry in [1e-100, 1e100]) get e = 0, so their
// results stay bit for bit what the plain formula gives.

/// The exponent e of the power of two 2^e ≤ m < 2^(e+1) when m lies outside [1e-100, 1e100], else
/// 0 (also for m = 0 or m not finite): dividing by 2^e brings an extreme magnitude into [1, 2).
pub fn pow2_exponent(m: f64) -> i32 {
    if (1e-100..=1e100).contains(&m) {
        return 0;
    }
    pow2_floor(m)
}

/// The exponent e of the power of two 2^e ≤ m < 2^(e+1) for a finite m > 0 (0 otherwise), at
/// every scale (unlike [`pow2_exponent`], which leaves moderate magnitudes alone).
pub fn pow2_floor(m: f64) -> i32 {
    if !(m.is_finite() && m > 0.0) {
        return 0;
    }
    let e = m.log2().floor() as i32;
    // log2 may round up across a power of two.
    if ldexp(1.0, e) > m {
        e - 1
    } else {
        e
    }
}

/// [`pow2_exponent`] of the largest |entry| of the values.
pub fn pow2_exponent_of(values: impl IntoIterator<Item = f64>) -> i32 {
    pow2_exponent(values.into_iter().fold(0.0f64, |m, x| m.max(x.abs())))
}

/// The largest |entry| of a matrix (0 for an empty one).
pub fn max_abs(m: &Mat) -> f64 {
    (0..m.ncols())
        .flat_map(|j| (0..m.nrows()).map(move |i| m[(i, j)]))
        .fold(0.0f64, |a, x| a.max(x.abs()))
}

/// [`pow2_exponent`] of the largest |entry| of a matrix.
pub fn pow2_exponent_mat(m: &Mat) -> i32 {
    pow2_exponent(max_abs(m))
}

/// x·2^e, exact where the result is a normal number; applied in steps so that 2^e itself need
/// not be representable (e may be far outside ±1022).
pub fn ldexp(mut x: f64, mut e: i32) -> f64 {
    const STEP: i32 = 1000;
    while e > STEP {
        x *= 2f64.powi(STEP);
        e -= STEP;
    }
    while e < -STEP {
        x *= 2f64.powi(-STEP);
        e += STEP;
    }
    x * 2f64.powi(e)
}

/// m·2^e entrywise ([`ldexp`]).
pub fn ldexp_mat(m: &Mat, e: i32) -> Mat {
    if e == 0 {
        return m.clone();
    }
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| ldexp(m[(i, j)], e))
}

/// The overflow error of a scale-aware formula: `what` names the argument(s), `quantity` the
/// result that exceeds the f64 range.
pub fn overflow_error(what: &str, quantity: &str) -> Error {
    Error::overflow(
        what,
        format!("{quantity} exceeds the f64 range (about 1.8e308) at this scale of {what}"),
    )
}

/// x·2^e ([`ldexp`]), or [`overflow_error`] where it is not finite.
pub fn unscale(what: &str, quantity: &str, x: f64, e: i32) -> Result<f64> {
    let v = ldexp(x, e);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(overflow_error(what, quantity))
    }
}

/// m·2^e ([`ldexp_mat`]), or [`overflow_error`] where an entry is not finite.
pub fn unscale_mat(what: &str, quantity: &str, m: &Mat, e: i32) -> Result<Mat> {
    let v = ldexp_mat(m, e);
    let finite = (0..v.ncols()).all(|j| (0..v.nrows()).all(|i| v[(i, j)].is_finite()));
    if finite {
        Ok(v)
    } else {
        Err(overflow_error(what, quantity))
    }
}

/// x₀y₁ − x₁y₀ (the planar cross product, e.g. an angular momentum x p_y − y p_x) scale-aware:
/// exact powers of two are factored out of x and y, and an overflow error naming `what` is
/// returned where the result is not representable.
pub fn cross2(what: &str, quantity: &str, x: [f64; 2], y: [f64; 2]) -> Result<f64> {
    let (ex, ey) = (pow2_exponent_of(x), pow2_exponent_of(y));
    let (x0, x1) = (ldexp(x[0], -ex), ldexp(x[1], -ex));
    let (y0, y1) = (ldexp(y[0], -ey), ldexp(y[1], -ey));
    unscale(what, quantity, x0 * y1 - x1 * y0, ex + ey)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_array_names_the_share_of_memory_it_may_take() {
        // Between 7/8 of the memory available and all of it: refused, and the message names
        // the 7/8 it may take beside the whole (the memory available may move meanwhile: the
        // two numbers are read back from the message).
        let Some(free) = available_memory() else {
            return;
        };
        let n = (free / 8 * 7 / 8 + free / 512) as usize;
        let Err(Error::InvalidArgument { message, .. }) = array_size("steps", &[n]) else {
            return;
        };
        let number = |after: &str| -> f64 {
            let rest = &message[message.find(after).expect(after) + after.len()..];
            rest.split(' ').next().unwrap().parse().unwrap()
        };
        let (may, whole) = (number("more than the "), number("(7/8 of the "));
        assert!(
            message.contains("GiB one array may take (7/8 of the"),
            "{message}"
        );
        assert!((may - whole * 7.0 / 8.0).abs() <= 0.1, "{message}");
        assert!(number("needs ") > may, "{message}");
    }

    #[test]
    fn rejects_nan_and_shape() {
        let mut m = Mat::zeros(3, 3);
        assert_eq!(square("X", &m, 2), Ok(3));
        m[(1, 2)] = f64::NAN;
        assert!(matches!(square("X", &m, 2), Err(Error::NonFinite { .. })));
        let r = Mat::zeros(2, 3);
        assert!(matches!(square("X", &r, 2), Err(Error::Shape { .. })));
        assert!(positive("dt", 0.0).is_err());
        assert!(positive("dt", f64::INFINITY).is_err());
        assert!(len_of("v", &[1.0, 2.0], 3).is_err());
        assert!(len_of("v", &[1.0, f64::NAN], 2).is_err());
        assert!(dense_size("B", 1 << 14, 1 << 14).is_ok());
        assert!(dense_size("B", (1 << 14) + 1, 1 << 14).is_err());
        assert!(dense_size("B", usize::MAX, 2).is_err());
        assert_eq!(zeros("w", &[2, 3]).map(|v| v.len()), Ok(6));
        assert!(zeros("w", &[10_000_000_000, 3, 3]).is_err());
        assert!(array_size("w", &[usize::MAX, 2]).is_err());
    }

    #[test]
    fn scale_helpers() {
        assert_eq!(pow2_exponent(1.0), 0);
        assert_eq!(pow2_exponent(1e99), 0);
        assert_eq!(pow2_exponent(f64::MAX), 1023);
        assert_eq!(pow2_exponent(1e300), 996);
        assert_eq!(pow2_exponent(5e-324), -1074);
        assert_eq!(ldexp(1.0, 1023), 2f64.powi(1023));
        assert_eq!(ldexp(ldexp(3.0, -1074), 1074), 3.0 * 1.0);
        assert_eq!(ldexp(1.5, 2000), f64::INFINITY);
        assert_eq!(cross2("z", "L", [1e300, 0.0], [0.0, 1e-300]), Ok(1.0));
        assert!(cross2("z", "L", [1e300, 0.0], [0.0, 1e300]).is_err());
        assert_eq!(cross2("z", "L", [1.0, 2.0], [3.0, 4.0]), Ok(-2.0));
    }
}
