!> The bar scene kind (the 1D uniaxial-strain scenes of chapter 2): its
!> configuration and bookkeeping (work, impulse, the start's energy and
!> momentum) and what it adds to the step: the surface traction on the
!> moving free surface, the mass matrix of &time mass, the uniaxial strain
!> (NTENS 6), the work and impulse sums and the axial moduli probe. Its
!> build: wellposed_mpm_bar_build.
module wellposed_mpm_bar_kind
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_method, only: mass_lumped
  use wellposed_mpm_bar_config, only: bar_config_t
  use wellposed_mpm_bar_loads, only: surface_stress
  use wellposed_mpm_mass_matrix, only: mass_matrix_update
  use wellposed_umat_host, only: umat_host_t, new_umat_host
  use wellposed_mpm_vumat_call, only: material_update
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t
  implicit none
  private
  public :: bar_kind_t, bar_book_t, bar_book, bar_modulus_plastic, probe_moduli

  !> The surface traction of one step: the nodes it acts on (is, is + 1),
  !> the weight w of the second, the nodal forces, and whether this rank
  !> holds the surface particle (global id 1).
  type :: bar_load_t
    integer :: is = 0
    real(dp) :: w = 0.0_dp, fs(2) = 0.0_dp
    logical :: mine = .false.
  end type bar_load_t

  !> The bar's bookkeeping per unit cross-section (J/m^2, kg m/s / m^2);
  !> the work and impulse are this rank's shares.
  type :: bar_book_t
    real(dp) :: work_internal = 0.0_dp    !< int sigma : d eps dV (stored + dissipated)
    real(dp) :: work_external = 0.0_dp    !< work of the surface traction
    real(dp) :: impulse = 0.0_dp          !< time integral of surface force + reaction
    real(dp) :: kinetic0 = 0.0_dp, momentum0 = 0.0_dp  !< at the start (all ranks)
  end type bar_book_t

  !> A bar: its deck's configuration, the nodes at x = 0 and x = length
  !> (global), the probed loading modulus, the bookkeeping and the step's
  !> surface traction.
  type, extends(scene_kind_t) :: bar_kind_t
    type(bar_config_t) :: cfg
    integer :: node_surface = 0, node_far = 0
    real(dp) :: modulus_plastic = 0.0_dp  !< axial loading modulus (Pa)
    type(bar_book_t) :: book
    type(bar_load_t) :: load
  contains
    procedure :: probe => bar_probe
    procedure :: conditions => bar_traction
    procedure :: grid_solved => bar_grid_solved
    procedure :: kinematics => bar_kinematics
    procedure :: bookkeeping => bar_bookkeeping
    procedure :: partial_sums => bar_partial_sums
    procedure :: set_partial_sums => bar_set_partial_sums
    procedure :: scalars => bar_scalars
    procedure :: set_scalars => bar_set_scalars
  end type bar_kind_t

contains

  !> The stiffest material's axial moduli (probe_moduli) and the time step
  !> dt = cfl * dx / sqrt(M_max / rho); the viscosity's sound speed is the
  !> elastic wave speed of uniaxial strain.
  subroutine bar_probe(self, sc, err)
    class(bar_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: m_elastic, m_plastic
    integer :: k
    do k = 1, sc%mats%n
      call probe_moduli(self%cfg, sc%mats%props(1:sc%mats%nprops(k), k), m_elastic, m_plastic, &
                        err, sc%mats%vumat(k))
      if (allocated(err)) return
      sc%modulus_elastic = max(sc%modulus_elastic, m_elastic)
      self%modulus_plastic = max(self%modulus_plastic, m_plastic)
    end do
    sc%modulus_dt = max(sc%modulus_elastic, self%modulus_plastic)
    sc%c_max = sqrt(sc%modulus_dt/self%cfg%density)
    sc%dt = self%cfg%cfl*self%cfg%dx/sc%c_max
    sc%c_visc = sqrt(sc%modulus_elastic/self%cfg%density)
  end subroutine bar_probe

  !> Axial moduli d sigma_xx / d eps_xx of the material at the initial
  !> state, through the UMAT: `elastic` from a compressive increment
  !> (unloading), `plastic` from the second of two extension increments
  !> (the first reaches the cone), each over a long DTIME (1000 s) so that
  !> a rate-dependent model answers with its quasi-static (stiffest) limit.
  !> Increments of 1e-5 strain. Pa.
  subroutine probe_moduli(cfg, props, elastic, plastic, err, vumat)
    type(bar_config_t), intent(in) :: cfg
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
  !> holding the two nodes (collective). No given velocity.
  subroutine bar_traction(self, sc, given)
    class(bar_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(inout) :: given(:)
    integer :: psurf, is
    real(dp) :: sig_b, xs, w, surf(4)
    associate (g => sc%grid, pt => sc%parts, load => self%load)
      psurf = findloc(pt%gid(1:pt%n), 1, 1)
      surf = 0.0_dp
      load%mine = psurf > 0
      if (load%mine) then
        sig_b = surface_stress(self%cfg, sc%t)
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
      call sc%exchange%sum_reals(surf)
      load%is = nint(surf(1))
      load%w = surf(2)
      load%fs = surf(3:4)
      is = load%is
      if (is >= g%glo .and. is <= g%ghi) g%fext(1, is) = g%fext(1, is) + load%fs(1)
      if (is + 1 >= g%glo .and. is + 1 <= g%ghi) g%fext(1, is + 1) = g%fext(1, is + 1) + &
                                                                      load%fs(2)
    end associate
  end subroutine bar_traction

  !> After the grid update: the mass matrix's acceleration (&time mass not
  !> lumped; on many ranks the whole bar's system, collective), then the
  !> step's impulse: the reaction at the fixed far end and the surface
  !> force on the surface particle's rank.
  subroutine bar_grid_solved(self, sc, reaction, err)
    class(bar_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: reaction(:)
    type(error_t), allocatable, intent(out) :: err
    if (self%cfg%mass /= mass_lumped) then
      call mass_matrix_update(self%cfg%mass, sc%grid, sc%parts, sc%parts%n, sc%nnz, sc%dt, &
                              sc%mass_floor, err, sc%exchange)
      if (allocated(err)) return
    end if
    if (self%load%mine) then
      self%book%impulse = self%book%impulse + sc%dt*(self%load%fs(1) + self%load%fs(2) + &
                                                     reaction(1))
    else
      self%book%impulse = self%book%impulse + sc%dt*reaction(1)
    end if
  end subroutine bar_grid_solved

  !> The bar's kinematics in one pass over plain arrays (uniaxial_strain),
  !> F of the start kept first when a user's UMAT reads DFGRD0.
  integer function bar_kinematics(self, sc) result(last)
    class(bar_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer :: p, n
    associate (pt => sc%parts)
      n = pt%n
      if (allocated(sc%f_n)) then
        do p = 1, n
          sc%f_n(1, 1, p) = pt%defgrad(1, 1, p)
        end do
      end if
      last = uniaxial_strain(n, sc%dt, sc%lgrad, size(sc%de, 1), sc%de, pt%defgrad, pt%vol0, &
                             pt%vol, sc%vol_n, size(pt%stress, 1), pt%stress, size(sc%s0, 1), &
                             sc%s0)
    end associate
  end function bar_kinematics

  !> The step's work: internal, int sigma d eps dV with sigma the mean of
  !> the start's and the end's sigma_11 less the viscous pressure's; and
  !> external, the surface force times the surface velocity of the strain
  !> (by the surface particle's rank, which holds both nodes when w < 1).
  subroutine bar_bookkeeping(self, sc)
    class(bar_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer :: p
    real(dp) :: vsurf
    associate (b => self%book, load => self%load)
      if (load%mine) then
        vsurf = load%w*sc%grid%velocity(1, load%is + 1)
        if (load%w < 1.0_dp) vsurf = (1.0_dp - load%w)*sc%grid%velocity(1, load%is) + vsurf
        b%work_external = b%work_external + sc%dt*(load%fs(1) + load%fs(2))*vsurf
      end if
      do p = 1, sc%parts%n
        b%work_internal = b%work_internal + &
          sc%vol_n(p)*0.5_dp*(sc%s0(1, p) + sc%parts%stress(1, p))*sc%de(1, p)
        if (sc%q(p) /= 0.0_dp) b%work_internal = b%work_internal - &
          sc%vol_n(p)*sc%q(p)*sc%de(1, p)
      end do
    end associate
  end subroutine bar_bookkeeping

  !> This rank's work and impulse (a checkpoint's partial sums).
  function bar_partial_sums(self) result(v)
    class(bar_kind_t), intent(in) :: self
    real(dp), allocatable :: v(:)
    v = [self%book%work_internal, self%book%work_external, self%book%impulse]
  end function bar_partial_sums

  subroutine bar_set_partial_sums(self, v)
    class(bar_kind_t), intent(inout) :: self
    real(dp), intent(in) :: v(:)
    self%book%work_internal = v(1)
    self%book%work_external = v(2)
    self%book%impulse = v(3)
  end subroutine bar_set_partial_sums

  !> The start's kinetic energy and momentum (a checkpoint's scalars).
  function bar_scalars(self) result(v)
    class(bar_kind_t), intent(in) :: self
    real(dp), allocatable :: v(:)
    v = [self%book%kinetic0, self%book%momentum0]
  end function bar_scalars

  subroutine bar_set_scalars(self, v)
    class(bar_kind_t), intent(inout) :: self
    real(dp), intent(in) :: v(:)
    self%book%kinetic0 = v(1)
    self%book%momentum0 = v(2)
  end subroutine bar_set_scalars

  !> The bookkeeping of the bar scene sc (zero for another kind).
  function bar_book(sc) result(b)
    type(mpm_scene_t), intent(in) :: sc
    type(bar_book_t) :: b
    select type (k => sc%kind)
    type is (bar_kind_t)
      b = k%book
    end select
  end function bar_book

  !> The axial loading modulus probed for the bar scene sc (Pa; zero for
  !> another kind).
  real(dp) function bar_modulus_plastic(sc) result(m)
    type(mpm_scene_t), intent(in) :: sc
    m = 0.0_dp
    select type (k => sc%kind)
    type is (bar_kind_t)
      m = k%modulus_plastic
    end select
  end function bar_modulus_plastic

  !> bar_kinematics over a step dt, particles 1 .. n in order, on plain
  !> arrays: uniaxial strain de = (L_11 dt, 0, 0, 0, 0, 0) (eq. 4.11;
  !> NTENS = nd = 6),
  !> F_11 (1 + d eps), V = F_11 V_0 with vol_n the volume of the start, and
  !> s11_0 the start's sigma_11 (the bar's work). Returns the first particle
  !> turned inside out (V <= 0), updated and the last one touched, or n + 1.
  integer function uniaxial_strain(n, dt, l11, nd, de, defgrad, vol0, vol, vol_n, ns, stress, &
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
  end function uniaxial_strain

end module wellposed_mpm_bar_kind
