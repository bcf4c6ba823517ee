!> Which scene a deck describes, among the kinds the program registers
!> (kind_words_t, one per kind: apps/mpm/wellposed_mpm_kind_table): &scene
!> kind = '<word>'; without the key, the first kind one of whose marking
!> groups the deck has, else the first kind (the default). An override
!> scene.kind=... on the command line wins. Also the check of &scene name,
!> which every kind's reader makes.
module wellposed_mpm_scene_kind
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: read_text_file, has_group, lower
  implicit none
  private
  public :: kind_words_t, deck_scene_kind, check_scene_kind, check_scene_name, takes_key, &
            key_owner, owners_text, kinds_text, marks_text

  !> What decks say of one scene kind: its &scene kind word, a few words on
  !> it for messages, its own groups, the groups that mark a deck as this
  !> kind when &scene gives none, and the keys of the shared groups that
  !> not every kind takes ('group.key', wellposed_mpm_deck_shared's
  !> kind_keys) that this kind takes.
  type :: kind_words_t
    character(len=16) :: name = ''
    character(len=64) :: what = ''
    character(len=16), allocatable :: groups(:), marks(:)
    character(len=32), allocatable :: keys(:)
  end type kind_words_t

contains

  !> The scene kind (index into `kinds`) of deck `path` with its
  !> command-line overrides.
  subroutine deck_scene_kind(path, overrides, kinds, which, err)
    character(len=*), intent(in) :: path, overrides(:)
    type(kind_words_t), intent(in) :: kinds(:)
    integer, intent(out) :: which
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: text, word
    character(len=64) :: name
    character(len=200) :: title
    character(len=16) :: kind
    namelist /scene/ name, title, kind
    integer :: unit, ios, i, eq, m
    character(len=512) :: msg
    which = 0
    call read_text_file(path, text, err)
    if (allocated(err)) return
    word = ''
    if (has_group(text, 'scene')) then
      kind = ''
      open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
      if (ios == 0) read (unit, nml=scene, iostat=ios, iomsg=msg)
      close (unit)
      ! an unknown key or bad value in &scene: the scene's reader says which
      if (ios == 0) word = trim(kind)
    end if
    do i = 1, size(overrides)
      eq = index(overrides(i), '=')
      if (lower(trim(adjustl(overrides(i)(1:eq - 1)))) == 'scene.kind') &
        word = unquote(trim(adjustl(overrides(i)(eq + 1:))))
    end do
    if (len(word) > 0) then
      call check_scene_kind(path, word, kinds, which, err)
      return
    end if
    do which = 1, size(kinds)
      if (any([(has_group(text, trim(kinds(which)%marks(m))), m = 1, size(kinds(which)%marks))])) &
        return
    end do
    which = 1
  end subroutine deck_scene_kind

  !> `v` without the quotes around it, if any.
  pure function unquote(v) result(u)
    character(len=*), intent(in) :: v
    character(len=:), allocatable :: u
    u = v
    if (len(u) >= 2) then
      if (scan(u(1:1), '''"') == 1) u = u(2:len(u) - 1)
    end if
  end function unquote

  !> The kind named `word` (its index into `kinds`), or a clear error that
  !> lists them.
  subroutine check_scene_kind(path, word, kinds, kind, err)
    character(len=*), intent(in) :: path, word
    type(kind_words_t), intent(in) :: kinds(:)
    integer, intent(out) :: kind
    type(error_t), allocatable, intent(out) :: err
    kind = findloc(kinds%name, lower(trim(word)), dim=1)
    if (kind /= 0) return
    call new_error(err, status_invalid, 'kind', path//': &scene: kind = '''//trim(word)// &
      ''' is not one of '//kinds_text(kinds))
  end subroutine check_scene_kind

  !> The kinds' words and what they are, for messages: 'bar' (the 1D
  !> bar), 'plate' (...) or 'axisymmetric' (...).
  pure function kinds_text(kinds) result(list)
    type(kind_words_t), intent(in) :: kinds(:)
    character(len=:), allocatable :: list
    integer :: i
    list = ''
    do i = 1, size(kinds)
      if (i > 1 .and. i == size(kinds)) then
        list = list//' or '
      else if (i > 1) then
        list = list//', '
      end if
      list = list//''''//trim(kinds(i)%name)//''' ('//trim(kinds(i)%what)//')'
    end do
  end function kinds_text

  !> The groups that mark a deck as each kind, for the usage text: &plate,
  !> &boundary or &study: 'plate'; &cylinder: 'axisymmetric' (in the
  !> table's order, the order they are tried in).
  pure function marks_text(kinds) result(list)
    type(kind_words_t), intent(in) :: kinds(:)
    character(len=:), allocatable :: list
    integer :: i, m
    list = ''
    do i = 1, size(kinds)
      if (size(kinds(i)%marks) == 0) cycle
      if (len(list) > 0) list = list//'; '
      do m = 1, size(kinds(i)%marks)
        if (m > 1 .and. m == size(kinds(i)%marks)) then
          list = list//' or '
        else if (m > 1) then
          list = list//', '
        end if
        list = list//'&'//trim(kinds(i)%marks(m))
      end do
      list = list//': '''//trim(kinds(i)%name)//''''
    end do
  end function marks_text

  !> Whether `words` takes the shared key `key` ('group.key').
  pure logical function takes_key(words, key)
    type(kind_words_t), intent(in) :: words
    character(len=*), intent(in) :: key
    takes_key = any(words%keys == key)
  end function takes_key

  !> The first kind of `kinds` that takes `key` (0: none).
  pure integer function key_owner(kinds, key)
    type(kind_words_t), intent(in) :: kinds(:)
    character(len=*), intent(in) :: key
    do key_owner = 1, size(kinds)
      if (takes_key(kinds(key_owner), key)) return
    end do
    key_owner = 0
  end function key_owner

  !> The names of every kind that takes `key`, for messages: 'plate', or
  !> 'axisymmetric and plate' ('' when none does).
  pure function owners_text(kinds, key) result(list)
    type(kind_words_t), intent(in) :: kinds(:)
    character(len=*), intent(in) :: key
    character(len=:), allocatable :: list
    integer :: i, n, m
    list = ''
    n = count([(takes_key(kinds(i), key), i = 1, size(kinds))])
    m = 0
    do i = 1, size(kinds)
      if (.not. takes_key(kinds(i), key)) cycle
      m = m + 1
      if (m > 1 .and. m == n) then
        list = list//' and '
      else if (m > 1) then
        list = list//', '
      end if
      list = list//trim(kinds(i)%name)
    end do
  end function owners_text

  !> &scene name of deck `path`: it names the output folder, so letters,
  !> digits, '_', '.' or '-' only, and not empty.
  subroutine check_scene_name(path, name, err)
    character(len=*), intent(in) :: path, name
    type(error_t), allocatable, intent(out) :: err
    if (len(name) == 0 .or. verify(name, &
        'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-') /= 0) &
      call new_error(err, status_invalid, 'name', path//': &scene: name = "'//name// &
        '" must be non-empty letters, digits, "_", "." or "-" (it names the output folder)')
  end subroutine check_scene_name

end module wellposed_mpm_scene_kind
