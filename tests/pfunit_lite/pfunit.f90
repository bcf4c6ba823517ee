!> pfunit_lite's module `pfunit` (the name pFUnit 4 MPI test files `use`):
!> everything of `funit`, the type MpiTestMethod that an MPI test receives,
!> and what the generated driver calls. As in pFUnit 4.14 (MpiTestCase,
!> MpiContext::makeSubcontext), a test of `npes` processes runs on ranks
!> 0 .. npes-1 of MPI_COMM_WORLD over a communicator of their own (the
!> other ranks wait), and fails when an assertion failed on any rank.
!> Communicators are the integer handles of `use mpi`, pFUnit's default
!> build (ENABLE_MPI_F08 off).
module pfunit
  use funit
  use mpi, only: MPI_COMM_WORLD, MPI_COMM_NULL, MPI_UNDEFINED, MPI_LOGICAL, MPI_LOR, &
                 MPI_Initialized, MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_Comm_size, &
                 MPI_Comm_split, MPI_Comm_free, MPI_Allreduce
  implicit none
  private :: MPI_COMM_WORLD, MPI_COMM_NULL, MPI_UNDEFINED, MPI_LOGICAL, MPI_LOR, &
             MPI_Initialized, MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_Comm_size, &
             MPI_Comm_split, MPI_Comm_free, MPI_Allreduce
  private :: rank_of, size_of, comm_of, mpi_method
  public :: MpiTestMethod, pfunit_start, pfunit_run_test, pfunit_stop

  !> What an MPI test sees: its communicator, its rank there, their number.
  type :: MpiTestMethod
    private
    integer :: comm = MPI_COMM_NULL
    integer :: rank = 0
    integer :: npes = 1
  contains
    procedure :: getProcessRank => rank_of
    procedure :: getNumProcesses => size_of
    procedure :: getMpiCommunicator => comm_of
  end type MpiTestMethod

  abstract interface
    subroutine mpi_method(this)
      import :: MpiTestMethod
      class(MpiTestMethod), intent(inout) :: this
    end subroutine mpi_method
  end interface

contains

  integer function rank_of(this)
    class(MpiTestMethod), intent(in) :: this
    rank_of = this%rank
  end function rank_of

  integer function size_of(this)
    class(MpiTestMethod), intent(in) :: this
    size_of = this%npes
  end function size_of

  integer function comm_of(this)
    class(MpiTestMethod), intent(in) :: this
    comm_of = this%comm
  end function comm_of

  !> Start MPI; only rank 0 prints the per-test lines and the summary.
  subroutine pfunit_start()
    logical :: started
    integer :: rank, ierr
    call MPI_Initialized(started, ierr)
    if (.not. started) call MPI_Init(ierr)
    call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
    call funit_reporting(rank == 0)
  end subroutine pfunit_start

  subroutine pfunit_stop()
    integer :: ierr
    call MPI_Finalize(ierr)
  end subroutine pfunit_stop

  !> Run `method` on ranks 0 .. npes-1 (collective over MPI_COMM_WORLD).
  !> More processes than the run has fail the test, as in pFUnit.
  subroutine pfunit_run_test(name, method, npes)
    character(len=*), intent(in) :: name
    procedure(mpi_method) :: method
    integer, intent(in) :: npes
    type(MpiTestMethod) :: this
    integer :: world_rank, world_size, ierr
    logical :: failed_anywhere
    character(len=80) :: where
    call MPI_Comm_rank(MPI_COMM_WORLD, world_rank, ierr)
    call MPI_Comm_size(MPI_COMM_WORLD, world_size, ierr)
    write (where, '(a,i0,a,i0)') ' on rank ', world_rank, ' of ', npes
    call funit_begin_test(name, trim(where))
    if (npes > world_size) then
      write (where, '(i0,a,i0,a)') npes, ' wanted, ', world_size, ' running'
      if (world_rank == 0) call funit_fail_test('Insufficient processes to run this test: '// &
                                                trim(where))
    else
      call MPI_Comm_split(MPI_COMM_WORLD, merge(0, MPI_UNDEFINED, world_rank < npes), &
                          world_rank, this%comm, ierr)
      if (world_rank < npes) then
        this%rank = world_rank
        this%npes = npes
        call method(this)
        call MPI_Comm_free(this%comm, ierr)
      end if
    end if
    call MPI_Allreduce(anyExceptions(), failed_anywhere, 1, MPI_LOGICAL, MPI_LOR, &
                       MPI_COMM_WORLD, ierr)
    call funit_end_test(failed_anywhere)
  end subroutine pfunit_run_test

end module pfunit
