!> The explicit MPM of the dissertation's section 4.3 for the 1D
!> uniaxial-strain scenes: lumped mass (eq. 4.4), internal force (eq. 4.5), grid acceleration and
!> forward-Euler velocity (eq. 4.9-4.10), velocity gradient (eq. 4.11),
!> FLIP particle velocity and position update (eq. 4.12-4.13), and the
!> stress update through the UMAT for every particle.
!>
!> Update variant: MUSL by default (deck: scheme = 'musl' or 'usl'). USL is
!> eq. 4.10-4.13 as the dissertation writes them: the strain rate comes from the
!> updated grid velocity v_i^{n+1}. MUSL rebuilds the grid velocity from the
!> updated particle velocities (v_i = sum_p phi_ip m_p v_p / m_i) before the
!> strain rate. Both are first-order-in-time variants of the same scheme;
!> MUSL is the default because its strain rate comes from momentum rather than
!> from f/m_i, so a node with a sliver of mass (a particle just entering a
!> cell, the free surface) cannot produce a spurious strain spike, and it
!> conserves energy better in the comparisons of Wallstedt and Guilkey (2008).
!>
!> One step, in order: hand-off of particles to the rank of their cell ->
!> shape weights and the support check -> P2G (mass, momentum, f_int) ->
!> ghost sum -> surface traction -> grid update and boundary conditions ->
!> G2P (FLIP velocity, position) -> [MUSL: momentum P2G, ghost sum,
!> velocity] -> strain increment, F and volume -> UMAT (Algorithm 1).
!> Units SI, tension positive.
!>
!> Ranks: the scene talks to other ranks only through its
!> exchange (wellposed_mpm_exchange): every rank builds the whole scene,
!> keeps its strip of cells with ghost layers as wide as the shape support
!> or the nonlocal Gaussian's (whichever is wider), and the step above runs
!> unchanged on the patch; the grid update covers ghost nodes too, which
!> hold the same sums as their owners, so no second exchange is needed.
!> Sums over particles (energies, momentum) are reduced over ranks; the
!> bookkeeping sums (work, impulse) stay this rank's share.
module wellposed_mpm_solver
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_config
  use wellposed_mpm_grid, only: grid_t, new_grid_1d, cell_layer
  use wellposed_mpm_particles, only: particles_t, new_particles
  use wellposed_mpm_shape, only: support_size, shape_1d
  use wellposed_mpm_loads, only: surface_stress
  use wellposed_mpm_transfer, only: p2g, p2g_momentum, grid_update, velocity_from_momentum, &
                                    g2p, velocity_gradient
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_update
  use wellposed_mpm_particle_umat, only: strain_increment, umat_particle
  use wellposed_mpm_exchange, only: mpm_exchange_t, mpm_serial_t
  use wellposed_mpm_materials, only: mpm_materials_t, single_material, material_of, &
                                     check_covered
  use wellposed_mpm_nonlocal, only: nonlocal_t, nonlocal_host_t, new_nonlocal, nonlocal_solve, &
                                    nonlocal_ghost_nodes, sweep_key
  implicit none
  private
  public :: mpm_scene_t, new_scene, advance, kinetic_energy, total_momentum, &
            timer_umat, timer_transfer, timer_grid, ntimers, probe_moduli

  integer, parameter :: timer_transfer = 1, timer_grid = 2, timer_umat = 3, ntimers = 3

  !> The state of a running scene. It is the host of the nonlocal
  !> Algorithm 1 (update: one particle through the UMAT from its
  !> start-of-step copies with STATEV(3) = <dlambda>).
  type, extends(nonlocal_host_t) :: mpm_scene_t
    type(mpm_config_t) :: cfg
    type(grid_t) :: grid
    type(particles_t) :: parts
    real(dp) :: t = 0.0_dp             !< time (s)
    real(dp) :: dt = 0.0_dp            !< time step (s)
    integer :: nstep = 0
    real(dp) :: modulus_elastic = 0.0_dp  !< probed d sigma_xx / d eps_xx, compression (Pa)
    real(dp) :: modulus_plastic = 0.0_dp  !< probed, extension from the initial state (Pa)
    real(dp) :: modulus_dt = 0.0_dp       !< modulus the time step was built on (Pa)
    integer :: node_surface = 0           !< global node at x = 0
    integer :: node_far = 0               !< global node at x = length
    ! bookkeeping (per unit cross-section: J/m^2, kg m/s / m^2)
    real(dp) :: work_internal = 0.0_dp    !< int sigma : d eps dV (stored + dissipated)
    real(dp) :: work_external = 0.0_dp    !< work of the surface traction
    real(dp) :: impulse = 0.0_dp          !< time integral of surface force + reaction
    real(dp) :: kinetic0 = 0.0_dp, momentum0 = 0.0_dp
    integer :: max_substeps = 1           !< largest UMAT cut-back split used
    integer :: max_substeps_step = 1      !< the same within the current step
    integer :: nl_log_unit = 6            !< where the nonlocal bound warnings go
    integer(int64) :: ticks(ntimers) = 0_int64
    !> the other ranks (a serial stand-in when the scene was built without)
    class(mpm_exchange_t), allocatable :: exchange
    real(dp) :: mass_floor = 0.0_dp       !< grid nodes below it count as empty (kg/m^2)
    ! workspace
    real(dp), allocatable :: dstrain(:)   !< axial strain increment of the step, per particle
    ! nonlocal Algorithm 1 (the dissertation's chapter 4): solver state, start-of-step copies
    type(nonlocal_t) :: nl
    real(dp), allocatable :: s0(:, :), sv0(:, :), e0(:, :)
    type(umat_host_t) :: host             !< the UMAT host (NTENS = 6), one per scene
    type(mpm_materials_t) :: mats         !< the materials by region (initial x)
  contains
    procedure :: update => scene_update
  end type mpm_scene_t

contains

  !> Build the grid and particles of `cfg`, check that the scene can run,
  !> probe the UMAT at the initial state for the wave speeds and set the time
  !> step dt = cfl * dx / sqrt(M_max / rho). Errors name the deck key.
  !> With `exchange` (collective then) the scene is this rank's share: its
  !> strip of cells with ghost layers (the wider of the shape support and
  !> nonlocal_ghost_nodes) and the particles in it.
  subroutine new_scene(self, cfg, err, exchange)
    type(mpm_scene_t), intent(out) :: self
    type(mpm_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    integer :: ncell_body, ncells, p, c, k, np, ghost
    real(dp) :: frac, lp, m_elastic, m_plastic

    call check_scene(cfg, err)
    if (allocated(err)) return
    self%cfg = cfg
    call new_umat_host(self%host, 6, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    self%host%celent = cfg%dx
    self%mats = single_material(cfg%materials, cfg%props(1:cfg%nprops), cfg%nstatv, 1, &
                                self%host%ours)
    ncell_body = nint(cfg%length/cfg%dx)
    ncells = ncell_body + 2*cfg%pad_cells
    call new_grid_1d(self%grid, -cfg%pad_cells*cfg%dx, cfg%dx, ncells)
    self%node_surface = cfg%pad_cells
    self%node_far = cfg%pad_cells + ncell_body
    select case (cfg%bc_far)
    case (bc_fixed, bc_symmetric)
      ! a wall at x = length: the node on it and those beyond (a GIMP
      ! particle's domain pressed past the wall would give them a sliver
      ! of mass, and USL's v = p/m + f dt/m on it no bound)
      self%grid%fixed(1, self%node_far:) = .true.
    end select

    np = ncell_body*cfg%ppc
    call new_particles(self%parts, np, 1, support_size(cfg%shape), cfg%nstatv)
    lp = 0.5_dp*cfg%dx/cfg%ppc
    p = 0
    do c = 0, ncell_body - 1
      do k = 1, cfg%ppc
        p = p + 1
        frac = (real(k, dp) - 0.5_dp)/cfg%ppc
        self%parts%gid(p) = p
        self%parts%x0(1, p) = (c + frac)*cfg%dx
      end do
    end do
    self%parts%n = np
    call check_covered(self%mats, self%parts%x0(:, 1:np), err)
    if (allocated(err)) return
    self%parts%x = self%parts%x0
    self%parts%v = cfg%velocity0
    self%parts%lp = lp
    self%parts%vol0 = 2.0_dp*lp
    self%parts%vol = self%parts%vol0
    self%parts%mass = cfg%density*self%parts%vol0
    self%parts%defgrad = 0.0_dp
    do k = 1, 3
      self%parts%defgrad(k, k, :) = 1.0_dp
    end do
    do p = 1, np
      self%parts%stress(:, p) = cfg%stress0
    end do
    self%parts%stran = 0.0_dp
    self%parts%statev = 0.0_dp
    ! particle masses never change: one floor for every step
    self%mass_floor = 1.0e-9_dp*minval(self%parts%mass(1:np))
    call new_nonlocal(self%nl, cfg%nonlocal, 1, [self%grid%origin], &
                      cfg%dx, [self%grid%nnodes], self%grid%glo, self%grid%ghi, err)
    if (allocated(err)) then
      err%message = '&nonlocal / &material: '//err%message
      return
    end if
    ! this rank's strip: ghost layers for GIMP's reach and the Gaussian's
    if (present(exchange)) then
      allocate (self%exchange, source=exchange)
    else
      allocate (mpm_serial_t :: self%exchange)
    end if
    ghost = max(merge(0, 1, cfg%shape == shape_linear), nonlocal_ghost_nodes(self%nl))
    call self%exchange%setup(ncells, ghost, self%grid%origin, cfg%dx, err)
    if (allocated(err)) return
    call self%exchange%restrict(self%grid, self%parts, err)
    if (allocated(err)) return
    if (self%grid%glo /= 0 .or. self%grid%ghi /= ncells) then
      call new_nonlocal(self%nl, cfg%nonlocal, 1, &
                        [self%grid%origin], cfg%dx, [self%grid%nnodes], self%grid%glo, &
                        self%grid%ghi, err)
      if (allocated(err)) return
    end if
    call size_workspace(self)

    ! the stiffest material's moduli (the time step)
    do k = 1, self%mats%n
      call probe_moduli(cfg, self%mats%props(1:self%mats%nprops(k), k), m_elastic, m_plastic, &
                        err)
      if (allocated(err)) return
      self%modulus_elastic = max(self%modulus_elastic, m_elastic)
      self%modulus_plastic = max(self%modulus_plastic, m_plastic)
    end do
    self%modulus_dt = max(self%modulus_elastic, self%modulus_plastic)
    self%dt = cfg%cfl*cfg%dx/sqrt(self%modulus_dt/cfg%density)
    self%kinetic0 = kinetic_energy(self)
    self%momentum0 = total_momentum(self)
  end subroutine new_scene

  !> Per-particle workspace for as many particles as the set can hold
  !> (a rank's count changes as particles cross; a restart refills it).
  subroutine size_workspace(self)
    class(mpm_scene_t), intent(inout) :: self
    integer :: cap
    cap = size(self%parts%gid)
    if (allocated(self%dstrain)) then
      if (min(size(self%dstrain), size(self%s0, 2), size(self%sv0, 2), size(self%e0, 2)) &
          >= cap) return
      deallocate (self%dstrain, self%s0, self%sv0, self%e0)
    end if
    allocate (self%dstrain(cap), self%s0(6, cap), self%sv0(self%cfg%nstatv, cap), &
              self%e0(6, cap))
  end subroutine size_workspace

  !> Checks a scene must pass before it runs (impossible scenes: error).
  pure subroutine check_scene(cfg, err)
    type(mpm_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: ncell
    if (.not. (cfg%dx > 0.0_dp .and. ieee_is_finite(cfg%dx))) then
      call bad('grid', 'dx', 'must be a finite cell size > 0 m', err); return
    end if
    if (.not. (cfg%length > 0.0_dp .and. ieee_is_finite(cfg%length))) then
      call bad('grid', 'length', 'must be a finite body length > 0 m', err); return
    end if
    ncell = cfg%length/cfg%dx
    if (abs(ncell - nint(ncell)) > 1.0e-9_dp*ncell .or. nint(ncell) < 2) then
      call bad('grid', 'length', 'must be at least two and a whole number of cells dx', err); return
    end if
    if (nint(ncell)*cfg%ppc > 50000000) then
      call bad('grid', 'dx', 'gives more than 5e7 particles', err); return
    end if
    if (cfg%ppc < 1 .or. cfg%ppc > 8) then
      call bad('grid', 'ppc', 'particles per cell must be 1 ... 8', err); return
    end if
    if (cfg%pad_cells < 2) then
      call bad('grid', 'pad_cells', 'must be >= 2 (the GIMP support reaches past the body)', err)
      return
    end if
    if (.not. (cfg%cfl > 0.0_dp .and. cfg%cfl <= 1.0_dp)) then
      call bad('time', 'cfl', 'the CFL fraction must lie in (0, 1]: dt = cfl*dx/c_max, and '// &
        'above 1 the explicit update is unstable', err); return
    end if
    if (.not. (cfg%t_end > 0.0_dp .and. ieee_is_finite(cfg%t_end))) then
      call bad('time', 't_end', 'must be a finite end time > 0 s', err); return
    end if
    if (.not. (cfg%density > 0.0_dp .and. ieee_is_finite(cfg%density))) then
      call bad('material', 'density', 'must be a finite mass density > 0 kg/m^3', err); return
    end if
    if (cfg%nprops < 1 .or. cfg%nprops > max_props) then
      call bad('material', 'nprops', 'must be 1 ... 40', err); return
    end if
    if (cfg%nstatv < 12) then
      call bad('material', 'nstatv', 'must be >= 12 (the UMAT contract)', err); return
    end if
    if (.not. all(ieee_is_finite(cfg%stress0))) then
      call bad('initial', 'stress', 'must be finite', err); return
    end if
    if (.not. (ieee_is_finite(cfg%load_base) .and. ieee_is_finite(cfg%load_peak) .and. &
               ieee_is_finite(cfg%load_duration) .and. cfg%load_duration >= 0.0_dp)) then
      call bad('load', 'peak', 'base, peak must be finite and duration >= 0', err); return
    end if
    if (cfg%nstations < 0 .or. cfg%station_first < 0.0_dp .or. &
        cfg%station_first + (cfg%nstations - 1)*cfg%station_spacing > cfg%length) then
      call bad('stations', 'first', 'stations must lie inside the body [0, length]', err); return
    end if
    if (.not. (cfg%sample_dt > 0.0_dp)) then
      call bad('output', 'sample_dt', 'must be > 0 s', err); return
    end if
  contains
    pure subroutine bad(group, key, what, e)
      character(len=*), intent(in) :: group, key, what
      type(error_t), allocatable, intent(out) :: e
      call new_error(e, status_invalid, group//'%'//key, '&'//group//' '//key//' '//what)
    end subroutine bad
  end subroutine check_scene

  !> Axial moduli d sigma_xx / d eps_xx of the material at the initial
  !> state, through the UMAT: `elastic` from a compressive increment
  !> (unloading), `plastic` from the second of two extension increments
  !> (the first reaches the cone), each over a long DTIME (1000 s) so that
  !> a rate-dependent model answers with its quasi-static (stiffest) limit.
  !> Increments of 1e-5 strain. Pa.
  subroutine probe_moduli(cfg, props, elastic, plastic, err)
    type(mpm_config_t), intent(in) :: cfg
    real(dp), intent(in) :: props(:)
    real(dp), intent(out) :: elastic, plastic
    type(error_t), allocatable, intent(out) :: err
    real(dp), parameter :: de = 1.0e-5_dp
    real(dp) :: s(6), sv(cfg%nstatv), e(6), d(6), s1
    integer :: nsub
    type(umat_host_t) :: h
    call new_umat_host(h, 6, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    h%celent = cfg%dx
    d = 0.0_dp
    s = cfg%stress0; sv = 0.0_dp; e = 0.0_dp; d(1) = -de
    h%dtime = 1.0e-6_dp
    call host_update(h, props, s, sv, e, d, nsub, err)
    if (allocated(err)) return
    elastic = (s(1) - cfg%stress0(1))/(-de)
    ! the plastic modulus over slow increments (a rate-dependent model relaxed)
    s = cfg%stress0; sv = 0.0_dp; e = 0.0_dp; d(1) = de
    h%dtime = 1.0e3_dp
    call host_update(h, props, s, sv, e, d, nsub, err)
    if (allocated(err)) return
    s1 = s(1)
    h%time = 1.0e3_dp
    call host_update(h, props, s, sv, e, d, nsub, err)
    if (allocated(err)) return
    plastic = (s(1) - s1)/de
    if (.not. (elastic > 0.0_dp .and. plastic > 0.0_dp)) then
      call new_error(err, status_invalid, 'material', 'the material has no positive axial '// &
        'stiffness at the initial state (probed through the UMAT), so no wave can travel')
    end if
  end subroutine probe_moduli

  !> One explicit step of length dt (see the module comment for the order).
  !> Collective over the scene's ranks; an error on any rank is an error on
  !> every rank.
  subroutine advance(self, err)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer(int64) :: t0, t1
    integer(int64), allocatable :: skey(:)
    integer :: p, n, psurf
    real(dp) :: dt, sig_b, xs, w, fs(2), vsurf, de, lg, mmin, surf(4), reaction(1), l1(1, 1), de6(6)
    integer :: is

    associate (g => self%grid, pt => self%parts, cfg => self%cfg, ex => self%exchange)
      dt = self%dt
      call system_clock(t0)
      ! --- particles to the rank of their cell (one rank: nothing moves)
      call ex%hand_off(pt, err)
      if (allocated(err)) return
      n = pt%n
      call size_workspace(self)
      ! --- Algorithm 1's sweep order: the owning cell at x^n (the positions
      ! the hand-off above decided from), then the id; the same keys on one
      ! rank as on N (ids follow x here, so this is the id order). A local
      ! model sweeps nothing: skey stays unallocated, i.e. no key is passed.
      if (self%nl%active) then
        allocate (skey(n))
        do p = 1, n
          skey(p) = sweep_key(cell_layer(pt%x(1, p), g%origin, cfg%dx, g%nnodes - 1), &
                              pt%gid(p))
        end do
      end if
      ! --- shape weights at x^n, eq. 4.6-4.7, and the support check
      do p = 1, n
        call shape_1d(cfg%shape, pt%x(1, p), pt%lp(1, p), g%origin, g%dx, pt%node(:, p), &
                      pt%phi(:, p), pt%grad(1, :, p))
      end do
      call ex%check_support(pt, g, err)
      if (allocated(err)) return
      ! --- particle to grid: eq. 4.4, momentum, eq. 4.5
      call p2g(g, pt, n)
      call ex%sum_grid(g, .false.)
      ! surface traction t_x = -sigma_b on the outward normal -x, at the
      ! surface x_s = x_1 - lp_1, spread with the linear hat; worked out by
      ! the rank holding the surface particle (global id 1) from the summed
      ! node masses, then applied by every rank holding the two nodes
      psurf = findloc(pt%gid(1:n), 1, 1)
      surf = 0.0_dp
      if (psurf > 0) then
        sig_b = surface_stress(cfg, self%t)
        xs = pt%x(1, psurf) - pt%lp(1, psurf)
        is = floor((xs - g%origin)/g%dx)
        w = (xs - (g%origin + is*g%dx))/g%dx
        ! once a tensile pulse moves the surface outside the first node with
        ! mass (linear shapes: the Dirac particle 1 lies inside its cell),
        ! that node's share would fall on a massless node and be dropped:
        ! give the whole traction to the next node (a node outside the
        ! patch carries no mass: no particle lies left of particle 1)
        if (is < g%glo) then
          w = 1.0_dp
        else if (g%mass(is) <= 0.0_dp) then
          w = 1.0_dp
        end if
        fs = -sig_b*[1.0_dp - w, w]
        surf = [real(is, dp), w, fs(1), fs(2)]
      end if
      call ex%sum_reals(surf)
      is = nint(surf(1))
      w = surf(2)
      fs = surf(3:4)
      if (is >= g%glo .and. is <= g%ghi) g%fext(1, is) = g%fext(1, is) + fs(1)
      if (is + 1 >= g%glo .and. is + 1 <= g%ghi) g%fext(1, is + 1) = g%fext(1, is + 1) + fs(2)
      call system_clock(t1)
      self%ticks(timer_transfer) = self%ticks(timer_transfer) + (t1 - t0)
      t0 = t1
      ! --- grid update, eq. 4.9-4.10, and the reaction at fixed nodes, over
      ! the whole patch: ghost nodes hold the same sums as their owners and
      ! give this rank's particles the same velocities
      ! the reaction at the fixed far end enters the impulse
      mmin = self%mass_floor
      call grid_update(g, dt, mmin, [0.0_dp], reaction)
      lg = reaction(1)
      ! the surface force enters the impulse of the surface particle's rank
      if (psurf > 0) then
        self%impulse = self%impulse + dt*(fs(1) + fs(2) + lg)
      else
        self%impulse = self%impulse + dt*lg
      end if
      call system_clock(t1)
      self%ticks(timer_grid) = self%ticks(timer_grid) + (t1 - t0)
      t0 = t1
      ! --- grid to particle: FLIP velocity (eq. 4.13), position (eq. 4.12)
      call g2p(g, pt, n, dt)
      if (cfg%scheme == scheme_musl) then
        ! rebuild the grid velocity from the updated particle momentum
        call p2g_momentum(g, pt, n)
        call ex%sum_grid(g, .true.)
        call velocity_from_momentum(g, mmin, [0.0_dp])
      end if
      ! --- velocity gradient, eq. 4.11: the axial strain increment
      do p = 1, n
        call velocity_gradient(g, pt, p, l1)
        call strain_increment(l1, dt, de6)
        self%dstrain(p) = de6(1)
      end do
      ! external work: surface force times the surface velocity of the strain
      ! (by the surface particle's rank, which holds both nodes when w < 1)
      if (psurf > 0) then
        vsurf = w*g%velocity(1, is + 1)
        if (w < 1.0_dp) vsurf = (1.0_dp - w)*g%velocity(1, is) + vsurf
        self%work_external = self%work_external + dt*(fs(1) + fs(2))*vsurf
      end if
      call system_clock(t1)
      self%ticks(timer_transfer) = self%ticks(timer_transfer) + (t1 - t0)
      t0 = t1
      ! --- stress update through the UMAT (uniaxial strain: d eps_xx only),
      ! by the dissertation's Algorithm 1: with h_zeta = 0 one call per particle,
      ! exactly the local update; otherwise the fixed point on the grid
      do p = 1, n
        self%s0(:, p) = pt%stress(:, p)
        self%sv0(:, p) = pt%statev(:, p)
        self%e0(:, p) = pt%stran(:, p)
      end do
      self%max_substeps_step = 1
      ! (collective: the sweeps in the serial order across ranks; the
      ! bound warnings from rank 0 only)
      if (ex%rank() == 0) then
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, self%nl_log_unit, ex, skey)
      else
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, ranks=ex, key=skey)
      end if
      if (allocated(err)) then
        err%message = 'step '//int_text(self%nstep + 1)//', t = '//real_text(self%t + dt)// &
                      ' s: '//err%message
        return
      end if
      if (self%max_substeps_step > self%max_substeps) self%max_substeps = self%max_substeps_step
      do p = 1, n
        de = self%dstrain(p)
        self%work_internal = self%work_internal + &
          pt%vol(p)*0.5_dp*(self%s0(1, p) + pt%stress(1, p))*de
        pt%defgrad(1, 1, p) = pt%defgrad(1, 1, p)*(1.0_dp + de)
        pt%vol(p) = pt%vol0(p)*pt%defgrad(1, 1, p)
      end do
      call system_clock(t1)
      self%ticks(timer_umat) = self%ticks(timer_umat) + (t1 - t0)
    end associate

    self%t = self%t + self%dt
    self%nstep = self%nstep + 1
  end subroutine advance

  !> The host side of Algorithm 1: particle p from its start-of-step copies
  !> with STATEV(3) = avg through the UMAT host (driver/host: its cut-back
  !> splitting, PNEWDT and non-finite rules); dlambda = STATEV(2) afterwards.
  subroutine scene_update(self, p, avg, dlambda, err)
    class(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: avg
    real(dp), intent(out) :: dlambda
    type(error_t), allocatable, intent(out) :: err
    integer :: nsub, k
    associate (pt => self%parts)
      pt%stress(:, p) = self%s0(:, p)
      pt%statev(:, p) = self%sv0(:, p)
      pt%stran(:, p) = self%e0(:, p)
      k = material_of(self%mats, pt%x0(:, p))
      self%host%ours = self%mats%contract(k)
      call umat_particle(self%host, self%mats%props(1:self%mats%nprops(k), k), self%t, &
                         self%dt, self%nstep + 1, pt%gid(p), pt%x(:, p), pt%stress(:, p), &
                         pt%statev(:, p), pt%stran(:, p), [self%dstrain(p), 0.0_dp, 0.0_dp, &
                         0.0_dp, 0.0_dp, 0.0_dp], avg, dlambda, nsub, err)
      if (allocated(err)) return
      if (nsub > self%max_substeps_step) self%max_substeps_step = nsub
    end associate
  end subroutine scene_update

  !> Kinetic energy of the particles on all ranks (J per m^2 of section;
  !> collective).
  real(dp) function kinetic_energy(self)
    type(mpm_scene_t), intent(in) :: self
    integer :: n
    real(dp) :: e(1)
    n = self%parts%n
    e(1) = 0.5_dp*sum(self%parts%mass(1:n)*self%parts%v(1, 1:n)**2)
    call self%exchange%sum_reals(e)
    kinetic_energy = e(1)
  end function kinetic_energy

  !> Momentum of the particles on all ranks (kg m/s per m^2 of section;
  !> collective).
  real(dp) function total_momentum(self)
    type(mpm_scene_t), intent(in) :: self
    integer :: n
    real(dp) :: m(1)
    n = self%parts%n
    m(1) = sum(self%parts%mass(1:n)*self%parts%v(1, 1:n))
    call self%exchange%sum_reals(m)
    total_momentum = m(1)
  end function total_momentum

end module wellposed_mpm_solver
