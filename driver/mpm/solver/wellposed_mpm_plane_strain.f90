!> The plate scene kind of the MPM in 2D plane strain (chapter 4, fig.
!> 4.1): a body [0, width] x [0, height] on a uniform grid, GIMP, CPDI or
!> linear weights, the UMAT with NTENS = 4. Here the geometry, boundaries
!> (bottom roller|fixed|free; top velocity|free with the platen on the
!> surface, grid or by contact; sides free|roller; nodes past a boundary
!> share its condition), dt = cfl dx / sqrt(M/rho) with M probed through the
!> UMAT, and the load kernel; ranks are strips of cell rows. Deck keys:
!> docs/guide/decks.md; the platen: docs/research/bands.md.
module wellposed_mpm_plane_strain
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text
  use wellposed_umat_host, only: host_call, host_error, verdict_ok, verdict_cutback
  use wellposed_mpm_vumat_call, only: material_update
  use wellposed_mpm_materials, only: single_material
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_shape_2d, only: support_size_2d, shape2d_reach, shape_2d, shape2d_linear
  use wellposed_mpm_plate_config, only: ps_config_t, check_plate_config, bc_roller, &
                                        bc_fixed2, bc_free2, bc_velocity, bc2_names, &
                                        platen_surface, platen_contact, platen_names
  use wellposed_mpm_scene, only: mpm_scene_t, platen_base, start_scene, setup_ranks, &
                                 scene_particles, assign_materials, init_particles
  implicit none
  private
  public :: ps_config_t, new_plate_scene, platen_velocity, platen_nodes, platen_push, &
            apparent_strain, bc_roller, bc_fixed2, bc_free2, bc_velocity, bc2_names, platen_names

contains

  !> Build grid, particles, materials and the time step; errors name keys.
  !> With `exchange` (collective then) this rank keeps its strip of cell
  !> rows, the nodes they touch with their ghost rows, and the particles in
  !> them (global ids as in the serial scene).
  subroutine new_plate_scene(self, cfg, err, exchange)
    type(mpm_scene_t), intent(out) :: self
    type(ps_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    integer :: ncx, ncy, np, p, a, b, k, g, nlocal, cap, rank
    real(dp) :: lp, xy(2), ds(4), m_k

    call check_plate_config(cfg, err)
    if (allocated(err)) return
    self%plate = cfg
    call start_scene(self, 2, cfg%dx, cfg%shape, cfg%scheme, cfg%density, &
                     [cfg%visc_a1, cfg%visc_a2], cfg%nstatv, err)
    if (allocated(err)) return
    ncx = nint(cfg%width/cfg%dx)
    ncy = nint(cfg%height/cfg%dx)
    self%nx = ncx + 2*cfg%pad_cells + 1
    self%ny = ncy + 2*cfg%pad_cells + 1
    self%nlayers = self%ny - 1
    self%origin = -cfg%pad_cells*cfg%dx
    call setup_ranks(self, cfg%nonlocal, self%nx*self%ny, &
                     shape2d_reach(cfg%shape), err, exchange)
    if (allocated(err)) return
    call platen_nodes(self)

    np = ncx*ncy*cfg%ppc**2
    self%ntotal = np
    lp = 0.5_dp*cfg%dx/cfg%ppc
    ! this rank's particles: those whose cell row it owns (all on one rank)
    rank = self%exchange%rank()
    nlocal = 0
    do b = 1, ncy*cfg%ppc
      if (self%exchange%owner((b - 0.5_dp)*2.0_dp*lp) == rank) nlocal = nlocal + ncx*cfg%ppc
    end do
    cap = np
    if (self%exchange%nranks() > 1) cap = min(np, nlocal + nlocal/4 + 64)
    call scene_particles(self, cap, support_size_2d(cfg%shape), cfg%nstatv)
    self%mats = single_material(cfg%materials, cfg%props(1:cfg%nprops), cfg%nstatv, 2, &
                                self%host%ours)
    p = 0
    g = 0
    do b = 1, ncy*cfg%ppc
      do a = 1, ncx*cfg%ppc
        g = g + 1
        xy = [(a - 0.5_dp)*2.0_dp*lp, (b - 0.5_dp)*2.0_dp*lp]
        if (self%exchange%owner(xy(2)) /= rank) cycle
        p = p + 1
        self%parts%gid(p) = g
        self%parts%x0(:, p) = xy
      end do
    end do
    self%parts%n = nlocal
    call assign_materials(self, err)
    if (allocated(err)) return
    call init_particles(self, nlocal, lp, (2.0_dp*lp)**2)
    do p = 1, nlocal
      self%parts%v(:, p) = matmul(cfg%velocity_gradient0, self%parts%x0(:, p))
    end do
    self%parts%stress(:, 1:nlocal) = 0.0_dp

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
      self%modulus_elastic = max(self%modulus_elastic, m_k)
      self%bulk = max(self%bulk, -ds(1)/3.0e-7_dp)
    end do
    self%modulus_dt = self%modulus_elastic
    self%c_max = sqrt(self%modulus_elastic/cfg%density)
    self%dt = cfg%cfl*cfg%dx/self%c_max
    self%c_visc = sqrt(self%bulk/cfg%density)

  contains

    !> The stress of one UMAT call from the natural state (0 when the UMAT
    !> asks to cut back; a refusal or a non-finite answer is the error err),
    !> or of the VUMAT's for a material called through it.
    function probe(m, d) result(dsig)
      integer, intent(in) :: m
      real(dp), intent(in) :: d(4)
      real(dp) :: dsig(4), s(4), sv(cfg%nstatv), e(4)
      integer :: verdict, nsub
      s = 0.0_dp
      sv = 0.0_dp
      e = 0.0_dp
      self%host%time = 0.0_dp
      self%host%dtime = 1.0e-6_dp
      self%host%noel = 1
      self%host%coords = 0.0_dp
      if (self%mats%vumat(m)) then
        ! through the VUMAT its particles are called through
        call material_update(self%host, self%mats%props(1:self%mats%nprops(m), m), .true., s, &
                             sv, e, d, nsub, err)
        dsig = s
        if (allocated(err)) err%message = err%message//' (probing the moduli)'
        return
      end if
      call host_call(self%host, self%mats%props(1:self%mats%nprops(m), m), s, sv, e, d, verdict)
      dsig = s
      if (verdict /= verdict_ok) dsig = 0.0_dp
      if (verdict /= verdict_ok .and. verdict /= verdict_cutback) &
        call host_error(self%host, verdict, err, 'probing the moduli')
    end function probe

  end subroutine new_plate_scene

  !> The boundary conditions on the nodes, set again whenever the platen's
  !> lowest node row changes (before each step's grid update). The platen
  !> covers the top face only, 0 <= x <= width, and its velocity (0, v_top)
  !> (v_top alone with top_lateral free) wins over the other conditions.
  !> 'grid': the node rows y >= height. 'surface': the rows at and above the
  !> highest row at or below the body's current top y = height + top_disp,
  !> so the cell under the lowest platen row is full of material: a node's
  !> internal force (eq. 4.5) integrates stress over the material in its
  !> cells only, so a partly filled cell of depth f dx under the platen row
  !> passes the load on at 1/f times the body's stress (docs/research/bands.md, "The
  !> platen"); the material above that row moves with the platen.
  subroutine platen_nodes(self)
    type(mpm_scene_t), intent(inout) :: self
    integer :: i, j, g, jtop
    real(dp) :: xy(2), tol
    associate (cfg => self%plate)
      tol = 1.0e-6_dp*cfg%dx
      jtop = self%ny
      if (cfg%top == bc_velocity) then
        if (cfg%platen == platen_contact) then
          jtop = self%ny + 1
        else if (cfg%platen == platen_surface) then
          jtop = floor((cfg%height + self%top_disp - self%origin(2))/cfg%dx + 1.0e-6_dp)
        else
          jtop = nint((cfg%height - self%origin(2))/cfg%dx)
        end if
      end if
      if (jtop == self%platen_row) return
      self%platen_row = jtop
      self%grid%fixed = .false.
      self%grid%given = .false.
      do j = self%grid%glo/self%nx, self%grid%ghi/self%nx
        do i = 0, self%nx - 1
          g = i + self%nx*j
          xy = self%origin + cfg%dx*[i, j]
          if (xy(2) <= 0.5_dp*tol) then
            if (cfg%bottom == bc_roller) self%grid%fixed(2, g) = .true.
            if (cfg%bottom == bc_fixed2) self%grid%fixed(:, g) = .true.
          end if
          if (cfg%sides == bc_roller .and. (xy(1) <= tol .or. xy(1) >= cfg%width - tol)) &
            self%grid%fixed(1, g) = .true.
          if (j >= jtop .and. xy(1) >= -tol .and. xy(1) <= cfg%width + tol) then
            self%grid%fixed(2, g) = .false.
            self%grid%given(2, g) = .true.
            if (cfg%top_lateral_fixed) then
              self%grid%fixed(1, g) = .false.
              self%grid%given(1, g) = .true.
            end if
          end if
        end do
      end do
    end associate
  end subroutine platen_nodes

  !> The frictionless platen (platen = 'contact'): a rigid plane at
  !> y = height + top_disp moving at v_top pushes, normal to itself only, on
  !> every particle whose top edge (the side of its domain, x_p + r2 +- r1,
  !> r1 = lp_x F e_x, r2 = lp_y F e_y) has passed it by g > 0 (at the edge's
  !> middle): f = -(k g + c (v_y - v_top)), never a pull, k = M w/lp_y (the
  !> constrained modulus M over half a particle, w the edge's width) but at
  !> most m_p/dt^2 (so omega dt <= 1 whatever cfl and ppc), c = sqrt(k m_p)
  !> (damping ratio 1/2). The force acts where a traction
  !> does, on the edge: half at each end, with the grid's bilinear weights,
  !> so a uniform stress is in equilibrium with it on any mesh (a node's
  !> eq. 4.5 integrates the stress over the body, whose top is that edge).
  !> Before the ghost sum. docs/research/bands.md, "The platen".
  subroutine platen_push(self, vtop)
    type(mpm_scene_t), intent(inout) :: self
    real(dp), intent(in) :: vtop
    integer :: p, k, e, nodes(4)
    real(dp) :: y_pl, r1(2), r2(2), edge(2), gap, stiff, force, phi(4), grad(2, 4)
    associate (cfg => self%plate, pt => self%parts, g => self%grid)
      if (cfg%top /= bc_velocity .or. cfg%platen /= platen_contact) return
      y_pl = cfg%height + self%top_disp
      do p = 1, pt%n
        call top_edge(pt, p, y_pl, r1, r2, gap)
        if (.not. gap > 0.0_dp) cycle
        stiff = min(self%modulus_elastic*2.0_dp*abs(r1(1))/pt%lp(2, p), &
                    pt%mass(p)/self%dt**2)
        force = -(stiff*gap + sqrt(stiff*pt%mass(p))*(pt%v(2, p) - vtop))
        force = 0.5_dp*min(force, 0.0_dp)
        do e = -1, 1, 2
          edge = pt%x(:, p) + r2 + e*r1
          call shape_2d(shape2d_linear, edge, pt%lp(:, p), pt%defgrad(1:2, 1:2, p), &
                        self%origin, self%dx, self%nx, nodes, phi, grad)
          do k = 1, 4
            if (nodes(k) >= g%glo .and. nodes(k) <= g%ghi) &
              g%fext(2, nodes(k)) = g%fext(2, nodes(k)) + phi(k)*force
          end do
        end do
      end do
    end associate
  end subroutine platen_push

  !> Particle p's domain, half side vectors r1 = lp_x F e_x, r2 = lp_y F e_y,
  !> and the height `gap` of its top edge's middle x_p + r2 above y_pl.
  pure subroutine top_edge(pt, p, y_pl, r1, r2, gap)
    type(particles_t), intent(in) :: pt
    integer, intent(in) :: p
    real(dp), intent(in) :: y_pl
    real(dp), intent(out) :: r1(2), r2(2), gap
    r1 = pt%lp(1, p)*pt%defgrad(1:2, 1, p)
    r2 = pt%lp(2, p)*pt%defgrad(1:2, 2, p)
    gap = pt%x(2, p) + r2(2) - y_pl
  end subroutine top_edge

  !> The apparent axial strain (compression +) of the body under the
  !> platen's lowest node row y_g, the body applied_stress averages over:
  !> -top_disp/height while that row lies above the body ('grid'), else
  !> -top_disp/(y_g - top_disp) (the layer above y_g moves with the platen).
  !> With platen = 'contact' the body's top is the platen's plane less the
  !> mean penetration of the edges it pushes (weighted by their width).
  !> Collective.
  real(dp) function apparent_strain(self) result(e)
    type(mpm_scene_t), intent(in) :: self
    real(dp) :: yg, a(2), r1(2), r2(2), gap
    integer :: p
    if (self%plate%platen == platen_contact) then
      a = 0.0_dp
      do p = 1, self%parts%n
        call top_edge(self%parts, p, self%plate%height + self%top_disp, r1, r2, gap)
        if (gap > 0.0_dp) a = a + [gap*abs(r1(1)), abs(r1(1))]
      end do
      call self%exchange%sum_reals(a)
      if (a(2) > 0.0_dp) a(1) = a(1)/a(2)
      e = -(self%top_disp + a(1))/self%plate%height
      return
    end if
    yg = platen_base(self)
    if (yg >= self%plate%height + self%top_disp) then
      e = -self%top_disp/self%plate%height
    else
      e = -self%top_disp/(yg - self%top_disp)
    end if
  end function apparent_strain

  !> The platen's velocity v_top of the step ending at t + dt: the deck's,
  !> ramped linearly over ramp_time (m/s).
  pure real(dp) function platen_velocity(cfg, t, dt) result(vtop)
    type(ps_config_t), intent(in) :: cfg
    real(dp), intent(in) :: t, dt
    vtop = cfg%top_velocity
    if (cfg%ramp_time > 0.0_dp) vtop = vtop*min(1.0_dp, (t + dt)/cfg%ramp_time)
  end function platen_velocity

end module wellposed_mpm_plane_strain
