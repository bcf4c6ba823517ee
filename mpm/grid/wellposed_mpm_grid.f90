!> The background grid of the MPM (section 4.3): uniform structured nodes
!> with lumped mass (eq. 4.4), momentum, internal and external force
!> (eq. 4.5), velocity and acceleration (eq. 4.9-4.10). Node arrays are
!> indexed by global node number over this rank's patch [glo, ghi], ghosts
!> included, so a decomposed run sums ghosts (wellposed_mpm_exchange)
!> without touching the loops; fields are (ndim, node), node = i + nx*j.
module wellposed_mpm_grid
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  implicit none
  private
  public :: grid_t, new_grid, new_grid_1d, grid_reset, cell_layer, zero

  type :: grid_t
    integer :: ndim = 1
    real(dp) :: origin = 0.0_dp     !< x of global node 0 (m)
    real(dp) :: dx = 1.0_dp         !< cell size h (m)
    integer :: nnodes = 0           !< global node count (nodes 0 .. nnodes-1)
    integer :: ilo = 0, ihi = -1    !< nodes this process owns
    integer :: glo = 0, ghi = -1    !< owned plus ghost nodes (array bounds)
    real(dp), allocatable :: mass(:)        !< lumped mass m_i (kg per m^2 of section)
    real(dp), allocatable :: momentum(:, :) !< m_i v_i (ndim, node)
    real(dp), allocatable :: fint(:, :)     !< internal force (N per m^2), eq. 4.5
    real(dp), allocatable :: fext(:, :)     !< external force
    real(dp), allocatable :: velocity(:, :) !< v_i after the update, eq. 4.10 (m/s)
    real(dp), allocatable :: accel(:, :)    !< a_i, eq. 4.9 (m/s^2)
    !> Per node and component: .true. where the velocity is prescribed zero
    !> (its nodal force is a reaction)
    logical, allocatable :: fixed(:, :)
    !> Per node and component: .true. where the velocity is given (a moving
    !> boundary; the value is the step's, wellposed_mpm_transfer)
    logical, allocatable :: given(:, :)
  end type grid_t

contains

  !> The cell (0 .. ncells-1) of `ncells` cells of size `dx` from `origin`
  !> holding coordinate `x`; -1 outside. The rule of every owner decision.
  elemental integer function cell_layer(x, origin, dx, ncells) result(layer)
    real(dp), intent(in) :: x, origin, dx
    integer, intent(in) :: ncells
    real(dp) :: s
    s = (x - origin)/dx
    layer = -1
    if (.not. (s >= 0.0_dp .and. s < real(ncells, dp))) return
    layer = min(int(s), ncells - 1)
  end function cell_layer

  !> A 1D grid of `ncells` cells of size `dx` starting at `origin`, one
  !> patch holding all nodes (serial run; no ghosts needed).
  subroutine new_grid_1d(self, origin, dx, ncells)
    type(grid_t), intent(out) :: self
    real(dp), intent(in) :: origin, dx
    integer, intent(in) :: ncells
    call new_grid(self, 1, origin, dx, ncells + 1, 0, ncells)
  end subroutine new_grid_1d

  !> A grid of `nnodes` nodes in `ndim` dimensions (node 0 at `origin` along
  !> x, cell size `dx`) of which this process holds the patch [glo, ghi]
  !> and owns all: free nodes at rest, nothing accumulated.
  subroutine new_grid(self, ndim, origin, dx, nnodes, glo, ghi)
    type(grid_t), intent(out) :: self
    integer, intent(in) :: ndim, nnodes, glo, ghi
    real(dp), intent(in) :: origin, dx
    integer :: st
    self%ndim = ndim
    self%origin = origin
    self%dx = dx
    self%nnodes = nnodes
    self%ilo = glo
    self%ihi = ghi
    self%glo = glo
    self%ghi = ghi
    allocate (self%mass(glo:ghi), self%momentum(ndim, glo:ghi), self%fint(ndim, glo:ghi), &
              self%fext(ndim, glo:ghi), self%velocity(ndim, glo:ghi), &
              self%accel(ndim, glo:ghi), self%fixed(ndim, glo:ghi), self%given(ndim, glo:ghi), &
              stat=st)
    if (st /= 0) call out_of_memory('grid', int(ghi - glo + 1, int64), st)
    self%fixed = .false.
    self%given = .false.
    call grid_reset(self)
    self%velocity = 0.0_dp
    self%accel = 0.0_dp
  end subroutine new_grid

  !> Zero the accumulated fields before a particle-to-grid pass.
  pure subroutine grid_reset(self)
    type(grid_t), intent(inout) :: self
    call zero(self%mass, size(self%mass))
    call zero(self%momentum, size(self%momentum))
    call zero(self%fint, size(self%fint))
    call zero(self%fext, size(self%fext))
  end subroutine grid_reset

  !> a(1:n) = 0: a node array as one run of memory (an (ndim, node) array
  !> zeroed directly is filled one short column at a time).
  pure subroutine zero(a, n)
    integer, intent(in) :: n
    real(dp), intent(out) :: a(n)
    a = 0.0_dp
  end subroutine zero

end module wellposed_mpm_grid
