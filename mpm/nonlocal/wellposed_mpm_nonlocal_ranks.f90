!> What Algorithm 1 (wellposed_mpm_algorithm1) needs from a run spread over
!> ranks, on a patch's nodal values: the pipeline of the Gauss-Seidel sweep
!> in the serial order (nodes_from_lower, nodes_to_higher,
!> nodes_from_highest), nodes_sum for the simultaneous sweeps (partial sums
!> at shared nodes, all ranks at once), and the reductions. The MPM's
!> exchange extends this type; one process passes a stand-in that does
!> nothing. Design: docs/guide/parallel.md, "Algorithm 1 across ranks".
module wellposed_mpm_nonlocal_ranks
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: nonlocal_ranks_t

  type, abstract :: nonlocal_ranks_t
  contains
    !> values of the nodes shared with the next lower rank, as that rank left them
    procedure(ranks_nodes), deferred :: nodes_from_lower
    !> this rank's values of the nodes shared with the next higher rank, to it
    procedure(ranks_nodes), deferred :: nodes_to_higher
    !> every node the value of the highest rank holding it
    procedure(ranks_nodes), deferred :: nodes_from_highest
    !> every node the sum of the partial values of all ranks holding it
    !> (added in ascending rank order, the same on every holder)
    procedure(ranks_nodes), deferred :: nodes_sum
    !> maximum over the ranks, in place
    procedure(ranks_max), deferred :: max_real
    !> sum over the ranks, in place
    procedure(ranks_sum_int), deferred :: sum_int
    !> element-wise sum over the ranks, in place
    procedure(ranks_sum_reals), deferred :: sum_reals
    !> true on every rank when true on any
    procedure(ranks_any), deferred :: any_true
    !> every rank's `mine` concatenated in rank order, on every rank
    procedure(ranks_gather), deferred :: gather_all
    !> the number of ranks
    procedure(ranks_count), deferred :: nranks
  end type nonlocal_ranks_t

  abstract interface
    subroutine ranks_nodes(self, values)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(inout) :: self
      real(dp), intent(inout) :: values(:)
    end subroutine ranks_nodes
    subroutine ranks_max(self, x)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(inout) :: self
      real(dp), intent(inout) :: x
    end subroutine ranks_max
    subroutine ranks_sum_int(self, i)
      import :: nonlocal_ranks_t
      class(nonlocal_ranks_t), intent(inout) :: self
      integer, intent(inout) :: i
    end subroutine ranks_sum_int
    subroutine ranks_sum_reals(self, x)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(in) :: self
      real(dp), intent(inout) :: x(:)
    end subroutine ranks_sum_reals
    logical function ranks_any(self, flag)
      import :: nonlocal_ranks_t
      class(nonlocal_ranks_t), intent(inout) :: self
      logical, intent(in) :: flag
    end function ranks_any
    subroutine ranks_gather(self, mine, all)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(inout) :: self
      real(dp), intent(in) :: mine(:)
      real(dp), allocatable, intent(out) :: all(:)
    end subroutine ranks_gather
    integer function ranks_count(self)
      import :: nonlocal_ranks_t
      class(nonlocal_ranks_t), intent(in) :: self
    end function ranks_count
  end interface

end module wellposed_mpm_nonlocal_ranks
