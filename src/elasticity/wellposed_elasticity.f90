!> Isotropic linear elasticity, sigma = C : eps with C = 3K Pvol + 2G Pdev
!> (eq. 1.5), in the Mandel form of wellposed_tensor.
module wellposed_elasticity
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: ntens6, trace, deviator
  implicit none
  private
  public :: elastic_t, stiffness, apply_stiffness, apply_compliance

  !> Bulk modulus K and shear modulus G, in the user's stress units.
  type :: elastic_t
    real(dp) :: bulk = 0.0_dp
    real(dp) :: shear = 0.0_dp
  end type elastic_t

contains

  !> The 6x6 Mandel stiffness C = 3K Pvol + 2G Pdev: 2G on the diagonal,
  !> K - 2G/3 added on the normal-normal block.
  pure function stiffness(el) result(c)
    type(elastic_t), intent(in) :: el
    real(dp) :: c(ntens6, ntens6)
    integer :: i
    c = 0.0_dp
    c(1:3, 1:3) = el%bulk - 2.0_dp*el%shear/3.0_dp
    do i = 1, ntens6
      c(i, i) = c(i, i) + 2.0_dp*el%shear
    end do
  end function stiffness

  !> C : eps without forming C.
  pure function apply_stiffness(el, eps) result(sig)
    type(elastic_t), intent(in) :: el
    real(dp), intent(in) :: eps(ntens6)
    real(dp) :: sig(ntens6)
    sig = 2.0_dp*el%shear*deviator(eps)
    sig(1:3) = sig(1:3) + el%bulk*trace(eps)
  end function apply_stiffness

  !> C^-1 : sig without forming C^-1.
  pure function apply_compliance(el, sig) result(eps)
    type(elastic_t), intent(in) :: el
    real(dp), intent(in) :: sig(ntens6)
    real(dp) :: eps(ntens6)
    eps = deviator(sig)/(2.0_dp*el%shear)
    eps(1:3) = eps(1:3) + trace(sig)/(9.0_dp*el%bulk)
  end function apply_compliance

end module wellposed_elasticity
