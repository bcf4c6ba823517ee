!> The studies a `wellposed-point` deck asks for at the end of its path:
!> &probe (the acoustic tensor, R(theta), wave speeds and Gudehus
!> envelopes of the probed state) and &chapter3 (the directional stiffness
!> cycles of chapter 3), read and checked. Keys: docs/guide/decks.md.
module wellposed_point_deck_studies
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: namelist_error, check_required, check_finite, check_range, unset, &
                            is_set, has_group, value_text
  use wellposed_point_chapter3, only: ch3_config_t
  implicit none
  private
  public :: probe_config_t, read_probe, read_chapter3

  !> Probe settings (&probe).
  type :: probe_config_t
    logical :: enabled = .false.
    integer :: at_leg = -1             !< state probed: end of this leg (0: initial; -1: last)
    logical :: rtheta = .true.
    integer :: n_theta = 360
    logical :: acoustic = .true.
    integer :: n_polar = 91, n_azimuth = 90
    logical :: wave = .true.
    real(dp) :: wave_sign = 1.0_dp
    logical :: gudehus = .false.
    real(dp) :: gudehus_size = 0.0_dp
    integer :: n_gudehus = 72
    integer :: n_sub = 10
  end type probe_config_t

contains

  !> &probe of the deck `path` (its text `text`, open on `unit`, `nlegs`
  !> legs) into `cfg` (enabled when the deck has the group).
  subroutine read_probe(path, text, nlegs, unit, cfg, err)
    character(len=*), intent(in) :: path, text
    integer, intent(in) :: nlegs, unit
    type(probe_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    integer :: at_leg, n_theta, n_polar, n_azimuth, n_gudehus, n_sub, ios
    logical :: rtheta, acoustic, wave, gudehus
    real(dp) :: wave_sign, gudehus_size
    character(len=512) :: msg
    namelist /probe/ at_leg, rtheta, n_theta, acoustic, n_polar, n_azimuth, wave, wave_sign, &
      gudehus, gudehus_size, n_gudehus, n_sub
    if (.not. has_group(text, 'probe')) return
    at_leg = -1; rtheta = .true.; n_theta = 360; acoustic = .true.; n_polar = 91
    n_azimuth = 90; wave = .true.; wave_sign = 1.0_dp; gudehus = .false.
    gudehus_size = unset; n_gudehus = 72; n_sub = 10
    rewind (unit)
    read (unit, nml=probe, iostat=ios, iomsg=msg)
    if (ios /= 0) then
      err = namelist_error(path, 'probe', ios, msg, text); return
    end if
    if (at_leg == -1) at_leg = nlegs
    call check_range(path, 'probe', 'at_leg', at_leg, 0, nlegs, err)
    if (allocated(err)) return
    call check_range(path, 'probe', 'n_theta', n_theta, 8, 100000, err)
    if (allocated(err)) return
    call check_range(path, 'probe', 'n_polar', n_polar, 2, 10000, err)
    if (allocated(err)) return
    call check_range(path, 'probe', 'n_azimuth', n_azimuth, 1, 10000, err)
    if (allocated(err)) return
    if (wave_sign /= 1.0_dp .and. wave_sign /= -1.0_dp) then
      call new_error(err, status_invalid, 'wave_sign', path//': &probe: wave_sign = '// &
        value_text(wave_sign)//' must be 1 (extension) or -1 (compression)'); return
    end if
    if (gudehus) then
      call check_required(path, 'probe', 'gudehus_size', is_set(gudehus_size), err)
      if (allocated(err)) return
      call check_range(path, 'probe', 'gudehus_size', gudehus_size, tiny(1.0_dp), &
                       huge(1.0_dp), err)
      if (allocated(err)) return
    end if
    call check_range(path, 'probe', 'n_gudehus', n_gudehus, 4, 10000, err)
    if (allocated(err)) return
    call check_range(path, 'probe', 'n_sub', n_sub, 1, 10000, err)
    if (allocated(err)) return
    if (acoustic .and. at_leg == 0) then
      call new_error(err, status_invalid, 'at_leg', path//': &probe: acoustic = .true. '// &
        'needs at_leg >= 1 (the tangent is that of continued loading along the leg)'); return
    end if
    cfg = probe_config_t(.true., at_leg, rtheta, n_theta, acoustic, n_polar, n_azimuth, &
      wave, wave_sign, gudehus, gudehus_size, n_gudehus, n_sub)
  end subroutine read_probe

  !> &chapter3 of the deck `path` (its text `text`, open on `unit`) into
  !> `ch3`; `enabled` when the deck has the group.
  subroutine read_chapter3(path, text, unit, enabled, ch3, err)
    character(len=*), intent(in) :: path, text
    integer, intent(in) :: unit
    logical, intent(inout) :: enabled
    type(ch3_config_t), intent(inout) :: ch3
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: magnitude, phi(4), drift_axial
    integer :: n_cycles, analysis_cycle, n_sub, ios
    character(len=512) :: msg
    namelist /chapter3/ magnitude, phi, n_cycles, analysis_cycle, drift_axial, n_sub
    if (.not. has_group(text, 'chapter3')) return
    magnitude = unset
    phi = [90.0_dp, 180.0_dp, 35.0_dp, 125.0_dp]
    n_cycles = 3
    analysis_cycle = 2
    drift_axial = unset
    n_sub = 10
    rewind (unit)
    read (unit, nml=chapter3, iostat=ios, iomsg=msg)
    if (ios /= 0) then
      err = namelist_error(path, 'chapter3', ios, msg, text); return
    end if
    call check_required(path, 'chapter3', 'magnitude', is_set(magnitude), err)
    if (allocated(err)) return
    call check_range(path, 'chapter3', 'magnitude', magnitude, tiny(1.0_dp), huge(1.0_dp), err)
    if (allocated(err)) return
    call check_finite(path, 'chapter3', 'phi', phi, err)
    if (allocated(err)) return
    if (.not. is_set(drift_axial)) drift_axial = -4.0_dp*magnitude
    call check_finite(path, 'chapter3', 'drift_axial', drift_axial, err)
    if (allocated(err)) return
    call check_range(path, 'chapter3', 'n_cycles', n_cycles, 3, 1000, err)
    if (allocated(err)) return
    call check_range(path, 'chapter3', 'analysis_cycle', analysis_cycle, 2, n_cycles - 1, err)
    if (allocated(err)) return
    call check_range(path, 'chapter3', 'n_sub', n_sub, 1, 10000, err)
    if (allocated(err)) return
    enabled = .true.
    ch3 = ch3_config_t(magnitude, phi, n_cycles, analysis_cycle, drift_axial, n_sub)
  end subroutine read_chapter3

end module wellposed_point_deck_studies
