!> Surface load history of the case study (seed section 2.3, fig. 2.1): the
!> axial stress prescribed at the free surface, sigma_b(t) = base + peak *
!> g((t - start)/duration), with g the triangle (rise over the first half,
!> fall over the second; shared reference A) or a raised cosine
!> g(s) = (1 - cos(2 pi s))/2 (smooth, for convergence studies). g = 0
!> outside 0 < s < 1. Units: Pa, s.
module wellposed_mpm_loads
  use wellposed_kinds, only: dp
  use wellposed_mpm_config, only: mpm_config_t, pulse_triangle, pulse_cosine
  implicit none
  private
  public :: surface_stress, pulse_shape

  real(dp), parameter :: pi = 3.14159265358979323846_dp

contains

  !> Axial stress sigma_xx prescribed at the surface at time t (Pa).
  pure real(dp) function surface_stress(cfg, t)
    type(mpm_config_t), intent(in) :: cfg
    real(dp), intent(in) :: t
    surface_stress = cfg%load_base
    if (cfg%load_duration > 0.0_dp) surface_stress = surface_stress + &
      cfg%load_peak*pulse_shape(cfg%pulse, (t - cfg%load_start)/cfg%load_duration)
  end function surface_stress

  !> Dimensionless pulse shape g(s), peak 1 at s = 1/2.
  elemental real(dp) function pulse_shape(kind, s)
    integer, intent(in) :: kind
    real(dp), intent(in) :: s
    pulse_shape = 0.0_dp
    if (s <= 0.0_dp .or. s >= 1.0_dp) return
    select case (kind)
    case (pulse_cosine)
      pulse_shape = 0.5_dp*(1.0_dp - cos(2.0_dp*pi*s))
    case (pulse_triangle)
      pulse_shape = 1.0_dp - abs(2.0_dp*s - 1.0_dp)
    end select
  end function pulse_shape

end module wellposed_mpm_loads
