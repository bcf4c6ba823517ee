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
  !> paths). The complement of the exponent field is 0 exactly for NaN and
  !> +-Inf, and that complement minus 1 is then the only negative one: OR-ing
  !> them needs no branch and no 64-bit comparison, so the loop vectorises.
  pure function all_finite(x) result(finite)
    real(dp), intent(in) :: x(:)
    logical :: finite
    integer(int64) :: carry
    integer :: i
    carry = 0
    do i = 1, size(x)
      carry = ior(carry, iand(not(transfer(x(i), 0_int64)), exponent_mask) - 1)
    end do
    finite = carry >= 0
  end function all_finite

end module wellposed_finite
