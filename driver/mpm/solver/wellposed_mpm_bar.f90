!> The bar scene kind of the MPM (the 1D uniaxial-strain scenes of the
!> dissertation's chapter 2, Sandler-Rubin case study): the body [0, length]
!> with ppc particles per cell, the far end fixed, symmetric or free, the
!> time step from the UMAT's axial moduli, and the dimension's load kernel:
!> the surface traction on the moving free surface with its bookkeeping
!> (impulse, external work). The step itself is wellposed_mpm_solver's.
module wellposed_mpm_bar
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_config
  use wellposed_mpm_cfl_limit, only: cfl_limit
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_shape, only: support_size
  use wellposed_mpm_loads, only: surface_stress
  use wellposed_umat_host, only: umat_host_t, new_umat_host
  use wellposed_mpm_vumat_call, only: material_update
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_materials, only: single_material
  use wellposed_mpm_scene, only: mpm_scene_t, start_scene, setup_ranks, scene_particles, &
                                 assign_materials, init_particles, kinetic_energy, &
                                 total_momentum
  implicit none
  private
  public :: new_bar_scene, probe_moduli, bar_load_t, bar_traction, bar_impulse, &
            bar_external_work, bar_kinematics

  !> The surface traction of one step: the nodes it acts on (is, is + 1),
  !> the weight w of the second, the nodal forces, and whether this rank
  !> holds the surface particle (global id 1).
  type :: bar_load_t
    integer :: is = 0
    real(dp) :: w = 0.0_dp, fs(2) = 0.0_dp
    logical :: mine = .false.
  end type bar_load_t

contains

  !> Build the grid and particles of `cfg`, check that the scene can run,
  !> probe the UMAT at the initial state for the wave speeds and set the time
  !> step dt = cfl * dx / sqrt(M_max / rho). Errors name the deck key.
  !> With `exchange` (collective then) the scene is this rank's share: its
  !> strip of cells with ghost layers (the wider of the shape support and
  !> the nonlocal Gaussian's) and the particles in it.
  subroutine new_bar_scene(self, cfg, err, exchange)
    type(mpm_scene_t), intent(out) :: self
    type(mpm_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    integer :: ncell_body, ncells, p, c, k, np, nlocal, cap, rank
    real(dp) :: frac, lp, m_elastic, m_plastic, x

    call check_scene(cfg, err)
    if (allocated(err)) return
    self%bar = cfg
    call start_scene(self, 1, cfg%dx, cfg%shape, cfg%scheme, cfg%density, &
                     [cfg%visc_a1, cfg%visc_a2], cfg%nstatv, err)
    if (allocated(err)) return
    self%mats = single_material(cfg%materials, cfg%props(1:cfg%nprops), cfg%nstatv, 1, &
                                self%host%ours)
    ncell_body = nint(cfg%length/cfg%dx)
    ncells = ncell_body + 2*cfg%pad_cells
    self%nlayers = ncells
    self%origin = -cfg%pad_cells*cfg%dx
    call setup_ranks(self, cfg%nonlocal, ncells + 1, &
                     merge(0, 1, cfg%shape == shape_linear), err, exchange)
    if (allocated(err)) return
    if (cfg%mass /= mass_lumped .and. self%exchange%nranks() > 1) then
      call new_error(err, status_invalid, 'mass', '&time mass = '''// &
        trim(mass_names(cfg%mass))//''' solves the mass matrix on one rank only; run it '// &
        'without mpirun, or with mass = ''lumped'''); return
    end if
    self%node_surface = cfg%pad_cells
    self%node_far = cfg%pad_cells + ncell_body
    select case (cfg%bc_far)
    case (bc_fixed, bc_symmetric)
      ! a wall at x = length: the node on it and those beyond (a GIMP
      ! particle's domain pressed past the wall would give them a sliver
      ! of mass, and USL's v = p/m + f dt/m on it no bound)
      if (self%node_far <= self%grid%ghi) &
        self%grid%fixed(1, max(self%node_far, self%grid%glo):) = .true.
    end select

    ! this rank's particles: those of its cells, in the order of the ids
    np = ncell_body*cfg%ppc
    self%ntotal = np
    lp = 0.5_dp*cfg%dx/cfg%ppc
    rank = self%exchange%rank()
    nlocal = 0
    do c = 0, ncell_body - 1
      do k = 1, cfg%ppc
        x = (c + (real(k, dp) - 0.5_dp)/cfg%ppc)*cfg%dx
        if (self%exchange%owner(x) == rank) nlocal = nlocal + 1
      end do
    end do
    cap = np
    if (self%exchange%nranks() > 1) cap = min(np, nlocal + nlocal/4 + 64)
    call scene_particles(self, cap, support_size(cfg%shape), cfg%nstatv)
    p = 0
    do c = 0, ncell_body - 1
      do k = 1, cfg%ppc
        frac = (real(k, dp) - 0.5_dp)/cfg%ppc
        x = (c + frac)*cfg%dx
        if (self%exchange%owner(x) /= rank) cycle
        p = p + 1
        self%parts%gid(p) = c*cfg%ppc + k
        self%parts%x0(1, p) = x
      end do
    end do
    self%parts%n = nlocal
    call assign_materials(self, err)
    if (allocated(err)) return
    call init_particles(self, nlocal, lp, 2.0_dp*lp)
    self%parts%v(:, 1:nlocal) = cfg%velocity0
    do p = 1, nlocal
      self%parts%stress(:, p) = cfg%stress0
    end do

    ! the stiffest material's moduli (the time step)
    do k = 1, self%mats%n
      call probe_moduli(cfg, self%mats%props(1:self%mats%nprops(k), k), m_elastic, m_plastic, &
                        err, self%mats%vumat(k))
      if (allocated(err)) return
      self%modulus_elastic = max(self%modulus_elastic, m_elastic)
      self%modulus_plastic = max(self%modulus_plastic, m_plastic)
    end do
    self%modulus_dt = max(self%modulus_elastic, self%modulus_plastic)
    self%dt = cfg%cfl*cfg%dx/sqrt(self%modulus_dt/cfg%density)
    ! the viscosity's sound speed: the elastic wave speed of uniaxial strain
    self%c_visc = sqrt(self%modulus_elastic/cfg%density)
    self%kinetic0 = kinetic_energy(self)
    self%momentum0 = total_momentum(self)
  end subroutine new_bar_scene

  !> Checks a scene must pass before it runs (impossible scenes: error).
  pure subroutine check_scene(cfg, err)
    type(mpm_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: ncell, limit
    character(len=12) :: lim_text, cfl_text, ppc_text
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
    limit = cfl_limit(cfg%scheme, cfg%mass, cfg%ppc)
    if (cfg%cfl > limit) then
      write (lim_text, '(f6.4)') limit
      write (cfl_text, '(g0.4)') cfg%cfl
      write (ppc_text, '(i0)') cfg%ppc
      call bad('time', 'cfl', '= '//trim(cfl_text)//' is above '//trim(lim_text)//', where '// &
        'scheme = '''//trim(scheme_names(cfg%scheme))//''' with mass = '''// &
        trim(mass_names(cfg%mass))//''' turns unstable at ppc = '//trim(ppc_text)// &
        ' (the linearised step; docs/research/timestep.md)', err); return
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
    if (cfg%nstatv < 1) then   ! our UMAT's 12: the material's check
      call bad('material', 'nstatv', 'must be >= 1', err); return
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
    ! GIMP's weights of a particle whose domain fills its cell are the linear
    ! ones: M_P is singular at rest for both shapes (GIMP ran: energy error 30)
    if (cfg%mass /= mass_lumped .and. cfg%ppc == 1) then
      call bad('time', 'mass', '= '''//trim(mass_names(cfg%mass))//''' needs ppc >= 2: '// &
        'with one particle per cell the particles'' mass matrix is singular (a '// &
        'node-to-node alternation no particle sees; GIMP''s weights at rest are the '// &
        'linear ones)', err); return
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
  !> Increments of 1e-5 strain. Pa. Through the VUMAT when `vumat` (the
  !> material's particles are called through it).
  subroutine probe_moduli(cfg, props, elastic, plastic, err, vumat)
    type(mpm_config_t), intent(in) :: cfg
    real(dp), intent(in) :: props(:)
    real(dp), intent(out) :: elastic, plastic
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: vumat
    real(dp), parameter :: de = 1.0e-5_dp
    real(dp) :: s(6), sv(cfg%nstatv), e(6), d(6), s1
    integer :: nsub
    type(umat_host_t) :: h
    logical :: via
    via = .false.
    if (present(vumat)) via = vumat
    call new_umat_host(h, 6, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    h%celent = cfg%dx
    d = 0.0_dp
    s = cfg%stress0; sv = 0.0_dp; e = 0.0_dp; d(1) = -de
    h%dtime = 1.0e-6_dp
    call material_update(h, props, via, s, sv, e, d, nsub, err)
    if (allocated(err)) return
    elastic = (s(1) - cfg%stress0(1))/(-de)
    ! the plastic modulus over slow increments (a rate-dependent model relaxed)
    s = cfg%stress0; sv = 0.0_dp; e = 0.0_dp; d(1) = de
    h%dtime = 1.0e3_dp
    call material_update(h, props, via, s, sv, e, d, nsub, err)
    if (allocated(err)) return
    s1 = s(1)
    h%time = 1.0e3_dp
    call material_update(h, props, via, s, sv, e, d, nsub, err)
    if (allocated(err)) return
    plastic = (s(1) - s1)/de
    if (.not. (elastic > 0.0_dp .and. plastic > 0.0_dp)) then
      call new_error(err, status_invalid, 'material', 'the material has no positive axial '// &
        'stiffness at the initial state (probed through the UMAT), so no wave can travel')
    end if
  end subroutine probe_moduli

  !> The surface traction t_x = -sigma_b on the outward normal -x at the
  !> surface x_s = x_1 - lp_1, spread with the linear hat onto the summed
  !> grid's external force; worked out by the rank holding the surface
  !> particle (global id 1) from the node masses, then applied by every rank
  !> holding the two nodes (collective).
  subroutine bar_traction(self, load)
    type(mpm_scene_t), intent(inout) :: self
    type(bar_load_t), intent(out) :: load
    integer :: psurf, is
    real(dp) :: sig_b, xs, w, surf(4)
    associate (g => self%grid, pt => self%parts)
      psurf = findloc(pt%gid(1:pt%n), 1, 1)
      surf = 0.0_dp
      load%mine = psurf > 0
      if (load%mine) then
        sig_b = surface_stress(self%bar, self%t)
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
        surf = [real(is, dp), w, -sig_b*(1.0_dp - w), -sig_b*w]
      end if
      call self%exchange%sum_reals(surf)
      load%is = nint(surf(1))
      load%w = surf(2)
      load%fs = surf(3:4)
      is = load%is
      if (is >= g%glo .and. is <= g%ghi) g%fext(1, is) = g%fext(1, is) + load%fs(1)
      if (is + 1 >= g%glo .and. is + 1 <= g%ghi) g%fext(1, is + 1) = g%fext(1, is + 1) + &
                                                                      load%fs(2)
    end associate
  end subroutine bar_traction

  !> The impulse of the step: the reaction at the fixed far end, and the
  !> surface force on the surface particle's rank.
  pure subroutine bar_impulse(self, load, reaction)
    type(mpm_scene_t), intent(inout) :: self
    type(bar_load_t), intent(in) :: load
    real(dp), intent(in) :: reaction
    if (load%mine) then
      self%impulse = self%impulse + self%dt*(load%fs(1) + load%fs(2) + reaction)
    else
      self%impulse = self%impulse + self%dt*reaction
    end if
  end subroutine bar_impulse

  !> External work: the surface force times the surface velocity of the
  !> strain (by the surface particle's rank, which holds both nodes when
  !> w < 1).
  pure subroutine bar_external_work(self, load)
    type(mpm_scene_t), intent(inout) :: self
    type(bar_load_t), intent(in) :: load
    real(dp) :: vsurf
    if (.not. load%mine) return
    vsurf = load%w*self%grid%velocity(1, load%is + 1)
    if (load%w < 1.0_dp) vsurf = (1.0_dp - load%w)*self%grid%velocity(1, load%is) + vsurf
    self%work_external = self%work_external + self%dt*(load%fs(1) + load%fs(2))*vsurf
  end subroutine bar_external_work

  !> The bar's kinematics over a step dt, particles 1 .. n in order, on
  !> plain arrays: uniaxial strain de = (L_11 dt, 0, 0, 0, 0, 0) (eq. 4.11;
  !> NTENS = nd = 6),
  !> F_11 (1 + d eps), V = F_11 V_0 with vol_n the volume of the start, and
  !> s11_0 the start's sigma_11 (the bar's work). Returns the first particle
  !> turned inside out (V <= 0), updated and the last one touched, or n + 1.
  integer function bar_kinematics(n, dt, l11, nd, de, defgrad, vol0, vol, vol_n, ns, stress, &
                                  n0, s11_0) result(bad)
    integer, intent(in) :: n, nd, ns, n0
    real(dp), intent(in) :: dt, l11(*), vol0(*), stress(ns, *)
    real(dp), intent(inout) :: de(nd, *), defgrad(9, *), vol(*), vol_n(*), s11_0(n0, *)
    integer :: p
    do p = 1, n
      de(1, p) = l11(p)*dt   ! element by element: a loop becomes a memset call
      de(2, p) = 0.0_dp
      de(3, p) = 0.0_dp
      de(4, p) = 0.0_dp
      de(5, p) = 0.0_dp
      de(6, p) = 0.0_dp
      vol_n(p) = vol(p)
      defgrad(1, p) = defgrad(1, p)*(1.0_dp + de(1, p))
      vol(p) = vol0(p)*defgrad(1, p)
      if (.not. vol(p) > 0.0_dp) then
        bad = p
        return
      end if
      s11_0(1, p) = stress(1, p)
    end do
    bad = n + 1
  end function bar_kinematics

end module wellposed_mpm_bar
