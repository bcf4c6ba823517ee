!> Finiteness tests for hot paths. ieee_arithmetic's ieee_is_finite makes
!> gfortran save and restore the floating-point environment around every
!> procedure that uses the module (hundreds of cycles per UMAT call), and an
!> ordered comparison such as abs(x) <= huge(x) raises the invalid flag for a
!> NaN (a trap under -ffpe-trap=invalid). Reading the exponent bits does
!> neither: an IEEE double is NaN or +-Inf exactly when they are all ones.
module wellposed_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: is_finite, all_finite

  integer(int64), parameter :: exponent_mask = int(z'7FF0000000000000', int64)

contains

  !> True for a finite real (neither NaN nor +-Inf); raises no flag.
  elemental function is_finite(x) result(finite)
    real(dp), intent(in) :: x
    logical :: finite
    finite = iand(transfer(x, 0_int64), exponent_mask) /= exponent_mask
  end function is_finite

  !> True when every entry of `x` is finite (one call per array on hot
  !> paths). The largest exponent field decides: no branch per entry, so
  !> the loop vectorises.
  pure function all_finite(x) result(finite)
    real(dp), intent(in) :: x(:)
    logical :: finite
    integer(int64) :: worst
    integer :: i
    worst = 0
    do i = 1, size(x)
      worst = max(worst, iand(transfer(x(i), 0_int64), exponent_mask))
    end do
    finite = worst /= exponent_mask
  end function all_finite

end module wellposed_finite
