!> Node values across the patches of the decomposition (wellposed_mpm_decomposition):
!> the partial sums at shared nodes added in ascending rank order, so that
!> every copy of a node ends bitwise equal, and the owners' values copied
!> to the ghosts. Design: docs/guide/parallel.md.
module wellposed_mpm_decomposition_ghosts
  use wellposed_kinds, only: dp
  use wellposed_mpi, only: comm_t, sendrecv_real
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_decomposition_layout, only: decomposition_t, owner_of_layer, patch_nodes
  implicit none
  private
  public :: sum_ghost_values, sum_ghost_grid, copy_owned_to_ghosts

contains

  !> values(:, glo:ghi) holds this rank's partial sums at its patch nodes;
  !> afterwards every node holds the sum over all ranks that hold it, added
  !> in ascending rank order (bitwise the same on every holder).
  subroutine sum_ghost_values(self, comm, values)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    real(dp), intent(inout) :: values(:, :)
    real(dp), allocatable :: total(:, :), recv(:)
    integer :: k, nc, glo, ghi, lo, hi, nn
    logical :: mine_added
    if (self%nnb == 0) return
    nc = size(values, 1)
    call patch_nodes(self, glo, ghi)
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
    integer :: k, nc, glo, ghi, lo, hi, nn, i, node
    if (self%nnb == 0) return
    nc = size(values, 1)
    call patch_nodes(self, glo, ghi)
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

end module wellposed_mpm_decomposition_ghosts
