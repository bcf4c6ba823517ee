!> What a program says when an allocation fails: the run's deck (set once by
!> the program's main), what could not be allocated and how many items, on
!> standard error (flushed), then exit status 1 without a runtime backtrace.
!> The estimate before a run (docs/guide/outputs.md, "Memory") refuses most
!> such decks first; this is for what it does not foresee.
module wellposed_out_of_memory
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  implicit none
  private
  public :: set_run_label, out_of_memory

  character(len=:), allocatable :: label  !< "wellposed-mpm: DECK"

contains

  !> The program and deck every out-of-memory message names.
  subroutine set_run_label(program, deck)
    character(len=*), intent(in) :: program, deck
    label = program//': '//deck
  end subroutine set_run_label

  !> Stop the run: `what` (e.g. "particle storage") of `items` entries could
  !> not be allocated (stat `stat` of the ALLOCATE).
  subroutine out_of_memory(what, items, stat)
    character(len=*), intent(in) :: what
    integer(int64), intent(in) :: items
    integer, intent(in) :: stat
    character(len=24) :: n, s
    write (n, '(i0)') items
    write (s, '(i0)') stat
    if (.not. allocated(label)) label = 'wellposed'
    write (error_unit, '(a)') label//': error: out of memory: the '//what//' for '// &
      trim(n)//' entries could not be allocated (stat '//trim(s)//'); the deck needs more '// &
      'memory than this machine can give (docs/guide/outputs.md)'
    flush (error_unit)
    stop 1, quiet=.true.
  end subroutine out_of_memory

end module wellposed_out_of_memory
