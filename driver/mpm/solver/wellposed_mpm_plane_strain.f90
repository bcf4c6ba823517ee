!> The explicit MPM of the dissertation's section 4.3 in 2D plane strain (chapter 4's
!> plate, fig. 4.1): a rectangular body [0, width] x [0, height] on a
!> uniform grid, 2D GIMP, CPDI or linear weights (wellposed_mpm_shape_2d),
!> the material through the UMAT with NTENS = 4 (11, 22, 33, 12; engineering
!> shear) and the dissertation's nonlocal Algorithm 1 (wellposed_mpm_nonlocal, the
!> same code as in 1D). Update: MUSL (as the 1D driver), Jaumann rotation of
!> the stress before the UMAT, F_{n+1} = (I + L dt) F_n, V = det F V0.
!>
!> Boundaries (deck): bottom 'roller' (v_y = 0 on nodes at y <= 0), 'fixed'
!> or 'free'; top 'velocity' (nodes at y >= height get (0, v_top), ramped
!> over ramp_time, for 0 <= x <= width: the platen covers the top face and
!> no more; with top_lateral_fixed = .false. only v_y) or 'free'; sides 'free' or 'roller' (v_x = 0 on nodes at
!> x <= 0 and x >= width). Nodes beyond a boundary line share its condition,
!> so GIMP/CPDI supports reaching past it see the same velocity.
!> Bulk artificial viscosity (shared reference B): q = rho (A1 c |D_kk| dx +
!> A2 D_kk^2 dx^2) when D_kk < 0, else 0, c = sqrt(K/rho) with K probed
!> through the UMAT; q enters the internal force as sigma - q I and is not
!> part of the material state.
!> Time step dt = cfl * dx / c_max, c_max = sqrt(M/rho) with the
!> constrained modulus M probed through the UMAT. SI units, tension +.
!>
!> Ranks: the scene carries a communicator and a domain
!> decomposition (wellposed_mpm_decomposition): strips of whole cell rows
!> (node g = i + nx*j, so a strip is one range of node numbers), each rank
!> holding the nodes its cells touch plus ghost rows as wide as the shape's
!> reach (shape2d_reach: linear 0, GIMP 1, CPDI 2). A particle belongs to the
!> rank of its cell row and is handed off, whole and with its viscous
!> pressure and material, when it crosses (start of a step). Mass, momentum
!> and force are summed over the ranks sharing a node (every holder adds the
!> partial sums in rank order, so all copies agree bitwise); the grid update
!> then runs over the whole patch, so ghost nodes hold their owners'
!> velocities without a second exchange. An error on one rank stops every
!> rank with its message. With one rank every exchange is skipped and the
!> step is the serial one bit for bit; with more, results differ from it by
!> the order of the nodal additions only. Nonlocal averaging (h_zeta /= 0)
!> widens the ghost rows to the Gaussian's support (nonlocal_ghost_nodes)
!> and runs Algorithm 1's passes over the nodal field as the pipeline of
!> wellposed_mpm_nonlocal, ordered by the owning cell row at the start of
!> the step, then the global id (sweep_key; one rank passes the same keys),
!> through the neighbour exchanges of wellposed_mpm_ranks on these strips
!> (the same as the 1D driver's): the sweeps and their counts are the
!> serial ones.
module wellposed_mpm_plane_strain
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_error, &
                                verdict_ok, verdict_cutback
  use wellposed_mpm_materials, only: mpm_materials_t, single_material, material_of, &
                                     check_covered
  use wellposed_mpm_particles, only: particles_t, new_particles
  use wellposed_mpm_config, only: scheme_musl
  use wellposed_mpm_grid, only: grid_t, new_grid
  use wellposed_mpm_particle_umat, only: strain_increment, umat_particle
  use wellposed_mpm_transfer, only: p2g, p2g_momentum, grid_update, velocity_from_momentum, &
                                    g2p, velocity_gradient
  use wellposed_mpm_shape_2d, only: shape_2d, support_size_2d, shape2d_reach, shape2d_names
  use wellposed_mpm_nonlocal, only: nonlocal_t, nonlocal_host_t, new_nonlocal, nonlocal_solve, &
                                    nonlocal_ghost_nodes, sweep_key
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpi, only: comm_t, allreduce_any, allreduce_min, allreduce_max, &
                           allreduce_sum, broadcast
  use wellposed_mpm_decomposition, only: decomposition_t, new_decomposition, patch_nodes, &
                                         owner_of_position, hand_off_particles_with, &
                                         layer_of_position, sum_ghost_grid
  use wellposed_mpm_plate_config, only: ps_config_t, check_plate_config, bc_roller, &
                                        bc_fixed2, bc_free2, bc_velocity, bc2_names
  implicit none
  private
  public :: ps_config_t, ps_scene_t, new_ps_scene, ps_advance, ps_applied_stress, &
            ps_plastic_strain, bc_roller, bc_fixed2, bc_free2, bc_velocity, bc2_names, &
            ps_kinetic_energy, ps_max_substeps, ps_plastic_count, ps_size_workspace

  !> The state of a running scene.
  type, extends(nonlocal_host_t) :: ps_scene_t
    type(ps_config_t) :: cfg
    type(particles_t) :: parts
    type(nonlocal_t) :: nl
    ! grid: node g = i + nx*j at origin + dx*(i, j)
    integer :: nx = 0, ny = 0, nnodes = 0
    real(dp) :: origin(2) = 0.0_dp
    type(grid_t) :: grid                      !< this rank's patch of nodes
    real(dp) :: t = 0.0_dp, dt = 0.0_dp
    integer :: nstep = 0
    real(dp) :: top_disp = 0.0_dp             !< vertical displacement of the top (m)
    real(dp) :: c_max = 0.0_dp, bulk = 0.0_dp, modulus = 0.0_dp
    type(mpm_materials_t) :: mats             !< the materials by region
    integer, allocatable :: mat(:)            !< material of each particle
    real(dp), allocatable :: q(:)             !< artificial viscous pressure (Pa)
    real(dp), allocatable :: s0(:, :), sv0(:, :), de(:, :)  !< start-of-step copies, increments
    integer :: max_substeps = 1
    integer :: nl_iterations_step = 0
    integer(int64) :: ticks_umat = 0, ticks_total = 0
    ! the ranks sharing the scene (one: the serial run)
    type(comm_t) :: comm
    type(decomposition_t) :: dec
    integer :: glo = 0, ghi = -1              !< this rank's nodes, ghost rows included
    integer :: ntotal = 0                     !< particles of the whole scene
    integer :: moved = 0                      !< particles this rank handed to others, so far
    real(dp) :: mass_floor = 0.0_dp           !< nodes lighter than this have no velocity (kg/m)
    type(mpm_ranks_t) :: nl_ranks             !< Algorithm 1's pipeline over the strips
    type(umat_host_t) :: host                 !< the UMAT host (NTENS = 4), one per scene
  contains
    procedure :: update => ps_update
  end type ps_scene_t

contains

  !> Build grid, particles, materials and the time step; errors name keys.
  !> With `comm` (collective; default one rank) this rank keeps its strip of
  !> cell rows, the nodes they touch with their ghost rows, and the
  !> particles in them (global ids as in the serial scene).
  subroutine new_ps_scene(self, cfg, err, comm)
    type(ps_scene_t), intent(out) :: self
    type(ps_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    type(comm_t), intent(in), optional :: comm
    integer :: ncx, ncy, np, p, a, b, k, nsup, g, i, j, nlocal, cap
    real(dp) :: lp, xy(2), ds(4), m_k

    call check_plate_config(cfg, err)
    if (allocated(err)) return
    self%cfg = cfg
    call new_umat_host(self%host, 4, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    self%host%celent = cfg%dx
    if (present(comm)) self%comm = comm
    ncx = nint(cfg%width/cfg%dx)
    ncy = nint(cfg%height/cfg%dx)
    self%nx = ncx + 2*cfg%pad_cells + 1
    self%ny = ncy + 2*cfg%pad_cells + 1
    self%nnodes = self%nx*self%ny
    self%origin = -cfg%pad_cells*cfg%dx
    ! ghost rows: the shape's reach, or the nonlocal Gaussian's support
    call new_nonlocal(self%nl, cfg%nonlocal, 2, self%origin, cfg%dx, &
                      [self%nx, self%ny], 0, -1, err)
    if (allocated(err)) return
    call new_decomposition(self%dec, self%comm, self%ny - 1, self%nx, &
                           max(shape2d_reach(cfg%shape), nonlocal_ghost_nodes(self%nl)), 2, &
                           self%origin(2), cfg%dx, err)
    if (allocated(err)) return
    call patch_nodes(self%dec, self%glo, self%ghi)
    call new_grid(self%grid, 2, self%origin(1), cfg%dx, self%nnodes, self%glo, self%ghi)
    do j = self%glo/self%nx, self%ghi/self%nx
      do i = 0, self%nx - 1
        g = i + self%nx*j
        xy = self%origin + cfg%dx*[i, j]
        if (xy(2) <= 0.5_dp*cfg%dx*1.0e-6_dp) then
          if (cfg%bottom == bc_roller) self%grid%fixed(2, g) = .true.
          if (cfg%bottom == bc_fixed2) self%grid%fixed(:, g) = .true.
        end if
        if (cfg%sides == bc_roller .and. (xy(1) <= 1.0e-6_dp*cfg%dx .or. &
                                           xy(1) >= cfg%width - 1.0e-6_dp*cfg%dx)) &
          self%grid%fixed(1, g) = .true.
        ! the platen covers the top face only: nodes at y >= height, 0 <= x <= width
        ! (its velocity (0, v_top) wins over the other conditions)
        if (cfg%top == bc_velocity .and. xy(2) >= cfg%height - 1.0e-6_dp*cfg%dx .and. &
            xy(1) >= -1.0e-6_dp*cfg%dx .and. xy(1) <= cfg%width + 1.0e-6_dp*cfg%dx) then
          self%grid%fixed(2, g) = .false.
          self%grid%given(2, g) = .true.
          if (cfg%top_lateral_fixed) then
            self%grid%fixed(1, g) = .false.
            self%grid%given(1, g) = .true.
          end if
        end if
      end do
    end do

    nsup = support_size_2d(cfg%shape)
    np = ncx*ncy*cfg%ppc**2
    self%ntotal = np
    lp = 0.5_dp*cfg%dx/cfg%ppc
    ! this rank's particles: those whose cell row it owns (all on one rank)
    nlocal = 0
    do b = 1, ncy*cfg%ppc
      if (owner_of_position(self%dec, (b - 0.5_dp)*2.0_dp*lp) == self%dec%rank) &
        nlocal = nlocal + ncx*cfg%ppc
    end do
    cap = np
    if (self%dec%nranks > 1) cap = min(np, nlocal + nlocal/4 + 64)
    call new_particles(self%parts, cap, 2, nsup, cfg%nstatv)
    allocate (self%mat(cap), self%q(cap), self%s0(4, cap), self%sv0(cfg%nstatv, cap), &
              self%de(4, cap))
    self%mats = single_material(cfg%materials, cfg%props(1:cfg%nprops), cfg%nstatv, 2, &
                                self%host%ours)
    p = 0
    g = 0
    do b = 1, ncy*cfg%ppc
      do a = 1, ncx*cfg%ppc
        g = g + 1
        xy = [(a - 0.5_dp)*2.0_dp*lp, (b - 0.5_dp)*2.0_dp*lp]
        if (owner_of_position(self%dec, xy(2)) /= self%dec%rank) cycle
        p = p + 1
        self%parts%gid(p) = g
        self%parts%x0(:, p) = xy
        self%mat(p) = material_of(self%mats, xy)
        if (self%mat(p) == 0) then
          call check_covered(self%mats, reshape(xy, [2, 1]), err); return
        end if
      end do
    end do
    self%parts%n = nlocal
    associate (n => nlocal)
      self%parts%x(:, 1:n) = self%parts%x0(:, 1:n)
      do p = 1, n
        self%parts%v(:, p) = matmul(cfg%velocity_gradient0, self%parts%x0(:, p))
      end do
      ! lp: the half-widths of the initial domain (GIMP, CPDI), never changed
      self%parts%lp(:, 1:n) = lp
      self%parts%vol0(1:n) = (2.0_dp*lp)**2
      self%parts%vol(1:n) = self%parts%vol0(1:n)
      self%parts%mass(1:n) = cfg%density*self%parts%vol0(1:n)
      self%parts%defgrad(:, :, 1:n) = 0.0_dp
      do k = 1, 3
        self%parts%defgrad(k, k, 1:n) = 1.0_dp
      end do
      self%parts%stress(:, 1:n) = 0.0_dp
      self%parts%stran(:, 1:n) = 0.0_dp
      self%parts%statev(:, 1:n) = 0.0_dp
      self%q(1:n) = 0.0_dp
    end associate
    ! every particle has this mass: the floor of the serial run's minval
    self%mass_floor = 1.0e-9_dp*(cfg%density*(2.0_dp*lp)**2)

    ! moduli through the UMAT: uniaxial strain (M) and isotropic (3K), the
    ! stiffest material's (the time step)
    do k = 1, self%mats%n
      ds = probe(k, [-1.0e-7_dp, 0.0_dp, 0.0_dp, 0.0_dp])
      if (allocated(err)) return
      m_k = -ds(1)/1.0e-7_dp
      ds = probe(k, [-1.0e-7_dp, -1.0e-7_dp, -1.0e-7_dp, 0.0_dp])
      if (allocated(err)) return
      if (.not. (m_k > 0.0_dp .and. -ds(1)/3.0e-7_dp > 0.0_dp)) then
        call new_error(err, status_invalid, 'material', 'the UMAT answers no positive '// &
          'stiffness at the initial state (M = '//real_text(m_k)//' Pa, K = '// &
          real_text(-ds(1)/3.0e-7_dp)//' Pa)'); return
      end if
      self%modulus = max(self%modulus, m_k)
      self%bulk = max(self%bulk, -ds(1)/3.0e-7_dp)
    end do
    self%c_max = sqrt(self%modulus/cfg%density)
    self%dt = cfg%cfl*cfg%dx/self%c_max

    call new_nonlocal(self%nl, cfg%nonlocal, 2, self%origin, cfg%dx, &
                      [self%nx, self%ny], self%glo, self%ghi, err)
    if (allocated(err)) return
    if (self%dec%nranks > 1) then
      call new_mpm_ranks(self%nl_ranks, self%comm)
      self%nl_ranks%dec = self%dec
      self%nl_ranks%glo = self%glo
    end if

  contains

    !> The stress of one UMAT call from the natural state (0 when the UMAT
    !> asks to cut back; a refusal or a non-finite answer is the error err).
    function probe(m, d) result(dsig)
      integer, intent(in) :: m
      real(dp), intent(in) :: d(4)
      real(dp) :: dsig(4), s(4), sv(cfg%nstatv), e(4)
      integer :: verdict
      s = 0.0_dp
      sv = 0.0_dp
      e = 0.0_dp
      self%host%time = 0.0_dp
      self%host%dtime = 1.0e-6_dp
      self%host%noel = 1
      self%host%coords = 0.0_dp
      call host_call(self%host, self%mats%props(1:self%mats%nprops(m), m), s, sv, e, d, verdict)
      dsig = s
      if (verdict /= verdict_ok) dsig = 0.0_dp
      if (verdict /= verdict_ok .and. verdict /= verdict_cutback) &
        call host_error(self%host, verdict, err, 'probing the moduli')
    end function probe

  end subroutine new_ps_scene

  !> One explicit step: weights, P2G, grid update with boundaries, G2P,
  !> MUSL velocity, L and F, artificial viscosity, Jaumann rotation, and
  !> the stress update of every particle through Algorithm 1.
  subroutine ps_advance(self, err, log_unit)
    type(ps_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: log_unit
    integer :: p, n
    real(dp) :: dt, vtop, mmin, lg(2, 2), dkk, rho, wspin, f2(2, 2), c, reaction(2)
    real(dp) :: s4(4)
    integer(int64), allocatable :: skey(:)
    integer(int64) :: t0, t1, t2

    call system_clock(t0)
    ! --- particles to the rank of their cell row (collective errors)
    if (self%dec%nranks > 1) then
      call hand_off(self, err)
      if (allocated(err)) return
    end if
    associate (pt => self%parts, cfg => self%cfg)
      n = pt%n
      dt = self%dt
      ! --- Algorithm 1's sweep order: the owning cell row at x^n (the
      ! positions the hand-off above decided from), then the id; the same
      ! keys on one rank as on N (a local model sweeps nothing)
      if (self%nl%active) then
        allocate (skey(n))
        do p = 1, n
          skey(p) = sweep_key(layer_of_position(self%dec, pt%x(self%dec%axis, p)), pt%gid(p))
        end do
      end if
      ! --- weights at x^n
      do p = 1, n
        f2 = pt%defgrad(1:2, 1:2, p)
        call shape_2d(cfg%shape, pt%x(:, p), pt%lp(:, p), f2, self%origin, cfg%dx, &
                      self%nx, pt%node(:, p), pt%phi(:, p), pt%grad(:, :, p))
        if (minval(pt%node(:, p)) < self%glo .or. maxval(pt%node(:, p)) > self%ghi) then
          if (minval(pt%node(:, p)) < 0 .or. maxval(pt%node(:, p)) >= self%nnodes) then
            call new_error(err, status_invalid, 'grid', 'step '//int_text(self%nstep + 1)// &
              ': particle '//int_text(pt%gid(p))//' at ('//real_text(pt%x(1, p))//', '// &
              real_text(pt%x(2, p))//') m left the grid; enlarge &grid pad_cells')
          else
            call new_error(err, status_invalid, 'grid', 'step '//int_text(self%nstep + 1)// &
              ': the domain of particle '//int_text(pt%gid(p))//' at ('// &
              real_text(pt%x(1, p))//', '//real_text(pt%x(2, p))//') m reaches more than '// &
              int_text(self%dec%ghost)//' node rows beyond its cell row (the ghost rows of '// &
              'rank '//int_text(self%dec%rank)//'): stretched beyond what '// &
              trim(shape_name(cfg%shape))//' supports on several ranks')
          end if
          exit
        end if
      end do
      call sync_error(self, err)
      if (allocated(err)) return
      ! --- P2G: mass, momentum, internal force (sigma - q I), summed over
      ! the ranks sharing a node
      call p2g(self%grid, pt, n, self%q)
      call sum_ghost_grid(self%dec, self%comm, self%grid, .false.)
      ! --- grid update and boundaries (the platen's (0, v_top)), on every
      ! node of the patch
      vtop = cfg%top_velocity
      if (cfg%ramp_time > 0.0_dp) vtop = vtop*min(1.0_dp, (self%t + dt)/cfg%ramp_time)
      mmin = self%mass_floor
      call grid_update(self%grid, dt, mmin, [0.0_dp, vtop], reaction)
      ! --- G2P: FLIP velocity, position
      call g2p(self%grid, pt, n, dt)
      ! --- MUSL: grid velocity from the updated particle momentum (USL
      ! keeps the updated grid velocity v_i^{n+1}, eq. 4.10-4.11)
      if (cfg%scheme == scheme_musl) then
        call p2g_momentum(self%grid, pt, n)
        call sum_ghost_grid(self%dec, self%comm, self%grid, .true.)
        call velocity_from_momentum(self%grid, mmin, [0.0_dp, vtop])
      end if
      ! --- velocity gradient (eq. 4.11), F, volume, viscosity, rotation
      c = sqrt(self%bulk/cfg%density)
      do p = 1, n
        call velocity_gradient(self%grid, pt, p, lg)
        ! lg(a, b) = d v_a / d x_b
        call strain_increment(lg, dt, self%de(:, p))
        f2 = pt%defgrad(1:2, 1:2, p)
        pt%defgrad(1:2, 1:2, p) = f2 + dt*matmul(lg, f2)
        pt%vol(p) = pt%vol0(p)*(pt%defgrad(1, 1, p)*pt%defgrad(2, 2, p) - &
                                pt%defgrad(1, 2, p)*pt%defgrad(2, 1, p))
        if (.not. pt%vol(p) > 0.0_dp) then
          call new_error(err, status_cutback, 'time', 'step '//int_text(self%nstep + 1)// &
            ': particle '//int_text(pt%gid(p))//' was turned inside out (det F <= 0); a '// &
            'smaller &time cfl may help')
          exit
        end if
        dkk = lg(1, 1) + lg(2, 2)
        rho = pt%mass(p)/pt%vol(p)
        if (dkk < 0.0_dp) then
          self%q(p) = rho*(cfg%visc_a1*c*abs(dkk)*cfg%dx + cfg%visc_a2*(dkk*cfg%dx)**2)
        else
          self%q(p) = 0.0_dp
        end if
        ! Jaumann rotation: sigma += dt (W sigma - sigma W), W12 = (L12 - L21)/2
        wspin = 0.5_dp*(lg(1, 2) - lg(2, 1))
        s4 = pt%stress(1:4, p)
        pt%stress(1, p) = s4(1) + 2.0_dp*dt*wspin*s4(4)
        pt%stress(2, p) = s4(2) - 2.0_dp*dt*wspin*s4(4)
        pt%stress(4, p) = s4(4) + dt*wspin*(s4(2) - s4(1))
      end do
      ! Algorithm 1 across ranks is collective: stop every rank before it
      if (self%nl%active) call sync_error(self, err)
      if (allocated(err)) return
      ! --- stress update: Algorithm 1 (one local pass when h_zeta = 0)
      do p = 1, n
        self%s0(:, p) = pt%stress(1:4, p)
        self%sv0(:, p) = pt%statev(:, p)
      end do
      call system_clock(t1)
      if (.not. self%nl%active) then
        ! one pass per particle on its own: nothing to exchange
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, log_unit)
      else if (self%dec%nranks == 1) then
        ! one process, in the order of every rank count
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, log_unit, key=skey)
      else if (self%dec%rank == 0) then
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, log_unit, self%nl_ranks, skey)
      else
        call nonlocal_solve(self%nl, self, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, ranks=self%nl_ranks, key=skey)
      end if
      call system_clock(t2)
      self%ticks_umat = self%ticks_umat + (t2 - t1)
      if (allocated(err)) err%message = 'step '//int_text(self%nstep + 1)//', t = '// &
                                        real_text(self%t + dt)//' s: '//err%message
      call sync_error(self, err)
      if (allocated(err)) return
      do p = 1, n
        pt%stran(1:4, p) = pt%stran(1:4, p) + self%de(:, p)
      end do
    end associate
    self%t = self%t + self%dt
    self%nstep = self%nstep + 1
    if (self%cfg%top == bc_velocity) self%top_disp = self%top_disp + vtop*self%dt
    call system_clock(t2)
    self%ticks_total = self%ticks_total + (t2 - t0)

  end subroutine ps_advance

  !> The name of shape family `kind`.
  pure function shape_name(kind) result(name)
    integer, intent(in) :: kind
    character(len=6) :: name
    name = shape2d_names(kind)
  end function shape_name

  !> Particles whose cell row another rank owns go there, with their
  !> viscous pressure and material (collective); the workspace follows the
  !> particles' capacity.
  subroutine hand_off(self, err)
    type(ps_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: extra(:, :)
    integer :: n, moved
    n = self%parts%n
    allocate (extra(2, size(self%parts%gid)))
    extra(1, 1:n) = self%q(1:n)
    extra(2, 1:n) = real(self%mat(1:n), dp)
    call hand_off_particles_with(self%dec, self%comm, self%parts, extra, err, moved)
    if (allocated(err)) return
    self%moved = self%moved + moved
    n = self%parts%n
    call ps_size_workspace(self)
    self%q(1:n) = extra(1, 1:n)
    self%mat(1:n) = nint(extra(2, 1:n))
  end subroutine hand_off

  !> Per-particle workspace (viscous pressure, material, start-of-step
  !> copies, increments) for as many particles as the set can hold (a
  !> rank's count changes as particles cross; a restart refills it).
  subroutine ps_size_workspace(self)
    type(ps_scene_t), intent(inout) :: self
    integer :: cap
    cap = size(self%parts%gid)
    if (size(self%q) < cap) then
      deallocate (self%q, self%mat, self%s0, self%sv0, self%de)
      allocate (self%q(cap), self%mat(cap), self%s0(4, cap), self%sv0(self%cfg%nstatv, cap), &
                self%de(4, cap))
    end if
  end subroutine ps_size_workspace

  !> Make an error on any rank an error on every rank (collective; nothing
  !> on one rank): the status and message of the lowest rank where it arose
  !> (Algorithm 1 tells the other ranks with key 'ranks' that it stopped).
  subroutine sync_error(self, err)
    type(ps_scene_t), intent(in) :: self
    type(error_t), allocatable, intent(inout) :: err
    integer :: first, head(2), k
    integer, allocatable :: codes(:)
    if (self%dec%nranks == 1) return
    if (.not. allreduce_any(self%comm, allocated(err))) return
    first = self%comm%size
    if (allocated(err)) then
      if (err%key /= 'ranks') first = self%comm%rank
    end if
    call allreduce_min(self%comm, first)
    if (first == self%comm%size) then
      if (allocated(err)) first = self%comm%rank
      call allreduce_min(self%comm, first)
    end if
    head = 0
    if (self%comm%rank == first) head = [err%status, len(err%message)]
    call broadcast(self%comm, head, first)
    allocate (codes(head(2)))
    if (self%comm%rank == first) codes = [(iachar(err%message(k:k)), k=1, head(2))]
    call broadcast(self%comm, codes, first)
    if (self%comm%rank /= first) then
      if (allocated(err)) deallocate (err)
      allocate (err)
      err%status = head(1)
      err%key = ''
      allocate (character(len=head(2)) :: err%message)
      do k = 1, head(2)
        err%message(k:k) = achar(codes(k))
      end do
    end if
  end subroutine sync_error

  !> The host side of Algorithm 1: particle p from its start-of-step copies
  !> with STATEV(3) = avg, through the UMAT host (NTENS = 4, STRAN = 0: the
  !> model is incremental); dlambda = STATEV(2). The host's rules apply:
  !> PNEWDT < 0 or a non-finite result stops the run naming the particle, a
  !> cut-back splits the increment (2, 4, ... 64 parts, each with its share
  !> of the average).
  subroutine ps_update(self, p, avg, dlambda, err)
    class(ps_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: avg
    real(dp), intent(out) :: dlambda
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: s(4), sv(self%cfg%nstatv), e(4)
    integer :: nsub
    associate (pt => self%parts, h => self%host)
      s = self%s0(:, p)
      sv = self%sv0(:, p)
      e = 0.0_dp
      h%ours = self%mats%contract(self%mat(p))
      associate (m => self%mat(p))
        call umat_particle(h, self%mats%props(1:self%mats%nprops(m), m), self%t, self%dt, &
                           self%nstep + 1, pt%gid(p), pt%x(:, p), s, sv, e, self%de(:, p), avg, &
                           dlambda, nsub, err)
      end associate
      if (allocated(err)) return
      pt%stress(1:4, p) = s
      pt%statev(:, p) = sv
      self%max_substeps = max(self%max_substeps, nsub)
    end associate
  end subroutine ps_update

  !> Applied axial stress (Pa, compression positive): the top force per
  !> unit initial width, from the volume average of sigma_yy (in
  !> equilibrium without body force, int sigma_yy dV = F_top * H, H the
  !> current height): -sum_p sigma_yy V_p / (width * (height + top_disp)).
  !> Robust to the boundary layer under a laterally fixed top and to the mesh.
  !> Collective: the sum runs over every rank's particles.
  real(dp) function ps_applied_stress(self) result(s)
    type(ps_scene_t), intent(in) :: self
    integer :: n
    n = self%parts%n
    s = sum(self%parts%stress(2, 1:n)*self%parts%vol(1:n))
    if (self%dec%nranks > 1) call allreduce_sum(self%comm, s)
    s = -s/(self%cfg%width*(self%cfg%height + self%top_disp))
  end function ps_applied_stress

  !> This rank's share of the plastic particles of the last step: their sum
  !> over the ranks is the scene's count (Algorithm 1 across ranks counts
  !> them all, and rank 0 reports them). A host adds the shares when it
  !> needs the count, e.g. once for a whole history.
  pure integer function ps_plastic_count(self) result(count_mine)
    type(ps_scene_t), intent(in) :: self
    count_mine = self%nl%last%n_plastic
    if (self%dec%nranks > 1 .and. self%nl%active .and. self%dec%rank /= 0) count_mine = 0
  end function ps_plastic_count

  !> The largest UMAT cut-back split used so far on any rank (collective).
  integer function ps_max_substeps(self) result(nsub)
    type(ps_scene_t), intent(in) :: self
    nsub = self%max_substeps
    if (self%dec%nranks > 1) call allreduce_max(self%comm, nsub)
  end function ps_max_substeps

  !> Magnitude of the plastic strain tensor ||eps^p|| of each particle
  !> (STATEV 5-10, engineering shears halved), as in fig. 4.2 and 4.4.
  pure function ps_plastic_strain(self) result(ep)
    type(ps_scene_t), intent(in) :: self
    real(dp) :: ep(self%parts%n)
    integer :: p
    do p = 1, self%parts%n
      associate (e => self%parts%statev(5:10, p))
        ep(p) = sqrt(e(1)**2 + e(2)**2 + e(3)**2 + 0.5_dp*(e(4)**2 + e(5)**2 + e(6)**2))
      end associate
    end do
  end function ps_plastic_strain

  !> Kinetic energy of the particles (J per m of thickness), over every
  !> rank (collective).
  real(dp) function ps_kinetic_energy(self) result(e)
    type(ps_scene_t), intent(in) :: self
    integer :: n
    n = self%parts%n
    e = 0.5_dp*sum(self%parts%mass(1:n)*(self%parts%v(1, 1:n)**2 + self%parts%v(2, 1:n)**2))
    if (self%dec%nranks > 1) call allreduce_sum(self%comm, e)
  end function ps_kinetic_energy


end module wellposed_mpm_plane_strain
