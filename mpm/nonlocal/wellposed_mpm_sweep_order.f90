!> The sweep order of Algorithm 1 (`sweep_key`): by the cell layer along the
!> decomposition axis that owns the particle's start-of-step position, then
!> by global id. The pipeline needs every key of rank r below every key of
!> rank r+1, which the id alone is not once particles cross ranks; the
!> layer does not depend on the rank count, so every N sweeps in the
!> serial program's order (docs/guide/parallel.md, "Algorithm 1 across ranks").
module wellposed_mpm_sweep_order
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: sweep_key, sweep_layer, sweep_colour, key_order, find_sorted

contains

  !> The sweep key of a particle in cell layer `layer` (0 .. ncells-1 along
  !> the decomposition axis, the layer that decides its owner) with global
  !> id `gid` (1 .. 2**31-1): layer first, then id. Below 2**53 while
  !> layer < 2**22, so exact also as a real (Anderson gathers keys so).
  elemental integer(int64) function sweep_key(layer, gid) result(k)
    integer, intent(in) :: layer, gid
    k = int(layer, int64)*2_int64**31 + int(gid, int64)
  end function sweep_key

  !> The cell layer of a sweep key.
  elemental integer function sweep_layer(k) result(layer)
    integer(int64), intent(in) :: k
    layer = int(k/2_int64**31)
  end function sweep_layer

  !> The colour (0 or 1) of the coloured sweep of a particle in cell layer
  !> `layer`: the parity of its block of `width` layers. Blocks wider than
  !> the Gaussian's reach keep a colour's particles out of each other's
  !> support.
  elemental integer function sweep_colour(layer, width) result(c)
    integer, intent(in) :: layer, width
    c = modulo(layer/width, 2)
  end function sweep_colour

  !> order(1:n): the indices of key(1:n) in ascending key order (stable
  !> merge sort; the identity, at the cost of one pass, when already sorted).
  pure subroutine key_order(key, order)
    integer(int64), intent(in) :: key(:)
    integer, allocatable, intent(out) :: order(:)
    integer, allocatable :: tmp(:)
    integer :: n, width, lo, mid, hi, i, j, k, p
    n = size(key)
    order = [(p, p=1, n)]
    if (n < 2) return
    if (all(key(2:) >= key(:n - 1))) return
    allocate (tmp(n))
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width, n + 1)
        hi = min(lo + 2*width, n + 1)
        i = lo
        j = mid
        do k = lo, hi - 1
          if (i < mid .and. (j >= hi .or. key(order(min(i, n))) <= key(order(min(j, n))))) then
            tmp(k) = order(i)
            i = i + 1
          else
            tmp(k) = order(j)
            j = j + 1
          end if
        end do
      end do
      order = tmp
      width = 2*width
    end do
  end subroutine key_order

  !> Index of `x` in the ascending `sorted` (x must occur).
  pure integer function find_sorted(sorted, x) result(pos)
    real(dp), intent(in) :: sorted(:), x(1)
    integer :: lo, hi, mid
    lo = 1
    hi = size(sorted)
    do while (lo < hi)
      mid = (lo + hi)/2
      if (sorted(mid) < x(1)) then
        lo = mid + 1
      else
        hi = mid
      end if
    end do
    pos = lo
  end function find_sorted

end module wellposed_mpm_sweep_order
