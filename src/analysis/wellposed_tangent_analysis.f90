!> Tangent analysis at a plastic state: the continuum elastic-plastic tangent
!> (eq. 3.14), the continuum stress rate of the regular and extended flow
!> rules, and the directional stiffness ratio R (eq. 2.5) over axisymmetric
!> strain-rate directions d eps = cos(phi) E_z + sin(phi) E_r of the state's
!> Lode plane, theta measured from the compressive tangent to the yield
!> surface towards the outward normal (section 2.4; docs/research/theory.md).
module wellposed_tangent_analysis
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: ntens6, sqrt2, sqrt3, identity2, trace, deviator, norm, outer
  use wellposed_elasticity, only: stiffness, apply_stiffness
  use wellposed_hardening, only: strength_slope
  use wellposed_drucker_prager, only: yield_normal, potential_direction, normal_norm
  use wellposed_dp_params, only: dp_params_t
  use wellposed_efr, only: efr_direction
  use wellposed_nonlocal, only: gaussian_k
  implicit none
  private
  public :: continuum_tangent, stress_rate, directional_stiffness, stiffness_ratio, &
            lode_direction, lode_basis, uniaxial_modulus, overlocal_uniaxial_modulus

contains

  !> Eq. 3.14: T = C - (1/mu) P (x) Q, P = C:M_hat, Q = C:N_hat,
  !> mu = P:N_hat + H, for unit flow direction M_hat, unit normal N_hat and
  !> ensemble hardening modulus H (H = (dk/dz)/||N|| for the cone of eq. 2.3).
  pure function continuum_tangent(c, m_hat, n_hat, hh) result(t)
    real(dp), intent(in) :: c(ntens6, ntens6), m_hat(ntens6), n_hat(ntens6), hh
    real(dp) :: t(ntens6, ntens6), pp(ntens6), qq(ntens6)
    pp = matmul(c, m_hat)
    qq = matmul(n_hat, c)
    t = c - outer(pp, qq)/(dot_product(pp, n_hat) + hh)
  end function continuum_tangent

  !> Continuum stress rate of the rate-independent model at the plastic
  !> state (sig, z) for the strain rate `deps` (any magnitude; the response
  !> is homogeneous of degree one). Loading when N:C:deps > 0; the flow
  !> direction is eq. 4.35 (regular) or eq. 2.7 (EFR, direction of deps).
  !> `modulus`, when present, replaces dk/dz (a perturbation analysis passes
  !> its frequency-dependent effective modulus).
  pure function stress_rate(p, sig, z, deps, modulus) result(dsig)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig(ntens6), z, deps(ntens6)
    real(dp), intent(in), optional :: modulus
    real(dp) :: dsig(ntens6), s_hat(ntens6), n(ntens6), ce(ntens6), m_hat(ntens6), m(ntens6)
    real(dp) :: load, hh, denom
    s_hat = deviator(sig)
    s_hat = s_hat/norm(s_hat)
    n = yield_normal(s_hat, p%beta)
    ce = apply_stiffness(p%el, deps)
    dsig = ce
    load = dot_product(n, ce)
    if (.not. load > 0.0_dp) return
    if (present(modulus)) then
      hh = modulus
    else
      hh = strength_slope(p%hard, z)
    end if
    m_hat = potential_direction(s_hat, p%beta_p)
    if (p%efr) then
      m = efr_direction(p, s_hat, deps)
      if (norm(m) > 0.0_dp) then
        m = m/norm(m)
        denom = dot_product(n, apply_stiffness(p%el, m)) + hh
        if (denom > 0.0_dp) m_hat = m
      end if
    end if
    denom = dot_product(n, apply_stiffness(p%el, m_hat)) + hh
    dsig = ce - (load/denom)*apply_stiffness(p%el, m_hat)
  end function stress_rate

  !> The orthonormal axisymmetric Lode basis of a state: E_z = I/sqrt(3)
  !> and E_r = S_hat.
  pure subroutine lode_basis(sig, e_z, e_r)
    real(dp), intent(in) :: sig(ntens6)
    real(dp), intent(out) :: e_z(ntens6), e_r(ntens6)
    e_z = identity2/sqrt3
    e_r = deviator(sig)
    e_r = e_r/norm(e_r)
  end subroutine lode_basis

  !> Unit strain-rate direction at loading angle theta (see the module
  !> description) for the state `sig` of the cone with friction `beta`.
  pure function lode_direction(sig, beta, theta) result(d)
    real(dp), intent(in) :: sig(ntens6), beta, theta
    real(dp) :: d(ntens6), e_z(ntens6), e_r(ntens6), n_z, n_r, phi0
    call lode_basis(sig, e_z, e_r)
    ! N in the plane: N_z = N:E_z = sqrt(3) beta, N_r = N:E_r = 1/sqrt(2).
    n_z = sqrt3*beta
    n_r = 1.0_dp/sqrt2
    ! theta = 0: the tangent (n_r, -n_z) or (-n_r, n_z) with negative trace.
    phi0 = atan2(-n_z, n_r)
    if (cos(phi0) > 0.0_dp) phi0 = atan2(n_z, -n_r)
    ! Rotate towards the normal: check the sense with N:d at theta = pi/2.
    if (n_z*cos(phi0 + 0.5_dp*acos(-1.0_dp)) + n_r*sin(phi0 + 0.5_dp*acos(-1.0_dp)) > 0.0_dp) then
      d = cos(phi0 + theta)*e_z + sin(phi0 + theta)*e_r
    else
      d = cos(phi0 - theta)*e_z + sin(phi0 - theta)*e_r
    end if
  end function lode_direction

  !> R = d eps : d sigma / (d eps : C : d eps) (eq. 2.5) of the continuum
  !> response at the plastic state (sig, z) for the strain-rate direction
  !> `deps`; 1 for directions that unload elastically.
  pure function directional_stiffness(p, sig, z, deps) result(r)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig(ntens6), z, deps(ntens6)
    real(dp) :: r
    r = dot_product(deps, stress_rate(p, sig, z, deps)) &
        /dot_product(deps, apply_stiffness(p%el, deps))
  end function directional_stiffness

  !> R = d eps : T : d eps / (d eps : C : d eps) (eq. 2.5) of any tangent T
  !> (a UMAT's DDSDDE in Mandel form, eq. 3.14, a fitted tangent) for the
  !> strain-rate direction `deps`.
  pure function stiffness_ratio(t, c, deps) result(r)
    real(dp), intent(in) :: t(ntens6, ntens6), c(ntens6, ntens6), deps(ntens6)
    real(dp) :: r
    r = dot_product(deps, matmul(t, deps))/dot_product(deps, matmul(c, deps))
  end function stiffness_ratio

  !> rho c^2 of a uniaxial-strain wave along axis 1 at the plastic state
  !> (sig, z): the 11 component of the stress rate for d eps = sign e_1
  !> (sign = +1 extension, -1 compression), divided by that strain rate.
  !> With the regular flow rule this is the reference's closed form
  !> K + 4G/3 - (3K beta_p - 2G/sqrt 3)(3K beta - 2G/sqrt 3)/(G + 9K beta beta_p
  !> + h sqrt(1/2 + 3 beta_p^2)) for a triaxial-compression state.
  pure function uniaxial_modulus(p, sig, z, sign, modulus) result(rho_c2)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig(ntens6), z, sign
    real(dp), intent(in), optional :: modulus
    real(dp) :: rho_c2, d(ntens6), dsig(ntens6)
    d = 0.0_dp
    d(1) = sign
    dsig = stress_rate(p, sig, z, d, modulus)
    rho_c2 = dsig(1)/sign
  end function uniaxial_modulus

  !> Dispersion of the overlocal model (eq. 2.12-2.15) for uniaxial-strain
  !> waves of wavenumber kappa (rad/m), by the perturbation method of Di Luzio
  !> and Bazant: a harmonic perturbation of dlambda is averaged by the
  !> normalised Gaussian, whose Fourier transform is exp(-kappa^2 L^2/(4 k^2)),
  !> so the linearised equations are the local ones with the effective modulus
  !> h_eff(kappa) = h_eta + h_zeta exp(-kappa^2 L^2/(4 k^2)) (docs/research/cases.md,
  !> case A: h((1 - m) + m exp(...)) with h_eta = (1 - m) h, h_zeta = m h).
  !> Returns rho c(kappa)^2; kappa -> 0 is the local model with h_eta + h_zeta,
  !> kappa -> infinity the local model with h_eta.
  pure function overlocal_uniaxial_modulus(p, sig, z, sign, kappa) result(rho_c2)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig(ntens6), z, sign, kappa
    real(dp) :: rho_c2, h_eff
    h_eff = strength_slope(p%hard, z) + &
            p%h_zeta*exp(-(kappa*p%length/(2.0_dp*gaussian_k))**2)
    rho_c2 = uniaxial_modulus(p, sig, z, sign, h_eff)
  end function overlocal_uniaxial_modulus

end module wellposed_tangent_analysis
