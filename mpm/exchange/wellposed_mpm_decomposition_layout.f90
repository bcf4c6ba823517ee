!> The layout of the MPM grid over ranks (wellposed_mpm_decomposition):
!> strips of whole cell layers along the last axis, so a rank's nodes are
!> one contiguous range [glo, ghi], with `ghost` node layers either side
!> (the shape's reach, or the nonlocal Gaussian's); the owner of a layer
!> or position, and a serial run's grid and particles cut down to a rank's.
module wellposed_mpm_decomposition_layout
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_mpi, only: comm_t
  use wellposed_nonlocal, only: weight_support
  use wellposed_mpm_grid, only: grid_t, cell_layer
  use wellposed_mpm_particles, only: particles_t, copy_particle
  implicit none
  private
  public :: decomposition_t, new_decomposition, owner_of_layer, owner_of_position, &
            layer_of_position, restrict_grid, restrict_particles, ghost_layers, patch_nodes, &
            particle_left_grid

  !> How the grid is shared out; the same on every rank but for `rank`.
  type :: decomposition_t
    integer :: rank = 0, nranks = 1
    integer :: ncells = 0        !< cell layers along the split axis
    integer :: layer_nodes = 1   !< nodes per node layer (1 in 1D, nx + 1 in 2D)
    integer :: ghost = 1         !< ghost node layers beyond the nodes the cells touch
    integer :: axis = 1          !< coordinate of a particle that picks its layer
    real(dp) :: origin = 0.0_dp  !< coordinate of node layer 0 along `axis` (m)
    real(dp) :: dx = 1.0_dp      !< cell size along `axis` (m)
    integer, allocatable :: cell_lo(:)  !< (0:nranks): first cell layer of each rank
    !> Ranks whose patches share nodes with this one, ascending, and the
    !> shared global node range [nb_lo, nb_hi] with each.
    integer :: nnb = 0
    integer, allocatable :: nb_rank(:), nb_lo(:), nb_hi(:)
  end type decomposition_t

  !> restrict_grid's cut of one node field.
  interface cut
    module procedure cut_reals, cut_columns, cut_flags
  end interface cut

contains

  !> Ghost node layers a patch needs: the shape functions' reach beyond a
  !> particle's cell (`reach`: 0 linear, 1 GIMP) and, with nonlocal
  !> averaging (length > 0), the nodes within the Gaussian's support
  !> weight_support(length, tol) of an owned node, in cells of size dx.
  pure integer function ghost_layers(reach, length, tol, dx) result(layers)
    integer, intent(in) :: reach
    real(dp), intent(in) :: length, tol, dx
    layers = reach
    if (length > 0.0_dp) layers = max(reach, ceiling(weight_support(length, tol)/dx))
  end function ghost_layers

  !> Share `ncells` cell layers (of size `dx` from `origin` along `axis`,
  !> `layer_nodes` nodes per node layer) over the ranks of `comm` in
  !> near-equal strips, or at the layers `cell_lo` (0:size) when given, with
  !> `ghost` node layers. Every rank needs at least one cell layer.
  subroutine new_decomposition(self, comm, ncells, layer_nodes, ghost, axis, origin, dx, &
                               err, cell_lo)
    type(decomposition_t), intent(out) :: self
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: ncells, layer_nodes, ghost, axis
    real(dp), intent(in) :: origin, dx
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: cell_lo(0:)
    integer :: r, lo, hi, olo, ohi
    self%rank = comm%rank
    self%nranks = comm%size
    self%ncells = ncells
    self%layer_nodes = layer_nodes
    self%ghost = ghost
    self%axis = axis
    self%origin = origin
    self%dx = dx
    if (ncells < comm%size) then
      call new_error(err, status_invalid, 'ranks', 'cannot share '//int_text(ncells)// &
        ' cell layers over '//int_text(comm%size)//' ranks: every rank needs at least one')
      return
    end if
    if (ghost < 0 .or. layer_nodes < 1) then
      call new_error(err, status_invalid, 'ghost', 'ghost width '//int_text(ghost)// &
        ' and layer size '//int_text(layer_nodes)//' must be >= 0 and >= 1')
      return
    end if
    allocate (self%cell_lo(0:comm%size))
    if (present(cell_lo)) then
      self%cell_lo = cell_lo(0:comm%size)
      if (self%cell_lo(0) /= 0 .or. self%cell_lo(comm%size) /= ncells .or. &
          any(self%cell_lo(1:) <= self%cell_lo(:comm%size - 1))) then
        call new_error(err, status_invalid, 'cell_lo', 'rank boundaries must rise from 0 '// &
          'to '//int_text(ncells)//' with at least one cell layer per rank')
        return
      end if
    else
      do r = 0, comm%size
        self%cell_lo(r) = int((int(r, 8)*ncells)/comm%size)
      end do
    end if
    ! neighbours: every other rank whose patch shares nodes with ours
    allocate (self%nb_rank(0), self%nb_lo(0), self%nb_hi(0))
    call patch_layers(self, self%rank, lo, hi)
    do r = 0, comm%size - 1
      if (r == self%rank) cycle
      call patch_layers(self, r, olo, ohi)
      if (max(lo, olo) <= min(hi, ohi)) then
        self%nb_rank = [self%nb_rank, r]
        self%nb_lo = [self%nb_lo, max(lo, olo)*layer_nodes]
        self%nb_hi = [self%nb_hi, (min(hi, ohi) + 1)*layer_nodes - 1]
      end if
    end do
    self%nnb = size(self%nb_rank)
  end subroutine new_decomposition

  !> Node layers [lo, hi] of rank r's patch.
  pure subroutine patch_layers(self, r, lo, hi)
    type(decomposition_t), intent(in) :: self
    integer, intent(in) :: r
    integer, intent(out) :: lo, hi
    lo = max(0, self%cell_lo(r) - self%ghost)
    hi = min(self%ncells, self%cell_lo(r + 1) + self%ghost)
  end subroutine patch_layers

  !> Node layers [lo, hi] rank r owns.
  pure subroutine owned_layers(self, r, lo, hi)
    type(decomposition_t), intent(in) :: self
    integer, intent(in) :: r
    integer, intent(out) :: lo, hi
    lo = self%cell_lo(r)
    hi = self%cell_lo(r + 1) - 1
    if (r == self%nranks - 1) hi = self%ncells
  end subroutine owned_layers

  !> The rank owning cell layer `layer` (0 .. ncells-1), or node layer
  !> `layer` (0 .. ncells); -1 outside the grid.
  pure integer function owner_of_layer(self, layer) result(owner)
    type(decomposition_t), intent(in) :: self
    integer, intent(in) :: layer
    integer :: lo, hi, mid
    owner = -1
    if (layer < 0 .or. layer > self%ncells) return
    if (layer == self%ncells) then
      owner = self%nranks - 1
      return
    end if
    lo = 0
    hi = self%nranks - 1
    do while (lo < hi)             ! the last r with cell_lo(r) <= layer
      mid = (lo + hi + 1)/2
      if (self%cell_lo(mid) <= layer) then
        lo = mid
      else
        hi = mid - 1
      end if
    end do
    owner = lo
  end function owner_of_layer

  !> The cell layer (0 .. ncells-1) holding coordinate `x` along the split
  !> axis, the one that decides its owner; -1 outside the grid's cells. It
  !> does not depend on the rank count.
  pure integer function layer_of_position(self, x) result(layer)
    type(decomposition_t), intent(in) :: self
    real(dp), intent(in) :: x
    layer = cell_layer(x, self%origin, self%dx, self%ncells)
  end function layer_of_position

  !> The rank owning the cell that holds coordinate `x` along the split
  !> axis; -1 outside the grid's cells.
  pure integer function owner_of_position(self, x) result(owner)
    type(decomposition_t), intent(in) :: self
    real(dp), intent(in) :: x
    integer :: c
    owner = -1
    c = layer_of_position(self, x)
    if (c < 0) return
    owner = owner_of_layer(self, c)
  end function owner_of_position

  !> Cut a grid holding every node (as built for a serial run) down to this
  !> rank's patch: [ilo, ihi] the owned nodes, [glo, ghi] the patch. Fixed
  !> flags and the other node fields of the patch nodes are kept.
  subroutine restrict_grid(self, grid)
    type(decomposition_t), intent(in) :: self
    type(grid_t), intent(inout) :: grid
    integer :: lo, hi, glo, ghi
    call patch_nodes(self, glo, ghi)
    call owned_layers(self, self%rank, lo, hi)
    grid%ilo = lo*self%layer_nodes
    grid%ihi = (hi + 1)*self%layer_nodes - 1
    call cut(grid%mass, glo, ghi)
    call cut(grid%momentum, glo, ghi)
    call cut(grid%fint, glo, ghi)
    call cut(grid%fext, glo, ghi)
    call cut(grid%velocity, glo, ghi)
    call cut(grid%accel, glo, ghi)
    call cut(grid%fixed, glo, ghi)
    if (allocated(grid%given)) call cut(grid%given, glo, ghi)
    grid%glo = glo
    grid%ghi = ghi
  end subroutine restrict_grid

  !> a(glo:ghi), the nodes of a patch, of a node field over every node.
  subroutine cut_reals(a, glo, ghi)
    real(dp), allocatable, intent(inout) :: a(:)
    integer, intent(in) :: glo, ghi
    real(dp), allocatable :: b(:)
    allocate (b(glo:ghi))
    b = a(glo:ghi)
    call move_alloc(b, a)
  end subroutine cut_reals

  !> a(:, glo:ghi), likewise.
  subroutine cut_columns(a, glo, ghi)
    real(dp), allocatable, intent(inout) :: a(:, :)
    integer, intent(in) :: glo, ghi
    real(dp), allocatable :: b(:, :)
    allocate (b(size(a, 1), glo:ghi))
    b = a(:, glo:ghi)
    call move_alloc(b, a)
  end subroutine cut_columns

  !> a(:, glo:ghi) of node flags, likewise.
  subroutine cut_flags(a, glo, ghi)
    logical, allocatable, intent(inout) :: a(:, :)
    integer, intent(in) :: glo, ghi
    logical, allocatable :: b(:, :)
    allocate (b(size(a, 1), glo:ghi))
    b = a(:, glo:ghi)
    call move_alloc(b, a)
  end subroutine cut_flags

  !> Keep only the particles this rank owns (all particles were built on
  !> every rank), in their order. A particle outside the grid is an error.
  subroutine restrict_particles(self, parts, err)
    type(decomposition_t), intent(in) :: self
    type(particles_t), intent(inout) :: parts
    type(error_t), allocatable, intent(out) :: err
    integer :: p, owner, m
    m = 0
    do p = 1, parts%n
      owner = owner_of_position(self, parts%x(self%axis, p))
      if (owner < 0) then
        call particle_left_grid(self, parts, p, err)
        return
      end if
      if (owner /= self%rank) cycle
      m = m + 1
      if (m /= p) call copy_particle(parts, p, m)
    end do
    parts%n = m
  end subroutine restrict_particles

  !> The error of particle p, which left the grid along the split axis.
  subroutine particle_left_grid(self, parts, p, err)
    type(decomposition_t), intent(in) :: self
    type(particles_t), intent(in) :: parts
    integer, intent(in) :: p
    type(error_t), allocatable, intent(out) :: err
    call new_error(err, status_invalid, 'grid', 'particle '//int_text(parts%gid(p))// &
      ' at '//real_text(parts%x(self%axis, p))//' m left the grid ['// &
      real_text(self%origin)//', '//real_text(self%origin + self%ncells*self%dx)// &
      '] m; enlarge the grid (grid%pad_cells) or shorten the run')
  end subroutine particle_left_grid

  !> Global node range [glo, ghi] of this rank's patch (its ghost layers
  !> included): the bounds a host allocates its own nodal arrays with so
  !> that sum_ghost_values and copy_owned_to_ghosts apply to them.
  pure subroutine patch_nodes(self, glo, ghi)
    type(decomposition_t), intent(in) :: self
    integer, intent(out) :: glo, ghi
    integer :: lo, hi
    call patch_layers(self, self%rank, lo, hi)
    glo = lo*self%layer_nodes
    ghi = (hi + 1)*self%layer_nodes - 1
  end subroutine patch_nodes

end module wellposed_mpm_decomposition_layout
