!> The Voigt tangents of the closed-form update (wellposed_dp_closed_form):
!> the isotropic stiffness, the consistent cone and apex tangents (eq.
!> 4.36-4.39) and their Duvaut-Lions blend (eq. 2.10), leading n x n block,
!> engineering shears (as DDSDDE).
module wellposed_dp_tangent
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: ntens6, sqrt2
  use wellposed_dp_params, only: dp_params_t
  use wellposed_return_mapping, only: state_plastic
  implicit none
  private
  public :: voigt_stiffness, closed_form_tangent, blend_voigt_stiffness

  real(dp), parameter :: third = 1.0_dp/3.0_dp

contains

  !> The consistent tangent of point_closed_form's return (status 1 cone, 2
  !> apex; s, q the trial's deviator and its norm, x = dlambda, dep and dz
  !> the apex's d eps^p and ||d eps^p||), leading n x n block, Voigt.
  pure subroutine closed_form_tangent(p, status, s, q, x, dep, dz, n, tangent)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: status, n
    real(dp), intent(in) :: s(ntens6), q, x, dep(ntens6), dz
    real(dp), intent(inout) :: tangent(n, n)
    real(dp) :: bulk, shear, sh(ntens6), cm(ntens6), cn(ntens6), rate, rn, g2, lam, coef, qn
    real(dp) :: t(ntens6, ntens6)
    integer :: j
    bulk = p%el%bulk
    shear = p%el%shear
    if (status == state_plastic) then
      ! Consistent cone tangent (Voigt form of the Mandel
      ! C - (C:M_hat)(x)(C:N)/(a + h) - x 2 sqrt(2) G^2/(n_m q)(Pdev - S_hat (x) S_hat)).
      rn = 1.0_dp/p%n_m
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
  end subroutine closed_form_tangent

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

end module wellposed_dp_tangent
