!> Runs a driver's plot script: `<python> <script> <args>` with
!> matplotlib's non-interactive Agg backend (MPLBACKEND=Agg), through
!> execute_command_line. The interpreter is the one CMake found
!> (wellposed_build_info: python_executable), where Debian's
!> python3-matplotlib and python3-h5py live.
module wellposed_plot
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_build_info, only: python_executable
  use wellposed_fs, only: shell_quote, path_exists, int_text
  use wellposed_checked_io, only: write_fault
  implicit none
  private
  public :: run_plot

contains

  !> Run `script` with the arguments `args` (already shell-quoted where
  !> needed; see wellposed_fs: shell_quote). An error names the command and
  !> its exit status when the script fails or cannot start (a PNG it could
  !> not write), or an injected failure of the PNG writes (wellposed_checked_io).
  subroutine run_plot(script, args, err)
    character(len=*), intent(in) :: script, args
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: command
    character(len=256) :: msg
    integer :: stat, cstat
    if (.not. path_exists(script)) then
      call new_error(err, status_invalid, script, 'plot script "'//script//'" not found')
      return
    end if
    command = 'MPLBACKEND=Agg '//shell_quote(python_executable)//' '// &
      shell_quote(script)//' '//args
    msg = ''
    call execute_command_line(command, wait=.true., exitstat=stat, cmdstat=cstat, cmdmsg=msg)
    if (cstat /= 0) then
      call new_error(err, status_invalid, script, 'cannot run "'//command//'": '//trim(msg))
    else if (stat /= 0) then
      call new_error(err, status_invalid, script, 'plot command failed with exit status '// &
        int_text(stat)//': '//command//' (needs python3-matplotlib and python3-h5py for '// &
        python_executable//')')
    else if (len(write_fault('plot.png')) > 0) then
      call new_error(err, status_invalid, script, 'cannot write the PNG plots: '// &
        write_fault('plot.png'))
    end if
  end subroutine run_plot

end module wellposed_plot
