!> The implicit step's nodal forces and their tangent (docs/research/implicit.md):
!> the internal force of eq. 4.5 in the step's end configuration written on
!> the start's weights, f_i = -sum_p P_p G_ip V_n,p with P = J sigma F^-T
!> (F = I + H, H = sum_i du_i G_i the step's displacement gradient), and
!> A = -dR/du from dP = (dJ sigma + J dsigma - J sigma F^-T dH^T) F^-T,
!> dsigma = DDSDDE d eps plus the Jaumann rotation's term of the plate.
!> In 1D P is sigma and A is sum G G DDSDDE V_n.
module wellposed_mpm_implicit_forces
  use wellposed_kinds, only: dp
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_linear_solver, only: linear_solver_t
  implicit none
  private
  public :: residual, assemble, assemble_hoop, row_nonzeros

contains

  !> R = f_ext + f_int (- inertia: the dynamic step's m a) on the free
  !> degrees of freedom dof(d, i) (0: not free), this rank's share: its
  !> particles' forces, and the loads and inertia of the nodes it owns
  !> (g%ilo .. g%ihi: every node on one rank); mag, the same share of each
  !> node's sum of |P G V_n| terms, |f_ext| and |inertia|, whose largest is
  !> the residual's scale (wellposed_mpm_implicit_dofs sums the shares). An
  !> axisymmetric scene gives each particle's radius and its step's hoop
  !> stretch r / r_n: J takes the stretch and f_r,i the hoop stress's
  !> -phi_ip sigma_tt V / r.
  subroutine residual(sc, dof, vn, r, mag, inertia, radius, stretch)
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: dof(:, sc%grid%glo:)
    real(dp), intent(in) :: vn(:)
    real(dp), intent(out) :: r(:), mag(:, sc%grid%glo:)
    real(dp), intent(in), optional :: inertia(:, sc%grid%glo:), radius(:), stretch(:)
    real(dp) :: pk(sc%ndim, sc%ndim), f, hoop
    integer :: p, a, i, d, nd
    nd = sc%ndim
    associate (g => sc%grid, pt => sc%parts)
      r = 0.0_dp
      mag = 0.0_dp
      mag(:, g%ilo:g%ihi) = abs(g%fext(1:nd, g%ilo:g%ihi))
      if (present(inertia)) mag(:, g%ilo:g%ihi) = mag(:, g%ilo:g%ihi) + &
        abs(inertia(:, g%ilo:g%ihi))
      do p = 1, pt%n
        pk = first_piola(sc, p)
        hoop = 0.0_dp
        if (present(radius)) then
          pk = pk*stretch(p)
          hoop = pt%stress(3, p)*pt%vol(p)/radius(p)
        end if
        do a = 1, sc%nnz(p)
          i = pt%node(a, p)
          do d = 1, nd
            f = dot_product(pk(d, :), pt%grad(1:nd, a, p))*vn(p)
            if (d == 1) f = f + pt%phi(a, p)*hoop
            mag(d, i) = mag(d, i) + abs(f)
            if (dof(d, i) > 0) r(dof(d, i)) = r(dof(d, i)) - f
          end do
        end do
      end do
      do i = g%ilo, g%ihi
        do d = 1, nd
          if (dof(d, i) <= 0) cycle
          r(dof(d, i)) = r(dof(d, i)) + g%fext(d, i)
          if (present(inertia)) r(dof(d, i)) = r(dof(d, i)) - inertia(d, i)
        end do
      end do
    end associate
  end subroutine residual

  !> A = -dR/du, A(id, je) = sum_p sum_bf G_ib C_dbef G_jf V_n,p (C = dP/dH
  !> of each particle, dtan its DDSDDE, s0 its stress at the step's start),
  !> added particle by particle as a block over its support's dofs.
  subroutine assemble(sc, solver, dof, dtan, s0, vn)
    type(mpm_scene_t), intent(in) :: sc
    type(linear_solver_t), intent(inout) :: solver
    integer, intent(in) :: dof(:, sc%grid%glo:)
    real(dp), intent(in) :: dtan(:, :), s0(:, :), vn(:)
    real(dp) :: c(sc%ndim, sc%ndim, sc%ndim, sc%ndim), t(sc%ndim, sc%ndim, sc%ndim)
    real(dp), allocatable :: ke(:, :)
    integer, allocatable :: idx(:)
    integer :: p, a, b, d, e, q, nd, k, m
    nd = sc%ndim
    call solver%zero()
    allocate (ke(nd*sc%parts%nsup, nd*sc%parts%nsup), idx(nd*sc%parts%nsup))
    associate (pt => sc%parts)
      do p = 1, pt%n
        k = sc%mat(p)
        if (sc%mats%ours(k)) then
          call piola_tangent(sc, p, dtan(:, p), s0(:, p), c, sc%mats%props(1:2, k))
        else
          call piola_tangent(sc, p, dtan(:, p), s0(:, p), c)
        end if
        m = nd*sc%nnz(p)
        do a = 1, sc%nnz(p)
          idx(nd*(a - 1) + 1:nd*a) = dof(:, pt%node(a, p))
        end do
        do b = 1, sc%nnz(p)
          ! t(d, q, e) = sum_f C_dqef G_jf, node j = node(b)
          do e = 1, nd
            do q = 1, nd
              do d = 1, nd
                t(d, q, e) = dot_product(c(d, q, e, :), pt%grad(1:nd, b, p))
              end do
            end do
          end do
          do a = 1, sc%nnz(p)
            do e = 1, nd
              do d = 1, nd
                ke(nd*(a - 1) + d, nd*(b - 1) + e) = &
                  dot_product(pt%grad(1:nd, a, p), t(d, :, e))*vn(p)
              end do
            end do
          end do
        end do
        call solver%add_block(idx(1:m), ke(1:m, 1:m))
      end do
    end associate
  end subroutine assemble

  !> The hoop terms of A for an axisymmetric scene (radius(p): each
  !> particle's): with the hoop strain's row of B, phi_b / r on the radial
  !> dof, the entries of sum_p B^T DDSDDE B V that involve it (the in-plane
  !> ones are assemble's). Small-strain: the hoop's geometric terms, of the
  !> order of the stress over the stiffness, are left out.
  subroutine assemble_hoop(sc, solver, dof, dtan, radius)
    type(mpm_scene_t), intent(in) :: sc
    type(linear_solver_t), intent(inout) :: solver
    integer, intent(in) :: dof(:, sc%grid%glo:)
    real(dp), intent(in) :: dtan(:, :), radius(:)
    real(dp), allocatable :: ke(:, :), b(:, :, :)
    integer, allocatable :: idx(:)
    real(dp) :: dd(4, 4), v
    integer :: p, a, c, d, e, m
    allocate (ke(2*sc%parts%nsup, 2*sc%parts%nsup), idx(2*sc%parts%nsup), &
              b(4, 2, sc%parts%nsup))
    associate (pt => sc%parts)
      do p = 1, pt%n
        dd = reshape(dtan(1:16, p), [4, 4])
        v = pt%vol(p)
        m = sc%nnz(p)
        ! B of node a: rows rr, zz, hoop, rz (engineering) by dofs r, z
        b = 0.0_dp
        do a = 1, m
          idx(2*a - 1:2*a) = dof(:, pt%node(a, p))
          b(1, 1, a) = pt%grad(1, a, p)
          b(2, 2, a) = pt%grad(2, a, p)
          b(3, 1, a) = pt%phi(a, p)/radius(p)
          b(4, :, a) = [pt%grad(2, a, p), pt%grad(1, a, p)]
        end do
        do c = 1, m
          do a = 1, m
            do e = 1, 2
              do d = 1, 2
                ! the hoop row of node a against every row of node c, then
                ! the in-plane rows of a against the hoop row of c
                ke(2*(a - 1) + d, 2*(c - 1) + e) = v*(b(3, d, a)*dot_product(dd(3, :), &
                  b(:, e, c)) + (b(1, d, a)*dd(1, 3) + b(2, d, a)*dd(2, 3) + &
                  b(4, d, a)*dd(4, 3))*b(3, e, c))
              end do
            end do
          end do
        end do
        call solver%add_block(idx(1:2*m), ke(1:2*m, 1:2*m))
      end do
    end associate
  end subroutine assemble_hoop

  !> The largest number of entries in a row of A: ndim times the nodes
  !> within two particle supports (w nodes wide) of a node, (2w - 1)^ndim.
  pure integer function row_nonzeros(ndim, nsup) result(m)
    integer, intent(in) :: ndim, nsup
    integer :: w
    w = nint(real(nsup, dp)**(1.0_dp/ndim))
    do while (w**ndim < nsup)
      w = w + 1
    end do
    m = ndim*(2*w - 1)**ndim
  end function row_nonzeros

  !> Particle p's first Piola stress of the step, P = J sigma F^-T with
  !> F = I + H (in-plane components; the bar's P is sigma).
  function first_piola(sc, p) result(pk)
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: p
    real(dp) :: pk(sc%ndim, sc%ndim)
    real(dp) :: f(sc%ndim, sc%ndim), finv(sc%ndim, sc%ndim), det
    call step_gradient(sc, p, f, finv, det)
    pk = det*matmul(in_plane(sc%parts%stress(:, p), sc%ndim), transpose(finv))
  end function first_piola

  !> C_abcd = dP_ab/dH_cd of particle p (see the module comment), its DDSDDE
  !> `dtan` (column-major, ntens x ntens) and stress at the start s0. The
  !> rotated start stress enters the update as the elastic trial does, so
  !> d sigma / d sigma_rot = DDSDDE C^-1 with C the isotropic stiffness of
  !> `moduli` (K, G: our UMAT's PROPS(1:2)); without them (a user's UMAT) I.
  subroutine piola_tangent(sc, p, dtan, s0, c, moduli)
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: p
    real(dp), intent(in) :: dtan(:), s0(:)
    real(dp), intent(out) :: c(:, :, :, :)
    real(dp), intent(in), optional :: moduli(2)
    real(dp) :: f(sc%ndim, sc%ndim), finv(sc%ndim, sc%ndim), det, sig(sc%ndim, sc%ndim)
    real(dp) :: dh(sc%ndim, sc%ndim), ds(sc%ndim, sc%ndim), dp_(sc%ndim, sc%ndim)
    real(dp) :: deps(sc%ntens), dsv(sc%ntens), dw, dd_(sc%ntens, sc%ntens)
    integer :: cc, dd, nd, nt
    nd = sc%ndim
    nt = sc%ntens
    dd_ = reshape(dtan(1:nt*nt), [nt, nt])
    call step_gradient(sc, p, f, finv, det)
    sig = in_plane(sc%parts%stress(:, p), nd)
    do dd = 1, nd
      do cc = 1, nd
        dh = 0.0_dp
        dh(cc, dd) = 1.0_dp
        deps = 0.0_dp
        deps(1) = dh(1, 1)
        if (nd == 2) then
          deps(2) = dh(2, 2)
          deps(4) = dh(1, 2) + dh(2, 1)
        end if
        dsv = matmul(dd_, deps)
        ds = in_plane(dsv, nd)
        if (nd == 2) then
          ! the Jaumann rotation of the start's stress (plate_kinematics),
          ! through d sigma / d sigma_rot = DDSDDE C^-1 (see above)
          dw = 0.5_dp*(dh(1, 2) - dh(2, 1))
          dsv = [2.0_dp*dw*s0(4), -2.0_dp*dw*s0(4), 0.0_dp, dw*(s0(2) - s0(1))]
          if (present(moduli)) dsv = matmul(dd_, compliance(moduli, dsv))
          ds = ds + in_plane(dsv, nd)
        end if
        dp_ = det*finv(dd, cc)*sig + det*ds - det*matmul(sig, matmul(transpose(finv), &
                                                                     transpose(dh)))
        c(:, :, cc, dd) = matmul(dp_, transpose(finv))
      end do
    end do
  end subroutine piola_tangent

  !> The step's F = I + H of particle p (H = dt lgrad), its inverse and det.
  pure subroutine step_gradient(sc, p, f, finv, det)
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: p
    real(dp), intent(out) :: f(:, :), finv(:, :), det
    integer :: d
    f = sc%dt*sc%lgrad(1:sc%ndim, 1:sc%ndim, p)
    do d = 1, sc%ndim
      f(d, d) = f(d, d) + 1.0_dp
    end do
    if (sc%ndim == 1) then
      det = f(1, 1)
      finv = 1.0_dp/det
    else
      det = f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1)
      finv = reshape([f(2, 2), -f(2, 1), -f(1, 2), f(1, 1)], [2, 2])/det
    end if
  end subroutine step_gradient

  !> Plane-strain strains (engineering shear) of the stress change ds under
  !> the isotropic stiffness of moduli = (K, G): C^-1 ds.
  pure function compliance(moduli, ds) result(de)
    real(dp), intent(in) :: moduli(2), ds(4)
    real(dp) :: de(4), mean
    mean = sum(ds(1:3))/3.0_dp
    de(1:3) = mean/(3.0_dp*moduli(1)) + (ds(1:3) - mean)/(2.0_dp*moduli(2))
    de(4) = ds(4)/moduli(2)
  end function compliance

  !> The in-plane stress matrix of a Voigt vector (11, 22, 33, 12; 1D: 11).
  pure function in_plane(s, nd) result(m)
    real(dp), intent(in) :: s(:)
    integer, intent(in) :: nd
    real(dp) :: m(nd, nd)
    if (nd == 1) then
      m(1, 1) = s(1)
    else
      m = reshape([s(1), s(4), s(4), s(2)], [2, 2])
    end if
  end function in_plane

end module wellposed_mpm_implicit_forces
