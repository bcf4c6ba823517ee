!> Small dense linear solves for local Newton iterations (a handful of
!> unknowns, so no LAPACK call overhead and pure for use inside the models).
module wellposed_dense
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: solve_dense

contains

  !> Solve A X = B in place by Gaussian elimination with partial pivoting:
  !> on return B holds X and A is destroyed. `ok` is false for a singular A.
  pure subroutine solve_dense(a, b, ok)
    real(dp), intent(inout) :: a(:, :)
    real(dp), intent(inout) :: b(:, :)
    logical, intent(out) :: ok
    integer :: n, i, k, piv
    real(dp) :: factor, scale
    real(dp), allocatable :: row(:), rhs(:)

    n = size(a, 1)
    ok = .false.
    scale = maxval(abs(a))
    if (.not. scale > 0.0_dp) return
    allocate (row(n), rhs(size(b, 2)))
    do k = 1, n
      piv = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
      if (.not. abs(a(piv, k)) > 1.0e3_dp*epsilon(1.0_dp)*scale) return
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
      b(k, :) = (b(k, :) - matmul(a(k, k + 1:n), b(k + 1:n, :)))/a(k, k)
    end do
    ok = .true.
  end subroutine solve_dense

end module wellposed_dense
