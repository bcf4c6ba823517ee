!> Stations: stress and velocity histories at fixed material points (the
!> dissertation's "locations", fig. 2.3-2.10) and the measures taken from
!> them. A bar's station interpolates the two particles bracketing its
!> reference position; a plate's reads the nearest particle. Histories are
!> sampled at exact multiples of sample_dt, interpolated between steps, so
!> runs with different dx or cfl share one time axis.
module wellposed_mpm_stations
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  use wellposed_dense, only: solve_dense
  use wellposed_mpm_particles, only: particles_t
  implicit none
  private
  public :: stations_t, new_stations, place_stations, &
            place_point_stations, start_stations, sample_stations, change_extreme, &
            station_measures_t, measure_stations, fit_speed, find_apex, phase_speed, nfields, &
            field_sxx, field_syy, field_v, field_z, field_apex, field_sxy, field_vy

  !> Sampled fields per station: sigma_xx, sigma_yy (Pa), v_x (m/s), z,
  !> 1 where a bracketing particle's last return was to the apex of the cone
  !> (STATEV(12) = 2 of the UMAT contract) else 0, sigma_xy (Pa), v_y (m/s;
  !> 0 in a bar).
  integer, parameter :: field_sxx = 1, field_syy = 2, field_v = 3, field_z = 4, &
                        field_apex = 5, field_sxy = 6, field_vy = 7, nfields = 7
  !> STATEV(12) of the UMAT contract: the status, 2 for a return to the apex.
  integer, parameter :: sv_status = 12
  real(dp), parameter :: status_apex = 2.0_dp

  type :: stations_t
    integer :: n = 0
    real(dp), allocatable :: x(:)          !< reference positions (m)
    real(dp), allocatable :: y(:)          !< plates: reference y (m) of the particle read
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
  !> here in numbers), signed as the load: for a compressive pulse the peak
  !> is the most negative change and the crossings are of the negative
  !> level. Arrival times are NaN where the signal never arrived.
  type :: station_measures_t
    real(dp), allocatable :: peak(:)       !< signed extreme of sigma_xx - sigma_xx(0) (Pa)
    real(dp), allocatable :: t_peak(:)     !< its time (s)
    real(dp), allocatable :: t_head(:)     !< crossing of `threshold` towards the peak (s)
    real(dp), allocatable :: t_tail(:)     !< crossing of it back after t_peak (s)
    real(dp), allocatable :: width(:)      !< t_tail - t_head (s)
    real(dp) :: threshold = 0.0_dp         !< crossing level (Pa), signed as the load
    real(dp) :: c_head = 0.0_dp            !< least-squares dx/dt of t_head (m/s), NaN if < 2
    real(dp) :: c_tail = 0.0_dp            !< same for t_tail
  end type station_measures_t

contains

  !> `nstations` stations of a bar at x = first + (s - 1) spacing (m) on the
  !> particles `parts` (reference positions x0), sampled every sample_dt.
  subroutine new_stations(self, first, spacing, nstations, parts, sample_dt, t_end)
    type(stations_t), intent(out) :: self
    real(dp), intent(in) :: first, spacing, sample_dt, t_end
    integer, intent(in) :: nstations
    type(particles_t), intent(in) :: parts
    call place_stations(self, first, spacing, nstations, parts%x0(1, 1:parts%n))
    call start_stations(self, parts, sample_dt, t_end)
  end subroutine new_stations

  !> Where a bar's stations read: x0(p), the reference x of every particle
  !> in id order (1D, increasing), gives the bracketing pair pa, pb = pa + 1
  !> (ids) and the weight wb of pb. Histories follow from start_stations.
  subroutine place_stations(self, first, spacing, nstations, x0)
    type(stations_t), intent(out) :: self
    real(dp), intent(in) :: first, spacing, x0(:)
    integer, intent(in) :: nstations
    integer :: s, p, n
    n = size(x0)
    self%n = nstations
    allocate (self%x(self%n), self%y(self%n), self%pa(self%n), self%pb(self%n), &
              self%wb(self%n))
    self%y = 0.0_dp
    do s = 1, self%n
      self%x(s) = first + (s - 1)*spacing
      p = count(x0 <= self%x(s))
      p = max(1, min(n - 1, p))
      self%pa(s) = p
      self%pb(s) = p + 1
      self%wb(s) = (self%x(s) - x0(p))/(x0(p + 1) - x0(p))
      self%wb(s) = max(0.0_dp, min(1.0_dp, self%wb(s)))
    end do
  end subroutine place_stations

  !> Stations of a plate at the reference points (xs(s), ys(s)) (m), each
  !> reading the particle whose reference position x0(1:2, p) (every
  !> particle, in id order) is nearest; x, y become that particle's.
  !> Histories follow from start_stations.
  subroutine place_point_stations(self, xs, ys, x0)
    type(stations_t), intent(out) :: self
    real(dp), intent(in) :: xs(:), ys(:), x0(:, :)
    integer :: s, p
    self%n = size(xs)
    allocate (self%x(self%n), self%y(self%n), self%pa(self%n), self%pb(self%n), &
              self%wb(self%n))
    do s = 1, self%n
      p = minloc((x0(1, :) - xs(s))**2 + (x0(2, :) - ys(s))**2, dim=1)
      self%pa(s) = p
      self%pb(s) = p
      self%wb(s) = 0.0_dp
      self%x(s) = x0(1, p)
      self%y(s) = x0(2, p)
    end do
  end subroutine place_point_stations

  !> The histories of `self` (n, pa, pb, wb set, indices into `parts`) for
  !> samples every sample_dt up to t_end, with the first sample now (t = 0).
  subroutine start_stations(self, parts, sample_dt, t_end)
    type(stations_t), intent(inout) :: self
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: sample_dt, t_end
    integer :: nmax, st
    self%sample_dt = sample_dt
    nmax = int(t_end/sample_dt) + 2
    allocate (self%time(nmax), self%hist(nfields, self%n, nmax), self%prev(nfields, self%n), &
              stat=st)
    if (st /= 0) call out_of_memory('station histories', int(nmax, int64)*self%n, st)
    self%ns = 0
    self%t_prev = 0.0_dp
    call current(self, parts, self%prev)
    self%ns = 1
    self%time(1) = 0.0_dp
    self%hist(:, :, 1) = self%prev
  end subroutine start_stations

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

  !> Sample j of station s's `field` farthest from its value at t = 0, and
  !> that change, signed: the extremes the kinds' summaries give.
  pure subroutine change_extreme(self, field, s, change, j)
    type(stations_t), intent(in) :: self
    integer, intent(in) :: field, s
    real(dp), intent(out) :: change
    integer, intent(out) :: j
    real(dp) :: d(self%ns)
    d = self%hist(field, s, 1:self%ns) - self%hist(field, s, 1)
    j = maxloc(abs(d), dim=1)
    change = d(j)
  end subroutine change_extreme

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
      now(field_sxy, s) = (1.0_dp - w)*parts%stress(4, a) + w*parts%stress(4, b)
      now(field_vy, s) = 0.0_dp
      if (size(parts%v, 1) >= 2) now(field_vy, s) = (1.0_dp - w)*parts%v(2, a) + w*parts%v(2, b)
      now(field_apex, s) = 0.0_dp
      if (size(parts%statev, 1) >= sv_status) then
        if (parts%statev(sv_status, a) == status_apex .or. &
            parts%statev(sv_status, b) == status_apex) now(field_apex, s) = 1.0_dp
      end if
    end do
  end subroutine current

  !> Peak, head and tail arrival and width at every station from the
  !> histories (time(ns), sxx(station, ns)). The signal d is sigma_xx minus
  !> its value at t = 0 (tension positive), times the sign of `level` (Pa,
  !> the drivers pass half the load peak, signed: a compressive pulse is
  !> measured as the tensile one of opposite sign); the main pulse is the one
  !> that holds the largest d, at t_peak, and its peak is reported signed.
  !>  - head: the last crossing of |level| towards the peak before t_peak,
  !>  - tail: the first crossing of |level| back after t_peak,
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
    real(dp) :: d(size(time)), nan, sgn, lev
    nan = ieee_value(0.0_dp, ieee_quiet_nan)
    nst = size(sxx, 1)
    ns = size(time)
    allocate (m%peak(nst), m%t_peak(nst), m%t_head(nst), m%t_tail(nst), m%width(nst))
    m%threshold = level
    sgn = merge(-1.0_dp, 1.0_dp, level < 0.0_dp)
    lev = abs(level)
    do s = 1, nst
      d = sgn*(sxx(s, :) - sxx(s, 1))
      kmax = maxloc(d, 1)
      m%peak(s) = sgn*d(kmax)
      m%t_peak(s) = time(kmax)
      m%t_head(s) = nan
      m%t_tail(s) = nan
      if (d(kmax) >= lev .and. lev > 0.0_dp) then
        do k = kmax, 2, -1
          if (d(k - 1) < lev .and. d(k) >= lev) then
            m%t_head(s) = cross(k); exit
          end if
        end do
        do k = kmax + 1, ns
          if (d(k - 1) >= lev .and. d(k) < lev) then
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
      cross = time(k - 1) + (lev - d(k - 1))/(d(k) - d(k - 1))*(time(k) - time(k - 1))
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

  !> The first station (k > 0; 0: none) whose material reached the apex of
  !> the cone, where the return maps to the hydrostatic tensile stress
  !> I1 = k/beta (docs/guide/umat.md, "Apex"): a sample of `apex` (field_apex,
  !> station by sample) above 0. `t_apex` is when, `s_apex` the stress
  !> sigma_xx there then (Pa); `stations` marks every station reaching it.
  pure subroutine find_apex(time, apex, sxx, k, t_apex, s_apex, stations)
    real(dp), intent(in) :: time(:), apex(:, :), sxx(:, :)
    integer, intent(out) :: k
    real(dp), intent(out) :: t_apex, s_apex
    logical, intent(out) :: stations(size(apex, 1))
    integer :: s, j
    k = 0
    t_apex = 0.0_dp
    s_apex = 0.0_dp
    do s = 1, size(apex, 1)
      stations(s) = any(apex(s, :) > 0.0_dp)
      if (k > 0 .or. .not. stations(s)) cycle
      k = s
      j = findloc(apex(s, :) > 0.0_dp, .true., dim=1)
      t_apex = time(j)
      s_apex = sxx(s, j)
    end do
  end subroutine find_apex

  !> Phase speed (m/s) of the sinusoid of `frequency` (Hz) riding on a ramp
  !> (&load pulse = 'ramp_sine', fig. 2.10 left): at every station the
  !> history after x/c_slow + 2/frequency is fitted by least squares with
  !> a + b u + c u^2 + d cos(w t) + e sin(w t) (u = t - window start,
  !> w = 2 pi frequency), its phase atan2(d, e) unwrapped along the
  !> stations, and c = w / kappa with -kappa the slope of phase against x.
  !> `rms` is the phase residual about the line (rad). ok = .false. when
  !> fewer than two stations have 20 samples in their window.
  pure subroutine phase_speed(time, sxx, xs, frequency, c_slow, c, rms, ok)
    real(dp), intent(in) :: time(:), sxx(:, :), xs(:), frequency, c_slow
    real(dp), intent(out) :: c, rms
    logical, intent(out) :: ok
    real(dp), parameter :: pi = 3.14159265358979323846_dp
    real(dp) :: w, phase(size(xs)), a(5, 5), b(5, 1), row(5), u, t0, span, slope, icpt, xm, pm
    integer :: s, j, n, nst
    logical :: fit_ok
    w = 2.0_dp*pi*frequency
    nst = size(xs)
    c = 0.0_dp
    rms = 0.0_dp
    ok = .false.
    if (nst < 2 .or. .not. (frequency > 0.0_dp) .or. .not. (c_slow > 0.0_dp)) return
    do s = 1, nst
      t0 = xs(s)/c_slow + 2.0_dp/frequency
      n = count(time >= t0)
      if (n < 20) return
      span = maxval(time) - t0
      a = 0.0_dp
      b = 0.0_dp
      do j = 1, size(time)
        if (time(j) < t0) cycle
        u = (time(j) - t0)/span          ! scaled for the normal equations
        row = [1.0_dp, u, u*u, cos(w*time(j)), sin(w*time(j))]
        a = a + spread(row, 2, 5)*spread(row, 1, 5)
        b(:, 1) = b(:, 1) + row*sxx(s, j)
      end do
      call solve_dense(a, b, fit_ok)
      if (.not. fit_ok) return
      phase(s) = atan2(b(4, 1), b(5, 1))
    end do
    do s = 2, nst                        ! unwrapped along the stations
      phase(s) = phase(s) - 2.0_dp*pi*nint((phase(s) - phase(s - 1))/(2.0_dp*pi))
    end do
    xm = sum(xs)/nst
    pm = sum(phase)/nst
    slope = sum((xs - xm)*(phase - pm))/sum((xs - xm)**2)
    icpt = pm - slope*xm
    if (.not. (slope < 0.0_dp)) return
    c = -w/slope
    rms = sqrt(sum((phase - (slope*xs + icpt))**2)/nst)
    ok = .true.
  end subroutine phase_speed

end module wellposed_mpm_stations
