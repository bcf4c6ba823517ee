!> Backward-Euler return mapping of the Drucker-Prager cone with the regular
!> flow rule d eps^p = dlambda M_hat (eq. 1.6, 4.35), and its consistent
!> tangent. With isotropic elasticity the deviator keeps the trial direction,
!> so the return is one scalar equation in dlambda (eq. 4.36), closed form
!> for linear hardening (eq. 4.39 with h_zeta = 0), safeguarded Newton for
!> eq. 2.6. When no point of the cone is reachable along the potential's
!> normals the stress returns to the apex I1 = k/beta. See docs/research/theory.md.
module wellposed_return_mapping
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_tensor, only: ntens6, sqrt2, identity2, trace, deviator, norm, outer
  use wellposed_elasticity, only: stiffness
  use wellposed_hardening, only: strength, strength_slope, is_linear
  use wellposed_dp_params, only: dp_params_t
  use wellposed_text, only: real_text
  implicit none
  private
  public :: return_t, regular_return, elastic_return, apex_return, state_elastic, state_plastic, &
            state_apex, max_newton, cylinder_error

  integer, parameter :: state_elastic = 0  !< no plastic flow
  integer, parameter :: state_plastic = 1  !< return to the cone
  integer, parameter :: state_apex = 2     !< return to the apex (tension cut-off)
  !> Iteration limit of the scalar Newton solves; reaching it is a cut-back.
  integer, parameter :: max_newton = 60

  !> The outcome of one return: all in Mandel form.
  type :: return_t
    real(dp) :: sig(ntens6) = 0.0_dp     !< stress at the end of the increment
    real(dp) :: deps_p(ntens6) = 0.0_dp  !< plastic strain increment
    real(dp) :: dz = 0.0_dp              !< ||deps_p||, the increment of z
    real(dp) :: f = 0.0_dp               !< yield function at the end
    integer :: state = state_elastic     !< state_elastic, state_plastic or state_apex
  end type return_t

contains

  !> The elastic outcome: stress = trial, tangent = C.
  pure subroutine elastic_return(p, sig_tr, f_tr, ret, tangent)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig_tr(ntens6), f_tr
    type(return_t), intent(out) :: ret
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    ret%sig = sig_tr
    ret%f = f_tr
    if (present(tangent)) tangent = stiffness(p%el)
  end subroutine elastic_return

  !> Return the trial stress `sig_tr` onto f(sigma, z, zeta) = 0 with the
  !> regular flow rule. `z_n` is the start-of-increment z; `zeta` the
  !> (already updated) nonlocal strength. `tangent`, when present, is the
  !> consistent tangent d sigma / d eps of this increment (Mandel).
  pure subroutine regular_return(p, sig_tr, z_n, zeta, ret, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig_tr(ntens6), z_n, zeta
    type(return_t), intent(out) :: ret
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: i1_tr, s_tr(ntens6), q, s_hat(ntens6), f_tr, k_n, x, x_max, g, hmod, scale
    real(dp) :: shrink, i1, g2
    integer :: it

    i1_tr = trace(sig_tr)
    s_tr = deviator(sig_tr)
    q = norm(s_tr)
    k_n = strength(p%hard, z_n) + zeta
    f_tr = q/sqrt2 + p%beta*i1_tr - k_n
    if (.not. f_tr > 0.0_dp) then
      call elastic_return(p, sig_tr, f_tr, ret, tangent)
      return
    end if
    g2 = p%el%shear

    ! Plastic: where along the return does the deviator vanish? (0 for a
    ! zero deviator: on a cylinder it has no return, below.)
    x_max = 0.0_dp
    if (q > 0.0_dp) x_max = q*p%n_m/(sqrt2*g2)
    if (p%beta > 0.0_dp) then
      if (q == 0.0_dp) then
        call apex_return(p, sig_tr, z_n, zeta, ret, tangent, err)
        return
      else if (cone_residual(x_max) > 0.0_dp) then
        call apex_return(p, sig_tr, z_n, zeta, ret, tangent, err)
        return
      end if
    end if

    if (q == 0.0_dp) then
      ! beta = 0 and f_tr = -k > 0: every stress lies outside the cylinder
      ! (sqrt(J2) >= 0 > k), and a zero deviator has no flow direction.
      call cylinder_error(k_n, err)
      return
    end if

    ! Cone: solve f_tr - a x - (k(z_n + x) - k(z_n)) = 0 for x = dlambda.
    if (is_linear(p%hard)) then
      x = f_tr/(p%a_m + p%hard%h)
    else
      ! The residual rounds at the size of k(z) itself: with a nonlocal
      ! zeta (eq. 4.34) k_n = k(z) + zeta can be far smaller than k(z).
      scale = abs(f_tr) + abs(strength(p%hard, z_n))
      x = f_tr/(p%a_m + strength_slope(p%hard, z_n))
      do it = 1, max_newton
        g = cone_residual(x)
        hmod = p%a_m + strength_slope(p%hard, z_n + x)
        x = max(x + g/hmod, 0.5_dp*x)
        if (abs(g) <= 4.0_dp*epsilon(1.0_dp)*scale) exit
      end do
      if (it > max_newton) then
        call new_error(err, status_cutback, '', 'return mapping: no convergence in '// &
          'the exponential-hardening Newton iteration (f_trial = '//real_text(f_tr)//')')
        return
      end if
    end if
    if (x > x_max) then
      ! Only reachable with beta = 0 (a cylinder has no apex): the strength
      ! has softened below what any stress can satisfy.
      call new_error(err, status_cutback, '', 'return mapping: the yield strength k = '// &
        real_text(strength(p%hard, z_n + x) + zeta)//' leaves no admissible stress')
      return
    end if

    s_hat = s_tr/q
    shrink = 1.0_dp - x/x_max
    i1 = i1_tr - 9.0_dp*p%el%bulk*p%beta_p*x/p%n_m
    ret%sig = shrink*s_tr + (i1/3.0_dp)*identity2
    ret%deps_p = x*(s_hat/sqrt2 + p%beta_p*identity2)/p%n_m
    ret%dz = x
    ret%f = shrink*q/sqrt2 + p%beta*i1 - strength(p%hard, z_n + x) - zeta
    ret%state = state_plastic
    if (present(tangent)) call cone_tangent(p, s_hat, q, x, &
      strength_slope(p%hard, z_n + x), tangent)

  contains

    !> f after a return of length x along the potential's normal (eq. 4.36).
    pure function cone_residual(xx) result(r)
      real(dp), intent(in) :: xx
      real(dp) :: r
      r = f_tr - p%a_m*xx - (strength(p%hard, z_n + xx) - strength(p%hard, z_n))
    end function cone_residual

  end subroutine regular_return

  !> The error of a softened cylinder (beta = 0) at a zero deviator: the
  !> strength k < 0 admits no stress (status -2, the arguments untouched).
  pure subroutine cylinder_error(k, err)
    real(dp), intent(in) :: k
    type(error_t), allocatable, intent(out) :: err
    call new_error(err, status_cutback, '', 'return mapping: the yield strength k = '// &
      real_text(k)//' < 0 of the cylinder (beta = 0) leaves no admissible stress')
  end subroutine cylinder_error

  !> Consistent tangent of the cone return:
  !>   T = C - (C:M_hat) (x) (C:N)/(a + H) - dlambda 2 sqrt(2) G^2/(n_m q) (Pdev - S_hat (x) S_hat)
  !> with N = S_hat/sqrt(2) + beta I, H = dk/dz at the end, q = ||S_trial||.
  pure subroutine cone_tangent(p, s_hat, q, x, hmod, tangent)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: s_hat(ntens6), q, x, hmod
    real(dp), intent(out) :: tangent(ntens6, ntens6)
    real(dp) :: cm(ntens6), cn(ntens6), lam, c2, rate
    integer :: i, j
    associate (bulk => p%el%bulk, shear => p%el%shear)
      cm = (sqrt2*shear*s_hat + 3.0_dp*bulk*p%beta_p*identity2)/p%n_m
      cn = sqrt2*shear*s_hat + 3.0_dp*bulk*p%beta*identity2
      rate = 1.0_dp/(p%a_m + hmod)
      c2 = x*2.0_dp*sqrt2*shear**2/(p%n_m*q)
      lam = bulk - 2.0_dp*shear/3.0_dp
      do j = 1, ntens6
        do i = 1, ntens6
          tangent(i, j) = (lam + c2/3.0_dp)*identity2(i)*identity2(j) - cm(i)*cn(j)*rate &
                          + c2*s_hat(i)*s_hat(j)
        end do
        tangent(j, j) = tangent(j, j) + 2.0_dp*shear - c2
      end do
    end associate
  end subroutine cone_tangent

  !> Return to the apex sigma = s I, s = (k(z_n + dz) + zeta)/(3 beta), with
  !> d eps^p = C^-1:(sigma_trial - sigma_apex) and dz = ||d eps^p||,
  !> solved by Newton on r(dz) = dz - ||E(dz)|| when k depends on z.
  pure subroutine apex_return(p, sig_tr, z_n, zeta, ret, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig_tr(ntens6), z_n, zeta
    type(return_t), intent(out) :: ret
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: e_dev(ntens6), i1_tr, s, ds, e(ntens6), d, r, drdd, e_hat(ntens6), en
    integer :: it
    logical :: constant_k

    associate (bulk => p%el%bulk, shear => p%el%shear)
      i1_tr = trace(sig_tr)
      e_dev = deviator(sig_tr)/(2.0_dp*shear)
      constant_k = is_linear(p%hard) .and. p%hard%h == 0.0_dp
      d = 0.0_dp
      do it = 1, max_newton
        s = (strength(p%hard, z_n + d) + zeta)/(3.0_dp*p%beta)
        e = e_dev + ((i1_tr - 3.0_dp*s)/(9.0_dp*bulk))*identity2
        en = norm(e)
        if (constant_k) then
          d = en
          exit
        end if
        ds = strength_slope(p%hard, z_n + d)/(3.0_dp*p%beta)
        e_hat = 0.0_dp
        if (en > 0.0_dp) e_hat = e/en
        r = d - en
        drdd = 1.0_dp + ds*trace(e_hat)/(3.0_dp*bulk)
        if (abs(r) <= 4.0_dp*epsilon(1.0_dp)*max(en, tiny(1.0_dp))) then
          d = en
          exit
        end if
        d = max(d - r/drdd, 0.0_dp)
      end do
      if (it > max_newton) then
        call new_error(err, status_cutback, '', 'return mapping: no convergence of '// &
          'the apex return (dz = '//real_text(d)//')')
        return
      end if
      s = (strength(p%hard, z_n + d) + zeta)/(3.0_dp*p%beta)
      ret%sig = s*identity2
      ret%deps_p = e_dev + ((i1_tr - 3.0_dp*s)/(9.0_dp*bulk))*identity2
      ret%dz = norm(ret%deps_p)
      ret%f = 3.0_dp*p%beta*s - strength(p%hard, z_n + ret%dz) - zeta
      ret%state = state_apex
      if (present(tangent)) then
        ! d sigma = s' I (x) E_hat / (1 + s' tr(E_hat)/(3K)), s' = H/(3 beta)
        ds = strength_slope(p%hard, z_n + ret%dz)/(3.0_dp*p%beta)
        e_hat = 0.0_dp
        if (ret%dz > 0.0_dp) e_hat = ret%deps_p/ret%dz
        tangent = (ds/(1.0_dp + ds*trace(e_hat)/(3.0_dp*bulk)))*outer(identity2, e_hat)
      end if
    end associate
  end subroutine apex_return

end module wellposed_return_mapping
