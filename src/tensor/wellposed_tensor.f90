!> Second- and fourth-order symmetric tensors as Mandel 6-vectors and 6x6
!> matrices. The one tensor convention inside src/:
!>
!>   a = [a11, a22, a33, sqrt(2) a12, sqrt(2) a13, sqrt(2) a23]
!>
!> for stresses and strains alike, so that a:b = dot_product(a, b), ||a|| is
!> the Euclidean norm and a fourth-order tensor acts by matmul. Conversion to
!> Abaqus order and engineering shears happens only in umat/.
module wellposed_tensor
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: ntens6, sqrt2, sqrt3, identity2, trace, deviator, norm, outer, &
            identity4, projector_vol, projector_dev

  !> Number of Mandel components.
  integer, parameter :: ntens6 = 6
  !> sqrt(2), the factor of Mandel's shear components.
  real(dp), parameter :: sqrt2 = 1.4142135623730950488_dp
  !> sqrt(3).
  real(dp), parameter :: sqrt3 = 1.7320508075688772935_dp
  !> Second-order identity I.
  real(dp), parameter :: identity2(ntens6) = [1.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]

contains

  !> tr(a) = a11 + a22 + a33.
  pure function trace(a) result(tr)
    real(dp), intent(in) :: a(ntens6)
    real(dp) :: tr
    tr = a(1) + a(2) + a(3)
  end function trace

  !> Deviatoric part a - tr(a)/3 I.
  pure function deviator(a) result(s)
    real(dp), intent(in) :: a(ntens6)
    real(dp) :: s(ntens6)
    s = a
    s(1:3) = s(1:3) - trace(a)/3.0_dp
  end function deviator

  !> Euclidean (Frobenius) norm sqrt(a:a).
  pure function norm(a) result(n)
    real(dp), intent(in) :: a(ntens6)
    real(dp) :: n
    n = sqrt(dot_product(a, a))
  end function norm

  !> Dyadic product (a (x) b)_ij = a_i b_j.
  pure function outer(a, b) result(c)
    real(dp), intent(in) :: a(ntens6), b(ntens6)
    real(dp) :: c(ntens6, ntens6)
    integer :: j
    do j = 1, ntens6
      c(:, j) = a*b(j)
    end do
  end function outer

  !> Fourth-order symmetric identity (the 6x6 unit matrix in Mandel form).
  pure function identity4() result(c)
    real(dp) :: c(ntens6, ntens6)
    integer :: i
    c = 0.0_dp
    do i = 1, ntens6
      c(i, i) = 1.0_dp
    end do
  end function identity4

  !> Volumetric projector (1/3) I (x) I.
  pure function projector_vol() result(c)
    real(dp) :: c(ntens6, ntens6)
    c = outer(identity2, identity2)/3.0_dp
  end function projector_vol

  !> Deviatoric projector: identity4 - projector_vol.
  pure function projector_dev() result(c)
    real(dp) :: c(ntens6, ntens6)
    c = identity4() - projector_vol()
  end function projector_dev

end module wellposed_tensor
