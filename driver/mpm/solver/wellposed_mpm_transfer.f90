!> The transfers of one explicit MPM step (section 4.3) for ndim = 1 and 2:
!> P2G (lumped mass eq. 4.4, momentum, internal force eq. 4.5), the grid
!> update with its boundary conditions (eq. 4.9-4.10), G2P (FLIP eq. 4.13,
!> position eq. 4.12), the MUSL rebuild and the velocity gradient (eq.
!> 4.11), over each particle's precomputed support and the patch's nodes.
!> Each dimension keeps its own order of summation, so every bar and plate
!> reproduces its reference bit for bit; `nnz` skips a CPDI particle's
!> unused support entries. Sums over ranks are the caller's.
module wellposed_mpm_transfer
  use wellposed_kinds, only: dp
  use wellposed_mpm_grid, only: grid_t, grid_reset, zero
  use wellposed_mpm_particles, only: particles_t
  implicit none
  private
  public :: p2g, grid_update, velocity_from_momentum, g2p, velocity_gradients

contains

  !> Mass, momentum and internal force of particles 1 .. n on the grid
  !> (the grid's sums zeroed first). The force takes sigma - q I in the
  !> plane (q: a viscous pressure per particle, optional). Components of
  !> the stress: Abaqus order (11, 22, 33, 12, ...).
  subroutine p2g(g, pt, n, q, nnz)
    type(grid_t), intent(inout) :: g
    type(particles_t), intent(in) :: pt
    integer, intent(in) :: n
    real(dp), intent(in), optional :: q(:)
    integer, intent(in), optional :: nnz(:)
    call grid_reset(g)
    if (g%ndim == 1) then
      ! a bar's supports are full (nnz = nsup): the node count is a constant
      select case (pt%nsup)
      case (3)
        call p2g_bar(n, 3, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, pt%stress, &
                     size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q)
      case (2)
        call p2g_bar(n, 2, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, pt%stress, &
                     size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q)
      case default
        call p2g_bar(n, pt%nsup, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, pt%stress, &
                     size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q)
      end select
    else
      call p2g_plate(n, pt%nsup, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, pt%stress, &
                     size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q, nnz)
    end if
  end subroutine p2g

  !> p2g of a bar on plain arrays: explicit shapes carry no descriptors to
  !> reload after each store to the grid, and dummies are distinct, so the
  !> particle's factors stay in registers. The arithmetic is p2g's. Every
  !> support is full (m nodes): called with a constant m, the node loop
  !> unrolls.
  pure subroutine p2g_bar(n, m, node, phi, grad, mass, v, vol, stress, ns, glo, ghi, gp, gm, &
                          gf, q)
    integer, value :: m
    integer, intent(in) :: n, ns, glo, ghi, node(m, *)
    real(dp), intent(in) :: phi(m, *), grad(m, *), mass(*), v(*), vol(*), stress(ns, *)
    real(dp), intent(inout) :: gp(glo:ghi), gm(glo:ghi), gf(glo:ghi)
    real(dp), intent(in), optional :: q(*)
    integer :: p, k, i
    real(dp) :: w, qp, mp, v1, vs
    do p = 1, n
      qp = 0.0_dp
      if (present(q)) qp = q(p)
      mp = mass(p)
      v1 = v(p)
      vs = vol(p)*(stress(1, p) - qp)
      do k = 1, m
        i = node(k, p)
        w = phi(k, p)*mp
        gm(i) = gm(i) + w
        gp(i) = gp(i) + w*v1
        gf(i) = gf(i) - vs*grad(k, p)
      end do
    end do
  end subroutine p2g_bar

  !> p2g of a plate on plain arrays (as p2g_bar); the force V (sigma G),
  !> eq. 4.5.
  pure subroutine p2g_plate(n, m, node, phi, grad, mass, v, vol, stress, ns, glo, ghi, gp, gm, &
                            gf, q, nnz)
    integer, intent(in) :: n, m, ns, glo, ghi, node(m, *)
    real(dp), intent(in) :: phi(m, *), grad(2, m, *), mass(*), v(2, *), vol(*), stress(ns, *)
    real(dp), intent(inout) :: gp(2, glo:ghi), gm(glo:ghi), gf(2, glo:ghi)
    real(dp), intent(in), optional :: q(*)
    integer, intent(in), optional :: nnz(*)
    integer :: p, k, i, mk
    real(dp) :: w, qp, s11, s22, s12, vl, f1, f2, mp, v1, v2
    mk = m
    do p = 1, n
      qp = 0.0_dp
      if (present(q)) qp = q(p)
      if (present(nnz)) mk = nnz(p)
      s11 = stress(1, p) - qp
      s22 = stress(2, p) - qp
      s12 = stress(4, p)
      vl = vol(p)
      mp = mass(p)
      v1 = v(1, p)
      v2 = v(2, p)
      do k = 1, mk
        i = node(k, p)
        w = phi(k, p)*mp
        gm(i) = gm(i) + w
        gp(1, i) = gp(1, i) + w*v1
        gp(2, i) = gp(2, i) + w*v2
        f1 = s11*grad(1, k, p) + s12*grad(2, k, p)
        f2 = s12*grad(1, k, p) + s22*grad(2, k, p)
        gf(1, i) = gf(1, i) - vl*f1
        gf(2, i) = gf(2, i) - vl*f2
      end do
    end do
  end subroutine p2g_plate

  !> Acceleration and velocity of every patch node, eq. 4.9-4.10 (nodes at
  !> or below `mmin` count as empty), then the boundary conditions: a
  !> fixed component is held at rest and its nodal force enters `reaction`
  !> (owned nodes only, so the ranks' shares add up), a given component
  !> takes `given(d)`.
  subroutine grid_update(g, dt, mmin, given, reaction)
    type(grid_t), intent(inout) :: g
    real(dp), intent(in) :: dt, mmin, given(:)
    real(dp), intent(out) :: reaction(:)
    reaction = 0.0_dp
    ! the dimension as a constant: its loops vanish in 1D
    if (g%ndim == 1) then
      call update_nodes(1, g%glo, g%ghi, g%ilo, g%ihi, dt, mmin, given, g%mass, g%momentum, &
                        g%fint, g%fext, g%fixed, g%given, g%accel, g%velocity, reaction)
    else
      call update_nodes(2, g%glo, g%ghi, g%ilo, g%ihi, dt, mmin, given, g%mass, g%momentum, &
                        g%fint, g%fext, g%fixed, g%given, g%accel, g%velocity, reaction)
    end if
  end subroutine grid_update

  !> grid_update on plain arrays of nd components per node.
  pure subroutine update_nodes(nd, glo, ghi, ilo, ihi, dt, mmin, given, mass, momentum, fint, &
                               fext, fixed, is_given, accel, velocity, reaction)
    integer, value :: nd
    integer, intent(in) :: glo, ghi, ilo, ihi
    real(dp), intent(in) :: dt, mmin, given(nd), mass(glo:ghi)
    real(dp), intent(in), dimension(nd, glo:ghi) :: momentum, fint, fext
    logical, intent(in), dimension(nd, glo:ghi) :: fixed, is_given
    real(dp), intent(inout), dimension(nd, glo:ghi) :: accel, velocity
    real(dp), intent(inout) :: reaction(nd)
    integer :: i, d
    do i = glo, ghi
      do d = 1, nd
        if (mass(i) > mmin) then
          accel(d, i) = (fint(d, i) + fext(d, i))/mass(i)
          velocity(d, i) = momentum(d, i)/mass(i) + accel(d, i)*dt
        else
          accel(d, i) = 0.0_dp
          velocity(d, i) = 0.0_dp
        end if
        if (fixed(d, i)) then
          if (i >= ilo .and. i <= ihi) reaction(d) = reaction(d) - (fint(d, i) + fext(d, i))
          accel(d, i) = 0.0_dp
          velocity(d, i) = 0.0_dp
        else if (is_given(d, i)) then
          accel(d, i) = 0.0_dp
          velocity(d, i) = given(d)
        end if
      end do
    end do
  end subroutine update_nodes

  !> MUSL: the grid velocity from the rebuilt momentum (no acceleration),
  !> with the boundary conditions of grid_update.
  subroutine velocity_from_momentum(g, mmin, given)
    type(grid_t), intent(inout) :: g
    real(dp), intent(in) :: mmin, given(:)
    call zero(g%accel, size(g%accel))
    if (g%ndim == 1) then
      call rebuild_nodes(1, g%glo, g%ghi, mmin, given, g%mass, g%momentum, g%fixed, g%given, &
                         g%velocity)
    else
      call rebuild_nodes(2, g%glo, g%ghi, mmin, given, g%mass, g%momentum, g%fixed, g%given, &
                         g%velocity)
    end if
  end subroutine velocity_from_momentum

  !> velocity_from_momentum on plain arrays of nd components per node.
  pure subroutine rebuild_nodes(nd, glo, ghi, mmin, given, mass, momentum, fixed, is_given, &
                                velocity)
    integer, value :: nd
    integer, intent(in) :: glo, ghi
    real(dp), intent(in) :: mmin, given(nd), mass(glo:ghi), momentum(nd, glo:ghi)
    logical, intent(in), dimension(nd, glo:ghi) :: fixed, is_given
    real(dp), intent(inout) :: velocity(nd, glo:ghi)
    integer :: i, d
    do i = glo, ghi
      do d = 1, nd
        if (mass(i) > mmin) then
          velocity(d, i) = momentum(d, i)/mass(i)
        else
          velocity(d, i) = 0.0_dp
        end if
        if (fixed(d, i)) then
          velocity(d, i) = 0.0_dp
        else if (is_given(d, i)) then
          velocity(d, i) = given(d)
        end if
      end do
    end do
  end subroutine rebuild_nodes

  !> FLIP velocity (eq. 4.13) and position (eq. 4.12) of particles 1 .. n;
  !> with `musl`, also MUSL's rebuild of the grid momentum from the updated
  !> velocities (sum over the particles in order of phi m v, as P2G's), in
  !> the same pass.
  subroutine g2p(g, pt, n, dt, nnz, musl)
    type(grid_t), intent(inout) :: g
    type(particles_t), intent(inout) :: pt
    integer, intent(in) :: n
    real(dp), intent(in) :: dt
    integer, intent(in), optional :: nnz(:)
    logical, intent(in), optional :: musl
    logical :: rebuild
    rebuild = .false.
    if (present(musl)) rebuild = musl
    if (rebuild) call zero(g%momentum, size(g%momentum))
    if (g%ndim == 1) then
      select case (pt%nsup)
      case (3)
        call g2p_bar(n, 3, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, pt%v, &
                     pt%x, rebuild, pt%mass, g%momentum)
      case (2)
        call g2p_bar(n, 2, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, pt%v, &
                     pt%x, rebuild, pt%mass, g%momentum)
      case default
        call g2p_bar(n, pt%nsup, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, pt%v, &
                     pt%x, rebuild, pt%mass, g%momentum)
      end select
    else
      call g2p_plate(n, pt%nsup, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, &
                     pt%v, pt%x, rebuild, pt%mass, g%momentum, nnz)
    end if
  end subroutine g2p

  !> g2p of a bar on plain arrays (as p2g_bar): the weighted nodal sums,
  !> then the step; with `rebuild`, the particle's new momentum onto gp.
  pure subroutine g2p_bar(n, m, node, phi, glo, ghi, ga, gv, dt, v, x, rebuild, mass, gp)
    integer, value :: m
    logical, value :: rebuild
    integer, intent(in) :: n, glo, ghi, node(m, *)
    real(dp), intent(in) :: phi(m, *), ga(glo:ghi), gv(glo:ghi), dt, mass(*)
    real(dp), intent(inout) :: v(*), x(*), gp(glo:ghi)
    integer :: p, k, i
    real(dp) :: vs, ds
    do p = 1, n
      vs = 0.0_dp
      ds = 0.0_dp
      do k = 1, m
        i = node(k, p)
        vs = vs + phi(k, p)*ga(i)
        ds = ds + phi(k, p)*gv(i)
      end do
      v(p) = v(p) + dt*vs
      x(p) = x(p) + dt*ds
      if (rebuild) then
        do k = 1, m
          i = node(k, p)
          gp(i) = gp(i) + (phi(k, p)*mass(p))*v(p)
        end do
      end if
    end do
  end subroutine g2p_bar

  !> g2p of a plate on plain arrays (as g2p_bar): velocity and position
  !> advanced node by node with w = dt phi, in scalars; with `rebuild`, the
  !> particle's new momentum onto gp.
  pure subroutine g2p_plate(n, m, node, phi, glo, ghi, ga, gv, dt, v, x, rebuild, mass, gp, &
                            nnz)
    logical, value :: rebuild
    integer, intent(in) :: n, m, glo, ghi, node(m, *)
    real(dp), intent(in) :: phi(m, *), ga(2, glo:ghi), gv(2, glo:ghi), dt, mass(*)
    real(dp), intent(inout) :: v(2, *), x(2, *), gp(2, glo:ghi)
    integer, intent(in), optional :: nnz(*)
    integer :: p, k, i, mk
    real(dp) :: w, v1, v2, x1, x2
    mk = m
    do p = 1, n
      if (present(nnz)) mk = nnz(p)
      v1 = v(1, p)
      v2 = v(2, p)
      x1 = x(1, p)
      x2 = x(2, p)
      do k = 1, mk
        i = node(k, p)
        w = dt*phi(k, p)
        v1 = v1 + w*ga(1, i)
        v2 = v2 + w*ga(2, i)
        x1 = x1 + w*gv(1, i)
        x2 = x2 + w*gv(2, i)
      end do
      v(1, p) = v1
      v(2, p) = v2
      x(1, p) = x1
      x(2, p) = x2
      if (rebuild) then
        do k = 1, mk
          i = node(k, p)
          w = phi(k, p)*mass(p)
          gp(1, i) = gp(1, i) + w*v1
          gp(2, i) = gp(2, i) + w*v2
        end do
      end if
    end do
  end subroutine g2p_plate

  !> Velocity gradients of particles 1 .. n, eq. 4.11: lg(a, b, p) = d v_a /
  !> d x_b (ndim x ndim each) from the grid velocity, one call for all.
  subroutine velocity_gradients(g, pt, n, lg, nnz)
    type(grid_t), intent(in) :: g
    type(particles_t), intent(in) :: pt
    integer, intent(in) :: n
    real(dp), intent(out), contiguous :: lg(:, :, :)
    integer, intent(in), optional :: nnz(:)
    if (g%ndim == 1) then
      select case (pt%nsup)
      case (3)
        call gradient_bar(n, 3, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg)
      case (2)
        call gradient_bar(n, 2, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg)
      case default
        call gradient_bar(n, pt%nsup, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg)
      end select
    else
      call gradient_plate(n, pt%nsup, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg, nnz)
    end if
  end subroutine velocity_gradients

  !> The bar's velocity gradients on plain arrays (as p2g_bar): each a sum
  !> from zero over the particle's nodes, in their order.
  pure subroutine gradient_bar(n, m, node, grad, glo, ghi, gv, l11)
    integer, value :: m
    integer, intent(in) :: n, glo, ghi, node(m, *)
    real(dp), intent(in) :: grad(m, *), gv(glo:ghi)
    real(dp), intent(out) :: l11(*)
    integer :: p, k
    real(dp) :: l
    do p = 1, n
      l = 0.0_dp
      do k = 1, m
        l = l + gv(node(k, p))*grad(k, p)
      end do
      l11(p) = l
    end do
  end subroutine gradient_bar

  !> The plate's velocity gradients on plain arrays: sums in scalars from
  !> zero, node by node in their order.
  pure subroutine gradient_plate(n, m, node, grad, glo, ghi, gv, lg, nnz)
    integer, intent(in) :: n, m, glo, ghi, node(m, *)
    real(dp), intent(in) :: grad(2, m, *), gv(2, glo:ghi)
    real(dp), intent(out) :: lg(2, 2, *)
    integer, intent(in), optional :: nnz(*)
    integer :: p, k, i, mk
    real(dp) :: l11, l21, l12, l22
    mk = m
    do p = 1, n
      if (present(nnz)) mk = nnz(p)
      l11 = 0.0_dp
      l21 = 0.0_dp
      l12 = 0.0_dp
      l22 = 0.0_dp
      do k = 1, mk
        i = node(k, p)
        l11 = l11 + gv(1, i)*grad(1, k, p)
        l21 = l21 + gv(2, i)*grad(1, k, p)
        l12 = l12 + gv(1, i)*grad(2, k, p)
        l22 = l22 + gv(2, i)*grad(2, k, p)
      end do
      lg(1, 1, p) = l11
      lg(2, 1, p) = l21
      lg(1, 2, p) = l12
      lg(2, 2, p) = l22
    end do
  end subroutine gradient_plate

end module wellposed_mpm_transfer
