//! Generalized pseudo-rigid bodies on GL⁺(n) (001): configuration X ∈ GL⁺(n) with the left,
//! right and two-sided SO(n) actions X ↦ gX, X ↦ Xh⁻¹, X ↦ gXh⁻¹ (001 (2.2), (6.1)).
//!
//! - [`inertia`]: the left/right inertia tensors A^L_X, A^R_X, Ad_X, Adᵀ_X and the bi-inertia
//!   tensor B_X (operator, matrix, closed-form inverse, eigen-decomposition), all through
//!   [`BiInertia`];
//! - [`connection`]: the connections ω^L, ω^R, the bi-connection ω^B, horizontal/vertical
//!   splits and the locked inertia tensors from the metric;
//! - [`momentum`]: angular momentum L, circulation Γ, the body coordinates
//!   (R, A, S, Ω, Ȧ, Λ) and the kinetic energy in its several forms;
//! - [`strata`]: strata and isotropy of the two-sided action;
//! - [`potential`]: SO(n)×SO(n)-invariant potentials U(X) (harmonic, Saint Venant–Kirchhoff,
//!   polytropic volumetric, stretch, self-gravity, sums);
//! - [`gravity`]: the self-gravity of a homogeneous ellipsoid (Chandrasekhar's index symbols and
//!   the potential [`potential::SelfGravity`], n = 3);
//! - [`equilibria`]: relative equilibria, the augmented and amended potentials (001 §8);
//! - [`dynamics`]: the full Hamiltonian system on T*GL⁺(n) (001 (3.22)), the Riemann-ellipsoid
//!   form (3.20), the Lagrangian form (Prop. 4.2) and Dedekind's adjoint motion;
//! - [`riemann`]: the Riemann-ellipsoid variables (Q, N) and their Poisson brackets;
//! - [`reduced`]: the reduced system on the principal stratum (001 §7): reduction,
//!   reconstruction, the reduced vector field and an orbit-preserving splitting integrator;
//! - [`stability`]: energy–momentum and spectral stability of relative equilibria (001 §8);
//! - [`system`]: [`PseudoRigidBody`], the body as a system of the integration driver.
//!
//! Conventions (DESIGN.md): so(n) pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) (001 (2.8)), e_ij basis, ξ block
//! before η block, metric ⟨Y, Z⟩ = tr(YᵀZ) on T_X GL⁺(n) (001 (2.9)).
//!
//! ```
//! use lieflow::lie::so::hat_n;
//! use lieflow::pseudo_rigid::{connection, BiInertia};
//! use lieflow::Mat;
//! // A configuration with distinct singular values, and ξ ⊕ η ∈ so(3) ⊕ so(3).
//! let x = Mat::from_fn(3, 3, |i, j| if i == j { 3.0 - i as f64 } else { 0.1 * (i + 2 * j) as f64 });
//! let (xi, eta) = (hat_n(&[0.1, 0.2, 0.3])?, hat_n(&[0.0, -0.1, 0.4])?);
//! let b = BiInertia::new(&x)?;
//! // The bi-connection recovers ξ ⊕ η from the vertical vector ξX + Xηᵀ (001 (6.19)).
//! let y = connection::vertical_vector(&b, &xi, &eta)?;
//! let (xi2, eta2) = connection::bi_connection(&b, &y)?;
//! assert!((&xi2 - &xi).norm_l2() < 1e-12 && (&eta2 - &eta).norm_l2() < 1e-12);
//! # Ok::<(), lieflow::Error>(())
//! ```

pub mod connection;
pub mod dynamics;
pub mod ellipsoids;
pub mod equilibria;
pub mod gravity;
pub mod inertia;
pub mod momentum;
pub mod potential;
pub mod reduced;
pub mod riemann;
pub mod right_reduced;
pub mod stability;
pub mod strata;
pub mod system;

pub use connection::Action;
pub use inertia::BiInertia;
pub use momentum::Body;
pub use right_reduced::RightReduced;
pub use system::PseudoRigidBody;
