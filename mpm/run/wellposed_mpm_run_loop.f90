!> The one time loop of wellposed-mpm, for every scene kind: step the
!> scene to t_end, after each step ask the case's outputs to sample it
!> (wellposed_mpm_output) and checkpoint when due (every STEPS steps, by
!> default a tenth of the run, never after the last step). With
!> stop_on_cutback a step whose material gave out ends the case at the
!> last complete one. Also the wall clock and the snapshot cadence the
!> outputs share. The loop and its outputs: docs/guide/mpm.md.
module wellposed_mpm_run_loop
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, status_cutback
  use wellposed_mpi, only: comm_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_solver, only: advance
  use wellposed_mpm_output, only: output_list_t, stage_sample
  use wellposed_mpm_checkpoints, only: run_checkpoints_t
  use wellposed_mpm_step_keeper, only: step_keeper_t
  use wellposed_mpm_implicit_stepper, only: implicit_stepper_t
  implicit none
  private
  public :: run_clock_t, checkpoint_every, checkpoint_due, snapshot_due, run_steps, loop_end_t

  !> How a case's steps ended: at t_end, or early at the last complete
  !> step (stop_on_cutback) with the material's message.
  type :: loop_end_t
    logical :: early = .false.
    character(len=:), allocatable :: message
  end type loop_end_t

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

  !> Step `sc` to t_end (steps of dt, the last within half a step of it),
  !> asking `outs` to sample after every step and `cks` to checkpoint
  !> when due (collective). An error of a step or an output is returned;
  !> with stop_on_cutback, one of a material that gave out ends the steps
  !> (`ended`) with `sc` at the last complete step. With `implicit`, its
  !> steps (&time scheme = 'implicit') instead of the explicit ones.
  subroutine run_steps(sc, t_end, outs, cks, comm, stop_on_cutback, ended, err, implicit)
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: t_end
    type(output_list_t), intent(inout) :: outs
    type(run_checkpoints_t), intent(inout) :: cks
    type(comm_t), intent(inout) :: comm
    logical, intent(in) :: stop_on_cutback
    type(loop_end_t), intent(out) :: ended
    type(error_t), allocatable, intent(out) :: err
    type(implicit_stepper_t), intent(inout), optional :: implicit
    type(step_keeper_t) :: keeper
    ended%message = ''
    do while (sc%t < t_end - 0.5_dp*sc%dt)
      ! (an implicit step that fails leaves the scene at its start itself)
      if (stop_on_cutback .and. .not. present(implicit)) call keeper%keep(sc)
      if (present(implicit)) then
        call implicit%advance(sc, t_end, err)
      else
        call advance(sc, err)
      end if
      if (allocated(err)) then
        if (.not. (stop_on_cutback .and. err%status == status_cutback)) return
        ended%message = err%message
        ended%early = .true.
        deallocate (err)
        if (.not. present(implicit)) call keeper%restore(sc, err)
        return
      end if
      call outs%ask(stage_sample, sc, comm, err)
      if (allocated(err)) return
      if (checkpoint_due(cks%every, sc%nstep, sc%t, t_end, sc%dt)) call cks%write(sc, outs, comm)
    end do
  end subroutine run_steps

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
