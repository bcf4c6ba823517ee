!> A solve's working state of Algorithm 1 (wellposed_mpm_algorithm1): the
!> step's particles, the ranks, the kind of sweep and the serial order,
!> which the iterations, the sweep and step 3 share; and what each of them
!> does to it: start a solve, project (eq. 4.46) in the serial order,
!> refresh the simultaneous sweeps' field, stop on an error on any rank.
module wellposed_mpm_algorithm1_work
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_nonlocal_settings, only: nl_sweep_auto, nl_gauss_seidel, nl_jacobi
  use wellposed_mpm_nonlocal_state, only: nonlocal_t, nonlocal_step_stats_t
  use wellposed_mpm_nonlocal_grid, only: nonlocal_project, add_projection
  use wellposed_mpm_nonlocal_ranks, only: nonlocal_ranks_t
  use wellposed_mpm_sweep_order, only: key_order
  implicit none
  private
  public :: algorithm1_work_t, start_solve, serial_order, project, refresh, stopped, key_of

  !> What one call of nonlocal_solve works with: its arguments, bound by
  !> pointer for the call's length, and what it derives from them.
  type :: algorithm1_work_t
    real(dp), pointer :: x(:, :) => null()     !< positions (ndim, n), m
    real(dp), pointer :: mass(:) => null()     !< m_p (kg)
    real(dp), pointer :: phi(:, :) => null()   !< this step's shape weights phi_ip (nsup, n)
    integer, pointer :: node(:, :) => null()   !< their nodes i (nsup, n)
    !> the particles' sweep keys (sweep_key); not associated: their indices
    integer(int64), pointer :: key(:) => null()
    !> the other ranks; not associated: one process
    class(nonlocal_ranks_t), pointer :: ranks => null()
    integer :: n = 0                 !< local particles
    logical :: par = .false.         !< over ranks (`ranks` associated)
    logical :: simul = .false.       !< a simultaneous sweep (jacobi, coloured)
    logical :: changed = .false.     !< step 3 made a particle plastic in this round
    integer, allocatable :: order(:) !< the local particles in the serial order
  end type algorithm1_work_t

contains

  !> The start of a solve, `w`'s pointers bound: the step-2 sweep ('auto'
  !> is Gauss-Seidel in one process, Jacobi across ranks), the last step's
  !> measures cleared, the per-particle arrays sized to n (the cache of
  !> the averages' weights emptied).
  subroutine start_solve(self, w)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(inout) :: w
    integer :: n, sweep

    n = size(w%mass)
    w%n = n
    w%par = associated(w%ranks)
    sweep = self%set%sweep
    if (sweep == nl_sweep_auto) then
      sweep = nl_gauss_seidel
      if (w%par) then
        if (w%ranks%nranks() > 1) sweep = nl_jacobi
      end if
    end if
    self%sweep = sweep
    w%simul = sweep /= nl_gauss_seidel
    self%last = nonlocal_step_stats_t()
    if (allocated(self%dl)) then
      if (size(self%dl) /= n) deallocate (self%dl, self%plastic)
    end if
    if (.not. allocated(self%dl)) allocate (self%dl(n), self%plastic(n))
    if (.not. self%active) return
    self%nbmax = 2*ceiling(self%radius/self%dx) + 3
    if (allocated(self%cached)) then
      if (size(self%cached) /= n) deallocate (self%wx, self%wy, self%den, self%blo, &
                                              self%bhi, self%cached)
    end if
    if (.not. allocated(self%cached)) allocate (self%wx(self%nbmax, n), &
      self%wy(self%nbmax, n), self%den(n), self%blo(2, n), self%bhi(2, n), self%cached(n))
    self%cached = .false.
  end subroutine start_solve

  !> w%order: the local particles in the serial order (by key; the
  !> simultaneous sweeps and a run without keys take the storage order).
  subroutine serial_order(w)
    type(algorithm1_work_t), intent(inout) :: w
    integer :: p
    if (associated(w%key) .and. .not. w%simul) then
      call key_order(w%key(1:w%n), w%order)
    else
      w%order = [(p, p=1, w%n)]
    end if
  end subroutine serial_order

  !> Node mass and field from particle `values` (eq. 4.46) in the key
  !> order: with ranks, pipelined (the Gauss-Seidel sweep's order across
  !> ranks); without a key, in storage order. The simultaneous sweeps: each
  !> rank its own part `own`, then the parts added at shared nodes.
  subroutine project(self, w, values)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    real(dp), intent(in) :: values(:)
    if (w%simul) then
      call nonlocal_project(self, w%mass, w%node, w%phi, values)
      self%own = self%field
      if (w%par) then
        call w%ranks%nodes_sum(self%node_mass)
        call w%ranks%nodes_sum(self%field)
      end if
      return
    end if
    if (.not. w%par .and. .not. associated(w%key)) then
      call nonlocal_project(self, w%mass, w%node, w%phi, values)
      return
    end if
    self%node_mass = 0.0_dp
    self%field = 0.0_dp
    if (w%par) then
      call w%ranks%nodes_from_lower(self%node_mass)
      call w%ranks%nodes_from_lower(self%field)
    end if
    call add_projection(self, w%mass, w%node, w%phi, values, w%order)
    if (.not. w%par) return
    call w%ranks%nodes_to_higher(self%node_mass)
    call w%ranks%nodes_to_higher(self%field)
    call w%ranks%nodes_from_highest(self%node_mass)
    call w%ranks%nodes_from_highest(self%field)
  end subroutine project

  !> The field of the simultaneous sweeps: every rank's `own` added at the
  !> nodes they share (collective).
  subroutine refresh(self, w)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    integer(int64) :: t0, t1
    self%field = self%own
    if (.not. w%par) return
    call system_clock(t0)
    call w%ranks%nodes_sum(self%field)
    call system_clock(t1)
    self%ticks_exchange = self%ticks_exchange + (t1 - t0)
  end subroutine refresh

  !> An error on this rank or, with ranks, on any (collective then): every
  !> rank stops with an error value.
  logical function stopped(w, e)
    type(algorithm1_work_t), intent(in) :: w
    type(error_t), allocatable, intent(inout) :: e
    stopped = allocated(e)
    if (.not. w%par) return
    stopped = w%ranks%any_true(stopped)
    if (stopped .and. .not. allocated(e)) call new_error(e, status_invalid, 'ranks', &
      'Algorithm 1 stopped on another rank (its message is above)')
  end function stopped

  !> The serial-order keys of local particles idx(:) (their indices
  !> without keys).
  pure function key_of(w, idx) result(k)
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: idx(:)
    integer(int64) :: k(size(idx))
    if (associated(w%key)) then
      k = w%key(idx)
    else
      k = int(idx, int64)
    end if
  end function key_of

end module wellposed_mpm_algorithm1_work
