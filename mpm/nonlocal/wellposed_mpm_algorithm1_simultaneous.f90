!> Step 2 of Algorithm 1 (wellposed_mpm_algorithm1) with the simultaneous
!> sweeps: jacobi (every plastic particle from the field of the previous
!> sweep, relaxed by 2/(2 +- b), b of eq. 4.43) and coloured (two colours of
!> blocks of cell layers), plain or with Anderson: each rank keeps its own
!> entries, the Gram system is summed (docs/guide/parallel.md).
module wellposed_mpm_algorithm1_simultaneous
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_anderson, only: anderson_t, new_anderson, anderson_push, anderson_normal_solve
  use wellposed_mpm_nonlocal_settings, only: nl_anderson, nl_coloured
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  use wellposed_mpm_nonlocal_host, only: nonlocal_host_t
  use wellposed_mpm_sweep_order, only: sweep_layer, sweep_colour
  use wellposed_mpm_algorithm1_work, only: algorithm1_work_t, refresh, stopped
  use wellposed_mpm_algorithm1_sweep, only: sweep_pass, correct_field, measure_sweep
  use wellposed_mpm_algorithm1_convergence, only: sweep_verdict, sweep_converged, sweep_stop, &
                                                  iteration_error
  implicit none
  private
  public :: iterate_simultaneous

contains

  !> Step 2 on this rank's plastic particles act(:) (nact over all ranks):
  !> sweeps (eq. 4.47, 4.39 through the UMAT, 4.49-4.50), each colour from
  !> the field the previous one left, to the tolerances.
  subroutine iterate_simultaneous(self, host, w, act, nact, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: act(:), nact
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: xk(size(act)), gx(size(act)), xn(size(act)), e, e_prev, best, limit, gmax, relax
    integer :: k, kbest, c, ncol, q, verdict, depth, colour(size(act))
    logical :: anderson, defer
    integer(int64) :: s0, s1
    type(anderson_t) :: acc

    call sweep_colours(self, w, act, colour, ncol)
    relax = relaxation(self)
    anderson = self%set%scheme == nl_anderson
    ! at most as many differences as unknowns: more make the least-squares
    ! problem singular, and the step wild
    depth = min(self%set%anderson_depth, nact)
    if (anderson) call new_anderson(acc, size(act), depth, relax*self%set%anderson_mixing)
    ! one colour and a step past the sweep's answer: the field is corrected
    ! once, from x^k to x^{k+1}, not to the sweep's answer and on
    defer = ncol == 1 .and. (anderson .or. relax /= 1.0_dp)
    best = huge(1.0_dp)
    e_prev = huge(1.0_dp)
    kbest = 0
    do k = 1, self%set%max_iterations
      xk = self%dl(act)
      call system_clock(s0)
      do c = 0, ncol - 1
        call refresh(self, w)
        call sweep_pass(self, host, w, pack(act, colour == c), defer, err)
        if (stopped(w, err)) return
      end do
      call system_clock(s1)
      self%ticks_sweeps = self%ticks_sweeps + (s1 - s0)
      call measure_sweep(self, w, act, xk, gx, e, gmax)
      call sweep_verdict(self, k, e, gmax, best, kbest, limit, verdict)
      if (verdict == sweep_converged) then
        if (defer) then
          do q = 1, size(act)
            call correct_field(self, w, act(q), gx(q) - xk(q))
          end do
        end if
        call refresh(self, w)
        return
      end if
      if (verdict == sweep_stop) exit
      if (anderson) then
        ! a residual that grew (the clamp dlambda >= 0 changed the map)
        ! starts the history afresh from the relaxed step
        if (e > e_prev) call new_anderson(acc, size(act), depth, relax*self%set%anderson_mixing)
        e_prev = e
        call summed_anderson_step(w, acc, self%set%anderson_depth, xk, gx, xn)
      else if (relax /= 1.0_dp) then
        xn = xk + relax*(gx - xk)
      else
        cycle
      end if
      do q = 1, size(act)
        call correct_field(self, w, act(q), xn(q) - merge(xk(q), gx(q), defer))
      end do
      self%dl(act) = xn
    end do
    call iteration_error(self, k > self%set%max_iterations, e, best, kbest, limit, nact, err)
  end subroutine iterate_simultaneous

  !> The colours of act(:) (ncol of them): one for jacobi; for coloured
  !> two, by blocks of cell layers as wide as the Gaussian's reach plus one.
  subroutine sweep_colours(self, w, act, colour, ncol)
    type(nonlocal_t), intent(in) :: self
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: act(:)
    integer, intent(out) :: colour(:), ncol
    colour = 0
    ncol = 1
    if (self%sweep /= nl_coloured) return
    ncol = 2
    if (associated(w%key)) then
      colour = sweep_colour(sweep_layer(w%key(act)), ceiling(self%radius/self%dx) + 1)
    else
      colour = sweep_colour(floor((w%x(self%ndim, act) - self%origin(self%ndim))/self%dx), &
                            ceiling(self%radius/self%dx) + 1)
    end if
  end subroutine sweep_colours

  !> The relaxation of the simultaneous sweeps. Their Jacobian is
  !> -h_zeta/(a + h_eta) times the averaging (eq. 4.39, 4.47), eigenvalues
  !> in [-b, 0] for h_zeta > 0, [0, b] for h_zeta < 0 (b = bound_43):
  !> relaxing by 2/(2 + b), resp. 2/(2 - b) when b < 1, centres them on 0,
  !> the smallest factor (docs/guide/parallel.md).
  pure real(dp) function relaxation(self) result(relax)
    type(nonlocal_t), intent(in) :: self
    relax = 1.0_dp
    if (.not. self%bound_43 > 0.0_dp) return
    if (self%h_zeta > 0.0_dp) then
      relax = 2.0_dp/(2.0_dp + self%bound_43)
    else if (self%h_zeta < 0.0_dp .and. self%bound_43 < 1.0_dp) then
      relax = 2.0_dp/(2.0_dp - self%bound_43)
    end if
  end function relaxation

  !> Anderson's step from xk with the sweep's answer gx (anderson_step),
  !> the Gram system dR^T [dR r] summed over the ranks: xn, the next iterate
  !> of this rank's entries. `depth` bounds the history.
  subroutine summed_anderson_step(w, acc, depth, xk, gx, xn)
    type(algorithm1_work_t), intent(in) :: w
    type(anderson_t), intent(inout) :: acc
    integer, intent(in) :: depth
    real(dp), intent(in) :: xk(:), gx(:)
    real(dp), intent(out) :: xn(:)
    real(dp) :: gram(depth*(depth + 1)), gamma(depth)
    real(dp), allocatable :: ata(:, :), atb(:)
    integer :: m
    call anderson_push(acc, xk, gx - xk)
    xn = xk + acc%mixing*(gx - xk)
    m = acc%count
    if (m == 0) return
    gram(1:m*m) = reshape(matmul(transpose(acc%dr(:, 1:m)), acc%dr(:, 1:m)), [m*m])
    gram(m*m + 1:m*m + m) = matmul(gx - xk, acc%dr(:, 1:m))
    if (w%par) call w%ranks%sum_reals(gram(1:m*m + m))
    ata = reshape(gram(1:m*m), [m, m])
    atb = gram(m*m + 1:m*m + m)
    call anderson_normal_solve(ata, atb, gamma(1:m))
    xn = xn - matmul(acc%dx(:, 1:m) + acc%mixing*acc%dr(:, 1:m), gamma(1:m))
  end subroutine summed_anderson_step

end module wellposed_mpm_algorithm1_simultaneous
