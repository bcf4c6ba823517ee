!> The files of a wellposed-mpm run, for every scene kind: rank 0 makes
!> the run folder ROOT/NAME(.partial) (wellposed_run_dir), and every rank
!> opens run.h5 in it (collective); a failure ends the run
!> (wellposed_mpm_stop).
module wellposed_mpm_run_files
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, broadcast
  use wellposed_run_dir, only: run_dir_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_stop, only: stop_alone, stop_all
  implicit none
  private
  public :: open_run_files

contains

  !> The run folder `rd` of run `name` under `out_root` for deck
  !> `deck_path` (rank 0), and run.h5 in it as `h5` (every rank).
  subroutine open_run_files(rd, h5, comm, out_root, name, deck_path)
    type(run_dir_t), intent(inout) :: rd
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(inout) :: comm
    character(len=*), intent(in) :: out_root, name, deck_path
    type(error_t), allocatable :: err
    character(len=:), allocatable :: h5_path
    h5_path = ''
    if (comm%rank == 0) then
      call rd%create(out_root, name, deck_path, err)
      if (allocated(err)) call stop_alone(comm, rd, err)
      h5_path = rd%path('run.h5')
    end if
    call broadcast(comm, h5_path, 0)
    call h5%create(comm, h5_path, err)
    if (allocated(err)) call stop_all(comm, rd, err)
  end subroutine open_run_files

end module wellposed_mpm_run_files
