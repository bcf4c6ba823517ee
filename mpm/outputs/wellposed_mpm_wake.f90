!> The wake behind a 1D pulse at a station (docs/research/waves.md, "The wake
!> oscillation"): over t >= x/C_E + 2 tau to the end of the record, the
!> largest |sigma_xx(t) - sigma_xx(0)|, its RMS, and the grid-scale part:
!> the largest deviation from a centred moving average over 4 dx/C_E (a
!> smooth continuum signal passes the average, a wave of 2 to 5 cells not).
module wellposed_mpm_wake
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: wake_t, station_wake, wake_start

  !> The wake at one station: the largest deviation, its RMS and the
  !> largest deviation from the moving average (Pa) over `samples` samples
  !> from `t_from` (s); samples = 0: the record ends before t_from, and the
  !> figures are 0.
  type :: wake_t
    real(dp) :: t_from = 0.0_dp
    real(dp) :: amplitude = 0.0_dp
    real(dp) :: rms = 0.0_dp
    real(dp) :: grid = 0.0_dp
    integer :: samples = 0
  end type wake_t

contains

  !> Start of the wake window at a station x (m): x/c_e + 2 tau (s), with
  !> c_e the unloading wave speed (m/s) and tau the pulse's duration (s).
  pure real(dp) function wake_start(x, c_e, tau)
    real(dp), intent(in) :: x, c_e, tau
    wake_start = x/c_e + 2.0_dp*tau
  end function wake_start

  !> The wake of the history sxx(:) sampled at time(:) (ascending, evenly
  !> spaced, time(1) the initial state) over t >= t_from, with the moving
  !> average over `window` (s) for the grid-scale part.
  pure function station_wake(time, sxx, t_from, window) result(w)
    real(dp), intent(in) :: time(:), sxx(:), t_from, window
    type(wake_t) :: w
    real(dp) :: d, s2
    integer :: k, n, h
    n = size(time)
    w%t_from = t_from
    h = 0
    if (n > 1) h = nint(0.5_dp*window/(time(2) - time(1)))
    s2 = 0.0_dp
    do k = 1, n
      if (time(k) < t_from) cycle
      d = abs(sxx(k) - sxx(1))
      w%amplitude = max(w%amplitude, d)
      s2 = s2 + d*d
      w%samples = w%samples + 1
      if (k > h .and. k + h <= n) &
        w%grid = max(w%grid, abs(sxx(k) - sum(sxx(k - h:k + h))/(2*h + 1)))
    end do
    if (w%samples > 0) w%rms = sqrt(s2/w%samples)
  end function station_wake

end module wellposed_mpm_wake
