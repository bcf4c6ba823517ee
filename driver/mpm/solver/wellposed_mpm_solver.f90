!> The explicit MPM of section 4.3, one step for the 1D bar and the 2D
!> plate: lumped mass (eq. 4.4), internal force with sigma - q I (eq. 4.5),
!> grid update (eq. 4.9-4.10), velocity gradient (eq. 4.11), FLIP update
!> (eq. 4.12-4.13) and the stress through the UMAT by Algorithm 1. MUSL by
!> default (the grid velocity rebuilt from the particles before the strain
!> rate: Wallstedt and Guilkey 2008), or USL. Bulk viscosity (shared
!> reference B): q = rho (A1 c |D_kk| dx + A2 D_kk^2 dx^2) for D_kk < 0.
!> Ranks only through the exchange. The step: docs/guide/mpm.md, "The solver's layout".
module wellposed_mpm_solver
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_config, only: mpm_config_t, scheme_musl, mass_lumped
  use wellposed_mpm_mass_matrix, only: mass_matrix_update
  use wellposed_mpm_plate_config, only: ps_config_t, bc_velocity
  use wellposed_mpm_grid, only: cell_layer
  use wellposed_mpm_shape, only: shape_bar
  use wellposed_mpm_shape_2d, only: shape_2d
  use wellposed_mpm_transfer, only: p2g, grid_update, velocity_from_momentum, g2p, &
                                    velocity_gradients
  use wellposed_mpm_particle_umat, only: strain_increment
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_nonlocal, only: nonlocal_solve, sweep_key
  use wellposed_mpm_scene, only: mpm_scene_t, size_workspace, kinetic_energy, total_momentum, &
                                 applied_stress, plastic_strain, max_substeps, plastic_count, &
                                 timer_transfer, timer_grid, timer_umat, ntimers
  use wellposed_mpm_bar, only: new_bar_scene, probe_moduli, bar_load_t, bar_traction, &
                               bar_impulse, bar_external_work, bar_kinematics
  use wellposed_mpm_plane_strain, only: new_plate_scene, platen_velocity, platen_nodes, &
                                        platen_push
  implicit none
  private
  public :: mpm_scene_t, new_scene, advance, kinetic_energy, total_momentum, applied_stress, &
            plastic_strain, max_substeps, plastic_count, probe_moduli, timer_umat, &
            timer_transfer, timer_grid, ntimers

  !> A scene of a bar (mpm_config_t) or a plate (ps_config_t).
  interface new_scene
    module procedure new_bar_scene, new_plate_scene
  end interface new_scene

contains

  !> One explicit step of length dt (see the module comment for the order).
  !> Collective over the scene's ranks; an error on any rank is an error on
  !> every rank, with the message of the rank where it arose.
  subroutine advance(self, err)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer(int64) :: t0, t1
    integer(int64), allocatable :: skey(:)
    integer :: p, n, d, nt, last
    real(dp) :: dt, mmin, lg(self%ndim, self%ndim), reaction(self%ndim), given(self%ndim)
    type(bar_load_t) :: load

    d = self%ndim
    nt = self%ntens
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
      call shape_weights(self)
      call ex%check_support(pt, g, err)
      call ex%sync_error(err)
      if (allocated(err)) return
      ! --- particle to grid: eq. 4.4, momentum, eq. 4.5 (sigma - q I)
      call p2g(g, pt, n, self%q, self%nnz)
      if (d == 2) call platen_push(self, platen_velocity(self%plate, self%t, dt))
      call ex%sum_grid(g, .false.)
      ! --- the load: the bar's surface traction, the plate's platen
      given = 0.0_dp
      if (d == 1) then
        call bar_traction(self, load)
      else
        call platen_nodes(self)
        given(2) = platen_velocity(self%plate, self%t, dt)
      end if
      call tick(timer_transfer)
      ! --- grid update, eq. 4.9-4.10, and the boundary conditions over the
      ! whole patch: ghost nodes hold the same sums as their owners
      mmin = self%mass_floor
      call grid_update(g, dt, mmin, given, reaction)
      if (d == 1 .and. self%bar%mass /= mass_lumped) then
        call mass_matrix_update(self%bar%mass, g, pt, n, self%nnz, dt, mmin, err)
        if (allocated(err)) return
      end if
      if (d == 1) call bar_impulse(self, load, reaction(1))
      call tick(timer_grid)
      ! --- grid to particle: FLIP velocity (eq. 4.13), position (eq. 4.12)
      call g2p(g, pt, n, dt, self%nnz, musl=self%scheme == scheme_musl)
      if (self%scheme == scheme_musl) then
        ! the grid velocity from the updated particle momentum (g2p's sums)
        call ex%sum_grid(g, .true.)
        call velocity_from_momentum(g, mmin, given)
      end if
      ! --- velocity gradient (eq. 4.11), strain increment, F and volume,
      ! viscosity, rotation
      call velocity_gradients(g, pt, n, self%lgrad, self%nnz)
      if (d == 1) then
        ! the bar in one pass over plain arrays, then what its deck adds (F of
        ! the start when a user's UMAT reads DFGRD0)
        if (allocated(self%f_n)) then
          do p = 1, n
            self%f_n(1, 1, p) = pt%defgrad(1, 1, p)
          end do
        end if
        last = bar_kinematics(n, dt, self%lgrad, size(self%de, 1), self%de, pt%defgrad, &
                              pt%vol0, pt%vol, self%vol_n, size(pt%stress, 1), pt%stress, &
                              size(self%s0, 1), self%s0)
        if (last <= n) call inside_out(last)
        if (self%visc_a1 > 0.0_dp .or. self%visc_a2 > 0.0_dp .or. self%nl%active) then
          do p = 1, last - 1
            lg(1, 1) = self%lgrad(1, 1, p)
            if (self%visc_a1 > 0.0_dp .or. self%visc_a2 > 0.0_dp) call viscosity(self, p, lg)
            call keep_start(p)
          end do
        end if
      else
        do p = 1, n
          ! entry by entry: a whole-array copy of runtime size costs a loop nest
          lg(1, 1) = self%lgrad(1, 1, p)
          lg(2, 1) = self%lgrad(2, 1, p)
          lg(1, 2) = self%lgrad(1, 2, p)
          lg(2, 2) = self%lgrad(2, 2, p)
          call strain_increment(lg, dt, self%de(:, p))
          self%vol_n(p) = pt%vol(p)
          if (allocated(self%f_n)) self%f_n(:, :, p) = pt%defgrad(1:d, 1:d, p)
          call deform(self, p, lg)
          if (.not. pt%vol(p) > 0.0_dp) then
            call inside_out(p)
            exit
          end if
          if (self%visc_a1 > 0.0_dp .or. self%visc_a2 > 0.0_dp) call viscosity(self, p, lg)
          call jaumann(self, p, lg)
          call keep_start(p)
        end do
      end if
      if (d == 1) call bar_external_work(self, load)
      call ex%sync_error(err)
      if (allocated(err)) return
      call tick(timer_transfer)
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
      ! --- bookkeeping: the bar's internal work, with the viscous pressure's
      if (d == 1) then
        do p = 1, n
          self%work_internal = self%work_internal + &
            self%vol_n(p)*0.5_dp*(self%s0(1, p) + pt%stress(1, p))*self%de(1, p)
          if (self%q(p) /= 0.0_dp) self%work_internal = self%work_internal - &
            self%vol_n(p)*self%q(p)*self%de(1, p)
        end do
      end if
      call tick(timer_umat)
    end associate
    self%t = self%t + dt
    self%nstep = self%nstep + 1
    if (d == 2) then
      if (self%plate%top == bc_velocity) self%top_disp = self%top_disp + given(2)*dt
    end if

  contains

    !> The error of particle p turned inside out (det F <= 0).
    subroutine inside_out(p)
      integer, intent(in) :: p
      call new_error(err, status_cutback, 'time', 'step '//int_text(self%nstep + 1)// &
        ': particle '//int_text(self%parts%gid(p))//' was turned inside out (det F <= 0); '// &
        'a smaller &time cfl may help')
    end subroutine inside_out

    !> The start of particle p's stress update: Algorithm 1's sweeps restart
    !> from copies; a local model updates in place (the bar's work keeps
    !> sigma_11 of the start, bar_kinematics).
    subroutine keep_start(p)
      integer, intent(in) :: p
      if (.not. self%nl%active) return
      self%s0(:, p) = self%parts%stress(1:nt, p)
      self%sv0(:, p) = self%parts%statev(:, p)
      self%e0(:, p) = self%parts%stran(1:nt, p)
    end subroutine keep_start

    subroutine tick(timer)
      integer, intent(in) :: timer
      call system_clock(t1)
      self%ticks(timer) = self%ticks(timer) + (t1 - t0)
      t0 = t1
    end subroutine tick

  end subroutine advance

  !> Particles to the rank of their cell layer (collective), with their
  !> material and viscous pressure; the workspace follows the capacity.
  subroutine hand_off(self, err)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: extra(:, :)
    integer :: n, moved
    if (self%exchange%nranks() == 1) then
      call size_workspace(self)
      return
    end if
    n = self%parts%n
    allocate (extra(2, size(self%parts%gid)))
    extra(1, 1:n) = self%q(1:n)
    extra(2, 1:n) = real(self%mat(1:n), dp)
    call self%exchange%hand_off(self%parts, extra, err, moved)
    if (allocated(err)) return
    self%moved = self%moved + moved
    n = self%parts%n
    call size_workspace(self)
    self%q(1:n) = extra(1, 1:n)
    self%mat(1:n) = nint(extra(2, 1:n))
  end subroutine hand_off

  !> The shape kernels: weights and gradients of every particle at x^n
  !> (eq. 4.6-4.7; 2D CPDI follows F).
  subroutine shape_weights(self)
    type(mpm_scene_t), intent(inout) :: self
    integer :: p
    real(dp) :: f2(2, 2)
    associate (pt => self%parts, g => self%grid)
      if (self%ndim == 1) then
        call shape_bar(self%shape, pt%n, pt%x, pt%lp, g%origin, g%dx, pt%nsup, pt%node, pt%phi, &
                       pt%grad)
        self%nnz(1:pt%n) = pt%nsup
      else
        do p = 1, pt%n
          f2 = pt%defgrad(1:2, 1:2, p)
          call shape_2d(self%shape, pt%x(:, p), pt%lp(:, p), f2, self%origin, self%dx, &
                        self%nx, pt%node(:, p), pt%phi(:, p), pt%grad(:, :, p), self%nnz(p))
        end do
      end if
    end associate
  end subroutine shape_weights

  !> The F and volume kernel of a plate's particle p over the step:
  !> F_{n+1} = F_n + dt L F_n, V = det F V_0 (a bar's: bar_kinematics).
  !> The caller checks V > 0 (a particle turned inside out): no error text
  !> here keeps this small enough to inline into the particle loop.
  pure subroutine deform(self, p, lg)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: lg(:, :)
    real(dp) :: f2(2, 2), lf
    integer :: a, b
    associate (pt => self%parts)
      ! F + dt (L F), the product written out (no temporary)
      f2 = pt%defgrad(1:2, 1:2, p)
      do b = 1, 2
        do a = 1, 2
          lf = lg(a, 1)*f2(1, b) + lg(a, 2)*f2(2, b)
          pt%defgrad(a, b, p) = f2(a, b) + self%dt*lf
        end do
      end do
      pt%vol(p) = pt%vol0(p)*(pt%defgrad(1, 1, p)*pt%defgrad(2, 2, p) - &
                              pt%defgrad(1, 2, p)*pt%defgrad(2, 1, p))
    end associate
  end subroutine deform

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

  !> Jaumann rotation of the in-plane stress of particle p before the UMAT:
  !> sigma += dt (W sigma - sigma W), W12 = (L12 - L21)/2.
  pure subroutine jaumann(self, p, lg)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: lg(:, :)
    real(dp) :: wspin, s4(4), dt
    dt = self%dt
    wspin = 0.5_dp*(lg(1, 2) - lg(2, 1))
    associate (pt => self%parts)
      s4 = pt%stress(1:4, p)
      pt%stress(1, p) = s4(1) + 2.0_dp*dt*wspin*s4(4)
      pt%stress(2, p) = s4(2) - 2.0_dp*dt*wspin*s4(4)
      pt%stress(4, p) = s4(4) + dt*wspin*(s4(2) - s4(1))
    end associate
  end subroutine jaumann

end module wellposed_mpm_solver
