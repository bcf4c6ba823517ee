!> Nonlocal (overlocal) plasticity helpers for hosts (section 2.5.4,
!> 4.4-4.5): the Gaussian weight of the nonlocal average and the Lipschitz
!> bounds of the two fixed-point schemes, so a host can warn before its
!> iteration diverges.
module wellposed_nonlocal
  use wellposed_kinds, only: dp
  use wellposed_dp_params, only: dp_params_t
  implicit none
  private
  public :: gaussian_k, nonlocal_weight, lipschitz_local_implicit, lipschitz_local_explicit, &
            weight_support

  !> k = (6 sqrt(pi))^(1/3) of eq. 2.15 and 4.27.
  real(dp), parameter :: gaussian_k = (6.0_dp*sqrt(acos(-1.0_dp)))**(1.0_dp/3.0_dp)

contains

  !> alpha(r) = exp(-(k r/L)^2) (eq. 2.15, 4.27; the printed
  !> exp[(-k|x|/L)^2] has a sign typo: the Gaussian decays).
  elemental function nonlocal_weight(r, length) result(alpha)
    real(dp), intent(in) :: r, length
    real(dp) :: alpha
    alpha = exp(-(gaussian_k*r/length)**2)
  end function nonlocal_weight

  !> Distance beyond which alpha < tol: L sqrt(-ln tol)/k. Hosts cut the
  !> Gaussian there (and size ghost layers by it).
  elemental function weight_support(length, tol) result(r)
    real(dp), intent(in) :: length, tol
    real(dp) :: r
    r = length*sqrt(-log(tol))/gaussian_k
  end function weight_support

  !> Eq. 4.43: the scheme of eq. 4.39 (local dlambda implicit, average
  !> lagged) converges when N_alpha |h_zeta/(a + h_eta)| < 1, with
  !> a = (G + 9 K beta beta_p)/sqrt(1/2 + 3 beta_p^2).
  elemental function lipschitz_local_implicit(p, n_alpha) result(bound)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: n_alpha
    real(dp) :: bound
    bound = n_alpha*abs(p%h_zeta/(p%a_m + p%hard%h))
  end function lipschitz_local_implicit

  !> Eq. 4.45: the scheme of eq. 4.41 (both hardening terms lagged)
  !> converges when N_alpha |(h_eta + h_zeta)/a| < 1.
  elemental function lipschitz_local_explicit(p, n_alpha) result(bound)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: n_alpha
    real(dp) :: bound
    bound = n_alpha*abs((p%hard%h + p%h_zeta)/p%a_m)
  end function lipschitz_local_explicit

end module wellposed_nonlocal
