!> The frictionless platen (platen = 'contact') in the quasi-static implicit
!> step (docs/research/implicit.md, "The contact platen"): the explicit
!> penalty's law without its damping and step cap, f = -k g (never a pull),
!> k = M w / lp_y, on the gap g of each top edge above the platen at the
!> step's end, linear in du (x_p + lp_y F e_y, F = (I + H) F_n) and summed
!> as the start's gap plus the step's change (rounding-free); the force
!> half to each end of the start's edge by the bilinear weights, so the
!> tangent is exact on the contact set.
module wellposed_mpm_implicit_contact
  use wellposed_kinds, only: dp
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t
  use wellposed_mpm_shape_2d, only: shape_2d, shape2d_linear
  use wellposed_mpm_plate_kind, only: plate_kind_t, platen_velocity
  use wellposed_mpm_plate_config, only: platen_contact, bc_velocity
  use wellposed_mpm_linear_solver, only: linear_solver_t
  implicit none
  private
  public :: contact_platen, contact_residual, contact_tangent

contains

  !> Whether scene kind `kind` has the contact platen; `plane`, its plane's
  !> height at the step's start and its motion over the step (m).
  logical function contact_platen(sc, kind, plane) result(on)
    type(mpm_scene_t), intent(in) :: sc
    class(scene_kind_t), intent(in) :: kind
    real(dp), intent(out) :: plane(2)
    on = .false.
    plane = 0.0_dp
    select type (kind)
    class is (plate_kind_t)
      on = kind%cfg%top == bc_velocity .and. kind%cfg%platen == platen_contact
      if (on) plane = [kind%cfg%height + kind%top_disp, &
                       platen_velocity(kind%cfg, sc%t, sc%dt)*sc%dt]
    end select
  end function contact_platen

  !> The platen's push at the iterate du (x0, f0: the start's positions and
  !> F; plane: contact_platen's) added to this rank's share of R on the free
  !> dofs and to the nodal magnitudes mag (wellposed_mpm_implicit_forces).
  subroutine contact_residual(sc, plane, x0, f0, du, dof, r, mag)
    type(mpm_scene_t), intent(in) :: sc
    real(dp), intent(in) :: plane(2), x0(:, :), f0(:, :, :), du(:, sc%grid%glo:)
    integer, intent(in) :: dof(:, sc%grid%glo:)
    real(dp), intent(inout) :: r(:), mag(:, sc%grid%glo:)
    real(dp) :: gap, k, phi(4, 2), f, dg(sc%parts%nsup)
    integer :: p, e, a, nodes(4, 2), i
    do p = 1, sc%parts%n
      call edge_contact(sc, p, plane, x0(:, p), f0(:, :, p), du, gap, k, nodes, phi, dg)
      if (.not. gap > 0.0_dp) cycle
      f = -0.5_dp*k*gap
      do e = 1, 2
        do a = 1, 4
          i = nodes(a, e)
          if (i < sc%grid%glo .or. i > sc%grid%ghi) cycle
          mag(2, i) = mag(2, i) + abs(phi(a, e)*f)
          if (dof(2, i) > 0) r(dof(2, i)) = r(dof(2, i)) + phi(a, e)*f
        end do
      end do
    end do
  end subroutine contact_residual

  !> The push's share of A = -dR/du: for each particle in contact,
  !> k/2 phi_edge,a dg/du_y,j with dg/du_y,j = phi_jp + lp_y (G_j1 F_n,12 +
  !> G_j2 F_n,22) (the start's weights), on the y dofs.
  subroutine contact_tangent(sc, plane, x0, f0, du, dof, solver)
    type(mpm_scene_t), intent(in) :: sc
    real(dp), intent(in) :: plane(2), x0(:, :), f0(:, :, :), du(:, sc%grid%glo:)
    integer, intent(in) :: dof(:, sc%grid%glo:)
    type(linear_solver_t), intent(inout) :: solver
    real(dp) :: gap, k, phi(4, 2), w(4)
    real(dp), allocatable :: dg(:), block(:, :)
    integer, allocatable :: idx(:)
    integer :: p, e, a, j, m, nodes(4, 2)
    associate (pt => sc%parts)
      allocate (dg(pt%nsup), idx(8 + pt%nsup), block(8 + pt%nsup, 8 + pt%nsup))
      do p = 1, pt%n
        call edge_contact(sc, p, plane, x0(:, p), f0(:, :, p), du, gap, k, nodes, phi, dg)
        if (.not. gap > 0.0_dp) cycle
        m = sc%nnz(p)
        ! rows: the edges' 8 y dofs; columns: the particle's support's
        block = 0.0_dp
        idx = 0
        do e = 1, 2
          w = 0.5_dp*k*phi(:, e)
          do a = 1, 4
            if (nodes(a, e) >= sc%grid%glo .and. nodes(a, e) <= sc%grid%ghi) &
              idx(4*(e - 1) + a) = dof(2, nodes(a, e))
            block(4*(e - 1) + a, 9:8 + m) = w(a)*dg(1:m)
          end do
        end do
        do j = 1, m
          idx(8 + j) = dof(2, pt%node(j, p))
        end do
        call solver%add_block(idx(1:8 + m), block(1:8 + m, 1:8 + m))
      end do
    end associate
  end subroutine contact_tangent

  !> Particle p's top edge at the iterate du: its gap above the platen's
  !> plane, the start's gap plus sum_j dg_j du_y,j less the plane's motion,
  !> dg_j = phi_jp + lp_y (G_j1 F_n,12 + G_j2 F_n,22) (the start's weights);
  !> the penalty k = M 2 |r1_x| / lp_y (r1 = lp_x F_n e_x); and each end of
  !> the start's edge (x0 + r2 -+ r1) with its 4 nodes and bilinear weights.
  subroutine edge_contact(sc, p, plane, x0, f0, du, gap, k, nodes, phi, dg)
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: p
    real(dp), intent(in) :: plane(2), x0(:), f0(:, :), du(:, sc%grid%glo:)
    real(dp), intent(out) :: gap, k, phi(4, 2), dg(:)
    integer, intent(out) :: nodes(4, 2)
    real(dp) :: r1(2), r2(2), grad(2, 4)
    integer :: e, j
    associate (pt => sc%parts)
      r1 = pt%lp(1, p)*f0(1:2, 1)
      r2 = pt%lp(2, p)*f0(1:2, 2)
      gap = x0(2) + r2(2) - plane(1) - plane(2)
      do j = 1, sc%nnz(p)
        dg(j) = pt%phi(j, p) + pt%lp(2, p)*(pt%grad(1, j, p)*f0(1, 2) + &
                                              pt%grad(2, j, p)*f0(2, 2))
        gap = gap + dg(j)*du(2, pt%node(j, p))
      end do
      k = sc%modulus_elastic*2.0_dp*abs(r1(1))/pt%lp(2, p)
      do e = 1, 2
        call shape_2d(shape2d_linear, x0 + r2 + (2*e - 3)*r1, pt%lp(:, p), &
                      f0(1:2, 1:2), sc%origin, sc%dx, sc%nx, nodes(:, e), phi(:, e), grad)
      end do
    end associate
  end subroutine edge_contact

end module wellposed_mpm_implicit_contact
