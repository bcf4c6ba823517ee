!> Shape functions of the MPM in 1D (eq. 4.6-4.8): the weights phi_ip and
!> gradient weights G_ip of a particle on a uniform grid. Linear (standard
!> MPM): the hat S_i(x_p). uGIMP (shared reference A, "uGIMP 1D"; h the
!> cell, lp the half-width, xi = x_p - x_i): S = 1 - (xi^2 + lp^2)/(2 h lp)
!> for |xi| <= lp, 1 - |xi|/h up to h - lp, (h + lp - |xi|)^2/(4 h lp) below
!> h + lp; G = dS/dx_p. 2D takes tensor products and adds CPDI.
module wellposed_mpm_shape
  use wellposed_kinds, only: dp
  use wellposed_mpm_method, only: shape_linear, shape_gimp
  implicit none
  private
  public :: support_size, shape_1d, shape_bar, gimp_weight, linear_weight, nearest_node

contains

  !> Nodes a particle can touch: 2 for linear, 3 for GIMP (lp <= h/2).
  pure integer function support_size(kind)
    integer, intent(in) :: kind
    select case (kind)
    case (shape_gimp)
      support_size = 3
    case default
      support_size = 2
    end select
  end function support_size

  !> nint(s), the node nearest a particle at s cells from node 0 (halves
  !> away from zero), without the libm call (lround) gfortran makes for
  !> nint: truncate, then round the fraction s - int(s), which is exact for
  !> |s| < 2**31 (the weights of every particle and step call it).
  elemental integer function nearest_node(s) result(i)
    real(dp), intent(in) :: s
    real(dp) :: r
    i = int(s)
    r = s - real(i, dp)
    if (r >= 0.5_dp) then
      i = i + 1
    else if (r <= -0.5_dp) then
      i = i - 1
    end if
  end function nearest_node

  !> Weights of one particle at x (m), half-width lp (m), on a grid with node
  !> 0 at `origin` and cell size h: nodes(k) global node numbers, phi(k)
  !> dimensionless, grad(k) in 1/m, for k = 1 .. support_size(kind). Unused
  !> entries (none for these kinds) would carry zero weight.
  pure subroutine shape_1d(kind, x, lp, origin, h, nodes, phi, grad)
    integer, intent(in) :: kind
    real(dp), intent(in) :: x, lp, origin, h
    integer, intent(out) :: nodes(:)
    real(dp), intent(out) :: phi(:), grad(:)
    call shape_bar(kind, 1, [x], [lp], origin, h, size(nodes), nodes, phi, grad)
  end subroutine shape_1d

  !> shape_1d of particles 1 .. n at x(p), half-widths lp(p), on plain
  !> arrays of m = support_size(kind) rows: one loop per kind, the node
  !> count a constant.
  pure subroutine shape_bar(kind, n, x, lp, origin, h, m, nodes, phi, grad)
    integer, value :: kind, m
    integer, intent(in) :: n
    real(dp), intent(in) :: x(n), lp(n), origin, h
    integer, intent(out) :: nodes(m, n)
    real(dp), intent(out) :: phi(m, n), grad(m, n)
    integer :: i0, k, p
    select case (kind)
    case (shape_gimp)
      do p = 1, n
        i0 = nearest_node((x(p) - origin)/h) - 1
        do k = 1, 3
          nodes(k, p) = i0 + k - 1
          call gimp_weight(x(p) - (origin + real(i0 + k - 1, dp)*h), lp(p), h, phi(k, p), &
                           grad(k, p))
        end do
      end do
    case default
      do p = 1, n
        i0 = floor((x(p) - origin)/h)
        do k = 1, 2
          nodes(k, p) = i0 + k - 1
          call linear_weight(x(p) - (origin + real(i0 + k - 1, dp)*h), h, phi(k, p), grad(k, p))
        end do
      end do
    end select
  end subroutine shape_bar

  !> uGIMP weight and gradient for offset xi = x_p - x_i (m).
  elemental subroutine gimp_weight(xi, lp, h, phi, grad)
    real(dp), value :: xi, lp, h
    real(dp), intent(out) :: phi, grad
    real(dp) :: a, sgn
    a = abs(xi)
    sgn = sign(1.0_dp, xi)
    if (a <= lp) then
      phi = 1.0_dp - (xi*xi + lp*lp)/(2.0_dp*h*lp)
      grad = -xi/(h*lp)
    else if (a <= h - lp) then
      phi = 1.0_dp - a/h
      grad = -sgn*(1.0_dp/h)   ! = -sgn/h exactly (sgn = +-1); 1/h leaves the loop
    else if (a < h + lp) then
      phi = (h + lp - a)**2/(4.0_dp*h*lp)
      grad = -sgn*(h + lp - a)/(2.0_dp*h*lp)
    else
      phi = 0.0_dp
      grad = 0.0_dp
    end if
  end subroutine gimp_weight

  !> Linear hat weight and gradient for offset xi = x_p - x_i (m).
  elemental subroutine linear_weight(xi, h, phi, grad)
    real(dp), value :: xi, h
    real(dp), intent(out) :: phi, grad
    real(dp) :: a
    a = abs(xi)
    if (a < h) then
      phi = 1.0_dp - a/h
      grad = -sign(1.0_dp, xi)/h
    else
      phi = 0.0_dp
      grad = 0.0_dp
    end if
  end subroutine linear_weight

end module wellposed_mpm_shape
