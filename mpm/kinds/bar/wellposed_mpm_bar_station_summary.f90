!> The station figures of a bar's summary.txt (wellposed_mpm_stations
!> measures them): head and tail speeds, per station the signed peak,
!> arrivals and width beside shared reference A (docs/research/cases.md), where the
!> apex was reached, and the phase speed of a ramp with a sinusoid (fig.
!> 2.10 left). The head is compared with C_P, or for an overlocal material
!> with its dispersion relation's low-frequency limit (head_speed). A figure
!> that does not apply is `not_applicable  # why` (docs/guide/decks.md).
module wellposed_mpm_bar_station_summary
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_text, only: int_text, real_text
  use wellposed_summary, only: summary_t
  use wellposed_mpm_bar_config, only: bar_config_t, pulse_ramp_sine
  use wellposed_mpm_method, only: scheme_implicit
  use wellposed_mpm_stations, only: station_measures_t, find_apex, phase_speed
  use wellposed_umat_host, only: umat_is_ours
  use wellposed_error, only: error_t
  use wellposed_umat_layout, only: prop_h, prop_h_zeta
  use wellposed_mpm_bar_build, only: probe_moduli
  implicit none
  private
  public :: add_station_summary, head_speed

  !> The speed the head of a plastic pulse runs at and how it was found.
  type, public :: head_speed_t
    real(dp) :: c = 0.0_dp                 !< m/s; 0 when not known
    character(len=:), allocatable :: what  !< the summary comment, or why not known
  end type head_speed_t

contains

  !> The speed of the head of a plastic pulse in the scene `cfg` with the
  !> UMAT's loading speed c_p: c_p for a local material; with Algorithm 1
  !> (`overlocal`) the low-frequency limit of the overlocal dispersion
  !> relation (fig. 2.10 left): a uniform field has <dlambda> = dlambda,
  !> so zeta hardens with h_zeta as eta with h_eta (eq. 4.24) and the head
  !> runs at the local speed with h_eta + h_zeta, probed through the UMAT
  !> with PROPS(6) = h_eta + h_zeta, PROPS(12) = 0. For a user's UMAT
  !> (nonlocal_contract) that slot meaning is not known: c = 0.
  function head_speed(cfg, overlocal, c_p) result(head)
    type(bar_config_t), intent(in) :: cfg
    logical, intent(in) :: overlocal
    real(dp), intent(in) :: c_p
    type(head_speed_t) :: head
    type(error_t), allocatable :: err
    real(dp) :: props(cfg%nprops), m_e, m_p
    head%c = c_p
    head%what = 'm/s, C_P of the UMAT''s loading modulus at the initial state'
    if (.not. overlocal) return
    head%c = 0.0_dp
    head%what = 'a user''s UMAT with nonlocal_contract: its overlocal head speed is not known'
    if (.not. umat_is_ours() .or. cfg%nprops < prop_h_zeta) return
    props = cfg%props(1:cfg%nprops)
    props(prop_h) = props(prop_h) + props(prop_h_zeta)
    props(prop_h_zeta) = 0.0_dp
    call probe_moduli(cfg, props, m_e, m_p, err)
    if (allocated(err)) then
      ! a softening h_eta + h_zeta: no wave of that speed (not an error of the run)
      head%what = 'the local model with h_eta + h_zeta has no positive loading modulus: '// &
                  'no low-frequency head speed'
      return
    end if
    head%c = sqrt(m_p/cfg%density)
    head%what = 'm/s, C_P(h_eta + h_zeta): the overlocal head speed, the low-frequency '// &
                'limit of its dispersion relation (the UMAT''s loading modulus with h_eta + '// &
                'h_zeta; c_plastic has h_eta alone)'
  end function head_speed

  !> Add the station figures of `meas` (stations at x, histories time,
  !> sxx and the apex flag as sampled) for the scene `cfg` with the UMAT's
  !> wave speeds c_e (unloading) and c_p (loading) at the initial state and
  !> the speed the head runs at (`head`, head_speed).
  subroutine add_station_summary(sm, cfg, x, time, sxx, apex_flag, meas, c_e, c_p, head)
    type(summary_t), intent(inout) :: sm
    type(bar_config_t), intent(in) :: cfg
    real(dp), intent(in) :: x(:), time(:), sxx(:, :), apex_flag(:, :), c_e, c_p
    type(station_measures_t), intent(in) :: meas
    type(head_speed_t), intent(in) :: head
    character(len=:), allocatable :: k, no_pulse, no_ideal, no_speed, who, no_head
    real(dp) :: tau, t_apex, s_apex, c, rms, c_h
    integer :: i, n, apex
    logical :: ramp, ideal, reached(size(x)), ok
    n = size(x)
    tau = cfg%load_duration
    ramp = cfg%pulse == pulse_ramp_sine
    no_pulse = 'the station never saw the pulse cross arrival_threshold'
    no_speed = 'fewer than two stations saw the pulse cross arrival_threshold'
    no_ideal = 'C_P < C_E: the plastic wave trails the elastic one, so the pulse has '// &
               'no admissible solution of reference A to compare with'
    if (ramp) then
      no_pulse = "pulse = 'ramp_sine' is a ramp, not a pulse (see phase_speed)"
      no_speed = no_pulse
      no_ideal = no_pulse
    end if

    c_h = head%c
    no_head = no_speed
    if (.not. c_h > 0.0_dp) no_head = head%what
    ! the admissible solution of reference A is the local model's (C_P, C_E)
    ideal = .not. ramp .and. c_p >= c_e
    if (cfg%scheme == scheme_implicit) then
      ! the quasi-static step has no inertia: every station loads at once
      no_speed = 'scheme = ''implicit'' is quasi-static: no wave, every station loads at once'
      call sm%not_applicable('c_head', no_speed)
      call sm%not_applicable('c_tail', no_speed)
    else
      call sm%add('c_head', meas%c_head, 'm/s, least-squares fit of x against t_head', no_speed)
      call sm%add('c_tail', meas%c_tail, 'm/s, least-squares fit of x against t_tail', no_speed)
    end if
    if (c_h > 0.0_dp) then
      call sm%add('c_plastic_head', c_h, head%what)
    else
      call sm%not_applicable('c_plastic_head', head%what)
    end if
    ! divided only where c_h > 0 (a division by 0 traps under -ffpe-trap)
    if (cfg%scheme == scheme_implicit) then
      call sm%not_applicable('c_head_over_c_plastic', no_speed)
    else if (c_h > 0.0_dp) then
      call sm%add('c_head_over_c_plastic', meas%c_head/c_h, 'c_head/c_plastic_head', no_head)
    else
      call sm%not_applicable('c_head_over_c_plastic', no_head)
    end if
    if (cfg%scheme == scheme_implicit) then
      call sm%not_applicable('c_tail_over_c_elastic', no_speed)
      call sm%not_applicable('separation_rate', no_speed)
    else
      call sm%add('c_tail_over_c_elastic', meas%c_tail/c_e, why=no_speed)
      call sm%add('separation_rate', meas%c_head - meas%c_tail, &
                  'm/s, head minus tail speed (ideal Sandler-Rubin: C_P - C_E)', no_speed)
    end if
    call sm%add('c_plastic_minus_c_elastic', c_p - c_e, 'm/s')
    call sm%add('arrival_threshold', meas%threshold, 'Pa, half the load peak, signed as it')
    call sm%add('arrival_definition', 'head = last crossing of arrival_threshold towards '// &
                'the station peak before it, tail = first crossing back after it (ringing '// &
                'behind the pulse ignored; a compressive pulse is measured with its sign); '// &
                'ideal: x/C_P + tau/4 and x/C_E + 3 tau/4')
    do i = 1, n
      k = 'station_'//int_text(i)
      call sm%add(k//'_x', x(i), 'm')
      call sm%add(k//'_peak', meas%peak(i), 'Pa, signed extreme of sigma_xx - sigma_xx(0)')
      call sm%add(k//'_t_peak', meas%t_peak(i), 's')
      call sm%add(k//'_t_head', meas%t_head(i), 's', no_pulse)
      call sm%add(k//'_t_tail', meas%t_tail(i), 's', no_pulse)
      call sm%add(k//'_width', meas%width(i), 's, t_tail - t_head', no_pulse)
      if (ideal) then
        call sm%add(k//'_width_ideal', x(i)*(1.0_dp/c_e - 1.0_dp/c_p) + 0.5_dp*tau, &
                    's, x (1/C_E - 1/C_P) + tau/2 (admissible solution, reference A)')
        call sm%add(k//'_t_head_ideal', x(i)/c_p + 0.25_dp*tau, 's, x/C_P + tau/4')
        call sm%add(k//'_t_tail_ideal', x(i)/c_e + 0.75_dp*tau, 's, x/C_E + 3 tau/4')
      else
        call sm%not_applicable(k//'_width_ideal', no_ideal)
        call sm%not_applicable(k//'_t_head_ideal', no_ideal)
        call sm%not_applicable(k//'_t_tail_ideal', no_ideal)
      end if
    end do
    if (n >= 2) then
      if (meas%peak(1) /= 0.0_dp) then
        call sm%add('peak_growth', meas%peak(n)/meas%peak(1), 'last station peak over first')
      else
        call sm%not_applicable('peak_growth', 'no pulse at the first station')
      end if
    end if
    call find_apex(time, apex_flag, sxx, apex, t_apex, s_apex, reached)
    ! as the stations' z (STATEV(1)), read whatever a user's UMAT keeps there
    ! (docs/guide/mpm.md); the comment says which UMAT it was
    who = ''
    if (.not. umat_is_ours()) who = ' (a user''s UMAT: its STATEV(12), whatever it holds)'
    if (apex > 0) then
      call sm%add('apex_reached_at_station', apex, 'first station whose material returned '// &
        'to the apex of the cone (STATEV(12) = 2: hydrostatic, I1 = k/beta) at t = '// &
        real_text(t_apex)//' s, sigma_xx = '//real_text(s_apex/1.0e6_dp)//' MPa; '// &
        int_text(count(reached))//' of '//int_text(n)//' stations reached it'//who)
    else
      call sm%add('apex_reached_at_station', 'none', 'no station''s material returned to '// &
                  'the apex of the cone'//who)
    end if
    if (ramp) then
      call phase_speed(time, sxx, x, cfg%load_frequency, min(c_e, c_p), c, rms, ok)
      call sm%add('phase_speed_frequency', cfg%load_frequency, 'Hz, &load frequency')
      if (ok .and. ieee_is_finite(c)) then
        call sm%add('phase_speed', c, 'm/s, of the sinusoid: its phase fitted at every '// &
                    'station after x/min(C_E, C_P) + 2/f, slope of phase against x; not '// &
                    'corrected for the grid''s phase lag')
        call sm%add('phase_speed_rms', rms, 'rad, phase residual about the straight line')
      else
        call sm%not_applicable('phase_speed', 'fewer than two stations hold 20 samples '// &
                               'after x/min(C_E, C_P) + 2/f, or the phase does not advance')
      end if
    end if
  end subroutine add_station_summary

end module wellposed_mpm_bar_station_summary
