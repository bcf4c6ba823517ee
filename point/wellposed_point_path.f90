!> Strain-, stress- and mixed-controlled paths of the single element. A leg
!> prescribes per component the total strain or the stress at its end,
!> reached in `n_inc` equal increments. Stress-controlled components are
!> found by Newton on DDSDDE with a line search, falling back to a
!> finite-difference Jacobian (a direction-dependent tangent, as the EFR's).
!> A refused or unsolved increment is cut back (by PNEWDT, between 1/10 and
!> 1/2); after `max_cutbacks` in a row an error says where and why.
module wellposed_point_path
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_dense, only: solve_dense
  use wellposed_point_material, only: material_t, point_state_t, umat_increment, ntens
  use wellposed_fs, only: int_text
  use wellposed_deck, only: value_text
  implicit none
  private
  public :: leg_t, solver_t, history_t, run_leg, solve_increment, virgin_stiffness

  !> One leg of a path.
  type :: leg_t
    real(dp) :: duration = 1.0_dp        !< time of the leg (> 0)
    integer :: n_inc = 1                 !< number of equal increments
    logical :: stress_control(ntens) = .false.  !< per component: stress (T) or strain (F)
    real(dp) :: target(ntens) = 0.0_dp   !< end-of-leg stress or total strain per component
  end type leg_t

  !> Solver settings (deck group &run).
  type :: solver_t
    !> relative tolerance on controlled stresses: of the largest of the
    !> controlled targets, the increment's start and current stress
    real(dp) :: stress_tol = 1.0e-9_dp
    real(dp) :: stress_floor = 1.0_dp    !< stress scale for the tolerance near zero stress
    integer :: max_iter = 25             !< Newton iterations per increment
    integer :: max_cutbacks = 12         !< consecutive cut-backs before giving up
    logical :: verbose = .true.          !< progress lines on standard output
  end type solver_t

  !> Rows of a path history: one per converged increment.
  type :: history_t
    integer :: n = 0
    real(dp), allocatable :: time(:), strain(:, :), stress(:, :), statev(:, :)
    integer, allocatable :: leg(:), inc(:)
    integer :: cutbacks = 0, fd_jacobians = 0, newton_iterations = 0
  contains
    procedure :: push => history_push
  end type history_t

  !> One increment's problem for solve_increment: the stress targets,
  !> the stress-controlled components u(1:nu), the time increment.
  type :: increment_t
    real(dp) :: sig_t(ntens) = 0.0_dp, dtime = 0.0_dp
    integer :: u(ntens) = 0, nu = 0
  end type increment_t

  !> A Newton iterate: the strain increment, the UMAT's state and DDSDDE
  !> after it, the residual of the stress-controlled components, its
  !> largest component and its sum of squares (the line search's merit).
  type :: iterate_t
    real(dp) :: de(ntens) = 0.0_dp
    type(point_state_t) :: s
    real(dp) :: dd(ntens, ntens) = 0.0_dp, r(ntens) = 0.0_dp
    real(dp) :: rnorm = 0.0_dp, merit = 0.0_dp
  end type iterate_t

  !> The Jacobians of a Newton step, in the order tried.
  integer, parameter :: mode_tangent = 1, mode_elastic = 2, mode_fd = 3
  !> What a Newton step or line search gave.
  integer, parameter :: step_ok = 0, step_retry = 1, step_stop = 2

contains

  subroutine history_push(self, s, leg, inc)
    class(history_t), intent(inout) :: self
    type(point_state_t), intent(in) :: s
    integer, intent(in) :: leg, inc
    integer :: cap, nsv, st(6)
    real(dp), allocatable :: t1(:), t2(:, :)
    integer, allocatable :: i1(:)
    nsv = size(s%statev)
    if (.not. allocated(self%time)) then
      allocate (self%time(64), self%strain(64, ntens), self%stress(64, ntens), &
                self%statev(64, nsv), self%leg(64), self%inc(64))
    end if
    cap = size(self%time)
    if (self%n == cap) then
      st = 0
      allocate (t1(2*cap), stat=st(1)); if (st(1) == 0) t1(1:cap) = self%time
      if (st(1) == 0) call move_alloc(t1, self%time)
      allocate (t2(2*cap, ntens), stat=st(2)); if (st(2) == 0) t2(1:cap, :) = self%strain
      if (st(2) == 0) call move_alloc(t2, self%strain)
      allocate (t2(2*cap, ntens), stat=st(3)); if (st(3) == 0) t2(1:cap, :) = self%stress
      if (st(3) == 0) call move_alloc(t2, self%stress)
      allocate (t2(2*cap, nsv), stat=st(4)); if (st(4) == 0) t2(1:cap, :) = self%statev
      if (st(4) == 0) call move_alloc(t2, self%statev)
      allocate (i1(2*cap), stat=st(5)); if (st(5) == 0) i1(1:cap) = self%leg
      if (st(5) == 0) call move_alloc(i1, self%leg)
      allocate (i1(2*cap), stat=st(6)); if (st(6) == 0) i1(1:cap) = self%inc
      if (st(6) == 0) call move_alloc(i1, self%inc)
      if (any(st /= 0)) call out_of_memory('path history', int(2*cap, int64), maxval(st))
    end if
    self%n = self%n + 1
    self%time(self%n) = s%time
    self%strain(self%n, :) = s%strain
    self%stress(self%n, :) = s%stress
    self%statev(self%n, :) = s%statev
    self%leg(self%n) = leg
    self%inc(self%n) = inc
  end subroutine history_push

  !> Run one leg from `s` (updated to the leg's end). `ileg` numbers the
  !> leg in messages; rows go to `hist` when present (one per converged
  !> increment, cut-back sub-increments included). `d_last` returns the
  !> strain increment of the last converged increment.
  subroutine run_leg(mat, s, leg, ileg, solver, err, hist, d_last, label)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(inout) :: s
    type(leg_t), intent(in) :: leg
    integer, intent(in) :: ileg
    type(solver_t), intent(in) :: solver
    type(error_t), allocatable, intent(out) :: err
    type(history_t), intent(inout), optional :: hist
    real(dp), intent(out), optional :: d_last(ntens)
    character(len=*), intent(in), optional :: label
    type(point_state_t) :: s1, start
    real(dp) :: frac, step, dfrac, eps_t(ntens), sig_t(ntens), dd(ntens, ntens), pnewdt
    real(dp) :: guess(ntens), c_el(ntens, ntens)
    integer :: ncut, inc, iters
    logical :: ok, used_fd
    character(len=:), allocatable :: why
    start = s
    s%kstep = ileg
    s%kinc = 0
    s%step_start = s%time
    call virgin_stiffness(mat, c_el, err)
    if (allocated(err)) then
      call rejected()
      return
    end if
    step = 1.0_dp/leg%n_inc
    frac = 0.0_dp
    dfrac = step
    ncut = 0
    inc = 0
    dd = 0.0_dp
    guess = 0.0_dp
    do while (frac < 1.0_dp - 1.0e-12_dp)
      dfrac = min(dfrac, 1.0_dp - frac)
      eps_t = start%strain + (frac + dfrac)*(leg%target - start%strain)
      sig_t = start%stress + (frac + dfrac)*(leg%target - start%stress)
      call solve_increment(mat, s, eps_t, sig_t, leg%stress_control, dfrac*leg%duration, &
                           solver, guess*dfrac, c_el, s1, dd, pnewdt, ok, iters, used_fd, why, &
                           err)
      if (present(hist)) then
        hist%newton_iterations = hist%newton_iterations + iters
        if (used_fd) hist%fd_jacobians = hist%fd_jacobians + 1
      end if
      if (allocated(err)) then
        call rejected()
        return
      end if
      if (.not. ok) then
        ncut = ncut + 1
        if (present(hist)) hist%cutbacks = hist%cutbacks + 1
        ! consecutive cut-backs, or an increment below the smallest one
        ! they allow (successes with ever smaller increments must not loop)
        if (ncut > solver%max_cutbacks .or. dfrac < step*0.5_dp**solver%max_cutbacks) then
          call new_error(err, status_cutback, 'leg', 'leg '//int_text(ileg)//' cannot be '// &
            'followed: at time '//value_text(s%time)//' (fraction '//value_text(frac)// &
            ' of the leg) '//why//' even after '//int_text(solver%max_cutbacks)// &
            ' cut-backs to an increment of '//value_text(dfrac)//' of the leg. A stress '// &
            'target beyond what the material can carry (perfect plasticity, softening) '// &
            'cannot be reached under stress control; use strain control there. A UMAT whose '// &
            'stress is not smooth or not converged to better than stress_tol = '// &
            value_text(solver%stress_tol)//' (relative) needs a larger stress_tol in &run.')
          return
        end if
        dfrac = dfrac*max(0.1_dp, min(0.5_dp, pnewdt))
        cycle
      end if
      guess = (s1%strain - s%strain)/dfrac
      s = s1
      frac = frac + dfrac
      if (present(d_last)) d_last = guess*dfrac
      ncut = 0
      ! after a cut-back, grow back towards the nominal increment
      dfrac = min(step, 2.0_dp*dfrac)
      inc = inc + 1
      if (present(hist)) call hist%push(s, ileg, inc)
    end do
    if (present(label) .and. solver%verbose) then
      write (*, '(a)') '  ['//label//'] leg '//int_text(ileg)//' done: '// &
        int_text(leg%n_inc)//' increments, time '//value_text(s%time)
    end if

  contains

    subroutine rejected()
      err%message = 'leg '//int_text(ileg)//': the UMAT rejected its input: '// &
        err%message//'; check the PROPS of material "'//mat%label//'"'
    end subroutine rejected

  end subroutine run_leg

  !> DDSDDE of a small strain increment from the stress-free virgin state:
  !> the elastic stiffness for the elastic predictor.
  subroutine virgin_stiffness(mat, c, err)
    type(material_t), intent(in) :: mat
    real(dp), intent(out) :: c(ntens, ntens)
    type(error_t), allocatable, intent(out) :: err
    type(point_state_t) :: s0, s1
    real(dp) :: pnewdt
    allocate (s0%statev(mat%nstatv))
    s0%statev = 0.0_dp
    call umat_increment(mat, s0, [1.0e-9_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], 1.0_dp, &
                        s1, c, pnewdt, err)
    if (allocated(err)) err%message = 'the elastic stiffness at the virgin state: '// &
      err%message
  end subroutine virgin_stiffness

  !> Solve one increment from `s0`: strain-controlled components reach
  !> `eps_t`, stress-controlled ones `sig_t` (to stress_tol). `c_el` is an
  !> elastic stiffness (elastic-predictor Jacobian). `guess` is the
  !> strain increment used as the first guess of the
  !> unknown strains. `ok` false: cut back (`why` says why); `dd` returns
  !> the DDSDDE of the converged call. `err`: the UMAT host's verdict that
  !> the run must stop (refused input, non-finite STRESS or STATEV).
  subroutine solve_increment(mat, s0, eps_t, sig_t, mask, dtime, solver, guess, c_el, s1, &
                             dd, pnewdt, ok, iters, used_fd, why, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s0
    real(dp), intent(in) :: eps_t(ntens), sig_t(ntens), dtime, guess(ntens)
    real(dp), intent(in) :: c_el(ntens, ntens)
    logical, intent(in) :: mask(ntens)
    type(solver_t), intent(in) :: solver
    type(point_state_t), intent(out) :: s1
    real(dp), intent(inout) :: dd(ntens, ntens)
    real(dp), intent(out) :: pnewdt
    logical, intent(out) :: ok, used_fd
    integer, intent(out) :: iters
    character(len=:), allocatable, intent(out) :: why
    type(error_t), allocatable, intent(out) :: err
    type(increment_t) :: inc
    type(iterate_t) :: it, try
    real(dp) :: tol, tol0, x(ntens)
    integer :: i, mode, outcome
    logical :: tried_elastic, from_rest
    inc%sig_t = sig_t
    inc%dtime = dtime
    do i = 1, ntens
      if (mask(i)) then
        inc%nu = inc%nu + 1
        inc%u(inc%nu) = i
      end if
    end do
    associate (u => inc%u, nu => inc%nu)
      it%de = eps_t - s0%strain
      used_fd = .false.
      iters = 0
      ok = .false.
      why = 'no convergence'
      ! the stress scale of the residual: the controlled targets, the stress at
      ! the start of the increment and (below, per iterate) the current stress,
      ! whose round-off bounds how well the controlled components can be met
      tol0 = solver%stress_floor
      if (nu > 0) tol0 = max(tol0, maxval(abs(sig_t(u(1:nu)))))
      tol0 = solver%stress_tol*max(tol0, maxval(abs(s0%stress)))
      ! first guess of the unknown strains: elastic-like prediction with the
      ! last tangent when it is usable, else the previous increment's rate
      if (nu > 0) then
        it%de(u(1:nu)) = 0.0_dp
        it%de(u(1:nu)) = guess(u(1:nu))
      end if
      tried_elastic = .false.
      mode = mode_tangent
      if (all(guess(u(1:nu)) == 0.0_dp)) mode = mode_elastic
    end associate
    ! Starting from a zero increment of the unknown strains, the elastic
    ! predictor step is taken whole: a rate-independent response is
    ! positively homogeneous of degree one in the increment, so at zero it
    ! has no tangent (the extended flow rule's depends on the increment's
    ! direction), and along any ray the residual is linear in the step,
    ! which a line search from zero cannot shorten into a decrease.
    from_rest = mode == mode_elastic
    call trial(mat, s0, inc, it, pnewdt, why, err)
    s1 = it%s             ! the current iterate's state, also on a cut-back
    if (pnewdt < 1.0_dp) return
    do
      tol = max(tol0, solver%stress_tol*maxval(abs(it%s%stress)))
      if (inc%nu == 0 .or. it%rnorm <= tol) then
        ok = .true.
        dd = it%dd
        return
      end if
      iters = iters + 1
      if (iters > solver%max_iter) then
        why = 'the stress-controlled components did not converge in '// &
          int_text(solver%max_iter)//' Newton iterations (residual '//value_text(it%rnorm)// &
          ', tolerance '//value_text(tol)//')'
        pnewdt = 0.5_dp
        return
      end if
      call newton_direction(mat, s0, inc, c_el, it, mode, tried_elastic, used_fd, x, outcome, &
                            pnewdt, why, err)
      if (outcome == step_retry) then
        mode = next_mode(mode, tried_elastic, it%rnorm, tol, why, pnewdt)
        if (mode < 0) return
        cycle
      end if
      if (outcome == step_stop) return
      call line_search(mat, s0, inc, it, x, from_rest, try, outcome, pnewdt, why, err)
      if (outcome == step_stop) return
      from_rest = .false.
      if (outcome == step_retry) then
        mode = next_mode(mode, tried_elastic, it%rnorm, tol, why, pnewdt)
        if (mode < 0) return
        cycle
      end if
      if (mode == mode_elastic) mode = mode_tangent
      it = try
      s1 = it%s
    end do
  end subroutine solve_increment

  !> The Newton step x(1:nu) of the stress-controlled strains from iterate
  !> `it`: the Jacobian of `mode` (the elastic stiffness for an elastic
  !> predictor (first iteration of a leg, or after a failed DDSDDE step),
  !> DDSDDE, or finite differences once both fail to lower the residual).
  !> `outcome`: step_ok, step_retry (this Jacobian gave no step: try the
  !> next) or step_stop (cut back, `why`; or err).
  subroutine newton_direction(mat, s0, inc, c_el, it, mode, tried_elastic, used_fd, x, &
                              outcome, pnewdt, why, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s0
    type(increment_t), intent(in) :: inc
    real(dp), intent(in) :: c_el(ntens, ntens)
    type(iterate_t), intent(in) :: it
    integer, intent(in) :: mode
    logical, intent(inout) :: tried_elastic, used_fd
    real(dp), intent(out) :: x(ntens)
    integer, intent(out) :: outcome
    real(dp), intent(inout) :: pnewdt
    character(len=:), allocatable, intent(inout) :: why
    type(error_t), allocatable, intent(inout) :: err
    real(dp) :: jac(ntens, ntens), b(ntens, 1), hstep, de_try(ntens), dd_try(ntens, ntens)
    type(point_state_t) :: sp
    integer :: j
    logical :: solved
    associate (u => inc%u, nu => inc%nu)
      outcome = step_ok
      solved = .false.
      if (mode == mode_elastic) then
        jac(1:nu, 1:nu) = c_el(u(1:nu), u(1:nu))
        tried_elastic = .true.
      else if (mode == mode_tangent) then
        jac(1:nu, 1:nu) = it%dd(u(1:nu), u(1:nu))
      end if
      if (mode /= mode_fd) then
        if (all(ieee_is_finite(jac(1:nu, 1:nu)))) then
          b(1:nu, 1) = it%r(1:nu)
          call solve_dense(jac(1:nu, 1:nu), b(1:nu, :), solved)
        end if
        if (.not. solved) outcome = step_retry
        if (solved) x(1:nu) = b(1:nu, 1)
        return
      end if
      used_fd = .true.
      hstep = 1.0e-7_dp*max(maxval(abs(it%de)), 1.0e-6_dp)
      do j = 1, nu
        de_try = it%de
        de_try(u(j)) = de_try(u(j)) + hstep
        call umat_increment(mat, s0, de_try, inc%dtime, sp, dd_try, pnewdt, err)
        if (allocated(err)) then
          outcome = step_stop
          return
        end if
        jac(1:nu, j) = (sp%stress(u(1:nu)) - it%s%stress(u(1:nu)))/hstep
      end do
      pnewdt = 1.0_dp
      b(1:nu, 1) = it%r(1:nu)
      call solve_dense(jac(1:nu, 1:nu), b(1:nu, :), solved)
      if (solved) x(1:nu) = b(1:nu, 1)
      if (.not. solved) then
        why = 'the tangent of the stress-controlled components is singular (the '// &
          'material offers no resistance in a controlled direction)'
        pnewdt = 0.5_dp
        outcome = step_stop
      end if
    end associate
  end subroutine newton_direction

  !> Backtracking line search from `it` along -x on the sum of squared
  !> residuals (the Newton direction is a descent direction for it, not
  !> necessarily for the largest component), except for the predictor
  !> step from rest (`from_rest`): the accepted iterate `try`, or
  !> `outcome` step_retry (no step lowered it) or step_stop (cut back).
  subroutine line_search(mat, s0, inc, it, x, from_rest, try, outcome, pnewdt, why, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s0
    type(increment_t), intent(in) :: inc
    type(iterate_t), intent(in) :: it
    real(dp), intent(in) :: x(ntens)
    logical, intent(in) :: from_rest
    type(iterate_t), intent(out) :: try
    integer, intent(out) :: outcome
    real(dp), intent(inout) :: pnewdt
    character(len=:), allocatable, intent(inout) :: why
    type(error_t), allocatable, intent(inout) :: err
    real(dp) :: alpha
    integer :: ls
    alpha = 1.0_dp
    outcome = step_retry
    do ls = 1, 12
      try%de = it%de
      try%de(inc%u(1:inc%nu)) = try%de(inc%u(1:inc%nu)) - alpha*x(1:inc%nu)
      call trial(mat, s0, inc, try, pnewdt, why, err)
      if (pnewdt < 1.0_dp) then
        outcome = step_stop
        return
      end if
      if (try%merit < it%merit .or. from_rest) then
        outcome = step_ok
        return
      end if
      alpha = 0.5_dp*alpha
    end do
  end subroutine line_search

  !> The next Jacobian to try after a failed step with `mode`; -1 (and
  !> `why`, a cut-back) when none is left.
  integer function next_mode(mode, tried_elastic, rnorm, tol, why, pnewdt) result(m)
    integer, intent(in) :: mode
    logical, intent(in) :: tried_elastic
    real(dp), intent(in) :: rnorm, tol
    character(len=:), allocatable, intent(inout) :: why
    real(dp), intent(inout) :: pnewdt
    if (.not. tried_elastic) then
      m = mode_elastic
    else if (mode /= mode_fd) then
      m = mode_fd
    else
      m = -1
      why = 'no step along the Newton direction lowers the stress residual (residual '// &
        value_text(rnorm)//', tolerance '//value_text(tol)//')'
      pnewdt = 0.5_dp
    end if
  end function next_mode

  !> One UMAT call with the strain increment it%de from s0 into `it`: its
  !> state, DDSDDE, residual, largest residual component rnorm and sum of
  !> squares merit (huge when the UMAT cuts back: `why`).
  subroutine trial(mat, s0, inc, it, pnewdt, why, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s0
    type(increment_t), intent(in) :: inc
    type(iterate_t), intent(inout) :: it
    real(dp), intent(out) :: pnewdt
    character(len=:), allocatable, intent(inout) :: why
    type(error_t), allocatable, intent(inout) :: err
    call umat_increment(mat, s0, it%de, inc%dtime, it%s, it%dd, pnewdt, err)
    it%r = 0.0_dp
    it%rnorm = huge(1.0_dp)
    it%merit = huge(1.0_dp)
    if (pnewdt < 1.0_dp) then
      why = 'the UMAT asked for a smaller increment (PNEWDT = '//value_text(pnewdt)//')'
      return
    end if
    associate (u => inc%u, nu => inc%nu)
      if (nu > 0) then
        it%r(1:nu) = it%s%stress(u(1:nu)) - inc%sig_t(u(1:nu))
        it%rnorm = maxval(abs(it%r(1:nu)))
        it%merit = sum(it%r(1:nu)**2)
      else
        it%rnorm = 0.0_dp
        it%merit = 0.0_dp
      end if
    end associate
  end subroutine trial

end module wellposed_point_path
