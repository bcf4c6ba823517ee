!> What a run of an implicit scheme (&time scheme = 'implicit' or 'newmark') adds to a
!> kind's run: the stepper's start on the scene (refused with the reason
!> when the scene cannot take the step), its summary keys and the Newton
!> history file <case>_newton.csv. The scheme: docs/research/implicit.md.
module wellposed_mpm_implicit_run
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_checked_io, only: out_file_t
  use wellposed_summary, only: summary_t
  use wellposed_text, only: real_text
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_linear_solver, only: solver_names
  use wellposed_mpm_implicit_step, only: implicit_refusal, dynamic_refusal
  use wellposed_mpm_implicit_stepper, only: implicit_stepper_t
  implicit none
  private
  public :: start_implicit, implicit_summary, write_newton_csv

contains

  !> The stepper of scene sc: steps of at most dt, linear solver `method`,
  !> the trapezoidal rule's dynamic steps when `dynamic`; sc%dt = dt. A
  !> scene the scheme cannot step is the error. A dynamic run's particle
  !> accelerations are the scene's (sc%accel, in its checkpoints).
  subroutine start_implicit(sc, dt, method, dynamic, restart, st, err)
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: dt
    integer, intent(in) :: method
    logical, intent(in) :: dynamic, restart
    type(implicit_stepper_t), intent(inout) :: st
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: why
    ! the scheme's own refusals first: they hold whatever the materials
    why = ''
    if (dynamic) why = dynamic_refusal(sc)
    if (len(why) == 0) why = implicit_refusal(sc)
    if (len(why) > 0) then
      call new_error(err, status_invalid, 'scheme', '&time scheme = '''// &
                     trim(merge('newmark ', 'implicit', dynamic))//''': '//why)
      return
    end if
    sc%dt = dt
    call st%start(dt, method, sc, dynamic)
    st%restarted = restart
  end subroutine start_implicit

  !> The summary keys of the stepper's run, each prefixed by `tag`.
  subroutine implicit_summary(sm, tag, st)
    type(summary_t), intent(inout) :: sm
    character(len=*), intent(in) :: tag
    type(implicit_stepper_t), intent(in) :: st
    associate (l => st%log(1:st%nlog))
      call sm%add(tag//'implicit_steps', st%nlog, 'accepted Newton steps ('// &
                  trim(merge('dynamic, trapezoidal', 'quasi-static        ', st%dynamic))//')')
      if (st%restarted) call sm%add(tag//'implicit_since_restart', .true., 'the implicit '// &
        'keys and the Newton history count the steps since the run continued')
      call sm%add(tag//'linear_solver', trim(solver_names(st%opt%method)))
      call sm%add(tag//'newton_solves', st%total_solves(), 'linear solves over the steps')
      call sm%add(tag//'newton_solves_max', st%max_solves(), 'the most in one step')
      call sm%add(tag//'newton_solves_mean', real(st%total_solves(), dp)/max(1, st%nlog))
      call sm%add(tag//'newton_residual_max', st%worst_residual(), 'largest converged '// &
                  'residual over the force scale (tolerance '//real_text(st%opt%rtol)//')')
      call sm%add(tag//'implicit_cutbacks', st%cutbacks, 'steps halved and retried')
      if (any(l%sweeps > 0)) call sm%add(tag//'nonlocal_sweeps_per_solve', &
        real(sum(l%sweeps), dp)/max(1, st%total_solves() + st%nlog), 'Algorithm 1''s '// &
        'sweeps per residual evaluation (one a Newton iterate)')
      if (st%nlog > 0) then
        call sm%add(tag//'implicit_dt_min', minval(l%dt), 's')
        call sm%add(tag//'implicit_dt_max', maxval(l%dt), 's (at most &time dt)')
      end if
    end associate
  end subroutine implicit_summary

  !> Every accepted step's Newton history, one row per residual evaluation:
  !> step, its end time, size, the solves before it (0: the predictor's),
  !> the relative residual, the step's linear-solver iterations and
  !> Algorithm 1's sweeps over the step (0: a local model).
  subroutine write_newton_csv(path, st, err)
    character(len=*), intent(in) :: path
    type(implicit_stepper_t), intent(in) :: st
    type(error_t), allocatable, intent(out) :: err
    type(out_file_t) :: out
    character(len=120) :: row
    integer :: k, j
    call out%open(path, err)
    if (allocated(err)) return
    call out%put('step,time_s,dt_s,iteration,relative_residual,step_linear_iterations,'// &
                 'step_nonlocal_sweeps')
    do k = 1, st%nlog
      associate (l => st%log(k))
        do j = 0, l%solves
          write (row, '(i0,2(",",es15.7),",",i0,",",es12.4,2(",",i0))') k, l%t, l%dt, j, &
            l%residual(j + 1), l%linear_iterations, l%sweeps
          call out%put(trim(row))
        end do
      end associate
    end do
    call out%close(err)
  end subroutine write_newton_csv

end module wellposed_mpm_implicit_run
