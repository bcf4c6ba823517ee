!> The bar's MPM deck: the shared groups (wellposed_mpm_deck_shared, with
!> the bar's defaults: the Sandler-Rubin case of shared reference A), the
!> bar's own &initial (stress, velocity, out_of_equilibrium), &load (base,
!> peak, duration, start, pulse; ramp_sine: rate, amplitude, frequency) and
!> &stations (first, spacing, count), and &output's reference keys, into a
!> bar_config_t; the defaults of &time mass and cfl follow the deck's other
!> keys. Overrides `group.key=value` are read after the deck as one-line
!> namelists, under the same rules. Keys: docs/guide/decks.md.
module wellposed_mpm_bar_deck
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: check_range, check_finite, unset, is_set, value_text, check_word
  use wellposed_mpm_deck_file, only: deck_groups_t, read_sources
  use wellposed_mpm_deck_shared, only: shared_deck_t, read_shared_deck
  use wellposed_mpm_scene_kind, only: kind_words_t
  use wellposed_mpm_materials, only: first_material
  use wellposed_mpm_material_deck, only: check_boxes
  use wellposed_mpm_bar_config
  use wellposed_mpm_bar_reference, only: check_reference
  use wellposed_mpm_bar_cfl_limit, only: cfl_limit
  use wellposed_mpm_method, only: implicit_scheme
  use wellposed_text, only: int_text, real_text
  implicit none
  private
  public :: read_bar_deck, bar_options_t, bar_words

  !> Driver options that are not part of the physics.
  type :: bar_options_t
    logical :: plot = .true.           !< run the plot script at the end
    character(len=:), allocatable :: reference, reference_label  !< &output
    !> why the deck, naming no &time mass, runs lumped (unallocated: it does not)
    character(len=:), allocatable :: mass_note
  end type bar_options_t

  character(len=8), parameter :: bar_groups(3) = [character(len=8) :: 'initial', 'load', &
    'stations']

  !> The bar's own groups as read, before their checks: &initial, &load
  !> and &stations.
  type, extends(deck_groups_t) :: bar_keys_t
    real(dp) :: stress(6) = 0.0_dp, velocity = 0.0_dp
    logical :: out_of_equilibrium = .false.
    real(dp) :: base = 0.0_dp, peak = 0.0_dp, duration = 0.0_dp, start = 0.0_dp
    real(dp) :: rate = 0.0_dp, amplitude = 0.0_dp, frequency = 0.0_dp
    character(len=16) :: pulse = 'triangle'
    integer :: count = 0
    real(dp) :: first = 0.0_dp, spacing = 0.0_dp
  contains
    procedure :: read_group => read_bar_group
  end type bar_keys_t

contains

  !> What decks say of the bar: &scene kind = 'bar', the default kind
  !> (no marking group), and its keys of the shared groups.
  pure function bar_words() result(words)
    type(kind_words_t) :: words
    words%name = 'bar'
    words%what = 'the 1D bar'
    words%groups = bar_groups
    words%marks = [character(len=16) ::]
    words%keys = [character(len=32) :: 'grid.length', 'grid.far_end', 'time.mass', &
                  'output.reference', 'output.reference_label']
  end function bar_words

  !> Read `path` (and then the overrides, each "group.key=value") into cfg;
  !> `kinds`: the program's scene kinds (for messages on their keys).
  subroutine read_bar_deck(path, overrides, kinds, cfg, opts, text, err)
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: overrides(:)
    type(kind_words_t), intent(in) :: kinds(:)
    type(bar_config_t), intent(out) :: cfg
    type(bar_options_t), intent(out) :: opts
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    type(shared_deck_t) :: sh
    type(bar_keys_t) :: k
    call bar_defaults(cfg, sh)
    call read_shared_deck(path, overrides, kinds, 'bar', shape_names, bc_names, &
                          sh, text, err)
    if (allocated(err)) return
    call shared_into_config(sh, cfg)
    call step_defaults(sh%mass_given, sh%cfl_given, cfg, opts%mass_note)
    if (ieee_is_finite(cfg%length)) then    ! else the scene's check names the length
      call check_boxes(cfg%materials, [cfg%length], 'the bar [0, '//real_text(cfg%length)// &
                       '] m (&grid length)', err)
      if (allocated(err)) return
    end if
    k%stress = cfg%stress0; k%velocity = cfg%velocity0; k%out_of_equilibrium = .false.
    k%base = cfg%load_base; k%peak = cfg%load_peak; k%duration = cfg%load_duration
    k%start = cfg%load_start; k%pulse = 'triangle'
    k%rate = unset; k%amplitude = unset; k%frequency = unset
    k%first = cfg%station_first; k%spacing = cfg%station_spacing; k%count = cfg%nstations
    call read_sources(k, path, text, overrides, bar_groups, err)
    if (allocated(err)) return
    call keys_into_config(path, k, cfg, err); if (allocated(err)) return
    opts%plot = sh%plot
    opts%reference = trim(sh%reference); opts%reference_label = trim(sh%reference_label)
    call check_reference(path, cfg%name, opts%reference, err)
  end subroutine read_bar_deck

  !> The bar's defaults (the Sandler-Rubin case of shared reference A) of
  !> the shared groups, from cfg's.
  subroutine bar_defaults(cfg, sh)
    type(bar_config_t), intent(in) :: cfg
    type(shared_deck_t), intent(inout) :: sh
    sh%ndim = 1
    sh%title = 'Sandler-Rubin case study'
    sh%length = cfg%length; sh%dx = cfg%dx; sh%ppc = cfg%ppc; sh%pad_cells = cfg%pad_cells
    sh%shape = 'gimp'; sh%far_end = 'fixed'; sh%scheme = 'musl'
    sh%mass = mass_names(cfg%mass)
    sh%t_end = cfg%t_end; sh%cfl = cfg%cfl
    sh%visc_a1 = cfg%visc_a1; sh%visc_a2 = cfg%visc_a2
    sh%sample_dt = cfg%sample_dt; sh%snapshot_dt = cfg%snapshot_dt
    sh%mdef%density = cfg%density
    sh%mdef%nstatv = cfg%nstatv
    sh%mdef%named = 0.0_dp
    sh%mdef%named(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
    sh%nonlocal = cfg%nonlocal
  end subroutine bar_defaults

  !> The shared groups' values into cfg.
  subroutine shared_into_config(sh, cfg)
    type(shared_deck_t), intent(in) :: sh
    type(bar_config_t), intent(inout) :: cfg
    cfg%name = trim(sh%name)
    cfg%title = trim(sh%title)
    cfg%length = sh%length; cfg%dx = sh%dx; cfg%ppc = sh%ppc
    cfg%pad_cells = sh%pad_cells
    cfg%shape = sh%shape_id; cfg%bc_far = sh%far_end_id; cfg%scheme = sh%scheme_id
    cfg%implicit_dt = sh%implicit_dt; cfg%linear_solver = sh%linear_solver_id
    cfg%mass = sh%mass_id
    cfg%t_end = sh%t_end; cfg%cfl = sh%cfl
    cfg%visc_a1 = sh%visc_a1; cfg%visc_a2 = sh%visc_a2
    cfg%materials = sh%materials
    cfg%density = sh%density
    call first_material(cfg%materials, cfg%props, cfg%nprops, cfg%nstatv)
    cfg%sample_dt = sh%sample_dt; cfg%snapshot_dt = sh%snapshot_dt
    cfg%progress = sh%progress
    cfg%nonlocal = sh%nonlocal
  end subroutine shared_into_config

  !> The &time mass and cfl the deck leaves out (docs/research/timestep.md,
  !> "The blended mass on the unstable materials"): the blended mass, the one that converges
  !> on the fig. 2.8 grid, unless it cannot run the deck (ppc = 1: M_P has
  !> no inverse; a given cfl above its stability limit), then the lumped one,
  !> and `note` says why; cfl_blended with MUSL and the blended mass, else
  !> cfl_dissertation, below every scheme's limit.
  subroutine step_defaults(mass_given, cfl_given, cfg, note)
    logical, intent(in) :: mass_given, cfl_given
    type(bar_config_t), intent(inout) :: cfg
    character(len=:), allocatable, intent(out) :: note
    real(dp) :: limit
    character(len=12) :: lim_text, cfl_text
    if (.not. mass_given .and. implicit_scheme(cfg%scheme)) then
      cfg%mass = mass_lumped        ! the implicit schemes' (eq. 4.9), check_implicit
    else if (.not. mass_given) then
      cfg%mass = mass_blended
      limit = cfl_limit(cfg%scheme, mass_blended, cfg%ppc)
      if (cfg%ppc == 1) then
        note = 'with ppc = 1 (the particles'' mass matrix has no inverse)'
      else if (cfl_given .and. cfg%cfl > limit) then
        write (lim_text, '(f6.4)') limit
        write (cfl_text, '(g0.4)') cfg%cfl
        note = 'at cfl = '//trim(cfl_text)//' (above its limit '//trim(lim_text)// &
               ' with scheme = '''//trim(scheme_names(cfg%scheme))//''')'
      end if
      if (allocated(note)) then
        cfg%mass = mass_lumped
        note = 'mass = ''lumped'': the deck names no &time mass, and the default '// &
               '''blended'' cannot run '//note//'; docs/research/timestep.md'
      end if
    end if
    if (.not. cfl_given) cfg%cfl = merge(cfl_blended, cfl_dissertation, &
                                         cfg%mass == mass_blended .and. cfg%scheme == scheme_musl)
  end subroutine step_defaults

  !> &initial, &load and &stations checked, into cfg.
  subroutine keys_into_config(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(bar_keys_t), intent(in) :: k
    type(bar_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    call check_word(path, 'load', 'pulse', k%pulse, pulse_names, cfg%pulse, err)
    if (allocated(err)) return
    cfg%stress0 = k%stress; cfg%velocity0 = k%velocity
    cfg%out_of_equilibrium = k%out_of_equilibrium
    call check_finite(path, 'initial', 'stress', k%stress, err); if (allocated(err)) return
    call check_finite(path, 'initial', 'velocity', k%velocity, err); if (allocated(err)) return
    call load_keys(path, k, err); if (allocated(err)) return
    cfg%load_base = k%base; cfg%load_peak = k%peak; cfg%load_duration = k%duration
    cfg%load_start = k%start
    call ramp_sine_keys(path, k, cfg, err); if (allocated(err)) return
    cfg%station_first = k%first; cfg%station_spacing = k%spacing; cfg%nstations = k%count
    call check_range(path, 'stations', 'count', k%count, 0, 1000, err)
    if (allocated(err)) return
    call check_finite(path, 'stations', 'first', k%first, err); if (allocated(err)) return
    call check_finite(path, 'stations', 'spacing', k%spacing, err); if (allocated(err)) return
    if (k%count > 1 .and. .not. k%spacing > 0.0_dp) then
      call new_error(err, status_invalid, 'spacing', path//': &stations: spacing = '// &
        real_text(k%spacing)//' m must be > 0 with count = '//int_text(k%count)// &
        ' (stations at distinct points of the bar)')
    end if
  end subroutine keys_into_config

  !> &load base, peak, duration and start finite, duration and start >= 0
  !> (a pulse that ended before t = 0 would leave the run unloaded).
  subroutine load_keys(path, k, err)
    character(len=*), intent(in) :: path
    type(bar_keys_t), intent(in) :: k
    type(error_t), allocatable, intent(out) :: err
    character(len=*), parameter :: keys(4) = [character(len=8) :: 'base', 'peak', &
                                              'duration', 'start']
    real(dp) :: values(4)
    integer :: j
    values = [k%base, k%peak, k%duration, k%start]
    do j = 1, 4
      call check_finite(path, 'load', trim(keys(j)), values(j), err)
      if (allocated(err)) return
      if (j >= 3 .and. values(j) < 0.0_dp) then
        call new_error(err, status_invalid, trim(keys(j)), path//': &load: '// &
          trim(keys(j))//' = '//real_text(values(j))//' s must be >= 0'); return
      end if
    end do
  end subroutine load_keys

  !> The keys of pulse = 'ramp_sine' (eq. of wellposed_mpm_bar_loads): all
  !> three given and finite, frequency > 0, and |amplitude| 2 pi frequency
  !> < |rate| so that the surface stress rate never changes sign (a
  !> reversal would unload the material elastically and the measured
  !> speed would no longer be the linearised loading one). With another
  !> pulse the keys are refused rather than silently ignored.
  subroutine ramp_sine_keys(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(bar_keys_t), intent(in) :: k
    type(bar_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    character(len=*), parameter :: keys(3) = [character(len=9) :: 'rate', 'amplitude', &
                                              'frequency']
    real(dp) :: values(3)
    integer :: j
    real(dp), parameter :: two_pi = 6.28318530717958647692_dp
    values = [k%rate, k%amplitude, k%frequency]
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
    if (.not. k%frequency > 0.0_dp) then
      call new_error(err, status_invalid, 'frequency', path//': &load: frequency = '// &
        value_text(k%frequency)//' must be > 0 Hz'); return
    end if
    if (.not. two_pi*k%frequency*abs(k%amplitude) < abs(k%rate)) then
      call new_error(err, status_invalid, 'amplitude', path//': &load: amplitude = '// &
        value_text(k%amplitude)//' Pa at frequency = '//value_text(k%frequency)//' Hz changes '// &
        'the surface stress at up to 2 pi frequency |amplitude| = '// &
        value_text(two_pi*k%frequency*abs(k%amplitude))//' Pa/s, which must stay below |rate| '// &
        '= '//value_text(abs(k%rate))//" Pa/s: with pulse = 'ramp_sine' the surface must "// &
        'never unload'); return
    end if
    cfg%load_rate = k%rate; cfg%load_amplitude = k%amplitude; cfg%load_frequency = k%frequency
  end subroutine ramp_sine_keys

  !> One READ of the bar's group `grp` from the deck (`unit`) or an
  !> override `line` into k.
  subroutine read_bar_group(self, grp, ios, msg, unit, line)
    class(bar_keys_t), intent(inout) :: self
    character(len=*), intent(in) :: grp
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: stress(6), velocity
    logical :: out_of_equilibrium
    real(dp) :: base, peak, duration, start, rate, amplitude, frequency
    integer :: count
    real(dp) :: first, spacing
    character(len=16) :: pulse
    namelist /initial/ stress, velocity, out_of_equilibrium
    namelist /load/ base, peak, duration, start, pulse, rate, amplitude, frequency
    namelist /stations/ first, spacing, count
    stress = self%stress; velocity = self%velocity
    out_of_equilibrium = self%out_of_equilibrium
    base = self%base; peak = self%peak; duration = self%duration; start = self%start
    pulse = self%pulse; rate = self%rate; amplitude = self%amplitude
    frequency = self%frequency
    first = self%first; spacing = self%spacing; count = self%count
    ios = 0
    select case (grp)
    case ('initial')
      if (present(unit)) read (unit, nml=initial, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=initial, iostat=ios, iomsg=msg)
    case ('load')
      if (present(unit)) read (unit, nml=load, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=load, iostat=ios, iomsg=msg)
    case ('stations')
      if (present(unit)) read (unit, nml=stations, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=stations, iostat=ios, iomsg=msg)
    end select
    self%stress = stress; self%velocity = velocity
    self%out_of_equilibrium = out_of_equilibrium
    self%base = base; self%peak = peak; self%duration = duration; self%start = start
    self%pulse = pulse; self%rate = rate; self%amplitude = amplitude
    self%frequency = frequency
    self%first = first; self%spacing = spacing; self%count = count
  end subroutine read_bar_group

end module wellposed_mpm_bar_deck
