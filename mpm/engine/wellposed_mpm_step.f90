!> The explicit MPM of section 4.3, one step in ndim dimensions for every
!> scene kind: lumped mass (eq. 4.4), internal force with sigma - q I (eq.
!> 4.5), grid update (eq. 4.9-4.10), velocity gradient (eq. 4.11), FLIP
!> update (eq. 4.12-4.13) and the stress through the UMAT by Algorithm 1;
!> the kind's loads, kinematics and bookkeeping between. MUSL by default
!> (Wallstedt and Guilkey 2008) or USL. Bulk viscosity (shared reference
!> B): q = rho (A1 c |D_kk| dx + A2 D_kk^2 dx^2) for D_kk < 0. Ranks only
!> through the exchange. The step: docs/guide/mpm.md, "The solver's layout".
module wellposed_mpm_step
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_method, only: scheme_musl
  use wellposed_mpm_grid, only: cell_layer
  use wellposed_mpm_shape_weights, only: shape_weights
  use wellposed_mpm_transfer, only: p2g, grid_update, velocity_from_momentum, g2p, &
                                    velocity_gradients
  use wellposed_mpm_nonlocal, only: nonlocal_solve, sweep_key
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t, size_workspace, timer_transfer, &
                                 timer_grid, timer_umat, keep_start
  implicit none
  private
  public :: advance, hand_off

contains

  !> One explicit step of length dt (see the module comment for the order).
  !> Collective over the scene's ranks; an error on any rank is an error on
  !> every rank, with the message of the rank where it arose. The kind
  !> leaves the scene for the step, so its bindings change it through their
  !> own argument and read the scene without an alias of it.
  subroutine advance(self, err)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    class(scene_kind_t), allocatable :: kind
    call move_alloc(self%kind, kind)
    call step(self, kind, err)
    call move_alloc(kind, self%kind)
  end subroutine advance

  !> The step of `advance`, the scene's kind in `kind`.
  subroutine step(self, kind, err)
    type(mpm_scene_t), intent(inout) :: self
    class(scene_kind_t), intent(inout) :: kind
    type(error_t), allocatable, intent(out) :: err
    integer(int64) :: t0
    integer(int64), allocatable :: skey(:)
    integer :: p, n, d, last
    real(dp) :: dt, mmin, reaction(self%ndim), given(self%ndim)
    logical :: visc

    d = self%ndim
    dt = self%dt
    call system_clock(t0)
    call hand_off(self, err)
    if (allocated(err)) return
    associate (g => self%grid, pt => self%parts, ex => self%exchange)
      n = pt%n
      ! --- Algorithm 1's sweep order: the owning cell layer at x^n (the
      ! positions the hand-off above decided from), then the id; the same
      ! keys on one rank as on N. A local model sweeps nothing: skey stays
      ! unallocated, i.e. no key is passed.
      if (self%nl%active) then
        allocate (skey(n))
        do p = 1, n
          skey(p) = sweep_key(cell_layer(pt%x(d, p), self%origin(d), self%dx, self%nlayers), &
                              pt%gid(p))
        end do
      end if
      ! --- shape weights at x^n, eq. 4.6-4.7, and the support check
      call shape_weights(self%shape, pt, self%origin, self%dx, self%nx, self%nnz)
      call ex%check_support(pt, g, err)
      call ex%sync_error(err)
      if (allocated(err)) return
      ! --- particle to grid: eq. 4.4, momentum, eq. 4.5 (sigma - q I), and
      ! the kind's forces of its own particles (before the ghost sum)
      call p2g(g, pt, n, self%q, self%nnz)
      call kind%forces(self)
      call ex%sum_grid(g, .false.)
      ! --- the kind's loads and boundary conditions on the summed grid
      given = 0.0_dp
      call kind%conditions(self, given)
      call tick(self, timer_transfer, t0)
      ! --- grid update, eq. 4.9-4.10, and the boundary conditions over the
      ! whole patch: ghost nodes hold the same sums as their owners
      mmin = self%mass_floor
      call grid_update(g, dt, mmin, given, reaction)
      call kind%grid_solved(self, reaction, err)
      if (allocated(err)) return
      call tick(self, timer_grid, t0)
      ! --- grid to particle: FLIP velocity (eq. 4.13), position (eq. 4.12)
      call g2p(g, pt, n, dt, self%nnz, musl=self%scheme == scheme_musl)
      if (self%scheme == scheme_musl) then
        ! the grid velocity from the updated particle momentum (g2p's sums)
        call ex%sum_grid(g, .true.)
        call velocity_from_momentum(g, mmin, given)
      end if
      ! --- velocity gradient (eq. 4.11); the kind's strain increment, F and
      ! volume; viscosity; the start of Algorithm 1's sweeps
      call velocity_gradients(g, pt, n, self%lgrad, self%nnz)
      last = kind%kinematics(self)
      if (last <= n) call inside_out(self, last, err)
      visc = self%visc_a1 > 0.0_dp .or. self%visc_a2 > 0.0_dp
      if (visc .or. self%nl%active) then
        do p = 1, last - 1
          if (visc) call viscosity(self, p, self%lgrad(:, :, p))
          call keep_start(self, p)
        end do
      end if
      call ex%sync_error(err)
      if (allocated(err)) return
      call tick(self, timer_transfer, t0)
      ! --- stress update through the UMAT by the dissertation's Algorithm 1:
      ! with h_zeta = 0 one call per particle, exactly the local update;
      ! otherwise the fixed point on the grid (collective: the sweeps in the
      ! serial order across ranks; the bound warnings from rank 0 only)
      self%max_substeps_step = 1
      if (ex%rank() == 0) then
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, self%nl_log_unit, ex, skey)
      else
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, ranks=ex, key=skey)
      end if
      if (allocated(err)) err%message = 'step '//int_text(self%nstep + 1)//', t = '// &
                                        real_text(self%t + dt)//' s: '//err%message
      call ex%sync_error(err)
      if (allocated(err)) return
      if (self%max_substeps_step > self%max_substeps) self%max_substeps = self%max_substeps_step
      ! --- the kind's bookkeeping of the step
      call kind%bookkeeping(self)
      call tick(self, timer_umat, t0)
    end associate
    self%t = self%t + dt
    self%nstep = self%nstep + 1
  end subroutine step

  !> The error of particle p turned inside out (det F <= 0).
  subroutine inside_out(self, p, err)
    type(mpm_scene_t), intent(in) :: self
    integer, intent(in) :: p
    type(error_t), allocatable, intent(inout) :: err
    call new_error(err, status_cutback, 'time', 'step '//int_text(self%nstep + 1)// &
      ': particle '//int_text(self%parts%gid(p))//' was turned inside out (det F <= 0); '// &
      'a smaller &time cfl may help')
  end subroutine inside_out

  !> The clock since t0 added to the scene's timer; t0 becomes now.
  subroutine tick(self, timer, t0)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: timer
    integer(int64), intent(inout) :: t0
    integer(int64) :: t1
    call system_clock(t1)
    self%ticks(timer) = self%ticks(timer) + (t1 - t0)
    t0 = t1
  end subroutine tick

  !> Particles to the rank of their cell layer (collective), with their
  !> material, viscous pressure, (a Newmark run) acceleration and, given,
  !> their values of `carry` (one a particle: the implicit step's warm
  !> start of Algorithm 1); the workspace follows the capacity.
  subroutine hand_off(self, err, carry)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable, intent(inout), optional :: carry(:)
    real(dp), allocatable :: extra(:, :)
    integer :: n, moved, na, nc
    if (self%exchange%nranks() == 1) then
      call size_workspace(self)
      return
    end if
    n = self%parts%n
    na = 0
    if (allocated(self%accel)) na = self%ndim
    nc = 0
    if (present(carry)) then
      if (allocated(carry)) nc = 1
    end if
    allocate (extra(2 + na + nc, size(self%parts%gid)))
    extra(1, 1:n) = self%q(1:n)
    extra(2, 1:n) = real(self%mat(1:n), dp)
    if (na > 0) extra(3:2 + na, 1:n) = self%accel(:, 1:n)
    if (nc > 0) extra(3 + na, 1:n) = carry(1:n)
    call self%exchange%hand_off(self%parts, extra, err, moved)
    if (allocated(err)) return
    self%moved = self%moved + moved
    n = self%parts%n
    call size_workspace(self)
    self%q(1:n) = extra(1, 1:n)
    self%mat(1:n) = nint(extra(2, 1:n))
    if (na > 0) self%accel(:, 1:n) = extra(3:2 + na, 1:n)
    if (nc > 0) carry = extra(3 + na, 1:n)
  end subroutine hand_off

  !> Bulk artificial viscosity of particle p (shared reference B): q = rho
  !> (A1 c |D_kk| dx + A2 D_kk^2 dx^2) in compression (D_kk < 0), else 0.
  pure subroutine viscosity(self, p, lg)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: lg(:, :)
    real(dp) :: dkk, rho
    integer :: k
    dkk = lg(1, 1)
    do k = 2, self%ndim
      dkk = dkk + lg(k, k)
    end do
    rho = self%parts%mass(p)/self%parts%vol(p)
    if (dkk < 0.0_dp) then
      self%q(p) = rho*(self%visc_a1*self%c_visc*abs(dkk)*self%dx + &
                       self%visc_a2*(dkk*self%dx)**2)
    else
      self%q(p) = 0.0_dp
    end if
  end subroutine viscosity

end module wellposed_mpm_step
