!> The admissibility conditions of the Sandler-Rubin pulse at a bar's
!> stations (section 2.2, eqs. 2.1-2.2): where the top of the load's
!> triangle opens into the region of nonuniqueness, between the plastic
!> head at C_P and the elastic tail at C_E, the stress rate keeps the sign
!> of the load (eq. 2.1, 0 <= sigma-dot for the tensile pulse) and the
!> region travels at speeds C_E < v < C_P (eq. 2.2). At a station x the
!> region passes over t_s + tau/2 + x/C_P <= t <= t_s + tau/2 + x/C_E
!> (load start t_s, duration tau). docs/research/waves.md, "Eqs. 2.1-2.2
!> at the stations".
module wellposed_mpm_admissibility
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: admissibility_t, station_admissibility

  !> One station's measures.
  type :: admissibility_t
    real(dp) :: t_from = 0.0_dp, t_to = 0.0_dp  !< the region's window (s)
    real(dp) :: fall = 0.0_dp       !< Pa, largest fall of sgn*sigma_xx inside the window
    real(dp) :: peak = 0.0_dp       !< Pa, largest sgn*(sigma_xx - sigma_xx(0)) of the record
    real(dp) :: peak_speed = 0.0_dp !< m/s, x/(t_peak - t_s - tau/2); 0 if not after tau/2
    integer :: samples = 0          !< samples inside the window
  end type admissibility_t

contains

  !> The measures of the history sxx(:) at time(:) of the station at x for
  !> a load of sign sgn (+1 tensile), start t_s and duration tau, wave
  !> speeds c_e < c_p. The fall is max over t1 < t2 in the window of
  !> sgn*(sxx(t1) - sxx(t2)): 0 when eq. 2.1 holds at every sample.
  pure function station_admissibility(time, sxx, x, sgn, t_s, tau, c_e, c_p) result(a)
    real(dp), intent(in) :: time(:), sxx(:), x, sgn, t_s, tau, c_e, c_p
    type(admissibility_t) :: a
    real(dp) :: top, d
    integer :: k, kpk
    a%t_from = t_s + 0.5_dp*tau + x/c_p
    a%t_to = t_s + 0.5_dp*tau + x/c_e
    top = -huge(1.0_dp)
    do k = 1, size(time)
      if (time(k) < a%t_from .or. time(k) > a%t_to) cycle
      a%samples = a%samples + 1
      top = max(top, sgn*sxx(k))
      a%fall = max(a%fall, top - sgn*sxx(k))
    end do
    if (size(time) == 0) return
    kpk = maxloc(sgn*(sxx - sxx(1)), 1)
    a%peak = sgn*(sxx(kpk) - sxx(1))
    d = time(kpk) - t_s - 0.5_dp*tau
    if (d > 0.0_dp) a%peak_speed = x/d
  end function station_admissibility

end module wellposed_mpm_admissibility
