!> The axisymmetric scene kind (r-z): a cylinder's section laid out as the
!> plate's (x = r - r_inner, y = z; wellposed_mpm_plate_kind) with what the
!> revolution adds, per radian: particle volume and mass times r, the hoop
!> strain from the radial motion (NTENS 4: 11, 22, 33, 12 = rr, zz, hoop,
!> rz), the hoop stress's nodal force, v_r = 0 on the axis, pressures on
!> the lateral surfaces. Equations: docs/guide/axisymmetric.md.
module wellposed_mpm_axisymmetric_kind
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_shape_2d, only: shape_2d, shape2d_linear
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t
  use wellposed_mpm_plate_kind, only: plate_kind_t
  use wellposed_mpm_plate_build, only: new_plate_scene
  use wellposed_mpm_axisymmetric_config, only: axi_config_t, check_axi_config
  implicit none
  private
  public :: axi_kind_t, new_axi_scene, pressure_factor

  real(dp), parameter :: pi = acos(-1.0_dp)

  !> An axisymmetric scene: the plate's section and platen, and the
  !> cylinder's radii and pressures.
  type, extends(plate_kind_t) :: axi_kind_t
    type(axi_config_t) :: axi
  contains
    procedure :: forces => axi_forces
    procedure :: conditions => axi_conditions
    procedure :: kinematics => axi_kinematics
    procedure :: radius => axi_radius
  end type axi_kind_t

contains

  !> Build the cylinder of cfg: its section as a plate (grid, particles,
  !> materials, time step, ends), then the axisymmetric kind in its place
  !> and every particle's volume and mass per radian, V = A r, m = rho A r
  !> (r = x + r_inner at its start), its stress -confining I. Collective
  !> with `exchange`.
  subroutine new_axi_scene(self, cfg, err, exchange)
    type(mpm_scene_t), intent(out) :: self
    type(axi_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    type(axi_kind_t) :: axi
    real(dp) :: r0
    integer :: p
    call check_axi_config(cfg, err)
    if (allocated(err)) return
    call new_plate_scene(self, cfg%section, err, exchange)
    if (allocated(err)) return
    select type (k => self%kind)
    type is (plate_kind_t)
      axi%plate_kind_t = k
    end select
    axi%axi = cfg
    deallocate (self%kind)
    allocate (self%kind, source=axi)
    associate (pt => self%parts)
      do p = 1, pt%n
        r0 = pt%x0(1, p) + cfg%r_inner
        pt%vol0(p) = pt%vol0(p)*r0
        pt%vol(p) = pt%vol(p)*r0
        pt%mass(p) = pt%mass(p)*r0
        pt%stress(1:3, p) = -cfg%confining
      end do
    end associate
    ! the smallest particle's radius: the innermost column's centre
    self%mass_floor = self%mass_floor*(cfg%r_inner + 0.5_dp*cfg%section%dx/cfg%section%ppc)
  end subroutine new_axi_scene

  !> The pressures' factor at time t (a half-cosine from 0 to 1 over
  !> `ramp`: no jump in the load's rate at either end, little ringing).
  pure real(dp) function pressure_factor(ramp, t) result(f)
    real(dp), intent(in) :: ramp, t
    f = 1.0_dp
    if (ramp > 0.0_dp) f = 0.5_dp*(1.0_dp - cos(pi*min(1.0_dp, max(t, 0.0_dp)/ramp)))
  end function pressure_factor

  !> The plate's forces (the contact platen), then, of this rank's
  !> particles: the hoop stress's force on node i, f_r -= V (sigma_tt - q)
  !> phi_i / r (the weak form's sigma_tt w_r / r term; docs/guide/axisymmetric.md), and the
  !> lateral pressures (confining + the ramped p_inner, p_outer) on the
  !> edges of the innermost and outermost columns.
  subroutine axi_forces(self, sc)
    class(axi_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer :: p, k, mk, i
    real(dp) :: r, s, f, spacing, pin, pout
    call self%plate_kind_t%forces(sc)
    associate (pt => sc%parts, g => sc%grid)
      do p = 1, pt%n
        mk = pt%nsup
        if (allocated(sc%nnz)) mk = sc%nnz(p)
        r = pt%x(1, p) + self%axi%r_inner
        s = pt%vol(p)*(pt%stress(3, p) - sc%q(p))/r
        do k = 1, mk
          i = pt%node(k, p)
          g%fint(1, i) = g%fint(1, i) - pt%phi(k, p)*s
        end do
      end do
      f = pressure_factor(self%axi%pressure_ramp, sc%t + sc%dt)
      pin = merge(self%axi%confining + f*self%axi%p_inner, 0.0_dp, self%axi%r_inner > 0.0_dp)
      pout = self%axi%confining + f*self%axi%p_outer
      if (pin == 0.0_dp .and. pout == 0.0_dp) return
      spacing = self%cfg%dx/self%cfg%ppc
      do p = 1, pt%n
        if (pt%x0(1, p) < spacing .and. pin /= 0.0_dp) call edge_pressure(self, sc, p, -1, pin)
        if (pt%x0(1, p) > self%cfg%width - spacing) call edge_pressure(self, sc, p, 1, pout)
      end do
    end associate
  end subroutine axi_forces

  !> A pressure `pres` on particle p's edge facing side = +1 (outward, r
  !> grows) or -1 (inward): the edge x_p +- r1 +- r2 (r1 = lp_x F e_x, r2 =
  !> lp_y F e_y) takes the traction -pres n over its length times its
  !> radius, half at each end with the grid's bilinear weights.
  subroutine edge_pressure(self, sc, p, side, pres)
    class(axi_kind_t), intent(in) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer, intent(in) :: p, side
    real(dp), intent(in) :: pres
    real(dp) :: r1(2), r2(2), mid(2), nl(2), force(2), phi(4), grad(2, 4)
    integer :: e, k, nodes(4)
    associate (pt => sc%parts, g => sc%grid)
      r1 = pt%lp(1, p)*pt%defgrad(1:2, 1, p)
      r2 = pt%lp(2, p)*pt%defgrad(1:2, 2, p)
      mid = pt%x(:, p) + side*r1
      ! the edge's outward normal times its length, from its vector 2 r2
      nl = side*[2.0_dp*r2(2), -2.0_dp*r2(1)]
      force = -0.5_dp*pres*(mid(1) + self%axi%r_inner)*nl
      do e = -1, 1, 2
        call shape_2d(shape2d_linear, mid + e*r2, pt%lp(:, p), pt%defgrad(1:2, 1:2, p), &
                      sc%origin, sc%dx, sc%nx, nodes, phi, grad)
        do k = 1, 4
          if (nodes(k) >= g%glo .and. nodes(k) <= g%ghi) &
            g%fext(:, nodes(k)) = g%fext(:, nodes(k)) + phi(k)*force
        end do
      end do
    end associate
  end subroutine edge_pressure

  !> The plate's conditions (the ends, the platen), then v_r = 0 on the
  !> nodes on and past the axis of a solid cylinder.
  subroutine axi_conditions(self, sc, given)
    class(axi_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(inout) :: given(:)
    integer :: g, i
    call self%plate_kind_t%conditions(sc, given)
    if (self%axi%r_inner > 0.0_dp) return
    do g = sc%grid%glo, sc%grid%ghi
      i = mod(g, sc%nx)
      if (sc%origin(1) + sc%dx*i <= 1.0e-6_dp*sc%dx) then
        sc%grid%fixed(1, g) = .true.
        sc%grid%given(1, g) = .false.
      end if
    end do
  end subroutine axi_conditions

  !> The radius of the section's point x (x(1) = r - r_inner).
  pure real(dp) function axi_radius(self, x) result(r)
    class(axi_kind_t), intent(in) :: self
    real(dp), intent(in) :: x(:)
    r = x(1) + self%axi%r_inner
  end function axi_radius

  !> The plate's kinematics in the section, then the hoop part of each
  !> particle: the hoop stretch F_33 = r/r_0, the increment de_33 =
  !> 2 (r - r_n)/(r + r_n) (the rate v_r/r at the step's middle) and the
  !> volume V = det(F_rz) F_33 V_0. A particle on or past the axis stops it.
  integer function axi_kinematics(self, sc) result(last)
    class(axi_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    integer :: p
    real(dp) :: r0, rn, r
    last = self%plate_kind_t%kinematics(sc)
    associate (pt => sc%parts)
      do p = 1, last - 1
        r0 = pt%x0(1, p) + self%axi%r_inner
        rn = r0*pt%defgrad(3, 3, p)
        r = pt%x(1, p) + self%axi%r_inner
        if (.not. r > 0.0_dp) then
          last = p
          return
        end if
        sc%de(3, p) = 2.0_dp*(r - rn)/(r + rn)
        pt%defgrad(3, 3, p) = r/r0
        pt%vol(p) = pt%vol(p)*pt%defgrad(3, 3, p)
      end do
    end associate
  end function axi_kinematics

end module wellposed_mpm_axisymmetric_kind
