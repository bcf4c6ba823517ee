!> Hashiguchi's extended flow rule (EFR, eq. 2.7): the plastic strain
!> direction M = N_hat ||de*|| + P_v de_v I + P_d de* turns with this
!> increment's total strain de. Backward Euler with N_hat at the end of the
!> increment gives seven equations in (sigma, dlambda), which reduce to one
!> scalar equation solved by Newton (efr_return); the tangent is their
!> implicit-function derivative d sigma/d de (it includes how M_hat turns
!> with de). No direction, or a direction that cannot lower f:
!> the regular flow rule. Derivation and edge cases: docs/research/theory.md.
module wellposed_efr
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_tensor, only: ntens6, sqrt2, identity2, trace, deviator, norm
  use wellposed_hardening, only: strength, strength_slope
  use wellposed_drucker_prager, only: potential_direction
  use wellposed_dp_params, only: dp_params_t
  use wellposed_text, only: real_text
  use wellposed_return_mapping, only: return_t, regular_return, elastic_return, apex_return, &
                                      state_plastic, max_newton, cylinder_error
  implicit none
  private
  public :: efr_direction, efr_return, efr_has_direction

  ! Multiplications replace the divisions by 3 and sqrt(2): a division
  ! costs several multiplications.
  real(dp), parameter :: third = 1.0_dp/3.0_dp, rsqrt2 = 1.0_dp/sqrt2

  !> The factored Jacobian of the seven return equations (factor_jacobian).
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
  !>
  !> The seven backward-Euler equations sigma = sigma_tr - t C:M(sigma),
  !> f(sigma, z_n + t ||M||) = 0 (t = dlambda/||M||) reduce to one scalar
  !> equation in t: with dev M = a0 S_hat + P_d de*, the deviator obeys
  !> (||S|| + 2G a0 t) S_hat = S_tr - 2G P_d t de* =: W(t), so S_hat =
  !> W/||W||, ||S|| = ||W|| - 2G a0 t, tr(sigma) = tr(sigma_tr) - 9K b0 t,
  !> and ||W||, S_hat : de* and ||M|| are scalar functions of t (a0 =
  !> ||de*||/(sqrt(2) n_m), b0 = beta_p ||de*||/n_m + P_v tr(de)). Newton on
  !> t; with P_d = 0 and linear hardening the equation is linear and the
  !> first step is exact. Derivation: docs/research/theory.md, docs/guide/performance.md.
  pure subroutine efr_return(p, sig_tr, deps, z_n, zeta, ret, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig_tr(ntens6), deps(ntens6), z_n, zeta
    type(return_t), intent(out) :: ret
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: s_tr(ntens6), q, f_tr, k_n, i1_tr, e_dev(ntens6), d_s, rn, a0, b0, c, se
    real(dp) :: mfix2, scale, t, f, df, fprev, wn, mn, x, qs, dt
    real(dp) :: w(ntens6), s_hat(ntens6), m(ntens6), m_hat(ntens6), cm(ntens6), sig(ntens6)
    type(efr_jacobian_t) :: jac
    integer :: it
    logical :: ok, flipped, converged

    e_dev = dev(deps)
    if (.not. efr_has_direction(p, deps)) then
      call regular_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      return
    end if
    i1_tr = sig_tr(1) + sig_tr(2) + sig_tr(3)
    s_tr = dev(sig_tr)
    q = norm(s_tr)
    k_n = strength(p%hard, z_n) + zeta
    f_tr = q/sqrt2 + p%beta*i1_tr - k_n
    if (.not. f_tr > 0.0_dp) then
      call elastic_return(p, sig_tr, f_tr, ret, tangent)
      return
    end if
    if (q == 0.0_dp) then
      ! On the hydrostatic axis outside the cone: only the apex is reachable;
      ! outside a cylinder (k < 0) no stress is.
      if (p%beta > 0.0_dp) then
        call apex_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      else
        call cylinder_error(k_n, err)
      end if
      return
    end if

    d_s = norm(e_dev)
    rn = 1.0_dp/p%n_m
    a0 = d_s*rn*rsqrt2
    b0 = p%beta_p*d_s*rn + p%p_v*(deps(1) + deps(2) + deps(3))
    c = 2.0_dp*p%el%shear*p%p_d
    se = dot_product(s_tr, e_dev)
    mfix2 = a0**2 + (p%p_d*d_s)**2 + 3.0_dp*b0**2
    ! At t = 0, -f' = N : C : M + k' ||M||: a direction that cannot lower f
    ! takes the regular flow rule.
    t = 0.0_dp
    call efr_residual(t, f, df, wn, mn, qs, flipped)
    ! On a cylinder f ignores I1: N : C : M = (c phi + 2 G a0)/sqrt(2) at
    ! t = 0 (the volumetric part of M does not act on f). A direction with
    ! N : C : M <= 0, or an increment whose deviator is zero to rounding
    ! (dev() errs by a few ulps of ||de||), returns only through hardening,
    ! with unbounded volumetric flow: the regular flow rule (docs/guide/umat.md).
    if (p%beta == 0.0_dp) then
      if (d_s <= 8.0_dp*epsilon(1.0_dp)*norm(deps) .or. &
          .not. c*se/q + 2.0_dp*p%el%shear*a0 > 0.0_dp) df = 0.0_dp
    end if
    if (.not. -df > 0.0_dp) then
      call regular_return(p, sig_tr, z_n, zeta, ret, tangent, err)
      return
    end if

    scale = norm(sig_tr) + abs(k_n)
    fprev = huge(1.0_dp)
    flipped = .false.
    converged = .false.
    do it = 1, max_newton
      dt = -f/df
      t = t + dt
      call efr_residual(t, f, df, wn, mn, qs, flipped)
      if (flipped) exit  ! the deviator went through zero: the cone is out of reach
      converged = abs(f) <= 16.0_dp*epsilon(1.0_dp)*scale .or. &
                  (it > 2 .and. abs(f) <= 1.0e-10_dp*scale .and. abs(f) > 0.5_dp*fprev)
      if (converged) exit
      fprev = abs(f)
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
    if (.not. converged .or. .not. t >= 0.0_dp) then
      call new_error(err, status_cutback, '', 'extended flow rule: the return mapping '// &
        'did not converge (f_trial = '//real_text(f_tr)//')')
      return
    end if

    w = s_tr - (c*t)*e_dev
    s_hat = w*(1.0_dp/wn)
    ! ||M|| is the last residual's (the same quantity to rounding).
    m = a0*s_hat + p%p_d*e_dev
    m(1:3) = m(1:3) + b0
    m_hat = m*(1.0_dp/mn)
    x = t*mn
    cm = elastic(p, m_hat)
    sig = sig_tr - x*cm
    ret%sig = sig
    ret%deps_p = x*m_hat
    ret%dz = x
    ret%f = f
    ret%state = state_plastic
    if (present(tangent)) then
      call factor_jacobian(p, s_hat, qs, m_hat, mn, cm, x, d_s, z_n, jac, ok)
      if (.not. ok) then
        call new_error(err, status_cutback, '', 'extended flow rule: singular '// &
          'tangent system')
        return
      end if
      call efr_tangent(p, jac, s_hat, m_hat, mn, cm, x, e_dev, d_s, tangent)
    end if

  contains

    !> f and df/dt after a return of t along C : M (the scalar equation
    !> above), with wn = ||W||, mn = ||M||, qs = ||S||, and `flip` when S
    !> no longer points along S_tr.
    pure subroutine efr_residual(tt, ff, dff, wn, mn, qs, flip)
      real(dp), intent(in) :: tt
      real(dp), intent(out) :: ff, dff, wn, mn, qs
      logical, intent(out) :: flip
      real(dp) :: we, phi, x, dphi, dmn
      wn = sqrt(q**2 - 2.0_dp*c*tt*se + (c*tt*d_s)**2)
      we = se - c*tt*d_s**2
      phi = we/wn
      mn = sqrt(mfix2 + 2.0_dp*a0*p%p_d*phi)
      x = tt*mn
      qs = wn - 2.0_dp*p%el%shear*a0*tt
      flip = .not. (qs > 0.0_dp .and. q**2 - c*tt*se > 0.0_dp)
      ff = qs*rsqrt2 + p%beta*(i1_tr - 9.0_dp*p%el%bulk*b0*tt) - strength(p%hard, z_n + x) &
           - zeta
      dphi = -c*(d_s**2 - phi**2)/wn
      dmn = a0*p%p_d*dphi/mn
      dff = -(c*phi + 2.0_dp*p%el%shear*a0)*rsqrt2 - 9.0_dp*p%el%bulk*p%beta*b0 &
            - strength_slope(p%hard, z_n + x)*(mn + tt*dmn)
    end subroutine efr_residual

  end subroutine efr_return

  !> The Jacobian of (R_sigma, R_f) with respect to (sigma, dlambda),
  !>   J = [A, C:M_hat; N, -k'],  A = I + x C : dM_hat/dM : dM/dsigma,
  !> held in factored form. With C isotropic and dM/dsigma = c1 (Pdev -
  !> S_hat (x) S_hat) = c1 P (P a projector on deviators), A = I + gamma P -
  !> alpha (C:M_hat) (x) u with alpha = x c1/||M||, gamma = 2 G alpha,
  !> u = P : M_hat: the inverse of I + gamma P is I - gamma/(1 + gamma) P,
  !> Sherman-Morrison adds the rank-one term and the Schur complement the
  !> bordering row and column (docs/guide/performance.md, the extended flow rule).
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

  !> The consistent tangent d sigma/d de: J [T; dx/de] = [B; 0],
  !>   B = C - x C : dM_hat/dM : dM/d de
  !>     = a0 Id + b0 I (x) I - b C:M_s (x) E_hat + b C:M_hat (x) v,
  !> dM/d de = M_s (x) E_hat + P_v I (x) I + P_d Pdev (M_s the regular
  !> potential direction, E_hat the unit deviator of de, b = x/||M||,
  !> v = (dM/d de)^T : M_hat, a0 = 2G (1 - b P_d), b0 = K - 2G/3 - b (3K P_v
  !> - 2G P_d/3)). With the factored J, T = A^-1 B - g (x) (B^T A^-T N)/schur
  !> and A^-1 B = B - shrink P B + rank1 W (x) (B^T u), where P B = a0 P -
  !> b (P C:M_s) (x) E_hat + b (P C:M_hat) (x) v (P I = 0): a sum of outer
  !> products and multiples of Id, I (x) I and S_hat (x) S_hat, formed entry
  !> by entry without a division.
  pure subroutine efr_tangent(p, jac, s_hat, m_hat, mn, cm, x, e_dev, d_s, tangent)
    type(dp_params_t), intent(in) :: p
    type(efr_jacobian_t), intent(in) :: jac
    real(dp), intent(in) :: s_hat(ntens6), m_hat(ntens6), mn, cm(ntens6), x, e_dev(ntens6)
    real(dp), intent(in) :: d_s
    real(dp), intent(out) :: tangent(ntens6, ntens6)
    real(dp) :: e_hat(ntens6), m_s(ntens6), cms(ntens6), v(ntens6), a1(ntens6), a2(ntens6)
    real(dp) :: an(ntens6), bu(ntens6), ban(ntens6), gs(ntens6), b, lam, a0, b0, c_id, c_ii
    real(dp) :: c_ss
    integer :: i, j
    e_hat = 0.0_dp
    if (d_s > 0.0_dp) e_hat = e_dev*(1.0_dp/d_s)
    m_s = unit_normal(s_hat, p%beta_p)*(1.0_dp/p%n_m)
    cms = elastic(p, m_s)
    v = dot_product(m_s, m_hat)*e_hat + p%p_v*trace(m_hat)*identity2 + p%p_d*dev(m_hat)
    b = x/mn
    lam = 3.0_dp*p%el%bulk*p%p_v - 2.0_dp*p%el%shear*p%p_d/3.0_dp
    a0 = 2.0_dp*p%el%shear*(1.0_dp - b*p%p_d)
    b0 = p%el%bulk - 2.0_dp*p%el%shear/3.0_dp - b*lam
    ! A^-T N (P is symmetric), then B^T u (u is a deviator: I . u = 0) and
    ! B^T A^-T N.
    an = jac%n - jac%shrink*project(s_hat, jac%n) + (jac%rank1*dot_product(jac%w, jac%n))*jac%u
    bu = a0*jac%u - (b*dot_product(cms, jac%u))*e_hat + (b*dot_product(cm, jac%u))*v
    ban = a0*an + (b0*trace(an))*identity2 - (b*dot_product(cms, an))*e_hat + &
          (b*dot_product(cm, an))*v
    a1 = -b*(cms - jac%shrink*project(s_hat, cms))
    a2 = b*(cm - jac%shrink*project(s_hat, cm))
    bu = jac%rank1*bu
    gs = -jac%rschur*jac%g
    c_id = a0*(1.0_dp - jac%shrink)
    c_ii = b0 + jac%shrink*a0/3.0_dp
    c_ss = jac%shrink*a0
    do j = 1, ntens6
      do i = 1, ntens6
        tangent(i, j) = c_ii*identity2(i)*identity2(j) + c_ss*s_hat(i)*s_hat(j) + &
                        a1(i)*e_hat(j) + a2(i)*v(j) + jac%w(i)*bu(j) + gs(i)*ban(j)
      end do
      tangent(j, j) = tangent(j, j) + c_id
    end do
  end subroutine efr_tangent

end module wellposed_efr
