!> Ending wellposed-mpm on an error, for every scene kind: the message,
!> where the partial output is, and every rank of the job ended. `stop_all`
!> when every rank has met the error (rank 0 says it; the ranks finalise);
!> `stop_alone` when only this rank knows of it (rank 0's files): it says
!> it and aborts the other ranks, which would otherwise wait for this one.
!> Each takes the message as text or as an error_t.
module wellposed_mpm_stop
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_abort, comm_stop
  use wellposed_run_dir, only: run_dir_t
  use wellposed_checked_io, only: say_error
  implicit none
  private
  public :: stop_alone, stop_all

  interface stop_alone
    module procedure stop_alone_text, stop_alone_error
  end interface stop_alone

  interface stop_all
    module procedure stop_all_text, stop_all_error
  end interface stop_all

contains

  subroutine stop_alone_error(comm, rd, err)
    type(comm_t), intent(in) :: comm
    type(run_dir_t), intent(in) :: rd
    type(error_t), intent(in) :: err
    call stop_alone_text(comm, rd, err%message)
  end subroutine stop_alone_error

  subroutine stop_all_error(comm, rd, err)
    type(comm_t), intent(inout) :: comm
    type(run_dir_t), intent(in) :: rd
    type(error_t), intent(in) :: err
    call stop_all_text(comm, rd, err%message)
  end subroutine stop_all_error

  subroutine stop_alone_text(comm, rd, message)
    type(comm_t), intent(in) :: comm
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    call say(rd, message)
    if (comm%size > 1) call comm_abort(comm, 1)
    stop 1, quiet=.true.
  end subroutine stop_alone_text

  !> Collective: every rank calls it with the same error.
  subroutine stop_all_text(comm, rd, message)
    type(comm_t), intent(inout) :: comm
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    if (comm%rank == 0) call say(rd, message)
    call comm_stop(comm)
    ! every rank has finalised: a plain stop, without error stop's backtrace
    stop 1, quiet=.true.
  end subroutine stop_all_text

  subroutine say(rd, message)
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    call say_error('wellposed-mpm: error: '//message)
    if (allocated(rd%partial)) call say_error('wellposed-mpm: the run did not '// &
      'finish; its partial output is in '//rd%partial)
  end subroutine say

end module wellposed_mpm_stop
