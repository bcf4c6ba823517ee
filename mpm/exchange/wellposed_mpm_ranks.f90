!> The exchanges of an MPM scene (bar or plate) over the ranks of an MPI
!> communicator: the solver's mpm_exchange_t, filled with
!> wellposed_mpm_decomposition and wellposed_mpi; on one rank every call is
!> an identity, so `mpirun -np 1` is the serial program bit for bit. Also
!> Algorithm 1's nonlocal_ranks_t: the Gauss-Seidel pipeline in the serial
!> order, from pairwise exchanges with the two neighbouring ranks (patches
!> are intervals of node layers in rank order). Design: docs/guide/parallel.md.
module wellposed_mpm_ranks
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, allreduce_sum, allreduce_max, allreduce_any, gatherv_real, &
                           broadcast, sendrecv_real, allreduce_min, &
                           legacy_handles
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_exchange, only: mpm_exchange_t, check_patch_support
  use wellposed_mpm_decomposition, only: decomposition_t, new_decomposition, restrict_grid, &
                                         hand_off_particles_with, sum_ghost_grid, &
                                         sum_ghost_values, &
                                         owner_of_position, patch_nodes
  implicit none
  private
  public :: mpm_ranks_t, new_mpm_ranks

  !> Tag of the nonlocal pipeline's messages.
  integer, parameter :: tag_pipeline = 81, tag_highest = 82

  !> A scene's ranks: the communicator and, after `setup`, the strips.
  type, extends(mpm_exchange_t) :: mpm_ranks_t
    type(comm_t) :: comm
    type(decomposition_t) :: dec
    integer :: glo = 0         !< first global node of this rank's patch
  contains
    procedure :: setup => ranks_setup
    procedure :: restrict_grid => ranks_restrict
    procedure :: owner => ranks_owner
    procedure :: sync_error => ranks_sync
    procedure :: gather_root => ranks_gather_root
    procedure :: hand_off => ranks_hand_off
    procedure :: check_support => ranks_check
    procedure :: sum_grid => ranks_sum_grid
    procedure :: sum_reals => ranks_sum_reals
    procedure :: rank => ranks_rank
    procedure :: nranks => ranks_nranks
    procedure :: ghost_layers => ranks_ghost
    procedure :: mpi_handle => ranks_handle
    procedure :: nodes_from_lower => ranks_from_lower
    procedure :: nodes_to_higher => ranks_to_higher
    procedure :: nodes_from_highest => ranks_from_highest
    procedure :: nodes_sum => ranks_nodes_sum
    procedure :: max_real => ranks_max
    procedure :: sum_int => ranks_sum_int
    procedure :: any_true => ranks_any
    procedure :: gather_all => ranks_gather
  end type mpm_ranks_t

contains

  !> The exchange of a scene over the ranks of `comm` (strips set by the
  !> scene through `setup`).
  subroutine new_mpm_ranks(self, comm)
    type(mpm_ranks_t), intent(out) :: self
    type(comm_t), intent(in) :: comm
    self%comm = comm
  end subroutine new_mpm_ranks

  subroutine ranks_setup(self, ncells, layer_nodes, ghost, axis, origin, dx, err)
    class(mpm_ranks_t), intent(inout) :: self
    integer, intent(in) :: ncells, layer_nodes, ghost, axis
    real(dp), intent(in) :: origin, dx
    type(error_t), allocatable, intent(out) :: err
    integer :: ghi
    call new_decomposition(self%dec, self%comm, ncells, layer_nodes, ghost, axis, origin, dx, &
                           err)
    if (allocated(err)) then
      err%message = 'cannot run on '//int_text(self%comm%size)//' ranks: '//err%message
      return
    end if
    call patch_nodes(self%dec, self%glo, ghi)
  end subroutine ranks_setup

  subroutine ranks_restrict(self, grid)
    class(mpm_ranks_t), intent(inout) :: self
    type(grid_t), intent(inout) :: grid
    call restrict_grid(self%dec, grid)
  end subroutine ranks_restrict

  integer function ranks_owner(self, x)
    class(mpm_ranks_t), intent(in) :: self
    real(dp), intent(in) :: x
    ranks_owner = owner_of_position(self%dec, x)
  end function ranks_owner

  subroutine ranks_hand_off(self, parts, extra, err, moved)
    class(mpm_ranks_t), intent(inout) :: self
    type(particles_t), intent(inout) :: parts
    real(dp), allocatable, intent(inout) :: extra(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out) :: moved
    moved = 0
    if (self%comm%size == 1) return
    call hand_off_particles_with(self%dec, self%comm, parts, extra, err, moved)
  end subroutine ranks_hand_off

  !> Make an error on any rank an error on every rank (nothing on one
  !> rank): the status and message of the lowest rank where it arose
  !> (Algorithm 1 tells the other ranks with key 'ranks' that it stopped).
  subroutine ranks_sync(self, err)
    class(mpm_ranks_t), intent(inout) :: self
    type(error_t), allocatable, intent(inout) :: err
    integer :: first, head(2), k
    integer, allocatable :: codes(:)
    if (self%comm%size == 1) return
    if (.not. allreduce_any(self%comm, allocated(err))) return
    first = self%comm%size
    if (allocated(err)) then
      if (err%key /= 'ranks') first = self%comm%rank
    end if
    call allreduce_min(self%comm, first)
    if (first == self%comm%size) then
      if (allocated(err)) first = self%comm%rank
      call allreduce_min(self%comm, first)
    end if
    head = 0
    if (self%comm%rank == first) head = [err%status, len(err%message)]
    call broadcast(self%comm, head, first)
    allocate (codes(head(2)))
    if (self%comm%rank == first) codes = [(iachar(err%message(k:k)), k=1, head(2))]
    call broadcast(self%comm, codes, first)
    if (self%comm%rank /= first) then
      if (allocated(err)) deallocate (err)
      allocate (err)
      err%status = head(1)
      err%key = ''
      allocate (character(len=head(2)) :: err%message)
      do k = 1, head(2)
        err%message(k:k) = achar(codes(k))
      end do
    end if
  end subroutine ranks_sync

  subroutine ranks_gather_root(self, mine, all, counts)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(in) :: mine(:)
    real(dp), allocatable, intent(out) :: all(:)
    integer, allocatable, intent(out) :: counts(:)
    if (self%comm%size == 1) then
      all = mine
      counts = [size(mine)]
      return
    end if
    call gatherv_real(self%comm, mine, all, 0, counts)
  end subroutine ranks_gather_root

  !> Support nodes outside the grid: the serial message (the particle left
  !> the grid); inside the grid but outside the patch: the ghost layers are
  !> too narrow (a defect, named as such). This rank's particles only (the
  !> solver makes the error every rank's with sync_error).
  subroutine ranks_check(self, parts, grid, err)
    class(mpm_ranks_t), intent(inout) :: self
    type(particles_t), intent(in) :: parts
    type(grid_t), intent(in) :: grid
    type(error_t), allocatable, intent(out) :: err
    call check_patch_support(parts, grid, self%comm%rank, self%dec%ghost, err)
  end subroutine ranks_check

  subroutine ranks_sum_grid(self, grid, momentum_only)
    class(mpm_ranks_t), intent(inout) :: self
    type(grid_t), intent(inout) :: grid
    logical, intent(in) :: momentum_only
    call sum_ghost_grid(self%dec, self%comm, grid, momentum_only)
  end subroutine ranks_sum_grid

  subroutine ranks_sum_reals(self, x)
    class(mpm_ranks_t), intent(in) :: self
    real(dp), intent(inout) :: x(:)
    if (self%comm%size == 1) return
    call allreduce_sum(self%comm, x)
  end subroutine ranks_sum_reals

  integer function ranks_rank(self)
    class(mpm_ranks_t), intent(in) :: self
    ranks_rank = self%comm%rank
  end function ranks_rank

  integer function ranks_nranks(self)
    class(mpm_ranks_t), intent(in) :: self
    ranks_nranks = self%comm%size
  end function ranks_nranks

  integer function ranks_handle(self)
    class(mpm_ranks_t), intent(in) :: self
    integer :: info
    call legacy_handles(self%comm, ranks_handle, info)
  end function ranks_handle

  integer function ranks_ghost(self)
    class(mpm_ranks_t), intent(in) :: self
    ranks_ghost = self%dec%ghost
  end function ranks_ghost

  !> Neighbour slot of rank `r` (0 when its patch shares no node with ours).
  pure integer function slot_of(self, r) result(k)
    class(mpm_ranks_t), intent(in) :: self
    integer, intent(in) :: r
    do k = 1, self%dec%nnb
      if (self%dec%nb_rank(k) == r) return
    end do
    k = 0
  end function slot_of

  !> values(:) over the patch: the nodes shared with rank r-1 take r-1's
  !> values (after its pass). Rank 0: nothing.
  subroutine ranks_from_lower(self, values)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(inout) :: values(:)
    real(dp) :: none(0)
    integer :: k, lo, hi
    k = slot_of(self, self%comm%rank - 1)
    if (self%comm%rank == 0 .or. k == 0) return
    lo = self%dec%nb_lo(k) - self%glo + 1
    hi = self%dec%nb_hi(k) - self%glo + 1
    call sendrecv_real(self%comm, none, self%comm%rank - 1, values(lo:hi), &
                       self%comm%rank - 1, tag_pipeline)
  end subroutine ranks_from_lower

  !> This rank's values of the nodes shared with rank r+1, to it.
  subroutine ranks_to_higher(self, values)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(inout) :: values(:)
    real(dp) :: none(0)
    integer :: k, lo, hi
    k = slot_of(self, self%comm%rank + 1)
    if (self%comm%rank == self%comm%size - 1 .or. k == 0) return
    lo = self%dec%nb_lo(k) - self%glo + 1
    hi = self%dec%nb_hi(k) - self%glo + 1
    call sendrecv_real(self%comm, values(lo:hi), self%comm%rank + 1, none, &
                       self%comm%rank + 1, tag_pipeline)
  end subroutine ranks_to_higher

  !> Every node the value of the highest rank holding it: the neighbours in
  !> ascending order, each higher one overwriting what it shares.
  subroutine ranks_from_highest(self, values)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(inout) :: values(:)
    real(dp), allocatable :: recv(:)
    integer :: k, lo, hi
    do k = 1, self%dec%nnb
      lo = self%dec%nb_lo(k) - self%glo + 1
      hi = self%dec%nb_hi(k) - self%glo + 1
      allocate (recv(hi - lo + 1))
      call sendrecv_real(self%comm, values(lo:hi), self%dec%nb_rank(k), recv, &
                         self%dec%nb_rank(k), tag_highest)
      if (self%dec%nb_rank(k) > self%comm%rank) values(lo:hi) = recv
      deallocate (recv)
    end do
  end subroutine ranks_from_highest

  !> Every node of the patch the sum of the partial values of the ranks
  !> holding it (the simultaneous sweeps of Algorithm 1).
  subroutine ranks_nodes_sum(self, values)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(inout) :: values(:)
    real(dp), allocatable :: buf(:, :)
    if (self%dec%nnb == 0) return
    buf = reshape(values, [1, size(values)])
    call sum_ghost_values(self%dec, self%comm, buf)
    values = buf(1, :)
  end subroutine ranks_nodes_sum

  subroutine ranks_max(self, x)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(inout) :: x
    if (self%comm%size > 1) call allreduce_max(self%comm, x)
  end subroutine ranks_max

  subroutine ranks_sum_int(self, i)
    class(mpm_ranks_t), intent(inout) :: self
    integer, intent(inout) :: i
    if (self%comm%size > 1) call allreduce_sum(self%comm, i)
  end subroutine ranks_sum_int

  logical function ranks_any(self, flag)
    class(mpm_ranks_t), intent(inout) :: self
    logical, intent(in) :: flag
    ranks_any = flag
    if (self%comm%size > 1) ranks_any = allreduce_any(self%comm, flag)
  end function ranks_any

  subroutine ranks_gather(self, mine, all)
    class(mpm_ranks_t), intent(inout) :: self
    real(dp), intent(in) :: mine(:)
    real(dp), allocatable, intent(out) :: all(:)
    integer :: n
    if (self%comm%size == 1) then
      all = mine
      return
    end if
    call gatherv_real(self%comm, mine, all, 0)
    n = size(all)
    call broadcast(self%comm, n, 0)
    if (self%comm%rank /= 0) then
      deallocate (all)
      allocate (all(n))
    end if
    call broadcast(self%comm, all, 0)
  end subroutine ranks_gather

end module wellposed_mpm_ranks
