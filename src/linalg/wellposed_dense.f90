!> Small dense linear solves for local Newton iterations (a handful of
!> unknowns, so no LAPACK call overhead and pure for use inside the models).
module wellposed_dense
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: solve_dense

contains

  !> Solve A X = B in place by Gaussian elimination with partial pivoting:
  !> on return B holds X and A is destroyed. `ok` is false for a singular A.
  !>
  !> The columns and then the rows of A are first scaled by powers of two
  !> to a largest entry of order one (exact: no rounding), so unknowns and
  !> equations of different units (a stress and a plastic multiplier, a
  !> stress residual and a yield function with a hardening modulus of
  !> 1e14 Pa) neither trip the singularity test nor steer the pivoting; a
  !> pivot counts as zero below 1e3 epsilon of its scaled row.
  pure subroutine solve_dense(a, b, ok)
    real(dp), intent(inout) :: a(:, :)
    real(dp), intent(inout) :: b(:, :)
    logical, intent(out) :: ok
    integer :: n, i, k, piv
    real(dp) :: factor, big
    ! Automatic arrays (on the stack): no heap allocation on a model's path.
    real(dp) :: row(size(a, 2)), rhs(size(b, 2)), col_scale(size(a, 1))

    n = size(a, 1)
    ok = .false.
    do k = 1, n
      big = maxval(abs(a(:, k)))
      if (.not. (big > 0.0_dp .and. big <= huge(big))) return
      col_scale(k) = power_of_two(big)
      a(:, k) = a(:, k)/col_scale(k)
    end do
    do i = 1, n
      big = maxval(abs(a(i, :)))
      if (.not. big > 0.0_dp) return
      factor = power_of_two(big)
      a(i, :) = a(i, :)/factor
      b(i, :) = b(i, :)/factor
    end do
    do k = 1, n
      piv = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
      if (.not. abs(a(piv, k)) > 1.0e3_dp*epsilon(1.0_dp)) return
      if (piv /= k) then
        row = a(k, :); a(k, :) = a(piv, :); a(piv, :) = row
        rhs = b(k, :); b(k, :) = b(piv, :); b(piv, :) = rhs
      end if
      do i = k + 1, n
        factor = a(i, k)/a(k, k)
        a(i, k:n) = a(i, k:n) - factor*a(k, k:n)
        b(i, :) = b(i, :) - factor*b(k, :)
      end do
    end do
    do k = n, 1, -1
      do i = k + 1, n
        b(k, :) = b(k, :) - a(k, i)*b(i, :)
      end do
      b(k, :) = b(k, :)/a(k, k)
    end do
    do k = 1, n
      b(k, :) = b(k, :)/col_scale(k)
    end do
    ok = .true.
  end subroutine solve_dense

  !> The largest power of two not above `x` > 0 (dividing by it is exact):
  !> x with its mantissa bits cleared, or by set_exponent when x is
  !> subnormal (the bit form is then 0).
  elemental real(dp) function power_of_two(x) result(p)
    real(dp), intent(in) :: x
    integer(int64), parameter :: exponent_bits = int(z'7FF0000000000000', int64)
    p = transfer(iand(transfer(x, 0_int64), exponent_bits), 1.0_dp)
    if (p == 0.0_dp) p = set_exponent(1.0_dp, exponent(x))
  end function power_of_two

end module wellposed_dense
