!> The plate's MPM deck (chapter 4's plane-strain plate): the shared groups
!> (wellposed_mpm_deck_shared, with the plate's defaults) and the plate's
!> own &plate, &boundary, &stations and &study (one run per dx and scale,
!> fig. 4.6), plus the plate's keys of &time (stop_on_cutback) and &output
!> (band_y, band_x, band_axis, band_time, band_drop, band_onset_strain),
!> into a plate_config_t and its list of cases. Overrides `group.key=value`
!> are read after the deck. Keys: docs/guide/decks.md; the platen: docs/research/bands.md.
module wellposed_mpm_plate_deck
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_deck, only: check_finite, unset, is_set, lower, check_word
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_mpm_deck_shared, only: shared_deck_t, read_shared_deck, max_cases
  use wellposed_mpm_materials, only: add_material, check_regions, first_material
  use wellposed_mpm_material_deck, only: check_boxes
  use wellposed_umat_layout, only: prop_k0
  use wellposed_mpm_deck_file, only: deck_groups_t, read_sources, sets_list
  use wellposed_mpm_scene_kind, only: kind_words_t
  use wellposed_mpm_plate_build, only: plate_config_t, plate_bc_names, bc_roller, &
                                       bc_plate_fixed, bc_plate_free, bc_velocity, platen_names
  use wellposed_mpm_shape_2d, only: shape2d_names
  implicit none
  private
  public :: read_plate_deck, plate_study_t, max_stations, plate_words

  character(len=8), parameter :: plate_groups(4) = [character(len=8) :: 'plate', 'boundary', &
    'stations', 'study']
  !> Most stations of a plate deck.
  integer, parameter :: max_stations = 16

  !> The cases of one deck and the output settings.
  type :: plate_study_t
    integer :: ncases = 1
    real(dp) :: dx(max_cases) = 0.0_dp
    real(dp) :: scale(max_cases) = 1.0_dp
    character(len=32) :: label(max_cases) = ''
    real(dp) :: snapshot_dt = 0.0_dp
    real(dp) :: sample_dt = 0.0_dp
    real(dp) :: band_y = 2.5_dp
    !> 'x': the band width is measured along the horizontal line y = band_y;
    !> 'y': along the vertical line x = band_x (a column, a 1D bar)
    character(len=1) :: band_axis = 'x'
    real(dp) :: band_x = 0.0_dp
    !> Time (s) at which the band width is measured (0: at the end), so that
    !> meshes are compared at the same apparent strain.
    real(dp) :: band_time = 0.0_dp
    !> The stage (drop of the apparent stress below its peak, a fraction) and
    !> the onset threshold of ||eps^p|| (wellposed_mpm_plate_band_watch)
    real(dp) :: band_drop = 0.05_dp, band_onset_strain = 1.0e-3_dp
    logical :: progress = .true.
    logical :: plot = .true.
    !> A cut-back the UMAT cannot resolve (a particle softened to zero
    !> strength) ends the case at the last complete step instead of failing.
    logical :: stop_on_cutback = .false.
    !> &stations: the points (m, unscaled plate) whose histories are sampled
    integer :: nstations = 0
    real(dp) :: station_x(max_stations) = 0.0_dp, station_y(max_stations) = 0.0_dp
  end type plate_study_t

  !> The plate's own groups as read, before their checks: &plate,
  !> &boundary, &study and &stations.
  type, extends(deck_groups_t) :: plate_keys_t
    real(dp) :: width = 0.0_dp, height = 0.0_dp, weak_x(2) = 0.0_dp, weak_y(2) = 0.0_dp
    real(dp) :: weak_k0 = 0.0_dp
    real(dp) :: dx(max_cases) = 0.0_dp, scale(max_cases) = 0.0_dp
    character(len=32) :: label(max_cases) = ''
    character(len=16) :: bottom = '', top = '', sides = '', top_lateral = '', platen = ''
    real(dp) :: top_velocity = 0.0_dp, ramp_time = 0.0_dp
    real(dp) :: x(max_stations) = 0.0_dp, y(max_stations) = 0.0_dp
  contains
    procedure :: read_group => read_plate_group
  end type plate_keys_t

contains

  !> What decks say of the plate: &scene kind = 'plate', or a deck with
  !> &plate, &boundary or &study, and its keys of the shared groups.
  pure function plate_words() result(words)
    type(kind_words_t) :: words
    words%name = 'plate'
    words%what = 'the plane-strain plate'
    words%groups = plate_groups
    words%marks = [character(len=16) :: 'plate', 'boundary', 'study']
    words%keys = [character(len=32) :: 'time.stop_on_cutback', 'output.band_y', &
                  'output.band_x', 'output.band_time', 'output.band_drop', &
                  'output.band_onset_strain', 'output.band_axis']
  end function plate_words

  !> Read `path` and the overrides into cfg (the first case's config) and
  !> study; `kinds`: the program's scene kinds (for messages on their keys).
  subroutine read_plate_deck(path, overrides, kinds, cfg, cases, text, err)
    character(len=*), intent(in) :: path, overrides(:)
    type(kind_words_t), intent(in) :: kinds(:)
    type(plate_config_t), intent(out) :: cfg
    type(plate_study_t), intent(out) :: cases
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    type(shared_deck_t) :: sh
    type(plate_keys_t) :: k
    real(dp) :: line_default(2)  !< band_x, band_y when the deck gives none
    call plate_defaults(cfg, sh, line_default)
    call read_shared_deck(path, overrides, kinds, 'plate', shape2d_names, &
                          [character(len=1) ::], sh, text, err)
    if (allocated(err)) return
    k%width = cfg%width; k%height = cfg%height
    k%weak_x = unset; k%weak_y = unset; k%weak_k0 = unset
    k%dx = unset; k%dx(1) = sh%dx; k%scale = unset; k%label = ''
    k%bottom = 'roller'; k%top = 'velocity'; k%sides = 'free'; k%top_lateral = 'fixed'
    k%platen = 'surface'
    k%top_velocity = cfg%top_velocity; k%ramp_time = cfg%ramp_time
    k%x = unset; k%y = unset
    call read_sources(k, path, text, overrides, plate_groups, err)
    if (allocated(err)) return
    call check_finite(path, 'plate', 'width', k%width, err); if (allocated(err)) return
    call check_finite(path, 'plate', 'height', k%height, err); if (allocated(err)) return
    call band_line(path, k, line_default, sh, err); if (allocated(err)) return
    call shared_into_config(path, sh, cfg, cases, err); if (allocated(err)) return
    cfg%width = k%width; cfg%height = k%height
    call legacy_weak_zone(path, k, cfg, err); if (allocated(err)) return
    call check_boxes(cfg%materials, [k%width, k%height], 'the plate [0, '//real_text(k%width)// &
                     '] x [0, '//real_text(k%height)//'] m (&plate width, height)', err)
    if (allocated(err)) return
    call first_material(cfg%materials, cfg%props, cfg%nprops, cfg%nstatv)
    call boundaries(path, k, cfg, err); if (allocated(err)) return
    call study_cases(path, k, cfg, cases, err); if (allocated(err)) return
    call station_points(path, k, cases, err)
  end subroutine read_plate_deck

  !> The plate's defaults of the shared groups, from cfg's; the measuring
  !> line unset, so that a line the deck gives is checked against the
  !> plate and a default one (`line_default`: band_x, band_y) is not.
  subroutine plate_defaults(cfg, sh, line_default)
    type(plate_config_t), intent(in) :: cfg
    type(shared_deck_t), intent(inout) :: sh
    real(dp), intent(out) :: line_default(2)
    sh%ndim = 2
    sh%title = 'plane-strain plate (fig. 4.1 of the dissertation)'
    sh%dx = cfg%dx; sh%ppc = cfg%ppc; sh%pad_cells = cfg%pad_cells; sh%shape = 'cpdi'
    sh%t_end = cfg%t_end; sh%cfl = cfg%cfl; sh%scheme = 'musl'
    sh%visc_a1 = cfg%visc_a1; sh%visc_a2 = cfg%visc_a2
    sh%mdef%density = cfg%density; sh%mdef%nstatv = cfg%nstatv
    sh%mdef%named = 0.0_dp
    sh%mdef%named(1:6) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 400.0e6_dp, -4.0e9_dp]
    sh%nonlocal = cfg%nonlocal
    line_default = [sh%band_x, sh%band_y]
    sh%band_x = unset; sh%band_y = unset
  end subroutine plate_defaults

  !> &output band_y, band_x (the measuring line, on the unscaled plate)
  !> and band_time (>= 0; 0: at the end) finite, and a line the deck
  !> gives on the plate: off it, it would measure nothing and say so
  !> only at the end. A default line is left to the measure.
  subroutine band_line(path, k, line_default, sh, err)
    character(len=*), intent(in) :: path
    type(plate_keys_t), intent(in) :: k
    real(dp), intent(in) :: line_default(2)
    type(shared_deck_t), intent(inout) :: sh
    type(error_t), allocatable, intent(out) :: err
    logical :: given(2)
    given = [is_set(sh%band_x), is_set(sh%band_y)]
    if (.not. given(1)) sh%band_x = line_default(1)
    if (.not. given(2)) sh%band_y = line_default(2)
    call check_finite(path, 'output', 'band_y', sh%band_y, err); if (allocated(err)) return
    call check_finite(path, 'output', 'band_x', sh%band_x, err); if (allocated(err)) return
    call check_finite(path, 'output', 'band_time', sh%band_time, err)
    if (allocated(err)) return
    if (given(2) .and. (sh%band_y < 0.0_dp .or. sh%band_y > k%height)) then
      call new_error(err, status_invalid, 'band_y', path//': &output: band_y = '// &
        real_text(sh%band_y)//' m is off the plate [0, '//real_text(k%height)//'] m (&plate '// &
        'height)'); return
    end if
    if (given(1) .and. (sh%band_x < 0.0_dp .or. sh%band_x > k%width)) then
      call new_error(err, status_invalid, 'band_x', path//': &output: band_x = '// &
        real_text(sh%band_x)//' m is off the plate [0, '//real_text(k%width)//'] m (&plate '// &
        'width)'); return
    end if
    if (sh%band_time < 0.0_dp) call new_error(err, status_invalid, 'band_time', path// &
      ': &output: band_time = '//real_text(sh%band_time)//' s must be >= 0 (0: at the end '// &
      'of each case)')
  end subroutine band_line

  !> &stations x(:), y(:): as many of each, finite, without gaps.
  subroutine station_points(path, k, cases, err)
    character(len=*), intent(in) :: path
    type(plate_keys_t), intent(in) :: k
    type(plate_study_t), intent(inout) :: cases
    type(error_t), allocatable, intent(out) :: err
    integer :: n
    n = count(is_set(k%x))
    if (count(is_set(k%y)) /= n .or. .not. all(is_set(k%x(1:n))) .or. &
        .not. all(is_set(k%y(1:n)))) then
      call new_error(err, status_invalid, 'x', path//': &stations: x and y must give '// &
        'the same number of points, without gaps (up to '//int_text(max_stations)//')')
      return
    end if
    call check_finite(path, 'stations', 'x', k%x(1:n), err); if (allocated(err)) return
    call check_finite(path, 'stations', 'y', k%y(1:n), err); if (allocated(err)) return
    cases%nstations = n
    cases%station_x(1:n) = k%x(1:n)
    cases%station_y(1:n) = k%y(1:n)
  end subroutine station_points

  !> One READ of the plate's group `grp` from the deck (`unit`) or an
  !> override `line` into self (an override of a list replaces the list).
  subroutine read_plate_group(self, grp, ios, msg, unit, line)
    class(plate_keys_t), intent(inout) :: self
    character(len=*), intent(in) :: grp
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: width, height, weak_x(2), weak_y(2), weak_k0
    real(dp) :: dx(max_cases), scale(max_cases)
    character(len=32) :: label(max_cases)
    character(len=16) :: bottom, top, sides, top_lateral, platen
    real(dp) :: top_velocity, ramp_time, x(max_stations), y(max_stations)
    namelist /plate/ width, height, weak_x, weak_y, weak_k0
    namelist /boundary/ bottom, top, sides, top_velocity, ramp_time, top_lateral, platen
    namelist /study/ dx, scale, label
    namelist /stations/ x, y
    width = self%width; height = self%height; weak_x = self%weak_x; weak_y = self%weak_y
    weak_k0 = self%weak_k0
    dx = self%dx; scale = self%scale; label = self%label
    bottom = self%bottom; top = self%top; sides = self%sides; top_lateral = self%top_lateral
    platen = self%platen; top_velocity = self%top_velocity; ramp_time = self%ramp_time
    x = self%x; y = self%y
    ios = 0
    select case (grp)
    case ('plate')
      if (present(unit)) read (unit, nml=plate, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=plate, iostat=ios, iomsg=msg)
    case ('boundary')
      if (present(unit)) read (unit, nml=boundary, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=boundary, iostat=ios, iomsg=msg)
    case ('stations')
      if (present(unit)) read (unit, nml=stations, iostat=ios, iomsg=msg)
      if (present(line)) then
        if (sets_list(line, 'x')) x = unset
        if (sets_list(line, 'y')) y = unset
        read (line, nml=stations, iostat=ios, iomsg=msg)
      end if
    case ('study')
      if (present(unit)) read (unit, nml=study, iostat=ios, iomsg=msg)
      if (present(line)) then
        if (sets_list(line, 'dx')) dx = unset
        if (sets_list(line, 'scale')) scale = unset
        if (sets_list(line, 'label')) label = ''
        read (line, nml=study, iostat=ios, iomsg=msg)
      end if
    end select
    self%width = width; self%height = height; self%weak_x = weak_x; self%weak_y = weak_y
    self%weak_k0 = weak_k0
    self%dx = dx; self%scale = scale; self%label = label
    self%bottom = bottom; self%top = top; self%sides = sides; self%top_lateral = top_lateral
    self%platen = platen; self%top_velocity = top_velocity; self%ramp_time = ramp_time
    self%x = x; self%y = y
  end subroutine read_plate_group

  !> The shared groups' values into cfg and cases.
  subroutine shared_into_config(path, sh, cfg, cases, err)
    character(len=*), intent(in) :: path
    type(shared_deck_t), intent(in) :: sh
    type(plate_config_t), intent(inout) :: cfg
    type(plate_study_t), intent(inout) :: cases
    type(error_t), allocatable, intent(out) :: err
    cfg%name = trim(sh%name)
    cfg%title = trim(sh%title)
    cfg%ppc = sh%ppc; cfg%pad_cells = sh%pad_cells
    cfg%shape = sh%shape_id; cfg%scheme = sh%scheme_id
    cfg%implicit_dt = sh%implicit_dt; cfg%linear_solver = sh%linear_solver_id
    cfg%t_end = sh%t_end; cfg%cfl = sh%cfl
    cfg%visc_a1 = sh%visc_a1; cfg%visc_a2 = sh%visc_a2
    cfg%materials = sh%materials
    cfg%density = sh%density
    cfg%nonlocal = sh%nonlocal
    cases%snapshot_dt = sh%snapshot_dt; cases%sample_dt = sh%sample_dt
    cases%band_y = sh%band_y; cases%band_x = sh%band_x; cases%band_time = sh%band_time
    cases%band_axis = sh%band_axis(1:1)
    call check_finite(path, 'output', 'band_drop', sh%band_drop, err)
    if (allocated(err)) return
    call check_finite(path, 'output', 'band_onset_strain', sh%band_onset_strain, err)
    if (allocated(err)) return
    if (.not. (sh%band_drop > 0.0_dp .and. sh%band_drop < 1.0_dp .and. &
               sh%band_onset_strain > 0.0_dp)) then
      call new_error(err, status_invalid, 'band_drop', path//': &output: band_drop must '// &
        'lie in (0, 1) and band_onset_strain be > 0'); return
    end if
    cases%band_drop = sh%band_drop; cases%band_onset_strain = sh%band_onset_strain
    cases%progress = sh%progress; cases%plot = sh%plot
    cases%stop_on_cutback = sh%stop_on_cutback
  end subroutine shared_into_config

  !> &boundary's words and numbers into cfg.
  subroutine boundaries(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(plate_keys_t), intent(in) :: k
    type(plate_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    call check_word(path, 'boundary', 'bottom', k%bottom, plate_bc_names, cfg%bottom, err)
    if (allocated(err)) return
    call check_word(path, 'boundary', 'top', k%top, plate_bc_names, cfg%top, err)
    if (allocated(err)) return
    call check_word(path, 'boundary', 'sides', k%sides, plate_bc_names, cfg%sides, err)
    if (allocated(err)) return
    if (cfg%bottom == bc_velocity .or. cfg%sides == bc_velocity .or. cfg%sides == bc_plate_fixed &
        .or. cfg%top == bc_roller .or. cfg%top == bc_plate_fixed) then
      call new_error(err, status_invalid, 'boundary', path//': &boundary: bottom is '// &
        "'roller', 'fixed' or 'free'; top is 'velocity' or 'free'; sides are 'free' or "// &
        "'roller'"); return
    end if
    cfg%top_velocity = k%top_velocity; cfg%ramp_time = k%ramp_time
    select case (lower(trim(k%top_lateral)))
    case ('fixed')
      cfg%top_lateral_fixed = .true.
    case ('free')
      cfg%top_lateral_fixed = .false.
    case default
      call new_error(err, status_invalid, 'top_lateral', path//": &boundary: top_lateral "// &
        "= '"//trim(k%top_lateral)//"' is not one of 'fixed' (v_x = 0 on the top, the "// &
        "dissertation's), 'free'")
      return
    end select
    call check_word(path, 'boundary', 'platen', k%platen, platen_names, cfg%platen, err)
    if (allocated(err)) return
    call check_finite(path, 'boundary', 'top_velocity', k%top_velocity, err)
    if (allocated(err)) return
    call check_finite(path, 'boundary', 'ramp_time', k%ramp_time, err)
  end subroutine boundaries

  !> The cases of &study (or &grid dx) into cases and the first case's dx.
  subroutine study_cases(path, k, cfg, cases, err)
    character(len=*), intent(in) :: path
    type(plate_keys_t), intent(in) :: k
    type(plate_config_t), intent(inout) :: cfg
    type(plate_study_t), intent(inout) :: cases
    type(error_t), allocatable, intent(out) :: err
    integer :: nc, j
    nc = count(is_set(k%dx))
    if (nc < 1 .or. .not. all(is_set(k%dx(1:nc)))) then
      call new_error(err, status_invalid, 'dx', path//': &study/&grid: dx must be one or '// &
        'more cell sizes without gaps'); return
    end if
    cases%ncases = nc
    cases%dx(1:nc) = k%dx(1:nc)
    cases%scale(1:nc) = 1.0_dp
    do j = 1, nc
      if (is_set(k%scale(j))) cases%scale(j) = k%scale(j)
      if (.not. (cases%dx(j) > 0.0_dp .and. cases%scale(j) > 0.0_dp)) then
        call new_error(err, status_invalid, 'dx', path//': &study: dx and scale must be '// &
          '> 0 (entry '//int_text(j)//')'); return
      end if
      cases%label(j) = k%label(j)
    end do
    cfg%dx = cases%dx(1)
  end subroutine study_cases

  !> The deprecated &plate weak_x, weak_y, weak_k0 (defaults 0, 1; 0, 1;
  !> 375 MPa as before): a second material, the first's PROPS with k0 =
  !> weak_k0, in the box weak_x by weak_y (none when weak_k0 = 0).
  subroutine legacy_weak_zone(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(plate_keys_t), intent(in) :: k
    type(plate_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: pr(size(cfg%materials%props, 1)), weak_x(2), weak_y(2), weak_k0
    integer :: np
    weak_x = k%weak_x; weak_y = k%weak_y; weak_k0 = k%weak_k0
    if (.not. (any(is_set([weak_x, weak_y])) .or. is_set(weak_k0))) return
    write (error_unit, '(a)') path//': &plate weak_x, weak_y, weak_k0 are deprecated '// &
      '(read for one more release): give the weak zone as a second &material with a box '// &
      'region (docs/guide/decks.md)'
    if (.not. is_set(weak_k0)) weak_k0 = 375.0e6_dp
    if (.not. all(is_set(weak_x))) weak_x = [0.0_dp, 1.0_dp]
    if (.not. all(is_set(weak_y))) weak_y = [0.0_dp, 1.0_dp]
    call check_finite(path, 'plate', 'weak_k0', weak_k0, err); if (allocated(err)) return
    call check_finite(path, 'plate', 'weak_x', weak_x, err); if (allocated(err)) return
    call check_finite(path, 'plate', 'weak_y', weak_y, err); if (allocated(err)) return
    if (weak_k0 == 0.0_dp) return
    np = cfg%materials%nprops(1)
    if (np < prop_k0) then
      call new_error(err, status_invalid, 'weak_k0', path//': &plate: weak_k0 needs '// &
        'PROPS(5) (k0) in the first &material'); return
    end if
    pr(1:np) = cfg%materials%props(1:np, 1)
    pr(prop_k0) = weak_k0
    call add_material(cfg%materials, pr(1:np), cfg%materials%nstatv(1), &
                      cfg%materials%ours(1), cfg%materials%contract(1), err, &
                      [weak_x(1), weak_y(1)], [weak_x(2), weak_y(2)])
    if (allocated(err)) return
    call check_regions(cfg%materials, err)
  end subroutine legacy_weak_zone

end module wellposed_mpm_plate_deck
