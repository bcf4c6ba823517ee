!> The summary keys of eqs. 2.1-2.2 at a bar's stations: per station the
!> largest fall of sigma_xx against the load's sign inside the region of
!> nonuniqueness (its middle half, and the whole) and the peak's speed (wellposed_mpm_admissibility
!> measures them); docs/research/waves.md, "Eqs. 2.1-2.2 at the stations".
module wellposed_mpm_bar_admissibility
  use wellposed_kinds, only: dp
  use wellposed_text, only: int_text
  use wellposed_summary, only: summary_t
  use wellposed_mpm_admissibility, only: admissibility_t, station_admissibility
  implicit none
  private
  public :: add_admissibility

contains

  !> The summary keys of eqs. 2.1-2.2 for stations at x(:) with histories
  !> sxx(station, sample) at time(:): per station the fall and its share of
  !> the peak, the peak's speed; over the stations the largest share and
  !> whether every peak travelled between C_E and C_P. `why` non-empty: the
  !> scene has no region of nonuniqueness (not a pulse, or C_P <= C_E).
  subroutine add_admissibility(sm, x, time, sxx, sgn, t_s, tau, c_e, c_p, why)
    type(summary_t), intent(inout) :: sm
    real(dp), intent(in) :: x(:), time(:), sxx(:, :), sgn, t_s, tau, c_e, c_p
    character(len=*), intent(in) :: why
    type(admissibility_t) :: a
    character(len=:), allocatable :: tag
    real(dp) :: worst
    integer :: i, iworst
    logical :: within
    if (len(why) > 0) then
      call sm%not_applicable('eq2_1_largest_fall_ratio', why)
      call sm%not_applicable('eq2_2_peaks_within', why)
      return
    end if
    call sm%add('eq2_definition', 'eq. 2.1: largest fall of sigma_xx against the load''s '// &
      'sign over the middle half of t_s + tau/2 + x/C_P <= t <= t_s + tau/2 + x/C_E (0: '// &
      'sigma-dot keeps the load''s sign there; _region: the whole interval, fronts '// &
      'included), over the station''s peak; eq. 2.2: the peak''s speed x/(t_peak - t_s - '// &
      'tau/2) between C_E and C_P')
    worst = 0.0_dp
    iworst = 0
    within = .true.
    do i = 1, size(x)
      a = station_admissibility(time, sxx(i, :), x(i), sgn, t_s, tau, c_e, c_p)
      tag = 'station_'//int_text(i)
      if (a%samples < 2 .or. .not. a%peak > 0.0_dp) then
        call sm%not_applicable(tag//'_eq2_1_fall', 'the record holds fewer than 2 samples '// &
                               'of the region, or no pulse')
        within = .false.
        cycle
      end if
      call sm%add(tag//'_eq2_1_fall', a%fall, 'Pa, in the middle half of the region')
      call sm%add(tag//'_eq2_1_fall_ratio', a%fall/a%peak, 'of the station''s peak')
      call sm%add(tag//'_eq2_1_region_fall_ratio', a%fall_region/a%peak, &
                  'over the whole region, the fronts'' numerical spread included')
      call sm%add(tag//'_eq2_2_peak_speed', a%peak_speed, 'm/s; eq. 2.2: C_E < v < C_P')
      if (a%fall/a%peak > worst .or. iworst == 0) then
        worst = a%fall/a%peak
        iworst = i
      end if
      within = within .and. a%peak_speed >= c_e .and. a%peak_speed <= c_p
    end do
    if (iworst > 0) then
      call sm%add('eq2_1_largest_fall_ratio', worst, 'the largest station_<i>_eq2_1_fall_ratio')
      call sm%add('eq2_1_worst_station', iworst)
    else
      call sm%not_applicable('eq2_1_largest_fall_ratio', 'no station''s record holds its region')
    end if
    call sm%add('eq2_2_peaks_within', within, 'every station''s peak speed in [C_E, C_P]')
  end subroutine add_admissibility

end module wellposed_mpm_bar_admissibility
