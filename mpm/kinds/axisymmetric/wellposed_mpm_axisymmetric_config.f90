!> The configuration of an axisymmetric scene (wellposed_mpm_axisymmetric_kind):
!> a hollow or solid cylinder r_inner <= r <= r_outer, 0 <= z <= height,
!> whose r-z section is laid out as a plate's (x = r - r_inner, y = z), with
!> pressures on its lateral surfaces, and the checks its deck's values must
!> pass before the scene is built, each error naming its deck key.
module wellposed_mpm_axisymmetric_config
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text
  use wellposed_umat_layout, only: prop_beta, prop_beta_p, prop_k0, prop_h, prop_k_lim, &
                                   prop_tau, prop_h_zeta
  use wellposed_mpm_plate_config, only: plate_config_t, check_plate_config, bc_velocity, &
                                        bc_plate_free
  implicit none
  private
  public :: axi_config_t, check_axi_config, closed_form_none, closed_form_lame, &
            closed_form_hill, closed_form_names, axi_max_stations

  !> The closed form a run compares its final state with: none, Lame's
  !> thick-walled cylinder in plane strain (elastic), or Hill's (elastic-
  !> perfectly-plastic von Mises; docs/guide/axisymmetric.md, "Closed forms").
  !> Most stations of a cylinder's deck.
  integer, parameter :: axi_max_stations = 16
  integer, parameter :: closed_form_none = 1, closed_form_lame = 2, closed_form_hill = 3
  character(len=8), parameter :: closed_form_names(3) = [character(len=8) :: 'none', 'lame', &
                                                         'hill']

  !> One axisymmetric scene. `section` holds the r-z section as a plate
  !> (width = r_outer - r_inner, height, grid, materials, ends); the
  !> pressures (Pa, compression positive) act on r = r_inner and r =
  !> r_outer, brought on over pressure_ramp seconds by a half-cosine, on
  !> top of `confining`: the specimen's isotropic start, sigma = -confining
  !> I, with that pressure on its lateral surfaces from t = 0 (a triaxial
  !> cell's). The &output settings: snapshots, curve samples (s), lines.
  type :: axi_config_t
    type(plate_config_t) :: section
    real(dp) :: r_inner = 1.0_dp                    !< m (0: a solid cylinder)
    real(dp) :: p_inner = 0.0_dp, p_outer = 0.0_dp  !< Pa
    real(dp) :: pressure_ramp = 0.0_dp              !< s (0: at once)
    real(dp) :: confining = 0.0_dp                  !< Pa
    integer :: closed_form = closed_form_none
    real(dp) :: snapshot_dt = 0.0_dp, sample_dt = 0.0_dp
    logical :: progress = .true., plot = .true.
    !> a material that gives out ends the run at the last complete step
    logical :: stop_on_cutback = .false.
    !> &stations: the points (r, z; m) whose particle's history is sampled
    integer :: nstations = 0
    real(dp) :: station_r(axi_max_stations) = 0.0_dp, station_z(axi_max_stations) = 0.0_dp
  end type axi_config_t

contains

  !> Checks on the deck values an axisymmetric scene needs (the section's
  !> as a plate's first).
  subroutine check_axi_config(cfg, err)
    type(axi_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: cells(2)
    associate (s => cfg%section)
      if (s%dx > 0.0_dp .and. ieee_is_finite(s%dx)) then
        cells = [s%width, s%height]/s%dx
        if (any(abs(cells - nint(cells)) > 1.0e-9_dp*cells) .or. any(nint(cells) < 2)) then
          call bad('r_outer', '- r_inner and height must be whole numbers (>= 2) of cells '// &
                   '&grid dx'); return
        end if
      end if
    end associate
    call check_plate_config(cfg%section, err)
    if (allocated(err)) return
    if (.not. (cfg%r_inner >= 0.0_dp .and. ieee_is_finite(cfg%r_inner))) then
      call bad('r_inner', 'must be a finite radius >= 0 m (0: a solid cylinder)'); return
    end if
    if (.not. (ieee_is_finite(cfg%p_inner) .and. ieee_is_finite(cfg%p_outer))) then
      call bad('p_inner', 'and p_outer must be finite pressures (Pa)'); return
    end if
    if (cfg%r_inner == 0.0_dp .and. cfg%p_inner /= 0.0_dp) then
      call bad('p_inner', 'needs a hole: a solid cylinder (r_inner = 0) has no inner surface')
      return
    end if
    if (.not. (cfg%pressure_ramp >= 0.0_dp .and. ieee_is_finite(cfg%pressure_ramp))) then
      call bad('pressure_ramp', 'must be a finite time >= 0 s'); return
    end if
    if (.not. (cfg%confining >= 0.0_dp .and. ieee_is_finite(cfg%confining))) then
      call bad('confining', 'must be a finite pressure >= 0 Pa'); return
    end if
    if (cfg%confining > 0.0_dp .and. .not. (cfg%section%top == bc_velocity .and. &
                                            cfg%section%bottom /= bc_plate_free)) then
      call bad('confining', "needs both ends held (&boundary top = 'velocity', bottom "// &
               "'roller' or 'fixed'): they carry sigma_zz = -confining from the start"); return
    end if
    if (cfg%closed_form == closed_form_hill) call check_hill(cfg, err)
  contains
    subroutine bad(key, what)
      character(len=*), intent(in) :: key, what
      call new_error(err, status_invalid, 'cylinder%'//key, '&cylinder '//key//' '//what)
    end subroutine bad
  end subroutine check_axi_config

  !> Hill's cylinder needs what its closed form assumes: a hollow cylinder
  !> of one material, ours, von Mises (beta = beta_p = 0) and perfectly
  !> plastic (no hardening, exponential limit, viscosity or nonlocal
  !> hardening), a bore pressure between first yield k (1 - a^2/b^2) and
  !> collapse 2k ln(b/a), nothing outside, no confinement.
  subroutine check_hill(cfg, err)
    type(axi_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: pr(max(cfg%section%materials%nprops(1), prop_h_zeta)), k, a, b
    associate (m => cfg%section%materials)
      if (m%n /= 1 .or. .not. m%ours(1)) then
        call bad('needs one &material of wellposed''s own UMAT (its PROPS give k)'); return
      end if
      pr = 0.0_dp
      pr(1:m%nprops(1)) = m%props(1:m%nprops(1), 1)
    end associate
    if (any(pr([prop_beta, prop_beta_p, prop_h, prop_k_lim, prop_tau, prop_h_zeta]) /= 0.0_dp)) &
      then
      call bad('is von Mises perfectly plastic: the &material needs beta = beta_p = h = k_lim '// &
               '= tau = h_zeta = 0'); return
    end if
    k = pr(prop_k0)
    a = cfg%r_inner
    b = cfg%r_inner + cfg%section%width
    if (a == 0.0_dp .or. cfg%p_outer /= 0.0_dp .or. cfg%confining /= 0.0_dp) then
      call bad('is a hollow cylinder (r_inner > 0) under bore pressure alone (p_outer = '// &
               'confining = 0)'); return
    end if
    if (.not. (cfg%p_inner > k*(1.0_dp - a**2/b**2) .and. cfg%p_inner < 2.0_dp*k*log(b/a))) then
      call bad('needs p_inner between first yield k (1 - a^2/b^2) = '// &
               real_text(k*(1.0_dp - a**2/b**2))//' Pa and collapse 2k ln(b/a) = '// &
               real_text(2.0_dp*k*log(b/a))//' Pa (k = k0)'); return
    end if
  contains
    subroutine bad(what)
      character(len=*), intent(in) :: what
      call new_error(err, status_invalid, 'cylinder%closed_form', "&cylinder closed_form = "// &
                     "'hill' "//what)
    end subroutine bad
  end subroutine check_hill

end module wellposed_mpm_axisymmetric_config
