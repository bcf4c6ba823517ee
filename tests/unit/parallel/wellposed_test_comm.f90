!> The comm_t of the communicator an MPI unit test receives
!> (this%getMpiCommunicator()), whichever Fortran binding the test
!> framework was built with: an integer handle of `use mpi` (pFUnit's
!> default and pfunit_lite) or a type(MPI_Comm) of `use mpi_f08`.
module wellposed_test_comm
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size
  use wellposed_mpi, only: comm_t
  implicit none
  private
  public :: test_comm

  interface test_comm
    module procedure comm_of_handle, comm_of_f08
  end interface test_comm

contains

  function comm_of_handle(handle) result(comm)
    integer, intent(in) :: handle
    type(comm_t) :: comm
    type(MPI_Comm) :: f08
    f08%MPI_VAL = handle
    comm = comm_of_f08(f08)
  end function comm_of_handle

  function comm_of_f08(handle) result(comm)
    type(MPI_Comm), intent(in) :: handle
    type(comm_t) :: comm
    comm%handle = handle
    call MPI_Comm_rank(handle, comm%rank)
    call MPI_Comm_size(handle, comm%size)
  end function comm_of_f08

end module wellposed_test_comm
