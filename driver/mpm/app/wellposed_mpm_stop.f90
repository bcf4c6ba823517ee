!> Ending wellposed-mpm on an error, for every scene kind: the message,
!> where the partial output is, and every rank of the job ended. `stop_all`
!> when every rank has met the error (rank 0 says it; the ranks finalise);
!> `stop_alone` when only this rank knows of it (rank 0's files): it says
!> it and aborts the other ranks, which would otherwise wait for this one.
module wellposed_mpm_stop
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_mpi, only: comm_t, comm_abort, comm_stop
  use wellposed_run_dir, only: run_dir_t
  implicit none
  private
  public :: stop_alone, stop_all

contains

  subroutine stop_alone(comm, rd, message)
    type(comm_t), intent(in) :: comm
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    call say(rd, message)
    if (comm%size > 1) call comm_abort(comm, 1)
    stop 1, quiet=.true.
  end subroutine stop_alone

  !> Collective: every rank calls it with the same error.
  subroutine stop_all(comm, rd, message)
    type(comm_t), intent(inout) :: comm
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    if (comm%rank == 0) call say(rd, message)
    call comm_stop(comm)
    ! every rank has finalised: a plain stop, without error stop's backtrace
    stop 1, quiet=.true.
  end subroutine stop_all

  subroutine say(rd, message)
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    write (error_unit, '(a)') 'wellposed-mpm: error: '//message
    if (allocated(rd%partial)) write (error_unit, '(a)') 'wellposed-mpm: the run did not '// &
      'finish; its partial output is in '//rd%partial
  end subroutine say

end module wellposed_mpm_stop
