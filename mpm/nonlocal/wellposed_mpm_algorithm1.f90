!> The dissertation's nonlocal Algorithm 1 for the MPM (eq. 4.46-4.50), one
!> code for 1D and 2D grids: `nonlocal_solve`, one time step. The material
!> is reached through the host (wellposed_mpm_nonlocal_host). Its parts are
!> the files wellposed_mpm_algorithm1_*: work (a solve's state), sweep,
!> gauss_seidel and simultaneous (step 2), diffusion (step 3), convergence.
!> Across ranks: docs/guide/parallel.md, "Algorithm 1 across ranks".
module wellposed_mpm_algorithm1
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_text, only: int_text
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  use wellposed_mpm_nonlocal_grid, only: row_prefix, disk_mass
  use wellposed_mpm_nonlocal_ranks, only: nonlocal_ranks_t
  use wellposed_mpm_nonlocal_host, only: nonlocal_host_t
  use wellposed_mpm_algorithm1_work, only: algorithm1_work_t, start_solve, serial_order, &
                                           project, stopped
  use wellposed_mpm_algorithm1_gauss_seidel, only: iterate_gauss_seidel
  use wellposed_mpm_algorithm1_simultaneous, only: iterate_simultaneous
  use wellposed_mpm_algorithm1_diffusion, only: plastic_diffusion
  use wellposed_mpm_algorithm1_convergence, only: plastic_stats, warn_bounds
  implicit none
  private
  public :: nonlocal_host_t, nonlocal_ranks_t, nonlocal_solve

contains

  !> One time step of Algorithm 1: (1) every particle once with <dlambda> = 0
  !> (eq. 4.41), the plastic set where dlambda > 0 (h_zeta = 0: the local
  !> update); (2) sweeps over the plastic set, the field corrected by
  !> (m_p/m_i) phi_ip (dlambda^{k+1} - dlambda^k) (eq. 4.49-4.50), to the
  !> tolerances; (3) elastic particles with a nonzero average called once
  !> more, and step 2 again if one yields. `x` (ndim, n) positions (m),
  !> `mass` (kg), `node`/`phi` this step's shape weights (nsup, n). A stall,
  !> divergence or host error is an error value; `log_unit` takes the
  !> warnings of eq. 4.43 and 4.45's bounds. Over ranks: `ranks` and `key`
  !> (sweep_key, unique), collective, errors and self%last alike on all.
  !> `dl_start` (n): a first iterate of step 2 in place of the local one.
  subroutine nonlocal_solve(self, host, x, mass, node, phi, err, log_unit, ranks, key, dl_start)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    real(dp), intent(in), target :: x(:, :), mass(:), phi(:, :)
    integer, intent(in), target :: node(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: log_unit
    class(nonlocal_ranks_t), intent(inout), optional, target :: ranks
    integer(int64), intent(in), optional, target :: key(:)
    real(dp), intent(in), optional :: dl_start(:)
    type(algorithm1_work_t) :: w
    integer :: round
    integer, allocatable :: act(:)

    w%x => x
    w%mass => mass
    w%node => node
    w%phi => phi
    if (present(key)) w%key => key
    if (present(ranks)) w%ranks => ranks
    call start_solve(self, w)
    call local_estimate(self, host, w, err)
    if (allocated(err)) return
    if (.not. self%active .or. self%last%n_plastic == 0) return
    ! a warm start (the implicit scheme's last Newton iterate): its dlambda
    ! where it has one for the plastic set, the local estimate elsewhere
    if (present(dl_start)) where (self%plastic .and. dl_start > 0.0_dp) self%dl = dl_start
    call serial_order(w)
    call project(self, w, self%dl)
    call check_bounds(self, w, log_unit)
    do round = 1, self%set%max_rounds
      self%last%rounds = round
      act = pack(w%order, self%plastic(w%order))
      call iterate(self, host, w, act, err)
      if (allocated(err)) return
      call plastic_diffusion(self, host, w, err)
      if (allocated(err)) return
      if (.not. w%changed) exit
      if (round == self%set%max_rounds) then
        call new_error(err, status_cutback, 'max_rounds', 'the nonlocal plastic set kept '// &
          'growing by plastic diffusion (step 3 of Algorithm 1) after '// &
          int_text(self%set%max_rounds)//' rounds; raise &nonlocal max_rounds')
        return
      end if
    end do
    call count_step(self, w)
  end subroutine nonlocal_solve

  !> Step 1: the local estimate, every particle with <dlambda> = 0; the
  !> plastic set, its size and largest dlambda over the ranks.
  subroutine local_estimate(self, host, w, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(in) :: w
    type(error_t), allocatable, intent(out) :: err
    integer(int64) :: c0, c1
    call system_clock(c0)
    call host%update_local(self%dl, err)
    if (stopped(w, err)) return
    call system_clock(c1)
    self%ticks_local = self%ticks_local + (c1 - c0)
    self%calls_local = self%calls_local + w%n
    self%last%umat_calls = w%n
    self%plastic = self%dl > 0.0_dp
    call plastic_stats(self)
    if (w%par) then
      call w%ranks%sum_int(self%last%n_plastic)
      call w%ranks%max_real(self%last%max_dlambda)
    end if
  end subroutine local_estimate

  !> The bounds of eq. 4.43 and 4.45 with this step's N_alpha (the largest
  !> support mass of a plastic particle over its own), before iterating;
  !> their warnings to `log_unit`.
  subroutine check_bounds(self, w, log_unit)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in), optional :: log_unit
    integer :: p
    real(dp), allocatable :: prefix(:)
    if (any(self%plastic(1:w%n))) then
      allocate (prefix(self%glo:self%ghi))
      call row_prefix(self, prefix)
    end if
    do p = 1, w%n
      if (.not. self%plastic(p)) cycle
      self%last%n_alpha = max(self%last%n_alpha, disk_mass(self, prefix, w%x(:, p))/w%mass(p))
    end do
    if (w%par) call w%ranks%max_real(self%last%n_alpha)
    if (self%bound_43 >= 0.0_dp) self%last%bound_printed = self%last%n_alpha*self%bound_43
    if (present(log_unit)) call warn_bounds(self, log_unit)
  end subroutine check_bounds

  !> Step 2 on this rank's plastic particles act(:), in the serial order:
  !> the sweep of the solve (wellposed_mpm_algorithm1_gauss_seidel or
  !> _simultaneous), plain or with Anderson.
  subroutine iterate(self, host, w, act, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: act(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: nact
    nact = size(act)
    if (w%par) call w%ranks%sum_int(nact)
    if (w%simul) then
      call iterate_simultaneous(self, host, w, act, nact, err)
    else
      call iterate_gauss_seidel(self, host, w, act, nact, err)
    end if
  end subroutine iterate

  !> The step's final measures over the ranks and the run's totals.
  subroutine count_step(self, w)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    call plastic_stats(self)
    if (w%par) then
      call w%ranks%sum_int(self%last%n_plastic)
      call w%ranks%sum_int(self%last%n_reclassified)
      call w%ranks%max_real(self%last%max_dlambda)
    end if
    self%steps_iterated = self%steps_iterated + 1
    self%iterations_total = self%iterations_total + self%last%iterations
    self%iterations_max = max(self%iterations_max, self%last%iterations)
  end subroutine count_step

end module wellposed_mpm_algorithm1
