//! 002 §IV: the relativistic tangent Euler top in Minkowski space-time and on a curved static
//! space-time −dt² + γ_ij dxⁱdxʲ over a surface ([`RelativisticTangentTop`], 002 (87)–(111)), and
//! in the weak-field limit of a static gravitational potential φ(x, y) ([`WeakFieldTop`],
//! 002 (115)–(120)), and on the static space-time of the potential itself, flat or over a
//! surface ([`StaticFieldTop`], 002 (115)–(117)).
//!
//! # Set-up (002 (81)–(82))
//! A planar body with mass distribution dm(ξ), centre of mass at ξ = 0, second-moment tensor
//! I = ∫ ξ ξᵀ dm (2×2; 𝕀 = tr I as in 002 (42); a symmetric top has I = (𝕀/2)·Id). Its frame is
//! E_i = S_ji Ê_j with S = R(θ) the rotation by θ (E₁ = cos θ Ê₁ + sin θ Ê₂, as in 002 (41)), and
//! time is that of a distant static observer (E₀ = ∂_t normalised). Definition IV.1 (002 (82)):
//! the Lagrangian is the integral over the body of √|⟨ċ + ξⁱ∇_ċE_i, ċ + ξʲ∇_ċE_j⟩|, expanded to
//! second order in ξ (odd orders integrate to zero).
//!
//! **Sign convention.** 002 (82)–(118) write L with the sign +m√(1 − v²); here L is the physical
//! action density −∫dτ dm, the negative of the seed's. The Euler–Lagrange equations are the same;
//! momenta and energies change sign: our p_θ and energy are −(seed's), so 002 (96) reads
//! E = +mγ + … here.
//!
//! # Minkowski (002 (87)–(96))
//! With ∇_ċE_i = Ṡ_ji Ê_j and |ċ|² = −1 + |ẋ|², the integrand is
//! √(1 − v² − 2ẋ·Ṡξ − |Ṡξ|²) = √(1−v²) − ẋ·Ṡξ/√(1−v²) − |Ṡξ|²/(2√(1−v²))
//! − (ẋ·Ṡξ)²/(2(1−v²)^{3/2}) + O(ξ³), and with Ṡ = θ̇ J S (J the rotation by π/2),
//! K(θ) = S J I Jᵀ Sᵀ, γ = (1 − v²)^{−1/2}:
//!
//! L(ẋ, θ, θ̇) = −m/γ + ½ θ̇² (𝕀 γ + γ³ ẋᵀK(θ)ẋ),        (002 (90), physical sign)
//!
//! which agrees with 002 (90) (tr(ṠIṠᵀ) = θ̇² 𝕀). **Which variables it depends on:** although
//! (81)–(82) look second order, with E₀ = ∂_t the frame is rotated by S(θ) only, so L depends on
//! (ẋ, θ, θ̇) and not on ẍ: it is a first-order Lagrangian on T(ℝ² × S¹), x is cyclic (p = ∂L/∂ẋ
//! is conserved), and for the symmetric top (K = (𝕀/2) Id) θ is cyclic too. No Ostrogradsky
//! construction is needed; the system is integrated in canonical form with the Hamiltonian
//! H(q, p) = p·q̇ − L, q = (x, y, θ), the velocities q̇(q, p) found by inverting the Legendre map
//! p = ∂L/∂q̇ with Newton's method (the Hessian ∂²L/∂q̇² must be positive definite: it is for
//! slow, slowly spinning tops, and the state check says where it is not).
//!
//! **Symmetric top (002 (93)–(96)).** With I₀ = 𝕀/2 (the seed's I), L = −m/γ + I₀θ̇²γ(1 + ½v²γ²)
//! (002 (93)). The momenta p = (mγ + I₀θ̇²(2γ³ + (3/2)v²γ⁵)) ẋ and
//! J = p_θ = 2I₀θ̇γ(1 + ½v²γ²) are conserved; so (the Legendre map being invertible) ẋ and θ̇ are
//! constant. Eliminating θ̇, with 1 + ½v²γ² = ½(2 − v²)γ² and 2γ² + (3/2)v²γ⁴ = ½(4 − v²)γ⁴,
//!
//! |p| = mγv (1 + J²(1 − v²)(4 − v²) / (2 I₀ m (2 − v²)²)),          (002 (94))
//! θ̇ = J / (2 I₀ γ (1 + ½v²γ²)),                                    (002 (95))
//! E = mγ + I₀θ̇² (γ + (5/2) v²γ³ + (3/2) v⁴γ⁵).                     (002 (96))
//!
//! These agree with the seed once its "J" is read as half the canonical momentum p_θ (its (95)
//! has I where 2I₀ = 𝕀 would stand with J = p_θ; (94) then has 4J² for J²) and the overall sign
//! of (96) is that of its Lagrangian. **Slip:** the seed concludes from (94) that v is fixed by
//! |p| because the left side "is never constant on an interval"; that does not make it
//! injective, and it is not: with κ = J²/(2I₀m) > 7.34 the function v ↦ |p| decreases on an
//! interval below v = 1 (at κ = 10 on about 0.908 < v < 0.976), so one |p| belongs to up to
//! three speeds, and the Legendre map is singular where the slope vanishes. (κ ~ rotational
//! energy over rest energy, far outside the small-body expansion; below the threshold the claim
//! holds.)
//! What makes v constant is the invertibility of the Legendre map along the motion, which
//! [`RelativisticTangentTop`] checks.
//!
//! # Curved static space-time (002 (97)–(111))
//! The metric ds² = −dt² + γ_ij dxⁱdxʲ with γ = g the metric of a [`Surface`] (orthonormal frame
//! Ê_a, connection 1-form w(v) = ⟨∇_vÊ₁, Ê₂⟩ = α·v, see [`crate::systems::tangent_top::surface`]). The lapse is
//! 1, so ∂_t is parallel and no Christoffel symbol carries a t (002 (86)): with ċ = ∂_t + ẋ and
//! E₁ = cos θ Ê₁ + sin θ Ê₂, E₂ = −sin θ Ê₁ + cos θ Ê₂,
//!
//! ∇_ċE₁ = s E₂,  ∇_ċE₂ = −s E₁,   s = θ̇ + α·ẋ   (the covariant spin rate),
//!
//! i.e. in the reference frame ∇_ċE_i = (Ṡ + ΩS)_ji Ê_j with Ω = w(ẋ) J, Ṡ + ΩS = s J S. With the
//! frame components u_a = g(ẋ, Ê_a) of ẋ (|u|² = g(ẋ, ẋ) = v²), the integrand of (82) is
//! √(1 − |u + s J S ξ|²), the Minkowski one with ẋ → u and θ̇ → s. So, to second order in ξ,
//!
//! L = −m/γ + ½ s² (𝕀γ + γ³ uᵀK(θ)u),   γ = (1 − g(ẋ, ẋ))^{−1/2},      (002 (102), physical sign)
//!
//! and for the symmetric top (K = (𝕀/2) Id, uᵀKu = 𝕀v²/2)
//!
//! L = −m/γ + ½ 𝕀 s² (γ + ½ γ³ v²)    (002 (103), physical sign; the L of [`TangentTop`] − m as v → 0).
//!
//! **Anisotropic top (002 (102)).** For any I the body term is P = uᵀK(θ)u with u the
//! components of ẋ in the orthonormal frame, u_a = g(ẋ, Ê_a), i.e. u = Fẋ with the coframe
//! F = e g (`e[a][i]` = e_a^i, [`Surface::frame`](super::surface::Surface::frame)): L = −m/γ + ½s²(𝕀γ + γ³P) (tested against
//! the exact (82) over an anisotropic body of mass points, `anisotropic_curved_lagrangian_is_the_
//! expansion_of_82`). L depends on θ, so p_θ is not conserved. The x-derivatives of u need the
//! derivatives of the frame, and these follow from the data a [`Surface`] already gives:
//! ∇Ê₁ = wÊ₂, ∇Ê₂ = −wÊ₁ read in coordinates, ∂_k e_1^j = −Γ^j_kl e_1^l + α_k e_2^j and
//! ∂_k e_2^j = −Γ^j_kl e_2^l − α_k e_1^j, so that
//!
//! ∂_k u_a = ½ e_a^l ẋ^i (∂_k g_il + ∂_i g_kl − ∂_l g_ik) − α_k (Ju)_a,   Ju = (−u₂, u₁),
//!
//! and ∂_k P = 2(∂_k u)·Ku, ∂_θ P = uᵀK′u (K′ = JK − KJ), ∂P/∂ẋ = 2Nẋ, ∂²P/∂ẋ² = 2N with
//! N = FᵀKF. (For I = (𝕀/2)·Id, P = ½𝕀g(ẋ, ẋ), since Σ_a e_a e_aᵀ = g⁻¹; that is (103).)
//! Under a change of reference frame Ê → R(β(x))Ê, u → R(β)ᵀu and θ → θ − β, so the body-frame
//! components R(θ)ᵀu, hence P, do not change: with s, L is frame independent (002 (104)–(114),
//! below). A lifted isometry carries the body frame and ẋ together, so it keeps P, s and v: the
//! Killing momenta are conserved for any I, and so is the energy.
//!
//! **Derivatives** (the kernel on a surface). With Q = g(ẋ, ẋ), L = −m√(1 − Q) + ½s²(𝕀γ + γ³P),
//! L_Q = ½mγ + ¼s²(𝕀γ³ + 3γ⁵P), L_s = s(𝕀γ + γ³P) = p_θ, L_P = ½s²γ³,
//! L_QQ = ¼mγ³ + ⅜s²(𝕀γ⁵ + 5γ⁷P), L_Qs = s(½𝕀γ³ + (3/2)γ⁵P), L_QP = ¾s²γ⁵,
//! L_ss = 𝕀γ + γ³P, L_sP = sγ³, L_PP = 0; with n = gẋ, k = Nẋ:
//! p_x = 2L_Q n + L_s α + 2L_P k,  p_θ = L_s,
//! ∂L/∂x^k = L_Q ẋᵀ(∂_k g)ẋ + L_s (∂_kα)·ẋ + L_P ∂_k P,  ∂L/∂θ = L_P ∂_θ P,
//! ∂²L/∂ẋ² = 2L_Q g + 2L_P N + 4L_QQ nnᵀ + 4L_QP(nkᵀ + knᵀ) + 2L_Qs(nαᵀ + αnᵀ) +
//! 2L_sP(kαᵀ + αkᵀ) + L_ss ααᵀ, ∂²L/∂ẋ∂θ̇ = 2L_Qs n + 2L_sP k + L_ss α, ∂²L/∂θ̇² = L_ss.
//! For the symmetric top (P = ½𝕀Q) these are the derivatives of L = −m√(1 − Q) + ½𝕀s²f(Q),
//! f(Q) = γ + ½Qγ³, written below.
//!
//! The symmetric top in those terms: with Q = g(ẋ, ẋ),
//! f(Q) = γ + ½Qγ³, f′ = γ³ + ¾Qγ⁵, f″ = (9/4)γ⁵ + (15/8)Qγ⁷, L = −m√(1 − Q) + ½𝕀s²f(Q),
//! λ = ∂L/∂Q = ½mγ + ½𝕀s²f′, σ = ∂L/∂s = 𝕀sf, n = gẋ:
//! p_x = 2λ n + σ α,  p_θ = σ,  ∂L/∂x^k = λ ẋᵀ(∂_k g)ẋ + σ (∂_kα)·ẋ,  ∂L/∂θ = 0,
//! and the Hessian in (ẋ, θ̇) from L_QQ = ¼mγ³ + ½𝕀s²f″, L_Qs = 𝕀sf′, L_ss = 𝕀f.
//!
//! **Conserved** (symmetric top). E = p·q̇ − L = mγ + ½𝕀s²(γ + (5/2)v²γ³ + (3/2)v⁴γ⁵) (002 (96) with θ̇ → s);
//! p_θ = 𝕀 s f(v²) (θ is cyclic); and for every Killing field X of the surface, lifted to
//! (x, θ) as in [`crate::systems::tangent_top::surface`], J = p_A X^A (v², s and so L are invariant under the
//! lifted isometries; [`RelativisticTangentTop::killing_momenta`], computed by
//! [`crate::systems::TangentTop::killing_momenta`]). Since E and p_θ are functions of (v, s) only,
//! v and s are constant along a motion (where (v, s) ↦ (E, p_θ) is locally invertible, as for
//! slow tops; the sphere test checks it), and the x-equation is
//! 2λ g∇_tẋ = σ dw(ẋ, ·): a charge σ = p_θ of mass 2λ = mγ + 𝕀s²f′ in the "magnetic field" −K dA,
//! moving on a curve of geodesic curvature κ = |p_θ K|/(2λ v) (on the sphere: a circle). 002 (94)
//! holds with |p| read as |p_x − p_θ α|_{g⁻¹} = 2λv, and (95), (96) with θ̇ → s.
//!
//! **The seed's (97)–(103)** (checked by the test `curved_lagrangian_is_the_expansion_of_82`
//! against the exact (82) over a ring of mass points on the sphere and on the hyperbolic plane,
//! with ∇_ċE_i computed from the Christoffel symbols of g and the frame, not from α): the
//! structure of (102)–(103) is right (in the seed's sign, L_seed = −L) once the following are read
//! as intended. (97) writes γ_ij dxⁱdxⁱ for γ_ij dxⁱdxʲ; (99)/(101) write ξʲS_jiω_jᵏ for
//! ξⁱS_jiω_jᵏ; the first term of (102) and (103) is m(1 − γ_ij ẋⁱẋʲ), without the square root
//! ((108) restores it: m√(1 − v²)); the matrix ω of (102)–(103) must be read as Ω_kj = ω_jᵏ(ċ)
//! (column j the components of ∇_ċÊ_j, so Ω = w(ẋ) J): with the other index order the cross term
//! 2tr(ṠSᵀωᵀ) flips sign and (103) would give (θ̇ − α·ẋ)², which the ring test rejects; and (103)
//! writes ⟨ċ, E_j⟩ (body frame) where (102) has ⟨ċ, Ê_j⟩ (the same here, the bracket being s² Id
//! for the symmetric top, but not for an anisotropic one). In (103) "I" is the seed's I₀ = 𝕀/2,
//! as in (93). With those readings (102) is the anisotropic L above: ∇_ċE_i = ((Ṡ + ΩS))_ji Ê_j
//! and Ṡ + ΩS = sJS, so its first bracket is tr((Ṡ + ΩS)I(Ṡ + ΩS)ᵀ) = 𝕀s² and its last
//! ⟨ċ, Ê_j⟩⟨ċ, Ê_m⟩((Ṡ + ΩS)I(Ṡ + ΩS)ᵀ)_jm = s²uᵀK(θ)u (the test against the exact (82) over
//! an anisotropic body checks it).
//!
//! # Prescribed centre motion (002 (91)–(92))
//! With the centre moving uniformly in a straight line, ẋ = u fixed (Minkowski), L reduces to
//! L(θ, θ̇) = −m/γ + ½F(θ)θ̇², F(θ) = 𝕀γ + γ³uᵀK(θ)u
//! ([`RelativisticTangentTop::prescribed_inertia`]). For u = (v, 0),
//! uᵀK(θ)u = v²(I₁₁ sin²θ + 2I₁₂ sin θ cos θ + I₂₂ cos²θ): the second moment of the body
//! across the motion. **Slip:** 002 (91) prints the cross term as −2I₃ sin θ cos θ; with the
//! seed's own S = R(θ) (E₁ = cos θ Ê₁ + sin θ Ê₂, 002 (41)) and I₃ = ∫ξ¹ξ² dm the sign is +
//! (the printed one is right for the product of inertia −∫ξ¹ξ² dm, or for θ measured the other
//! way; the test `prescribed_centre_motion_91_92` decides against L of the full top). F has
//! period π in θ, not 2π as the text says. The θ-equation keeps the spin energy
//! E = θ̇ ∂L/∂θ̇ − L − m/γ = ½F(θ)θ̇² (the seed's "L = θ̇²F(θ) = H", with its F half of this one
//! and the sign of its L), so θ̇ = ±√(2E/F(θ)) (002 (92),
//! [`RelativisticTangentTop::prescribed_spin_rate`]). The seed calls E/F an effective
//! potential; E/F is θ̇² itself. A potential in the usual sense is V(θ) = −E/F(θ): ½θ̇² + V = 0
//! and θ̈ = −V′(θ) = −½θ̇²F′/F (differentiate ½Fθ̇² = E)
//! ([`RelativisticTangentTop::prescribed_potential`]). So the spin is fastest where F is least,
//! with the body's larger second moment along the motion (the smaller across it), and slowest
//! broadside, by the factor √(F_max/F_min) = √((𝕀 + γ²v²I_max)/(𝕀 + γ²v²I_min)) (I_max, I_min
//! the principal second moments), which tends to 1 as v → 0: the classical top spins
//! uniformly. (This is the seed's "rotates faster and other times slower"; the centre's motion is
//! prescribed, not free: for the free anisotropic top ẋ varies too.)
//!
//! # Frame independence (002 (104)–(114))
//! Under a change of reference frame Ê → R(β(x))Ê the body angle is θ → θ − β and the connection
//! form α → α + dβ, so s = θ̇ + α·ẋ is invariant; u → R(β)ᵀu, so the body-frame components
//! R(θ)ᵀu of ẋ, v² and P = uᵀK(θ)u are invariant: L is the same function of the motion, for the
//! symmetric and the anisotropic top. The seed reaches this through (110)–(114): the extra term
//! is vᵀ[A + ω, B]v with A = SᵀṠ, B = RᵀṘ and ω skew, so the bracket is skew and the term vanishes.
//! (Its (111) drops the factor 2 that (110) carries on RᵀṘRᵀṘ; with it the R-terms are
//! −B² − B² + 2B² = 0 as claimed.) The tests `frame_change_*` integrate the same physical
//! motion from two frames that differ by a position-dependent β(x).
//!
//! # Weak field (002 (115)–(120))
//! The static metric is ds² = −e^{2φ(x)} dt² + δ_ij dxⁱdxʲ (**slip corrected:** 002 (115) lacks
//! the dt² of the time-time term and writes ẋ for dx). With E₀ = e^{−φ}∂_t, Γ^t_{ti} = ∂_iφ, so
//! ∇_ċE_i = Ṡ_ji ∂_j + (S_ji G_j) ∂_t, G = ∇φ, and the integrand of (82) is
//! e^{2φ}(1 + G·Sξ)² − |ẋ + Ṡξ|². To second order in ξ, with b = e^{2φ} − v², for a symmetric
//! top (I = I₀ Id) this gives (the physical-sign form of 002 (117))
//!
//! L = −m√b + I₀θ̇²/√b − I₀e^{2φ}|G|²/(2√b)
//!   + I₀(θ̇²v² + 2e^{2φ}θ̇ (G_y ẋ − G_x ẏ) + e^{4φ}|G|²)/(2 b^{3/2}).
//!
//! (The point of the body is moved along ξⁱ∇_ċE_i as (82) prescribes; evaluating φ at x + Sξ
//! instead would add a tidal term ∝ I₀ Δφ.) The weak-field limit, φ, |G| = O(ε²), v = O(ε),
//! θ̇ = O(1), keeping terms to O(ε³) and dropping the constant −m:
//!
//! L = ½ m v² − m φ + I₀ θ̇² (1 − φ + v²) + I₀ θ̇ (G_y ẋ − G_x ẏ).      (002 (118))
//!
//! **Slip:** 002 (118), in the seed's sign (L_seed = −L), carries the coupling term with the
//! opposite sign, +Iθ̇(G_yẋ − G_xẏ); the expansion of 002 (117) gives the sign above. (117)
//! itself is right here if its G is a row vector, as its GGᵀ = |G|² says: then
//! −2e^{2φ}ṠSᵀGᵀv = −2e^{2φ}θ̇(JGᵀ)·v = +2e^{2φ}θ̇(G_yẋ − G_xẏ); read as Gᵀ-column
//! contracted the other way, GᵀṠSᵀv, it has the wrong sign. The test
//! `weak_field_lagrangian_is_the_expansion` checks the sign against the exact integral over a
//! ring of mass points, and `static_field_lagrangian_is_the_expansion_of_82` the whole L. The Euler–Lagrange equations
//! (002 (119), here with every term, G = ∇φ, Δφ = ∂_xG_x + ∂_yG_y):
//!
//! J = p_θ = 2I₀θ̇(1 − φ + v²) + I₀(G_y ẋ − G_x ẏ) = const,
//! (m + 2I₀θ̇²)ẍ + 4I₀θ̇θ̈ ẋ + I₀θ̈ G_y = −(m + I₀θ̇²) G_x − I₀θ̇ Δφ ẏ,
//! (m + 2I₀θ̇²)ÿ + 4I₀θ̇θ̈ ẏ − I₀θ̈ G_x = −(m + I₀θ̇²) G_y + I₀θ̇ Δφ ẋ.
//!
//! 002 (120) drops the θ̈G terms and prints the Δφ terms with the opposite signs (the same
//! coupling-sign slip). Here the full equations of (118) are integrated, in canonical form as
//! above. The Hessian of (118) in the velocities is positive definite only for slow motion (its
//! θ̇–ẋ entry 4I₀θ̇ẋ + I₀JᵀG grows with v): the weak-field ordering v = O(ε) is a domain
//! condition, which the state check enforces. Conserved: the energy
//! E = ½mv² + mφ + I₀θ̇²(1 − φ + 3v²) + I₀θ̇(G_yẋ − G_xẏ), p_θ, and for a central potential
//! the angular momentum x p_y − y p_x (a uniform field conserves the momentum across the field).
//! The spin–field force I₀θ̇Δφ(−ẏ, ẋ) is "magnetic" (it does no work); φ = −GM/r restricted to
//! the plane has Δφ = −GM/r³ ≠ 0, so it acts in the point-mass field.
//!
//! # Static field (002 (115)–(117)), [`StaticFieldTop`]
//! The L above, not expanded in the field or the speed, and on a curved spatial metric: the
//! symmetric top on ds² = −e^{2φ}dt² + γ_ij dxⁱdxʲ to second order in ξ only ((115) with its dt²
//! restored; (117), physical sign), γ = dx² + dy² ([`StaticFieldTop::new`]) or the metric g of a
//! [`Surface`] ([`StaticFieldTop::on_surface`]), φ(x¹, x²) a function of the chart.
//!
//! **Derivation on a surface.** With ċ = ∂_t + ẋ and the body frame E_a = S_ba Ê_b spatial, the
//! only Christoffel symbols of the static metric that reach ∇_ċE_a are the surface's and
//! Γ^t_{tj} = ∂_jφ (Γ^k_{tj} = Γ^t_{ij} = 0), so
//!
//! ∇_ċE_a = dφ(E_a) ∂_t + s (JS)_ba Ê_b = (SᵀG)_a ∂_t + s (JS)_ba Ê_b,   s = θ̇ + α·ẋ,
//!
//! G_b = dφ(Ê_b) = e_bⁱ∂_iφ the frame components of dφ (the ω_a⁰ ∝ G_a of (116)). With u the
//! frame components of ẋ the integrand of (82) is e^{2φ}(1 + G·Sξ)² − |u + sJSξ|²: the flat one
//! with ẋ → u, θ̇ → s, G in the frame. So L is the flat (117) in
//! Q = |u|² = g(ẋ, ẋ), s, c = G₂u₁ − G₁u₂, ε = e^{2φ}, |G|² = g^{ij}∂_iφ∂_jφ:
//!
//! L = −m√b + I₀s²/√b − I₀ε|G|²/(2√b) + I₀(s²Q + 2εsc + ε²|G|²)/(2b^{3/2}),   b = ε − Q.
//!
//! G and u turn together under a change of frame and s does not change ("Frame
//! independence"), so L is frame independent; in the chart (a positive orthonormal frame has
//! e₁ᵏe₂ⁱ − e₂ᵏe₁ⁱ = ϵ^{ki}/√det g), with n = gẋ and φ⊥ = (∂₂φ, −∂₁φ),
//! c = (∂₂φ n₁ − ∂₁φ n₂)/√det g = h·ẋ,   h = gφ⊥/√det g,
//! and the kernel needs g, ∂g, α, ∂α and the chart Hessian of φ, not the frame. In the plane
//! (g = Id, α = 0) s = θ̇, u = ẋ, h = JᵀG = (G_y, −G_x), c = G_yẋ − G_xẏ.
//!
//! **Slips of (115)–(117)** (besides the dt² of (115)): (117) is right with G a row vector (see
//! "Weak field") and with every Ṡ read as the covariant Ṡ + ωS, i.e. θ̇ → s, as its brackets
//! tr(ṠṠᵀ) + 2tr(ṠSᵀωᵀ) + tr(ωωᵀ) = 2s² do; the printed coupling −2e^{2φ}ṠSᵀGᵀv carries Ṡ
//! alone, which would couple the field to θ̇ instead of s on a curved surface. The test
//! `static_field_on_a_surface_is_the_expansion_of_82` (the exact (82) over a ring on the sphere,
//! the half-plane and a graph, ∇_ċE from the chart's Christoffel symbols and differences of φ)
//! finds the error O(r⁴) with s and c as here, O(r²) with θ̇ in the coupling or with −c.
//!
//! **Derivatives** (the kernel, one for the plane and the surfaces): with β = b^{−1/2},
//! T = s²Q + 2εsc + ε²|G|²,
//! L = −m/β + I₀s²β − ½I₀ε|G|²β + ½I₀β³T,
//! L_Q = ½mβ + I₀s²β³ − ¼I₀ε|G|²β³ + ¾I₀β⁵T, L_c = I₀εsβ³, L_s = 2I₀sβ + I₀β³(sQ + εc),
//! L_QQ = ¼mβ³ + (9/4)I₀s²β⁵ − ⅜I₀ε|G|²β⁵ + (15/8)I₀β⁷T, L_Qc = (3/2)I₀εsβ⁵,
//! L_Qs = 2I₀sβ³ + (3/2)I₀β⁵(sQ + εc), L_cc = 0, L_cs = I₀εβ³, L_ss = 2I₀β + I₀Qβ³,
//! L_ε = −½mβ − ½I₀s²β³ − ½I₀|G|²β + ¼I₀ε|G|²β³ − ¾I₀β⁵T + I₀β³(sc + ε|G|²),
//! L_|G|² = −½I₀εβ + ½I₀ε²β³; then
//! p_x = 2L_Q n + L_c h + L_s α,  p_θ = L_s,
//! ∂²L/∂ẋ² = 2L_Q g + 4L_QQ nnᵀ + 2L_Qc(nhᵀ + hnᵀ) + 2L_Qs(nαᵀ + αnᵀ) + L_cs(hαᵀ + αhᵀ) + L_ss ααᵀ,
//! ∂²L/∂ẋ∂θ̇ = 2L_Qs n + L_cs h + L_ss α,  ∂²L/∂θ̇² = L_ss,
//! ∂L/∂x^k = L_Q ẋᵀ∂_kgẋ + L_c ∂_kh·ẋ + L_s ∂_kα·ẋ + 2ε∂_kφ L_ε + ∂_k|G|² L_|G|²,  ∂L/∂θ = 0,
//! ∂_k|G|² = 2∂_k∂_iφ (g⁻¹dφ)ⁱ − (g⁻¹dφ)ᵀ∂_kg(g⁻¹dφ),
//! ∂_kh = (g∂_kφ⊥ + ∂_kg φ⊥)/√det g − ½tr(g⁻¹∂_kg) h.
//! In the plane every term with ∂g, α, ∂α is an exact zero (g = Id, √det g = 1), so the plane's
//! numbers are those of the flat formulas, and [`StaticFieldTop::new`] runs the same kernel on
//! [`Plane`](super::surface::Plane)'s geometry (`kernel_derivatives_are_those_of_its_lagrangian`
//! checks the kernel against differences of its L).
//!
//! **Conserved.** The metric is static (∂_t Killing), so E = p·q̇ − L is; θ is cyclic (p_θ). In
//! the plane a central φ keeps x p_y − y p_x and a uniform one the momentum across the field.
//! On a surface Q, s, c, ε and |G|² are invariant under a lifted isometry that keeps φ, so the
//! momentum J = p_A X^A of a Killing field X with X(φ) = 0 is conserved; the invariants list
//! those of the affine generators X(x) = Ax + b that provably keep the potential (φ = k·x:
//! Aᵀk = 0 and k·b = 0; the point mass: A skew and b = 0), e.g. J_z on the sphere in φ = kϑ,
//! and [`StaticFieldTop::killing_momenta`] gives all. φ = 0 gives the top of −dt² + g
//! (002 (93), (103)); in the plane, expanding in φ, |G| = O(ε²), v = O(ε), θ̇ = O(1) gives
//! (118) − m + O(ε⁴) (`static_field_expands_to_118` measures the ε⁴). The anisotropic body would
//! add θ through Q(θ) = SISᵀ: L = −m√b + 𝕀θ̇²/(2√b) − e^{2φ}GᵀQG/(2√b) + aᵀQa/(2b^{3/2}) with
//! a = e^{2φ}G − θ̇Jᵀẋ (not implemented).
//!
//! # Tangent lift (issue 26)
//! H(q, p) = p·q̇ − L at the q̇ of the Legendre map ∂L/∂q̇ = p, so its Hessian follows from the
//! implicit-function theorem: δq̇ = L_q̇q̇⁻¹(δp − L_q̇q δq), δ(∂H/∂p) = δq̇,
//! δ(∂H/∂q) = −(L_qq δq + L_qq̇ δq̇) (`lift`). The kernels are written once over a scalar type
//! that is f64 for a run and a dual number for its lift, so the mixed and position second
//! derivatives of L come from the same code as ∂L/∂q̇ and ∂L/∂q, exact to round-off; what they
//! read at x (the surface's g, ∂g, α, ∂α, the frame, the potential's φ, ∇φ, ∇²φ) is lifted with
//! its derivative along δx, which needs the surface's second derivatives and the potential's
//! third ([`Potential::third`]: the point mass and the uniform field; a custom potential or a
//! surface without them leaves the top without a lift). Parameters: the mass and 𝕀 (the
//! tensor scaled with it).
//!
//! # State
//! All three systems: z = (x, y, θ, p_x, p_y, p_θ) (canonical, q = (x, y, θ); on a surface x = (x¹, x²)
//! are its chart's coordinates and p₁, p₂ their momenta); build one from velocities with `state`,
//! read the velocities back with `velocities`.
//!
//! [`Surface`]: super::surface::Surface
//! [`TangentTop`]: super::TangentTop

mod lift;
mod spacetime;
mod static_field;
mod weak_field;

use nalgebra::{Matrix3, Vector3};

use crate::check;
use crate::convergence::{self, Monitor, Rule, Verdict};
use crate::error::{Error, Result};
use crate::integrate::methods::canonical_catalog;
use crate::integrate::problem::Canonical;
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{CanonicalTangent, Tangent};
use crate::integrate::Problem;
use crate::numerics::dual::Dual;
use lift::DerivsT;

pub use spacetime::RelativisticTangentTop;
pub use static_field::StaticFieldTop;
pub use weak_field::{Potential, PotentialValue, WeakFieldTop};

/// The derivatives of a Lagrangian L(q, q̇) on ℝ³ at one point: value, ∂L/∂q̇, ∂L/∂q, ∂²L/∂q̇².
struct Derivs {
    l: f64,
    lv: Vector3<f64>,
    lq: Vector3<f64>,
    hess: Matrix3<f64>,
}

/// The stopping rule of the Legendre inversion ([`crate::convergence`]; the Newton step relative
/// to 1 + |q̇|_∞; ended at once at 10⁻¹³, after which one more step brings q̇ to round-off).
const LEGENDRE: Rule = Rule {
    tol: convergence::TOL,
    floor: 1e-13,
    max_iter: 60,
};

/// Solves ∂L/∂q̇(q, q̇) = p for q̇ by Newton's method with a Cholesky-factored Hessian (so that the
/// Hessian is positive definite at the answer), halving steps that leave the domain (`derivs`
/// returns None there), from `guess`, under the rule [`LEGENDRE`], then takes one more step. None
/// when it fails (singular or indefinite Hessian, no convergence).
fn legendre_inverse(
    p: &[f64],
    guess: Vector3<f64>,
    derivs: impl Fn(&Vector3<f64>) -> Option<Derivs>,
) -> Option<(Vector3<f64>, Derivs)> {
    let p = Vector3::new(p[0], p[1], p[2]);
    let mut v = guess;
    let mut d = derivs(&v)?;
    let mut monitor = Monitor::new(LEGENDRE);
    let mut polish = false;
    loop {
        let chol = d.hess.cholesky()?;
        let step = chol.solve(&(p - d.lv));
        let mut t = 1.0;
        let (nv, nd) = loop {
            let nv = v + step * t;
            if let Some(nd) = derivs(&nv) {
                break (nv, nd);
            }
            t *= 0.5;
            if t < 1e-12 {
                return None;
            }
        };
        v = nv;
        d = nd;
        if polish {
            return d.hess.cholesky().is_some().then_some((v, d));
        }
        match monitor.check(step.amax() * t, 1.0 + v.amax()) {
            Verdict::Continue => {}
            Verdict::Converged => polish = true,
            Verdict::Failed(_) => return None,
        }
    }
}

/// The state layout shared by both systems.
fn space() -> Space {
    Space::new([
        ("x", Block::Real(2)),
        ("theta", Block::Real(1)),
        ("p", Block::Real(2)),
        ("p_theta", Block::Real(1)),
    ])
}

/// What both tops share: a Lagrangian L(q, q̇) in q = (x, y, θ) with its derivatives, and the
/// inverse of its Legendre map, from which H, Hamilton's equations, the state helpers and the
/// catalog follow once ([`legendre_kinds`]).
trait Legendre: Problem {
    /// L, ∂L/∂q̇, ∂L/∂q and ∂²L/∂q̇² at (q, q̇); None where L is not defined.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs>;

    /// q̇ with ∂L/∂q̇(q, q̇) = p, and the derivatives there; None where the map is not inverted.
    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)>;

    /// The error for a (q, q̇) where L is not defined.
    fn undefined(&self, q: [f64; 3], v: [f64; 3]) -> Error;

    /// Checks that q lies in the configuration space's chart (before a Legendre inversion).
    fn check_point(&self, _q: &[f64]) -> Result<()> {
        Ok(())
    }

    /// The kernel at q + ε dq, q̇ + ε dq̇ with the parameter m (if any) moved at unit rate, in
    /// [`Dual`] numbers: the ε parts of ∂L/∂q̇ and ∂L/∂q are their directional derivatives (the
    /// tangent lift, [`lift`]); None where L is not defined or the data lack the derivatives.
    fn derivs_dual(
        &self,
        q: [Dual; 3],
        v: [Dual; 3],
        parameter: Option<usize>,
    ) -> Option<DerivsT<Dual>>;

    /// Whether [`Legendre::derivs_dual`] has what it needs (a surface's second derivatives, a
    /// potential's third): then the top has a tangent lift.
    fn has_hessian(&self) -> bool;
}

/// L(q, q̇), checked.
fn lagrangian<T: Legendre>(t: &T, q: [f64; 3], v: [f64; 3]) -> Result<f64> {
    check::finite_slice("q and qdot", &[q[0], q[1], q[2], v[0], v[1], v[2]])?;
    t.derivs(&q, &Vector3::from(v))
        .map(|d| d.l)
        .ok_or_else(|| t.undefined(q, v))
}

/// The canonical state (q, ∂L/∂q̇) at (q, q̇); the Legendre map must be invertible there.
fn state<T: Legendre>(t: &T, q: [f64; 3], v: [f64; 3]) -> Result<Vec<f64>> {
    check::finite_slice(
        "x, theta, xdot, thetadot",
        &[q[0], q[1], q[2], v[0], v[1], v[2]],
    )?;
    let d = t
        .derivs(&q, &Vector3::from(v))
        .ok_or_else(|| t.undefined(q, v))?;
    if d.hess.cholesky().is_none() {
        return Err(not_invertible(t.name()));
    }
    Ok(vec![q[0], q[1], q[2], d.lv[0], d.lv[1], d.lv[2]])
}

/// The velocities of a state (the inverse Legendre map).
fn velocities<T: Legendre>(t: &T, z: &[f64]) -> Result<[f64; 3]> {
    check::len_of("state", z, 6)?;
    check::finite_slice("state", z)?;
    t.check_point(&z[..3])?;
    t.solve(&z[..3], &z[3..])
        .map(|(v, _)| [v[0], v[1], v[2]])
        .ok_or_else(|| not_invertible(t.name()))
}

/// E = H = p·q̇ − L of a state.
fn energy<T: Legendre>(t: &T, z: &[f64]) -> Result<f64> {
    check::len_of("state", z, 6)?;
    check::finite_slice("state", z)?;
    t.check_point(&z[..3])?;
    let sol = t.solve(&z[..3], &z[3..]);
    if sol.is_none() {
        return Err(not_invertible(t.name()));
    }
    Ok(hamiltonian_of(&z[3..], sol))
}

/// `Canonical` (H and its gradient through the inverse Legendre map), `VectorField` (Hamilton's
/// equations, for rk4) and the catalog of a [`Legendre`] top.
macro_rules! legendre_kinds {
    ($t:ty) => {
        impl Canonical for $t {
            fn dof(&self) -> usize {
                3
            }
            fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
                hamiltonian_of(p, self.solve(q, p))
            }
            fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
                gradient_of(self.solve(q, p), hq, hp);
            }
        }

        /// D²H\\[dq, dp\\] and ∂∇H/∂θ through the implicit-function theorem on the Legendre
        /// map (`lift`).
        impl CanonicalTangent for $t {
            fn gradient_tangent(
                &self,
                q: &[f64],
                p: &[f64],
                dq: &[f64],
                dp: &[f64],
                dhq: &mut [f64],
                dhp: &mut [f64],
            ) {
                lift::gradient_tangent(self, q, p, dq, dp, dhq, dhp);
            }

            fn gradient_parameter(
                &self,
                q: &[f64],
                p: &[f64],
                m: usize,
                dhq: &mut [f64],
                dhp: &mut [f64],
            ) {
                lift::gradient_parameter(self, q, p, m, dhq, dhp);
            }
        }

        // The tangent lift where the kernel's data have the derivatives it needs.
        $crate::integrate::methods::canonical_system!($t, canonical_catalog(), |t: &$t| t
            .has_hessian()
            .then(|| Tangent::field(t.clone()).into_system()));
    };
}

fn not_invertible(name: &str) -> Error {
    Error::invalid(
        "state",
        format!(
            "{name}: the Legendre map is not invertible at these momenta (∂²L/∂q̇² not positive \
             definite, or no velocity with these momenta); the expansion of 002 §IV needs slow, \
             moderately spinning tops"
        ),
    )
}

/// H(q, p) = p·q̇ − L and its gradient ∂H/∂p = q̇, ∂H/∂q = −∂L/∂q (at the q̇ of p); NaN where the
/// Legendre map cannot be inverted (the Gauss solver then reports the step).
fn hamiltonian_of(p: &[f64], sol: Option<(Vector3<f64>, Derivs)>) -> f64 {
    match sol {
        Some((v, d)) => p[0] * v[0] + p[1] * v[1] + p[2] * v[2] - d.l,
        None => f64::NAN,
    }
}

fn gradient_of(sol: Option<(Vector3<f64>, Derivs)>, hq: &mut [f64], hp: &mut [f64]) {
    match sol {
        Some((v, d)) => {
            for i in 0..3 {
                hp[i] = v[i];
                hq[i] = -d.lq[i];
            }
        }
        None => {
            hq.fill(f64::NAN);
            hp.fill(f64::NAN);
        }
    }
}

legendre_kinds!(RelativisticTangentTop);

legendre_kinds!(WeakFieldTop);

legendre_kinds!(StaticFieldTop);
