!> wellposed_mpi for a build without MPI (WELLPOSED_WITH_MPI=OFF): the same
!> module name and interface as wellposed_mpi.f90, for exactly one rank.
!> Reductions and broadcasts leave their data as it is, exchanges copy the
!> block a rank sends to itself, gathers copy. CMake compiles one of the two.
module wellposed_mpi
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  implicit none
  private
  public :: comm_t, comm_start, comm_stop, comm_abort, comm_self, mpi_available
  public :: barrier, allreduce_sum, allreduce_min, allreduce_max, allreduce_any, &
            broadcast, alltoall_counts, alltoallv_real, gatherv_real, gatherv_int, &
            sendrecv_real, exscan_sum, alltoallv_int, legacy_handles

  !> False: this build has no MPI.
  logical, parameter :: mpi_available = .false.

  !> One rank.
  type :: comm_t
    integer :: rank = 0
    integer :: size = 1
    logical :: started = .false.
  end type comm_t

  interface allreduce_sum
    module procedure keep_r0, keep_r1, keep_i0, keep_i1
  end interface allreduce_sum
  interface allreduce_min
    module procedure keep_r0, keep_i0
  end interface allreduce_min
  interface allreduce_max
    module procedure keep_r0, keep_i0
  end interface allreduce_max
  interface broadcast
    module procedure bkeep_r1, bkeep_i1, bkeep_i0, bkeep_l0, bkeep_text
  end interface broadcast

contains

  subroutine comm_start(comm, err)
    type(comm_t), intent(out) :: comm
    type(error_t), allocatable, intent(out) :: err
    comm%rank = 0
    comm%size = 1
    if (.false.) allocate (err)
  end subroutine comm_start

  function comm_self() result(comm)
    type(comm_t) :: comm
    comm%rank = 0
    comm%size = 1
  end function comm_self

  subroutine comm_stop(comm)
    type(comm_t), intent(inout) :: comm
    comm%started = .false.
  end subroutine comm_stop

  subroutine comm_abort(comm, code)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: code
    if (comm%size == 1) error stop code
  end subroutine comm_abort

  subroutine barrier(comm)
    type(comm_t), intent(in) :: comm
    if (comm%size /= 1) error stop 'wellposed_mpi_serial: one rank only'
  end subroutine barrier

  subroutine keep_r0(comm, x)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x
    if (comm%size /= 1) x = x
  end subroutine keep_r0

  subroutine keep_r1(comm, x)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x(:)
    if (comm%size /= 1) x = x
  end subroutine keep_r1

  subroutine keep_i0(comm, x)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x
    if (comm%size /= 1) x = x
  end subroutine keep_i0

  subroutine keep_i1(comm, x)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x(:)
    if (comm%size /= 1) x = x
  end subroutine keep_i1

  logical function allreduce_any(comm, flag) result(any_flag)
    type(comm_t), intent(in) :: comm
    logical, intent(in) :: flag
    any_flag = flag .and. comm%size == 1
  end function allreduce_any

  subroutine bkeep_r1(comm, x, root)
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: x(:)
    integer, intent(in) :: root
    if (comm%size /= 1 .or. root /= 0) x = x
  end subroutine bkeep_r1

  subroutine bkeep_i1(comm, x, root)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x(:)
    integer, intent(in) :: root
    if (comm%size /= 1 .or. root /= 0) x = x
  end subroutine bkeep_i1

  subroutine bkeep_i0(comm, x, root)
    type(comm_t), intent(in) :: comm
    integer, intent(inout) :: x
    integer, intent(in) :: root
    if (comm%size /= 1 .or. root /= 0) x = x
  end subroutine bkeep_i0

  subroutine bkeep_l0(comm, x, root)
    type(comm_t), intent(in) :: comm
    logical, intent(inout) :: x
    integer, intent(in) :: root
    if (comm%size /= 1 .or. root /= 0) x = x
  end subroutine bkeep_l0

  subroutine alltoall_counts(comm, send, recv)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: send(0:)
    integer, intent(out) :: recv(0:)
    recv(0:comm%size - 1) = send(0:comm%size - 1)
  end subroutine alltoall_counts

  subroutine alltoallv_real(comm, send, scount, sdispl, recv, rcount, rdispl)
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: send(:)
    integer, intent(in) :: scount(0:), sdispl(0:), rcount(0:), rdispl(0:)
    real(dp), intent(inout) :: recv(:)
    if (comm%size /= 1 .or. rcount(0) /= scount(0)) error stop 'alltoallv_real: counts'
    recv(rdispl(0) + 1:rdispl(0) + rcount(0)) = send(sdispl(0) + 1:sdispl(0) + scount(0))
  end subroutine alltoallv_real

  subroutine gatherv_real(comm, mine, all, root, counts)
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: mine(:)
    real(dp), allocatable, intent(out) :: all(:)
    integer, intent(in) :: root
    integer, allocatable, intent(out), optional :: counts(:)
    if (comm%size /= 1 .or. root /= 0) error stop 'gatherv_real: one rank only'
    all = mine
    if (present(counts)) then
      allocate (counts(0:0))
      counts(0) = size(mine)
    end if
  end subroutine gatherv_real

  subroutine gatherv_int(comm, mine, all, root, counts)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: mine(:)
    integer, allocatable, intent(out) :: all(:)
    integer, intent(in) :: root
    integer, allocatable, intent(out), optional :: counts(:)
    if (comm%size /= 1 .or. root /= 0) error stop 'gatherv_int: one rank only'
    all = mine
    if (present(counts)) then
      allocate (counts(0:0))
      counts(0) = size(mine)
    end if
  end subroutine gatherv_int

  subroutine sendrecv_real(comm, send, dest, recv, source, tag)
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: send(:)
    integer, intent(in) :: dest, source, tag
    real(dp), intent(inout) :: recv(:)
    if (comm%size /= 1 .or. dest /= 0 .or. source /= 0 .or. tag < 0) &
      error stop 'sendrecv_real: one rank only'
    recv(1:size(send)) = send
  end subroutine sendrecv_real

  !> Nothing below rank 0.
  integer function exscan_sum(comm, x) result(below)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: x
    below = 0
    if (comm%size /= 1) below = x
  end function exscan_sum

  subroutine bkeep_text(comm, text, root)
    type(comm_t), intent(in) :: comm
    character(len=:), allocatable, intent(inout) :: text
    integer, intent(in) :: root
    if (comm%size /= 1 .or. root /= 0) text = text
  end subroutine bkeep_text

  subroutine alltoallv_int(comm, send, scount, sdispl, recv, rcount, rdispl)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: send(:)
    integer, intent(in) :: scount(0:), sdispl(0:), rcount(0:), rdispl(0:)
    integer, intent(inout) :: recv(:)
    if (comm%size /= 1 .or. rcount(0) /= scount(0)) error stop 'alltoallv_int: counts'
    recv(rdispl(0) + 1:rdispl(0) + rcount(0)) = send(sdispl(0) + 1:sdispl(0) + scount(0))
  end subroutine alltoallv_int

  !> No MPI: both handles are 0.
  subroutine legacy_handles(comm, comm_f, info_f)
    type(comm_t), intent(in) :: comm
    integer, intent(out) :: comm_f, info_f
    comm_f = 0
    info_f = 0
    if (comm%size /= 1) comm_f = -1
  end subroutine legacy_handles

end module wellposed_mpi
