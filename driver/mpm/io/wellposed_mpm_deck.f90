!> The MPM deck: Fortran namelist groups read into an mpm_config_t
!> (wellposed_deck conventions: every message names file, group and key).
!> Groups (all optional; a missing group or key keeps the default scene,
!> the Sandler-Rubin case of shared reference A):
!>   &scene    name, title
!>   &grid     length (m), dx (m), ppc, pad_cells, shape ('gimp'|'linear'),
!>             far_end ('fixed'|'symmetric'|'free')
!>   &time     t_end (s), cfl (fraction of the CFL step), scheme ('musl'|'usl')
!>   &material one or more groups (wellposed_mpm_material_deck): density
!>             (kg/m^3), nstatv, the named wellposed parameters K, G, beta,
!>             beta_p, k0, h, k_lim, z_ref, P_v, P_d, tau, h_zeta, L (PROPS
!>             1-13) or props = <list> (any UMAT), and a region (x range or
!>             'rest')
!>   &initial  stress (6 values, Pa, Abaqus order, tension +), velocity (m/s),
!>             out_of_equilibrium (stress need not balance the load at t = 0)
!>   &load     base, peak (Pa), duration, start (s), pulse ('triangle'|'cosine'|
!>             'ramp_sine'); ramp_sine only: rate (Pa/s), amplitude (Pa),
!>             frequency (Hz), required, with |amplitude| 2 pi frequency < |rate|
!>             (the surface never unloads); peak and duration are not used
!>   &stations first (m), spacing (m), count
!>   &output   sample_dt (s), snapshot_dt (s), progress, plot, reference, reference_label
!>             (the run drawn dashed in stations.png: wellposed_mpm_reference)
!>   &nonlocal scheme ('fixed_point'|'anderson'), tolerance, rel_tolerance,
!>             max_iterations, stall_iterations, max_rounds, anderson_depth,
!>             anderson_mixing, weight_cutoff (Algorithm 1 of the dissertation; iterates only
!>             when &material h_zeta /= 0)
!> Overrides from the command line, `group.key=value`, are read after the
!> deck as one-line namelists, so they obey the same rules.
module wellposed_mpm_deck
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: namelist_error, check_range, check_finite, &
                            unset, is_set, has_group, real_str, lower, check_word
  use wellposed_mpm_material_deck, only: read_materials, material_defaults_t, &
                                         is_material_group
  use wellposed_mpm_deck_file, only: open_deck, override_line
  use wellposed_mpm_scene_kind, only: check_scene_name
  use wellposed_mpm_materials, only: first_material
  use wellposed_mpm_config
  use wellposed_mpm_nonlocal, only: nonlocal_settings_t, nl_scheme_id
  use wellposed_mpm_reference, only: check_reference
  implicit none
  private
  public :: read_mpm_deck, mpm_options_t

  !> Driver options that are not part of the physics.
  type :: mpm_options_t
    logical :: plot = .true.           !< run the plot script at the end
    character(len=:), allocatable :: reference, reference_label  !< &output
  end type mpm_options_t

contains

  !> Read `path` (and then the overrides, each "group.key=value") into cfg.
  subroutine read_mpm_deck(path, overrides, cfg, opts, text, err)
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: overrides(:)
    type(mpm_config_t), intent(out) :: cfg
    type(mpm_options_t), intent(out) :: opts
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    ! namelist variables (defaults: the default scene)
    character(len=64) :: name
    character(len=200) :: title
    character(len=16) :: kind   !< 'bar' (read by wellposed_mpm_scene_kind)
    real(dp) :: length, dx
    integer :: ppc, pad_cells
    character(len=16) :: shape, far_end, scheme
    real(dp) :: t_end, cfl
    type(material_defaults_t) :: mdef
    real(dp) :: stress(6), velocity
    logical :: out_of_equilibrium
    real(dp) :: base, peak, duration, start, rate, amplitude, frequency
    integer :: count
    real(dp) :: first, spacing
    real(dp) :: sample_dt, snapshot_dt
    logical :: progress, plot
    character(len=200) :: reference, reference_label
    namelist /scene/ name, title, kind
    namelist /grid/ length, dx, ppc, pad_cells, shape, far_end
    namelist /time/ t_end, cfl, scheme
    namelist /initial/ stress, velocity, out_of_equilibrium
    namelist /load/ base, peak, duration, start, pulse, rate, amplitude, frequency
    namelist /stations/ first, spacing, count
    namelist /output/ sample_dt, snapshot_dt, progress, plot, reference, reference_label
    character(len=16) :: pulse
    integer :: unit, ios, i
    character(len=512) :: msg
    character(len=:), allocatable :: line, group

    name = ''   ! a deck names its scene (wellposed_mpm_deck_file)
    title = 'Sandler-Rubin case study'
    kind = 'bar'
    length = cfg%length; dx = cfg%dx; ppc = cfg%ppc; pad_cells = cfg%pad_cells
    shape = 'gimp'; far_end = 'fixed'; scheme = 'musl'
    t_end = cfg%t_end; cfl = cfg%cfl
    mdef%density = cfg%density
    mdef%nstatv = cfg%nstatv
    mdef%named = 0.0_dp
    mdef%named(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
    stress = cfg%stress0; velocity = cfg%velocity0; out_of_equilibrium = .false.
    base = cfg%load_base; peak = cfg%load_peak; duration = cfg%load_duration
    start = cfg%load_start
    rate = unset; amplitude = unset; frequency = unset
    first = cfg%station_first; spacing = cfg%station_spacing; count = cfg%nstations
    sample_dt = cfg%sample_dt; snapshot_dt = cfg%snapshot_dt
    progress = .true.; plot = .true.; reference = ''; reference_label = ''

    call open_deck(path, text, unit, err)
    if (allocated(err)) return
    pulse = 'triangle'
    if (has_group(text, 'scene')) then
      rewind (unit); read (unit, nml=scene, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('scene'); return; end if
    end if
    if (has_group(text, 'grid')) then
      rewind (unit); read (unit, nml=grid, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('grid'); return; end if
    end if
    if (has_group(text, 'time')) then
      rewind (unit); read (unit, nml=time, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('time'); return; end if
    end if
    if (has_group(text, 'initial')) then
      rewind (unit); read (unit, nml=initial, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('initial'); return; end if
    end if
    if (has_group(text, 'load')) then
      rewind (unit); read (unit, nml=load, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('load'); return; end if
    end if
    if (has_group(text, 'stations')) then
      rewind (unit); read (unit, nml=stations, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('stations'); return; end if
    end if
    if (has_group(text, 'output')) then
      rewind (unit); read (unit, nml=output, iostat=ios, iomsg=msg)
      if (ios /= 0) then; call nml_fail('output'); return; end if
    end if
    if (has_group(text, 'nonlocal')) then
      rewind (unit)
      call nonlocal_group(cfg%nonlocal, ios, msg, unit=unit)
      if (ios /= 0) then; call nml_fail('nonlocal'); return; end if
    end if
    close (unit)

    ! command-line overrides: group.key=value
    do i = 1, size(overrides)
      call override_line(overrides(i), group, line, err)
      if (allocated(err)) return
      if (is_material_group(group)) cycle   ! read_materials reads them
      select case (group)
      case ('scene'); read (line, nml=scene, iostat=ios, iomsg=msg)
      case ('grid'); read (line, nml=grid, iostat=ios, iomsg=msg)
      case ('time'); read (line, nml=time, iostat=ios, iomsg=msg)
      case ('initial'); read (line, nml=initial, iostat=ios, iomsg=msg)
      case ('load'); read (line, nml=load, iostat=ios, iomsg=msg)
      case ('stations'); read (line, nml=stations, iostat=ios, iomsg=msg)
      case ('output'); read (line, nml=output, iostat=ios, iomsg=msg)
      case ('nonlocal'); call nonlocal_group(cfg%nonlocal, ios, msg, line=line)
      case default
        call new_error(err, status_invalid, group, 'override "'//trim(overrides(i))// &
          '": no group &'//group); return
      end select
      if (ios /= 0) then
        err = namelist_error('command line', group, ios, msg, line); return
      end if
    end do

    ! ---- into the config, validating the words and the numbers' kinds
    cfg%name = trim(name)
    cfg%title = trim(title)
    call check_scene_name(path, cfg%name, err)
    if (allocated(err)) return
    cfg%length = length; cfg%dx = dx; cfg%ppc = ppc; cfg%pad_cells = pad_cells
    cfg%shape = word(shape, shape_names, 'grid', 'shape'); if (allocated(err)) return
    cfg%bc_far = word(far_end, bc_names, 'grid', 'far_end'); if (allocated(err)) return
    cfg%scheme = word(scheme, scheme_names, 'time', 'scheme'); if (allocated(err)) return
    cfg%pulse = word(pulse, pulse_names, 'load', 'pulse'); if (allocated(err)) return
    cfg%t_end = t_end; cfg%cfl = cfl
    call check_finite(path, 'time', 'cfl', cfl, err); if (allocated(err)) return
    call read_materials(path, text, overrides, 1, mdef, cfg%materials, cfg%density, err)
    if (allocated(err)) return
    call first_material(cfg%materials, cfg%props, cfg%nprops, cfg%nstatv)
    cfg%stress0 = stress; cfg%velocity0 = velocity; cfg%out_of_equilibrium = out_of_equilibrium
    call check_finite(path, 'initial', 'stress', stress, err); if (allocated(err)) return
    cfg%load_base = base; cfg%load_peak = peak; cfg%load_duration = duration
    cfg%load_start = start
    call ramp_sine_keys(); if (allocated(err)) return
    cfg%station_first = first; cfg%station_spacing = spacing; cfg%nstations = count
    call check_range(path, 'stations', 'count', count, 0, 1000, err)
    if (allocated(err)) return
    cfg%sample_dt = sample_dt; cfg%snapshot_dt = snapshot_dt
    cfg%progress = progress
    opts%plot = plot
    opts%reference = trim(reference); opts%reference_label = trim(reference_label)
    call check_reference(path, cfg%name, opts%reference, err); if (allocated(err)) return
    if (cfg%nonlocal%scheme == 0) then
      call new_error(err, status_invalid, 'scheme', path//': &nonlocal: scheme is not one '// &
        "of 'fixed_point', 'anderson'")
      return
    end if

  contains

    !> The keys of pulse = 'ramp_sine' (eq. of wellposed_mpm_loads): all
    !> three given and finite, frequency > 0, and |amplitude| 2 pi frequency
    !> < |rate| so that the surface stress rate never changes sign (a
    !> reversal would unload the material elastically and the measured
    !> speed would no longer be the linearised loading one). With another
    !> pulse the keys are refused rather than silently ignored.
    subroutine ramp_sine_keys()
      character(len=*), parameter :: keys(3) = [character(len=9) :: 'rate', 'amplitude', &
                                                'frequency']
      real(dp) :: values(3)
      integer :: j
      real(dp), parameter :: two_pi = 6.28318530717958647692_dp
      values = [rate, amplitude, frequency]
      if (cfg%pulse /= pulse_ramp_sine) then
        do j = 1, 3
          if (is_set(values(j))) then
            call new_error(err, status_invalid, trim(keys(j)), path//': &load: '// &
              trim(keys(j))//" is used only by pulse = 'ramp_sine' (pulse is '"// &
              trim(pulse_names(cfg%pulse))//"')")
            return
          end if
        end do
        return
      end if
      do j = 1, 3
        if (.not. is_set(values(j))) then
          call new_error(err, status_invalid, trim(keys(j)), path//': &load: key '// &
            trim(keys(j))//" is required with pulse = 'ramp_sine'")
          return
        end if
        call check_finite(path, 'load', trim(keys(j)), values(j), err)
        if (allocated(err)) return
      end do
      if (.not. frequency > 0.0_dp) then
        call new_error(err, status_invalid, 'frequency', path//': &load: frequency = '// &
          real_str(frequency)//' must be > 0 Hz'); return
      end if
      if (.not. two_pi*frequency*abs(amplitude) < abs(rate)) then
        call new_error(err, status_invalid, 'amplitude', path//': &load: amplitude = '// &
          real_str(amplitude)//' Pa at frequency = '//real_str(frequency)//' Hz changes '// &
          'the surface stress at up to 2 pi frequency |amplitude| = '// &
          real_str(two_pi*frequency*abs(amplitude))//' Pa/s, which must stay below |rate| '// &
          '= '//real_str(abs(rate))//" Pa/s: with pulse = 'ramp_sine' the surface must "// &
          'never unload'); return
      end if
      cfg%load_rate = rate; cfg%load_amplitude = amplitude; cfg%load_frequency = frequency
    end subroutine ramp_sine_keys

    subroutine nml_fail(grp)
      character(len=*), intent(in) :: grp
      close (unit)
      err = namelist_error(path, grp, ios, msg, text)
    end subroutine nml_fail

    integer function word(value, names, grp, key) result(id)
      character(len=*), intent(in) :: value, names(:), grp, key
      call check_word(path, grp, key, value, names, id, err)
    end function word

  end subroutine read_mpm_deck

  !> Read the &nonlocal group (from `unit` or the one-line `line`) into `s`.
  !> A scheme word that is not known leaves s%scheme = 0.
  subroutine nonlocal_group(s, ios, msg, unit, line)
    type(nonlocal_settings_t), intent(inout) :: s
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    character(len=16) :: scheme
    real(dp) :: tolerance, rel_tolerance, anderson_mixing, weight_cutoff
    integer :: max_iterations, stall_iterations, max_rounds, anderson_depth
    namelist /nonlocal/ scheme, tolerance, rel_tolerance, max_iterations, &
      stall_iterations, max_rounds, anderson_depth, anderson_mixing, weight_cutoff
    scheme = 'fixed_point'
    if (s%scheme == 2) scheme = 'anderson'
    tolerance = s%tolerance; rel_tolerance = s%rel_tolerance
    max_iterations = s%max_iterations; stall_iterations = s%stall_iterations
    max_rounds = s%max_rounds; anderson_depth = s%anderson_depth
    anderson_mixing = s%anderson_mixing; weight_cutoff = s%weight_cutoff
    ios = 0
    if (present(unit)) read (unit, nml=nonlocal, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=nonlocal, iostat=ios, iomsg=msg)
    if (ios /= 0) return
    s%scheme = nl_scheme_id(lower(trim(scheme)))
    s%tolerance = tolerance; s%rel_tolerance = rel_tolerance
    s%max_iterations = max_iterations; s%stall_iterations = stall_iterations
    s%max_rounds = max_rounds; s%anderson_depth = anderson_depth
    s%anderson_mixing = anderson_mixing; s%weight_cutoff = weight_cutoff
  end subroutine nonlocal_group

end module wellposed_mpm_deck
