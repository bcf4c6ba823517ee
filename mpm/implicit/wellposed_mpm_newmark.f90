!> The trapezoidal (Newmark beta = 1/4, gamma = 1/2) rule of the implicit
!> dynamic step (docs/research/implicit.md, "Newmark dynamics") on the grid:
!> the start's nodal v and a from the particles (p2g, lumped mass of eq.
!> 4.9), the end's acceleration of the step's du, a1 = 4 (du - dt v) / dt^2
!> - a, its inertia m_i a1 in the residual and 4 m_i / dt^2 on the tangent's
!> diagonal; the particles take a_p = sum phi a1, v_p += dt (a_p,0 + a_p) / 2.
!> Fixed dofs hold v = a = 0, given ones the given velocity and a = 0.
module wellposed_mpm_newmark
  use wellposed_kinds, only: dp
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_linear_solver, only: linear_solver_t
  implicit none
  private
  public :: newmark_t, newmark_start, newmark_inertia, newmark_tangent, newmark_particles

  !> The step's start on the grid: nodal velocity v and acceleration a.
  type :: newmark_t
    real(dp), allocatable :: v(:, :), a(:, :)
  end type newmark_t

contains

  !> The start's nodal v and a of scene sc (after p2g and the ranks' sum:
  !> g%mass, g%momentum), the particles' accelerations `accel` (ndim, n),
  !> their m a summed at the nodes the ranks share; `given`, the given
  !> velocity; du, the predictor dt v + dt^2 a / 4 (a1 = a). Collective.
  subroutine newmark_start(sc, accel, given, nm, du)
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: accel(:, :), given(:)
    type(newmark_t), intent(out) :: nm
    real(dp), intent(out) :: du(:, sc%grid%glo:)
    real(dp) :: col(sc%grid%ghi - sc%grid%glo + 1)
    integer :: p, k, i, d, nd
    nd = sc%ndim
    associate (g => sc%grid, pt => sc%parts)
      allocate (nm%v(nd, g%glo:g%ghi), nm%a(nd, g%glo:g%ghi), source=0.0_dp)
      do p = 1, pt%n
        do k = 1, sc%nnz(p)
          i = pt%node(k, p)
          nm%a(:, i) = nm%a(:, i) + pt%mass(p)*pt%phi(k, p)*accel(:, p)
        end do
      end do
      if (sc%exchange%nranks() > 1) then
        do d = 1, nd
          col = nm%a(d, :)
          call sc%exchange%nodes_sum(col)
          nm%a(d, :) = col
        end do
      end if
      do i = g%glo, g%ghi
        if (g%mass(i) > sc%mass_floor) then
          nm%v(:, i) = g%momentum(1:nd, i)/g%mass(i)
          nm%a(:, i) = nm%a(:, i)/g%mass(i)
        else
          nm%v(:, i) = 0.0_dp
          nm%a(:, i) = 0.0_dp
        end if
        do d = 1, nd
          if (g%fixed(d, i)) then
            nm%v(d, i) = 0.0_dp
            nm%a(d, i) = 0.0_dp
          else if (g%given(d, i)) then
            nm%v(d, i) = given(d)
            nm%a(d, i) = 0.0_dp
          end if
        end do
        du(:, i) = sc%dt*nm%v(:, i) + 0.25_dp*sc%dt**2*nm%a(:, i)
      end do
    end associate
  end subroutine newmark_start

  !> The end's nodal inertia m_i a1 of the step displacement du.
  pure function newmark_inertia(sc, nm, du) result(f)
    type(mpm_scene_t), intent(in) :: sc
    type(newmark_t), intent(in) :: nm
    real(dp), intent(in) :: du(:, sc%grid%glo:)
    real(dp) :: f(sc%ndim, sc%grid%glo:sc%grid%ghi)
    integer :: i
    associate (g => sc%grid)
      do i = g%glo, g%ghi
        f(:, i) = g%mass(i)*end_acceleration(sc%dt, nm, du, i)
      end do
    end associate
  end function newmark_inertia

  !> 4 m_i / dt^2 on the diagonal of each free dof (dof > 0) of the nodes
  !> this rank owns: the inertia's share of A = -dR/du.
  subroutine newmark_tangent(sc, solver, dof)
    type(mpm_scene_t), intent(in) :: sc
    type(linear_solver_t), intent(inout) :: solver
    integer, intent(in) :: dof(:, sc%grid%glo:)
    integer :: i, d
    associate (g => sc%grid)
      do i = g%ilo, g%ihi
        do d = 1, sc%ndim
          if (dof(d, i) > 0) call solver%add(dof(d, i), dof(d, i), 4.0_dp*g%mass(i)/sc%dt**2)
        end do
      end do
    end associate
  end subroutine newmark_tangent

  !> The converged step on the particles: a_p = sum phi a1 into accel, and
  !> v_p += dt (a_p,start + a_p) / 2 (the weights are the start's).
  subroutine newmark_particles(sc, nm, du, accel)
    type(mpm_scene_t), intent(inout) :: sc
    type(newmark_t), intent(in) :: nm
    real(dp), intent(in) :: du(:, sc%grid%glo:)
    real(dp), intent(inout) :: accel(:, :)
    real(dp) :: a1(sc%ndim)
    integer :: p, k
    associate (pt => sc%parts)
      do p = 1, pt%n
        a1 = 0.0_dp
        do k = 1, sc%nnz(p)
          a1 = a1 + pt%phi(k, p)*end_acceleration(sc%dt, nm, du, pt%node(k, p))
        end do
        pt%v(:, p) = pt%v(:, p) + 0.5_dp*sc%dt*(accel(:, p) + a1)
        accel(:, p) = a1
      end do
    end associate
  end subroutine newmark_particles

  !> Node i's end acceleration a1 = 4 (du - dt v) / dt^2 - a.
  pure function end_acceleration(dt, nm, du, i) result(a1)
    real(dp), intent(in) :: dt
    type(newmark_t), intent(in) :: nm
    real(dp), intent(in) :: du(:, lbound(nm%v, 2):)
    integer, intent(in) :: i
    real(dp) :: a1(size(nm%v, 1))
    a1 = 4.0_dp*(du(:, i) - dt*nm%v(:, i))/dt**2 - nm%a(:, i)
  end function end_acceleration

end module wellposed_mpm_newmark
