!> wellposed-batch: run a batch file of decks through a driver, the jobs
!> shared over the ranks of an MPI run (wellposed_batch_run):
!>   [mpirun -np N] wellposed-batch [--out ROOT] [--figures K1,K2,...]
!>                                  DRIVER BATCHFILE [DRIVER_OPTION ...]
!> Writes ROOT/<batch name>/batch_summary.txt and .csv. Exit status 0 when
!> every job succeeded, 1 when any failed or the batch's own files could not
!> be written, 2 when the batch could not run.
!> Details: docs/guide/parallel.md.
program wellposed_batch_main
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop
  use wellposed_batch_run, only: run_batch, default_figures
  use wellposed_fs, only: shell_quote
  use wellposed_checked_io, only: say_error
  implicit none

  type(comm_t) :: comm
  type(error_t), allocatable :: err
  character(len=:), allocatable :: out_root, driver, batch_file, command, arg, figure_list
  character(len=64), allocatable :: figures(:)
  integer :: i, nargs, nfailed, k

  call comm_start(comm, err)
  if (allocated(err)) then
    call say_error('wellposed-batch: error: '//err%message)
    stop 2, quiet=.true.
  end if
  out_root = 'out'
  driver = ''
  batch_file = ''
  command = ''
  figure_list = ''
  nargs = command_argument_count()
  i = 0
  do while (i < nargs)
    i = i + 1
    arg = get_arg(i)
    if (len(batch_file) > 0) then          ! options for every job
      command = command//' '//shell_quote(arg)
      cycle
    end if
    select case (arg)
    case ('-h', '--help')
      if (comm%rank == 0) call usage()
      call comm_stop(comm)
      stop
    case ('--out')
      i = i + 1
      out_root = get_arg(i)
    case ('--figures')
      i = i + 1
      figure_list = get_arg(i)
    case default
      if (len(arg) == 0) call die('an empty argument where DRIVER or BATCHFILE was expected')
      if (arg(1:1) == '-') call die('unknown option "'//arg//'" (see --help)')
      if (len(driver) == 0) then
        driver = arg
      else
        batch_file = arg
      end if
    end select
  end do
  if (len(batch_file) == 0) call die('need DRIVER and BATCHFILE (see --help)')
  if (len(figure_list) > 0) then
    allocate (figures(0))
    do while (len(figure_list) > 0)
      k = index(figure_list, ',')
      if (k == 0) k = len(figure_list) + 1
      if (k > 1) figures = [character(len=64) :: figures, figure_list(1:k - 1)]
      figure_list = figure_list(min(k + 1, len(figure_list) + 1):)
    end do
  else
    figures = default_figures(driver)
  end if
  command = shell_quote(driver)//command
  call run_batch(comm, batch_file, command, out_root, figures, nfailed, err)
  if (allocated(err)) call die(err%message, exit_code_of(err%message))
  call comm_stop(comm)
  if (nfailed > 0) stop 1, quiet=.true.

contains

  !> End every rank with exit status `code` (default 2: the batch could not
  !> run) and `text`, said by rank 0: the program's own line, no backtrace.
  subroutine die(text, code)
    character(len=*), intent(in) :: text
    integer, intent(in), optional :: code
    if (comm%rank == 0) call say_error('wellposed-batch: error: '//text)
    call comm_stop(comm)
    if (present(code)) then
      if (code == 1) stop 1, quiet=.true.
    end if
    stop 2, quiet=.true.
  end subroutine die

  !> 1 for a failed write of the batch's own files (wellposed_checked_io's
  !> "cannot write"), else 2.
  integer function exit_code_of(text) result(code)
    character(len=*), intent(in) :: text
    code = merge(1, 2, index(text, 'cannot write "') == 1)
  end function exit_code_of

  function get_arg(k) result(a)
    integer, intent(in) :: k
    character(len=:), allocatable :: a
    integer :: n
    if (k > nargs) call die('an option needs a value')
    call get_command_argument(k, length=n)
    allocate (character(len=n) :: a)
    call get_command_argument(k, a)
  end function get_arg

  subroutine usage()
    write (output_unit, '(a)') 'usage: [mpirun -np N] wellposed-batch [--out ROOT] '// &
      '[--figures K1,K2,...] DRIVER BATCHFILE [DRIVER_OPTION ...]', &
      '  BATCHFILE: one deck per line (then optional arguments for that job); # and ! '// &
      'start comments', &
      '  writes ROOT/<batch name>/batch_summary.txt and .csv (ROOT = out); exit 1 when '// &
      'any job failed'
  end subroutine usage

end program wellposed_batch_main
