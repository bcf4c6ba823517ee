!> The transfers of one explicit MPM step (section 4.3) in ndim dimensions:
!> P2G (lumped mass eq. 4.4, momentum, internal force eq. 4.5), the grid
!> update with its boundary conditions (eq. 4.9-4.10), G2P (FLIP eq. 4.13,
!> position eq. 4.12), the MUSL rebuild and the velocity gradient (eq.
!> 4.11), over each particle's precomputed support and the patch's nodes.
!> Each kernel is written once over nd; where 1D rounds otherwise (noted at
!> the line) it keeps its own order, so every scene reproduces its
!> reference bit for bit. `nnz` skips a CPDI particle's unused entries.
module wellposed_mpm_transfer
  use wellposed_kinds, only: dp
  use wellposed_mpm_grid, only: grid_t, grid_reset, zero
  use wellposed_mpm_particles, only: particles_t
  implicit none
  private
  public :: p2g, grid_update, velocity_from_momentum, g2p, velocity_gradients

contains

  !> Mass, momentum and internal force of particles 1 .. n on the grid
  !> (the grid's sums zeroed first). The force takes sigma - q I (q: a
  !> viscous pressure per particle, optional). Components of the stress:
  !> Abaqus order (11, 22, 33, 12, 13, 23).
  subroutine p2g(g, pt, n, q, nnz)
    type(grid_t), intent(inout) :: g
    type(particles_t), intent(in) :: pt
    integer, intent(in) :: n
    real(dp), intent(in), optional :: q(:)
    integer, intent(in), optional :: nnz(:)
    call grid_reset(g)
    ! the dimension and, in 1D (full supports, nnz = nsup), the node count
    ! as constants: the kernel's small loops unroll
    if (g%ndim == 1 .and. pt%nsup == 3) then
      call p2g_nodes(1, n, 3, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, pt%stress, &
                     size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q)
    else if (g%ndim == 1 .and. pt%nsup == 2) then
      call p2g_nodes(1, n, 2, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, pt%stress, &
                     size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q)
    else if (g%ndim == 1) then
      call p2g_nodes(1, n, pt%nsup, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, &
                     pt%stress, size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, q)
    else if (g%ndim == 2) then
      call p2g_nodes(2, n, pt%nsup, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, &
                     pt%stress, size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, &
                     q, nnz)
    else
      call p2g_nodes(g%ndim, n, pt%nsup, pt%node, pt%phi, pt%grad, pt%mass, pt%v, pt%vol, &
                     pt%stress, size(pt%stress, 1), g%glo, g%ghi, g%momentum, g%mass, g%fint, &
                     q, nnz)
    end if
  end subroutine p2g

  !> p2g on plain arrays of nd components: explicit shapes carry no
  !> descriptors to reload after each store to the grid, and dummies are
  !> distinct, so the particle's factors stay in registers. The force on
  !> node i is -V (sigma - q I) G_i, eq. 4.5.
  pure subroutine p2g_nodes(nd, n, m, node, phi, grad, mass, v, vol, stress, ns, glo, ghi, &
                            gp, gm, gf, q, nnz)
    integer, value :: nd, m
    integer, intent(in) :: n, ns, glo, ghi, node(m, *)
    real(dp), intent(in) :: phi(m, *), grad(nd, m, *), mass(*), v(nd, *), vol(*), stress(ns, *)
    real(dp), intent(inout) :: gp(nd, glo:ghi), gm(glo:ghi), gf(nd, glo:ghi)
    real(dp), intent(in), optional :: q(*)
    integer, intent(in), optional :: nnz(*)
    integer :: p, k, i, a, b, mk
    real(dp) :: w, qp, mp, vl, sg(3, 3), f
    mk = m
    do p = 1, n
      qp = 0.0_dp
      if (present(q)) qp = q(p)
      if (present(nnz)) mk = nnz(p)
      mp = mass(p)
      vl = vol(p)
      do b = 1, nd
        do a = 1, nd
          sg(a, b) = stress(voigt(a, b), p)
        end do
        sg(b, b) = sg(b, b) - qp
      end do
      if (nd == 1) then
        ! one term: V sigma first, the 1D reference's rounding (1 V = V exactly)
        sg(1, 1) = vl*sg(1, 1)
        vl = 1.0_dp
      end if
      do k = 1, mk
        i = node(k, p)
        w = phi(k, p)*mp
        gm(i) = gm(i) + w
        do a = 1, nd
          gp(a, i) = gp(a, i) + w*v(a, p)
        end do
        do a = 1, nd
          f = sg(a, 1)*grad(1, k, p)
          do b = 2, nd
            f = f + sg(a, b)*grad(b, k, p)
          end do
          gf(a, i) = gf(a, i) - vl*f
        end do
      end do
    end do
  end subroutine p2g_nodes

  !> The row of component (a, b) of a symmetric tensor in Abaqus order:
  !> 11, 22, 33, then 12, 13, 23.
  elemental integer function voigt(a, b)
    integer, intent(in) :: a, b
    if (a == b) then
      voigt = a
    else
      voigt = a + b + 1
    end if
  end function voigt

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
    if (g%ndim == 1 .and. pt%nsup == 3) then   ! constants, as in p2g
      call g2p_nodes(1, n, 3, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, pt%v, &
                     pt%x, rebuild, pt%mass, g%momentum)
    else if (g%ndim == 1 .and. pt%nsup == 2) then
      call g2p_nodes(1, n, 2, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, pt%v, &
                     pt%x, rebuild, pt%mass, g%momentum)
    else if (g%ndim == 1) then
      call g2p_nodes(1, n, pt%nsup, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, &
                     pt%v, pt%x, rebuild, pt%mass, g%momentum)
    else if (g%ndim == 2) then
      call g2p_nodes(2, n, pt%nsup, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, dt, &
                     pt%v, pt%x, rebuild, pt%mass, g%momentum, nnz)
    else
      call g2p_nodes(g%ndim, n, pt%nsup, pt%node, pt%phi, g%glo, g%ghi, g%accel, g%velocity, &
                     dt, pt%v, pt%x, rebuild, pt%mass, g%momentum, nnz)
    end if
  end subroutine g2p

  !> g2p on plain arrays of nd components (as p2g_nodes): velocity and
  !> position advanced over the particle's nodes in scalars; with
  !> `rebuild`, the particle's new momentum onto gp.
  pure subroutine g2p_nodes(nd, n, m, node, phi, glo, ghi, ga, gv, dt, v, x, rebuild, mass, &
                            gp, nnz)
    integer, value :: nd, m
    logical, value :: rebuild
    integer, intent(in) :: n, glo, ghi, node(m, *)
    real(dp), intent(in) :: phi(m, *), ga(nd, glo:ghi), gv(nd, glo:ghi), dt, mass(*)
    real(dp), intent(inout) :: v(nd, *), x(nd, *), gp(nd, glo:ghi)
    integer, intent(in), optional :: nnz(*)
    integer :: p, k, i, a, mk
    real(dp) :: w, vs(3), xs(3)
    mk = m
    do p = 1, n
      if (present(nnz)) mk = nnz(p)
      ! 1D sums phi a and phi v from zero and steps once (its reference's
      ! rounding); otherwise each node's dt phi term is added in turn
      do a = 1, nd
        vs(a) = 0.0_dp
        xs(a) = 0.0_dp
        if (nd > 1) vs(a) = v(a, p)
        if (nd > 1) xs(a) = x(a, p)
      end do
      do k = 1, mk
        i = node(k, p)
        w = phi(k, p)
        if (nd > 1) w = dt*phi(k, p)
        do a = 1, nd
          vs(a) = vs(a) + w*ga(a, i)
          xs(a) = xs(a) + w*gv(a, i)
        end do
      end do
      do a = 1, nd
        if (nd == 1) then
          v(a, p) = v(a, p) + dt*vs(a)
          x(a, p) = x(a, p) + dt*xs(a)
        else
          v(a, p) = vs(a)
          x(a, p) = xs(a)
        end if
      end do
      if (rebuild) then
        do k = 1, mk
          i = node(k, p)
          w = phi(k, p)*mass(p)
          do a = 1, nd
            gp(a, i) = gp(a, i) + w*v(a, p)
          end do
        end do
      end if
    end do
  end subroutine g2p_nodes

  !> Velocity gradients of particles 1 .. n, eq. 4.11: lg(a, b, p) = d v_a /
  !> d x_b (ndim x ndim each) from the grid velocity, one call for all.
  subroutine velocity_gradients(g, pt, n, lg, nnz)
    type(grid_t), intent(in) :: g
    type(particles_t), intent(in) :: pt
    integer, intent(in) :: n
    real(dp), intent(out), contiguous :: lg(:, :, :)
    integer, intent(in), optional :: nnz(:)
    if (g%ndim == 1 .and. pt%nsup == 3) then   ! constants, as in p2g
      call gradient_nodes(1, n, 3, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg)
    else if (g%ndim == 1 .and. pt%nsup == 2) then
      call gradient_nodes(1, n, 2, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg)
    else if (g%ndim == 1) then
      call gradient_nodes(1, n, pt%nsup, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg)
    else if (g%ndim == 2) then
      call gradient_nodes(2, n, pt%nsup, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg, nnz)
    else
      call gradient_nodes(g%ndim, n, pt%nsup, pt%node, pt%grad, g%glo, g%ghi, g%velocity, lg, &
                          nnz)
    end if
  end subroutine velocity_gradients

  !> The velocity gradients on plain arrays (as p2g_nodes): each entry a sum
  !> in a scalar from zero, node by node in their order.
  pure subroutine gradient_nodes(nd, n, m, node, grad, glo, ghi, gv, lg, nnz)
    integer, value :: nd, m
    integer, intent(in) :: n, glo, ghi, node(m, *)
    real(dp), intent(in) :: grad(nd, m, *), gv(nd, glo:ghi)
    real(dp), intent(out) :: lg(nd, nd, *)
    integer, intent(in), optional :: nnz(*)
    integer :: p, k, i, a, b, mk
    real(dp) :: l(3, 3)
    mk = m
    do p = 1, n
      if (present(nnz)) mk = nnz(p)
      do b = 1, nd
        do a = 1, nd
          l(a, b) = 0.0_dp
        end do
      end do
      do k = 1, mk
        i = node(k, p)
        do b = 1, nd
          do a = 1, nd
            l(a, b) = l(a, b) + gv(a, i)*grad(b, k, p)
          end do
        end do
      end do
      do b = 1, nd
        do a = 1, nd
          lg(a, b, p) = l(a, b)
        end do
      end do
    end do
  end subroutine gradient_nodes

end module wellposed_mpm_transfer
