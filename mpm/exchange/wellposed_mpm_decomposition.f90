!> Domain decomposition of the MPM grid over ranks: strips of whole cell
!> layers along the last axis, so a rank's nodes are one contiguous range
!> [glo, ghi], with `ghost` node layers either side (the shape's reach, or
!> the nonlocal Gaussian's). `hand_off_particles` moves particles to the
!> rank owning their cell, in a deterministic order; `sum_ghost_values`
!> adds the holders' partial sums in ascending rank order, so every copy of
!> a node ends bitwise equal. Design: docs/guide/parallel.md.
module wellposed_mpm_decomposition
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_mpi, only: comm_t, alltoall_counts, alltoallv_real, sendrecv_real, &
                           allreduce_any, gatherv_real, gatherv_int, allreduce_sum
  use wellposed_nonlocal, only: weight_support
  use wellposed_mpm_grid, only: grid_t, cell_layer
  use wellposed_mpm_particles, only: particles_t, copy_particle, particle_record_length, &
                                     pack_particle, unpack_particle, ensure_capacity, first_outside
  implicit none
  private
  public :: decomposition_t, new_decomposition, owner_of_layer, owner_of_position, &
            layer_of_position, &
            restrict_grid, restrict_particles, hand_off_particles, sum_ghost_values, &
            sum_ghost_grid, copy_owned_to_ghosts, gather_by_gid, check_support, ghost_layers
  public :: patch_nodes, hand_off_particles_with

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
    call patch_layers(self, self%rank, lo, hi)
    glo = lo*self%layer_nodes
    ghi = (hi + 1)*self%layer_nodes - 1
    call owned_layers(self, self%rank, lo, hi)
    grid%ilo = lo*self%layer_nodes
    grid%ihi = (hi + 1)*self%layer_nodes - 1
    call cut_r1(grid%mass)
    call cut_r2(grid%momentum)
    call cut_r2(grid%fint)
    call cut_r2(grid%fext)
    call cut_r2(grid%velocity)
    call cut_r2(grid%accel)
    call cut_l2(grid%fixed)
    if (allocated(grid%given)) call cut_l2(grid%given)
    grid%glo = glo
    grid%ghi = ghi
  contains
    subroutine cut_r1(a)
      real(dp), allocatable, intent(inout) :: a(:)
      real(dp), allocatable :: b(:)
      allocate (b(glo:ghi))
      b = a(glo:ghi)
      call move_alloc(b, a)
    end subroutine cut_r1
    subroutine cut_r2(a)
      real(dp), allocatable, intent(inout) :: a(:, :)
      real(dp), allocatable :: b(:, :)
      allocate (b(size(a, 1), glo:ghi))
      b = a(:, glo:ghi)
      call move_alloc(b, a)
    end subroutine cut_r2
    subroutine cut_l2(a)
      logical, allocatable, intent(inout) :: a(:, :)
      logical, allocatable :: b(:, :)
      allocate (b(size(a, 1), glo:ghi))
      b = a(:, glo:ghi)
      call move_alloc(b, a)
    end subroutine cut_l2
  end subroutine restrict_grid

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
        call outside(self, parts, p, err)
        return
      end if
      if (owner /= self%rank) cycle
      m = m + 1
      if (m /= p) call copy_particle(parts, p, m)
    end do
    parts%n = m
  end subroutine restrict_particles

  subroutine outside(self, parts, p, err)
    type(decomposition_t), intent(in) :: self
    type(particles_t), intent(in) :: parts
    integer, intent(in) :: p
    type(error_t), allocatable, intent(out) :: err
    call new_error(err, status_invalid, 'grid', 'particle '//int_text(parts%gid(p))// &
      ' at '//real_text(parts%x(self%axis, p))//' m left the grid ['// &
      real_text(self%origin)//', '//real_text(self%origin + self%ncells*self%dx)// &
      '] m; enlarge the grid (grid%pad_cells) or shorten the run')
  end subroutine outside

  !> Send every particle whose cell another rank owns to that rank, and take
  !> in the particles other ranks send here (collective). Stayers keep their
  !> order; arrivals are appended in the order of the sending ranks. A
  !> particle that left the grid is an error on every rank (the first rank
  !> to see one names it). `moved` counts the particles this rank sent.
  subroutine hand_off_particles(self, comm, parts, err, moved)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(inout) :: parts
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: moved
    real(dp), allocatable :: none(:, :)
    ! the same hand-off with no data beside particles_t (zero rows travel)
    allocate (none(0, size(parts%gid)))
    call hand_off_particles_with(self, comm, parts, none, err, moved)
  end subroutine hand_off_particles

  !> True when every particle's support nodes (parts%node) lie in the
  !> patch; otherwise an error naming the first particle that reaches out.
  subroutine check_support(self, parts, grid, err)
    type(decomposition_t), intent(in) :: self
    type(particles_t), intent(in) :: parts
    type(grid_t), intent(in) :: grid
    type(error_t), allocatable, intent(out) :: err
    integer :: p
    p = first_outside(parts%node, parts%n, grid%glo, grid%ghi)
    if (p == 0) return
    call new_error(err, status_invalid, 'ghost', 'particle '//int_text(parts%gid(p))// &
      ' at '//real_text(parts%x(self%axis, p))//' m reaches nodes outside the patch ['// &
      int_text(grid%glo)//', '//int_text(grid%ghi)//'] of rank '//int_text(self%rank)// &
      ': the ghost width '//int_text(self%ghost)//' is below the shape support')
  end subroutine check_support

  !> values(:, glo:ghi) holds this rank's partial sums at its patch nodes;
  !> afterwards every node holds the sum over all ranks that hold it, added
  !> in ascending rank order (bitwise the same on every holder).
  subroutine sum_ghost_values(self, comm, values)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: values(:, :)
    real(dp), allocatable :: total(:, :), recv(:)
    integer :: k, nc, glo, lo, hi, nn
    logical :: mine_added
    if (self%nnb == 0) return
    nc = size(values, 1)
    glo = lbound_node(self)
    allocate (total(nc, size(values, 2)))
    total = 0.0_dp
    mine_added = .false.
    do k = 1, self%nnb
      if (.not. mine_added .and. self%nb_rank(k) > self%rank) then
        total = total + values
        mine_added = .true.
      end if
      lo = self%nb_lo(k) - glo + 1
      hi = self%nb_hi(k) - glo + 1
      nn = hi - lo + 1
      allocate (recv(nc*nn))
      call sendrecv_real(comm, reshape(values(:, lo:hi), [nc*nn]), self%nb_rank(k), recv, &
                         self%nb_rank(k), 71)
      total(:, lo:hi) = total(:, lo:hi) + reshape(recv, [nc, nn])
      deallocate (recv)
    end do
    if (.not. mine_added) total = total + values
    values = total
  end subroutine sum_ghost_values

  !> Sum the grid fields a particle-to-grid pass accumulates: mass,
  !> momentum, internal and external force (or the momentum only, for the
  !> MUSL velocity rebuild). One message per neighbour.
  subroutine sum_ghost_grid(self, comm, grid, momentum_only)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    type(grid_t), intent(inout) :: grid
    logical, intent(in) :: momentum_only
    real(dp), allocatable :: buf(:, :)
    integer :: d
    if (self%nnb == 0) return
    d = grid%ndim
    if (momentum_only) then
      call sum_ghost_values(self, comm, grid%momentum)
      return
    end if
    allocate (buf(1 + 3*d, grid%glo:grid%ghi))
    buf(1, :) = grid%mass
    buf(2:1 + d, :) = grid%momentum
    buf(2 + d:1 + 2*d, :) = grid%fint
    buf(2 + 2*d:1 + 3*d, :) = grid%fext
    call sum_ghost_values(self, comm, buf)
    grid%mass = buf(1, :)
    grid%momentum = buf(2:1 + d, :)
    grid%fint = buf(2 + d:1 + 2*d, :)
    grid%fext = buf(2 + 2*d:1 + 3*d, :)
  end subroutine sum_ghost_grid

  !> values(:, glo:ghi): every ghost node takes the value its owner holds
  !> (for fields computed on owned nodes only, e.g. a nodal nonlocal field).
  subroutine copy_owned_to_ghosts(self, comm, values)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: values(:, :)
    real(dp), allocatable :: recv(:), sent(:, :)
    integer :: k, nc, glo, lo, hi, nn, i, node
    if (self%nnb == 0) return
    nc = size(values, 1)
    glo = lbound_node(self)
    do k = 1, self%nnb
      lo = self%nb_lo(k) - glo + 1
      hi = self%nb_hi(k) - glo + 1
      nn = hi - lo + 1
      allocate (recv(nc*nn))
      sent = values(:, lo:hi)
      call sendrecv_real(comm, reshape(sent, [nc*nn]), self%nb_rank(k), recv, &
                         self%nb_rank(k), 72)
      do i = 1, nn
        node = self%nb_lo(k) + i - 1
        if (owner_of_layer(self, node/self%layer_nodes) == self%nb_rank(k)) &
          values(:, lo + i - 1) = recv((i - 1)*nc + 1:i*nc)
      end do
      deallocate (recv)
    end do
  end subroutine copy_owned_to_ghosts

  !> First global node of this rank's patch.
  pure integer function lbound_node(self) result(glo)
    type(decomposition_t), intent(in) :: self
    integer :: lo, hi
    call patch_layers(self, self%rank, lo, hi)
    glo = lo*self%layer_nodes
  end function lbound_node

  !> Gather values(:, 1:n) of the local particles (ids gid(1:n)) onto
  !> `root` as all(:, 1:ntotal) in global-id order, the layout of a serial
  !> run. ntotal is the largest id; every id 1..ntotal must occur once.
  subroutine gather_by_gid(comm, gid, values, root, all)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: gid(:)
    real(dp), intent(in) :: values(:, :)
    integer, intent(in) :: root
    real(dp), allocatable, intent(out) :: all(:, :)
    integer, allocatable :: ids(:)
    real(dp), allocatable :: flat(:)
    integer :: nc, p, ntot
    nc = size(values, 1)
    call gatherv_int(comm, gid, ids, root)
    call gatherv_real(comm, reshape(values, [nc*size(gid)]), flat, root)
    ntot = size(gid)
    call allreduce_sum(comm, ntot)
    if (comm%rank == root) then
      allocate (all(nc, ntot))
      all = 0.0_dp
      do p = 1, size(ids)
        all(:, ids(p)) = flat((p - 1)*nc + 1:p*nc)
      end do
    else
      allocate (all(nc, 0))
    end if
  end subroutine gather_by_gid

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

  !> hand_off_particles for a host that keeps more per-particle data beside
  !> particles_t: extra(:, p) (any number of reals per particle, columns
  !> 1 .. parts%n in use) travels with particle p and ends in the same slot;
  !> it grows with the particles' capacity. Collective; same order rules.
  subroutine hand_off_particles_with(self, comm, parts, extra, err, moved)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(inout) :: parts
    real(dp), allocatable, intent(inout) :: extra(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: moved
    integer :: owner(parts%n), scount(0:comm%size - 1), rcount(0:comm%size - 1)
    integer :: sdispl(0:comm%size - 1), rdispl(0:comm%size - 1), fill(0:comm%size - 1)
    integer :: p, q, m, reclen, plen, ne, nin, bad
    real(dp), allocatable :: sbuf(:), rbuf(:), grown(:, :)
    plen = particle_record_length(parts)
    ne = size(extra, 1)
    reclen = plen + ne
    bad = 0
    scount = 0
    do p = 1, parts%n
      owner(p) = owner_of_position(self, parts%x(self%axis, p))
      if (owner(p) < 0) then
        if (bad == 0) bad = p
        owner(p) = self%rank
      end if
      if (owner(p) /= self%rank) scount(owner(p)) = scount(owner(p)) + 1
    end do
    if (allreduce_any(comm, bad > 0)) then
      if (bad > 0) then
        call outside(self, parts, bad, err)
      else
        call new_error(err, status_invalid, 'grid', 'a particle on another rank left the grid')
      end if
      return
    end if
    if (present(moved)) moved = sum(scount)
    call alltoall_counts(comm, scount, rcount)
    scount = scount*reclen
    rcount = rcount*reclen
    sdispl(0) = 0
    rdispl(0) = 0
    do q = 1, comm%size - 1
      sdispl(q) = sdispl(q - 1) + scount(q - 1)
      rdispl(q) = rdispl(q - 1) + rcount(q - 1)
    end do
    allocate (sbuf(max(1, sum(scount))), rbuf(max(1, sum(rcount))))
    fill = sdispl
    m = 0
    do p = 1, parts%n
      q = owner(p)
      if (q /= self%rank) then
        call pack_particle(parts, p, sbuf(fill(q) + 1:fill(q) + plen))
        sbuf(fill(q) + plen + 1:fill(q) + reclen) = extra(:, p)
        fill(q) = fill(q) + reclen
      else
        m = m + 1
        if (m /= p) then
          call copy_particle(parts, p, m)
          extra(:, m) = extra(:, p)
        end if
      end if
    end do
    call alltoallv_real(comm, sbuf, scount, sdispl, rbuf, rcount, rdispl)
    nin = sum(rcount)/reclen
    parts%n = m
    call ensure_capacity(parts, m + nin)
    if (size(extra, 2) < size(parts%gid)) then
      allocate (grown(ne, size(parts%gid)))
      grown(:, 1:m) = extra(:, 1:m)
      call move_alloc(grown, extra)
    end if
    do p = 1, nin
      call unpack_particle(parts, m + p, rbuf((p - 1)*reclen + 1:(p - 1)*reclen + plen))
      extra(:, m + p) = rbuf((p - 1)*reclen + plen + 1:p*reclen)
    end do
    parts%n = m + nin
  end subroutine hand_off_particles_with

end module wellposed_mpm_decomposition
