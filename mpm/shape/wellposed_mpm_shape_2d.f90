!> Shape functions of the MPM in 2D (eq. 4.6-4.8) on a uniform grid (node
!> g = i + nx*j): linear (bilinear hats, 4 nodes); uGIMP, the tensor product
!> of wellposed_mpm_shape's weights (9 nodes); CPDI (Sadeghirad, Brannon &
!> Burghardt 2011; shared reference "CPDI 2D"): the parallelogram of half
!> sides r1 = F (lx, 0), r2 = F (0, ly), phi_ip = (1/4) sum_a S_i(c_a) over
!> its corners, G_ip from the corners' differences over V = 4 |r1 x r2|
!> (up to 16 nodes). Unused support entries carry the first node with zero
!> weight, so loops over nsup need no test. Units: m, 1/m.
module wellposed_mpm_shape_2d
  use wellposed_kinds, only: dp
  use wellposed_mpm_shape, only: gimp_weight, nearest_node
  implicit none
  private
  public :: shape2d_linear, shape2d_gimp, shape2d_cpdi, shape2d_names, support_size_2d, &
            shape_2d, cpdi_corners, shape2d_reach

  !> Families in 2D.
  integer, parameter :: shape2d_linear = 1, shape2d_gimp = 2, shape2d_cpdi = 3
  character(len=6), parameter :: shape2d_names(3) = [character(len=6) :: 'linear', 'gimp', &
                                                     'cpdi']

contains

  !> Nodes per particle: 4 linear, 9 GIMP (lp <= h/2), 16 CPDI.
  pure integer function support_size_2d(kind)
    integer, intent(in) :: kind
    select case (kind)
    case (shape2d_gimp)
      support_size_2d = 9
    case (shape2d_cpdi)
      support_size_2d = 16
    case default
      support_size_2d = 4
    end select
  end function support_size_2d

  !> Node layers a particle's support reaches beyond the cell holding its
  !> centre, per side (the ghost width of a domain decomposition,
  !> wellposed_mpm_decomposition): linear 0; uGIMP 1 (lp <= h/2); CPDI 2,
  !> which holds while a corner stays less than 2 h from the centre along
  !> the split axis (|F21 lx| + |F22 ly| < 2 h: a fourfold stretch of the
  !> initial domain; a run checks it every step).
  pure integer function shape2d_reach(kind) result(layers)
    integer, intent(in) :: kind
    select case (kind)
    case (shape2d_gimp)
      layers = 1
    case (shape2d_cpdi)
      layers = 2
    case default
      layers = 0
    end select
  end function shape2d_reach

  !> Weights of one particle at xp (m): lp(2) the half-widths of its initial
  !> rectangle (m), f(2, 2) the in-plane deformation gradient (CPDI only);
  !> grid origin(2) (m), cell size h (m), nx nodes per row. nodes(:) global
  !> node numbers, phi(:), grad(2, :) (1/m), size support_size_2d(kind);
  !> nused (optional): the nodes in use, 1 .. nused (past it phi = 0).
  pure subroutine shape_2d(kind, xp, lp, f, origin, h, nx, nodes, phi, grad, nused)
    integer, intent(in) :: kind, nx
    real(dp), intent(in) :: xp(2), lp(2), f(2, 2), origin(2), h
    integer, intent(out), contiguous :: nodes(:)
    real(dp), intent(out), contiguous :: phi(:), grad(:, :)
    integer, intent(out), optional :: nused
    real(dp) :: sx(3), sy(3), dsx(3), dsy(3), s(2)
    integer :: i0(2), a, b, k, m
    m = size(phi)
    select case (kind)
    case (shape2d_gimp)
      s = (xp - origin)/h
      i0 = nearest_node(s) - 1
      do a = 1, 3
        call gimp_weight(xp(1) - (origin(1) + (i0(1) + a - 1)*h), lp(1), h, sx(a), dsx(a))
        call gimp_weight(xp(2) - (origin(2) + (i0(2) + a - 1)*h), lp(2), h, sy(a), dsy(a))
      end do
      k = 0
      do b = 1, 3
        do a = 1, 3
          k = k + 1
          nodes(k) = (i0(1) + a - 1) + nx*(i0(2) + b - 1)
          phi(k) = sx(a)*sy(b)
          grad(:, k) = [dsx(a)*sy(b), sx(a)*dsy(b)]
        end do
      end do
    case (shape2d_cpdi)
      call cpdi_2d(xp, matmul(f, [lp(1), 0.0_dp]), matmul(f, [0.0_dp, lp(2)]), origin, h, &
                   nx, nodes, phi, grad, m)
    case default
      call bilinear(xp, origin, h, nx, nodes(1:4), phi(1:4), grad(:, 1:4))
      m = 4
    end select
    if (present(nused)) nused = m
  end subroutine shape_2d

  !> The four corners (2, 4) of a CPDI parallelogram, counter-clockwise.
  pure function cpdi_corners(xp, r1, r2) result(c)
    real(dp), intent(in) :: xp(2), r1(2), r2(2)
    real(dp) :: c(2, 4)
    c(:, 1) = xp - r1 - r2
    c(:, 2) = xp + r1 - r2
    c(:, 3) = xp + r1 + r2
    c(:, 4) = xp - r1 + r2
  end function cpdi_corners

  !> CPDI weights (module comment) for half side vectors r1, r2 (m);
  !> nused: the distinct nodes, first in nodes(:), in the order the corners
  !> 1-4 first reach them; past nused, phi and grad are 0 and the node is
  !> nodes(1). A corner's four nodes are distinct, so each node's value of a
  !> corner is that corner's weight, unsummed. The nodes are found by their
  !> place in the box of the corners' cells (a table of at most 4 x 4 slots)
  !> or, for a box wider than that (a particle stretched over more than two
  !> cells), by a search of the list. Only the unused entries are zeroed
  !> (zeroing all 16 first is slower, though fewer instructions).
  pure subroutine cpdi_2d(xp, r1, r2, origin, h, nx, nodes, phi, grad, nused)
    real(dp), intent(in) :: xp(2), r1(2), r2(2), origin(2), h
    integer, intent(in) :: nx
    integer, intent(out) :: nodes(16)
    real(dp), intent(out) :: phi(16), grad(2, 16)
    integer, intent(out) :: nused
    real(dp) :: c(2, 4), sc(4, 4), vol, w(16, 4), v13(2), v24(2)
    integer :: cell(2, 4), slot(16), lo(2), a, j, k, m, node, base, corner_node, node_off(4)
    ! node m of a corner, in the order of bilinear's loops (x fastest): its
    ! offset in the 4 x 4 box of slots and in the grid's numbering
    integer, parameter :: box_off(4) = [0, 1, 4, 5]
    c = cpdi_corners(xp, r1, r2)
    do a = 1, 4
      call bilinear_weights(c(:, a), origin, h, cell(:, a), sc(:, a))
    end do
    lo(1) = min(cell(1, 1), cell(1, 2), cell(1, 3), cell(1, 4))
    lo(2) = min(cell(2, 1), cell(2, 2), cell(2, 3), cell(2, 4))
    nused = 0
    node_off = [0, 1, nx, nx + 1]
    if (max(cell(1, 1), cell(1, 2), cell(1, 3), cell(1, 4)) - lo(1) <= 2 .and. &
        max(cell(2, 1), cell(2, 2), cell(2, 3), cell(2, 4)) - lo(2) <= 2) then
      slot = 0
      do a = 1, 4
        corner_node = cell(1, a) + nx*cell(2, a)
        base = (cell(1, a) - lo(1)) + 4*(cell(2, a) - lo(2)) + 1
        do m = 1, 4
          j = base + box_off(m)
          k = slot(j)
          if (k == 0) then
            nused = nused + 1
            k = nused
            slot(j) = k
            nodes(k) = corner_node + node_off(m)
            w(k, :) = 0.0_dp
          end if
          w(k, a) = w(k, a) + sc(m, a)
        end do
      end do
    else
      do a = 1, 4
        corner_node = cell(1, a) + nx*cell(2, a)
        do m = 1, 4
          node = corner_node + node_off(m)
          k = findloc(nodes(1:nused), node, dim=1)
          if (k == 0) then
            nused = nused + 1
            k = nused
            nodes(k) = node
            w(k, :) = 0.0_dp
          end if
          w(k, a) = w(k, a) + sc(m, a)
        end do
      end do
    end if
    vol = 4.0_dp*abs(r1(1)*r2(2) - r1(2)*r2(1))
    v13 = [r1(2) - r2(2), r2(1) - r1(1)]
    v24 = [r1(2) + r2(2), -r1(1) - r2(1)]
    do k = 1, nused
      ! the corners summed in their order, as sum() did (no weight is -0)
      phi(k) = 0.25_dp*(((w(k, 1) + w(k, 2)) + w(k, 3)) + w(k, 4))
      grad(:, k) = ((w(k, 1) - w(k, 3))*v13 + (w(k, 2) - w(k, 4))*v24)/vol
    end do
    do k = nused + 1, 16
      nodes(k) = nodes(1)
      phi(k) = 0.0_dp
      grad(1, k) = 0.0_dp
      grad(2, k) = 0.0_dp
    end do
  end subroutine cpdi_2d

  !> The cell (i, j) holding x and the bilinear weights of its four nodes
  !> (x fastest): the arithmetic of bilinear's phi, without the gradients.
  pure subroutine bilinear_weights(x, origin, h, cell, phi)
    real(dp), intent(in) :: x(2), origin(2), h
    integer, intent(out) :: cell(2)
    real(dp), intent(out) :: phi(4)
    real(dp) :: s(2), fr(2)
    s = (x - origin)/h
    cell = floor(s)
    fr = s - cell
    phi(1) = (1.0_dp - fr(1))*(1.0_dp - fr(2))
    phi(2) = fr(1)*(1.0_dp - fr(2))
    phi(3) = (1.0_dp - fr(1))*fr(2)
    phi(4) = fr(1)*fr(2)
  end subroutine bilinear_weights

  !> Bilinear hats of the cell holding x: 4 nodes, weights, gradients (the
  !> cell's own gradients, also on its edges, so they always sum to zero).
  pure subroutine bilinear(x, origin, h, nx, nodes, phi, grad)
    real(dp), intent(in) :: x(2), origin(2), h
    integer, intent(in) :: nx
    integer, intent(out) :: nodes(4)
    real(dp), intent(out) :: phi(4), grad(2, 4)
    real(dp) :: sx(2), sy(2), dsx(2), dsy(2), s(2), fr(2)
    integer :: i0(2), a, b, k
    s = (x - origin)/h
    i0 = floor(s)
    fr = s - i0
    sx = [1.0_dp - fr(1), fr(1)]
    sy = [1.0_dp - fr(2), fr(2)]
    dsx = [-1.0_dp, 1.0_dp]/h
    dsy = dsx
    k = 0
    do b = 1, 2
      do a = 1, 2
        k = k + 1
        nodes(k) = (i0(1) + a - 1) + nx*(i0(2) + b - 1)
        phi(k) = sx(a)*sy(b)
        grad(:, k) = [dsx(a)*sy(b), sx(a)*dsy(b)]
      end do
    end do
  end subroutine bilinear

end module wellposed_mpm_shape_2d
