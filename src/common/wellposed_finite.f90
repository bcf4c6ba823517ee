!> Finiteness tests for hot paths, by a bit test: an IEEE double is NaN or
!> +-Inf exactly when its exponent bits are all ones. Not ieee_is_finite:
!> the IEEE module makes gfortran save and restore the floating-point
!> environment around every procedure that uses it. Not abs(x) <= huge(x):
!> an ordered comparison raises the invalid flag for a NaN (a trap under
!> -ffpe-trap=invalid).
module wellposed_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: is_finite, all_finite, nonfinite_bits, finite_carry, range_bits, range_carry, &
            exponent_bits

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
    finite = finite_carry(x) >= 0
  end function all_finite

  !> nonfinite_bits of every entry of `x` OR-ed: negative when one of them
  !> is NaN or +-Inf. Several arrays' carries OR-ed need one branch.
  pure function finite_carry(x) result(carry)
    real(dp), intent(in) :: x(:)
    integer(int64) :: carry
    integer :: i
    carry = 0
    do i = 1, size(x)
      carry = ior(carry, nonfinite_bits(x(i)))
    end do
  end function finite_carry

  !> Negative when x is NaN or +-Inf, else >= 0 (the complement of the
  !> exponent field minus 1): an OR of such values is negative exactly when
  !> one of them is, so many arrays can be tested with one branch.
  elemental integer(int64) function nonfinite_bits(x)
    real(dp), intent(in) :: x
    nonfinite_bits = iand(not(transfer(x, 0_int64)), exponent_mask) - 1_int64
  end function nonfinite_bits

  !> The exponent field of x (sign dropped): an order of |x| by powers of
  !> two, all ones for NaN and +-Inf.
  elemental integer(int64) function exponent_bits(x)
    real(dp), intent(in) :: x
    exponent_bits = iand(transfer(x, 0_int64), exponent_mask)
  end function exponent_bits

  !> Negative when |x| >= 2**(e + 1), e the exponent of the limit whose
  !> exponent_bits are `limit` (NaN and +-Inf included), else >= 0: a range
  !> test that ORs like nonfinite_bits, for the same cost.
  elemental integer(int64) function range_bits(x, limit)
    real(dp), intent(in) :: x
    integer(int64), intent(in) :: limit
    range_bits = limit - iand(transfer(x, 0_int64), exponent_mask)
  end function range_bits

  !> range_bits of every entry of `x` OR-ed.
  pure function range_carry(x, limit) result(carry)
    real(dp), intent(in) :: x(:)
    integer(int64), intent(in) :: limit
    integer(int64) :: carry
    integer :: i
    carry = 0
    do i = 1, size(x)
      carry = ior(carry, range_bits(x(i), limit))
    end do
  end function range_carry

end module wellposed_finite
