!> The convergence control of Algorithm 1's step 2 (wellposed_mpm_algorithm1):
!> the one test after every sweep (`sweep_verdict`), the error value of an
!> iteration that did not converge, the warnings of the contraction bounds
!> of eq. 4.43 and 4.45, and the step's count of plastic particles.
module wellposed_mpm_algorithm1_convergence
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_text, only: real_text, int_text
  use wellposed_mpm_nonlocal_settings, only: nl_sweep_names, nl_scheme_names
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  implicit none
  private
  public :: warn_bounds, iteration_error, sweep_verdict, sweep_go, sweep_converged, sweep_stop, &
            plastic_stats

  !> sweep_verdict's answers.
  integer, parameter :: sweep_go = 0, sweep_converged = 1, sweep_stop = 2

contains

  !> The contraction bounds' warning and note (once per run each) to `unit`.
  subroutine warn_bounds(self, unit)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: unit
    if (self%bound_43 > 1.0_dp .and. .not. self%warned_sharp) then
      write (unit, '(a)') 'warning: nonlocal contraction factor |h_zeta/(a + h_eta)| '// &
        '(eq. 4.43 with normalised weights) = '//real_text(self%bound_43)//' > 1: the '// &
        'dissertation''s fixed point (scheme fixed_point) is not a contraction and may diverge'
      self%warned_sharp = .true.
    end if
    if (self%last%bound_printed > 1.0_dp .and. .not. self%warned_printed) then
      write (unit, '(a)') 'note: the dissertation''s Lipschitz bound of eq. 4.43, '// &
        'N_alpha |h_zeta/(a + h_eta)| with N_alpha = '//real_text(self%last%n_alpha)//', is '// &
        real_text(self%last%bound_printed)//' > 1 (eq. 4.45: '// &
        real_text(self%last%n_alpha*self%bound_45)//'); it counts every particle in the '// &
        'support at full weight, so convergence is not guaranteed by it; the sharp '// &
        'factor above decides'
      self%warned_printed = .true.
    end if
  end subroutine warn_bounds

  !> After sweep k of step 2 (error e, largest |dlambda| gmax): the error is
  !> recorded and `verdict` is sweep_converged when e <= limit (tolerance +
  !> rel_tolerance gmax), sweep_stop when e is not finite or no new smallest
  !> error came for stall_iterations sweeps (then iteration_error), else
  !> sweep_go. The one test of every sweep scheme.
  subroutine sweep_verdict(self, k, e, gmax, best, kbest, limit, verdict)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: k
    real(dp), intent(in) :: e, gmax
    real(dp), intent(inout) :: best
    integer, intent(inout) :: kbest
    real(dp), intent(out) :: limit
    integer, intent(out) :: verdict
    self%last%error = e
    limit = self%set%tolerance + self%set%rel_tolerance*gmax
    verdict = sweep_stop
    if (.not. ieee_is_finite(e)) return
    verdict = sweep_converged
    if (e <= limit) return
    verdict = sweep_go
    if (e < best) then
      best = e
      kbest = k
    else if (k - kbest >= self%set%stall_iterations) then
      verdict = sweep_stop
    end if
  end subroutine sweep_verdict

  !> The error value of a step-2 iteration that did not converge
  !> (`exhausted`: in max_iterations sweeps) or diverged.
  subroutine iteration_error(self, exhausted, e, best, kbest, limit, nact, err)
    type(nonlocal_t), intent(in) :: self
    logical, intent(in) :: exhausted
    real(dp), intent(in) :: e, best, limit
    integer, intent(in) :: kbest, nact
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: why, hint
    if (exhausted) then
      why = 'did not converge in '//int_text(self%set%max_iterations)//' sweeps'
    else if (.not. ieee_is_finite(e)) then
      why = 'diverges: the error is no longer finite'
    else
      why = 'diverges: no smaller error in '//int_text(self%set%stall_iterations)//' sweeps'
    end if
    if (self%bound_43 > 1.0_dp) then
      hint = ' > 1: the plain fixed point cannot be relied on; set &nonlocal scheme = '// &
             '''anderson'''
    else
      hint = ' <= 1'
    end if
    call new_error(err, status_cutback, 'scheme', 'the nonlocal '// &
      trim(nl_scheme_names(self%set%scheme))//' iteration ('//trim(nl_sweep_names(self%sweep))// &
      ' sweeps) '//why// &
      ' (max |dlambda^{k+1} - dlambda^k| = '//real_text(e)//', smallest '// &
      real_text(best)//' at sweep '//int_text(kbest)//', tolerance '// &
      real_text(limit)//'; '//int_text(nact)//' plastic particles); '// &
      'contraction factor |h_zeta/(a + h_eta)| of eq. 4.43 = '//real_text(self%bound_43)//hint)
  end subroutine iteration_error

  !> The step's count of plastic particles and largest dlambda (at least
  !> 0), in one pass: count and maxval were a pass each, and maxval's NaN
  !> rule a branch per particle (dlambda is finite here: the host checks).
  pure subroutine plastic_stats(self)
    type(nonlocal_t), intent(inout) :: self
    integer :: p, m
    real(dp) :: top
    m = 0
    top = 0.0_dp
    do p = 1, size(self%dl)
      m = m + merge(1, 0, self%plastic(p))
      top = max(top, self%dl(p))
    end do
    self%last%n_plastic = m
    self%last%max_dlambda = top
  end subroutine plastic_stats

end module wellposed_mpm_algorithm1_convergence
