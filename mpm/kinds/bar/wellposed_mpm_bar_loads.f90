!> Surface load history of the case study (section 2.3, fig. 2.1), Pa:
!> sigma_b(t) = base + peak g((t - start)/duration), g the triangle (shared
!> reference A) or the raised cosine (1 - cos(2 pi s))/2, 0 outside
!> 0 < s < 1; or a ramp with a sinusoid (fig. 2.10 left), base + rate s +
!> amplitude sin(2 pi f s), s = t - start, where |amplitude| 2 pi f < |rate|
!> keeps the surface loading so the sinusoid travels at the plastic
!> (dispersive) wave speed at f.
module wellposed_mpm_bar_loads
  use wellposed_kinds, only: dp
  use wellposed_mpm_bar_config, only: bar_config_t, pulse_triangle, pulse_cosine, pulse_ramp_sine
  implicit none
  private
  public :: surface_stress, pulse_shape, ramp_sine

  real(dp), parameter :: pi = 3.14159265358979323846_dp

contains

  !> Axial stress sigma_xx prescribed at the surface at time t (Pa).
  pure real(dp) function surface_stress(cfg, t)
    type(bar_config_t), intent(in) :: cfg
    real(dp), intent(in) :: t
    surface_stress = cfg%load_base
    if (cfg%pulse == pulse_ramp_sine) then
      surface_stress = surface_stress + ramp_sine(cfg%load_rate, cfg%load_amplitude, &
                                                  cfg%load_frequency, t - cfg%load_start)
    else if (cfg%load_duration > 0.0_dp) then
      surface_stress = surface_stress + &
        cfg%load_peak*pulse_shape(cfg%pulse, (t - cfg%load_start)/cfg%load_duration)
    end if
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

  !> Increment of the ramp-and-sinusoid load at time s after its start (Pa):
  !> rate s + amplitude sin(2 pi frequency s) for s > 0, else 0.
  !> rate in Pa/s, amplitude in Pa, frequency in Hz.
  elemental real(dp) function ramp_sine(rate, amplitude, frequency, s)
    real(dp), intent(in) :: rate, amplitude, frequency, s
    ramp_sine = 0.0_dp
    if (s <= 0.0_dp) return
    ramp_sine = rate*s + amplitude*sin(2.0_dp*pi*frequency*s)
  end function ramp_sine

end module wellposed_mpm_bar_loads
