!> The largest stable &time cfl of a bar (docs/research/timestep.md, "Where a bar's
!> step is stable"): eq. 4.9-4.13 linearised on an elastic bar at rest. Per
!> Fourier mode theta, cfl = c dt/dx: mu = a + 2 b cos(theta) (the mass
!> matrix M_P), w0^2 = 4 sin^2(theta/2), alpha = 1 (lumped), 1/mu
!> (consistent), 2/(mu (1 + mu)) (blended). MUSL is stable iff
!> cfl^2 w0^2 mu alpha <= 4, USL iff cfl^2 w0^2 alpha (2 - mu) <= 4.
!> tests/regression/mpm/mpm_bloch.py checks these against the whole step.
module wellposed_mpm_bar_cfl_limit
  use wellposed_kinds, only: dp
  use wellposed_mpm_method, only: scheme_musl, mass_lumped, mass_consistent
  implicit none
  private
  public :: cfl_limit

contains

  !> The limit for `scheme`, `mass` (wellposed_mpm_method's codes) and `ppc`;
  !> huge() where M_P is singular at rest (one particle per cell: a
  !> node-to-node alternation no particle sees) and the solve has none.
  pure function cfl_limit(scheme, mass, ppc) result(limit)
    integer, intent(in) :: scheme, mass, ppc
    real(dp) :: limit
    integer, parameter :: nt = 4096   ! theta in (0, pi]: the lumped maximum is inside
    real(dp), parameter :: pi = 3.14159265358979323846_dp
    real(dp) :: a, b, x, th, mu, w2, alpha, worst
    integer :: k

    ! M_P's row, lumped mass 1: particles at (k - 1/2)/ppc of a cell, mass 1/ppc
    a = 0.0_dp
    b = 0.0_dp
    do k = 1, ppc
      x = (k - 0.5_dp)/ppc
      a = a + ((1.0_dp - x)**2 + x**2)/ppc
      b = b + x*(1.0_dp - x)/ppc
    end do
    if (mass /= mass_lumped .and. a - 2.0_dp*b <= 1.0e-12_dp) then
      limit = huge(1.0_dp)
      return
    end if
    worst = 0.0_dp
    do k = 1, nt
      th = pi*k/nt
      mu = a + 2.0_dp*b*cos(th)
      w2 = 4.0_dp*sin(0.5_dp*th)**2
      if (mass == mass_lumped) then
        alpha = 1.0_dp
      else if (mass == mass_consistent) then
        alpha = 1.0_dp/mu
      else
        alpha = 2.0_dp/(mu*(1.0_dp + mu))
      end if
      if (scheme == scheme_musl) then
        worst = max(worst, w2*mu*alpha)
      else
        worst = max(worst, w2*alpha*(2.0_dp - mu))
      end if
    end do
    limit = 2.0_dp/sqrt(worst)
  end function cfl_limit

end module wellposed_mpm_bar_cfl_limit
