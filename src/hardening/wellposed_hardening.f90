!> Isotropic hardening of the yield strength with the cumulative equivalent
!> plastic strain z = sum ||d eps^p||:
!>
!>   k(z) = k_exp(z) + h z,   k_exp = k0, or eq. 2.6 when k_lim > 0:
!>   k_exp(z) = k_lim + (k0 - k_lim) exp(-z / z_ref).
!>
!> h < 0 softens. The nonlocal part zeta of the strength (eq. 4.34) is added
!> by the caller.
module wellposed_hardening
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: hardening_t, strength, strength_slope, min_strength_slope, is_linear

  !> Hardening parameters (stress units; z_ref is a strain).
  type :: hardening_t
    real(dp) :: k0 = 0.0_dp     !< initial yield strength
    real(dp) :: h = 0.0_dp      !< linear modulus h_eta
    real(dp) :: k_lim = 0.0_dp  !< exponential limit (0: off)
    real(dp) :: z_ref = 0.0_dp  !< exponential reference strain
  end type hardening_t

contains

  !> True when k(z) is linear in z (no exponential part).
  elemental function is_linear(hd) result(lin)
    type(hardening_t), intent(in) :: hd
    logical :: lin
    lin = .not. (hd%k_lim > 0.0_dp)
  end function is_linear

  !> Local yield strength k(z) (eq. 2.3 and 2.6 plus h z).
  elemental function strength(hd, z) result(k)
    type(hardening_t), intent(in) :: hd
    real(dp), intent(in) :: z
    real(dp) :: k
    if (is_linear(hd)) then
      k = hd%k0 + hd%h*z
    else
      k = hd%k_lim + (hd%k0 - hd%k_lim)*exp(-z/hd%z_ref) + hd%h*z
    end if
  end function strength

  !> dk/dz, the hardening modulus of the return mapping.
  elemental function strength_slope(hd, z) result(dk)
    type(hardening_t), intent(in) :: hd
    real(dp), intent(in) :: z
    real(dp) :: dk
    if (is_linear(hd)) then
      dk = hd%h
    else
      dk = (hd%k_lim - hd%k0)/hd%z_ref*exp(-z/hd%z_ref) + hd%h
    end if
  end function strength_slope

  !> The smallest dk/dz over z >= 0: at z = 0 when the exponential part
  !> softens, h (z -> infinity) when it hardens.
  elemental function min_strength_slope(hd) result(dk)
    type(hardening_t), intent(in) :: hd
    real(dp) :: dk
    dk = hd%h
    if (.not. is_linear(hd)) dk = dk + min(0.0_dp, (hd%k_lim - hd%k0)/hd%z_ref)
  end function min_strength_slope

end module wellposed_hardening
