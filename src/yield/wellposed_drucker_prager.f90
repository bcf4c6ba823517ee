!> The linear Drucker-Prager cone f = sqrt(J2) + beta I1 - k (eq. 2.3, 4.34)
!> and its plastic potential of slope beta_p (eq. 4.35). With the Mandel
!> deviator S, sqrt(J2) = ||S|| / sqrt(2).
module wellposed_drucker_prager
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: ntens6, sqrt2, identity2, trace, deviator, norm
  implicit none
  private
  public :: yield_value, yield_normal, potential_direction, normal_norm

contains

  !> f(sigma) = ||S||/sqrt(2) + beta tr(sigma) - k (eq. 2.3 with k the
  !> current strength, eq. 4.34).
  pure function yield_value(sig, beta, k) result(f)
    real(dp), intent(in) :: sig(ntens6), beta, k
    real(dp) :: f
    f = norm(deviator(sig))/sqrt2 + beta*trace(sig) - k
  end function yield_value

  !> ||df/dsigma|| = ||S_hat/sqrt(2) + beta I|| = sqrt(1/2 + 3 beta^2).
  elemental function normal_norm(beta) result(n)
    real(dp), intent(in) :: beta
    real(dp) :: n
    n = sqrt(0.5_dp + 3.0_dp*beta**2)
  end function normal_norm

  !> N = df/dsigma = S_hat/sqrt(2) + beta I, not normalised (S_hat the unit
  !> deviator; N:C:M etc. of the reference oracles use this N).
  pure function yield_normal(s_hat, beta) result(n)
    real(dp), intent(in) :: s_hat(ntens6), beta
    real(dp) :: n(ntens6)
    n = s_hat/sqrt2 + beta*identity2
  end function yield_normal

  !> Unit normal of the plastic potential (eq. 4.35):
  !> M_hat = (S_hat/sqrt(2) + beta_p I) / sqrt(1/2 + 3 beta_p^2).
  pure function potential_direction(s_hat, beta_p) result(m)
    real(dp), intent(in) :: s_hat(ntens6), beta_p
    real(dp) :: m(ntens6)
    m = yield_normal(s_hat, beta_p)/normal_norm(beta_p)
  end function potential_direction

end module wellposed_drucker_prager
