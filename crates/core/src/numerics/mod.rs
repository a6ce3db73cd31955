//! Numerical kernels that know no mechanics: Jacobi and Carlson elliptic functions
//! ([`elliptic`]), rotation angles in floating point ([`angle`]), SIMD lanes of the rotation
//! flows ([`simd`]) and dense kernels with storage allocated once (`linalg`).

pub mod angle;
pub mod elliptic;
pub(crate) mod fd;
pub(crate) mod linalg;
pub mod simd;
