!> Everything that defines one MPM scene (section 4.3 and the 1D case
!> study of section 2.3), as plain data: the deck reader fills it, the unit
!> tests build it by hand, the solver only reads it. SI units throughout
!> (m, s, kg, Pa); stresses tension positive, Abaqus component order.
module wellposed_mpm_bar_config
  use wellposed_kinds, only: dp
  use wellposed_mpm_nonlocal, only: nonlocal_settings_t
  use wellposed_mpm_materials, only: mpm_materials_t
  ! the method's choices, here too for the bar's deck and runner
  use wellposed_mpm_method, only: shape_linear, shape_gimp, shape_names, scheme_usl, &
                                  scheme_musl, scheme_names, mass_lumped, mass_consistent, &
                                  mass_blended, mass_names
  implicit none
  private
  public :: bar_config_t, shape_linear, shape_gimp, shape_names, scheme_usl, scheme_musl, &
            scheme_names, bc_fixed, bc_symmetric, bc_free, bc_names, pulse_triangle, &
            pulse_cosine, pulse_ramp_sine, pulse_names, max_props, mass_lumped, &
            mass_consistent, mass_blended, mass_names, cfl_blended, cfl_dissertation

  !> Far-end conditions. In uniaxial strain a symmetry plane and a fixed end
  !> both hold v_x = 0; they are kept apart because 2D distinguishes them.
  integer, parameter :: bc_fixed = 1, bc_symmetric = 2, bc_free = 3
  character(len=9), parameter :: bc_names(3) = [character(len=9) :: 'fixed', 'symmetric', &
                                                 'free']
  !> Surface loads: the dissertation's triangle pulse (fig. 2.1), a raised-cosine
  !> pulse (smooth, for convergence studies against d'Alembert), and a
  !> monotonic ramp with a small superposed sinusoid (the dispersion
  !> measurement of fig. 2.10 left: every particle keeps loading).
  integer, parameter :: pulse_triangle = 1, pulse_cosine = 2, pulse_ramp_sine = 3
  character(len=9), parameter :: pulse_names(3) = [character(len=9) :: 'triangle', 'cosine', &
                                                    'ramp_sine']
  !> Most PROPS a deck may give (the wellposed contract has 14 slots).
  integer, parameter :: max_props = 40
  !> The default &time cfl: MUSL with the blended mass is most accurate at
  !> 0.5; other schemes and masses take the dissertation's 0.2, below the
  !> stability limit of each (docs/research/timestep.md).
  real(dp), parameter :: cfl_blended = 0.5_dp, cfl_dissertation = 0.2_dp

  !> One scene. Defaults are the Sandler-Rubin case (shared reference A).
  type :: bar_config_t
    character(len=:), allocatable :: name           !< scene name, output folder
    character(len=:), allocatable :: title          !< one line for plots
    ! geometry and grid (m)
    real(dp) :: length = 700.0_dp       !< body length, surface at x = 0
    real(dp) :: dx = 0.25_dp            !< cell size
    integer :: ppc = 2                  !< particles per cell
    integer :: pad_cells = 3            !< empty cells beyond each end of the body
    integer :: shape = shape_gimp
    integer :: scheme = scheme_musl
    real(dp) :: implicit_dt = 0.0_dp     !< the implicit scheme's largest step (s)
    integer :: linear_solver = 1         !< its solver (wellposed_mpm_linear_solver)
    !> the grid acceleration's mass matrix: blended, which converges where the
    !> dissertation's lumped mass grows a grid-scale wake (docs/research/timestep.md)
    integer :: mass = mass_blended
    integer :: bc_far = bc_fixed        !< condition at x = length
    ! time (s)
    real(dp) :: t_end = 0.3_dp
    real(dp) :: cfl = cfl_blended       !< dt = cfl * dx / c_max
    ! material
    real(dp) :: density = 2000.0_dp     !< kg/m^3
    integer :: nprops = 14
    real(dp) :: props(max_props) = 0.0_dp
    integer :: nstatv = 12
    real(dp) :: stress0(6) = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    real(dp) :: velocity0 = 0.0_dp      !< initial particle velocity (m/s)
    logical :: out_of_equilibrium = .false. !< stress0 need not balance the load at t = 0
    ! surface load: sigma_xx(surface) = base + peak * shape((t - start)/duration)
    real(dp) :: load_base = -100.0e6_dp !< Pa; equals stress0(1) for equilibrium
    real(dp) :: load_peak = 10.0e6_dp   !< Pa, tensile increment
    real(dp) :: load_duration = 2.0e-3_dp
    real(dp) :: load_start = 0.0_dp
    integer :: pulse = pulse_triangle
    ! pulse = ramp_sine: sigma_xx(surface) = base + rate*s + amplitude*sin(2 pi
    ! frequency s), s = t - start > 0 (peak and duration are not used)
    real(dp) :: load_rate = 0.0_dp      !< Pa/s, ramp rate (sign: loading direction)
    real(dp) :: load_amplitude = 0.0_dp !< Pa, sinusoid amplitude
    real(dp) :: load_frequency = 0.0_dp !< Hz, sinusoid frequency
    ! stations (Lagrangian positions, m) and sampling (s)
    real(dp) :: station_first = 100.0_dp
    real(dp) :: station_spacing = 100.0_dp
    integer :: nstations = 5
    real(dp) :: sample_dt = 2.0e-5_dp
    real(dp) :: snapshot_dt = 0.05_dp
    ! bulk artificial viscosity (wellposed_mpm_solver); 0: off, the default
    real(dp) :: visc_a1 = 0.0_dp, visc_a2 = 0.0_dp
    ! bookkeeping
    logical :: progress = .true.
    !> Algorithm 1 of the dissertation (eq. 4.46-4.50): scheme, tolerances; it
    !> iterates only when PROPS(12) h_zeta /= 0 (wellposed_mpm_nonlocal).
    type(nonlocal_settings_t) :: nonlocal
    !> materials by region (none: one material of props, nstatv)
    type(mpm_materials_t) :: materials
  end type bar_config_t

end module wellposed_mpm_bar_config
