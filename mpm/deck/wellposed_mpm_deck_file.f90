!> An MPM deck opened for reading: its whole text (to find groups, quote
!> values, store in run.h5), a unit for the namelist READs, a command-line
!> override group.key=value as a one-line namelist, and the sources of a
!> group in turn, the deck's then the overrides'. A file that is not a deck
!> (empty, comments only, not text, cut inside a group) or names no scene
!> is refused before anything is set up.
module wellposed_mpm_deck_file
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: read_deck_text, has_group, namelist_error, lower
  implicit none
  private
  public :: open_deck, override_line, start_sources, next_source, read_failed, sets_list, &
            read_sources

  !> Where a reader's groups come from, in turn (start_sources, then
  !> next_source until false): each of its groups the deck holds (`unit`,
  !> the deck rewound), then each override of one of them (`line`, a
  !> one-line namelist); the one not current is unallocated, so passed on
  !> it is absent. read_sources makes the READs through the reader's
  !> deck_groups_t.
  type, public :: deck_sources_t
    character(len=:), allocatable :: path, text
    character(len=:), allocatable :: groups(:), overrides(:), known(:)
    procedure(group_test), pointer, nopass :: is_other => null()
    integer :: deck_unit = -1             !< the deck, open while its groups are read
    integer :: next = 1                   !< the source after the current one
    integer, allocatable :: unit          !< the deck, when the current source
    character(len=:), allocatable :: line !< the current override's namelist
  end type deck_sources_t

  !> A reader's values of its groups: read_group makes one READ of group
  !> `grp` (a namelist of its own: a namelist group cannot be an argument)
  !> from the deck (`unit`) or an override `line`, iostat ios, iomsg msg.
  type, abstract, public :: deck_groups_t
  contains
    procedure(read_group_i), deferred :: read_group
  end type deck_groups_t

  abstract interface
    subroutine read_group_i(self, grp, ios, msg, unit, line)
      import :: deck_groups_t
      class(deck_groups_t), intent(inout) :: self
      character(len=*), intent(in) :: grp
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: msg
      integer, intent(in), optional :: unit
      character(len=*), intent(in), optional :: line
    end subroutine read_group_i
    !> True for a group another reader takes (a &material occurrence).
    pure logical function group_test(group)
      character(len=*), intent(in) :: group
    end function group_test
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
        "needs ""&scene name = '...' /"" (the run folder's name; see docs/guide/decks.md), and "// &
        'the default scene runs only when no deck is given')
      return
    end if
    open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) call new_error(err, status_invalid, path, 'cannot open "'//path//'": '// &
                                 trim(msg))
  end subroutine open_deck

  !> The group of `override` (group.key=value) and the one-line namelist
  !> `&group key=value /` to read; err when it is not of that form. A bare
  !> word or text (time.mass=blended, what a shell leaves of
  !> time.mass='blended'; "scene.title=a title"; a path) is quoted, unless
  !> it spells a logical (t, f, true, false) or nan/inf.
  subroutine override_line(override, group, line, err)
    character(len=*), intent(in) :: override
    character(len=:), allocatable, intent(out) :: group, line
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: value
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
    value = trim(override(eq + 1:))
    if (bare_word(value)) value = "'"//value//"'"
    line = '&'//group//' '//override(dot + 1:eq)//value//' /'
  end subroutine override_line

  !> Text of letters, digits, blanks and _ - . / : + that starts with a
  !> letter and is neither a logical nor nan/inf: a namelist reads it only
  !> between quotes (no comma: a list of words stays as given).
  pure logical function bare_word(value)
    character(len=*), intent(in) :: value
    character(len=*), parameter :: letters = 'abcdefghijklmnopqrstuvwxyz'
    character(len=*), parameter :: word_chars = letters//'0123456789_-./:+ '
    character(len=len(value)) :: low
    low = lower(value)
    bare_word = .false.
    if (len(value) == 0) return
    if (index(letters, low(1:1)) == 0 .or. verify(low, word_chars) /= 0) return
    ! logicals, and the numbers nan, inf and infinity, as the reader takes them
    bare_word = all(low /= [character(len=8) :: 't', 'f', 'true', 'false', 'nan', 'inf', &
                            'infinity'])
  end function bare_word

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

  !> The sources of `groups` in deck `path` (its text `text`) and in
  !> `overrides`; errors name the deck or the command line and the group.
  !> With `known`, an override of a group in neither list (nor one
  !> `is_other` takes) is refused.
  subroutine start_sources(src, path, text, overrides, groups, err, known, is_other)
    type(deck_sources_t), intent(out) :: src
    character(len=*), intent(in) :: path, text, overrides(:), groups(:)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: known(:)
    procedure(group_test), optional :: is_other
    integer :: ios
    character(len=512) :: msg
    src%path = path
    src%text = text
    src%groups = groups
    src%overrides = overrides
    if (present(known)) src%known = known
    if (present(is_other)) src%is_other => is_other
    open (newunit=src%deck_unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      src%deck_unit = -1
      src%next = size(groups) + size(overrides) + 1
      call new_error(err, status_invalid, path, 'cannot open "'//path//'": '//trim(msg))
    end if
  end subroutine start_sources

  !> Every source of `groups` (start_sources' arguments) in turn into
  !> `keys`; err names the source, the group and the READ's message.
  subroutine read_sources(keys, path, text, overrides, groups, err, known, is_other)
    class(deck_groups_t), intent(inout) :: keys
    character(len=*), intent(in) :: path, text, overrides(:), groups(:)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: known(:)
    procedure(group_test), optional :: is_other
    type(deck_sources_t) :: src
    character(len=:), allocatable :: grp
    character(len=512) :: msg
    integer :: ios
    call start_sources(src, path, text, overrides, groups, err, known, is_other)
    do while (next_source(src, grp, err))
      call keys%read_group(grp, ios, msg, src%unit, src%line)
      if (read_failed(src, grp, ios, msg, err)) return
    end do
  end subroutine read_sources

  !> The next source, its group in `group`: false at the end (the deck
  !> closed) or with err set (the deck could not be opened, a malformed or
  !> unknown override).
  logical function next_source(src, group, err) result(more)
    type(deck_sources_t), intent(inout) :: src
    character(len=:), allocatable, intent(out) :: group
    type(error_t), allocatable, intent(inout) :: err
    integer :: i, ng
    more = .false.
    if (allocated(err)) return
    if (allocated(src%unit)) deallocate (src%unit)
    if (allocated(src%line)) deallocate (src%line)
    ng = size(src%groups)
    do while (src%next <= ng)
      i = src%next
      src%next = i + 1
      if (.not. has_group(src%text, trim(src%groups(i)))) cycle
      rewind (src%deck_unit)
      src%unit = src%deck_unit
      group = trim(src%groups(i))
      more = .true.
      return
    end do
    call close_deck(src)
    do while (src%next <= ng + size(src%overrides))
      i = src%next - ng
      src%next = src%next + 1
      call override_line(src%overrides(i), group, src%line, err)
      if (allocated(err)) return
      if (any(src%groups == group)) then
        more = .true.
        return
      end if
      deallocate (src%line)
      if (.not. allocated(src%known)) cycle
      if (any(src%known == group)) cycle
      if (associated(src%is_other)) then
        if (src%is_other(group)) cycle
      end if
      call new_error(err, status_invalid, group, 'override "'//trim(src%overrides(i))// &
        '": no group &'//group)
      return
    end do
  end function next_source

  !> True when the READ of the current source failed (iostat ios /= 0):
  !> err then names the deck or the command line, the group and the
  !> message (iomsg msg), and the deck is closed.
  logical function read_failed(src, group, ios, msg, err) result(failed)
    type(deck_sources_t), intent(inout) :: src
    character(len=*), intent(in) :: group, msg
    integer, intent(in) :: ios
    type(error_t), allocatable, intent(inout) :: err
    failed = ios /= 0
    if (.not. failed) return
    if (allocated(src%line)) then
      err = namelist_error('command line', group, ios, msg, src%line)
    else
      err = namelist_error(src%path, group, ios, msg, src%text)
    end if
    call close_deck(src)
  end function read_failed

  subroutine close_deck(src)
    type(deck_sources_t), intent(inout) :: src
    if (src%deck_unit /= -1) close (src%deck_unit)
    src%deck_unit = -1
  end subroutine close_deck

end module wellposed_mpm_deck_file
