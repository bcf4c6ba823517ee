!> The command line of wellposed-mpm, read once for every scene kind:
!>   [mpirun -np N] wellposed-mpm [--out ROOT] [--name NAME] [--no-plot] [--force] [--check]
!>       [--checkpoint-every STEPS] [--keep-checkpoints]
!>       [--restart | --restart-from FILE] [--max-memory SIZE]
!>       [DECK] [group.key=value ...]
!>   [mpirun -np N] wellposed-mpm --batch FILE [--out ROOT] [--no-plot]
!> A word with '=' overrides the deck, one starting with '-' is an option
!> (an unknown one is refused), anything else the deck. Errors as values.
module wellposed_mpm_cli
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_scene_kind, only: kind_words_t, kinds_text, marks_text
  implicit none
  private
  public :: mpm_cli_t, read_mpm_cli, write_mpm_usage

  !> What the command line asks for.
  type :: mpm_cli_t
    character(len=:), allocatable :: deck_path    !< '' when none was given
    character(len=:), allocatable :: out_root     !< ROOT (default 'out')
    character(len=:), allocatable :: run_name     !< '' unless --name
    character(len=:), allocatable :: ck_file      !< --restart-from FILE, else ''
    character(len=:), allocatable :: batch_file   !< --batch FILE, else ''
    character(len=:), allocatable :: max_memory   !< --max-memory SIZE, else ''
    character(len=512), allocatable :: overrides(:)
    !> --checkpoint-every STEPS; -1: the scene's default (a tenth of a run)
    integer :: ck_every = -1
    logical :: restart = .false.
    !> --keep-checkpoints: a finished run leaves ROOT/NAME.checkpoints
    logical :: keep_checkpoints = .false.
    logical :: no_plot = .false.
    logical :: help = .false.
    logical :: force = .false.       !< --force: run past the deck's step limit
    logical :: check = .false.       !< --check: read and check the deck, run nothing
    !> The scene kinds the program registers (set by it, not read here).
    type(kind_words_t), allocatable :: kinds(:)
  end type mpm_cli_t

contains

  !> Read the program's arguments into cli (err: the first bad one).
  subroutine read_mpm_cli(cli, err)
    type(mpm_cli_t), intent(out) :: cli
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: arg
    integer :: i, nargs
    cli%deck_path = ''
    cli%out_root = 'out'
    cli%run_name = ''
    cli%ck_file = ''
    cli%batch_file = ''
    cli%max_memory = ''
    allocate (cli%overrides(0))
    nargs = command_argument_count()
    i = 0
    do while (i < nargs)
      i = i + 1
      arg = argument(i)
      select case (arg)
      case ('-h', '--help')
        cli%help = .true.
        return
      case ('--out')
        call value_of(cli%out_root); if (allocated(err)) return
      case ('--name')
        call value_of(cli%run_name); if (allocated(err)) return
      case ('--no-plot')
        cli%no_plot = .true.
      case ('--max-memory')
        call value_of(cli%max_memory); if (allocated(err)) return
      case ('--force')
        cli%force = .true.
      case ('--check')
        cli%check = .true.
      case ('--checkpoint-every')
        call value_of(arg); if (allocated(err)) return
        if (verify(arg, '0123456789') /= 0 .or. len(arg) == 0 .or. len(arg) > 9) then
          call bad('--checkpoint-every needs a whole number of steps >= 0, not "'//arg//'"')
          return
        end if
        read (arg, *) cli%ck_every
      case ('--restart')
        cli%restart = .true.
      case ('--keep-checkpoints')
        cli%keep_checkpoints = .true.
      case ('--restart-from')
        call value_of(cli%ck_file); if (allocated(err)) return
        cli%restart = .true.
      case ('--batch')
        call value_of(cli%batch_file); if (allocated(err)) return
      case default
        if (len(arg) == 0) then
          call bad('an empty argument where a DECK or group.key=value was expected')
          return
        else if (index(arg, '=') > 0) then
          cli%overrides = [character(len=512) :: cli%overrides, arg]
        else if (arg(1:1) == '-') then
          call bad('unknown option "'//arg//'" (see --help)')
          return
        else if (len(cli%deck_path) == 0) then
          cli%deck_path = arg
        else
          call bad('unexpected argument "'//arg//'" (one DECK only; see --help)')
          return
        end if
      end select
    end do
    if (len(cli%batch_file) > 0 .and. (len(cli%deck_path) > 0 .or. size(cli%overrides) > 0 &
        .or. cli%restart .or. cli%ck_every >= 0 .or. len(cli%run_name) > 0 &
        .or. cli%keep_checkpoints)) &
      call bad('--batch FILE takes only --out and --no-plot; give decks, names and '// &
               'overrides on the lines of FILE')

  contains

    !> The value after option i (the next argument).
    subroutine value_of(v)
      character(len=:), allocatable, intent(inout) :: v
      if (i >= nargs) then
        call bad('option "'//arg//'" needs a value')
        return
      end if
      i = i + 1
      v = argument(i)
      if (len(v) == 0) call bad('option "'//arg//'" needs a non-empty value')
    end subroutine value_of

    subroutine bad(text)
      character(len=*), intent(in) :: text
      call new_error(err, status_invalid, 'command line', text)
    end subroutine bad

  end subroutine read_mpm_cli

  function argument(k) result(a)
    integer, intent(in) :: k
    character(len=:), allocatable :: a
    integer :: n
    call get_command_argument(k, length=n)
    allocate (character(len=n) :: a)
    call get_command_argument(k, a)
  end function argument

  !> The usage text, on standard output.
  subroutine write_mpm_usage(default_deck, kinds)
    character(len=*), intent(in) :: default_deck
    type(kind_words_t), intent(in) :: kinds(:)
    write (output_unit, '(a)') 'usage: [mpirun -np N] wellposed-mpm [--out ROOT] '// &
      '[--name NAME] [--no-plot] [--force] [--check] [--checkpoint-every STEPS]'
    write (output_unit, '(a)') '         [--keep-checkpoints] [--restart | --restart-from FILE] '// &
      '[--max-memory SIZE] [DECK] [group.key=value ...]'
    write (output_unit, '(a)') '       [mpirun -np N] wellposed-mpm --batch FILE [--out ROOT] '// &
      '[--no-plot]'
    write (output_unit, '(a)') '  DECK: its &scene kind says which scene it is: '//kinds_text(kinds)
    write (output_unit, '(a)') '  (absent: by the deck''s groups, '//marks_text(kinds)//', else '// &
      ''''//trim(kinds(1)%name)//'''); default '//default_deck
    write (output_unit, '(a)') '  results go to ROOT/NAME (ROOT = out, NAME = &scene name)'
    write (output_unit, '(a)') '  overrides, e.g. grid.dx=0.5 time.cfl=0.1 material.h=-5e8'
    write (output_unit, '(a)') '  --checkpoint-every STEPS  into ROOT/NAME.checkpoints/ '// &
      '(default a tenth of the run or case, 0: none), the newest two kept'
    write (output_unit, '(a)') '  --keep-checkpoints        keep them when the run is done '// &
      '(by default a finished run removes them)'
    write (output_unit, '(a)') '  --restart                 continue from the newest '// &
      '(same deck and overrides; any number of ranks)'
    write (output_unit, '(a)') '  --restart-from FILE       continue from checkpoint FILE'
    write (output_unit, '(a)') '  --max-memory SIZE         refuse a deck whose estimated memory '// &
      'exceeds SIZE (4G, 512M; default: MemAvailable)'
    write (output_unit, '(a)') '  --force                   run a deck of more time steps '// &
      'than the limit (docs/guide/decks.md)'
    write (output_unit, '(a)') '  --check                   read and check the deck and '// &
      'overrides, run and write nothing'
    write (output_unit, '(a)') '  --batch FILE              one deck per line, optionally '// &
      'with options; jobs shared over the ranks'
    write (output_unit, '(a)') '  wellposed-mpm2d is an alias of this program, kept for one release'
  end subroutine write_mpm_usage

end module wellposed_mpm_cli
