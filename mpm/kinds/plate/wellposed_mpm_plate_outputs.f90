!> The outputs of a plate case (chapter 4, fig. 4.1-4.6) as components of
!> the run loop: the stress-strain curve with Algorithm 1's iterations and
!> plastic counts per step, the band width along the band line, the band
!> watch, the stations, the particle snapshots and the progress line. Each
!> samples, summarises under the case's tag and puts its state by name;
!> the finished case's run.h5 datasets are wellposed_mpm_plate_done's.
!> Outputs: docs/guide/mpm.md.
module wellposed_mpm_plate_outputs
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text, real_text
  use wellposed_mpi, only: comm_t, allreduce_sum, allreduce_max
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_solver, only: applied_stress, plastic_strain, plastic_count
  use wellposed_mpm_plate_build, only: apparent_strain
  use wellposed_mpm_decomposition, only: gather_by_gid
  use wellposed_mpm_plate_cases, only: band_width
  use wellposed_mpm_plate_band_watch, only: band_watch_t
  use wellposed_mpm_plate_stations, only: plate_stations_t, plate_station_keys
  use wellposed_mpm_statev_outputs, only: plate_field_rows, add_plate_band, no_slot_why, &
                                          slot_plastic_strain
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_mpm_output, only: mpm_output_t
  use wellposed_mpm_snapshot_output, only: snapshot_output_t, progress_output_t
  use wellposed_mpm_run_loop, only: snapshot_due
  implicit none
  private
  public :: plate_curve_t, plate_band_t, plate_watch_t, plate_stations_output_t, &
            plate_snapshots_t, plate_progress_t

  !> The apparent stress-strain curve every sample_dt, and per step
  !> Algorithm 1's iterations, this rank's plastic particles (summed over
  !> the ranks at the end) and the sweep's bounds.
  type, extends(mpm_output_t) :: plate_curve_t
    character(len=:), allocatable :: tag
    real(dp), allocatable :: curve(:, :)    !< (time, apparent strain, stress)
    integer, allocatable :: its(:), nplast(:)
    real(dp), allocatable :: bounds(:, :)   !< (n_alpha, eq. 4.43 bound, error)
    integer :: ncurve = 0, nit = 0
    real(dp) :: next_sample = 0.0_dp, sample_dt = 0.0_dp
  contains
    procedure :: setup => curve_setup
    procedure :: sample => curve_sample
    procedure :: finish => curve_finish
    procedure :: summarise => curve_summarise
    procedure :: put => curve_put
    procedure :: get => curve_get
  end type plate_curve_t

  !> The FWHM of ||eps^p|| along the band line, at band_time or at the end.
  type, extends(mpm_output_t) :: plate_band_t
    character(len=:), allocatable :: tag
    character(len=1) :: axis = 'x'
    real(dp) :: line = 0.0_dp, half_spacing = 0.0_dp, band_time = 0.0_dp
    integer :: nstatv = 0
    logical :: measured = .false.
    real(dp) :: fwhm = 0.0_dp, peak_x = 0.0_dp, peak_v = 0.0_dp, band_t = 0.0_dp
    real(dp) :: epmax = 0.0_dp
  contains
    procedure :: sample => band_sample
    procedure :: finish => band_finish
    procedure :: summarise => band_summarise
    procedure :: put => band_put
    procedure :: get => band_get
  end type plate_band_t

  !> The band watch (wellposed_mpm_plate_band_watch) on the case's curve.
  type, extends(mpm_output_t) :: plate_watch_t
    character(len=:), allocatable :: tag
    type(band_watch_t) :: bw
    type(plate_curve_t), pointer :: curve => null()
    integer :: nstatv = 0
  contains
    procedure :: sample => watch_sample
    procedure :: summarise => watch_summarise
    procedure :: put => watch_put
    procedure :: get => watch_get
  end type plate_watch_t

  !> The case's stations (wellposed_mpm_plate_stations).
  type, extends(mpm_output_t) :: plate_stations_output_t
    character(len=:), allocatable :: tag
    type(plate_stations_t) :: pst
  contains
    procedure :: sample => stations_sample
    procedure :: summarise => stations_summarise
    procedure :: put => stations_put
    procedure :: get => stations_get
  end type plate_stations_output_t

  !> Snapshots of every case into cases/<tag>/snap_<n>/, every snapshot_dt,
  !> at the band watch's stage and at the end; one store for every case.
  type, extends(snapshot_output_t) :: plate_snapshots_t
    character(len=:), allocatable :: tag
    type(plate_watch_t), pointer :: watch => null()
  contains
    procedure :: rows => plate_rows
    procedure :: start => plate_snapshots_start
    procedure :: sample => plate_snapshots_sample
    procedure :: finish => plate_snapshots_finish
    procedure :: snap => plate_snap
  end type plate_snapshots_t

  !> A line every 10 s of wall time (rank 0, &output progress).
  type, extends(progress_output_t) :: plate_progress_t
    logical :: on = .false.
    character(len=:), allocatable :: tag
    integer :: nsteps_est = 0
    real(dp) :: t_end = 0.0_dp        !< the case's end (s): the time left from t
    type(plate_curve_t), pointer :: curve => null()
  contains
    procedure :: sample => plate_progress_sample
  end type plate_progress_t

contains

  !> Room for `nsteps` steps (with a margin) of a case sampled every `dt`.
  subroutine curve_setup(self, tag, nsteps, dt)
    class(plate_curve_t), intent(inout) :: self
    character(len=*), intent(in) :: tag
    integer, intent(in) :: nsteps
    real(dp), intent(in) :: dt
    self%name = 'curve'
    self%tag = tag
    self%sample_dt = dt
    allocate (self%curve(3, nsteps + 10), self%its(nsteps + 10), self%nplast(nsteps + 10), &
              self%bounds(3, nsteps + 10))
  end subroutine curve_setup

  subroutine curve_sample(self, sc, comm, err)
    class(plate_curve_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    ! an implicit run's step control may take more steps than estimated
    if (self%nit == size(self%its)) call grow(self)
    self%nit = self%nit + 1
    self%its(self%nit) = sc%nl%last%iterations
    self%nplast(self%nit) = plastic_count(sc)     ! this rank's share, summed at the end
    self%bounds(:, self%nit) = [sc%nl%last%n_alpha, sc%nl%last%bound_printed, sc%nl%last%error]
    if (sc%t >= self%next_sample - 1.0e-12_dp) then
      self%ncurve = self%ncurve + 1
      self%curve(:, self%ncurve) = [sc%t, apparent_strain(sc), applied_stress(sc)]
      self%next_sample = self%next_sample + self%sample_dt
    end if
  end subroutine curve_sample

  !> The per-step records twice as long (the samples with them).
  subroutine grow(self)
    type(plate_curve_t), intent(inout) :: self
    real(dp), allocatable :: c(:, :), b(:, :)
    integer, allocatable :: its(:), np(:)
    integer :: m
    m = 2*size(self%its)
    allocate (c(3, m), b(3, m), its(m), np(m))
    c(:, 1:self%ncurve) = self%curve(:, 1:self%ncurve)
    b(:, 1:self%nit) = self%bounds(:, 1:self%nit)
    its(1:self%nit) = self%its(1:self%nit)
    np(1:self%nit) = self%nplast(1:self%nit)
    call move_alloc(c, self%curve)
    call move_alloc(b, self%bounds)
    call move_alloc(its, self%its)
    call move_alloc(np, self%nplast)
  end subroutine grow

  !> The plastic counts summed over the ranks.
  subroutine curve_finish(self, sc, comm, err)
    class(plate_curve_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (comm%size > 1) call allreduce_sum(comm, self%nplast(1:self%nit))
  end subroutine curve_finish

  subroutine curve_summarise(self, sm)
    class(plate_curve_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    integer :: j, n
    n = self%ncurve
    j = maxloc(self%curve(3, 1:n), dim=1)
    call sm%add(self%tag//'.peak_stress', self%curve(3, j)*1.0e-6_dp, 'MPa, compression +')
    call sm%add(self%tag//'.strain_at_peak', self%curve(2, j), 'apparent axial strain')
    call sm%add(self%tag//'.final_stress', self%curve(3, n)*1.0e-6_dp, 'MPa')
    call sm%add(self%tag//'.final_strain', self%curve(2, n))
  end subroutine curve_summarise

  !> Every column by name, each with a leading 0 (so that an empty one is
  !> still an entry); the plastic counts summed over the ranks.
  subroutine curve_put(self, ck, comm)
    class(plate_curve_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    integer, allocatable :: nplast(:)
    character(len=:), allocatable :: p
    integer :: n, m
    allocate (nplast(self%nit))
    nplast = self%nplast(1:self%nit)
    if (comm%size > 1) call allreduce_sum(comm, nplast)
    if (comm%rank /= 0) return
    p = self%name//'/'
    n = self%ncurve
    m = self%nit
    call ck%put(p//'time', [0.0_dp, self%curve(1, 1:n)])
    call ck%put(p//'strain', [0.0_dp, self%curve(2, 1:n)])
    call ck%put(p//'stress', [0.0_dp, self%curve(3, 1:n)])
    call ck%put(p//'next_sample', self%next_sample)
    call ck%put(p//'iterations', [0, self%its(1:m)])
    call ck%put(p//'n_plastic', [0, nplast])
    call ck%put(p//'n_alpha', [0.0_dp, self%bounds(1, 1:m)])
    call ck%put(p//'bound', [0.0_dp, self%bounds(2, 1:m)])
    call ck%put(p//'error', [0.0_dp, self%bounds(3, 1:m)])
  end subroutine curve_put

  !> Rank 0 holds the plastic counts so far, the others none.
  subroutine curve_get(self, ck, comm, err)
    class(plate_curve_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: a(:)
    integer, allocatable :: iv(:)
    character(len=:), allocatable :: p
    integer :: k
    p = self%name//'/'
    call ck%get(p//'time', a, err); if (allocated(err)) return
    self%ncurve = size(a) - 1
    self%curve(1, 1:self%ncurve) = a(2:)
    call ck%get(p//'strain', a, err); if (allocated(err)) return
    self%curve(2, 1:self%ncurve) = a(2:)
    call ck%get(p//'stress', a, err); if (allocated(err)) return
    self%curve(3, 1:self%ncurve) = a(2:)
    call ck%get(p//'next_sample', self%next_sample, err); if (allocated(err)) return
    call ck%get(p//'iterations', iv, err); if (allocated(err)) return
    self%nit = size(iv) - 1
    self%its(1:self%nit) = iv(2:)
    call ck%get(p//'n_plastic', iv, err); if (allocated(err)) return
    self%nplast(1:self%nit) = iv(2:)
    if (comm%rank /= 0) self%nplast(1:self%nit) = 0
    do k = 1, 3
      call ck%get(p//trim(bound_cols(k)), a, err); if (allocated(err)) return
      self%bounds(k, 1:self%nit) = a(2:)
    end do
  end subroutine curve_get

  pure function bound_cols(k) result(name)
    integer, intent(in) :: k
    character(len=8) :: name
    character(len=8), parameter :: names(3) = ['n_alpha ', 'bound   ', 'error   ']
    name = names(k)
  end function bound_cols

  !> The band width now (fwhm, peak_x, peak_v on rank 0; band_t and
  !> measured everywhere). Collective: rank 0 gathers the particles.
  subroutine band_measure(self, sc, comm)
    class(plate_band_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    real(dp), allocatable :: f(:, :), all(:, :)
    integer :: n
    n = sc%parts%n
    allocate (f(3, n))
    f(1:2, :) = sc%parts%x(:, 1:n)
    f(3, :) = plastic_strain(sc)
    call gather_by_gid(comm, sc%parts%gid(1:n), f, 0, all)
    self%fwhm = 0.0_dp; self%peak_x = 0.0_dp; self%peak_v = 0.0_dp
    if (comm%rank == 0) call band_width(all(1:2, :), all(3, :), merge(1, 2, self%axis == 'x'), &
                                        self%line, self%half_spacing, self%fwhm, self%peak_x, &
                                        self%peak_v)
    self%band_t = sc%t
    self%measured = .true.
  end subroutine band_measure

  subroutine band_sample(self, sc, comm, err)
    class(plate_band_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (self%band_time > 0.0_dp .and. .not. self%measured .and. sc%t >= self%band_time) &
      call band_measure(self, sc, comm)
  end subroutine band_sample

  !> The width at the end unless band_time came; the largest plastic strain.
  subroutine band_finish(self, sc, comm, err)
    class(plate_band_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. self%measured) call band_measure(self, sc, comm)
    self%epmax = maxval(plastic_strain(sc))
    if (comm%size > 1) call allreduce_max(comm, self%epmax)
  end subroutine band_finish

  subroutine band_summarise(self, sm)
    class(plate_band_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    call add_plate_band(sm, self%tag, self%nstatv, self%epmax, self%fwhm, self%line, &
                        self%band_t, self%peak_x, self%peak_v)
  end subroutine band_summarise

  subroutine band_put(self, ck, comm)
    class(plate_band_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (comm%rank /= 0) return
    call ck%put(self%name//'/measured', merge(1, 0, self%measured))
    call ck%put(self%name//'/fwhm', self%fwhm)
    call ck%put(self%name//'/peak_x', self%peak_x)
    call ck%put(self%name//'/peak_v', self%peak_v)
    call ck%put(self%name//'/time', self%band_t)
  end subroutine band_put

  subroutine band_get(self, ck, comm, err)
    class(plate_band_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    integer :: m
    call ck%get(self%name//'/measured', m, err); if (allocated(err)) return
    self%measured = m == 1
    call ck%get(self%name//'/fwhm', self%fwhm, err); if (allocated(err)) return
    call ck%get(self%name//'/peak_x', self%peak_x, err); if (allocated(err)) return
    call ck%get(self%name//'/peak_v', self%peak_v, err); if (allocated(err)) return
    call ck%get(self%name//'/time', self%band_t, err)
  end subroutine band_get

  subroutine watch_sample(self, sc, comm, err)
    class(plate_watch_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%bw%step(sc, comm, self%curve%curve(:, 1:self%curve%ncurve))
  end subroutine watch_sample

  subroutine watch_summarise(self, sm)
    class(plate_watch_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    if (self%nstatv < slot_plastic_strain) then
      call self%bw%summarise(sm, self%tag, no_slot_why('plastic strain', self%nstatv))
    else
      call self%bw%summarise(sm, self%tag)
    end if
  end subroutine watch_summarise

  subroutine watch_put(self, ck, comm)
    class(plate_watch_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (comm%rank == 0) call self%bw%put(ck, self%name//'/')
  end subroutine watch_put

  subroutine watch_get(self, ck, comm, err)
    class(plate_watch_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%bw%get(ck, self%name//'/', err)
  end subroutine watch_get

  subroutine stations_sample(self, sc, comm, err)
    class(plate_stations_output_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%pst%sample(sc, comm)
  end subroutine stations_sample

  subroutine stations_summarise(self, sm)
    class(plate_stations_output_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    call self%pst%summarise(sm, self%tag//'.station_', plate_station_keys, 0.0_dp)
  end subroutine stations_summarise

  subroutine stations_put(self, ck, comm)
    class(plate_stations_output_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    call self%pst%put(ck, self%name//'/')
  end subroutine stations_put

  subroutine stations_get(self, ck, comm, err)
    class(plate_stations_output_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%pst%get(ck, self%name//'/', err)
  end subroutine stations_get

  !> Snapshot rows: x, y, ||eps^p||, sigma_xx, sigma_yy, sigma_xy and the
  !> STATEV fields the material has (wellposed_mpm_statev_outputs).
  subroutine plate_rows(self, sc, group, rows)
    class(plate_snapshots_t), intent(in) :: self
    type(mpm_scene_t), intent(in) :: sc
    character(len=:), allocatable, intent(out) :: group
    real(dp), allocatable, intent(out) :: rows(:, :)
    real(dp), allocatable :: f(:, :)
    integer :: n
    n = sc%parts%n
    allocate (f(8, n))
    f(1:2, :) = sc%parts%x(:, 1:n)
    f(3, :) = plastic_strain(sc)
    f(4, :) = sc%parts%stress(1, 1:n)
    f(5, :) = sc%parts%stress(2, 1:n)
    f(6, :) = sc%parts%stress(4, 1:n)
    f(7:8, :) = 0.0_dp
    if (sc%parts%nstatv >= 2) f(7, :) = sc%parts%statev(2, 1:n)
    if (sc%parts%nstatv >= 4) f(8, :) = sc%parts%statev(4, 1:n)
    rows = f(plate_field_rows(sc%parts%nstatv), :)
    group = 'cases/'//self%tag//'/snap_'//int_text(self%taken)//'/'
  end subroutine plate_rows

  !> A snapshot now, the schedule moved on when it was due.
  subroutine plate_snap(self, sc, comm, err)
    class(plate_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (snapshot_due(self%interval, sc%t, self%next, 1.0e-12_dp)) &
      self%next = self%next + self%interval
    call self%take(sc, comm, err)
  end subroutine plate_snap

  !> A case's first snapshot, at t = 0.
  subroutine plate_snapshots_start(self, sc, comm, err)
    class(plate_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    self%taken = 0
    self%next = 0.0_dp
    call self%snap(sc, comm, err)
  end subroutine plate_snapshots_start

  subroutine plate_snapshots_sample(self, sc, comm, err)
    class(plate_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (self%watch%bw%just_staged .or. snapshot_due(self%interval, sc%t, self%next, &
                                                    1.0e-12_dp)) call self%snap(sc, comm, err)
  end subroutine plate_snapshots_sample

  !> The last state, unless a scheduled snapshot just took it.
  subroutine plate_snapshots_finish(self, sc, comm, err)
    class(plate_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (self%last_due(sc)) call self%snap(sc, comm, err)
  end subroutine plate_snapshots_finish

  subroutine plate_progress_sample(self, sc, comm, err)
    class(plate_progress_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. self%on) return
    if (.not. self%clock%progress_due()) return
    associate (c => self%curve)
      write (output_unit, '(a)') '    '//self%tag//': step '//int_text(sc%nstep)//'/'// &
        int_text(self%nsteps_est)//', t = '//real_text(sc%t)//' s, stress = '// &
        real_text(c%curve(3, max(c%ncurve, 1))*1.0e-6_dp)//' MPa, plastic '// &
        int_text(c%nplast(c%nit))//', iterations '//int_text(sc%nl%last%iterations)// &
        ', ~'//int_text(nint(self%clock%elapsed()*max(self%t_end - sc%t, 0.0_dp)/ &
        max(sc%t, tiny(1.0_dp))))//' s left'
    end associate
    flush (output_unit)
  end subroutine plate_progress_sample

end module wellposed_mpm_plate_outputs
