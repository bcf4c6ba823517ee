!> The text of a deck (docs/guide/decks.md): a file read whole and refused
!> unless it is plain text of namelist groups, each group closed; its
!> groups in order (has_group, check_group_names), its essence for
!> comparing decks, and a failed namelist READ turned into a message naming
!> the file, the group, the key and what was expected (namelist_error).
!> Passed on by wellposed_deck with its value checks.
module wellposed_deck_text
  use, intrinsic :: iso_fortran_env, only: iostat_end
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  implicit none
  private
  public :: read_text_file, read_deck_text, check_deck_text, namelist_error, has_group, &
            lower, deck_essence, check_group_names

  character(len=*), parameter :: deck_need = ': a deck is plain text of Fortran namelist '// &
    'groups "&group key = value, ... /" (see docs/guide/decks.md)'

contains

  !> The whole file `path` as one string (lines separated by new_line('a')).
  subroutine read_text_file(path, text, err)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    integer :: unit, ios, nbytes
    character(len=512) :: msg
    logical :: exists
    inquire (file=path, exist=exists, size=nbytes)
    if (.not. exists) then
      call new_error(err, status_invalid, path, 'deck file "'//path//'" does not exist')
      return
    end if
    open (newunit=unit, file=path, access='stream', form='unformatted', action='read', &
          status='old', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call new_error(err, status_invalid, path, 'cannot open "'//path//'": '//trim(msg))
      return
    end if
    allocate (character(len=max(nbytes, 0)) :: text)
    if (nbytes > 0) read (unit, iostat=ios, iomsg=msg) text
    close (unit)
    if (ios /= 0) then
      call new_error(err, status_invalid, path, 'cannot read "'//path//'": '//trim(msg))
    end if
  end subroutine read_text_file

  !> The whole deck file `path` as text, refused (`check_deck_text`) unless
  !> it is plain text holding at least one complete namelist group.
  subroutine read_deck_text(path, text, err)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    call read_text_file(path, text, err)
    if (allocated(err)) return
    call check_deck_text(path, text, err)
  end subroutine read_deck_text

  !> Error unless `text` (deck `path`) is a deck: plain text (no NUL or
  !> control byte but tab, CR, form feed), at least one namelist group
  !> "&group ... /" outside comments, and every group closed by "/" or
  !> "&end" (a file cut in the middle of a group is refused here, where the
  !> namelist READ would report an end of file under another group's name).
  pure subroutine check_deck_text(path, text, err)
    character(len=*), intent(in) :: path, text
    type(error_t), allocatable, intent(out) :: err
    integer :: i, c, open_line
    character(len=:), allocatable :: open_name
    character(len=32), allocatable :: names(:)
    integer, allocatable :: lines(:)
    logical :: at_end
    do i = 1, len(text)
      c = iachar(text(i:i))
      if ((c < 32 .and. c /= 9 .and. c /= 10 .and. c /= 12 .and. c /= 13) .or. c == 127) then
        call new_error(err, status_invalid, path, path//': not a text file (byte '// &
          int_text(i)//' is '//int_text(c)//')'//deck_need)
        return
      end if
    end do
    call scan_groups(text, names, lines, open_name, open_line, at_end)
    if (len(open_name) > 0) then
      call new_error(err, status_invalid, open_name, path//': namelist group &'//open_name// &
        ' (line '//int_text(open_line)//') is not closed by "/" before '// &
        trim(merge('the end of file', 'the next group ', at_end))// &
        ': is the file cut short?'//deck_need)
    else if (size(names) == 0) then
      call new_error(err, status_invalid, path, path//': holds no namelist group (empty, '// &
        'or comments only)'//deck_need)
    end if
  end subroutine check_deck_text

  !> The namelist groups of a deck's text in order (lower-case names, the
  !> line of each "&name"), outside comments and quoted values; a group is
  !> closed by "/" or "&end". A group still open when the text ends, or
  !> when another "&name" starts, is `open_name` (line `open_line`; '' when
  !> none), and `at_end` is false in the second case (the scan stops there).
  pure subroutine scan_groups(text, names, lines, open_name, open_line, at_end)
    character(len=*), intent(in) :: text
    character(len=32), allocatable, intent(out) :: names(:)
    integer, allocatable, intent(out) :: lines(:)
    character(len=:), allocatable, intent(out) :: open_name
    integer, intent(out) :: open_line
    logical, intent(out) :: at_end
    character(len=*), parameter :: letters = 'abcdefghijklmnopqrstuvwxyz'
    integer :: i, j, line
    character(len=1) :: quote
    logical :: comment
    character(len=:), allocatable :: low
    low = lower(text)
    allocate (names(0), lines(0))
    open_name = ''
    open_line = 0
    line = 1
    quote = ' '
    comment = .false.
    at_end = .true.
    i = 0
    do while (i < len(low))
      i = i + 1
      if (low(i:i) == new_line('a')) then
        line = line + 1
        comment = .false.
        cycle
      end if
      if (comment) cycle
      if (quote /= ' ') then
        if (low(i:i) == quote) quote = ' '
        cycle
      end if
      select case (low(i:i))
      case ('!')
        comment = .true.
      case ('"', "'")
        if (len(open_name) > 0) quote = low(i:i)
      case ('/')
        if (len(open_name) > 0) open_name = ''
      case ('&')
        j = i + 1
        do while (j <= len(low))
          if (verify(low(j:j), letters//'0123456789_') /= 0) exit
          j = j + 1
        end do
        if (j == i + 1) cycle
        if (low(i + 1:j - 1) == 'end') then
          open_name = ''
        else if (len(open_name) > 0) then
          at_end = .false.
          return
        else if (index(letters, low(i + 1:i + 1)) > 0) then
          open_name = low(i + 1:j - 1)
          open_line = line
          names = [character(len=32) :: names, open_name]
          lines = [lines, line]
        end if
        i = j - 1
      end select
    end do
  end subroutine scan_groups

  !> Error unless every namelist group of deck `path` (its `text`) is one of
  !> `known` (lower case) and each but those of `repeatable` is given once:
  !> a namelist READ skips a group it is not asked for and reads only the
  !> first of two, so either would be silently ignored.
  pure subroutine check_group_names(path, text, known, repeatable, err)
    character(len=*), intent(in) :: path, text, known(:), repeatable(:)
    type(error_t), allocatable, intent(out) :: err
    character(len=32), allocatable :: names(:)
    integer, allocatable :: lines(:)
    character(len=:), allocatable :: open_name, valid
    integer :: k, j, open_line
    logical :: at_end
    call scan_groups(text, names, lines, open_name, open_line, at_end)
    do k = 1, size(names)
      if (all(known /= names(k))) then
        valid = ''
        do j = 1, size(known)
          valid = valid//merge(', &', '  &', j > 1)//trim(known(j))
        end do
        call new_error(err, status_invalid, trim(names(k)), path//': line '// &
          int_text(lines(k))//': unknown namelist group &'//trim(names(k))// &
          ' (the groups of this deck are'//valid(2:)//'; docs/guide/decks.md)')
        return
      end if
      if (any(repeatable == names(k))) cycle
      j = findloc(names(1:k - 1), names(k), 1)
      if (j > 0) then
        call new_error(err, status_invalid, trim(names(k)), path//': line '// &
          int_text(lines(k))//': a second namelist group &'//trim(names(k))// &
          ' (the first is on line '//int_text(lines(j))//'): a deck gives each group '// &
          'once (only the first would be read); merge them')
        return
      end if
    end do
  end subroutine check_group_names

  !> What a namelist READ sees of a deck's text: comments ("!" to the end of
  !> a line outside quotes) dropped, every run of blanks, tabs and line ends
  !> outside quotes one blank (none beside "=", "," and "/"), letters outside
  !> quotes in lower case, quoted strings as written. Decks with equal
  !> essences set the same keys to the same values; a restart compares them,
  !> so that editing a comment does not orphan a run's checkpoints.
  pure function deck_essence(text) result(essence)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: essence
    character(len=len(text)) :: buf
    character(len=1) :: ch, quote
    integer :: i, n
    logical :: comment, gap
    n = 0
    quote = ' '
    comment = .false.
    gap = .false.
    do i = 1, len(text)
      ch = text(i:i)
      if (quote /= ' ') then
        n = n + 1
        buf(n:n) = ch
        if (ch == quote) quote = ' '
        cycle
      end if
      if (ch == new_line('a')) comment = .false.
      if (comment) cycle
      if (ch == '!') then
        comment = .true.
      else if (index(' '//achar(9)//achar(10)//achar(12)//achar(13), ch) > 0) then
        gap = .true.
      else
        if (gap .and. n > 0 .and. index('=,/', ch) == 0) then
          if (index('=,/', buf(n:n)) == 0) then
            n = n + 1
            buf(n:n) = ' '
          end if
        end if
        gap = .false.
        if (ch == '"' .or. ch == "'") quote = ch
        n = n + 1
        buf(n:n) = lower(ch)
      end if
    end do
    essence = buf(1:n)
  end function deck_essence

  !> True when the text of a deck holds the namelist group `&group`
  !> (case-insensitive, outside comments), so an optional group can be
  !> skipped without reading it.
  pure logical function has_group(text, group)
    character(len=*), intent(in) :: text, group
    character(len=:), allocatable :: low, key
    integer :: i
    logical :: in_comment
    low = lower(text)
    key = '&'//lower(group)
    has_group = .false.
    in_comment = .false.
    do i = 1, len(low) - len(key) + 1
      if (low(i:i) == new_line('a')) then
        in_comment = .false.
      else if (low(i:i) == '!') then
        in_comment = .true.
      end if
      if (in_comment) cycle
      if (low(i:i + len(key) - 1) == key) then
        if (i + len(key) > len(low)) then
          has_group = .true.; return
        end if
        if (verify(low(i + len(key):i + len(key)), ' ,/'//new_line('a')//char(9)//char(13)) &
            == 0) then
          has_group = .true.; return
        end if
      end if
    end do
  end function has_group

  !> The error for a failed namelist READ of group `group` from `path`,
  !> quoting gfortran's iomsg. gfortran reports a value it cannot read
  !> (text for a number, "2.5" for an integer) as "Cannot match namelist
  !> object name <token>", the same words as for an unknown key; when the
  !> deck's `text` is given, the token is located in it and a token that
  !> follows "key =" is reported as a bad value of that key.
  function namelist_error(path, group, iostat, iomsg, text) result(err)
    character(len=*), intent(in) :: path, group, iomsg
    integer, intent(in) :: iostat
    character(len=*), intent(in), optional :: text
    type(error_t), allocatable :: err
    character(len=:), allocatable :: hint, token, key
    character(len=*), parameter :: marker = 'Cannot match namelist object name '
    integer :: at
    if (iostat == iostat_end) then
      call new_error(err, status_invalid, group, path//': namelist group &'//group// &
        ' not found (the deck must contain "&'//group//' ... /")')
      return
    end if
    hint = ''
    at = index(iomsg, marker)
    if (at > 0) then
      token = trim(iomsg(at + len(marker):))
      key = ''
      if (present(text)) key = key_of_value(text, token)
      if (len(key) > 0) then
        hint = ' (key '//key//': a value of the wrong type or a malformed number)'
      else if (is_name(token)) then
        hint = ' (unknown key "'//token//'": see docs/guide/decks.md for the keys of &'//group//')'
      else
        hint = ' (a value of the wrong type or a malformed number)'
      end if
    else if (index(lower(iomsg), 'bad') > 0) then
      hint = ' (a value of the wrong type, or a missing value)'
    end if
    call new_error(err, status_invalid, group, path//': cannot read namelist group &'// &
      group//': '//trim(iomsg)//hint)
  end function namelist_error

  !> The key whose value contains `token` in the deck text ("key = value"),
  !> or '' when `token` is not part of a value.
  pure function key_of_value(text, token) result(key)
    character(len=*), intent(in) :: text, token
    character(len=:), allocatable :: key, low
    integer :: at, i
    character(len=*), parameter :: stops = ' ,='//char(9)//char(10)//char(13)
    key = ''
    if (len(token) == 0) return
    low = lower(text)
    at = 0
    do                                   ! every occurrence, first with a key wins
      i = index(low(at + 1:), lower(token))
      if (i == 0) return
      at = at + i
      key = key_at(at)
      if (len(key) > 0) return
    end do

  contains

    pure function key_at(at) result(key)
      integer, intent(in) :: at
      character(len=:), allocatable :: key
      integer :: i, j
      key = ''
      i = at - 1
      do while (i >= 1)                  ! back to the start of the value
        if (index(stops, low(i:i)) > 0) exit
        i = i - 1
      end do
      do while (i >= 1)                  ! blanks before it
        if (low(i:i) /= ' ' .and. low(i:i) /= char(9)) exit
        i = i - 1
      end do
      if (i < 1) return
      if (low(i:i) /= '=') return
      i = i - 1
      do while (i >= 1)
        if (low(i:i) /= ' ' .and. low(i:i) /= char(9)) exit
        i = i - 1
      end do
      j = i
      do while (i >= 1)
        if (.not. is_name(low(i:i)) .and. index('()_', low(i:i)) == 0 .and. &
            index('0123456789', low(i:i)) == 0) exit
        i = i - 1
      end do
      if (j > i) key = text(i + 1:j)
    end function key_at

  end function key_of_value

  !> True for a Fortran name (a letter, then letters, digits, underscores).
  pure logical function is_name(token)
    character(len=*), intent(in) :: token
    character(len=*), parameter :: letters = 'abcdefghijklmnopqrstuvwxyz'
    is_name = .false.
    if (len(token) == 0) return
    if (index(letters, lower(token(1:1))) == 0) return
    is_name = verify(lower(token), letters//'0123456789_') == 0
  end function is_name

  !> `text` with ASCII capitals in lower case (namelist names are
  !> case-insensitive; decks compare keys and words through this).
  pure function lower(text) result(low)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: low
    integer :: i, c
    low = text
    do i = 1, len(text)
      c = iachar(text(i:i))
      if (c >= iachar('A') .and. c <= iachar('Z')) low(i:i) = achar(c + 32)
    end do
  end function lower

end module wellposed_deck_text
