!> The shape layer's one entry for a step (eq. 4.6-4.7): the weights and
!> gradient weights of every particle at x^n on the uniform grid, by the
!> particles' dimension: 1D families in one pass (wellposed_mpm_shape),
!> 2D particle by particle (wellposed_mpm_shape_2d; CPDI follows F).
module wellposed_mpm_shape_weights
  use wellposed_kinds, only: dp
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_shape, only: shape_bar
  use wellposed_mpm_shape_2d, only: shape_2d
  implicit none
  private
  public :: shape_weights

contains

  !> Weights of particles 1 .. pt%n of shape family `kind` on the grid with
  !> node 0 at `origin` (m), cell size h (m) and nx nodes per row (2D):
  !> pt%node, pt%phi, pt%grad, and nnz(p) the support entries in use.
  subroutine shape_weights(kind, pt, origin, h, nx, nnz)
    integer, intent(in) :: kind, nx
    type(particles_t), intent(inout) :: pt
    real(dp), intent(in) :: origin(:), h
    integer, intent(inout) :: nnz(:)
    integer :: p
    real(dp) :: f2(2, 2)
    if (pt%ndim == 1) then
      call shape_bar(kind, pt%n, pt%x, pt%lp, origin(1), h, pt%nsup, pt%node, pt%phi, pt%grad)
      nnz(1:pt%n) = pt%nsup
    else
      do p = 1, pt%n
        f2 = pt%defgrad(1:2, 1:2, p)
        call shape_2d(kind, pt%x(:, p), pt%lp(:, p), f2, origin, h, nx, pt%node(:, p), &
                      pt%phi(:, p), pt%grad(:, :, p), nnz(p))
      end do
    end if
  end subroutine shape_weights

end module wellposed_mpm_shape_weights
