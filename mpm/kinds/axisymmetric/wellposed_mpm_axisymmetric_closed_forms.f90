!> The closed forms an axisymmetric run compares its final state with
!> (&cylinder closed_form): Lame's elastic thick-walled cylinder in plane
!> strain, and Hill's elastic-perfectly-plastic one (von Mises, plane
!> strain, incompressible), as an output of the run loop; the moduli
!> probed through the UMAT, the yield stress from our PROPS. Equations and
!> keys: docs/guide/axisymmetric.md, "Closed forms".
module wellposed_mpm_axisymmetric_closed_forms
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, allreduce_max
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_umat_layout, only: prop_k0
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_scene_sums, only: plastic_strain
  use wellposed_mpm_output, only: mpm_output_t
  use wellposed_mpm_axisymmetric_config, only: axi_config_t, closed_form_none, &
                                               closed_form_lame, closed_form_hill
  use wellposed_mpm_axisymmetric_kind, only: axi_kind_t, pressure_factor
  implicit none
  private
  public :: axi_closed_form_t, lame_stress, hill_stress, hill_radius

  !> The final state against the deck's closed form: relative L2 errors
  !> (volume weighted) of the normal stresses together and of the hoop
  !> stress; Lame: the outermost column's radial displacement; Hill: the
  !> plastic radius, exact and the MPM's (the outermost yielded particle).
  type, extends(mpm_output_t) :: axi_closed_form_t
    integer :: form = closed_form_none
    real(dp) :: young = 0.0_dp, poisson = 0.0_dp, k_yield = 0.0_dp
    real(dp) :: err_stress = 0.0_dp, err_hoop = 0.0_dp, err_u_outer = 0.0_dp
    real(dp) :: c_exact = 0.0_dp, c_mpm = 0.0_dp
  contains
    procedure :: finish => closed_finish
    procedure :: summarise => closed_summarise
    procedure :: put => closed_put
    procedure :: get => closed_get
  end type axi_closed_form_t

contains

  !> Lame's plane-strain stresses (sigma_rr, sigma_tt, sigma_zz; tension +)
  !> and radial displacement at radius r of the cylinder a <= r <= b under
  !> pressures pa, pb (compression +): sigma = A -+ B/r^2, A = (pa a^2 -
  !> pb b^2)/(b^2 - a^2), B = (pa - pb) a^2 b^2/(b^2 - a^2), sigma_zz = 2 nu A,
  !> u = (1 + nu)/E ((1 - 2 nu) A r + B/r).
  pure subroutine lame_stress(a, b, pa, pb, young, nu, r, s, u)
    real(dp), intent(in) :: a, b, pa, pb, young, nu, r
    real(dp), intent(out) :: s(3), u
    real(dp) :: ca, cb
    ca = (pa*a**2 - pb*b**2)/(b**2 - a**2)
    cb = (pa - pb)*a**2*b**2/(b**2 - a**2)
    s = [ca - cb/r**2, ca + cb/r**2, 2.0_dp*nu*ca]
    u = (1.0_dp + nu)/young*((1.0_dp - 2.0_dp*nu)*ca*r + cb/r)
  end subroutine lame_stress

  !> Hill's cylinder a <= r <= b, plastic out to c, shear yield stress k
  !> (von Mises: sqrt(J2) = k, i.e. sigma_tt - sigma_rr = 2k in plane
  !> strain), tension +: for r < c sigma_rr = -p + 2k ln(r/a), sigma_tt =
  !> sigma_rr + 2k; for r >= c sigma_rr = -k c^2 (1/r^2 - 1/b^2), sigma_tt =
  !> k c^2 (1/r^2 + 1/b^2); sigma_zz = (sigma_rr + sigma_tt)/2 (incompressible).
  pure function hill_stress(a, b, k, c, r) result(s)
    real(dp), intent(in) :: a, b, k, c, r
    real(dp) :: s(3), p
    p = k*(2.0_dp*log(c/a) + 1.0_dp - c**2/b**2)
    if (r < c) then
      s(1) = -p + 2.0_dp*k*log(r/a)
      s(2) = s(1) + 2.0_dp*k
    else
      s(1) = -k*c**2*(1.0_dp/r**2 - 1.0_dp/b**2)
      s(2) = k*c**2*(1.0_dp/r**2 + 1.0_dp/b**2)
    end if
    s(3) = 0.5_dp*(s(1) + s(2))
  end function hill_stress

  !> The plastic radius c of Hill's cylinder under bore pressure p: the root
  !> of p = k (2 ln(c/a) + 1 - c^2/b^2) in [a, b] (increasing in c), by
  !> bisection; a for p at or below first yield, b at or above collapse.
  pure real(dp) function hill_radius(a, b, k, p) result(c)
    real(dp), intent(in) :: a, b, k, p
    real(dp) :: lo, hi
    integer :: i
    lo = a
    hi = b
    do i = 1, 200
      c = 0.5_dp*(lo + hi)
      if (k*(2.0_dp*log(c/a) + 1.0_dp - c**2/b**2) < p) then
        lo = c
      else
        hi = c
      end if
    end do
    c = 0.5_dp*(lo + hi)
  end function hill_radius

  !> The comparison (collective): E and nu from the probed moduli (M = K +
  !> 4G/3 and K), the pressures at the final time beyond the confined
  !> start, every particle at its current radius. Lame: u of the outermost
  !> column at its initial radius; Hill: sigma_rr and sigma_tt only (the
  !> material's nu < 1/2 moves sigma_zz off the incompressible mean).
  subroutine closed_finish(self, sc, comm, err)
    class(axi_closed_form_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    type(axi_config_t) :: c
    real(dp) :: kb, g, f, a, b, s(3), u, sums(7), r, d(3), pa, pb, cm
    real(dp), allocatable :: ep(:)
    integer :: p, nd
    if (self%form == closed_form_none) return
    select type (kind => sc%kind)
    class is (axi_kind_t)
      c = kind%axi
      kb = kind%bulk
    class default
      return
    end select
    g = 0.75_dp*(sc%modulus_elastic - kb)
    self%young = 9.0_dp*kb*g/(3.0_dp*kb + g)
    self%poisson = (3.0_dp*kb - 2.0_dp*g)/(2.0_dp*(3.0_dp*kb + g))
    f = pressure_factor(c%pressure_ramp, sc%t)
    pa = f*c%p_inner
    pb = f*c%p_outer
    a = c%r_inner
    b = c%r_inner + c%section%width
    nd = 3
    if (self%form == closed_form_hill) then
      self%k_yield = sc%mats%props(prop_k0, 1)
      self%c_exact = hill_radius(a, b, self%k_yield, pa)
      nd = 2
    end if
    sums = 0.0_dp
    cm = a
    ep = plastic_strain(sc)
    associate (pt => sc%parts)
      do p = 1, pt%n
        r = pt%x(1, p) + a
        if (self%form == closed_form_hill) then
          s = hill_stress(a, b, self%k_yield, self%c_exact, r)
          if (ep(p) > 0.0_dp) cm = max(cm, pt%x0(1, p) + a)
        else
          ! the confined start, -confining I, plus Lame's state of the pressures beyond it
          call lame_stress(a, b, pa, pb, self%young, self%poisson, r, s, u)
          s = s - c%confining
        end if
        d = [pt%stress(1, p), pt%stress(3, p), pt%stress(2, p)] - s
        sums(1:4) = sums(1:4) + pt%vol(p)*[sum(d(1:nd)**2), sum(s(1:nd)**2), d(2)**2, s(2)**2]
        if (self%form == closed_form_lame .and. &
            pt%x0(1, p) > c%section%width - c%section%dx/c%section%ppc) then
          call lame_stress(a, b, pa, pb, self%young, self%poisson, pt%x0(1, p) + a, s, u)
          sums(5:7) = sums(5:7) + [pt%x(1, p) - pt%x0(1, p), u, 1.0_dp]
        end if
      end do
    end associate
    call sc%exchange%sum_reals(sums)
    if (comm%size > 1) call allreduce_max(comm, cm)
    self%c_mpm = cm
    self%err_stress = sqrt(sums(1)/max(sums(2), tiny(1.0_dp)))
    self%err_hoop = sqrt(sums(3)/max(sums(4), tiny(1.0_dp)))
    self%err_u_outer = abs(sums(5) - sums(6))/max(abs(sums(6)), tiny(1.0_dp))
  end subroutine closed_finish

  subroutine closed_summarise(self, sm)
    class(axi_closed_form_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    select case (self%form)
    case (closed_form_lame)
      call sm%add('lame_young', self%young, 'Pa, from the moduli probed through the UMAT')
      call sm%add('lame_poisson', self%poisson)
      call sm%add('lame_stress_error', self%err_stress, 'relative L2 (volume weighted) of '// &
                  'sigma_rr, sigma_tt, sigma_zz against Lame at the final time')
      call sm%add('lame_hoop_error', self%err_hoop, 'relative L2 of sigma_tt')
      call sm%add('lame_u_outer_error', self%err_u_outer, 'relative, the outermost '// &
                  'column''s mean radial displacement')
    case (closed_form_hill)
      call sm%add('hill_poisson', self%poisson, 'of the material (Hill''s is 1/2)')
      call sm%add('hill_yield_k', self%k_yield, 'Pa, the shear yield stress (PROPS(5) k0)')
      call sm%add('hill_plastic_radius', self%c_exact, 'm, exact at the final pressure')
      call sm%add('hill_plastic_radius_mpm', self%c_mpm, 'm, the initial radius of the '// &
                  'outermost particle that yielded')
      call sm%add('hill_stress_error', self%err_stress, 'relative L2 (volume weighted) of '// &
                  'sigma_rr, sigma_tt against Hill at the final time')
      call sm%add('hill_hoop_error', self%err_hoop, 'relative L2 of sigma_tt')
    end select
  end subroutine closed_summarise

  !> Nothing to keep: the comparison is made after the last step.
  subroutine closed_put(self, ck, comm)
    class(axi_closed_form_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
  end subroutine closed_put

  subroutine closed_get(self, ck, comm, err)
    class(axi_closed_form_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
  end subroutine closed_get

end module wellposed_mpm_axisymmetric_closed_forms
