//! Numerical kernels that know no mechanics: Jacobi and Carlson elliptic functions
//! ([`elliptic`]), rotation angles in floating point ([`angle`]), SIMD lanes of the rotation
//! flows ([`simd`]), dense kernels with storage allocated once and the slice norm (`linalg`), and
//! the one finite-difference Jacobian and gradient (`fd`), forward-mode dual numbers (`dual`).

pub mod angle;
pub(crate) mod dual;
pub mod elliptic;
pub(crate) mod fd;
pub(crate) mod linalg;
pub mod simd;
