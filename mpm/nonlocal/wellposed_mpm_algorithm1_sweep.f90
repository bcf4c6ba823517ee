!> One sweep of Algorithm 1's step 2 (wellposed_mpm_algorithm1): for each
!> particle of a list the average (eq. 4.47), the UMAT (eq. 4.39, through
!> the host) and the correction of the nodal field (eq. 4.49-4.50); and
!> what every iteration measures after a sweep.
module wellposed_mpm_algorithm1_sweep
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  use wellposed_mpm_nonlocal_grid, only: cached_average
  use wellposed_mpm_nonlocal_host, only: nonlocal_host_t
  use wellposed_mpm_algorithm1_work, only: algorithm1_work_t
  implicit none
  private
  public :: sweep_pass, correct_field, measure_sweep

contains

  !> One pass over `list` in its order: average, UMAT, correction (eq. 4.47,
  !> 4.39, 4.49-4.50). Gauss-Seidel corrects the field it reads as it goes;
  !> the simultaneous sweeps read the field as the pass began and correct
  !> this rank's part `own`: their UMAT calls go to the host as one list;
  !> with `defer` the correction is left to the caller.
  subroutine sweep_pass(self, host, w, list, defer, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: list(:)
    logical, intent(in) :: defer
    type(error_t), allocatable, intent(out) :: err
    integer :: q, pp
    real(dp) :: avg, dn
    real(dp), allocatable :: avgs(:), dns(:)
    if (w%simul) then
      allocate (avgs(size(list)), dns(size(list)))
      do q = 1, size(list)
        call cached_average(self, list(q), w%x(:, list(q)), avgs(q))
      end do
      call host%update_list(list, avgs, dns, err)
      if (allocated(err)) return
      if (defer) then
        self%dl(list) = dns
        return
      end if
      do q = 1, size(list)
        pp = list(q)
        call correct_field(self, w, pp, dns(q) - self%dl(pp))
        self%dl(pp) = dns(q)
      end do
      return
    end if
    do q = 1, size(list)
      pp = list(q)
      call cached_average(self, pp, w%x(:, pp), avg)
      call host%update(pp, avg, dn, err)
      if (allocated(err)) return
      call correct_field(self, w, pp, dn - self%dl(pp))
      self%dl(pp) = dn
    end do
  end subroutine sweep_pass

  !> eq. 4.49-4.50: move particle p's contribution on its nodes by `delta`
  !> (in the simultaneous sweeps on this rank's part of the field).
  subroutine correct_field(self, w, p, delta)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: p
    real(dp), intent(in) :: delta
    integer :: k, i
    if (delta == 0.0_dp) return
    if (w%simul) then
      do k = 1, size(w%node, 1)
        i = w%node(k, p)
        self%own(i) = self%own(i) + w%mass(p)*w%phi(k, p)*delta
      end do
      return
    end if
    do k = 1, size(w%node, 1)
      i = w%node(k, p)
      self%field(i) = self%field(i) + w%mass(p)*w%phi(k, p)*delta
    end do
  end subroutine correct_field

  !> After a sweep over this rank's act(:) from xk: gx its answer, e the
  !> largest change max |gx - xk| and gmax the largest |gx|, both over the
  !> ranks; the sweep and its UMAT calls counted.
  subroutine measure_sweep(self, w, act, xk, gx, e, gmax)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: act(:)
    real(dp), intent(in) :: xk(:)
    real(dp), intent(out) :: gx(:), e, gmax
    integer(int64) :: s0, s1
    self%calls_sweeps = self%calls_sweeps + size(act)
    self%last%umat_calls = self%last%umat_calls + size(act)
    self%last%iterations = self%last%iterations + 1
    gx = self%dl(act)
    e = 0.0_dp
    gmax = 0.0_dp
    if (size(act) > 0) then
      e = maxval(abs(gx - xk))
      gmax = maxval(abs(gx))
    end if
    if (.not. w%par) return
    call system_clock(s0)
    call w%ranks%max_real(e)
    call w%ranks%max_real(gmax)
    call system_clock(s1)
    self%ticks_exchange = self%ticks_exchange + (s1 - s0)
  end subroutine measure_sweep

end module wellposed_mpm_algorithm1_sweep
