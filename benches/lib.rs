//! Criterion benchmarks of lieflow live in `benches/`; this library is empty.
