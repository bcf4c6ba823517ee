!> The one module that talks to MPI (mpi_f08). Drivers see a `comm_t`
!> (communicator, rank, size) and a handful of collective and
!> point-to-point calls on real(dp) and default-integer data; nothing else
!> in wellposed names an MPI routine, so a run on one rank is the serial
!> program and the physics never branches on "parallel or not".
!> Every routine here is collective over `comm` unless it says otherwise.
!> A build without MPI (WELLPOSED_WITH_MPI=OFF) compiles
!> wellposed_mpi_serial.f90 instead: the same module for one rank.
module wellposed_mpi
  use mpi_f08
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  implicit none
  private
  public :: comm_t, comm_start, comm_stop, comm_abort, comm_self, mpi_available
  public :: barrier, allreduce_sum, allreduce_min, allreduce_max, allreduce_any, &
            broadcast, alltoall_counts, alltoallv_real, gatherv_real, gatherv_int, &
            sendrecv_real, exscan_sum, alltoallv_int, legacy_handles

  !> True in the MPI build (false in wellposed_mpi_serial).
  logical, parameter :: mpi_available = .true.

  !> A communicator and this process's place in it.
  type :: comm_t
    type(MPI_Comm) :: handle = MPI_COMM_NULL
    integer :: rank = 0     !< 0-based rank of this process
    integer :: size = 1     !< number of ranks
    logical :: started = .false.  !< this comm_t initialised MPI (and finalizes it)
  end type comm_t

  !> Sum over all ranks, in place (every rank gets the result).
  interface allreduce_sum
    module procedure sum_r0, sum_r1, sum_i0, sum_i1
  end interface allreduce_sum
  !> Minimum / maximum over all ranks, in place.
  interface allreduce_min
    module procedure min_r0, min_i0
  end interface allreduce_min
  interface allreduce_max
    module procedure max_r0, max_i0
  end interface allreduce_max
  !> Broadcast from `root` to every rank, in place.
  interface broadcast
    module procedure bcast_r1, bcast_i1, bcast_i0, bcast_l0, bcast_text
  end interface broadcast

contains

  !> Initialise MPI (unless the host already did) and describe
  !> MPI_COMM_WORLD. Under a plain `./program` this is a singleton run:
  !> rank 0 of 1.
  subroutine comm_start(comm, err)
    type(comm_t), intent(out) :: comm
    type(error_t), allocatable, intent(out) :: err
    logical :: done
    integer :: ierr
    call MPI_Initialized(done, ierr)
    if (.not. done) then
      call MPI_Init(ierr)
      if (ierr /= MPI_SUCCESS) then
        call new_error(err, status_invalid, 'mpi', 'MPI_Init failed (error '// &
          int_text(ierr)//')')
        return
      end if
      comm%started = .true.
    end if
    comm%handle = MPI_COMM_WORLD
    call MPI_Comm_rank(comm%handle, comm%rank)
    call MPI_Comm_size(comm%handle, comm%size)
  end subroutine comm_start

  !> This process alone (MPI_COMM_SELF): rank 0 of 1, for work one rank
  !> does by itself inside a parallel run (after comm_start).
  function comm_self() result(comm)
    type(comm_t) :: comm
    comm%handle = MPI_COMM_SELF
    comm%rank = 0
    comm%size = 1
  end function comm_self

  !> Finalize MPI if `comm_start` initialised it.
  subroutine comm_stop(comm)
    type(comm_t), intent(inout) :: comm
    logical :: done
    if (.not. comm%started) return
    call MPI_Finalized(done)
    if (.not. done) call MPI_Finalize()
    comm%started = .false.
  end subroutine comm_stop

  !> End every rank of the job with exit status `code` (not collective: for
  !> an error found by one rank only; a collective error path should let
  !> every rank return and stop on its own).
  subroutine comm_abort(comm, code)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: code
    call MPI_Abort(comm%handle, code)
  end subroutine comm_abort

  subroutine barrier(comm)
    type(comm_t), intent(in) :: comm
    call MPI_Barrier(comm%handle)
  end subroutine barrier

  subroutine sum_r0(comm, x)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x
    real(dp) :: y(1)
    call MPI_Allreduce([x], y, 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm%handle)
    x = y(1)
  end subroutine sum_r0

  subroutine sum_r1(comm, x)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, comm%handle)
  end subroutine sum_r1

  subroutine sum_i0(comm, x)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x
    integer :: y(1)
    call MPI_Allreduce([x], y, 1, MPI_INTEGER, MPI_SUM, comm%handle)
    x = y(1)
  end subroutine sum_i0

  subroutine sum_i1(comm, x)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_INTEGER, MPI_SUM, comm%handle)
  end subroutine sum_i1

  subroutine min_r0(comm, x)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x
    real(dp) :: y(1)
    call MPI_Allreduce([x], y, 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm%handle)
    x = y(1)
  end subroutine min_r0

  subroutine min_i0(comm, x)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x
    integer :: y(1)
    call MPI_Allreduce([x], y, 1, MPI_INTEGER, MPI_MIN, comm%handle)
    x = y(1)
  end subroutine min_i0

  subroutine max_r0(comm, x)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x
    real(dp) :: y(1)
    call MPI_Allreduce([x], y, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm%handle)
    x = y(1)
  end subroutine max_r0

  subroutine max_i0(comm, x)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x
    integer :: y(1)
    call MPI_Allreduce([x], y, 1, MPI_INTEGER, MPI_MAX, comm%handle)
    x = y(1)
  end subroutine max_i0

  !> True on every rank when `flag` is true on any rank.
  logical function allreduce_any(comm, flag) result(any_flag)
    type(comm_t), intent(in) :: comm
    logical, intent(in) :: flag
    logical :: y(1)
    call MPI_Allreduce([flag], y, 1, MPI_LOGICAL, MPI_LOR, comm%handle)
    any_flag = y(1)
  end function allreduce_any

  subroutine bcast_r1(comm, x, root)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x(:)
    integer, intent(in) :: root
    call MPI_Bcast(x, size(x), MPI_DOUBLE_PRECISION, root, comm%handle)
  end subroutine bcast_r1

  subroutine bcast_i1(comm, x, root)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x(:)
    integer, intent(in) :: root
    call MPI_Bcast(x, size(x), MPI_INTEGER, root, comm%handle)
  end subroutine bcast_i1

  subroutine bcast_i0(comm, x, root)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x
    integer, intent(in) :: root
    call MPI_Bcast(x, 1, MPI_INTEGER, root, comm%handle)
  end subroutine bcast_i0

  subroutine bcast_l0(comm, x, root)
    type(comm_t), intent(in) :: comm
    logical, intent(inout) :: x
    integer, intent(in) :: root
    call MPI_Bcast(x, 1, MPI_LOGICAL, root, comm%handle)
  end subroutine bcast_l0

  !> recv(q) = what rank q put in its send(me), for q = 0 .. size-1
  !> (arrays indexed 0:size-1).
  subroutine alltoall_counts(comm, send, recv)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: send(0:)
    integer, intent(out) :: recv(0:)
    call MPI_Alltoall(send, 1, MPI_INTEGER, recv, 1, MPI_INTEGER, comm%handle)
  end subroutine alltoall_counts

  !> Personalised all-to-all of reals: the block of `send` for rank q starts
  !> at sdispl(q) (0-based) and has scount(q) values; what q sends here lands
  !> at rdispl(q) with rcount(q) values.
  subroutine alltoallv_real(comm, send, scount, sdispl, recv, rcount, rdispl)
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: send(:)
    integer, intent(in) :: scount(0:), sdispl(0:), rcount(0:), rdispl(0:)
    real(dp), intent(inout) :: recv(:)
    call MPI_Alltoallv(send, scount, sdispl, MPI_DOUBLE_PRECISION, recv, rcount, rdispl, &
                       MPI_DOUBLE_PRECISION, comm%handle)
  end subroutine alltoallv_real

  !> Concatenate every rank's `mine` on `root`, in rank order, into `all`
  !> (allocated on every rank; sized to the total on root, empty elsewhere).
  !> `counts`, allocated (0:size-1), receives every rank's length on root.
  subroutine gatherv_real(comm, mine, all, root, counts)
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: mine(:)
    real(dp), allocatable, intent(out) :: all(:)
    integer, intent(in) :: root
    integer, allocatable, intent(out), optional :: counts(:)
    integer :: n(0:comm%size - 1), displ(0:comm%size - 1), q
    call MPI_Gather([size(mine)], 1, MPI_INTEGER, n, 1, MPI_INTEGER, root, comm%handle)
    if (comm%rank == root) then
      displ(0) = 0
      do q = 1, comm%size - 1
        displ(q) = displ(q - 1) + n(q - 1)
      end do
      allocate (all(sum(n)))
    else
      allocate (all(0))
    end if
    call MPI_Gatherv(mine, size(mine), MPI_DOUBLE_PRECISION, all, n, displ, &
                     MPI_DOUBLE_PRECISION, root, comm%handle)
    if (present(counts)) counts = n
  end subroutine gatherv_real

  !> `gatherv_real` for default integers.
  subroutine gatherv_int(comm, mine, all, root, counts)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: mine(:)
    integer, allocatable, intent(out) :: all(:)
    integer, intent(in) :: root
    integer, allocatable, intent(out), optional :: counts(:)
    integer :: n(0:comm%size - 1), displ(0:comm%size - 1), q
    call MPI_Gather([size(mine)], 1, MPI_INTEGER, n, 1, MPI_INTEGER, root, comm%handle)
    if (comm%rank == root) then
      displ(0) = 0
      do q = 1, comm%size - 1
        displ(q) = displ(q - 1) + n(q - 1)
      end do
      allocate (all(sum(n)))
    else
      allocate (all(0))
    end if
    call MPI_Gatherv(mine, size(mine), MPI_INTEGER, all, n, displ, MPI_INTEGER, root, &
                     comm%handle)
    if (present(counts)) counts = n
  end subroutine gatherv_int

  !> Send `send` to rank `dest` and receive `recv` from rank `source`
  !> (point-to-point, deadlock-free in a ring or a pairwise exchange).
  subroutine sendrecv_real(comm, send, dest, recv, source, tag)
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: send(:)
    integer, intent(in) :: dest, source, tag
    real(dp), intent(inout) :: recv(:)
    call MPI_Sendrecv(send, size(send), MPI_DOUBLE_PRECISION, dest, tag, recv, size(recv), &
                      MPI_DOUBLE_PRECISION, source, tag, comm%handle, MPI_STATUS_IGNORE)
  end subroutine sendrecv_real

  !> Exclusive prefix sum: the sum of `x` over the ranks below this one
  !> (0 on rank 0), e.g. the first row of this rank's block in a file.
  integer function exscan_sum(comm, x) result(below)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: x
    integer :: y(1)
    y = 0
    call MPI_Exscan([x], y, 1, MPI_INTEGER, MPI_SUM, comm%handle)
    below = 0
    if (comm%rank > 0) below = y(1)   ! MPI leaves rank 0's result undefined
  end function exscan_sum

  !> Broadcast a text of any length from `root` (reallocated elsewhere).
  subroutine bcast_text(comm, text, root)
    type(comm_t), intent(in) :: comm
    character(len=:), allocatable, intent(inout) :: text
    integer, intent(in) :: root
    integer :: n(1)
    n = 0
    if (comm%rank == root) n = len(text)
    call MPI_Bcast(n, 1, MPI_INTEGER, root, comm%handle)
    if (comm%rank /= root) then
      if (allocated(text)) deallocate (text)
      allocate (character(len=n(1)) :: text)
    end if
    if (n(1) > 0) call MPI_Bcast(text, n(1), MPI_CHARACTER, root, comm%handle)
  end subroutine bcast_text

  !> `alltoallv_real` for default integers.
  subroutine alltoallv_int(comm, send, scount, sdispl, recv, rcount, rdispl)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: send(:)
    integer, intent(in) :: scount(0:), sdispl(0:), rcount(0:), rdispl(0:)
    integer, intent(inout) :: recv(:)
    call MPI_Alltoallv(send, scount, sdispl, MPI_INTEGER, recv, rcount, rdispl, &
                       MPI_INTEGER, comm%handle)
  end subroutine alltoallv_int

  !> The communicator and MPI_INFO_NULL as integer handles of the older
  !> Fortran binding (`use mpi`), for libraries that take those (HDF5's
  !> h5pset_fapl_mpio_f). Not collective.
  subroutine legacy_handles(comm, comm_f, info_f)
    type(comm_t), intent(in) :: comm
    integer, intent(out) :: comm_f, info_f
    comm_f = comm%handle%MPI_VAL
    info_f = MPI_INFO_NULL%MPI_VAL
  end subroutine legacy_handles

end module wellposed_mpi
