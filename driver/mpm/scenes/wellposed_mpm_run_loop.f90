!> The pieces of a scene driver's time loop that every scene kind shares:
!> the wall clock with its progress cadence, the checkpoint cadence (every
!> STEPS steps, by default a tenth of the run, never after the last step)
!> and the snapshot cadence. What a scene prints, samples and saves at
!> those moments is its own (wellposed_mpm_bar_run, wellposed_mpm_plate_run).
module wellposed_mpm_run_loop
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: run_clock_t, checkpoint_every, checkpoint_due, snapshot_due

  !> Wall time of a loop since `start`, and a progress line due every
  !> `interval` seconds.
  type :: run_clock_t
    integer(int64) :: c0 = 0, clast = 0, rate = 1
    real(dp) :: interval = 2.0_dp
  contains
    procedure :: start => clock_start
    procedure :: elapsed => clock_elapsed
    procedure :: progress_due => clock_due
  end type run_clock_t

contains

  subroutine clock_start(self, interval)
    class(run_clock_t), intent(inout) :: self
    real(dp), intent(in) :: interval
    self%interval = interval
    call system_clock(self%c0, self%rate)
    self%clast = self%c0
  end subroutine clock_start

  !> Seconds since start.
  real(dp) function clock_elapsed(self)
    class(run_clock_t), intent(in) :: self
    integer(int64) :: c1
    call system_clock(c1)
    clock_elapsed = real(c1 - self%c0, dp)/self%rate
  end function clock_elapsed

  !> True once every `interval` seconds (the next one counted from now).
  logical function clock_due(self)
    class(run_clock_t), intent(inout) :: self
    integer(int64) :: c1
    call system_clock(c1)
    clock_due = real(c1 - self%clast, dp)/self%rate > self%interval
    if (clock_due) self%clast = c1
  end function clock_due

  !> Steps between checkpoints: the command line's `requested` (0: none),
  !> or a tenth of the run's `nsteps` when it gives none (< 0).
  pure integer function checkpoint_every(requested, nsteps) result(every)
    integer, intent(in) :: requested, nsteps
    every = requested
    if (every < 0) every = max(1, nsteps/10)
  end function checkpoint_every

  !> A checkpoint is due after step `nstep` at time t: every `every` steps,
  !> but not at the end (t_end, steps of dt), where the run's outputs follow.
  pure logical function checkpoint_due(every, nstep, t, t_end, dt) result(due)
    integer, intent(in) :: every, nstep
    real(dp), intent(in) :: t, t_end, dt
    due = .false.
    if (every <= 0) return
    due = mod(nstep, every) == 0 .and. t < t_end - 0.5_dp*dt
  end function checkpoint_due

  !> A snapshot is due at time t when snapshots are on (interval > 0) and
  !> t has reached the next snapshot time `next` within `tol`.
  pure logical function snapshot_due(interval, t, next, tol) result(due)
    real(dp), intent(in) :: interval, t, next, tol
    due = interval > 0.0_dp .and. t >= next - tol
  end function snapshot_due

end module wellposed_mpm_run_loop
