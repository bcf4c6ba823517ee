!> The configuration of a plane-strain plate scene (wellposed_mpm_plate_build;
!> chapter 4's fig. 4.1 by default) and the checks a deck's values must
!> pass before the scene is built, each error naming its deck key.
module wellposed_mpm_plate_config
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_materials, only: mpm_materials_t
  use wellposed_mpm_method, only: scheme_musl
  use wellposed_mpm_shape_2d, only: shape2d_cpdi
  use wellposed_mpm_nonlocal, only: nonlocal_settings_t
  implicit none
  private
  public :: plate_config_t, check_plate_config, bc_roller, bc_plate_fixed, bc_plate_free, &
            bc_velocity, plate_bc_names
  public :: platen_surface, platen_grid, platen_contact, platen_names

  !> Boundary kinds in 2D.
  integer, parameter :: bc_roller = 1, bc_plate_fixed = 2, bc_plate_free = 3, bc_velocity = 4
  character(len=8), parameter :: plate_bc_names(4) = [character(len=8) :: 'roller', 'fixed', &
                                                      'free', 'velocity']
  integer, parameter :: max_props2 = 40
  !> Where the platen acts (docs/research/bands.md, "The platen"): 'surface', on the
  !> nodes at and above the highest node row at or below the body's current
  !> top; 'grid', on the fixed node row y = height and above; 'contact', a
  !> frictionless rigid plane pressing on the particles (no node condition).
  integer, parameter :: platen_surface = 1, platen_grid = 2, platen_contact = 3
  character(len=8), parameter :: platen_names(3) = [character(len=8) :: 'surface', 'grid', &
                                                    'contact']

  !> One plane-strain scene (defaults: the 4 m x 5 m plate of fig. 4.1 with
  !> the local softening material of section 4.7.1, h = 0.5 m).
  type :: plate_config_t
    character(len=:), allocatable :: name, title
    real(dp) :: width = 4.0_dp, height = 5.0_dp   !< m
    real(dp) :: dx = 0.5_dp                        !< cell size h (m)
    integer :: ppc = 2                             !< particles per cell per direction
    integer :: pad_cells = 2
    integer :: shape = shape2d_cpdi
    real(dp) :: t_end = 0.02_dp, cfl = 0.2_dp      !< s, fraction of the CFL step
    integer :: scheme = scheme_musl                !< USL, MUSL, implicit (wellposed_mpm_method)
    real(dp) :: implicit_dt = 0.0_dp               !< the implicit scheme's largest step (s)
    integer :: linear_solver = 1                   !< its solver (wellposed_mpm_linear_solver)
    real(dp) :: density = 1000.0_dp                !< kg/m^3
    integer :: nprops = 14
    real(dp) :: props(max_props2) = 0.0_dp
    integer :: nstatv = 12
    !> materials by region (none: one material of props, nstatv)
    type(mpm_materials_t) :: materials
    ! boundaries
    integer :: bottom = bc_roller, top = bc_velocity, sides = bc_plate_free
    real(dp) :: top_velocity = -7.5_dp             !< v_y of the top (m/s, < 0 compresses)
    real(dp) :: ramp_time = 0.0_dp                 !< s, linear ramp of the top velocity
    logical :: top_lateral_fixed = .true.          !< v_x = 0 on the top too (the dissertation's)
    integer :: platen = platen_surface             !< platen_surface or platen_grid
    ! initial state
    real(dp) :: velocity_gradient0(2, 2) = 0.0_dp  !< initial v = L0 x (patch test), 1/s
    ! artificial viscosity
    real(dp) :: visc_a1 = 0.4_dp, visc_a2 = 4.0_dp
    type(nonlocal_settings_t) :: nonlocal
  end type plate_config_t

contains

  !> Checks on the deck values a scene needs.
  subroutine check_plate_config(cfg, err)
    type(plate_config_t), intent(in) :: cfg
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
    if (cfg%nstatv < 1) then   ! our UMAT's 12: the material's check
      call bad('material', 'nstatv', 'must be >= 1'); return
    end if
    if (cfg%visc_a1 < 0.0_dp .or. cfg%visc_a2 < 0.0_dp) then
      call bad('viscosity', 'a1', 'A1 and A2 must be >= 0 (0 switches a term off)'); return
    end if
    if (cfg%ramp_time < 0.0_dp) then
      call bad('boundary', 'ramp_time', 'must be >= 0 s'); return
    end if
    if (cfg%top == bc_velocity .and. cfg%platen == platen_contact .and. &
        cfg%top_lateral_fixed) then
      call bad('boundary', 'platen', "= 'contact' is frictionless (it pushes normal to the "// &
        "top only) and cannot hold the top laterally: set top_lateral = 'free', or use "// &
        "platen = 'surface' for a clamped top"); return
    end if
  contains
    subroutine bad(group, key, what)
      character(len=*), intent(in) :: group, key, what
      call new_error(err, status_invalid, group//'%'//key, '&'//group//' '//key//' '//what)
    end subroutine bad
  end subroutine check_plate_config

end module wellposed_mpm_plate_config
