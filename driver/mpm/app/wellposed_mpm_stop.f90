!> Ending wellposed-mpm on an error only this rank knows of (rank 0's
!> files): the message, where the partial output is, and every other rank of
!> the job aborted (they would otherwise wait for this one). For every scene
!> kind.
module wellposed_mpm_stop
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_mpi, only: comm_t, comm_abort
  use wellposed_run_dir, only: run_dir_t
  implicit none
  private
  public :: stop_alone

contains

  subroutine stop_alone(comm, rd, message)
    type(comm_t), intent(in) :: comm
    type(run_dir_t), intent(in) :: rd
    character(len=*), intent(in) :: message
    write (error_unit, '(a)') 'wellposed-mpm: error: '//message
    if (allocated(rd%partial)) write (error_unit, '(a)') 'wellposed-mpm: the run did not '// &
      'finish; its partial output is in '//rd%partial
    if (comm%size > 1) call comm_abort(comm, 1)
    stop 1, quiet=.true.
  end subroutine stop_alone

end module wellposed_mpm_stop
