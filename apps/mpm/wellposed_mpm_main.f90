!> wellposed-mpm: the explicit material point method of section 4.3 for
!> every MPM deck, the 1D bars of chapter 2 and the plane-strain plates of
!> chapter 4; the deck's &scene kind picks the scene (its entry of
!> wellposed_mpm_kind_table), the command line is wellposed_mpm_cli's.
!> Without DECK: inputs/sandler_rubin_default.nml.
!> Results go to ROOT/NAME/ (renamed from ROOT/NAME.partial when done);
!> errors to standard error, exit status 1. `wellposed-mpm2d` is an alias.
!> Usage: docs/guide/mpm.md.
program wellposed_mpm
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop
  use wellposed_mpm_cli, only: mpm_cli_t, read_mpm_cli, write_mpm_usage
  use wellposed_mpm_scene_kind, only: deck_scene_kind
  use wellposed_mpm_kind_table, only: mpm_kind_entry_t, scene_kinds
  use wellposed_mpm_paths, only: find_data, default_deck_name
  use wellposed_batch_run, only: run_batch, default_figures
  use wellposed_fs, only: shell_quote
  use wellposed_checked_io, only: say_error
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: set_run_label
  use wellposed_mpm_memory, only: resident_start
  use wellposed_memory, only: check_memory, parse_memory
  implicit none

  type(comm_t) :: comm
  type(mpm_cli_t) :: cli
  type(error_t), allocatable :: err
  integer :: kind, i
  type(mpm_kind_entry_t), allocatable :: kinds(:)
  type(mpm_kind_entry_t) :: entry

  call comm_start(comm, err)
  if (allocated(err)) call die(err%message)
  call read_mpm_cli(cli, err)
  if (allocated(err)) call die(err%message)
  kinds = scene_kinds()
  cli%kinds = [(kinds(i)%words(), i = 1, size(kinds))]
  if (cli%help) then
    if (comm%rank == 0) call write_mpm_usage(default_deck_name, cli%kinds)
    call comm_stop(comm)
    stop
  end if
  if (len(cli%batch_file) > 0) call batch()
  if (len(cli%deck_path) == 0) cli%deck_path = find_data(default_deck_name)
  call set_run_label('wellposed-mpm', cli%deck_path)
  call deck_scene_kind(cli%deck_path, cli%overrides, cli%kinds, kind, err)
  if (allocated(err)) call die(err%message)
  entry = kinds(kind)
  call memory_check()
  if (cli%check) then
    call entry%verify(cli, err)
    if (allocated(err)) call die(err%message)
    if (comm%rank == 0) write (output_unit, '(a)') cli%deck_path//': read and checked '// &
      '(--check: nothing run)'
    call comm_stop(comm)
    stop
  end if
  call resident_start()
  call entry%run(cli, comm)
  call comm_stop(comm)

contains

  !> --batch FILE: every deck of FILE (bars and plates alike) through this
  !> program, one process each, shared over the ranks of an mpirun
  !> (wellposed_batch_run); exit status 1 when any failed.
  subroutine batch()
    character(len=4096) :: self
    character(len=:), allocatable :: command
    integer :: nfailed
    call get_command_argument(0, self)
    command = shell_quote(trim(self))
    if (cli%no_plot) command = command//' --no-plot'
    call run_batch(comm, cli%batch_file, command, cli%out_root, &
                   default_figures('wellposed-mpm'), nfailed, err)
    call comm_stop(comm)
    if (allocated(err)) then
      if (comm%rank == 0) call say_error('wellposed-mpm: error: '//err%message)
      stop 1, quiet=.true.
    end if
    if (nfailed > 0) stop 1, quiet=.true.
    stop
  end subroutine batch

  !> Refuse, before anything is allocated, a deck whose estimated memory
  !> exceeds --max-memory or the machine's available memory (every rank
  !> reads the same deck and meets the same verdict).
  subroutine memory_check()
    real(dp) :: bytes, nparticles, limit
    limit = 0.0_dp
    if (len(cli%max_memory) > 0) then
      call parse_memory(cli%max_memory, limit, err)
      if (allocated(err)) call die(err%message)
    end if
    call entry%memory(cli, bytes, nparticles, err)
    if (allocated(err)) call die(err%message)
    call check_memory(cli%deck_path, bytes, nparticles, 'particles', limit, err)
    if (allocated(err)) call die(err%message)
  end subroutine memory_check

  !> Stop every rank with `text`, said by rank 0 (every rank meets the same
  !> error before the run starts).
  subroutine die(text)
    character(len=*), intent(in) :: text
    if (comm%rank == 0) call say_error('wellposed-mpm: error: '//text)
    call comm_stop(comm)
    stop 1, quiet=.true.
  end subroutine die

end program wellposed_mpm
