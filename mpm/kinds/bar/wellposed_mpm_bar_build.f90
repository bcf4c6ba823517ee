!> The bar scene kind's build (the 1D uniaxial-strain scenes of the
!> dissertation's chapter 2, Sandler-Rubin case study): the body [0, length]
!> with ppc particles per cell, the far end fixed, symmetric or free, the
!> checks a scene must pass and the time step from the UMAT's axial moduli.
!> The kind itself: wellposed_mpm_bar_kind; the step: wellposed_mpm_step.
module wellposed_mpm_bar_build
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_bar_config
  use wellposed_mpm_bar_cfl_limit, only: cfl_limit
  use wellposed_mpm_shape, only: support_size
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_materials, only: single_material
  use wellposed_mpm_scene, only: mpm_scene_t, probe_kind
  use wellposed_mpm_scene_build, only: start_scene, setup_ranks, scene_particles, &
                                       assign_materials, init_particles
  use wellposed_mpm_scene_sums, only: kinetic_energy, total_momentum
  use wellposed_mpm_bar_kind, only: bar_kind_t, probe_moduli
  implicit none
  private
  public :: new_bar_scene, probe_moduli

contains

  !> Build the grid and particles of `cfg`, check that the scene can run,
  !> probe the UMAT at the initial state for the wave speeds and set the time
  !> step (bar_probe). Errors name the deck key.
  !> With `exchange` (collective then) the scene is this rank's share: its
  !> strip of cells with ghost layers (the wider of the shape support and
  !> the nonlocal Gaussian's) and the particles in it.
  subroutine new_bar_scene(self, cfg, err, exchange)
    type(mpm_scene_t), intent(out) :: self
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    integer :: ncell_body, ncells, p, c, k, np, nlocal, cap, rank
    real(dp) :: frac, lp, x
    type(bar_kind_t) :: bar

    call check_scene(cfg, err)
    if (allocated(err)) return
    ncell_body = nint(cfg%length/cfg%dx)
    bar%cfg = cfg
    bar%ntens = 6   ! uniaxial strain through the full tensor
    bar%node_surface = cfg%pad_cells
    bar%node_far = cfg%pad_cells + ncell_body
    call start_scene(self, bar, 1, cfg%dx, cfg%shape, cfg%scheme, cfg%density, &
                     [cfg%visc_a1, cfg%visc_a2], cfg%nstatv, err)
    if (allocated(err)) return
    self%mats = single_material(cfg%materials, cfg%props(1:cfg%nprops), cfg%nstatv, 1, &
                                self%host%ours)
    ncells = ncell_body + 2*cfg%pad_cells
    self%nlayers = ncells
    self%origin = -cfg%pad_cells*cfg%dx
    call setup_ranks(self, cfg%nonlocal, ncells + 1, &
                     merge(0, 1, cfg%shape == shape_linear), err, exchange)
    if (allocated(err)) return
    select case (cfg%bc_far)
    case (bc_fixed, bc_symmetric)
      ! a wall at x = length: the node on it and those beyond (a GIMP
      ! particle's domain pressed past the wall would give them a sliver
      ! of mass, and USL's v = p/m + f dt/m on it no bound)
      if (bar%node_far <= self%grid%ghi) &
        self%grid%fixed(1, max(bar%node_far, self%grid%glo):) = .true.
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

    ! the stiffest material's moduli (the time step), the start's sums
    call probe_kind(self, err)
    if (allocated(err)) return
    select type (bk => self%kind)
    type is (bar_kind_t)
      bk%book%kinetic0 = kinetic_energy(self)
      bk%book%momentum0 = total_momentum(self)
    end select
  end subroutine new_bar_scene

  !> Checks a scene must pass before it runs (impossible scenes: error).
  pure subroutine check_scene(cfg, err)
    type(bar_config_t), intent(in) :: cfg
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

end module wellposed_mpm_bar_build
