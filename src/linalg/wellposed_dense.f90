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
    ! The column scales live in a fixed buffer up to max_fixed unknowns
    ! (gfortran puts automatic arrays on the heap): no allocation on a
    ! model's path.
    integer, parameter :: max_fixed = 32
    real(dp) :: scale_fixed(max_fixed)
    real(dp), allocatable :: scale_heap(:)
    integer :: n, m
    n = size(a, 1)
    m = size(b, 2)
    if (n <= max_fixed) then
      call eliminate(n, m, a, b, scale_fixed, ok)
    else
      allocate (scale_heap(n))
      call eliminate(n, m, a, b, scale_heap, ok)
    end if
  end subroutine solve_dense

  !> solve_dense on explicit-shape arrays (contiguous: the compiler can
  !> specialise it for a caller's fixed n), the column scales' storage given.
  pure subroutine eliminate(n, m, a, b, col_scale, ok)
    integer, intent(in) :: n, m
    real(dp), intent(inout) :: a(n, n)
    real(dp), intent(inout) :: b(n, m)
    real(dp), intent(out) :: col_scale(*)
    logical, intent(out) :: ok
    integer :: i, j, k, piv
    real(dp) :: factor, big, swap

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
    ! Column-oriented elimination; the multipliers overwrite column k.
    do k = 1, n
      piv = k
      big = abs(a(k, k))
      do i = k + 1, n
        if (abs(a(i, k)) > big) then
          piv = i
          big = abs(a(i, k))
        end if
      end do
      if (.not. big > 1.0e3_dp*epsilon(1.0_dp)) return
      if (piv /= k) then
        do j = 1, n
          swap = a(k, j); a(k, j) = a(piv, j); a(piv, j) = swap
        end do
        do j = 1, m
          swap = b(k, j); b(k, j) = b(piv, j); b(piv, j) = swap
        end do
      end if
      do i = k + 1, n
        a(i, k) = a(i, k)/a(k, k)
      end do
      do j = k + 1, n
        do i = k + 1, n
          a(i, j) = a(i, j) - a(i, k)*a(k, j)
        end do
      end do
      do j = 1, m
        do i = k + 1, n
          b(i, j) = b(i, j) - a(i, k)*b(k, j)
        end do
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
  end subroutine eliminate

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
