!> Hashiguchi's extended flow rule (EFR, eq. 2.7): the plastic strain
!> direction M = N_hat ||de*|| + P_v de_v I + P_d de* turns with this
!> increment's total strain de. Backward Euler with N_hat at the end of the
!> increment gives seven equations in (sigma, dlambda), solved by Newton; the
!> tangent is their implicit-function derivative d sigma/d de (it includes how
!> M_hat turns with de). No direction, or a direction that cannot lower f:
!> the regular flow rule. Derivation and edge cases: docs/theory.md.
module wellposed_efr
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_tensor, only: ntens6, sqrt2, identity2, trace, deviator, norm, outer, &
                              identity4, projector_dev
  use wellposed_elasticity, only: stiffness
  use wellposed_hardening, only: strength, strength_slope
  use wellposed_drucker_prager, only: yield_normal, potential_direction
  use wellposed_dp_params, only: dp_params_t
  use wellposed_text, only: real_text
  use wellposed_return_mapping, only: return_t, regular_return, elastic_return, apex_return, &
                                      state_plastic, max_newton
  use wellposed_dense, only: solve_dense
  implicit none
  private
  public :: efr_direction, efr_return

contains

  !> The (unnormalised) EFR direction M of eq. 2.7 for the deviatoric unit
  !> direction `s_hat` of the stress and the strain increment `deps`.
  pure function efr_direction(p, s_hat, deps) result(m)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: s_hat(ntens6), deps(ntens6)
    real(dp) :: m(ntens6), de_dev(ntens6)
    de_dev = deviator(deps)
    m = potential_direction(s_hat, p%beta_p)*norm(de_dev) + p%p_v*trace(deps)*identity2 &
        + p%p_d*de_dev
  end function efr_direction

  !> Return `sig_tr` onto the cone with the EFR direction of the strain
  !> increment `deps` (Mandel). Arguments as regular_return.
  pure subroutine efr_return(p, sig_tr, deps, z_n, zeta, ret, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig_tr(ntens6), deps(ntens6), z_n, zeta
    type(return_t), intent(out) :: ret
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: s_tr(ntens6), q, f_tr, k_n, sig(ntens6), x, s(ntens6), qs, s_hat(ntens6)
    real(dp) :: m(ntens6), mn, m_hat(ntens6), cm(ntens6), c(ntens6, ntens6)
    real(dp) :: jac(7, 7), rhs(7, ntens6), res(7, 1), rnorm, rprev, scale, d_s
    real(dp) :: dm_ds(ntens6, ntens6), dmhat(ntens6, ntens6), dm_de(ntens6, ntens6)
    real(dp) :: e_hat(ntens6)
    integer :: it
    logical :: ok, flipped

    d_s = norm(deviator(deps))
    if (d_s == 0.0_dp .and. (p%p_v == 0.0_dp .or. trace(deps) == 0.0_dp)) then
      call regular_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      return
    end if
    s_tr = deviator(sig_tr)
    q = norm(s_tr)
    k_n = strength(p%hard, z_n) + zeta
    f_tr = q/sqrt2 + p%beta*trace(sig_tr) - k_n
    if (.not. f_tr > 0.0_dp) then
      call elastic_return(p, sig_tr, f_tr, ret, tangent)
      return
    end if
    if (q == 0.0_dp) then
      ! On the hydrostatic axis outside the cone: only the apex is reachable.
      call apex_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      return
    end if
    c = stiffness(p%el)
    m = efr_direction(p, s_tr/q, deps)
    if (.not. dot_product(yield_normal(s_tr/q, p%beta), matmul(c, m))/norm(m) &
        + strength_slope(p%hard, z_n) > 0.0_dp) then
      call regular_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      return
    end if

    scale = norm(sig_tr) + abs(k_n)
    sig = sig_tr
    x = 0.0_dp
    rprev = huge(1.0_dp)
    flipped = .false.
    ok = .true.
    do it = 1, max_newton
      s = deviator(sig)
      qs = norm(s)
      if (.not. dot_product(s, s_tr) > 0.0_dp) then
        flipped = .true.  ! the deviator went through zero: the cone is out of reach
        exit
      end if
      s_hat = s/qs
      m = efr_direction(p, s_hat, deps)
      mn = norm(m)
      m_hat = m/mn
      cm = matmul(c, m_hat)
      res(1:6, 1) = sig - sig_tr + x*cm
      res(7, 1) = qs/sqrt2 + p%beta*trace(sig) - strength(p%hard, z_n + x) - zeta
      ! Jacobian of (R_sigma, R_f) with respect to (sigma, dlambda).
      dmhat = (identity4() - outer(m_hat, m_hat))/mn
      dm_ds = (d_s/(sqrt2*p%n_m*qs))*(projector_dev() - outer(s_hat, s_hat))
      jac(1:6, 1:6) = identity4() + x*matmul(c, matmul(dmhat, dm_ds))
      jac(1:6, 7) = cm
      jac(7, 1:6) = yield_normal(s_hat, p%beta)
      jac(7, 7) = -strength_slope(p%hard, z_n + x)
      rnorm = maxval(abs(res(:, 1)))
      if (rnorm <= 16.0_dp*epsilon(1.0_dp)*scale) exit
      if (it > 2 .and. rnorm <= 1.0e-10_dp*scale .and. rnorm > 0.5_dp*rprev) exit
      rprev = rnorm
      res = -res
      call solve_dense(jac, res, ok)
      if (.not. ok) exit
      sig = sig + res(1:6, 1)
      x = x + res(7, 1)
    end do
    if (flipped) then
      if (p%beta > 0.0_dp) then
        call apex_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      else
        call new_error(err, status_cutback, '', 'extended flow rule: the yield strength '// &
          'leaves no admissible stress on the cylinder (beta = 0)')
      end if
      return
    end if
    if (it > max_newton .or. .not. ok .or. .not. x >= 0.0_dp) then
      call new_error(err, status_cutback, '', 'extended flow rule: the return mapping '// &
        'did not converge (f_trial = '//real_text(f_tr)//')')
      return
    end if

    ret%sig = sig
    ret%deps_p = x*m_hat
    ret%dz = x
    ret%f = qs/sqrt2 + p%beta*trace(sig) - strength(p%hard, z_n + x) - zeta
    ret%state = state_plastic
    if (present(tangent)) then
      ! d R_sigma/d de = -C + x C : dM_hat/dM : dM/d de;  d R_f/d de = 0.
      e_hat = 0.0_dp
      if (d_s > 0.0_dp) e_hat = deviator(deps)/d_s
      dm_de = outer(potential_direction(s_hat, p%beta_p), e_hat) &
              + p%p_v*outer(identity2, identity2) + p%p_d*projector_dev()
      rhs(1:6, :) = c - x*matmul(c, matmul(dmhat, dm_de))
      rhs(7, :) = 0.0_dp
      call solve_dense(jac, rhs, ok)
      if (.not. ok) then
        call new_error(err, status_cutback, '', 'extended flow rule: singular '// &
          'tangent system')
        return
      end if
      tangent = rhs(1:6, :)
    end if


  end subroutine efr_return

end module wellposed_efr
