!> Step 2 of Algorithm 1 (wellposed_mpm_algorithm1) with the dissertation's
!> Gauss-Seidel sweep in the serial order, pipelined across ranks: the
!> fixed point of eq. 4.39, plain or accelerated by Anderson on the whole
!> plastic set (every rank runs it on the gathered vectors, bitwise alike).
module wellposed_mpm_algorithm1_gauss_seidel
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_anderson, only: anderson_t, new_anderson, anderson_step
  use wellposed_mpm_nonlocal_settings, only: nl_anderson
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  use wellposed_mpm_nonlocal_host, only: nonlocal_host_t
  use wellposed_mpm_sweep_order, only: key_order, find_sorted
  use wellposed_mpm_algorithm1_work, only: algorithm1_work_t, project, stopped, key_of
  use wellposed_mpm_algorithm1_sweep, only: sweep_pass, measure_sweep
  use wellposed_mpm_algorithm1_convergence, only: sweep_verdict, sweep_converged, sweep_stop, &
                                                  iteration_error
  implicit none
  private
  public :: iterate_gauss_seidel

contains

  !> Step 2 on this rank's plastic particles act(:) in the serial order
  !> (nact over all ranks): Gauss-Seidel sweeps (eq. 4.47, 4.39 through the
  !> UMAT, 4.49-4.50) to the tolerances, the field passed from rank to rank.
  subroutine iterate_gauss_seidel(self, host, w, act, nact, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: act(:), nact
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: xk(size(act)), gx(size(act)), e, best, limit, gmax
    real(dp), allocatable :: xn(:), xall(:), gall(:)
    integer, allocatable :: perm(:), pos(:)
    integer :: k, kbest, verdict
    integer(int64) :: s0, s1, s2, s3
    logical :: anderson
    type(anderson_t) :: acc

    anderson = self%set%scheme == nl_anderson
    if (anderson) then
      if (w%par) call serial_positions(w, act, perm, pos)
      call new_anderson(acc, nact, self%set%anderson_depth, self%set%anderson_mixing)
      allocate (xn(nact))
    end if
    best = huge(1.0_dp)
    kbest = 0
    do k = 1, self%set%max_iterations
      xk = self%dl(act)
      call system_clock(s0)
      if (w%par) call w%ranks%nodes_from_lower(self%field)
      call system_clock(s1)
      self%ticks_exchange = self%ticks_exchange + (s1 - s0)
      call sweep_pass(self, host, w, act, .false., err)
      if (w%par) then
        call system_clock(s2)
        call w%ranks%nodes_to_higher(self%field)
        call w%ranks%nodes_from_highest(self%field)
        call system_clock(s3)
        self%ticks_exchange = self%ticks_exchange + (s3 - s2)
      end if
      if (stopped(w, err)) return
      call system_clock(s1)
      self%ticks_sweeps = self%ticks_sweeps + (s1 - s0)
      call measure_sweep(self, w, act, xk, gx, e, gmax)
      call sweep_verdict(self, k, e, gmax, best, kbest, limit, verdict)
      if (verdict == sweep_converged) return
      if (verdict == sweep_stop) exit
      if (.not. anderson) cycle
      if (w%par) then
        call w%ranks%gather_all(xk, xall)
        call w%ranks%gather_all(gx, gall)
        call anderson_step(acc, xall(perm), gall(perm), xn)
        self%dl(act) = xn(pos)
      else
        call anderson_step(acc, xk, gx, xn)
        self%dl(act) = xn
      end if
      call project(self, w, self%dl)
    end do
    call iteration_error(self, k > self%set%max_iterations, e, best, kbest, limit, nact, err)
  end subroutine iterate_gauss_seidel

  !> Anderson across ranks on the gathered vectors (rank order): perm puts
  !> them in the serial order, pos(q) is where act(q) stands in it.
  subroutine serial_positions(w, act, perm, pos)
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: act(:)
    integer, allocatable, intent(out) :: perm(:), pos(:)
    real(dp), allocatable :: kall(:)
    integer :: q
    call w%ranks%gather_all(real(key_of(w, act), dp), kall)
    call key_order(nint(kall, int64), perm)
    kall = kall(perm)
    allocate (pos(size(act)))
    do q = 1, size(act)
      pos(q) = find_sorted(kall, real(key_of(w, [act(q)]), dp))
    end do
  end subroutine serial_positions

end module wellposed_mpm_algorithm1_gauss_seidel
