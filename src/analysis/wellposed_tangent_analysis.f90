!> Tangent analysis at a plastic state: the continuum elastic-plastic tangent
!> (eq. 3.14), the continuum stress rate of the regular and extended flow
!> rules, and the directional stiffness ratio R (eq. 2.5) over axisymmetric
!> strain-rate directions.
!>
!> Axisymmetric directions live in the Lode plane of the state: the unit
!> tensors E_z = I/sqrt(3) and E_r = S_hat (the unit stress deviator), and
!> d eps(theta) = cos(phi) E_z + sin(phi) E_r. The angle theta is measured
!> from the direction tangent to the yield surface (N : d eps = 0) whose trace
!> is negative (compressive), towards the outward normal: theta = pi/2 is
!> d eps along N's projection on the plane (seed section 2.4).
module wellposed_tangent_analysis
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: ntens6, sqrt2, sqrt3, identity2, trace, deviator, norm, outer
  use wellposed_elasticity, only: stiffness, apply_stiffness
  use wellposed_hardening, only: strength_slope
  use wellposed_drucker_prager, only: yield_normal, potential_direction, normal_norm
  use wellposed_dp_params, only: dp_params_t
  use wellposed_efr, only: efr_direction
  implicit none
  private
  public :: continuum_tangent, stress_rate, directional_stiffness, stiffness_ratio, &
            lode_direction, lode_basis

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
  pure function stress_rate(p, sig, z, deps) result(dsig)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig(ntens6), z, deps(ntens6)
    real(dp) :: dsig(ntens6), s_hat(ntens6), n(ntens6), ce(ntens6), m_hat(ntens6), m(ntens6)
    real(dp) :: load, hh, denom
    s_hat = deviator(sig)
    s_hat = s_hat/norm(s_hat)
    n = yield_normal(s_hat, p%beta)
    ce = apply_stiffness(p%el, deps)
    dsig = ce
    load = dot_product(n, ce)
    if (.not. load > 0.0_dp) return
    hh = strength_slope(p%hard, z)
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

end module wellposed_tangent_analysis
