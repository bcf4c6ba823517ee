!> Stations: stress and velocity histories at fixed material points (the
!> the dissertation's "locations", fig. 2.3-2.10: every 100 m), and the measures taken
!> from them. A station at reference position X reads the two particles whose
!> reference positions bracket X, linearly interpolated; histories are sampled
!> at exact multiples of sample_dt by linear interpolation between steps, so
!> runs with different dx or CFL fractions share one time axis (the mesh
!> study subtracts them).
module wellposed_mpm_stations
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use wellposed_kinds, only: dp
  use wellposed_mpm_config, only: mpm_config_t
  use wellposed_mpm_particles, only: particles_t
  implicit none
  private
  public :: stations_t, new_stations, sample_stations, station_measures_t, &
            measure_stations, fit_speed, nfields, field_sxx, field_syy, field_v, field_z

  !> Sampled fields per station: sigma_xx, sigma_yy (Pa), v_x (m/s), z.
  integer, parameter :: field_sxx = 1, field_syy = 2, field_v = 3, field_z = 4, nfields = 4

  type :: stations_t
    integer :: n = 0
    real(dp), allocatable :: x(:)          !< reference positions (m)
    integer, allocatable :: pa(:), pb(:)   !< bracketing particles
    real(dp), allocatable :: wb(:)         !< weight of pb
    real(dp) :: sample_dt = 0.0_dp
    integer :: ns = 0                      !< samples taken
    real(dp), allocatable :: time(:)       !< (ns) s
    real(dp), allocatable :: hist(:, :, :) !< (nfields, station, sample)
    real(dp) :: t_prev = 0.0_dp
    real(dp), allocatable :: prev(:, :)    !< (nfields, station) at t_prev
  end type stations_t

  !> Measures of one run's station histories (fig. 2.3 read by eye,
  !> here in numbers). Arrival times are NaN where the signal never arrived.
  type :: station_measures_t
    real(dp), allocatable :: peak(:)       !< max of sigma_xx - sigma_xx(0) (Pa)
    real(dp), allocatable :: t_peak(:)     !< its time (s)
    real(dp), allocatable :: t_head(:)     !< upward crossing of `threshold` before t_peak (s)
    real(dp), allocatable :: t_tail(:)     !< downward crossing of it after t_peak (s)
    real(dp), allocatable :: width(:)      !< t_tail - t_head (s)
    real(dp) :: threshold = 0.0_dp         !< crossing level (Pa)
    real(dp) :: c_head = 0.0_dp            !< least-squares dx/dt of t_head (m/s), NaN if < 2
    real(dp) :: c_tail = 0.0_dp            !< same for t_tail
  end type station_measures_t

contains

  !> Stations of `cfg` on the particles `parts` (reference positions x0).
  subroutine new_stations(self, cfg, parts, t_end)
    type(stations_t), intent(out) :: self
    type(mpm_config_t), intent(in) :: cfg
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: t_end
    integer :: s, p, nmax
    self%n = cfg%nstations
    allocate (self%x(self%n), self%pa(self%n), self%pb(self%n), self%wb(self%n))
    do s = 1, self%n
      self%x(s) = cfg%station_first + (s - 1)*cfg%station_spacing
      ! particles are laid out in order of x0 (1D): find the bracketing pair
      p = count(parts%x0(1, 1:parts%n) <= self%x(s))
      p = max(1, min(parts%n - 1, p))
      self%pa(s) = p
      self%pb(s) = p + 1
      self%wb(s) = (self%x(s) - parts%x0(1, p))/(parts%x0(1, p + 1) - parts%x0(1, p))
      self%wb(s) = max(0.0_dp, min(1.0_dp, self%wb(s)))
    end do
    self%sample_dt = cfg%sample_dt
    nmax = int(t_end/cfg%sample_dt) + 2
    allocate (self%time(nmax), self%hist(nfields, self%n, nmax), self%prev(nfields, self%n))
    self%ns = 0
    self%t_prev = 0.0_dp
    call current(self, parts, self%prev)
    self%ns = 1
    self%time(1) = 0.0_dp
    self%hist(:, :, 1) = self%prev
  end subroutine new_stations

  !> Record every sample time in (t_prev, t] by interpolation to time t.
  subroutine sample_stations(self, parts, t)
    type(stations_t), intent(inout) :: self
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: t
    real(dp) :: now(nfields, self%n), ts, a
    do
      ts = self%ns*self%sample_dt
      if (ts > t*(1.0_dp + 1.0e-12_dp) .or. self%ns >= size(self%time)) exit
      if (self%ns == 0) exit
      call current(self, parts, now)
      a = (ts - self%t_prev)/(t - self%t_prev)
      self%ns = self%ns + 1
      self%time(self%ns) = ts
      self%hist(:, :, self%ns) = (1.0_dp - a)*self%prev + a*now
    end do
    call current(self, parts, self%prev)
    self%t_prev = t
  end subroutine sample_stations

  pure subroutine current(self, parts, now)
    type(stations_t), intent(in) :: self
    type(particles_t), intent(in) :: parts
    real(dp), intent(out) :: now(:, :)
    integer :: s, a, b
    real(dp) :: w
    do s = 1, self%n
      a = self%pa(s); b = self%pb(s); w = self%wb(s)
      now(field_sxx, s) = (1.0_dp - w)*parts%stress(1, a) + w*parts%stress(1, b)
      now(field_syy, s) = (1.0_dp - w)*parts%stress(2, a) + w*parts%stress(2, b)
      now(field_v, s) = (1.0_dp - w)*parts%v(1, a) + w*parts%v(1, b)
      now(field_z, s) = (1.0_dp - w)*parts%statev(1, a) + w*parts%statev(1, b)
    end do
  end subroutine current

  !> Peak, head and tail arrival and width at every station from the
  !> histories (time(ns), sxx(station, ns)). The signal d is sigma_xx minus
  !> its value at t = 0 (tension positive); the main pulse is the one that
  !> holds the largest d, at t_peak. With `level` (Pa, the drivers pass half
  !> the load peak):
  !>  - head: the last upward crossing of `level` before t_peak,
  !>  - tail: the first downward crossing of `level` after t_peak,
  !> both linearly interpolated between samples; width = tail - head.
  !> Restricting the crossings to the pulse around the peak keeps the
  !> grid's elastic ringing behind the pulse (GIMP, linear) from being read
  !> as a late tail, and half the load peak lies far above that ringing.
  !> For the admissible solution of shared reference A (rise from x/C_P over
  !> tau/2, plateau, fall over tau/2 ending at x/C_E + tau) the head is
  !> x/C_P + tau/4 and the tail x/C_E + 3 tau/4, so the fitted head and tail
  !> speeds are C_P and C_E and width = x (1/C_E - 1/C_P) + tau/2.
  pure subroutine measure_stations(time, sxx, xs, level, m)
    real(dp), intent(in) :: time(:), sxx(:, :), xs(:), level
    type(station_measures_t), intent(out) :: m
    integer :: s, k, ns, nst, kmax
    real(dp) :: d(size(time)), nan
    nan = ieee_value(0.0_dp, ieee_quiet_nan)
    nst = size(sxx, 1)
    ns = size(time)
    allocate (m%peak(nst), m%t_peak(nst), m%t_head(nst), m%t_tail(nst), m%width(nst))
    m%threshold = level
    do s = 1, nst
      d = sxx(s, :) - sxx(s, 1)
      kmax = maxloc(d, 1)
      m%peak(s) = d(kmax)
      m%t_peak(s) = time(kmax)
      m%t_head(s) = nan
      m%t_tail(s) = nan
      if (m%peak(s) >= level .and. level > 0.0_dp) then
        do k = kmax, 2, -1
          if (d(k - 1) < level .and. d(k) >= level) then
            m%t_head(s) = cross(k); exit
          end if
        end do
        do k = kmax + 1, ns
          if (d(k - 1) >= level .and. d(k) < level) then
            m%t_tail(s) = cross(k); exit
          end if
        end do
      end if
      m%width(s) = m%t_tail(s) - m%t_head(s)
    end do
    m%c_head = fit_speed(xs, m%t_head)
    m%c_tail = fit_speed(xs, m%t_tail)
  contains
    pure real(dp) function cross(k)
      integer, intent(in) :: k
      cross = time(k - 1) + (level - d(k - 1))/(d(k) - d(k - 1))*(time(k) - time(k - 1))
    end function cross
  end subroutine measure_stations

  !> Least-squares slope dx/dt of positions xs against arrival times t
  !> (NaN entries skipped); NaN with fewer than two arrivals. m/s.
  pure real(dp) function fit_speed(xs, t)
    real(dp), intent(in) :: xs(:), t(:)
    logical :: ok(size(t))
    real(dp) :: tm, xm
    integer :: n
    ok = t == t
    n = count(ok)
    if (n < 2) then
      fit_speed = ieee_value(0.0_dp, ieee_quiet_nan)
      return
    end if
    tm = sum(t, mask=ok)/n
    xm = sum(xs, mask=ok)/n
    fit_speed = sum((t - tm)*(xs - xm), mask=ok)/sum((t - tm)**2, mask=ok)
  end function fit_speed

end module wellposed_mpm_stations
