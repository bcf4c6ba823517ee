!> The plate scene kind in 2D plane strain (chapter 4, fig. 4.1): its
!> configuration and bookkeeping (the top's displacement, the platen's
!> lowest node row) and what it adds to the step: the boundary conditions
!> and the platen (on the surface, grid or by contact), the plane-strain
!> kinematics (NTENS 4, Jaumann rotation), the moduli probe; and its
!> measures (applied stress, apparent strain). Its build:
!> wellposed_mpm_plate_build. The platen: docs/research/bands.md.
module wellposed_mpm_plate_kind
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text
  use wellposed_umat_host, only: umat_host_t, host_call, host_error, verdict_ok, verdict_cutback
  use wellposed_mpm_materials, only: mpm_materials_t
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_shape_2d, only: shape_2d, shape2d_linear
  use wellposed_mpm_particle_umat, only: strain_increment
  use wellposed_mpm_vumat_call, only: material_update
  use wellposed_mpm_plate_config, only: plate_config_t, bc_roller, bc_plate_fixed, bc_velocity, &
                                        platen_surface, platen_contact
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t
  implicit none
  private
  public :: plate_kind_t, platen_nodes, applied_stress, platen_base, apparent_strain, &
            platen_velocity, plate_config, probe_stress

  !> A plate: its deck's configuration, the top's vertical displacement
  !> (m), the platen's lowest node row (none yet: -huge) and the probed
  !> bulk modulus K (Pa).
  type, extends(scene_kind_t) :: plate_kind_t
    type(plate_config_t) :: cfg
    real(dp) :: top_disp = 0.0_dp
    integer :: platen_row = -huge(1)
    real(dp) :: bulk = 0.0_dp
    !> the contact platen's explicit push in `forces` (off: the implicit
    !> step puts its own in the residual, wellposed_mpm_implicit_contact)
    logical :: push = .true.
  contains
    procedure :: probe => plate_probe
    procedure :: forces => platen_push
    procedure :: conditions => plate_conditions
    procedure :: kinematics => plate_kinematics
    procedure :: bookkeeping => plate_bookkeeping
    procedure :: scalars => plate_scalars
    procedure :: set_scalars => plate_set_scalars
  end type plate_kind_t

contains

  !> Moduli through the UMAT: uniaxial strain (M) and isotropic (3K), the
  !> stiffest material's; dt = cfl dx / sqrt(M/rho), the viscosity's sound
  !> speed sqrt(K/rho).
  subroutine plate_probe(self, sc, err)
    class(plate_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: ds(4), m_k
    integer :: k
    do k = 1, sc%mats%n
      ds = probe_stress(sc%host, sc%mats, k, [-1.0e-7_dp, 0.0_dp, 0.0_dp, 0.0_dp], &
                        self%cfg%nstatv, 'probing the moduli', err)
      if (allocated(err)) return
      m_k = -ds(1)/1.0e-7_dp
      ds = probe_stress(sc%host, sc%mats, k, [-1.0e-7_dp, -1.0e-7_dp, -1.0e-7_dp, 0.0_dp], &
                        self%cfg%nstatv, 'probing the moduli', err)
      if (allocated(err)) return
      if (.not. (m_k > 0.0_dp .and. -ds(1)/3.0e-7_dp > 0.0_dp)) then
        call new_error(err, status_invalid, 'material', 'the UMAT answers no positive '// &
          'stiffness at the initial state (M = '//real_text(m_k)//' Pa, K = '// &
          real_text(-ds(1)/3.0e-7_dp)//' Pa)'); return
      end if
      sc%modulus_elastic = max(sc%modulus_elastic, m_k)
      self%bulk = max(self%bulk, -ds(1)/3.0e-7_dp)
    end do
    sc%modulus_dt = sc%modulus_elastic
    sc%c_max = sqrt(sc%modulus_elastic/self%cfg%density)
    sc%dt = self%cfg%cfl*self%cfg%dx/sc%c_max
    sc%c_visc = sqrt(self%bulk/self%cfg%density)
  end subroutine plate_probe

  !> The stress of one call of material m of `mats` through `host` from the
  !> natural state over d (0 when the UMAT asks to cut back; a refusal or a
  !> non-finite answer is the error err, its context `what`), or of the
  !> VUMAT's for a material called through it. The scene's probe and the
  !> deck's step check (wellposed_mpm_plate_checks) both call it.
  function probe_stress(host, mats, m, d, nstatv, what, err) result(dsig)
    type(umat_host_t), intent(inout) :: host
    type(mpm_materials_t), intent(in) :: mats
    integer, intent(in) :: m, nstatv
    real(dp), intent(in) :: d(4)
    character(len=*), intent(in) :: what
    type(error_t), allocatable, intent(inout) :: err
    real(dp) :: dsig(4), s(4), sv(nstatv), e(4)
    integer :: verdict, nsub
    s = 0.0_dp
    sv = 0.0_dp
    e = 0.0_dp
    host%time = 0.0_dp
    host%dtime = 1.0e-6_dp
    host%noel = 1
    host%coords = 0.0_dp
    if (mats%vumat(m)) then
      ! through the VUMAT its particles are called through
      call material_update(host, mats%props(1:mats%nprops(m), m), .true., s, sv, e, d, &
                           nsub, err)
      dsig = s
      if (allocated(err)) err%message = err%message//' ('//what//')'
      return
    end if
    call host_call(host, mats%props(1:mats%nprops(m), m), s, sv, e, d, verdict)
    dsig = s
    if (verdict /= verdict_ok) dsig = 0.0_dp
    if (verdict /= verdict_ok .and. verdict /= verdict_cutback) &
      call host_error(host, verdict, err, what)
  end function probe_stress

  !> The platen's node conditions of the step (platen_nodes) and its
  !> velocity (0, v_top) as the given one.
  subroutine plate_conditions(self, sc, given)
    class(plate_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(inout) :: given(:)
    call platen_nodes(self, sc)
    given(2) = platen_velocity(self%cfg, sc%t, sc%dt)
  end subroutine plate_conditions

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
  subroutine platen_nodes(self, sc)
    class(plate_kind_t), intent(inout) :: self
    type(mpm_scene_t), intent(inout) :: sc
    integer :: i, j, g, jtop
    real(dp) :: xy(2), tol
    associate (cfg => self%cfg)
      tol = 1.0e-6_dp*cfg%dx
      jtop = sc%ny
      if (cfg%top == bc_velocity) then
        if (cfg%platen == platen_contact) then
          jtop = sc%ny + 1
        else if (cfg%platen == platen_surface) then
          jtop = floor((cfg%height + self%top_disp - sc%origin(2))/cfg%dx + 1.0e-6_dp)
        else
          jtop = nint((cfg%height - sc%origin(2))/cfg%dx)
        end if
      end if
      if (jtop == self%platen_row) return
      self%platen_row = jtop
      sc%grid%fixed = .false.
      sc%grid%given = .false.
      do j = sc%grid%glo/sc%nx, sc%grid%ghi/sc%nx
        do i = 0, sc%nx - 1
          g = i + sc%nx*j
          xy = sc%origin + cfg%dx*[i, j]
          if (xy(2) <= 0.5_dp*tol) then
            if (cfg%bottom == bc_roller) sc%grid%fixed(2, g) = .true.
            if (cfg%bottom == bc_plate_fixed) sc%grid%fixed(:, g) = .true.
          end if
          if (cfg%sides == bc_roller .and. (xy(1) <= tol .or. xy(1) >= cfg%width - tol)) &
            sc%grid%fixed(1, g) = .true.
          if (j >= jtop .and. xy(1) >= -tol .and. xy(1) <= cfg%width + tol) then
            sc%grid%fixed(2, g) = .false.
            sc%grid%given(2, g) = .true.
            if (cfg%top_lateral_fixed) then
              sc%grid%fixed(1, g) = .false.
              sc%grid%given(1, g) = .true.
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
  !> Before the ghost sum, at the step's v_top. docs/research/bands.md, "The platen".
  subroutine platen_push(self, sc)
    class(plate_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer :: p, k, e, nodes(4)
    real(dp) :: y_pl, r1(2), r2(2), edge(2), gap, stiff, force, phi(4), grad(2, 4), vtop
    associate (cfg => self%cfg, pt => sc%parts, g => sc%grid)
      if (cfg%top /= bc_velocity .or. cfg%platen /= platen_contact .or. .not. self%push) return
      vtop = platen_velocity(cfg, sc%t, sc%dt)
      y_pl = cfg%height + self%top_disp
      do p = 1, pt%n
        call top_edge(pt, p, y_pl, r1, r2, gap)
        if (.not. gap > 0.0_dp) cycle
        stiff = min(sc%modulus_elastic*2.0_dp*abs(r1(1))/pt%lp(2, p), &
                    pt%mass(p)/sc%dt**2)
        force = -(stiff*gap + sqrt(stiff*pt%mass(p))*(pt%v(2, p) - vtop))
        force = 0.5_dp*min(force, 0.0_dp)
        do e = -1, 1, 2
          edge = pt%x(:, p) + r2 + e*r1
          call shape_2d(shape2d_linear, edge, pt%lp(:, p), pt%defgrad(1:2, 1:2, p), &
                        sc%origin, sc%dx, sc%nx, nodes, phi, grad)
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

  !> The plane-strain kinematics of particles 1 .. n in order: the strain
  !> increment from lgrad (NTENS 4), the start's volume (and F for a user's
  !> UMAT), F and volume (deform), then the Jaumann rotation of the stress.
  !> Stops at the first particle turned inside out (after its deform).
  integer function plate_kinematics(self, sc) result(last)
    class(plate_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer :: p
    real(dp) :: lg(2, 2)
    associate (pt => sc%parts)
      do p = 1, pt%n
        ! entry by entry: a whole-array copy of runtime size costs a loop nest
        lg(1, 1) = sc%lgrad(1, 1, p)
        lg(2, 1) = sc%lgrad(2, 1, p)
        lg(1, 2) = sc%lgrad(1, 2, p)
        lg(2, 2) = sc%lgrad(2, 2, p)
        call strain_increment(lg, sc%dt, sc%de(:, p))
        sc%vol_n(p) = pt%vol(p)
        if (allocated(sc%f_n)) sc%f_n(:, :, p) = pt%defgrad(1:2, 1:2, p)
        call deform(sc, p, lg)
        if (.not. pt%vol(p) > 0.0_dp) then
          last = p
          return
        end if
        call jaumann(sc, p, lg)
      end do
      last = pt%n + 1
    end associate
  end function plate_kinematics

  !> The top's displacement over the step, at the platen's velocity.
  subroutine plate_bookkeeping(self, sc)
    class(plate_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    if (self%cfg%top == bc_velocity) &
      self%top_disp = self%top_disp + platen_velocity(self%cfg, sc%t, sc%dt)*sc%dt
  end subroutine plate_bookkeeping

  !> The top's displacement (a checkpoint's scalar; the platen row follows).
  function plate_scalars(self) result(v)
    class(plate_kind_t), intent(in) :: self
    real(dp), allocatable :: v(:)
    v = [self%top_disp]
  end function plate_scalars

  subroutine plate_set_scalars(self, v)
    class(plate_kind_t), intent(inout) :: self
    real(dp), intent(in) :: v(:)
    self%top_disp = v(1)
  end subroutine plate_set_scalars

  !> The configuration of the plate scene sc (the defaults for another kind).
  function plate_config(sc) result(cfg)
    type(mpm_scene_t), intent(in) :: sc
    type(plate_config_t) :: cfg
    select type (k => sc%kind)
    type is (plate_kind_t)
      cfg = k%cfg
    end select
  end function plate_config

  !> The plate's applied axial stress (Pa, compression positive): the top
  !> force per unit initial width, from the volume average of sigma_yy (in
  !> equilibrium without body force, int sigma_yy dV = F_top * H, H the
  !> current height) over the body under the platen's lowest node row y_g
  !> (the layer above it moves with the platen): -sum_p sigma_yy V_p /
  !> (width * min(y_g, height + top_disp)), particles with y_p < y_g.
  !> Robust to the boundary layer under a laterally fixed top and to the
  !> mesh. Collective; zero for a scene of another kind.
  real(dp) function applied_stress(sc) result(s)
    type(mpm_scene_t), intent(in) :: sc
    integer :: n
    real(dp) :: a(1), yg
    s = 0.0_dp
    select type (self => sc%kind)
    type is (plate_kind_t)
      n = sc%parts%n
      yg = platen_base(sc)
      a(1) = sum(sc%parts%stress(2, 1:n)*sc%parts%vol(1:n), mask=sc%parts%x(2, 1:n) < yg)
      call sc%exchange%sum_reals(a)
      s = -a(1)/(self%cfg%width*min(yg, self%cfg%height + self%top_disp))
    end select
  end function applied_stress

  !> The height y_g under which the plate's body is measured (applied_stress,
  !> the top cell row's stress ratio): the platen's lowest node row, or the
  !> platen's plane with platen = 'contact' (no node row; docs/research/bands.md).
  pure real(dp) function platen_base(sc) result(yg)
    type(mpm_scene_t), intent(in) :: sc
    yg = 0.0_dp
    select type (self => sc%kind)
    type is (plate_kind_t)
      if (self%cfg%platen == platen_contact) then
        yg = self%cfg%height + self%top_disp
      else
        yg = sc%origin(2) + sc%dx*self%platen_row
      end if
    end select
  end function platen_base

  !> The apparent axial strain (compression +) of the body under the
  !> platen's lowest node row y_g, the body applied_stress averages over:
  !> -top_disp/height while that row lies above the body ('grid'), else
  !> -top_disp/(y_g - top_disp) (the layer above y_g moves with the platen).
  !> With platen = 'contact' the body's top is the platen's plane less the
  !> mean penetration of the edges it pushes (weighted by their width).
  !> Collective; zero for a scene of another kind.
  real(dp) function apparent_strain(sc) result(e)
    type(mpm_scene_t), intent(in) :: sc
    real(dp) :: yg, a(2), r1(2), r2(2), gap
    integer :: p
    e = 0.0_dp
    select type (self => sc%kind)
    type is (plate_kind_t)
    if (self%cfg%platen == platen_contact) then
      a = 0.0_dp
      do p = 1, sc%parts%n
        call top_edge(sc%parts, p, self%cfg%height + self%top_disp, r1, r2, gap)
        if (gap > 0.0_dp) a = a + [gap*abs(r1(1)), abs(r1(1))]
      end do
      call sc%exchange%sum_reals(a)
      if (a(2) > 0.0_dp) a(1) = a(1)/a(2)
      e = -(self%top_disp + a(1))/self%cfg%height
      return
    end if
    yg = platen_base(sc)
    if (yg >= self%cfg%height + self%top_disp) then
      e = -self%top_disp/self%cfg%height
    else
      e = -self%top_disp/(yg - self%top_disp)
    end if
    end select
  end function apparent_strain

  !> The platen's velocity v_top of the step [t, t + dt]: the mean over it of
  !> the deck's velocity ramped linearly over ramp_time (m/s), so that the
  !> step moves the platen by the ramp's exact displacement whatever dt (an
  !> implicit step may span the ramp).
  pure real(dp) function platen_velocity(cfg, t, dt) result(vtop)
    type(plate_config_t), intent(in) :: cfg
    real(dp), intent(in) :: t, dt
    real(dp) :: r
    vtop = cfg%top_velocity
    r = cfg%ramp_time
    if (r <= 0.0_dp) return
    if (dt > 0.0_dp) then
      vtop = vtop*(ramped(t + dt) - ramped(t))/dt
    else
      vtop = vtop*min(1.0_dp, t/r)
    end if
  contains
    !> the ramp's displacement at time s over the full speed's
    pure real(dp) function ramped(s)
      real(dp), intent(in) :: s
      ramped = merge(max(s, 0.0_dp)**2/(2.0_dp*r), s - 0.5_dp*r, s < r)
    end function ramped
  end function platen_velocity

  !> The F and volume kernel of a plate's particle p over the step:
  !> F_{n+1} = F_n + dt L F_n, V = det F V_0 (a bar's: wellposed_mpm_bar_kind).
  !> The caller checks V > 0 (a particle turned inside out): no error text
  !> here keeps this small enough to inline into the particle loop.
  pure subroutine deform(self, p, lg)
    class(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: lg(2, 2)
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

  !> Jaumann rotation of the in-plane stress of particle p before the UMAT:
  !> sigma += dt (W sigma - sigma W), W12 = (L12 - L21)/2.
  pure subroutine jaumann(self, p, lg)
    class(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: lg(2, 2)
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

end module wellposed_mpm_plate_kind
