!> The outputs of a bar run (section 4.3, the scenes of chapter 2) as
!> components of the run loop: the stations with their measures and wakes,
!> the energy and momentum balance, Algorithm 1's record per plastic step,
!> the particle snapshots and the progress line. Each samples, summarises,
!> writes its run.h5 datasets and puts its state by name. The scene's
!> energy sums are read here only (bar_energy_t). Outputs: docs/guide/mpm.md.
module wellposed_mpm_bar_outputs
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, allreduce_sum, broadcast
  use wellposed_mpm_bar_config, only: bar_config_t, pulse_ramp_sine
  use wellposed_mpm_method, only: scheme_implicit
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_bar_kind, only: bar_book_t, bar_book
  use wellposed_mpm_solver, only: kinetic_energy, total_momentum
  use wellposed_mpm_stations, only: stations_t, place_stations, sample_stations, &
                                    station_measures_t, measure_stations, field_sxx, &
                                    field_syy, field_v, field_z, field_apex, nfields
  use wellposed_mpm_bar_station_summary, only: add_station_summary, head_speed_t
  use wellposed_mpm_wake, only: wake_t, station_wake, wake_start
  use wellposed_mpm_bar_admissibility, only: add_admissibility
  use wellposed_mpm_parallel_io, only: station_proxy_t, gather_reference_positions, &
                                       start_proxied_stations, fill_station_proxy, &
                                       put_stations, get_stations
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_output, only: mpm_output_t
  use wellposed_mpm_snapshot_output, only: snapshot_output_t, progress_output_t
  use wellposed_mpm_run_loop, only: snapshot_due
  implicit none
  private
  public :: bar_stations_t, bar_energy_t, bar_nonlocal_t, bar_snapshots_t, bar_progress_t

  !> The stations, on rank 0 over every particle in id order, read through
  !> a proxy; their measures at the end.
  type, extends(mpm_output_t) :: bar_stations_t
    type(stations_t) :: st
    type(station_measures_t) :: meas
    type(station_proxy_t) :: proxy
    type(bar_config_t) :: cfg
    real(dp) :: c_e = 0.0_dp, c_p = 0.0_dp
    type(head_speed_t) :: head
    logical :: sampled = .false.   !< rank 0: the last step was a sample
  contains
    procedure :: setup => stations_setup
    procedure :: sample => stations_sample
    procedure :: finish => stations_finish
    procedure :: summarise => stations_summarise
    procedure :: write_h5 => stations_write_h5
    procedure :: put => stations_put
    procedure :: get => stations_get
  end type bar_stations_t

  !> The energy and momentum balance at every station sample (rank 0's
  !> rows) and at the end (every rank's sums).
  type, extends(mpm_output_t) :: bar_energy_t
    type(bar_stations_t), pointer :: stations => null()
    real(dp), allocatable :: rows(:, :)   !< (t, E_kin, W_int, W_ext, P - impulse)
    integer :: n = 0
    real(dp) :: kinetic0 = 0.0_dp, momentum0 = 0.0_dp
    real(dp) :: ke_end = 0.0_dp, p_end = 0.0_dp, sums(3) = 0.0_dp
    !> the quasi-static scheme's run: no inertia, so no momentum balance and
    !> its particles' v = du/dt no kinetic energy
    logical :: quasi_static = .false.
  contains
    procedure :: setup => energy_setup
    procedure :: sample => energy_sample
    procedure :: finish => energy_finish
    procedure :: summarise => energy_summarise
    procedure :: write_h5 => energy_write_h5
    procedure :: put => energy_put
    procedure :: get => energy_get
  end type bar_energy_t

  !> Algorithm 1 per step with plastic particles: the step, its sweeps and
  !> the dissertation's bound of eq. 4.43 (N_alpha |h_zeta/(a + h_eta)|).
  type, extends(mpm_output_t) :: bar_nonlocal_t
    integer, allocatable :: step(:), its(:)
    real(dp), allocatable :: bound(:)
    integer :: n = 0
  contains
    procedure :: sample => nonlocal_sample
    procedure :: write_h5 => nonlocal_write_h5
    procedure :: put => nonlocal_put
    procedure :: get => nonlocal_get
  end type bar_nonlocal_t

  !> Snapshots every &output snapshot_dt (points on the x axis over time).
  type, extends(snapshot_output_t) :: bar_snapshots_t
  contains
    procedure :: rows => bar_rows
    procedure :: start => bar_snapshots_start
    procedure :: sample => bar_snapshots_sample
    procedure :: write_h5 => bar_snapshots_write_h5
  end type bar_snapshots_t

  !> A line every 2 s of wall time (rank 0, &output progress).
  type, extends(progress_output_t) :: bar_progress_t
    logical :: on = .false.
    real(dp) :: t_end = 0.0_dp
  contains
    procedure :: sample => bar_progress_sample
  end type bar_progress_t

contains

  !> Stations of `cfg` on scene `sc` of `ntotal` particles (collective).
  subroutine stations_setup(self, cfg, sc, ntotal, comm)
    class(bar_stations_t), intent(inout) :: self
    type(bar_config_t), intent(in) :: cfg
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: ntotal
    type(comm_t), intent(inout) :: comm
    real(dp), allocatable :: x0(:, :)
    self%name = 'stations'
    self%cfg = cfg
    call gather_reference_positions(comm, sc%parts, 0, x0)
    if (comm%rank == 0) then
      call place_stations(self%st, cfg%station_first, cfg%station_spacing, cfg%nstations, &
                          x0(1, :))
    else
      allocate (self%st%x(0), self%st%time(0), self%st%hist(nfields, 0, 0))
    end if
    call start_proxied_stations(self%st, comm, ntotal, sc%parts, cfg%sample_dt, cfg%t_end, &
                                self%proxy)
  end subroutine stations_setup

  subroutine stations_sample(self, sc, comm, err)
    class(bar_stations_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    integer :: s
    call fill_station_proxy(self%proxy, comm, sc%parts)
    self%sampled = .false.
    if (comm%rank /= 0) return
    s = self%st%ns
    call sample_stations(self%st, self%proxy%parts, sc%t)
    self%sampled = self%st%ns > s
  end subroutine stations_sample

  subroutine stations_finish(self, sc, comm, err)
    class(bar_stations_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    associate (st => self%st)
      call measure_stations(st%time(1:st%ns), st%hist(field_sxx, :, 1:st%ns), st%x, &
                            0.5_dp*self%cfg%load_peak, self%meas)
    end associate
  end subroutine stations_finish

  subroutine stations_summarise(self, sm)
    class(bar_stations_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    character(len=:), allocatable :: why
    associate (st => self%st)
      call add_station_summary(sm, self%cfg, st%x, st%time(1:st%ns), &
                               st%hist(field_sxx, :, 1:st%ns), st%hist(field_apex, :, 1:st%ns), &
                               self%meas, self%c_e, self%c_p, self%head)
    end associate
    call add_wake(self, sm)
    why = ''
    if (.not. self%c_p > self%c_e) why = 'C_P <= C_E: the pulse opens no region of nonuniqueness'
    if (self%cfg%pulse == pulse_ramp_sine) why = "pulse = 'ramp_sine' is a ramp, not a pulse"
    associate (st => self%st, cfg => self%cfg)
      call add_admissibility(sm, st%x, st%time(1:st%ns), st%hist(field_sxx, :, 1:st%ns), &
                             sign(1.0_dp, cfg%load_peak), cfg%load_start, cfg%load_duration, &
                             self%c_e, self%c_p, why)
    end associate
  end subroutine stations_summarise

  !> The wake behind the pulse at every station (wellposed_mpm_wake) and
  !> the largest over the stations whose record reaches the window.
  subroutine add_wake(self, sm)
    class(bar_stations_t), intent(in) :: self
    type(summary_t), intent(inout) :: sm
    type(wake_t) :: w
    character(len=:), allocatable :: why, tag
    real(dp) :: worst, worst_grid
    logical :: any_window
    integer :: i
    why = 'the record ends before the wake window starts'
    if (self%cfg%pulse == pulse_ramp_sine) why = "pulse = 'ramp_sine' is a ramp, not a pulse"
    call sm%add('wake_definition', 'max and RMS of |sigma_xx(t) - sigma_xx(0)| at a '// &
                'station over t >= x/C_E + 2 tau (the ideal elastic tail plus one pulse '// &
                'duration) to t_end, where the continuum is at or near its initial '// &
                'stress; _grid: max |sigma_xx - its centred moving average over 4 dx/C_E|, '// &
                'the grid-scale part, without the smooth signal a plastic pulse leaves')
    worst = 0.0_dp
    worst_grid = 0.0_dp
    any_window = .false.
    associate (st => self%st, cfg => self%cfg)
      do i = 1, st%n
        w = station_wake(st%time(1:st%ns), st%hist(field_sxx, i, 1:st%ns), &
                         wake_start(st%x(i), self%c_e, cfg%load_duration), 4.0_dp*cfg%dx/self%c_e)
        if (cfg%pulse == pulse_ramp_sine) w%samples = 0
        tag = 'station_'//int_text(i)
        if (w%samples > 1) then
          call sm%add(tag//'_wake_amplitude', w%amplitude, 'Pa')
          call sm%add(tag//'_wake_rms', w%rms, 'Pa')
          call sm%add(tag//'_wake_grid', w%grid, 'Pa')
          any_window = .true.
          worst = max(worst, w%amplitude)
          worst_grid = max(worst_grid, w%grid)
        else
          call sm%not_applicable(tag//'_wake_amplitude', why)
          call sm%not_applicable(tag//'_wake_rms', why)
          call sm%not_applicable(tag//'_wake_grid', why)
        end if
      end do
    end associate
    if (any_window) then
      call sm%add('wake_amplitude', worst, 'Pa, the largest station_<i>_wake_amplitude')
      call sm%add('wake_grid_amplitude', worst_grid, 'Pa, the largest station_<i>_wake_grid')
    else
      why = 'no station''s record reaches its wake window'
      call sm%not_applicable('wake_amplitude', why)
      call sm%not_applicable('wake_grid_amplitude', why)
    end if
  end subroutine add_wake

  subroutine stations_write_h5(self, h5)
    class(bar_stations_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    associate (st => self%st)
      call h5%write('stations/time', st%time(1:st%ns))
      call h5%write('stations/x', st%x)
      call h5%write('stations/sigma_xx', st%hist(field_sxx, :, 1:st%ns))
      call h5%write('stations/sigma_yy', st%hist(field_syy, :, 1:st%ns))
      call h5%write('stations/velocity', st%hist(field_v, :, 1:st%ns))
      call h5%write('stations/z', st%hist(field_z, :, 1:st%ns))
    end associate
    call h5%write('measures/peak', self%meas%peak)
    call h5%write('measures/t_head', self%meas%t_head)
    call h5%write('measures/t_tail', self%meas%t_tail)
    call h5%write('measures/width', self%meas%width)
  end subroutine stations_write_h5

  subroutine stations_put(self, ck, comm)
    class(bar_stations_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (comm%rank == 0) call put_stations(ck, self%name//'/', self%st)
  end subroutine stations_put

  subroutine stations_get(self, ck, comm, err)
    class(bar_stations_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (comm%rank == 0) call get_stations(ck, self%name//'/', self%st, err)
  end subroutine stations_get

  !> The balance of scene `sc` read at every sample of `stations`.
  subroutine energy_setup(self, stations, sc)
    class(bar_energy_t), intent(inout) :: self
    type(bar_stations_t), target, intent(in) :: stations
    type(mpm_scene_t), intent(in) :: sc
    type(bar_book_t) :: book
    self%name = 'energy'
    self%stations => stations
    book = bar_book(sc)
    self%kinetic0 = book%kinetic0
    self%momentum0 = book%momentum0
    self%quasi_static = sc%scheme == scheme_implicit
    allocate (self%rows(5, max(size(stations%st%time), 1)))
    self%n = 1
    self%rows(:, 1) = [0.0_dp, book%kinetic0, 0.0_dp, 0.0_dp, book%momentum0]
  end subroutine energy_setup

  !> The energies and momentum summed over the ranks now (collective).
  subroutine energy_sums(self, sc, comm)
    class(bar_energy_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    self%ke_end = kinetic_energy(sc)
    self%p_end = total_momentum(sc)
    self%sums = sc%kind%partial_sums()
    call allreduce_sum(comm, self%sums)
  end subroutine energy_sums

  subroutine energy_sample(self, sc, comm, err)
    class(bar_energy_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    logical :: due
    due = .false.
    if (comm%rank == 0) due = self%stations%sampled .and. self%n < size(self%rows, 2)
    call broadcast(comm, due, 0)
    if (.not. due) return
    call energy_sums(self, sc, comm)
    if (comm%rank /= 0) return
    self%n = self%n + 1
    self%rows(:, self%n) = [sc%t, self%ke_end, self%sums(1), self%sums(2), &
                            self%p_end - self%sums(3)]
  end subroutine energy_sample

  subroutine energy_finish(self, sc, comm, err)
    class(bar_energy_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call energy_sums(self, sc, comm)
  end subroutine energy_finish

  subroutine energy_summarise(self, sm)
    class(bar_energy_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    real(dp) :: escale, ebal
    associate (w_int => self%sums(1), w_ext => self%sums(2), impulse => self%sums(3))
      escale = abs(w_ext) + self%kinetic0
      ebal = self%ke_end - self%kinetic0 + w_int - w_ext
      call sm%add('energy_input', escale, 'J/m^2, |W_ext| + E_kin0: the work of the '// &
                  'surface load and the initial kinetic energy')
      if (self%quasi_static) then
        ! the static balance W_int = W_ext; the momentum is the supports'
        call sm%add('energy_balance_error', (w_int - w_ext)/max(escale, tiny(1.0_dp)), &
                    '(W_int - W_ext)/energy_input at the end (quasi-static: no kinetic energy)')
        call sm%not_applicable('momentum_error', 'scheme = ''implicit'' is quasi-static: '// &
                               'no inertia, the supports take the load''s impulse')
      else
        call sm%add('energy_balance_error', ebal/max(escale, tiny(1.0_dp)), &
                    '(E_kin - E_kin0 + W_int - W_ext)/energy_input at the end')
        call sm%add('momentum_error', (self%p_end - self%momentum0 - impulse)/ &
                    max(abs(impulse), maxval(abs(self%rows(5, 1:self%n))), tiny(1.0_dp)), &
                    '(P - P0 - impulse)/max|impulse|')
      end if
    end associate
  end subroutine energy_summarise

  subroutine energy_write_h5(self, h5)
    class(bar_energy_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    call h5%write('energy/time', self%rows(1, 1:self%n))
    call h5%write('energy/kinetic', self%rows(2, 1:self%n))
    call h5%write('energy/internal_work', self%rows(3, 1:self%n))
    call h5%write('energy/external_work', self%rows(4, 1:self%n))
    call h5%write('energy/momentum_minus_impulse', self%rows(5, 1:self%n))
  end subroutine energy_write_h5

  subroutine energy_put(self, ck, comm)
    class(bar_energy_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (comm%rank /= 0) return
    call ck%put(self%name//'/time', self%rows(1, 1:self%n))
    call ck%put(self%name//'/kinetic', self%rows(2, 1:self%n))
    call ck%put(self%name//'/internal_work', self%rows(3, 1:self%n))
    call ck%put(self%name//'/external_work', self%rows(4, 1:self%n))
    call ck%put(self%name//'/momentum_minus_impulse', self%rows(5, 1:self%n))
  end subroutine energy_put

  subroutine energy_get(self, ck, comm, err)
    class(bar_energy_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    character(len=24), parameter :: cols(5) = [character(len=24) :: 'time', 'kinetic', &
      'internal_work', 'external_work', 'momentum_minus_impulse']
    real(dp), allocatable :: a(:)
    integer :: k
    if (comm%rank /= 0) return
    do k = 1, 5
      call ck%get(self%name//'/'//trim(cols(k)), a, err); if (allocated(err)) return
      if (size(a) > size(self%rows, 2) .or. (k > 1 .and. size(a) /= self%n)) then
        call new_error(err, status_invalid, 'checkpoint', 'its rows do not fit this deck')
        return
      end if
      self%n = size(a)
      self%rows(k, 1:self%n) = a
    end do
  end subroutine energy_get

  subroutine nonlocal_sample(self, sc, comm, err)
    class(bar_nonlocal_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. (sc%nl%active .and. sc%nl%last%n_plastic > 0)) return
    if (.not. allocated(self%its)) allocate (self%its(1024), self%step(1024), self%bound(1024))
    if (self%n == size(self%its)) then
      self%its = [self%its, self%its]; self%step = [self%step, self%step]
      self%bound = [self%bound, self%bound]
    end if
    self%n = self%n + 1
    self%its(self%n) = sc%nl%last%iterations
    self%step(self%n) = sc%nstep
    self%bound(self%n) = sc%nl%last%bound_printed
  end subroutine nonlocal_sample

  subroutine nonlocal_write_h5(self, h5)
    class(bar_nonlocal_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    if (self%n == 0) return
    call h5%write('nonlocal/step', self%step(1:self%n))
    call h5%write('nonlocal/iterations', self%its(1:self%n))
    call h5%write('nonlocal/lipschitz_eq4_43_printed', self%bound(1:self%n))
  end subroutine nonlocal_write_h5

  !> The records with a leading 0, so that none is still an entry.
  subroutine nonlocal_put(self, ck, comm)
    class(bar_nonlocal_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (comm%rank /= 0) return
    if (self%n == 0) allocate (self%its(0), self%step(0), self%bound(0))
    call ck%put(self%name//'/step', [0, self%step(1:self%n)])
    call ck%put(self%name//'/iterations', [0, self%its(1:self%n)])
    call ck%put(self%name//'/bound', [0.0_dp, self%bound(1:self%n)])
    if (self%n == 0) deallocate (self%its, self%step, self%bound)
  end subroutine nonlocal_put

  subroutine nonlocal_get(self, ck, comm, err)
    class(bar_nonlocal_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: step(:), its(:)
    real(dp), allocatable :: bound(:)
    call ck%get(self%name//'/step', step, err); if (allocated(err)) return
    call ck%get(self%name//'/iterations', its, err); if (allocated(err)) return
    call ck%get(self%name//'/bound', bound, err); if (allocated(err)) return
    self%n = size(step) - 1
    if (size(its) /= self%n + 1 .or. size(bound) /= self%n + 1) then
      call new_error(err, status_invalid, 'checkpoint', 'its records are garbled')
      return
    end if
    if (self%n == 0) return
    allocate (self%its(self%n + 1024), self%step(self%n + 1024), self%bound(self%n + 1024))
    self%step(1:self%n) = step(2:)
    self%its(1:self%n) = its(2:)
    self%bound(1:self%n) = bound(2:)
  end subroutine nonlocal_get

  !> Snapshot rows: x, x0, velocity, sigma_xx, sigma_yy, z (statev 1).
  subroutine bar_rows(self, sc, group, rows)
    class(bar_snapshots_t), intent(in) :: self
    type(mpm_scene_t), intent(in) :: sc
    character(len=:), allocatable, intent(out) :: group
    real(dp), allocatable, intent(out) :: rows(:, :)
    character(len=16) :: tag
    integer :: n
    n = sc%parts%n
    allocate (rows(6, n))
    rows(1, :) = sc%parts%x(1, 1:n)
    rows(2, :) = sc%parts%x0(1, 1:n)
    rows(3, :) = sc%parts%v(1, 1:n)
    rows(4, :) = sc%parts%stress(1, 1:n)
    rows(5, :) = sc%parts%stress(2, 1:n)
    rows(6, :) = sc%parts%statev(1, 1:n)
    write (tag, '(i4.4)') self%taken
    group = 'snapshots/'//trim(tag)//'/'
  end subroutine bar_rows

  !> The first snapshot at t = 0 (when snapshots are on).
  subroutine bar_snapshots_start(self, sc, comm, err)
    class(bar_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (self%interval <= 0.0_dp) return
    call self%take(sc, comm, err)
    self%next = self%taken*self%interval
  end subroutine bar_snapshots_start

  subroutine bar_snapshots_sample(self, sc, comm, err)
    class(bar_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. snapshot_due(self%interval, sc%t, self%next, 0.5_dp*sc%dt)) return
    call self%take(sc, comm, err)
    self%next = self%taken*self%interval
  end subroutine bar_snapshots_sample

  subroutine bar_snapshots_write_h5(self, h5)
    class(bar_snapshots_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    call h5%write('snapshots/count', [self%taken])
  end subroutine bar_snapshots_write_h5

  subroutine bar_progress_sample(self, sc, comm, err)
    class(bar_progress_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: wall
    if (.not. self%on) return
    if (.not. self%clock%progress_due()) return
    wall = self%clock%elapsed()
    write (output_unit, '(a,f9.2,a,f5.1,a,i0,a,f7.1,a,f7.1,a)') '  t = ', &
      sc%t*1e3_dp, ' ms (', 100*sc%t/self%t_end, ' %), step ', sc%nstep, ', ', &
      wall, ' s elapsed, ~', wall*(self%t_end - sc%t)/sc%t, ' s left'
    flush (output_unit)
  end subroutine bar_progress_sample

end module wellposed_mpm_bar_outputs
