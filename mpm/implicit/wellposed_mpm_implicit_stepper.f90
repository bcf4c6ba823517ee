!> The implicit scheme's step control (docs/research/implicit.md): steps of
!> at most dt_max to t_end; a step whose Newton iteration fails or whose
!> UMAT asks to cut back (PNEWDT < 1) is retried at half the size, down to
!> dt_max/2**max_halvings; after a step that took at most half the
!> iteration limit the next may double, up to dt_max. It keeps each step's Newton history for
!> the run's newton.csv and the summary's keys.
module wellposed_mpm_implicit_stepper
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_step, only: hand_off
  use wellposed_mpm_linear_solver, only: linear_solver_t
  use wellposed_mpm_implicit_step, only: implicit_settings_t, newton_report_t, &
                                         advance_implicit
  implicit none
  private
  public :: implicit_stepper_t, step_log_t

  integer, parameter :: max_halvings = 10

  !> One accepted step: its end time, size, Newton solves, linear
  !> iterations, Algorithm 1's sweeps and the relative residual after each
  !> solve (0: the predictor's).
  type :: step_log_t
    real(dp) :: t = 0.0_dp, dt = 0.0_dp
    integer :: solves = 0, linear_iterations = 0, sweeps = 0
    real(dp), allocatable :: residual(:)
  end type step_log_t

  !> The scheme's settings, its linear solver and what its steps did.
  type :: implicit_stepper_t
    type(implicit_settings_t) :: opt
    type(linear_solver_t) :: solver
    real(dp) :: dt_max = 0.0_dp, dt_next = 0.0_dp
    integer :: cutbacks = 0, nlog = 0
    !> continued from a checkpoint: the log holds the steps since
    logical :: restarted = .false.
    !> the trapezoidal rule's dynamic steps (the particles' accelerations
    !> are the scene's, sc%accel: from rest, zero at the start)
    logical :: dynamic = .false.
    type(step_log_t), allocatable :: log(:)
  contains
    procedure :: start => stepper_start
    procedure :: advance => stepper_advance
    procedure :: total_solves, max_solves, worst_residual
  end type implicit_stepper_t

contains

  !> Steps of at most dt_max of scene sc, linear solver `method`; `dynamic`:
  !> the trapezoidal rule's steps from the particles' zero acceleration. A
  !> stepper started before (a study's earlier case) starts afresh.
  subroutine stepper_start(self, dt_max, method, sc, dynamic)
    class(implicit_stepper_t), intent(inout) :: self
    real(dp), intent(in) :: dt_max
    integer, intent(in) :: method
    type(mpm_scene_t), intent(inout) :: sc
    logical, intent(in) :: dynamic
    call self%solver%destroy()
    if (allocated(self%log)) deallocate (self%log)
    if (allocated(sc%accel)) deallocate (sc%accel)
    self%dynamic = dynamic
    if (dynamic) allocate (sc%accel(sc%ndim, size(sc%parts%gid)), source=0.0_dp)
    self%dt_max = dt_max
    self%dt_next = dt_max
    self%opt%method = method
    self%cutbacks = 0
    self%nlog = 0
    allocate (self%log(64))
  end subroutine stepper_start

  !> One accepted step of sc towards t_end (sc%dt set to its size); an
  !> error other than a cut-back, or a cut-back below the smallest size,
  !> leaves sc at its start and is returned. Collective: first the
  !> particles to their ranks, with their accelerations.
  subroutine stepper_advance(self, sc, t_end, err)
    class(implicit_stepper_t), intent(inout) :: self
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: t_end
    type(error_t), allocatable, intent(out) :: err
    type(newton_report_t) :: rep
    real(dp) :: dt, dt_min
    real(dp), allocatable :: accel(:, :)
    character(len=:), allocatable :: why
    real(dp), allocatable :: warm(:)
    ! Algorithm 1's warm start (the last solve's dlambda) travels with the
    ! particles, so one rank and many start each solve alike
    if (allocated(sc%nl%dl) .and. sc%exchange%nranks() > 1) then
      if (size(sc%nl%dl) == sc%parts%n) warm = sc%nl%dl
    end if
    call hand_off(sc, err, warm)
    if (allocated(err)) return
    if (allocated(warm)) then
      ! sized to the particles now here (plastic: Algorithm 1's, set anew)
      deallocate (sc%nl%dl, sc%nl%plastic)
      allocate (sc%nl%plastic(sc%parts%n), source=.false.)
      call move_alloc(warm, sc%nl%dl)
    end if
    dt_min = self%dt_max/2.0_dp**max_halvings
    dt = min(self%dt_next, t_end - sc%t)
    ! no sliver of a step left for the end
    if (t_end - sc%t - dt < 1.0e-3_dp*dt) dt = t_end - sc%t
    do
      sc%dt = dt
      ! quasi-static: accel unallocated, so absent in advance_implicit
      ! (taken out of the scene for the call: no alias of sc)
      call move_alloc(sc%accel, accel)
      call advance_implicit(sc, self%solver, self%opt, rep, err, accel)
      call move_alloc(accel, sc%accel)
      if (.not. allocated(err)) exit
      if (err%status /= status_cutback) return
      self%cutbacks = self%cutbacks + 1
      if (dt/2.0_dp < dt_min) then
        why = err%message
        call new_error(err, status_cutback, 'time', why//'; the step was cut back '// &
                       int_text(max_halvings)//' times to '//real_text(dt)//' s')
        return
      end if
      dt = dt/2.0_dp
      deallocate (err)
    end do
    call keep(self, sc%t, dt, rep)
    self%dt_next = dt
    if (2*rep%iterations <= self%opt%max_iterations) self%dt_next = min(self%dt_max, 2.0_dp*dt)
  end subroutine stepper_advance

  !> The step's history into the log (grown by doubling).
  subroutine keep(self, t, dt, rep)
    class(implicit_stepper_t), intent(inout) :: self
    real(dp), intent(in) :: t, dt
    type(newton_report_t), intent(in) :: rep
    type(step_log_t), allocatable :: grown(:)
    if (self%nlog == size(self%log)) then
      allocate (grown(2*self%nlog))
      grown(1:self%nlog) = self%log
      call move_alloc(grown, self%log)
    end if
    self%nlog = self%nlog + 1
    associate (l => self%log(self%nlog))
      l%t = t
      l%dt = dt
      l%solves = rep%iterations
      l%linear_iterations = rep%linear_iterations
      l%sweeps = rep%sweeps
      l%residual = rep%residual(0:rep%iterations)
    end associate
  end subroutine keep

  !> Newton solves over the accepted steps.
  integer function total_solves(self)
    class(implicit_stepper_t), intent(in) :: self
    total_solves = sum(self%log(1:self%nlog)%solves)
  end function total_solves

  !> The most solves one accepted step took.
  integer function max_solves(self)
    class(implicit_stepper_t), intent(in) :: self
    max_solves = 0
    if (self%nlog > 0) max_solves = maxval(self%log(1:self%nlog)%solves)
  end function max_solves

  !> The largest converged relative residual of the accepted steps.
  real(dp) function worst_residual(self)
    class(implicit_stepper_t), intent(in) :: self
    integer :: k
    worst_residual = 0.0_dp
    do k = 1, self%nlog
      associate (r => self%log(k)%residual)
        worst_residual = max(worst_residual, r(size(r)))
      end associate
    end do
  end function worst_residual

end module wellposed_mpm_implicit_stepper
