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
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_update, &
                                host_error, verdict_ok, verdict_cutback
  use wellposed_umat_layout, only: prop_k0
  use wellposed_mpm_particles, only: particles_t, new_particles, particle_record_length, &
                                     pack_particle, unpack_particle, ensure_capacity
  use wellposed_mpm_config, only: scheme_musl
  use wellposed_mpm_shape_2d, only: shape_2d, support_size_2d, shape2d_cpdi, shape2d_gimp, &
                                    shape2d_linear, shape2d_reach, shape2d_names
  use wellposed_mpm_nonlocal, only: nonlocal_settings_t, nonlocal_t, nonlocal_host_t, &
                                    new_nonlocal, nonlocal_solve, nonlocal_ghost_nodes, &
                                    sweep_key
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpi, only: comm_t, allreduce_any, allreduce_min, allreduce_max, &
                           allreduce_sum, broadcast, gatherv_real
  use wellposed_mpm_decomposition, only: decomposition_t, new_decomposition, patch_nodes, &
                                         owner_of_position, hand_off_particles_with, &
                                         layer_of_position, &
                                         sum_ghost_values
  use wellposed_checkpoint, only: checkpoint_t
  implicit none
  private
  public :: ps_config_t, ps_scene_t, new_ps_scene, ps_advance, ps_applied_stress, &
            ps_plastic_strain, bc_roller, bc_fixed2, bc_free2, bc_velocity, bc2_names, &
            ps_kinetic_energy, ps_save, ps_restore, ps_max_substeps, ps_plastic_count

  !> Boundary kinds in 2D.
  integer, parameter :: bc_roller = 1, bc_fixed2 = 2, bc_free2 = 3, bc_velocity = 4
  character(len=8), parameter :: bc2_names(4) = [character(len=8) :: 'roller', 'fixed', 'free', &
                                                 'velocity']
  integer, parameter :: max_props2 = 40
  !> Version of the checkpoint entries of ps_save; ps_restore refuses others.
  integer, parameter :: ps_layout_version = 1

  !> One plane-strain scene (defaults: the 4 m x 5 m plate of fig. 4.1 with
  !> the local softening material of section 4.7.1, h = 0.5 m).
  type :: ps_config_t
    character(len=:), allocatable :: name, title
    real(dp) :: width = 4.0_dp, height = 5.0_dp   !< m
    real(dp) :: dx = 0.5_dp                        !< cell size h (m)
    integer :: ppc = 2                             !< particles per cell per direction
    integer :: pad_cells = 2
    integer :: shape = shape2d_cpdi
    real(dp) :: t_end = 0.02_dp, cfl = 0.2_dp      !< s, fraction of the CFL step
    integer :: scheme = scheme_musl                !< USL or MUSL (wellposed_mpm_config)
    real(dp) :: density = 1000.0_dp                !< kg/m^3
    integer :: nprops = 14
    real(dp) :: props(max_props2) = 0.0_dp
    integer :: nstatv = 12
    ! weak zone: particles whose initial centre lies in it get k0 = weak_k0
    real(dp) :: weak_x(2) = [0.0_dp, 1.0_dp], weak_y(2) = [0.0_dp, 1.0_dp]
    real(dp) :: weak_k0 = 0.0_dp                   !< Pa; 0: no weak zone
    ! boundaries
    integer :: bottom = bc_roller, top = bc_velocity, sides = bc_free2
    real(dp) :: top_velocity = -7.5_dp             !< v_y of the top (m/s, < 0 compresses)
    real(dp) :: ramp_time = 0.0_dp                 !< s, linear ramp of the top velocity
    logical :: top_lateral_fixed = .true.          !< v_x = 0 on the top too (the dissertation's)
    ! initial state
    real(dp) :: velocity_gradient0(2, 2) = 0.0_dp  !< initial v = L0 x (patch test), 1/s
    ! artificial viscosity
    real(dp) :: visc_a1 = 0.4_dp, visc_a2 = 4.0_dp
    type(nonlocal_settings_t) :: nonlocal
  end type ps_config_t

  !> The state of a running scene.
  type, extends(nonlocal_host_t) :: ps_scene_t
    type(ps_config_t) :: cfg
    type(particles_t) :: parts
    type(nonlocal_t) :: nl
    ! grid: node g = i + nx*j at origin + dx*(i, j)
    integer :: nx = 0, ny = 0, nnodes = 0
    real(dp) :: origin(2) = 0.0_dp
    real(dp), allocatable :: gmass(:), gmom(:, :), gforce(:, :), gvel(:, :), gacc(:, :)
    integer, allocatable :: gfix(:, :)        !< 0 free, 1 zero, 2 prescribed top (2, node)
    real(dp) :: t = 0.0_dp, dt = 0.0_dp
    integer :: nstep = 0
    real(dp) :: top_disp = 0.0_dp             !< vertical displacement of the top (m)
    real(dp) :: c_max = 0.0_dp, bulk = 0.0_dp, modulus = 0.0_dp
    real(dp), allocatable :: props_p(:, :)    !< PROPS per material (nprops, 2): 1 body, 2 weak
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
    real(dp) :: lp, xy(2), ds(4)

    call check(cfg, err)
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
    call new_nonlocal(self%nl, cfg%nonlocal, cfg%props(1:cfg%nprops), 2, self%origin, cfg%dx, &
                      [self%nx, self%ny], 0, -1, err)
    if (allocated(err)) return
    call new_decomposition(self%dec, self%comm, self%ny - 1, self%nx, &
                           max(shape2d_reach(cfg%shape), nonlocal_ghost_nodes(self%nl)), 2, &
                           self%origin(2), cfg%dx, err)
    if (allocated(err)) return
    call patch_nodes(self%dec, self%glo, self%ghi)
    allocate (self%gmass(self%glo:self%ghi), self%gmom(2, self%glo:self%ghi), &
              self%gforce(2, self%glo:self%ghi), self%gvel(2, self%glo:self%ghi), &
              self%gacc(2, self%glo:self%ghi), self%gfix(2, self%glo:self%ghi))
    self%gvel = 0.0_dp
    self%gacc = 0.0_dp
    self%gfix = 0
    do j = self%glo/self%nx, self%ghi/self%nx
      do i = 0, self%nx - 1
        g = i + self%nx*j
        xy = self%origin + cfg%dx*[i, j]
        if (xy(2) <= 0.5_dp*cfg%dx*1.0e-6_dp) then
          if (cfg%bottom == bc_roller) self%gfix(2, g) = 1
          if (cfg%bottom == bc_fixed2) self%gfix(:, g) = 1
        end if
        if (cfg%sides == bc_roller .and. (xy(1) <= 1.0e-6_dp*cfg%dx .or. &
                                           xy(1) >= cfg%width - 1.0e-6_dp*cfg%dx)) &
          self%gfix(1, g) = 1
        ! the platen covers the top face only: nodes at y >= height, 0 <= x <= width
        if (cfg%top == bc_velocity .and. xy(2) >= cfg%height - 1.0e-6_dp*cfg%dx .and. &
            xy(1) >= -1.0e-6_dp*cfg%dx .and. xy(1) <= cfg%width + 1.0e-6_dp*cfg%dx) then
          self%gfix(2, g) = 2
          if (cfg%top_lateral_fixed) self%gfix(1, g) = 2
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
    allocate (self%props_p(cfg%nprops, 2))
    self%props_p(:, 1) = cfg%props(1:cfg%nprops)
    self%props_p(:, 2) = cfg%props(1:cfg%nprops)
    if (cfg%weak_k0 > 0.0_dp) self%props_p(prop_k0, 2) = cfg%weak_k0
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
        self%mat(p) = 1
        if (cfg%weak_k0 > 0.0_dp) then
          if (xy(1) >= cfg%weak_x(1) .and. xy(1) <= cfg%weak_x(2) .and. &
              xy(2) >= cfg%weak_y(1) .and. xy(2) <= cfg%weak_y(2)) self%mat(p) = 2
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

    ! moduli through the UMAT: uniaxial strain (M) and isotropic (3K)
    ds = probe([-1.0e-7_dp, 0.0_dp, 0.0_dp, 0.0_dp])
    if (allocated(err)) return
    self%modulus = -ds(1)/1.0e-7_dp
    ds = probe([-1.0e-7_dp, -1.0e-7_dp, -1.0e-7_dp, 0.0_dp])
    if (allocated(err)) return
    self%bulk = -ds(1)/3.0e-7_dp
    if (.not. (self%modulus > 0.0_dp .and. self%bulk > 0.0_dp)) then
      call new_error(err, status_invalid, 'material', 'the UMAT answers no positive '// &
        'stiffness at the initial state (M = '//real_text(self%modulus)//' Pa, K = '// &
        real_text(self%bulk)//' Pa)'); return
    end if
    self%c_max = sqrt(self%modulus/cfg%density)
    self%dt = cfg%cfl*cfg%dx/self%c_max

    call new_nonlocal(self%nl, cfg%nonlocal, cfg%props(1:cfg%nprops), 2, self%origin, cfg%dx, &
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
    function probe(d) result(dsig)
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
      call host_call(self%host, self%props_p(:, 1), s, sv, e, d, verdict)
      dsig = s
      if (verdict /= verdict_ok) dsig = 0.0_dp
      if (verdict /= verdict_ok .and. verdict /= verdict_cutback) &
        call host_error(self%host, verdict, err, 'probing the moduli')
    end function probe

  end subroutine new_ps_scene

  !> Checks on the deck values a scene needs.
  subroutine check(cfg, err)
    type(ps_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: r(2)
    if (.not. (cfg%dx > 0.0_dp .and. ieee_is_finite(cfg%dx))) then
      call bad('grid', 'dx', 'must be a finite cell size > 0 m'); return
    end if
    r = [cfg%width, cfg%height]/cfg%dx
    if (any(abs(r - nint(r)) > 1.0e-9_dp*r) .or. any(nint(r) < 2)) then
      call bad('plate', 'width', 'and height must be whole numbers (>= 2) of cells dx')
      return
    end if
    if (product(real(nint(r), dp))*cfg%ppc**2 > 2.0e7_dp) then
      call bad('grid', 'dx', 'gives more than 2e7 particles'); return
    end if
    if (cfg%ppc < 1 .or. cfg%ppc > 4) then
      call bad('grid', 'ppc', 'particles per cell per direction must be 1 ... 4'); return
    end if
    if (cfg%pad_cells < 2) then
      call bad('grid', 'pad_cells', 'must be >= 2 (GIMP/CPDI supports reach past the body)')
      return
    end if
    if (.not. (cfg%cfl > 0.0_dp .and. cfg%cfl <= 1.0_dp)) then
      call bad('time', 'cfl', 'the CFL fraction must lie in (0, 1]'); return
    end if
    if (.not. (cfg%t_end > 0.0_dp .and. ieee_is_finite(cfg%t_end))) then
      call bad('time', 't_end', 'must be a finite end time > 0 s'); return
    end if
    if (.not. (cfg%density > 0.0_dp)) then
      call bad('material', 'density', 'must be > 0 kg/m^3'); return
    end if
    if (cfg%nstatv < 12) then
      call bad('material', 'nstatv', 'must be >= 12 (the UMAT contract)'); return
    end if
    if (cfg%nprops < prop_k0 .and. cfg%weak_k0 > 0.0_dp) then
      call bad('weak', 'k0', 'needs PROPS(5) (k0) in the material'); return
    end if
    if (cfg%visc_a1 < 0.0_dp .or. cfg%visc_a2 < 0.0_dp) then
      call bad('viscosity', 'a1', 'A1 and A2 must be >= 0 (0 switches a term off)'); return
    end if
    if (cfg%ramp_time < 0.0_dp) then
      call bad('boundary', 'ramp_time', 'must be >= 0 s'); return
    end if
  contains
    subroutine bad(group, key, what)
      character(len=*), intent(in) :: group, key, what
      call new_error(err, status_invalid, group//'%'//key, '&'//group//' '//key//' '//what)
    end subroutine bad
  end subroutine check

  !> One explicit step: weights, P2G, grid update with boundaries, G2P,
  !> MUSL velocity, L and F, artificial viscosity, Jaumann rotation, and
  !> the stress update of every particle through Algorithm 1.
  subroutine ps_advance(self, err, log_unit)
    type(ps_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: log_unit
    integer :: p, k, i, n, ns
    real(dp) :: dt, w, vtop, mmin, lg(2, 2), dkk, rho, sig(2, 2), wspin, f2(2, 2), c
    real(dp) :: s4(4)
    real(dp), allocatable :: sums(:, :)
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
      ns = pt%nsup
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
      ! --- P2G: mass, momentum, internal force (sigma - q I)
      self%gmass = 0.0_dp
      self%gmom = 0.0_dp
      self%gforce = 0.0_dp
      do p = 1, n
        sig = reshape([pt%stress(1, p) - self%q(p), pt%stress(4, p), pt%stress(4, p), &
                       pt%stress(2, p) - self%q(p)], [2, 2])
        do k = 1, ns
          i = pt%node(k, p)
          w = pt%phi(k, p)*pt%mass(p)
          self%gmass(i) = self%gmass(i) + w
          self%gmom(:, i) = self%gmom(:, i) + w*pt%v(:, p)
          self%gforce(:, i) = self%gforce(:, i) - pt%vol(p)*matmul(sig, pt%grad(:, k, p))
        end do
      end do
      ! nodes shared with other ranks: the sums over every rank
      if (self%dec%nnb > 0) then
        allocate (sums(5, self%glo:self%ghi))
        sums(1, :) = self%gmass
        sums(2:3, :) = self%gmom
        sums(4:5, :) = self%gforce
        call sum_ghost_values(self%dec, self%comm, sums)
        self%gmass = sums(1, :)
        self%gmom = sums(2:3, :)
        self%gforce = sums(4:5, :)
      end if
      ! --- grid update and boundaries, on every node of the patch
      vtop = cfg%top_velocity
      if (cfg%ramp_time > 0.0_dp) vtop = vtop*min(1.0_dp, (self%t + dt)/cfg%ramp_time)
      mmin = self%mass_floor
      do i = self%glo, self%ghi
        if (self%gmass(i) > mmin) then
          self%gacc(:, i) = self%gforce(:, i)/self%gmass(i)
          self%gvel(:, i) = self%gmom(:, i)/self%gmass(i) + self%gacc(:, i)*dt
        else
          self%gacc(:, i) = 0.0_dp
          self%gvel(:, i) = 0.0_dp
        end if
        call apply_bc(i)
      end do
      ! --- G2P: FLIP velocity, position
      do p = 1, n
        do k = 1, ns
          i = pt%node(k, p)
          pt%v(:, p) = pt%v(:, p) + dt*pt%phi(k, p)*self%gacc(:, i)
          pt%x(:, p) = pt%x(:, p) + dt*pt%phi(k, p)*self%gvel(:, i)
        end do
      end do
      ! --- MUSL: grid velocity from the updated particle momentum (USL
      ! keeps the updated grid velocity v_i^{n+1}, eq. 4.10-4.11)
      if (cfg%scheme == scheme_musl) then
        self%gmom = 0.0_dp
        do p = 1, n
          do k = 1, ns
            i = pt%node(k, p)
            self%gmom(:, i) = self%gmom(:, i) + pt%phi(k, p)*pt%mass(p)*pt%v(:, p)
          end do
        end do
        if (self%dec%nnb > 0) call sum_ghost_values(self%dec, self%comm, self%gmom)
        do i = self%glo, self%ghi
          if (self%gmass(i) > mmin) then
            self%gvel(:, i) = self%gmom(:, i)/self%gmass(i)
          else
            self%gvel(:, i) = 0.0_dp
          end if
          self%gacc(:, i) = 0.0_dp
          call apply_bc(i)
        end do
      end if
      ! --- velocity gradient (eq. 4.11), F, volume, viscosity, rotation
      c = sqrt(self%bulk/cfg%density)
      do p = 1, n
        lg = 0.0_dp
        do k = 1, ns
          i = pt%node(k, p)
          lg(:, 1) = lg(:, 1) + self%gvel(:, i)*pt%grad(1, k, p)
          lg(:, 2) = lg(:, 2) + self%gvel(:, i)*pt%grad(2, k, p)
        end do
        ! lg(a, b) = d v_a / d x_b
        self%de(:, p) = dt*[lg(1, 1), lg(2, 2), 0.0_dp, lg(1, 2) + lg(2, 1)]
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

  contains

    subroutine apply_bc(node)
      integer, intent(in) :: node
      integer :: d
      do d = 1, 2
        select case (self%gfix(d, node))
        case (1)
          self%gvel(d, node) = 0.0_dp
          self%gacc(d, node) = 0.0_dp
        case (2)
          self%gvel(d, node) = merge(vtop, 0.0_dp, d == 2)
          self%gacc(d, node) = 0.0_dp
        end select
      end do
    end subroutine apply_bc

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
    integer :: n, cap, moved
    n = self%parts%n
    allocate (extra(2, size(self%parts%gid)))
    extra(1, 1:n) = self%q(1:n)
    extra(2, 1:n) = real(self%mat(1:n), dp)
    call hand_off_particles_with(self%dec, self%comm, self%parts, extra, err, moved)
    if (allocated(err)) return
    self%moved = self%moved + moved
    n = self%parts%n
    cap = size(self%parts%gid)
    if (size(self%q) < cap) then
      deallocate (self%q, self%mat, self%s0, self%sv0, self%de)
      allocate (self%q(cap), self%mat(cap), self%s0(4, cap), self%sv0(self%cfg%nstatv, cap), &
                self%de(4, cap))
    end if
    self%q(1:n) = extra(1, 1:n)
    self%mat(1:n) = nint(extra(2, 1:n))
  end subroutine hand_off

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
      ! the nonlocal slots (STATEV 2 in, 3 out) only for a UMAT that has them
      if (h%ours) sv(3) = avg
      e = 0.0_dp
      h%time = self%t
      h%dtime = self%dt
      h%kinc = self%nstep + 1
      h%noel = pt%gid(p)
      h%coords = [pt%x(1, p), pt%x(2, p), 0.0_dp]
      call host_update(h, self%props_p(:, self%mat(p)), s, sv, e, self%de(:, p), nsub, err)
      if (allocated(err)) return
      pt%stress(1:4, p) = s
      pt%statev(:, p) = sv
      dlambda = 0.0_dp
      if (h%ours) dlambda = sv(2)
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

  !> Put the state of a running scene into `ckpt` (collective; `ckpt` is
  !> filled on rank 0 only): time, step, time step, top displacement, the
  !> run totals of Algorithm 1, and every particle (all fields but the
  !> connectivity, rebuilt each step, with its viscous pressure and
  !> material) in every rank's order, with the count each rank held. The
  !> grid is rebuilt every step, so this is all the next step reads.
  subroutine ps_save(self, ckpt)
    type(ps_scene_t), intent(in) :: self
    type(checkpoint_t), intent(inout) :: ckpt
    real(dp), allocatable :: rec(:), recs(:)
    integer, allocatable :: counts(:)
    integer :: plen, reclen, p, nsub, moved
    plen = particle_record_length(self%parts)
    reclen = plen + 2
    allocate (rec(reclen*self%parts%n))
    do p = 1, self%parts%n
      call pack_particle(self%parts, p, rec((p - 1)*reclen + 1:(p - 1)*reclen + plen))
      rec((p - 1)*reclen + plen + 1) = self%q(p)
      rec(p*reclen) = real(self%mat(p), dp)
    end do
    call gatherv_real(self%comm, rec, recs, 0, counts)
    nsub = ps_max_substeps(self)
    moved = self%moved
    if (self%dec%nranks > 1) call allreduce_sum(self%comm, moved)
    if (self%comm%rank /= 0) return
    call ckpt%put('ps/layout', [ps_layout_version, self%parts%ndim, self%parts%nsup, &
                                self%parts%nstatv, self%ntotal, self%comm%size, reclen])
    call ckpt%put('ps/counts', counts/reclen)
    call ckpt%put('ps/particles', recs)
    call ckpt%put('ps/scalars', [self%t, self%dt, self%top_disp, self%cfg%dx])
    call ckpt%put('ps/steps', [self%nstep, nsub, moved])
    call ckpt%put('ps/nonlocal', [self%nl%steps_iterated, self%nl%iterations_total, &
                                  self%nl%iterations_max, merge(1, 0, self%nl%warned_sharp), &
                                  merge(1, 0, self%nl%warned_printed)])
  end subroutine ps_save

  !> Continue `self`, freshly built by new_ps_scene from the deck of the run
  !> that wrote `ckpt` (every rank holds the whole checkpoint). Saved on as
  !> many ranks as now: every rank takes back its particles in their order,
  !> and the run continues bit for bit. Saved on another number: every rank
  !> takes the particles of its cell rows in global-id order (the
  !> continuation then differs by the order of nodal additions only). A
  !> checkpoint of another layout, cell size or time step is refused.
  subroutine ps_restore(self, ckpt, err)
    type(ps_scene_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ckpt
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: layout(:), counts(:), steps(:), nl(:), order(:)
    real(dp), allocatable :: recs(:), sc(:)
    integer :: plen, reclen, nsaved, first, p, m, g, cap, k
    call ckpt%get('ps/layout', layout, err)
    if (allocated(err)) return
    plen = particle_record_length(self%parts)
    if (size(layout) /= 7) then
      call bad('its plane-strain layout entry is garbled'); return
    end if
    if (layout(1) /= ps_layout_version) then
      call bad('plane-strain checkpoint layout '//int_text(layout(1))//', this program '// &
               'reads '//int_text(ps_layout_version)); return
    end if
    if (layout(2) /= self%parts%ndim .or. layout(3) /= self%parts%nsup .or. &
        layout(4) /= self%parts%nstatv .or. layout(5) /= self%ntotal .or. &
        layout(7) /= plen + 2) then
      call bad('it holds '//int_text(layout(5))//' particles with nsup, nstatv = '// &
               int_text(layout(3))//', '//int_text(layout(4))//'; this deck gives '// &
               int_text(self%ntotal)//', '//int_text(self%parts%nsup)//', '// &
               int_text(self%parts%nstatv)//' (another deck?)'); return
    end if
    reclen = layout(7)
    nsaved = layout(6)
    call ckpt%get('ps/scalars', sc, err); if (allocated(err)) return
    if (size(sc) /= 4) then
      call bad('its scalars entry is garbled'); return
    end if
    if (sc(4) /= self%cfg%dx .or. sc(2) /= self%dt) then
      call bad('it was written with dx = '//real_text(sc(4))//' m and dt = '// &
               real_text(sc(2))//' s; this deck gives '//real_text(self%cfg%dx)//' m and '// &
               real_text(self%dt)//' s: restart with the deck (and overrides) of the '// &
               'interrupted run'); return
    end if
    call ckpt%get('ps/counts', counts, err); if (allocated(err)) return
    call ckpt%get('ps/particles', recs, err); if (allocated(err)) return
    call ckpt%get('ps/steps', steps, err); if (allocated(err)) return
    call ckpt%get('ps/nonlocal', nl, err); if (allocated(err)) return
    if (size(counts) /= nsaved .or. sum(counts) /= self%ntotal .or. &
        size(recs) /= reclen*self%ntotal .or. size(steps) /= 3 .or. size(nl) /= 5) then
      call bad('its particle entries do not match its layout'); return
    end if
    ! which saved records this rank takes, in which order
    if (nsaved == self%comm%size) then
      first = sum(counts(1:self%comm%rank))
      order = [(first + p, p=1, counts(self%comm%rank + 1))]
    else
      allocate (order(self%ntotal))
      order = 0
      do p = 1, self%ntotal
        g = nint(recs((p - 1)*reclen + 1))
        if (g < 1 .or. g > self%ntotal) then
          call bad('its particle ids are not 1 .. '//int_text(self%ntotal)); return
        end if
        order(g) = p
      end do
      m = 0
      do k = 1, self%ntotal
        p = order(k)
        if (p == 0) then
          call bad('its particle ids are not 1 .. '//int_text(self%ntotal)); return
        end if
        if (owner_of_position(self%dec, recs((p - 1)*reclen + 1 + self%parts%ndim + self%dec%axis)) &
            /= self%dec%rank) cycle
        m = m + 1
        order(m) = p
      end do
      order = order(1:m)
    end if
    m = size(order)
    self%parts%n = 0
    call ensure_capacity(self%parts, m)
    cap = size(self%parts%gid)
    if (size(self%q) < cap) then
      deallocate (self%q, self%mat, self%s0, self%sv0, self%de)
      allocate (self%q(cap), self%mat(cap), self%s0(4, cap), self%sv0(self%cfg%nstatv, cap), &
                self%de(4, cap))
    end if
    do k = 1, m
      p = order(k)
      call unpack_particle(self%parts, k, recs((p - 1)*reclen + 1:(p - 1)*reclen + plen))
      self%q(k) = recs((p - 1)*reclen + plen + 1)
      self%mat(k) = nint(recs(p*reclen))
    end do
    self%parts%n = m
    self%t = sc(1)
    self%top_disp = sc(3)
    self%nstep = steps(1)
    self%max_substeps = steps(2)
    self%moved = 0
    if (self%comm%rank == 0) self%moved = steps(3)
    self%nl%steps_iterated = nl(1)
    self%nl%iterations_total = nl(2)
    self%nl%iterations_max = nl(3)
    self%nl%warned_sharp = nl(4) == 1
    self%nl%warned_printed = nl(5) == 1
  contains
    subroutine bad(why)
      character(len=*), intent(in) :: why
      call new_error(err, status_invalid, 'checkpoint', 'the checkpoint cannot continue this '// &
                     'scene: '//why)
    end subroutine bad
  end subroutine ps_restore

end module wellposed_mpm_plane_strain
