!> An MPM deck opened for reading, for every scene kind's reader: its whole
!> text (to find groups, quote values and store in run.h5) and a unit on it
!> for the namelist READs; and a command-line override group.key=value as
!> the one-line namelist the reader reads after the deck. A file that is not
!> a deck (empty, comments only, not text, cut in the middle of a group) or
!> that names no scene is refused here, before anything is set up: the
!> default scene runs only when the program is given no deck at all.
module wellposed_mpm_deck_file
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: read_deck_text, has_group
  implicit none
  private
  public :: open_deck, override_line

contains

  !> Read `path` into `text` and open it on `unit` (the caller closes it).
  subroutine open_deck(path, text, unit, err)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    integer, intent(out) :: unit
    type(error_t), allocatable, intent(out) :: err
    integer :: ios
    character(len=512) :: msg
    unit = -1
    call read_deck_text(path, text, err)
    if (allocated(err)) return
    if (.not. has_group(text, 'scene')) then
      call new_error(err, status_invalid, 'scene', path//': names no scene: an MPM deck '// &
        "needs ""&scene name = '...' /"" (the run folder's name; see docs/decks.md), and "// &
        'the default scene runs only when no deck is given')
      return
    end if
    open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) call new_error(err, status_invalid, path, 'cannot open "'//path//'": '// &
                                 trim(msg))
  end subroutine open_deck

  !> The group of `override` (group.key=value) and the one-line namelist
  !> `&group key=value /` to read; err when it is not of that form.
  subroutine override_line(override, group, line, err)
    character(len=*), intent(in) :: override
    character(len=:), allocatable, intent(out) :: group, line
    type(error_t), allocatable, intent(out) :: err
    integer :: dot, eq
    dot = index(override, '.')
    eq = index(override, '=')
    if (dot < 2 .or. eq < dot + 2) then
      call new_error(err, status_invalid, trim(override), 'override "'//trim(override)// &
        '" is not of the form group.key=value')
      group = ''
      line = ''
      return
    end if
    group = override(1:dot - 1)
    line = '&'//group//' '//trim(override(dot + 1:))//' /'
  end subroutine override_line

end module wellposed_mpm_deck_file
