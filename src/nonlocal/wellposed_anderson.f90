!> Anderson acceleration of a fixed-point iteration x = G(x) (Walker and Ni
!> 2011, "type II" with depth m): the next iterate combines the last m + 1
!> evaluations so as to minimise the linearised residual, solved as a small
!> least-squares problem. For a linear G it is equivalent to GMRES, so it
!> converges where the plain iteration diverges (a Lipschitz constant of
!> eq. 4.43 above 1), and it needs fewer evaluations where both converge.
!> A host owns one anderson_t per solve; no state is saved elsewhere.
module wellposed_anderson
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: anderson_t, new_anderson, anderson_step, anderson_push, anderson_normal_solve

  !> History of differences of iterates and residuals (columns, newest last).
  type :: anderson_t
    integer :: depth = 0                  !< m, the number of kept differences
    integer :: count = 0                  !< differences held so far (<= depth)
    real(dp) :: mixing = 1.0_dp           !< beta: x_next = x + beta r - (dX + beta dR) gamma
    real(dp), allocatable :: dx(:, :)     !< x_k - x_{k-1}
    real(dp), allocatable :: dr(:, :)     !< r_k - r_{k-1}
    real(dp), allocatable :: x_prev(:), r_prev(:)
    logical :: started = .false.
  end type anderson_t

contains

  !> An accelerator for vectors of length n with depth m >= 1 and mixing
  !> beta in (0, 1] (1: undamped).
  pure subroutine new_anderson(self, n, depth, mixing)
    type(anderson_t), intent(out) :: self
    integer, intent(in) :: n, depth
    real(dp), intent(in) :: mixing
    self%depth = max(depth, 1)
    self%mixing = mixing
    allocate (self%dx(n, self%depth), self%dr(n, self%depth), self%x_prev(n), self%r_prev(n))
    self%dx = 0.0_dp
    self%dr = 0.0_dp
  end subroutine new_anderson

  !> Given the current iterate x and its image gx = G(x), return the next
  !> iterate. The residual is r = gx - x.
  pure subroutine anderson_step(self, x, gx, x_next)
    type(anderson_t), intent(inout) :: self
    real(dp), intent(in) :: x(:), gx(:)
    real(dp), intent(out) :: x_next(:)
    real(dp) :: r(size(x)), gamma(self%depth)
    integer :: k

    r = gx - x
    call anderson_push(self, x, r)

    x_next = x + self%mixing*r
    k = self%count
    if (k == 0) return
    call least_squares(self%dr(:, 1:k), r, gamma(1:k))
    x_next = x_next - matmul(self%dx(:, 1:k) + self%mixing*self%dr(:, 1:k), gamma(1:k))
  end subroutine anderson_step

  !> Append the differences to the last call's x and residual r = G(x) - x
  !> to the history (the newest last, the oldest dropped when full). With
  !> anderson_normal_solve, the pieces of anderson_step for a host whose
  !> vectors are split over processes: it sums the small Gram system.
  pure subroutine anderson_push(self, x, r)
    type(anderson_t), intent(inout) :: self
    real(dp), intent(in) :: x(:), r(:)
    if (self%started) then
      ! shift the history when full, then append the newest differences
      if (self%count == self%depth) then
        self%dx(:, 1:self%depth - 1) = self%dx(:, 2:self%depth)
        self%dr(:, 1:self%depth - 1) = self%dr(:, 2:self%depth)
      else
        self%count = self%count + 1
      end if
      self%dx(:, self%count) = x - self%x_prev
      self%dr(:, self%count) = r - self%r_prev
    end if
    self%x_prev = x
    self%r_prev = r
    self%started = .true.
  end subroutine anderson_push

  !> min ||a g - b|| by the normal equations with a small Tikhonov shift (the
  !> columns of a are few and may become nearly dependent near convergence).
  pure subroutine least_squares(a, b, g)
    real(dp), intent(in) :: a(:, :), b(:)
    real(dp), intent(out) :: g(:)
    real(dp) :: ata(size(a, 2), size(a, 2)), atb(size(a, 2))
    ata = matmul(transpose(a), a)
    atb = matmul(b, a)
    call anderson_normal_solve(ata, atb, g)
  end subroutine least_squares

  !> g solving (ata + shift) g = atb, ata = a^T a of the history's residual
  !> differences and atb = a^T b (symmetric positive semi-definite).
  pure subroutine anderson_normal_solve(ata, atb, g)
    real(dp), intent(inout) :: ata(:, :), atb(:)
    real(dp), intent(out) :: g(:)
    real(dp) :: piv
    integer :: n, i, j
    n = size(ata, 2)
    do i = 1, n
      ata(i, i) = ata(i, i)*(1.0_dp + 1.0e-12_dp) + tiny(1.0_dp)
    end do
    ! Cholesky-free Gaussian elimination: ata is symmetric positive definite.
    do i = 1, n
      piv = ata(i, i)
      do j = i + 1, n
        atb(j) = atb(j) - ata(j, i)/piv*atb(i)
        ata(j, i:n) = ata(j, i:n) - ata(j, i)/piv*ata(i, i:n)
      end do
    end do
    do i = n, 1, -1
      g(i) = (atb(i) - dot_product(ata(i, i + 1:n), g(i + 1:n)))/ata(i, i)
    end do
  end subroutine anderson_normal_solve

end module wellposed_anderson
