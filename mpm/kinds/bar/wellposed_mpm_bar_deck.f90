!> The bar's MPM deck: the shared groups (wellposed_mpm_deck_shared, with
!> the bar's defaults: the Sandler-Rubin case of shared reference A), the
!> bar's own &initial (stress, velocity, out_of_equilibrium), &load (base,
!> peak, duration, start, pulse; ramp_sine: rate, amplitude, frequency) and
!> &stations (first, spacing, count), and &output's reference keys, into an
!> bar_config_t. Overrides `group.key=value` are read after the deck as
!> one-line namelists, under the same rules. Keys: docs/guide/decks.md.
module wellposed_mpm_bar_deck
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: check_range, check_finite, unset, is_set, real_str, check_word
  use wellposed_mpm_deck_file, only: deck_sources_t, start_sources, next_source, read_failed
  use wellposed_mpm_deck_shared, only: shared_deck_t, read_shared_deck
  use wellposed_mpm_scene_kind, only: scene_kind_bar
  use wellposed_mpm_materials, only: first_material
  use wellposed_mpm_material_deck, only: check_boxes
  use wellposed_mpm_bar_config
  use wellposed_mpm_bar_reference, only: check_reference
  use wellposed_text, only: int_text, real_text
  implicit none
  private
  public :: read_bar_deck, bar_options_t

  !> Driver options that are not part of the physics.
  type :: bar_options_t
    logical :: plot = .true.           !< run the plot script at the end
    character(len=:), allocatable :: reference, reference_label  !< &output
  end type bar_options_t

  character(len=8), parameter :: bar_groups(3) = [character(len=8) :: 'initial', 'load', &
    'stations']

contains

  !> Read `path` (and then the overrides, each "group.key=value") into cfg.
  subroutine read_bar_deck(path, overrides, cfg, opts, text, err)
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: overrides(:)
    type(bar_config_t), intent(out) :: cfg
    type(bar_options_t), intent(out) :: opts
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    type(shared_deck_t) :: sh
    real(dp) :: stress(6), velocity
    logical :: out_of_equilibrium
    real(dp) :: base, peak, duration, start, rate, amplitude, frequency
    integer :: count
    real(dp) :: first, spacing
    character(len=16) :: pulse
    type(deck_sources_t) :: src
    character(len=:), allocatable :: grp
    character(len=512) :: rd_msg
    integer :: rd_ios
    namelist /initial/ stress, velocity, out_of_equilibrium
    namelist /load/ base, peak, duration, start, pulse, rate, amplitude, frequency
    namelist /stations/ first, spacing, count

    sh%title = 'Sandler-Rubin case study'
    sh%length = cfg%length; sh%dx = cfg%dx; sh%ppc = cfg%ppc; sh%pad_cells = cfg%pad_cells
    sh%shape = 'gimp'; sh%far_end = 'fixed'; sh%scheme = 'musl'
    sh%t_end = cfg%t_end; sh%cfl = cfg%cfl
    sh%visc_a1 = cfg%visc_a1; sh%visc_a2 = cfg%visc_a2
    sh%sample_dt = cfg%sample_dt; sh%snapshot_dt = cfg%snapshot_dt
    sh%mdef%density = cfg%density
    sh%mdef%nstatv = cfg%nstatv
    sh%mdef%named = 0.0_dp
    sh%mdef%named(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
    sh%nonlocal = cfg%nonlocal
    call read_shared_deck(path, overrides, scene_kind_bar, bar_groups, shape_names, bc_names, &
                          sh, text, err)
    if (allocated(err)) return
    call shared_into_config()
    if (ieee_is_finite(cfg%length)) then    ! else the scene's check names the length
      call check_boxes(cfg%materials, [cfg%length], 'the bar [0, '//real_text(cfg%length)// &
                       '] m (&grid length)', err)
      if (allocated(err)) return
    end if

    stress = cfg%stress0; velocity = cfg%velocity0; out_of_equilibrium = .false.
    base = cfg%load_base; peak = cfg%load_peak; duration = cfg%load_duration
    start = cfg%load_start; pulse = 'triangle'
    rate = unset; amplitude = unset; frequency = unset
    first = cfg%station_first; spacing = cfg%station_spacing; count = cfg%nstations
    call start_sources(src, path, text, overrides, bar_groups, err)
    do while (next_source(src, grp, err))
      call read_group(grp, rd_ios, rd_msg, src%unit, src%line)
      if (read_failed(src, grp, rd_ios, rd_msg, err)) return
    end do
    if (allocated(err)) return

    cfg%pulse = word(pulse, pulse_names, 'load', 'pulse'); if (allocated(err)) return
    cfg%stress0 = stress; cfg%velocity0 = velocity; cfg%out_of_equilibrium = out_of_equilibrium
    call check_finite(path, 'initial', 'stress', stress, err); if (allocated(err)) return
    call check_finite(path, 'initial', 'velocity', velocity, err); if (allocated(err)) return
    call load_keys(); if (allocated(err)) return
    cfg%load_base = base; cfg%load_peak = peak; cfg%load_duration = duration
    cfg%load_start = start
    call ramp_sine_keys(); if (allocated(err)) return
    cfg%station_first = first; cfg%station_spacing = spacing; cfg%nstations = count
    call check_range(path, 'stations', 'count', count, 0, 1000, err)
    if (allocated(err)) return
    call check_finite(path, 'stations', 'first', first, err); if (allocated(err)) return
    call check_finite(path, 'stations', 'spacing', spacing, err); if (allocated(err)) return
    if (count > 1 .and. .not. spacing > 0.0_dp) then
      call new_error(err, status_invalid, 'spacing', path//': &stations: spacing = '// &
        real_text(spacing)//' m must be > 0 with count = '//int_text(count)//' (stations at '// &
        'distinct points of the bar)'); return
    end if
    opts%plot = sh%plot
    opts%reference = trim(sh%reference); opts%reference_label = trim(sh%reference_label)
    call check_reference(path, cfg%name, opts%reference, err); if (allocated(err)) return

  contains

    !> &load base, peak, duration and start finite, duration and start >= 0
    !> (a pulse that ended before t = 0 would leave the run unloaded).
    subroutine load_keys()
      character(len=*), parameter :: keys(4) = [character(len=8) :: 'base', 'peak', &
                                                'duration', 'start']
      real(dp) :: values(4)
      integer :: j
      values = [base, peak, duration, start]
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

    !> One READ of the bar's group `grp` from the deck (`unit`) or an
    !> override `line`.
    !> Each reader keeps its own: a namelist group cannot be an argument.
    subroutine read_group(grp, ios, msg, unit, line)
      character(len=*), intent(in) :: grp
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: msg
      integer, intent(in), optional :: unit
      character(len=*), intent(in), optional :: line
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
    end subroutine read_group

    !> The shared groups' values into cfg.
    subroutine shared_into_config()
      cfg%name = trim(sh%name)
      cfg%title = trim(sh%title)
      cfg%length = sh%length; cfg%dx = sh%dx; cfg%ppc = sh%ppc
      cfg%pad_cells = sh%pad_cells
      cfg%shape = sh%shape_id; cfg%bc_far = sh%far_end_id; cfg%scheme = sh%scheme_id
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

    integer function word(value, names, grp, key) result(id)
      character(len=*), intent(in) :: value, names(:), grp, key
      call check_word(path, grp, key, value, names, id, err)
    end function word

  end subroutine read_bar_deck

end module wellposed_mpm_bar_deck
