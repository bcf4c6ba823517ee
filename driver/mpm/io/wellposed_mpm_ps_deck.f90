!> The plane-strain MPM deck (chapter 4's plate): namelist groups read into
!> a ps_config_t plus the list of cases a figure needs (meshes, sizes), with
!> the wellposed_deck conventions (every message names file, group, key).
!>   &scene     name, title
!>   &plate     width, height (m); deprecated: weak_x(2), weak_y(2) (m),
!>              weak_k0 (Pa), read as a second &material (a copy of the
!>              first with k0 = weak_k0) in the box weak_x by weak_y
!>   &grid      dx (m), ppc (per direction), pad_cells, shape ('cpdi'|'gimp'|'linear')
!>   &time      t_end (s), cfl, scheme ('musl'|'usl'), stop_on_cutback (end a
!>              case cleanly when a particle has softened to zero strength:
!>              the UMAT's cut-back)
!>   &material  one or more groups (wellposed_mpm_material_deck): density
!>              (kg/m^3), nstatv, our named keys (K, G, beta, beta_p, k0, h,
!>              h_zeta, L, ...) or props = <list> (any UMAT), and a region
!>              (x and y ranges, or 'rest')
!>   &boundary  bottom ('roller'|'fixed'|'free'), top ('velocity'|'free'),
!>              sides ('free'|'roller'), top_velocity (m/s), ramp_time (s),
!>              top_lateral ('fixed': v_x = 0 on the top as the dissertation; 'free')
!>   &viscosity a1, a2 (shared reference B; 0 switches a term off)
!>   &nonlocal  scheme ('fixed_point'|'anderson'), tolerance, rel_tolerance,
!>              max_iterations, stall_iterations, max_rounds, anderson_depth,
!>              anderson_mixing, weight_cutoff (wellposed_mpm_nonlocal)
!>   &study     dx(:) (m), scale(:): one run per entry, the plate, weak zone,
!>              top velocity and t_end scaled by `scale` (fig. 4.6), the mesh
!>              by dx; label(:) optional names. Absent: one run at &grid dx.
!>   &output    snapshot_dt (s), sample_dt (s), band_y (m, the line across the
!>              band where its width is measured, in units of the unscaled
!>              plate), band_axis ('x': along y = band_y; 'y': along x =
!>              band_x, for a column), band_x (m), band_time (s: when to
!>              measure it; 0: at the end of each case), band_drop (the
!>              stage where the band is measured normal to itself: the
!>              apparent stress this fraction below its peak; default 0.05),
!>              band_onset_strain (||eps^p|| whose first crossing marks where
!>              the band starts; default 1e-3), progress, plot
!> Overrides from the command line, `group.key=value`, are read after the
!> deck as one-line namelists.
module wellposed_mpm_ps_deck
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_deck, only: namelist_error, check_finite, has_group, unset, &
                            is_set, lower, check_word
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_mpm_material_deck, only: read_materials, material_defaults_t, &
                                         is_material_group
  use wellposed_mpm_materials, only: add_material, check_regions, first_material
  use wellposed_umat_layout, only: prop_k0
  use wellposed_mpm_deck_file, only: open_deck, override_line
  use wellposed_mpm_scene_kind, only: check_scene_name
  use wellposed_mpm_plane_strain, only: ps_config_t, bc2_names, bc_roller, bc_fixed2, bc_free2, &
                                        bc_velocity
  use wellposed_mpm_shape_2d, only: shape2d_names
  use wellposed_mpm_nonlocal, only: nl_scheme_names, nl_scheme_id
  use wellposed_mpm_config, only: scheme_names
  implicit none
  private
  public :: read_ps_deck, ps_study_t

  integer, parameter :: max_cases = 16

  !> The cases of one deck and the output settings.
  type :: ps_study_t
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
    !> the onset threshold of ||eps^p|| (wellposed_mpm_band_watch)
    real(dp) :: band_drop = 0.05_dp, band_onset_strain = 1.0e-3_dp
    logical :: progress = .true.
    logical :: plot = .true.
    !> A cut-back the UMAT cannot resolve (a particle softened to zero
    !> strength) ends the case at the last complete step instead of failing.
    logical :: stop_on_cutback = .false.
  end type ps_study_t

contains

  !> Read `path` and the overrides into cfg (the first case's config) and study.
  subroutine read_ps_deck(path, overrides, cfg, cases, text, err)
    character(len=*), intent(in) :: path, overrides(:)
    type(ps_config_t), intent(out) :: cfg
    type(ps_study_t), intent(out) :: cases
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    character(len=64) :: name
    character(len=200) :: title
    character(len=16) :: kind   !< 'plate' (read by wellposed_mpm_scene_kind)
    real(dp) :: width, height, weak_x(2), weak_y(2), weak_k0
    real(dp) :: dx(max_cases), scale(max_cases)
    character(len=32) :: label(max_cases)
    integer :: ppc, pad_cells, max_iterations, stall_iterations, max_rounds, &
               anderson_depth
    character(len=16) :: shape, bottom, top, sides, scheme, top_lateral, band_axis, time_scheme
    real(dp) :: t_end, cfl
    type(material_defaults_t) :: mdef
    real(dp) :: top_velocity, ramp_time, a1, a2, tolerance, rel_tolerance, anderson_mixing, &
                weight_cutoff, snapshot_dt, sample_dt, band_y, band_x, band_time, &
                band_drop, band_onset_strain
    logical :: progress, plot, stop_on_cutback
    namelist /scene/ name, title, kind
    namelist /plate/ width, height, weak_x, weak_y, weak_k0
    namelist /grid/ dx, ppc, pad_cells, shape
    namelist /time/ t_end, cfl, scheme, stop_on_cutback
    namelist /boundary/ bottom, top, sides, top_velocity, ramp_time, top_lateral
    namelist /viscosity/ a1, a2
    namelist /nonlocal/ scheme, tolerance, rel_tolerance, max_iterations, stall_iterations, &
      max_rounds, anderson_depth, anderson_mixing, weight_cutoff
    namelist /study/ dx, scale, label
    namelist /output/ snapshot_dt, sample_dt, band_y, band_x, band_axis, band_time, &
      band_drop, band_onset_strain, progress, plot
    integer :: unit, ios, i, nc
    character(len=512) :: msg
    character(len=:), allocatable :: line, group
    character(len=9), parameter :: groups(9) = [character(len=9) :: 'scene', 'plate', 'grid', &
      'time', 'boundary', 'viscosity', 'nonlocal', 'study', 'output']

    name = ''   ! a deck names its scene (wellposed_mpm_deck_file)
    title = 'plane-strain plate (fig. 4.1 of the dissertation)'
    kind = 'plate'
    width = cfg%width; height = cfg%height
    weak_x = unset; weak_y = unset; weak_k0 = unset
    dx = unset; dx(1) = cfg%dx
    scale = unset
    label = ''
    ppc = cfg%ppc; pad_cells = cfg%pad_cells; shape = 'cpdi'
    t_end = cfg%t_end; cfl = cfg%cfl; stop_on_cutback = .false.
    mdef%density = cfg%density; mdef%nstatv = cfg%nstatv
    mdef%named = 0.0_dp
    mdef%named(1:6) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 400.0e6_dp, -4.0e9_dp]
    bottom = 'roller'; top = 'velocity'; sides = 'free'; top_lateral = 'fixed'
    top_velocity = cfg%top_velocity; ramp_time = cfg%ramp_time
    a1 = cfg%visc_a1; a2 = cfg%visc_a2
    scheme = 'fixed_point'
    time_scheme = 'musl'
    tolerance = cfg%nonlocal%tolerance; rel_tolerance = cfg%nonlocal%rel_tolerance
    max_iterations = cfg%nonlocal%max_iterations
    stall_iterations = cfg%nonlocal%stall_iterations
    max_rounds = cfg%nonlocal%max_rounds; anderson_depth = cfg%nonlocal%anderson_depth
    anderson_mixing = cfg%nonlocal%anderson_mixing
    weight_cutoff = cfg%nonlocal%weight_cutoff
    snapshot_dt = 0.0_dp; sample_dt = 0.0_dp; band_y = 2.5_dp; band_x = 0.0_dp; band_time = 0.0_dp
    band_axis = 'x'
    band_drop = 0.05_dp; band_onset_strain = 1.0e-3_dp
    progress = .true.; plot = .true.

    call open_deck(path, text, unit, err)
    if (allocated(err)) return
    do i = 1, size(groups)
      if (.not. has_group(text, trim(groups(i)))) cycle
      rewind (unit)
      call read_group(trim(groups(i)), unit=unit)
      if (ios /= 0) then
        close (unit)
        err = namelist_error(path, trim(groups(i)), ios, msg, text)
        return
      end if
    end do
    close (unit)
    do i = 1, size(overrides)
      call override_line(overrides(i), group, line, err)
      if (allocated(err)) return
      if (is_material_group(group)) cycle   ! read_materials reads them
      if (.not. any(groups == group)) then
        call new_error(err, status_invalid, group, 'override "'//trim(overrides(i))// &
          '": no group &'//group)
        return
      end if
      call read_group(group, text=line)
      if (ios /= 0) then
        err = namelist_error('command line', group, ios, msg, line)
        return
      end if
    end do

    cfg%name = trim(name)
    cfg%title = trim(title)
    call check_scene_name(path, cfg%name, err)
    if (allocated(err)) return
    call check_finite(path, 'plate', 'width', [width, height], err)
    if (allocated(err)) return
    cfg%width = width; cfg%height = height
    cfg%ppc = ppc; cfg%pad_cells = pad_cells
    cfg%shape = word(shape, shape2d_names, 'grid', 'shape'); if (allocated(err)) return
    cfg%t_end = t_end; cfg%cfl = cfl
    cfg%scheme = word(time_scheme, scheme_names, 'time', 'scheme'); if (allocated(err)) return
    call check_finite(path, 'time', 'cfl', [t_end, cfl], err); if (allocated(err)) return
    call read_materials(path, text, overrides, 2, mdef, cfg%materials, cfg%density, err)
    if (allocated(err)) return
    call legacy_weak_zone(); if (allocated(err)) return
    call first_material(cfg%materials, cfg%props, cfg%nprops, cfg%nstatv)
    cfg%bottom = word(bottom, bc2_names, 'boundary', 'bottom'); if (allocated(err)) return
    cfg%top = word(top, bc2_names, 'boundary', 'top'); if (allocated(err)) return
    cfg%sides = word(sides, bc2_names, 'boundary', 'sides'); if (allocated(err)) return
    if (cfg%bottom == bc_velocity .or. cfg%sides == bc_velocity .or. cfg%sides == bc_fixed2 &
        .or. cfg%top == bc_roller .or. cfg%top == bc_fixed2) then
      call new_error(err, status_invalid, 'boundary', path//': &boundary: bottom is '// &
        "'roller', 'fixed' or 'free'; top is 'velocity' or 'free'; sides are 'free' or "// &
        "'roller'"); return
    end if
    cfg%top_velocity = top_velocity; cfg%ramp_time = ramp_time
    select case (lower(trim(top_lateral)))
    case ('fixed')
      cfg%top_lateral_fixed = .true.
    case ('free')
      cfg%top_lateral_fixed = .false.
    case default
      call new_error(err, status_invalid, 'top_lateral', path//": &boundary: top_lateral = '"// &
        trim(top_lateral)//"' is not one of 'fixed' (v_x = 0 on the top, the dissertation's), 'free'")
      return
    end select
    call check_finite(path, 'boundary', 'top_velocity', [top_velocity, ramp_time], err)
    if (allocated(err)) return
    cfg%visc_a1 = a1; cfg%visc_a2 = a2
    cfg%nonlocal%scheme = nl_scheme_id(lower(trim(scheme)))
    if (cfg%nonlocal%scheme == 0) then
      i = word(scheme, nl_scheme_names, 'nonlocal', 'scheme'); return
    end if
    cfg%nonlocal%tolerance = tolerance; cfg%nonlocal%rel_tolerance = rel_tolerance
    cfg%nonlocal%max_iterations = max_iterations
    cfg%nonlocal%stall_iterations = stall_iterations
    cfg%nonlocal%max_rounds = max_rounds; cfg%nonlocal%anderson_depth = anderson_depth
    cfg%nonlocal%anderson_mixing = anderson_mixing
    cfg%nonlocal%weight_cutoff = weight_cutoff

    nc = count(is_set(dx))
    if (nc < 1 .or. .not. all(is_set(dx(1:nc)))) then
      call new_error(err, status_invalid, 'dx', path//': &study/&grid: dx must be one or '// &
        'more cell sizes without gaps'); return
    end if
    cases%ncases = nc
    cases%dx(1:nc) = dx(1:nc)
    cases%scale(1:nc) = 1.0_dp
    do i = 1, nc
      if (is_set(scale(i))) cases%scale(i) = scale(i)
      if (.not. (cases%dx(i) > 0.0_dp .and. cases%scale(i) > 0.0_dp)) then
        call new_error(err, status_invalid, 'dx', path//': &study: dx and scale must be > 0 '// &
          '(entry '//int_text(i)//')'); return
      end if
      cases%label(i) = label(i)
    end do
    cfg%dx = cases%dx(1)
    cases%snapshot_dt = snapshot_dt; cases%sample_dt = sample_dt; cases%band_y = band_y
    cases%band_x = band_x
    cases%band_time = band_time
    call check_finite(path, 'output', 'band_drop', band_drop, err)
    if (allocated(err)) return
    call check_finite(path, 'output', 'band_onset_strain', band_onset_strain, err)
    if (allocated(err)) return
    if (.not. (band_drop > 0.0_dp .and. band_drop < 1.0_dp .and. band_onset_strain > 0.0_dp)) then
      call new_error(err, status_invalid, 'band_drop', path//': &output: band_drop must lie '// &
        'in (0, 1) and band_onset_strain be > 0'); return
    end if
    cases%band_drop = band_drop; cases%band_onset_strain = band_onset_strain
    select case (lower(trim(band_axis)))
    case ('x', 'y')
      cases%band_axis = lower(trim(band_axis))
    case default
      call new_error(err, status_invalid, 'band_axis', path//": &output: band_axis = '"// &
        trim(band_axis)//"' is not one of 'x' (along y = band_y), 'y' (along x = band_x)")
      return
    end select
    cases%progress = progress; cases%plot = plot
    cases%stop_on_cutback = stop_on_cutback

  contains

    subroutine read_group(grp, unit, text)
      character(len=*), intent(in) :: grp
      integer, intent(in), optional :: unit
      character(len=*), intent(in), optional :: text
      character(len=16) :: nl_word
      select case (grp)
      case ('scene')
        if (present(unit)) read (unit, nml=scene, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=scene, iostat=ios, iomsg=msg)
      case ('plate')
        if (present(unit)) read (unit, nml=plate, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=plate, iostat=ios, iomsg=msg)
      case ('grid')
        if (present(unit)) read (unit, nml=grid, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=grid, iostat=ios, iomsg=msg)
      case ('time')
        ! &time and &nonlocal both have a key `scheme`: the one variable
        ! holds &time's while &time is read
        nl_word = scheme
        scheme = time_scheme
        if (present(unit)) read (unit, nml=time, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=time, iostat=ios, iomsg=msg)
        time_scheme = scheme
        scheme = nl_word
      case ('boundary')
        if (present(unit)) read (unit, nml=boundary, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=boundary, iostat=ios, iomsg=msg)
      case ('viscosity')
        if (present(unit)) read (unit, nml=viscosity, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=viscosity, iostat=ios, iomsg=msg)
      case ('nonlocal')
        if (present(unit)) read (unit, nml=nonlocal, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=nonlocal, iostat=ios, iomsg=msg)
      case ('study')
        if (present(unit)) read (unit, nml=study, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=study, iostat=ios, iomsg=msg)
      case ('output')
        if (present(unit)) read (unit, nml=output, iostat=ios, iomsg=msg)
        if (present(text)) read (text, nml=output, iostat=ios, iomsg=msg)
      end select
    end subroutine read_group

    integer function word(value, names, grp, key) result(id)
      character(len=*), intent(in) :: value, names(:), grp, key
      call check_word(path, grp, key, value, names, id, err)
    end function word

    !> The deprecated &plate weak_x, weak_y, weak_k0 (defaults 0, 1; 0, 1;
    !> 375 MPa as before): a second material, the first's PROPS with k0 =
    !> weak_k0, in the box weak_x by weak_y (none when weak_k0 = 0).
    subroutine legacy_weak_zone()
      real(dp) :: pr(size(cfg%materials%props, 1))
      integer :: np
      if (.not. (any(is_set([weak_x, weak_y])) .or. is_set(weak_k0))) return
      write (error_unit, '(a)') path//': &plate weak_x, weak_y, weak_k0 are deprecated '// &
        '(read for one more release): give the weak zone as a second &material with a box '// &
        'region (docs/decks.md)'
      if (.not. is_set(weak_k0)) weak_k0 = 375.0e6_dp
      if (.not. all(is_set(weak_x))) weak_x = [0.0_dp, 1.0_dp]
      if (.not. all(is_set(weak_y))) weak_y = [0.0_dp, 1.0_dp]
      call check_finite(path, 'plate', 'weak_k0', [weak_k0, weak_x, weak_y], err)
      if (allocated(err)) return
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

  end subroutine read_ps_deck

end module wellposed_mpm_ps_deck
