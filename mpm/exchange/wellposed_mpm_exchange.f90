!> What a domain-decomposed run exchanges between ranks, as calls the MPM
!> solver makes every step without knowing whether there are other ranks.
!> mpm_serial_t (here): one process owning the whole grid, nothing to
!> exchange, a particle leaving the grid an error naming it. mpm_ranks_t
!> (wellposed_mpm_ranks) extends it with MPI in the parallel library, so the
!> core library keeps no MPI; one rank is the serial program bit for bit.
!> Also Algorithm 1's node exchanges and reductions (nonlocal_ranks_t).
module wellposed_mpm_exchange
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_particles, only: particles_t, first_outside
  use wellposed_mpm_nonlocal, only: nonlocal_ranks_t
  implicit none
  private
  public :: mpm_exchange_t, mpm_serial_t, left_grid_error, check_patch_support

  !> The exchanges of a decomposed scene (collective where it says so).
  type, abstract, extends(nonlocal_ranks_t) :: mpm_exchange_t
  contains
    !> share `ncells` cell layers along coordinate `axis` (node layer 0 at
    !> `origin`, size `dx`, m; `layer_nodes` nodes per node layer) with
    !> `ghost` node layers around every patch
    procedure(ex_setup), deferred :: setup
    !> cut a whole grid (as built for one process) down to this rank's patch
    procedure(ex_restrict), deferred :: restrict_grid
    !> the rank owning the cell layer that holds coordinate x along the
    !> split axis (-1 outside the grid)
    procedure(ex_owner), deferred :: owner
    !> particles to the rank of their cell layer, each with its column of
    !> `extra` (collective); `moved`: the particles this rank sent
    procedure(ex_hand_off), deferred :: hand_off
    !> every particle's support nodes (parts%node) inside the patch, else an
    !> error naming the first that is not (this rank's particles)
    procedure(ex_check), deferred :: check_support
    !> sum the patches' partial particle-to-grid sums at shared nodes:
    !> mass, momentum and forces, or the momentum only (collective)
    procedure(ex_sum_grid), deferred :: sum_grid
    !> an error on any rank becomes an error on every rank, with the
    !> message of the lowest rank where it arose (collective)
    procedure(ex_sync), deferred :: sync_error
    !> every rank's `mine` concatenated in rank order on rank 0, with the
    !> count of each rank (collective; the other ranks get nothing)
    procedure(ex_gather), deferred :: gather_root
    !> 0-based rank of this process (the number of ranks: nranks)
    procedure(ex_int), deferred :: rank
    !> ghost node layers of the patches
    procedure(ex_int), deferred :: ghost_layers
    !> the Fortran handle of the ranks' MPI communicator (MPI_Comm%MPI_VAL,
    !> for a library such as PETSc); -1 for one process without MPI
    procedure(ex_int), deferred :: mpi_handle
  end type mpm_exchange_t

  abstract interface
    subroutine ex_setup(self, ncells, layer_nodes, ghost, axis, origin, dx, err)
      import :: mpm_exchange_t, dp, error_t
      class(mpm_exchange_t), intent(inout) :: self
      integer, intent(in) :: ncells, layer_nodes, ghost, axis
      real(dp), intent(in) :: origin, dx
      type(error_t), allocatable, intent(out) :: err
    end subroutine ex_setup
    subroutine ex_restrict(self, grid)
      import :: mpm_exchange_t, grid_t
      class(mpm_exchange_t), intent(inout) :: self
      type(grid_t), intent(inout) :: grid
    end subroutine ex_restrict
    integer function ex_owner(self, x)
      import :: mpm_exchange_t, dp
      class(mpm_exchange_t), intent(in) :: self
      real(dp), intent(in) :: x
    end function ex_owner
    subroutine ex_hand_off(self, parts, extra, err, moved)
      import :: mpm_exchange_t, particles_t, error_t, dp
      class(mpm_exchange_t), intent(inout) :: self
      type(particles_t), intent(inout) :: parts
      real(dp), allocatable, intent(inout) :: extra(:, :)
      type(error_t), allocatable, intent(out) :: err
      integer, intent(out) :: moved
    end subroutine ex_hand_off
    subroutine ex_sync(self, err)
      import :: mpm_exchange_t, error_t
      class(mpm_exchange_t), intent(inout) :: self
      type(error_t), allocatable, intent(inout) :: err
    end subroutine ex_sync
    subroutine ex_gather(self, mine, all, counts)
      import :: mpm_exchange_t, dp
      class(mpm_exchange_t), intent(inout) :: self
      real(dp), intent(in) :: mine(:)
      real(dp), allocatable, intent(out) :: all(:)
      integer, allocatable, intent(out) :: counts(:)
    end subroutine ex_gather
    subroutine ex_check(self, parts, grid, err)
      import :: mpm_exchange_t, particles_t, grid_t, error_t
      class(mpm_exchange_t), intent(inout) :: self
      type(particles_t), intent(in) :: parts
      type(grid_t), intent(in) :: grid
      type(error_t), allocatable, intent(out) :: err
    end subroutine ex_check
    subroutine ex_sum_grid(self, grid, momentum_only)
      import :: mpm_exchange_t, grid_t
      class(mpm_exchange_t), intent(inout) :: self
      type(grid_t), intent(inout) :: grid
      logical, intent(in) :: momentum_only
    end subroutine ex_sum_grid
    integer function ex_int(self)
      import :: mpm_exchange_t
      class(mpm_exchange_t), intent(in) :: self
    end function ex_int
  end interface

  !> One process: the whole grid is its patch, nothing to exchange.
  type, extends(mpm_exchange_t) :: mpm_serial_t
  contains
    procedure :: setup => serial_setup
    procedure :: restrict_grid => serial_restrict
    procedure :: owner => serial_owner
    procedure :: sync_error => serial_sync
    procedure :: gather_root => serial_gather_root
    procedure :: hand_off => serial_hand_off
    procedure :: check_support => serial_check
    procedure :: sum_grid => serial_sum_grid
    procedure :: sum_reals => serial_sum_reals
    procedure :: rank => serial_rank
    procedure :: nranks => serial_nranks
    procedure :: ghost_layers => serial_ghost
    procedure :: mpi_handle => serial_handle
    procedure :: nodes_from_lower => serial_nodes
    procedure :: nodes_to_higher => serial_nodes
    procedure :: nodes_from_highest => serial_nodes
    procedure :: nodes_sum => serial_nodes
    procedure :: max_real => serial_max
    procedure :: sum_int => serial_sum_int
    procedure :: any_true => serial_any
    procedure :: gather_all => serial_gather
  end type mpm_serial_t

contains

  !> The error of particle p (global id gid, at x m) whose support left the
  !> grid [x_lo, x_hi] (m, along x(1)): the same words on one rank and on
  !> many. A plate names the point (x, y).
  subroutine left_grid_error(gid, x, x_lo, x_hi, err)
    integer, intent(in) :: gid
    real(dp), intent(in) :: x(:), x_lo, x_hi
    type(error_t), allocatable, intent(out) :: err
    character(len=160) :: buf
    if (size(x) == 1) then
      write (buf, '(a,i0,a,es12.5,a,es12.5,a,es12.5,a)') 'particle ', gid, ' at x = ', x(1), &
        ' m left the grid [', x_lo, ', ', x_hi, '] m'
    else
      write (buf, '(a,i0,a,es12.5,a,es12.5,a)') 'particle ', gid, ' at (x, y) = (', x(1), &
        ', ', x(2), ') m left the grid'
    end if
    call new_error(err, status_invalid, 'grid', trim(buf)//'; enlarge the grid '// &
      '(grid%pad_cells) or shorten the run')
  end subroutine left_grid_error

  !> The first particle whose support nodes (parts%node) lie outside the
  !> patch [grid%glo, grid%ghi] of rank `rank`: outside the grid, the error
  !> that it left the grid; inside, that the `ghost` layers are too narrow
  !> (a defect, named as such). Nothing when every support is inside.
  subroutine check_patch_support(parts, grid, rank, ghost, err)
    type(particles_t), intent(in) :: parts
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: rank, ghost
    type(error_t), allocatable, intent(out) :: err
    integer :: p
    p = first_outside(parts%node, parts%n, grid%glo, grid%ghi)
    if (p == 0) return
    if (minval(parts%node(:, p)) < 0 .or. maxval(parts%node(:, p)) > grid%nnodes - 1) then
      call left_grid_error(parts%gid(p), parts%x(:, p), grid%origin, &
                           grid%origin + (grid%nnodes - 1)*grid%dx, err)
    else
      call new_error(err, status_invalid, 'ghost', 'particle '//int_text(parts%gid(p))// &
        ' reaches nodes outside the patch ['//int_text(grid%glo)//', '// &
        int_text(grid%ghi)//'] of rank '//int_text(rank)//': ghost width '// &
        int_text(ghost)//' is below the shape support')
    end if
  end subroutine check_patch_support

  ! The serial stand-in: every argument it does not need is unused on
  ! purpose (this file is compiled with -Wno-unused-dummy-argument).

  subroutine serial_setup(self, ncells, layer_nodes, ghost, axis, origin, dx, err)
    class(mpm_serial_t), intent(inout) :: self
    integer, intent(in) :: ncells, layer_nodes, ghost, axis
    real(dp), intent(in) :: origin, dx
    type(error_t), allocatable, intent(out) :: err
  end subroutine serial_setup

  subroutine serial_restrict(self, grid)
    class(mpm_serial_t), intent(inout) :: self
    type(grid_t), intent(inout) :: grid
  end subroutine serial_restrict

  integer function serial_owner(self, x)
    class(mpm_serial_t), intent(in) :: self
    real(dp), intent(in) :: x
    serial_owner = 0
  end function serial_owner

  subroutine serial_hand_off(self, parts, extra, err, moved)
    class(mpm_serial_t), intent(inout) :: self
    type(particles_t), intent(inout) :: parts
    real(dp), allocatable, intent(inout) :: extra(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out) :: moved
    moved = 0
  end subroutine serial_hand_off

  subroutine serial_sync(self, err)
    class(mpm_serial_t), intent(inout) :: self
    type(error_t), allocatable, intent(inout) :: err
  end subroutine serial_sync

  subroutine serial_gather_root(self, mine, all, counts)
    class(mpm_serial_t), intent(inout) :: self
    real(dp), intent(in) :: mine(:)
    real(dp), allocatable, intent(out) :: all(:)
    integer, allocatable, intent(out) :: counts(:)
    all = mine
    counts = [size(mine)]
  end subroutine serial_gather_root

  !> A particle whose support nodes lie outside the grid (the whole grid
  !> is the patch): an error naming the first of them.
  subroutine serial_check(self, parts, grid, err)
    class(mpm_serial_t), intent(inout) :: self
    type(particles_t), intent(in) :: parts
    type(grid_t), intent(in) :: grid
    type(error_t), allocatable, intent(out) :: err
    call check_patch_support(parts, grid, 0, 0, err)
  end subroutine serial_check

  subroutine serial_sum_grid(self, grid, momentum_only)
    class(mpm_serial_t), intent(inout) :: self
    type(grid_t), intent(inout) :: grid
    logical, intent(in) :: momentum_only
  end subroutine serial_sum_grid

  subroutine serial_sum_reals(self, x)
    class(mpm_serial_t), intent(in) :: self
    real(dp), intent(inout) :: x(:)
  end subroutine serial_sum_reals

  integer function serial_rank(self)
    class(mpm_serial_t), intent(in) :: self
    serial_rank = 0
  end function serial_rank

  integer function serial_nranks(self)
    class(mpm_serial_t), intent(in) :: self
    serial_nranks = 1
  end function serial_nranks

  integer function serial_ghost(self)
    class(mpm_serial_t), intent(in) :: self
    serial_ghost = 0
  end function serial_ghost

  integer function serial_handle(self)
    class(mpm_serial_t), intent(in) :: self
    serial_handle = -1
  end function serial_handle

  subroutine serial_nodes(self, values)
    class(mpm_serial_t), intent(inout) :: self
    real(dp), intent(inout) :: values(:)
  end subroutine serial_nodes

  subroutine serial_max(self, x)
    class(mpm_serial_t), intent(inout) :: self
    real(dp), intent(inout) :: x
  end subroutine serial_max

  subroutine serial_sum_int(self, i)
    class(mpm_serial_t), intent(inout) :: self
    integer, intent(inout) :: i
  end subroutine serial_sum_int

  logical function serial_any(self, flag)
    class(mpm_serial_t), intent(inout) :: self
    logical, intent(in) :: flag
    serial_any = flag
  end function serial_any

  subroutine serial_gather(self, mine, all)
    class(mpm_serial_t), intent(inout) :: self
    real(dp), intent(in) :: mine(:)
    real(dp), allocatable, intent(out) :: all(:)
    all = mine
  end subroutine serial_gather

end module wellposed_mpm_exchange
