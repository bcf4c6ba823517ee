!> One increment of the Drucker-Prager model at one point in the components
!> hosts store: stress and strain [11, 22, 33, 12, 13, 23] with tensor
!> shears, the tangent in Voigt form (engineering shears, as DDSDDE).
!> point_closed_form: the regular flow rule with linear hardening and
!> Duvaut-Lions (eq. 4.36-4.39, 2.10) without Mandel conversions, types or
!> calls, so a host's loop can inline and vectorise it. point_update: every
!> model, the closed form where it applies, else dp_update (eq. 2.6, 2.7).
module wellposed_dp_point
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, status_cutback
  use wellposed_tensor, only: ntens6, sqrt2
  use wellposed_dp_params, only: dp_params_t
  use wellposed_hardening, only: is_linear
  use wellposed_dp_model, only: dp_state_t, dp_output_t, dp_update
  use wellposed_return_mapping, only: state_elastic, state_plastic, state_apex
  use wellposed_efr, only: efr_has_direction
  implicit none
  private
  public :: point_update, point_closed_form, has_closed_form, voigt_stiffness, &
            elastic_energy

  real(dp), parameter :: third = 1.0_dp/3.0_dp, rsqrt2 = 1.0_dp/sqrt2
  !> Shear scale between tensor and Mandel components.
  real(dp), parameter :: mandel(ntens6) = [1.0_dp, 1.0_dp, 1.0_dp, sqrt2, sqrt2, sqrt2]
  real(dp), parameter :: rmandel(ntens6) = [1.0_dp, 1.0_dp, 1.0_dp, rsqrt2, rsqrt2, rsqrt2]

contains

  !> True when point_closed_form serves the model: regular flow rule and
  !> linear hardening (k = k0 + h z).
  elemental function has_closed_form(p) result(yes)
    type(dp_params_t), intent(in) :: p
    logical :: yes
    yes = .not. p%efr .and. is_linear(p%hard)
  end function has_closed_form

  !> Advance `sig` and the state (z, zeta, eps_p) by the strain increment
  !> `de` over `dtime`, for any model. Arguments as point_closed_form; on
  !> error `err` is allocated and nothing is changed.
  pure subroutine point_update(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, &
                               status, n, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    type(error_t), allocatable, intent(out) :: err

    if (has_closed_form(p) .or. (is_linear(p%hard) .and. .not. efr_has_direction(p, de))) then
      call point_closed_form(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, &
                             status, n, tangent)
      if (status /= status_cutback) return
    end if
    ! Newton models, and the rare closed-form case with no answer (the
    ! general return then finds the answer or explains why there is none).
    call point_general(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, status, n, &
                       tangent, err)
  end subroutine point_update

  !> point_update through dp_update (Mandel components, derived types): a
  !> procedure of its own so that a closed-form call does not initialise
  !> them.
  pure subroutine point_general(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, &
                                status, n, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    type(error_t), allocatable, intent(out) :: err
    type(dp_state_t) :: state
    type(dp_output_t) :: out
    real(dp) :: sig_m(ntens6), t(ntens6, ntens6)
    integer :: i, j

    sig_m = sig*mandel
    state%z = z
    state%zeta = zeta
    state%eps_p = eps_p*mandel
    if (present(tangent)) then
      call dp_update(p, sig_m, state, de*mandel, dtime, avg_dlambda, out, t, err)
    else
      call dp_update(p, sig_m, state, de*mandel, dtime, avg_dlambda, out, err=err)
    end if
    if (allocated(err)) return
    sig = sig_m/mandel
    zeta = state%zeta
    ! An elastic step leaves the plastic state bit for bit: the Mandel
    ! round trip of eps_p (x sqrt(2), / sqrt(2)) is not exact.
    if (out%status /= state_elastic) then
      z = state%z
      eps_p = state%eps_p/mandel
    end if
    dlambda = out%dlambda
    f = out%f
    status = out%status
    if (present(tangent)) then
      ! Mandel T to Voigt: D^-1 T D^-1, D = diag(mandel); engineering shears.
      ! Multiplications by 1, 1/sqrt(2) and 1/2: no division.
      do j = 1, n
        do i = 1, n
          tangent(i, j) = t(i, j)*(rmandel(i)*rmandel(j))
        end do
      end do
    end if
  end subroutine point_general

  !> The closed-form increment (regular flow rule, linear hardening, eq.
  !> 4.36-4.39; apex return; Duvaut-Lions eq. 2.10 by backward Euler), in
  !> tensor components. `status` is 0 elastic, 1 cone, 2 apex, or
  !> status_cutback where no closed-form answer exists (a cylinder softened
  !> below any admissible stress, or an apex equation without a root): the
  !> arguments are then untouched. `tangent(n, n)` (n = 4 or 6), when
  !> present, receives the leading n x n block of d sigma/d eps (Voigt).
  pure subroutine point_closed_form(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, &
                                    f, status, n, tangent)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    real(dp) :: bulk, shear, zeta_new, tr_de, sig_tr(ntens6), s(ntens6), i1_tr, q, k_n, f_tr
    real(dp) :: x, x_max, shrink, i1, dep(ntens6), dz, sig_new(ntens6), w, s_ap, c0, c1, a2
    real(dp) :: b2, c2, disc, sh(ntens6), cm(ntens6), cn(ntens6), rate, lam, g2, coef, qn, rn
    real(dp) :: t(ntens6, ntens6)
    integer :: j
    logical :: apex

    bulk = p%el%bulk
    shear = p%el%shear
    zeta_new = zeta + p%h_zeta*avg_dlambda
    ! Elastic trial C : de (eq. 1.5).
    tr_de = de(1) + de(2) + de(3)
    sig_tr(1:3) = sig(1:3) + 2.0_dp*shear*(de(1:3) - tr_de/3.0_dp) + bulk*tr_de
    sig_tr(4:6) = sig(4:6) + 2.0_dp*shear*de(4:6)
    i1_tr = sig_tr(1) + sig_tr(2) + sig_tr(3)
    s(1:3) = sig_tr(1:3) - i1_tr/3.0_dp
    s(4:6) = sig_tr(4:6)
    q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
    k_n = p%hard%k0 + p%hard%h*z + zeta_new
    f_tr = q/sqrt2 + p%beta*i1_tr - k_n

    if (.not. f_tr > 0.0_dp) then
      sig = sig_tr
      zeta = zeta_new
      dlambda = 0.0_dp
      f = f_tr
      status = state_elastic
      if (present(tangent)) call voigt_stiffness(bulk, shear, n, tangent)
      return
    end if

    ! Cone (eq. 4.36): x = dlambda from f_tr - (a + h) x = 0; the deviator
    ! vanishes at x_max, beyond which only the apex is reachable. A zero
    ! deviator outside a cylinder (k < 0, beta = 0) has no return: x_max = 0.
    x_max = 0.0_dp
    if (q > 0.0_dp) x_max = q*p%n_m/(sqrt2*shear)
    apex = .false.
    if (p%beta > 0.0_dp) apex = q == 0.0_dp .or. f_tr - (p%a_m + p%hard%h)*x_max > 0.0_dp
    if (.not. apex) then
      x = f_tr/(p%a_m + p%hard%h)
      if (x > x_max) then
        status = status_cutback
        return
      end if
      shrink = 1.0_dp - x/x_max
      rn = 1.0_dp/p%n_m
      i1 = i1_tr - 9.0_dp*bulk*p%beta_p*x*rn
      sig_new = shrink*s
      sig_new(1:3) = sig_new(1:3) + i1/3.0_dp
      ! d eps^p = x M_hat, M_hat = (S_hat/sqrt(2) + beta_p I)/n_m (eq. 4.35).
      dep = (rsqrt2*x*rn/q)*s
      dep(1:3) = dep(1:3) + x*p%beta_p*rn
      dz = x
      status = state_plastic
    else
      ! Apex sigma = s_ap I, s_ap = k(z + d)/(3 beta), d eps^p = C^-1 :
      ! (sigma_trial - sigma_apex), d = ||d eps^p||: with k linear,
      ! d^2 = ||S||^2/(2G)^2 + 3 (c0 - c1 d)^2, a quadratic in d.
      c0 = (i1_tr - k_n/p%beta)/(9.0_dp*bulk)
      c1 = p%hard%h/(9.0_dp*bulk*p%beta)
      a2 = 1.0_dp - 3.0_dp*c1**2
      b2 = 3.0_dp*c0*c1
      c2 = (q/(2.0_dp*shear))**2 + 3.0_dp*c0**2
      disc = b2**2 + a2*c2
      if (.not. disc >= 0.0_dp) then
        status = status_cutback
        return
      end if
      if (b2 >= 0.0_dp) then
        x = c2/(b2 + sqrt(disc))
      else
        x = (sqrt(disc) - b2)/a2
      end if
      if (.not. (x >= 0.0_dp .and. x <= huge(x))) then
        status = status_cutback
        return
      end if
      s_ap = (k_n + p%hard%h*x)/(3.0_dp*p%beta)
      dep = s/(2.0_dp*shear)
      dep(1:3) = dep(1:3) + (i1_tr - 3.0_dp*s_ap)/(9.0_dp*bulk)
      dz = sqrt(dep(1)**2 + dep(2)**2 + dep(3)**2 + 2.0_dp*(dep(4)**2 + dep(5)**2 + dep(6)**2))
      sig_new(1:3) = s_ap
      sig_new(4:6) = 0.0_dp
      status = state_apex
    end if

    if (present(tangent)) then
      if (.not. apex) then
        ! Consistent cone tangent (Voigt form of the Mandel
        ! C - (C:M_hat)(x)(C:N)/(a + h) - x 2 sqrt(2) G^2/(n_m q)(Pdev - S_hat (x) S_hat)).
        sh = (1.0_dp/q)*s
        cm = sqrt2*shear*sh
        cn = cm
        cm(1:3) = cm(1:3) + 3.0_dp*bulk*p%beta_p
        cm = cm*rn
        cn(1:3) = cn(1:3) + 3.0_dp*bulk*p%beta
        rate = 1.0_dp/(p%a_m + p%hard%h)
        g2 = x*2.0_dp*sqrt2*shear**2*rn/q
        lam = bulk - third*(2.0_dp*shear - g2)
        call cone_tangent(shear, g2, rate, lam, sh, cm, cn, t)
        ! One copy into the host's array; n = 6 spelt out so that its
        ! stores are unrolled.
        if (n == ntens6) then
          tangent = t
        else
          tangent = t(1:n, 1:n)
        end if
      else
        ! d sigma = s' I (x) E_hat/(1 + s' tr(E_hat)/(3K)), s' = h/(3 beta).
        coef = 0.0_dp
        qn = p%hard%h/(3.0_dp*p%beta)
        if (dz > 0.0_dp) coef = qn/(1.0_dp + qn*(dep(1) + dep(2) + dep(3))/(dz*3.0_dp*bulk))/dz
        do j = 1, n
          tangent(1:3, j) = coef*dep(j)
          tangent(4:n, j) = 0.0_dp
        end do
      end if
    end if

    if (p%tau > 0.0_dp) then
      ! Duvaut-Lions (eq. 2.10, backward Euler): relax toward the trial.
      w = p%tau/(p%tau + dtime)
      sig_new = sig_new + w*(sig_tr - sig_new)
      dep = (1.0_dp - w)*dep
      dz = (1.0_dp - w)*dz
      if (present(tangent)) call blend_voigt_stiffness(bulk, shear, n, w, tangent)
      i1 = sig_new(1) + sig_new(2) + sig_new(3)
      s(1:3) = sig_new(1:3) - i1/3.0_dp
      s(4:6) = sig_new(4:6)
      q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
      f = q/sqrt2 + p%beta*i1 - (p%hard%k0 + p%hard%h*(z + dz)) - zeta_new
    else if (.not. apex) then
      f = rsqrt2*shrink*q + p%beta*i1 - (p%hard%k0 + p%hard%h*(z + dz)) - zeta_new
    else
      f = 3.0_dp*p%beta*s_ap - (p%hard%k0 + p%hard%h*(z + dz)) - zeta_new
    end if

    sig = sig_new
    eps_p = eps_p + dep
    z = z + dz
    zeta = zeta_new
    dlambda = dz
  end subroutine point_closed_form

  !> The isotropic stiffness in Voigt form (leading n x n block):
  !> K + 4G/3 and K - 2G/3 on the normal block, G on the shears. Each entry
  !> written once; n = 6 spelt out so that its stores are unrolled.
  pure subroutine voigt_stiffness(bulk, shear, n, c)
    real(dp), intent(in) :: bulk, shear
    integer, intent(in) :: n
    real(dp), intent(out) :: c(n, n)
    real(dp) :: lam
    integer :: i, j
    lam = bulk - 2.0_dp*shear/3.0_dp
    if (n == ntens6) then
      do j = 1, ntens6
        do i = 1, ntens6
          c(i, j) = stiffness_entry(i, j, lam, shear)
        end do
      end do
    else
      do j = 1, n
        do i = 1, n
          c(i, j) = stiffness_entry(i, j, lam, shear)
        end do
      end do
    end if
  end subroutine voigt_stiffness

  !> Entry (i, j) of the Voigt stiffness (lam = K - 2G/3).
  pure function stiffness_entry(i, j, lam, shear) result(c)
    integer, intent(in) :: i, j
    real(dp), intent(in) :: lam, shear
    real(dp) :: c
    c = merge(lam, 0.0_dp, i <= 3 .and. j <= 3) + &
        merge(merge(2.0_dp*shear, shear, j <= 3), 0.0_dp, i == j)
  end function stiffness_entry

  !> The consistent cone tangent of point_closed_form (6 x 6):
  !> g2 S_hat (x) S_hat - (C:M_hat)(x)(C:N)/(a + h), plus 2G - g2 (normal)
  !> or G - g2/2 (shear) on the diagonal and lam on the normal block.
  pure subroutine cone_tangent(shear, g2, rate, lam, sh, cm, cn, t)
    real(dp), intent(in) :: shear, g2, rate, lam, sh(ntens6), cm(ntens6), cn(ntens6)
    real(dp), intent(out) :: t(ntens6, ntens6)
    integer :: i, j
    do j = 1, ntens6
      do i = 1, ntens6
        t(i, j) = g2*sh(i)*sh(j) - cm(i)*cn(j)*rate
      end do
      t(j, j) = t(j, j) + merge(2.0_dp*shear - g2, shear - 0.5_dp*g2, j <= 3)
    end do
    t(1:3, 1:3) = t(1:3, 1:3) + lam
  end subroutine cone_tangent

  !> c = (1 - w) c + w C (Voigt form, leading n x n block).
  pure subroutine blend_voigt_stiffness(bulk, shear, n, w, c)
    real(dp), intent(in) :: bulk, shear, w
    integer, intent(in) :: n
    real(dp), intent(inout) :: c(n, n)
    real(dp) :: lam
    integer :: i, j
    lam = bulk - 2.0_dp*shear/3.0_dp
    do j = 1, n
      do i = 1, n
        c(i, j) = (1.0_dp - w)*c(i, j) + w*merge(lam, 0.0_dp, i <= 3 .and. j <= 3)
      end do
      c(j, j) = c(j, j) + w*merge(2.0_dp*shear, shear, j <= 3)
    end do
  end subroutine blend_voigt_stiffness

  !> Elastic energy density sigma : C^-1 : sigma / 2 of a stress in tensor
  !> components: ||S||^2/(4G) + I1^2/(18K).
  pure function elastic_energy(bulk, shear, sig) result(e)
    real(dp), intent(in) :: bulk, shear, sig(ntens6)
    real(dp) :: e, i1, s(3)
    i1 = sig(1) + sig(2) + sig(3)
    s = sig(1:3) - i1/3.0_dp
    e = (s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(sig(4)**2 + sig(5)**2 + sig(6)**2)) &
        /(4.0_dp*shear) + i1**2/(18.0_dp*bulk)
  end function elastic_energy

end module wellposed_dp_point
