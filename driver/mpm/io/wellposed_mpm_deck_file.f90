!> An MPM deck opened for reading, for every scene kind's reader: its whole
!> text (to find groups, quote values and store in run.h5) and a unit on it
!> for the namelist READs; a command-line override group.key=value as the
!> one-line namelist the reader reads after the deck; and the loop every
!> reader makes over its groups, the deck's then the overrides'. A file that is not
!> a deck (empty, comments only, not text, cut in the middle of a group) or
!> that names no scene is refused here, before anything is set up: the
!> default scene runs only when the program is given no deck at all.
module wellposed_mpm_deck_file
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: read_deck_text, has_group, namelist_error, lower
  implicit none
  private
  public :: open_deck, override_line, read_deck_groups, group_reader, sets_list

  abstract interface
    !> One READ of namelist group `grp` from `unit` (the deck) or `line`
    !> (an override), iostat and iomsg in ios and msg.
    subroutine group_reader(grp, ios, msg, unit, line)
      character(len=*), intent(in) :: grp
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: msg
      integer, intent(in), optional :: unit
      character(len=*), intent(in), optional :: line
    end subroutine group_reader
  end interface

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

  !> Whether override line `line` (&group key=... /) gives list key `key`
  !> whole (not key(i)): the reader then clears the list first, so that
  !> study.dx=0.125 means the one case 0.125 m, not the deck's list with
  !> its first entry replaced (a namelist READ sets only the entries given).
  pure logical function sets_list(line, key)
    character(len=*), intent(in) :: line, key
    character(len=len(line)) :: rest
    integer :: b
    sets_list = .false.
    b = index(line, ' ')
    if (b == 0) return
    rest = adjustl(line(b:))
    if (len_trim(rest) <= len(key)) return
    if (lower(rest(1:len(key))) /= key) return
    rest = adjustl(rest(len(key) + 1:))
    sets_list = rest(1:1) == '='
  end function sets_list

  !> Each of `groups` that deck `path` (its text `text`) holds, then each
  !> override of those groups, through `reader`; errors name the deck or the
  !> command line and the group. With `known`, an override of a group in
  !> neither list (nor a &material occurrence: `is_other`) is refused.
  subroutine read_deck_groups(path, text, overrides, groups, reader, err, known, is_other)
    character(len=*), intent(in) :: path, text, overrides(:), groups(:)
    procedure(group_reader) :: reader
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: known(:)
    interface
      pure logical function is_other(group)
        character(len=*), intent(in) :: group
      end function is_other
    end interface
    optional :: is_other
    integer :: unit, ios, i
    character(len=512) :: msg
    character(len=:), allocatable :: line, group
    open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call new_error(err, status_invalid, path, 'cannot open "'//path//'": '//trim(msg))
      return
    end if
    do i = 1, size(groups)
      if (.not. has_group(text, trim(groups(i)))) cycle
      rewind (unit)
      call reader(trim(groups(i)), ios, msg, unit=unit)
      if (ios /= 0) then
        close (unit)
        err = namelist_error(path, trim(groups(i)), ios, msg, text); return
      end if
    end do
    close (unit)
    do i = 1, size(overrides)
      call override_line(overrides(i), group, line, err)
      if (allocated(err)) return
      if (.not. any(groups == group)) then
        if (.not. present(known)) cycle
        if (any(known == group)) cycle
        if (present(is_other)) then
          if (is_other(group)) cycle
        end if
        call new_error(err, status_invalid, group, 'override "'//trim(overrides(i))// &
          '": no group &'//group); return
      end if
      call reader(group, ios, msg, line=line)
      if (ios /= 0) then
        err = namelist_error('command line', group, ios, msg, line); return
      end if
    end do
  end subroutine read_deck_groups

end module wellposed_mpm_deck_file
