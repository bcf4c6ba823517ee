!> The groups every MPM deck shares (&scene, &grid, &time, &material,
!> &viscosity, &nonlocal, &output), read once for every scene kind with the
!> wellposed_deck conventions. The viscosity is q = rho (a1 c |D_kk| dx +
!> a2 D_kk^2 dx^2) for D_kk < 0. Keys only some kinds take (kind_keys,
!> kind_words_t%keys) are refused for another kind, naming one that takes
!> them. A kind's reader puts its defaults into a shared_deck_t, calls
!> read_shared_deck, then reads its own groups. Keys: docs/guide/decks.md.
module wellposed_mpm_deck_shared
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: check_finite, check_word, unset, is_set, lower, value_text, &
                            check_group_names
  use wellposed_mpm_deck_file, only: open_deck, deck_groups_t, read_sources
  use wellposed_mpm_scene_kind, only: check_scene_name, kind_words_t, takes_key, &
                                      owners_text
  use wellposed_mpm_material_deck, only: read_materials, material_defaults_t, &
                                         is_material_group
  use wellposed_mpm_materials, only: mpm_materials_t
  use wellposed_mpm_nonlocal_settings, only: nonlocal_settings_t, nl_scheme_names, &
                                             nl_scheme_id, nl_sweep_names, nl_sweep_id
  use wellposed_mpm_nonlocal_deck, only: resolve_nonlocal
  use wellposed_mpm_method, only: scheme_names, mass_names
  use wellposed_mpm_linear_solver, only: solver_names
  use wellposed_mpm_deck_checks, only: check_implicit
  use wellposed_text, only: real_text
  implicit none
  private
  public :: shared_deck_t, read_shared_deck, max_cases, shared_groups, kind_keys

  !> Cases of a plate deck's &study.
  integer, parameter :: max_cases = 16
  character(len=9), parameter :: shared_groups(6) = [character(len=9) :: 'scene', 'grid', &
    'time', 'viscosity', 'nonlocal', 'output']
  !> The keys of the shared groups that only the kinds taking them accept.
  character(len=24), parameter :: kind_keys(12) = [character(len=24) :: 'grid.length', &
    'grid.far_end', 'time.mass', 'time.stop_on_cutback', 'output.reference', &
    'output.reference_label', 'output.band_y', 'output.band_x', 'output.band_time', &
    'output.band_drop', 'output.band_onset_strain', 'output.band_axis']

  !> The shared groups' values: the kind's defaults before reading, the
  !> deck's after (words also as ids into the kind's name lists).
  type :: shared_deck_t
    integer :: ndim = 1                         !< of the material regions
    character(len=64) :: name = ''
    character(len=200) :: title = ''
    real(dp) :: length = 0.0_dp                 !< bar length (m)
    real(dp) :: dx = 0.25_dp                    !< cell size (m)
    integer :: ppc = 2, pad_cells = 2
    character(len=16) :: shape = 'gimp', far_end = 'fixed', scheme = 'musl', mass = 'lumped'
    integer :: shape_id = 0, far_end_id = 0, scheme_id = 0, mass_id = 0
    real(dp) :: t_end = 0.0_dp, cfl = 0.2_dp
    !> &time dt, linear_solver: the implicit scheme's largest step (s; default
    !> t_end/100) and its linear solver (wellposed_mpm_linear_solver's names)
    real(dp) :: implicit_dt = 0.0_dp
    character(len=16) :: linear_solver = 'direct'
    integer :: linear_solver_id = 1
    logical :: mass_given = .false., cfl_given = .false.  !< by the deck or an override
    logical :: stop_on_cutback = .false.
    real(dp) :: visc_a1 = 0.0_dp, visc_a2 = 0.0_dp  !< &viscosity a1, a2
    real(dp) :: sample_dt = 0.0_dp, snapshot_dt = 0.0_dp
    real(dp) :: band_y = 2.5_dp, band_x = 0.0_dp, band_time = 0.0_dp
    real(dp) :: band_drop = 0.05_dp, band_onset_strain = 1.0e-3_dp
    character(len=16) :: band_axis = 'x'
    character(len=200) :: reference = '', reference_label = ''
    logical :: progress = .true., plot = .true.
    type(nonlocal_settings_t) :: nonlocal
    type(material_defaults_t) :: mdef
    type(mpm_materials_t) :: materials
    real(dp) :: density = 0.0_dp
  end type shared_deck_t

  !> A given key the deck's kind does not take (sentinel: unset, '' or a
  !> logical read both ways).
  type :: foreign_t
    character(len=:), allocatable :: group, key
  end type foreign_t

  !> The shared groups as read for the deck's kind (`words`): the values
  !> given (sentinels elsewhere, blank), the first given key it does not
  !> take, and &nonlocal's words and lengths.
  type, extends(deck_groups_t) :: shared_keys_t
    type(kind_words_t) :: words
    type(shared_deck_t) :: given
    type(foreign_t) :: foreign
    type(nonlocal_settings_t) :: nonlocal
    character(len=16) :: nl_word = '', nl_sweep = ''
    real(dp) :: nl_length = 0.0_dp, nl_h_zeta = 0.0_dp
  contains
    procedure :: read_group => read_shared_group
  end type shared_keys_t

contains

  !> Read the shared groups of deck `path` and the overrides into `sh` (its
  !> defaults set by the caller) for the scene kind named `name` of the
  !> registered `kinds`, whose own groups are left to its reader; shapes(:)
  !> are the kind's shape words, far_ends(:) its far-end words (when it
  !> takes grid.far_end). `text` is the deck's text.
  subroutine read_shared_deck(path, overrides, kinds, name, shapes, far_ends, sh, text, err)
    character(len=*), intent(in) :: path, overrides(:), name, shapes(:), far_ends(:)
    type(kind_words_t), intent(in) :: kinds(:)
    type(shared_deck_t), intent(inout) :: sh
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    type(shared_keys_t) :: k
    integer :: unit, i, this
    character(len=:), allocatable :: owners
    call blank(k%given)
    this = findloc(kinds%name, name, dim=1)
    if (this == 0) then
      call new_error(err, status_invalid, 'kind', path//': the scene kind '''//name// &
        ''' is not registered with the program (apps/mpm/wellposed_mpm_kind_table)'); return
    end if
    k%words = kinds(this)
    k%given%stop_on_cutback = sh%stop_on_cutback
    k%given%progress = sh%progress
    k%given%plot = sh%plot
    k%nonlocal = sh%nonlocal
    k%nl_length = unset; k%nl_h_zeta = unset
    k%nl_word = nl_scheme_names(sh%nonlocal%scheme)
    k%nl_sweep = nl_sweep_names(sh%nonlocal%sweep)
    call open_deck(path, text, unit, err)
    if (allocated(err)) return
    close (unit)
    associate (own => k%words%groups)
      call check_group_names(path, text, [character(len=32) :: shared_groups, own, &
                             'material'], [character(len=32) :: 'material'], err)
      if (allocated(err)) return
      call read_sources(k, path, text, overrides, shared_groups, err, own, is_material_group)
      if (allocated(err)) return
    end associate
    if (allocated(k%foreign%key)) then
      owners = owners_text(kinds, k%foreign%group//'.'//k%foreign%key)
      if (len(owners) == 0) then     ! a key of kind_keys no registered kind takes
        call new_error(err, status_invalid, k%foreign%key, path//': &'//k%foreign%group// &
          ': '//k%foreign%key//' is not a key of '//name//' scenes (docs/guide/decks.md)')
      else
        call new_error(err, status_invalid, k%foreign%key, path//': &'//k%foreign%group// &
          ': '//k%foreign%key//' is a key of '//owners//' scenes; this deck''s scene '// &
          'kind is '''//name//''' (docs/guide/decks.md)')
      end if
      return
    end if
    sh%nonlocal = k%nonlocal
    call merge_given(k%given, sh)
    call check_shared(path, k%words, shapes, far_ends, sh, err)
    if (allocated(err)) return
    call read_materials(path, text, overrides, sh%ndim, sh%mdef, sh%materials, sh%density, err)
    if (allocated(err)) return
    call check_word(path, 'nonlocal', 'scheme', k%nl_word, nl_scheme_names, i, err)
    if (allocated(err)) return
    sh%nonlocal%scheme = nl_scheme_id(lower(trim(k%nl_word)))
    call check_word(path, 'nonlocal', 'sweep', k%nl_sweep, nl_sweep_names, i, err)
    if (allocated(err)) return
    sh%nonlocal%sweep = nl_sweep_id(lower(trim(k%nl_sweep)))
    call resolve_nonlocal(path, sh%materials, k%nl_length, k%nl_h_zeta, sh%nonlocal, err)
  end subroutine read_shared_deck

  !> One READ of group `grp` from the deck (`unit`) or an override `line`
  !> into the given values, and the kind-foreign keys it gave.
  subroutine read_shared_group(self, grp, ios, msg, unit, line)
    class(shared_keys_t), intent(inout) :: self
    character(len=*), intent(in) :: grp
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    ios = 0
    select case (grp)
    case ('scene')
      call read_scene(self%given, ios, msg, unit, line)
    case ('grid')
      call read_grid(self%given, ios, msg, unit, line)
    case ('time')
      call read_time_keys(self, ios, msg, unit, line)
    case ('viscosity')
      call read_viscosity(self%given, ios, msg, unit, line)
    case ('nonlocal')
      call read_nonlocal(self%nonlocal, self%nl_word, self%nl_sweep, self%nl_length, &
                         self%nl_h_zeta, ios, msg, unit, line)
    case ('output')
      call read_output(self%given, ios, msg, unit, line)
    end select
    if (ios == 0) call note_foreign(self, grp)
  end subroutine read_shared_group

  !> &time. stop_on_cutback, a logical, has no unset value: when the kind
  !> does not take it, &time is read again from the opposite value, and the
  !> key was given when both reads agree.
  subroutine read_time_keys(self, ios, msg, unit, line)
    type(shared_keys_t), intent(inout) :: self
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    logical :: soc
    call read_time(self%given, ios, msg, unit, line)
    if (ios /= 0 .or. takes_key(self%words, 'time.stop_on_cutback')) return
    soc = self%given%stop_on_cutback
    self%given%stop_on_cutback = .not. soc
    if (present(unit)) rewind (unit)
    call read_time(self%given, ios, msg, unit, line)
    if (self%given%stop_on_cutback .eqv. soc) call note(self%foreign, 'time', 'stop_on_cutback')
    self%given%stop_on_cutback = soc
  end subroutine read_time_keys

  !> The keys of group `grp` in kind_keys given and not taken by the kind.
  subroutine note_foreign(self, grp)
    type(shared_keys_t), intent(inout) :: self
    character(len=*), intent(in) :: grp
    integer :: i, dot
    do i = 1, size(kind_keys)
      dot = index(kind_keys(i), '.')
      if (kind_keys(i)(1:dot - 1) /= grp) cycle
      if (takes_key(self%words, trim(kind_keys(i)))) cycle
      if (is_given(self%given, trim(kind_keys(i)))) &
        call note(self%foreign, grp, trim(kind_keys(i)(dot + 1:)))
    end do
  end subroutine note_foreign

  !> Whether the kind key `key` ('group.key' of kind_keys) was given: not
  !> its sentinel. time.stop_on_cutback: read_time_keys tells.
  pure logical function is_given(g, key)
    type(shared_deck_t), intent(in) :: g
    character(len=*), intent(in) :: key
    select case (key)
    case ('grid.length'); is_given = is_set(g%length)
    case ('grid.far_end'); is_given = g%far_end /= achar(0)
    case ('time.mass'); is_given = g%mass /= achar(0)
    case ('output.reference'); is_given = len_trim(g%reference) > 0
    case ('output.reference_label'); is_given = len_trim(g%reference_label) > 0
    case ('output.band_y'); is_given = is_set(g%band_y)
    case ('output.band_x'); is_given = is_set(g%band_x)
    case ('output.band_time'); is_given = is_set(g%band_time)
    case ('output.band_drop'); is_given = is_set(g%band_drop)
    case ('output.band_onset_strain'); is_given = is_set(g%band_onset_strain)
    case ('output.band_axis'); is_given = g%band_axis /= achar(0)
    case default; is_given = .false.
    end select
  end function is_given

  !> The first foreign key given: `grp`, `key`.
  subroutine note(foreign, grp, key)
    type(foreign_t), intent(inout) :: foreign
    character(len=*), intent(in) :: grp, key
    if (allocated(foreign%key)) return
    foreign%group = grp
    foreign%key = key
  end subroutine note

  !> `sh` with every sentinel: nothing given yet.
  subroutine blank(sh)
    type(shared_deck_t), intent(out) :: sh
    sh%name = achar(0); sh%title = achar(0)
    sh%length = unset; sh%dx = unset; sh%ppc = -huge(1); sh%pad_cells = -huge(1)
    ! words: achar(0), so that a word given as '' is checked (and refused)
    sh%shape = achar(0); sh%far_end = achar(0); sh%scheme = achar(0); sh%mass = achar(0)
    sh%t_end = unset; sh%cfl = unset; sh%stop_on_cutback = .false.
    sh%implicit_dt = unset; sh%linear_solver = achar(0)
    sh%visc_a1 = unset; sh%visc_a2 = unset
    sh%sample_dt = unset; sh%snapshot_dt = unset
    sh%band_y = unset; sh%band_x = unset; sh%band_time = unset
    sh%band_drop = unset; sh%band_onset_strain = unset; sh%band_axis = achar(0)
  end subroutine blank

  !> The values given (not sentinels) over the defaults in `sh`.
  subroutine merge_given(g, sh)
    type(shared_deck_t), intent(in) :: g
    type(shared_deck_t), intent(inout) :: sh
    if (g%name /= achar(0)) sh%name = g%name
    if (g%title /= achar(0)) sh%title = g%title
    if (is_set(g%length)) sh%length = g%length
    if (is_set(g%dx)) sh%dx = g%dx
    if (g%ppc /= -huge(1)) sh%ppc = g%ppc
    if (g%pad_cells /= -huge(1)) sh%pad_cells = g%pad_cells
    if (g%shape /= achar(0)) sh%shape = g%shape
    if (g%far_end /= achar(0)) sh%far_end = g%far_end
    if (g%scheme /= achar(0)) sh%scheme = g%scheme
    if (g%mass /= achar(0)) sh%mass = g%mass
    sh%mass_given = g%mass /= achar(0)
    if (is_set(g%t_end)) sh%t_end = g%t_end
    if (is_set(g%cfl)) sh%cfl = g%cfl
    sh%cfl_given = is_set(g%cfl)
    if (is_set(g%implicit_dt)) sh%implicit_dt = g%implicit_dt
    if (g%linear_solver /= achar(0)) sh%linear_solver = g%linear_solver
    if (is_set(g%visc_a1)) sh%visc_a1 = g%visc_a1
    if (is_set(g%visc_a2)) sh%visc_a2 = g%visc_a2
    sh%stop_on_cutback = g%stop_on_cutback
    if (is_set(g%sample_dt)) sh%sample_dt = g%sample_dt
    if (is_set(g%snapshot_dt)) sh%snapshot_dt = g%snapshot_dt
    if (is_set(g%band_y)) sh%band_y = g%band_y
    if (is_set(g%band_x)) sh%band_x = g%band_x
    if (is_set(g%band_time)) sh%band_time = g%band_time
    if (is_set(g%band_drop)) sh%band_drop = g%band_drop
    if (is_set(g%band_onset_strain)) sh%band_onset_strain = g%band_onset_strain
    if (g%band_axis /= achar(0)) sh%band_axis = g%band_axis
    sh%reference = g%reference
    sh%reference_label = g%reference_label
    sh%progress = g%progress
    sh%plot = g%plot
  end subroutine merge_given

  !> The words as ids of the kind's lists, the name, the finite numbers.
  subroutine check_shared(path, words, shapes, far_ends, sh, err)
    character(len=*), intent(in) :: path, shapes(:), far_ends(:)
    type(kind_words_t), intent(in) :: words
    type(shared_deck_t), intent(inout) :: sh
    type(error_t), allocatable, intent(out) :: err
    call check_scene_name(path, trim(sh%name), err); if (allocated(err)) return
    call check_word(path, 'grid', 'shape', sh%shape, shapes, sh%shape_id, err)
    if (allocated(err)) return
    if (takes_key(words, 'grid.far_end')) then
      call check_word(path, 'grid', 'far_end', sh%far_end, far_ends, sh%far_end_id, err)
      if (allocated(err)) return
    end if
    if (takes_key(words, 'time.mass')) then
      call check_word(path, 'time', 'mass', sh%mass, mass_names, sh%mass_id, err)
      if (allocated(err)) return
    end if
    call check_word(path, 'time', 'scheme', sh%scheme, scheme_names, sh%scheme_id, err)
    if (allocated(err)) return
    call check_finite(path, 'time', 't_end', sh%t_end, err); if (allocated(err)) return
    call check_finite(path, 'time', 'cfl', sh%cfl, err); if (allocated(err)) return
    call check_word(path, 'time', 'linear_solver', sh%linear_solver, solver_names, &
                    sh%linear_solver_id, err)
    if (allocated(err)) return
    call check_implicit(path, sh%scheme_id, sh%t_end, [sh%visc_a1, sh%visc_a2], &
                        sh%mass_given, sh%mass_id, sh%implicit_dt, err)
    if (allocated(err)) return
    call check_viscosity(path, 'a1', sh%visc_a1, err); if (allocated(err)) return
    call check_viscosity(path, 'a2', sh%visc_a2, err); if (allocated(err)) return
    call check_finite(path, 'output', 'sample_dt', sh%sample_dt, err); if (allocated(err)) return
    call check_finite(path, 'output', 'snapshot_dt', sh%snapshot_dt, err)
    if (allocated(err)) return
    if (sh%snapshot_dt < 0.0_dp) then
      call new_error(err, status_invalid, 'snapshot_dt', path//': &output: snapshot_dt = '// &
        real_text(sh%snapshot_dt)//' s must be >= 0 (0: no snapshots)'); return
    end if
    select case (lower(trim(sh%band_axis)))
    case ('x', 'y')
      sh%band_axis = lower(trim(sh%band_axis))
    case default
      call new_error(err, status_invalid, 'band_axis', path//": &output: band_axis = '"// &
        trim(sh%band_axis)//"' is not one of 'x' (along y = band_y), 'y' (along x = band_x)")
    end select
  end subroutine check_shared

  !> &viscosity `key` = `a`: finite and >= 0.
  subroutine check_viscosity(path, key, a, err)
    character(len=*), intent(in) :: path, key
    real(dp), intent(in) :: a
    type(error_t), allocatable, intent(out) :: err
    call check_finite(path, 'viscosity', key, a, err); if (allocated(err)) return
    if (a < 0.0_dp) call new_error(err, status_invalid, key, path//': &viscosity: '//key// &
      ' = '//value_text(a)//' must be >= 0 (the coefficient of a bulk artificial viscosity; '// &
      '0 switches its term off)')
  end subroutine check_viscosity

  subroutine read_viscosity(g, ios, msg, unit, line)
    type(shared_deck_t), intent(inout) :: g
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: a1, a2
    namelist /viscosity/ a1, a2
    a1 = g%visc_a1; a2 = g%visc_a2
    ios = 0
    if (present(unit)) read (unit, nml=viscosity, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=viscosity, iostat=ios, iomsg=msg)
    g%visc_a1 = a1; g%visc_a2 = a2
  end subroutine read_viscosity

  subroutine read_scene(g, ios, msg, unit, line)
    type(shared_deck_t), intent(inout) :: g
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    character(len=64) :: name
    character(len=200) :: title
    character(len=16) :: kind   !< read by wellposed_mpm_scene_kind
    namelist /scene/ name, title, kind
    name = g%name; title = g%title; kind = ''
    ios = 0
    if (present(unit)) read (unit, nml=scene, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=scene, iostat=ios, iomsg=msg)
    g%name = name; g%title = title
  end subroutine read_scene

  subroutine read_grid(g, ios, msg, unit, line)
    type(shared_deck_t), intent(inout) :: g
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: length, dx
    integer :: ppc, pad_cells
    character(len=16) :: shape, far_end
    namelist /grid/ length, dx, ppc, pad_cells, shape, far_end
    length = g%length; dx = g%dx; ppc = g%ppc; pad_cells = g%pad_cells
    shape = g%shape; far_end = g%far_end
    ios = 0
    if (present(unit)) read (unit, nml=grid, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=grid, iostat=ios, iomsg=msg)
    g%length = length; g%dx = dx; g%ppc = ppc; g%pad_cells = pad_cells
    g%shape = shape; g%far_end = far_end
  end subroutine read_grid

  subroutine read_time(g, ios, msg, unit, line)
    type(shared_deck_t), intent(inout) :: g
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: t_end, cfl, dt
    character(len=16) :: scheme, mass, linear_solver
    logical :: stop_on_cutback
    namelist /time/ t_end, cfl, scheme, stop_on_cutback, mass, dt, linear_solver
    t_end = g%t_end; cfl = g%cfl; scheme = g%scheme; stop_on_cutback = g%stop_on_cutback
    mass = g%mass; dt = g%implicit_dt; linear_solver = g%linear_solver
    ios = 0
    if (present(unit)) read (unit, nml=time, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=time, iostat=ios, iomsg=msg)
    g%t_end = t_end; g%cfl = cfl; g%scheme = scheme; g%stop_on_cutback = stop_on_cutback
    g%mass = mass; g%implicit_dt = dt; g%linear_solver = linear_solver
  end subroutine read_time

  subroutine read_output(g, ios, msg, unit, line)
    type(shared_deck_t), intent(inout) :: g
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: sample_dt, snapshot_dt, band_y, band_x, band_time, band_drop, band_onset_strain
    character(len=16) :: band_axis
    character(len=200) :: reference, reference_label
    logical :: progress, plot
    namelist /output/ sample_dt, snapshot_dt, band_y, band_x, band_axis, band_time, &
      band_drop, band_onset_strain, progress, plot, reference, reference_label
    sample_dt = g%sample_dt; snapshot_dt = g%snapshot_dt; band_y = g%band_y
    band_x = g%band_x; band_axis = g%band_axis; band_time = g%band_time
    band_drop = g%band_drop; band_onset_strain = g%band_onset_strain
    progress = g%progress; plot = g%plot
    reference = g%reference; reference_label = g%reference_label
    ios = 0
    if (present(unit)) read (unit, nml=output, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=output, iostat=ios, iomsg=msg)
    g%sample_dt = sample_dt; g%snapshot_dt = snapshot_dt; g%band_y = band_y
    g%band_x = band_x; g%band_axis = band_axis; g%band_time = band_time
    g%band_drop = band_drop; g%band_onset_strain = band_onset_strain
    g%progress = progress; g%plot = plot
    g%reference = reference; g%reference_label = reference_label
  end subroutine read_output

  !> &nonlocal into `s`, its scheme and sweep words and the given L and h_zeta.
  subroutine read_nonlocal(s, word, sweep_word, length, h_zeta, ios, msg, unit, line)
    type(nonlocal_settings_t), intent(inout) :: s
    character(len=*), intent(inout) :: word, sweep_word
    real(dp), intent(inout) :: length, h_zeta
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    character(len=16) :: scheme, sweep
    real(dp) :: tolerance, rel_tolerance, anderson_mixing, weight_cutoff, l
    integer :: max_iterations, stall_iterations, max_rounds, anderson_depth
    namelist /nonlocal/ scheme, sweep, tolerance, rel_tolerance, max_iterations, &
      stall_iterations, max_rounds, anderson_depth, anderson_mixing, weight_cutoff, l, h_zeta
    scheme = word; sweep = sweep_word; l = length
    tolerance = s%tolerance; rel_tolerance = s%rel_tolerance
    max_iterations = s%max_iterations; stall_iterations = s%stall_iterations
    max_rounds = s%max_rounds; anderson_depth = s%anderson_depth
    anderson_mixing = s%anderson_mixing; weight_cutoff = s%weight_cutoff
    ios = 0
    if (present(unit)) read (unit, nml=nonlocal, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=nonlocal, iostat=ios, iomsg=msg)
    if (ios /= 0) return
    word = scheme; sweep_word = sweep; length = l
    s%tolerance = tolerance; s%rel_tolerance = rel_tolerance
    s%max_iterations = max_iterations; s%stall_iterations = stall_iterations
    s%max_rounds = max_rounds; s%anderson_depth = anderson_depth
    s%anderson_mixing = anderson_mixing; s%weight_cutoff = weight_cutoff
  end subroutine read_nonlocal

end module wellposed_mpm_deck_shared
