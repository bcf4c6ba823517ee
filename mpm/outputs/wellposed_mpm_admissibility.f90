!> Eqs. 2.1-2.2 at a bar's station (section 2.2): in the region of
!> nonuniqueness between the plastic head at C_P and the elastic tail at
!> C_E the stress rate keeps the load's sign (eq. 2.1) and the region moves
!> at C_E < v < C_P (eq. 2.2). At x it passes over t_s + tau/2 + x/C_P <= t
!> <= t_s + tau/2 + x/C_E; its middle half leaves out the fronts' numerical
!> spread (docs/research/waves.md, "Eqs. 2.1-2.2 at the stations").
module wellposed_mpm_admissibility
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: admissibility_t, station_admissibility

  !> One station's measures.
  type :: admissibility_t
    real(dp) :: t_from = 0.0_dp, t_to = 0.0_dp  !< the region's window (s)
    real(dp) :: fall = 0.0_dp       !< Pa, largest fall of sgn*sigma_xx in its middle half
    real(dp) :: fall_region = 0.0_dp  !< Pa, the same over the whole window
    real(dp) :: peak = 0.0_dp       !< Pa, largest sgn*(sigma_xx - sigma_xx(0)) of the record
    real(dp) :: peak_speed = 0.0_dp !< m/s, x/(t_peak - t_s - tau/2); 0 if not after tau/2
    integer :: samples = 0          !< samples in the window's middle half
  end type admissibility_t

contains

  !> The measures of the history sxx(:) at time(:) of the station at x for
  !> a load of sign sgn (+1 tensile), start t_s and duration tau, wave
  !> speeds c_e < c_p. A fall is max over t1 < t2 in a window of
  !> sgn*(sxx(t1) - sxx(t2)): 0 when eq. 2.1 holds at every sample.
  pure function station_admissibility(time, sxx, x, sgn, t_s, tau, c_e, c_p) result(a)
    real(dp), intent(in) :: time(:), sxx(:), x, sgn, t_s, tau, c_e, c_p
    type(admissibility_t) :: a
    real(dp) :: d, q
    integer :: kpk, m
    a%t_from = t_s + 0.5_dp*tau + x/c_p
    a%t_to = t_s + 0.5_dp*tau + x/c_e
    q = 0.25_dp*(a%t_to - a%t_from)
    call largest_fall(time, sgn*sxx, a%t_from, a%t_to, a%fall_region, m)
    call largest_fall(time, sgn*sxx, a%t_from + q, a%t_to - q, a%fall, a%samples)
    if (size(time) == 0) return
    kpk = maxloc(sgn*(sxx - sxx(1)), 1)
    a%peak = sgn*(sxx(kpk) - sxx(1))
    d = time(kpk) - t_s - 0.5_dp*tau
    if (d > 0.0_dp) a%peak_speed = x/d
  end function station_admissibility

  !> max over t0 <= t1 < t2 <= t3 of s(t1) - s(t2) on the samples of
  !> [t0, t3] (m of them); 0 for a non-decreasing s.
  pure subroutine largest_fall(time, s, t0, t3, fall, m)
    real(dp), intent(in) :: time(:), s(:), t0, t3
    real(dp), intent(out) :: fall
    integer, intent(out) :: m
    real(dp) :: top
    integer :: k
    fall = 0.0_dp
    top = -huge(1.0_dp)
    m = 0
    do k = 1, size(time)
      if (time(k) < t0 .or. time(k) > t3) cycle
      m = m + 1
      top = max(top, s(k))
      fall = max(fall, top - s(k))
    end do
  end subroutine largest_fall

end module wellposed_mpm_admissibility
