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
  use wellposed_tensor, only: ntens6, sqrt2, identity2, trace, deviator, norm
  use wellposed_elasticity, only: stiffness, apply_stiffness
  use wellposed_hardening, only: strength, strength_slope
  use wellposed_drucker_prager, only: yield_normal, potential_direction
  use wellposed_dp_params, only: dp_params_t
  use wellposed_text, only: real_text
  use wellposed_return_mapping, only: return_t, regular_return, elastic_return, apex_return, &
                                      state_plastic, max_newton
  implicit none
  private
  public :: efr_direction, efr_return, efr_has_direction

  ! Multiplications replace the divisions by 3 and sqrt(2) on the Newton
  ! path: a division costs several multiplications, and each iteration has
  ! dozens.
  real(dp), parameter :: third = 1.0_dp/3.0_dp, rsqrt2 = 1.0_dp/sqrt2

  !> The factored Newton Jacobian of the return (factor_jacobian).
  type :: efr_jacobian_t
    real(dp) :: s_hat(ntens6) = 0.0_dp  !< unit stress deviator
    real(dp) :: u(ntens6) = 0.0_dp      !< P : M_hat
    real(dp) :: w(ntens6) = 0.0_dp      !< (I + gamma P)^-1 : C : M_hat
    real(dp) :: g(ntens6) = 0.0_dp      !< A^-1 : C : M_hat
    real(dp) :: n(ntens6) = 0.0_dp      !< yield normal N
    real(dp) :: shrink = 0.0_dp         !< gamma/(1 + gamma)
    real(dp) :: rank1 = 0.0_dp          !< Sherman-Morrison factor
    real(dp) :: schur = 0.0_dp          !< N : A^-1 : C : M_hat - k'
    real(dp) :: rschur = 0.0_dp         !< 1/schur
  end type efr_jacobian_t

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

  !> True when the increment `deps` (Mandel or tensor components) gives the
  !> EFR a direction: a deviatoric part, or a volumetric one with P_v /= 0.
  !> Without one the regular flow rule applies.
  pure function efr_has_direction(p, deps) result(yes)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: deps(ntens6)
    logical :: yes
    yes = any(deviator(deps) /= 0.0_dp) .or. (p%p_v /= 0.0_dp .and. trace(deps) /= 0.0_dp)
  end function efr_has_direction

  !> Return `sig_tr` onto the cone with the EFR direction of the strain
  !> increment `deps` (Mandel). Arguments as regular_return.
  pure subroutine efr_return(p, sig_tr, deps, z_n, zeta, ret, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig_tr(ntens6), deps(ntens6), z_n, zeta
    type(return_t), intent(out) :: ret
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: s_tr(ntens6), q, f_tr, k_n, sig(ntens6), x, s(ntens6), qs, s_hat(ntens6)
    real(dp) :: m(ntens6), mn, m_hat(ntens6), cm(ntens6), res(7), rnorm, rprev, scale, d_s
    real(dp) :: e_dev(ntens6), dsig(ntens6), dx, m_fixed(ntens6), rn
    type(efr_jacobian_t) :: jac
    integer :: it
    logical :: ok, flipped, converged

    e_dev = deviator(deps)
    d_s = norm(e_dev)
    if (.not. efr_has_direction(p, deps)) then
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
    m = efr_direction(p, s_tr/q, deps)
    if (.not. dot_product(yield_normal(s_tr/q, p%beta), apply_stiffness(p%el, m))/norm(m) &
        + strength_slope(p%hard, z_n) > 0.0_dp) then
      call regular_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      return
    end if

    ! The part of M that does not turn with the stress (eq. 2.7).
    m_fixed = p%p_v*trace(deps)*identity2 + p%p_d*e_dev
    rn = 1.0_dp/p%n_m
    scale = norm(sig_tr) + abs(k_n)
    sig = sig_tr
    x = 0.0_dp
    cm = 0.0_dp
    rprev = huge(1.0_dp)
    flipped = .false.
    converged = .false.
    do it = 1, max_newton
      s = dev(sig)
      qs = norm(s)
      if (.not. dot_product(s, s_tr) > 0.0_dp) then
        flipped = .true.  ! the deviator went through zero: the cone is out of reach
        exit
      end if
      s_hat = s*(1.0_dp/qs)
      m = unit_normal(s_hat, p%beta_p)*(d_s*rn) + m_fixed
      mn = norm(m)
      m_hat = m*(1.0_dp/mn)
      cm = elastic(p, m_hat)
      res(1:6) = sig - sig_tr + x*cm
      res(7) = qs*rsqrt2 + p%beta*trace(sig) - strength(p%hard, z_n + x) - zeta
      call factor_jacobian(p, s_hat, qs, m_hat, mn, cm, x, d_s, z_n, jac, ok)
      rnorm = maxval(abs(res))
      converged = rnorm <= 16.0_dp*epsilon(1.0_dp)*scale .or. &
                  (it > 2 .and. rnorm <= 1.0e-10_dp*scale .and. rnorm > 0.5_dp*rprev)
      if (converged .or. .not. ok) exit
      rprev = rnorm
      call solve_jacobian(jac, -res(1:6), -res(7), dsig, dx)
      sig = sig + dsig
      x = x + dx
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
    if (.not. converged .or. .not. x >= 0.0_dp) then
      call new_error(err, status_cutback, '', 'extended flow rule: the return mapping '// &
        'did not converge (f_trial = '//real_text(f_tr)//')')
      return
    end if

    ret%sig = sig
    ret%deps_p = x*m_hat
    ret%dz = x
    ret%f = res(7)
    ret%state = state_plastic
    if (present(tangent)) then
      if (.not. ok) then
        call new_error(err, status_cutback, '', 'extended flow rule: singular '// &
          'tangent system')
        return
      end if
      call efr_tangent(p, jac, s_hat, m_hat, mn, cm, x, e_dev, d_s, tangent)
    end if

  end subroutine efr_return

  !> The Newton Jacobian of (R_sigma, R_f) with respect to (sigma, dlambda),
  !>   J = [A, C:M_hat; N, -k'],  A = I + x C : dM_hat/dM : dM/dsigma,
  !> held in factored form. With C isotropic and dM/dsigma = c1 (Pdev -
  !> S_hat (x) S_hat) = c1 P (P a projector on deviators), A = I + gamma P -
  !> alpha (C:M_hat) (x) u with alpha = x c1/||M||, gamma = 2 G alpha,
  !> u = P : M_hat: the inverse of I + gamma P is I - gamma/(1 + gamma) P,
  !> Sherman-Morrison adds the rank-one term and the Schur complement the
  !> bordering row and column (docs/performance.md, the extended flow rule).
  pure subroutine factor_jacobian(p, s_hat, qs, m_hat, mn, cm, x, d_s, z_n, jac, ok)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: s_hat(ntens6), qs, m_hat(ntens6), mn, cm(ntens6), x, d_s, z_n
    type(efr_jacobian_t), intent(out) :: jac
    logical, intent(out) :: ok
    real(dp) :: alpha, gamma, denom
    alpha = x*d_s/(sqrt2*p%n_m*qs*mn)
    gamma = 2.0_dp*p%el%shear*alpha
    jac%s_hat = s_hat
    jac%u = project(s_hat, m_hat)
    jac%n = unit_normal(s_hat, p%beta)
    ok = 1.0_dp + gamma /= 0.0_dp
    if (.not. ok) return
    jac%shrink = gamma/(1.0_dp + gamma)
    jac%w = cm - jac%shrink*project(s_hat, cm)
    denom = 1.0_dp - alpha*dot_product(jac%u, cm)/(1.0_dp + gamma)
    ok = denom /= 0.0_dp
    if (.not. ok) return
    jac%rank1 = alpha/((1.0_dp + gamma)*denom)
    jac%g = apply_a_inverse(jac, cm)
    jac%schur = dot_product(jac%n, jac%g) + strength_slope(p%hard, z_n + x)
    ok = jac%schur /= 0.0_dp
    if (ok) jac%rschur = 1.0_dp/jac%schur
  end subroutine factor_jacobian

  !> P : v = dev(v) - (S_hat : v) S_hat.
  pure function project(s_hat, v) result(pv)
    real(dp), intent(in) :: s_hat(ntens6), v(ntens6)
    real(dp) :: pv(ntens6)
    pv = dev(v) - dot_product(s_hat, v)*s_hat
  end function project

  !> Deviatoric part a - tr(a)/3 I (Mandel).
  pure function dev(a) result(s)
    real(dp), intent(in) :: a(ntens6)
    real(dp) :: s(ntens6)
    s = a
    s(1:3) = a(1:3) - (a(1) + a(2) + a(3))*third
  end function dev

  !> The cone's normal S_hat/sqrt(2) + b I for the slope b (beta: the yield
  !> normal N; beta_p: n_m times the regular potential direction, eq. 4.35).
  pure function unit_normal(s_hat, b) result(n)
    real(dp), intent(in) :: s_hat(ntens6), b
    real(dp) :: n(ntens6)
    n = s_hat*rsqrt2 + b*identity2
  end function unit_normal

  !> C : v = 2G dev(v) + K tr(v) I (Mandel) without forming C.
  pure function elastic(p, v) result(cv)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: v(ntens6)
    real(dp) :: cv(ntens6)
    cv = (2.0_dp*p%el%shear)*dev(v)
    cv(1:3) = cv(1:3) + p%el%bulk*(v(1) + v(2) + v(3))
  end function elastic

  !> A^-1 : v (Sherman-Morrison on I + gamma P; u^T (I + gamma P)^-1 =
  !> u^T/(1 + gamma) since P u = u).
  pure function apply_a_inverse(jac, v) result(y)
    type(efr_jacobian_t), intent(in) :: jac
    real(dp), intent(in) :: v(ntens6)
    real(dp) :: y(ntens6)
    y = v - jac%shrink*project(jac%s_hat, v) + (jac%rank1*dot_product(jac%u, v))*jac%w
  end function apply_a_inverse

  !> Solve J [y; t] = [r; r7] by the Schur complement of the bordered system.
  pure subroutine solve_jacobian(jac, r, r7, y, t)
    type(efr_jacobian_t), intent(in) :: jac
    real(dp), intent(in) :: r(ntens6), r7
    real(dp), intent(out) :: y(ntens6), t
    y = apply_a_inverse(jac, r)
    t = (dot_product(jac%n, y) - r7)*jac%rschur
    y = y - t*jac%g
  end subroutine solve_jacobian

  !> The consistent tangent d sigma/d de: J [T; dx/de] = [C - x C : dM_hat/dM
  !> : dM/d de; 0], dM/d de = M_s (x) E_hat + P_v I (x) I + P_d Pdev
  !> (M_s the regular potential direction, E_hat the unit deviator of de),
  !> solved column by column with the factored J.
  pure subroutine efr_tangent(p, jac, s_hat, m_hat, mn, cm, x, e_dev, d_s, tangent)
    type(dp_params_t), intent(in) :: p
    type(efr_jacobian_t), intent(in) :: jac
    real(dp), intent(in) :: s_hat(ntens6), m_hat(ntens6), mn, cm(ntens6), x, e_dev(ntens6)
    real(dp), intent(in) :: d_s
    real(dp), intent(out) :: tangent(ntens6, ntens6)
    real(dp) :: e_hat(ntens6), m_s(ntens6), cms(ntens6), v(ntens6), c(ntens6, ntens6)
    real(dp) :: col(ntens6), b, lam, t
    integer :: i, j
    e_hat = 0.0_dp
    if (d_s > 0.0_dp) e_hat = e_dev*(1.0_dp/d_s)
    m_s = unit_normal(s_hat, p%beta_p)*(1.0_dp/p%n_m)
    cms = elastic(p, m_s)
    ! (dM/d de)^T : M_hat, and C : dM/d de = cms (x) e_hat + the isotropic
    ! P_v 3K I (x) I + P_d 2G Pdev.
    v = dot_product(m_s, m_hat)*e_hat + p%p_v*trace(m_hat)*identity2 + p%p_d*dev(m_hat)
    b = x/mn
    c = stiffness(p%el)
    lam = 3.0_dp*p%el%bulk*p%p_v - 2.0_dp*p%el%shear*p%p_d/3.0_dp
    do j = 1, ntens6
      do i = 1, ntens6
        col(i) = c(i, j) - b*(cms(i)*e_hat(j) - cm(i)*v(j) + lam*identity2(i)*identity2(j))
      end do
      col(j) = col(j) - b*2.0_dp*p%el%shear*p%p_d
      col = apply_a_inverse(jac, col)
      t = dot_product(jac%n, col)*jac%rschur
      tangent(:, j) = col - t*jac%g
    end do
  end subroutine efr_tangent

end module wellposed_efr
