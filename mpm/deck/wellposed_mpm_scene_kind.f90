!> Which scene a deck describes: &scene kind = 'bar' (the 1D uniaxial-strain
!> bar of the dissertation's chapter 2) or 'plate' (the plane-strain plate of
!> chapter 4). Without the key, a deck with a group only plates have
!> (&plate, &boundary, &study) is a plate and any other a bar.
!> An override scene.kind=... on the command line wins. Also the check of
!> &scene name, which every kind's reader makes.
module wellposed_mpm_scene_kind
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: read_text_file, has_group, lower
  implicit none
  private
  public :: scene_kind_bar, scene_kind_plate, scene_kind_names, deck_scene_kind, &
            check_scene_kind, check_scene_name

  integer, parameter :: scene_kind_bar = 1, scene_kind_plate = 2
  character(len=5), parameter :: scene_kind_names(2) = [character(len=5) :: 'bar', 'plate']

contains

  !> The scene kind of deck `path` with its command-line overrides.
  subroutine deck_scene_kind(path, overrides, which, err)
    character(len=*), intent(in) :: path, overrides(:)
    integer, intent(out) :: which
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: text, word
    character(len=64) :: name
    character(len=200) :: title
    character(len=16) :: kind
    namelist /scene/ name, title, kind
    integer :: unit, ios, i, eq
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
    if (len(word) == 0) then
      which = scene_kind_bar
      if (has_group(text, 'plate') .or. has_group(text, 'boundary') .or. &
          has_group(text, 'study')) which = scene_kind_plate
      return
    end if
    call check_scene_kind(path, word, which, err)
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

  !> The kind named `word` ('bar' or 'plate'), or a clear error.
  subroutine check_scene_kind(path, word, kind, err)
    character(len=*), intent(in) :: path, word
    integer, intent(out) :: kind
    type(error_t), allocatable, intent(out) :: err
    kind = findloc(scene_kind_names, lower(trim(word)), dim=1)
    if (kind == 0) call new_error(err, status_invalid, 'kind', path//': &scene: kind = '''// &
      trim(word)//''' is not one of ''bar'' (the 1D bar) or ''plate'' (the plane-strain plate)')
  end subroutine check_scene_kind

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
