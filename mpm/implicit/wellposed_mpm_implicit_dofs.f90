!> The implicit step's unknowns over the ranks (docs/research/implicit.md,
!> "Over ranks"): the free degrees of freedom numbered over the whole grid
!> in node order, the same numbers on every rank, so the rows a rank owns
!> (its strip's nodes) follow in rank order; the free values of du and the
!> residual as whole vectors on every rank, from each rank's share. One
!> rank: the same numbers and vectors without an exchange.
module wellposed_mpm_implicit_dofs
  use wellposed_kinds, only: dp
  use wellposed_mpm_scene, only: mpm_scene_t
  implicit none
  private
  public :: number_dofs, gather_free, complete_residual, zero_mean_motion

  !> A node's mass below this share of the grid's largest: not an unknown.
  real(dp), parameter :: touched = 1.0e-6_dp

contains

  !> The free degrees of freedom: each direction of a node neither fixed nor
  !> given, of mass above `touched` of the grid's largest, numbered 1 ..
  !> nfree over the whole grid (dof(d, i), i the patch's nodes; 0: not
  !> free); rows, the numbers of this rank's own nodes (g%ilo .. g%ihi). A
  !> node a particle's domain barely reaches (a deformed CPDI corner past a
  !> node line) has next to no stiffness; as a dof its displacement is
  !> whatever keeps its residual under the tolerance (metres, next to a
  !> cylinder's end). Below `touched` a node keeps the predictor's du, its
  !> particles' motion, as the explicit step moves it (docs/research/
  !> implicit.md, "Nodes a particle barely reaches"). With `pinned`: a
  !> direction no node in use holds (no fixed or given dof: a plate free
  !> sideways) leaves a rigid translation, which no static load resists;
  !> its first free dof keeps the predictor (pinned(d) true) and
  !> zero_mean_motion moves the converged body back. Collective.
  subroutine number_dofs(sc, dof, nfree, rows, pinned)
    type(mpm_scene_t), intent(inout) :: sc
    integer, allocatable, intent(out) :: dof(:, :)
    integer, intent(out) :: nfree, rows(2)
    logical, intent(out), optional :: pinned(:)
    real(dp), allocatable :: free(:)
    real(dp) :: floor, held(sc%ndim)
    integer :: i, d, k, nd
    nd = sc%ndim
    associate (g => sc%grid)
      floor = 0.0_dp
      if (g%ghi >= g%glo) floor = maxval(g%mass)
      call sc%exchange%max_real(floor)
      floor = max(sc%mass_floor, touched*floor)
      ! each rank flags its own nodes' free directions (direction d of node
      ! i at nd i + d); the sum over the ranks is the grid's
      allocate (free(nd*g%nnodes), source=0.0_dp)
      held = 0.0_dp
      do i = g%ilo, g%ihi
        if (.not. g%mass(i) > floor) cycle
        do d = 1, nd
          if (.not. (g%fixed(d, i) .or. g%given(d, i))) then
            free(nd*i + d) = 1.0_dp
          else
            held(d) = 1.0_dp
          end if
        end do
      end do
      if (sc%exchange%nranks() > 1) call sc%exchange%sum_reals(free)
      if (present(pinned)) then
        call sc%exchange%sum_reals(held)
        do d = 1, nd
          pinned(d) = held(d) < 0.5_dp
          if (.not. pinned(d)) cycle
          k = findloc(free(d::nd) > 0.5_dp, .true., dim=1)
          if (k > 0) free(nd*(k - 1) + d) = 0.0_dp
        end do
      end if
      allocate (dof(nd, g%glo:g%ghi), source=0)
      nfree = 0
      rows = [1, 0]
      do i = 0, g%nnodes - 1
        if (i == g%ilo) rows(1) = nfree + 1
        do d = 1, nd
          k = nd*i + d
          if (free(k) < 0.5_dp) cycle
          nfree = nfree + 1
          if (i >= g%glo .and. i <= g%ghi) dof(d, i) = nfree
        end do
        if (i == g%ihi) rows(2) = nfree
      end do
    end associate
  end subroutine number_dofs

  !> The free dofs' values of du into x (dof(d, i) > 0: x(dof(d, i))), the
  !> whole vector on every rank, each rank giving its own nodes'. Collective.
  subroutine gather_free(sc, dof, du, x)
    type(mpm_scene_t), intent(inout) :: sc
    integer, intent(in) :: dof(:, sc%grid%glo:)
    real(dp), intent(in) :: du(:, sc%grid%glo:)
    real(dp), intent(out) :: x(:)
    integer :: i, d
    x = 0.0_dp
    do i = sc%grid%ilo, sc%grid%ihi
      do d = 1, sc%ndim
        if (dof(d, i) > 0) x(dof(d, i)) = du(d, i)
      end do
    end do
    if (sc%exchange%nranks() > 1) call sc%exchange%sum_reals(x)
  end subroutine gather_free

  !> The step's du of a body free in the pinned directions (number_dofs)
  !> moved rigidly so that its mass centre stays, sum_i m_i du_i = 0, as
  !> its momentum does when nothing pushes it that way (explicit); the
  !> stresses do not change (sum_i G_i = 0). Collective.
  subroutine zero_mean_motion(sc, pinned, du)
    type(mpm_scene_t), intent(inout) :: sc
    logical, intent(in) :: pinned(:)
    real(dp), intent(inout) :: du(:, sc%grid%glo:)
    real(dp) :: sums(2*sc%ndim)
    integer :: d, nd
    nd = sc%ndim
    if (.not. any(pinned)) return
    associate (g => sc%grid)
      do d = 1, nd
        sums(d) = sum(g%mass(g%ilo:g%ihi)*du(d, g%ilo:g%ihi))
      end do
      sums(nd + 1:) = sum(g%mass(g%ilo:g%ihi))
      call sc%exchange%sum_reals(sums)
      do d = 1, nd
        if (pinned(d) .and. sums(nd + d) > 0.0_dp) du(d, :) = du(d, :) - sums(d)/sums(nd + d)
      end do
    end associate
  end subroutine zero_mean_motion

  !> The residual r and its scale over the ranks: r, this rank's share (its
  !> particles' forces, the loads and inertia of its own nodes) summed into
  !> the whole vector on every rank; mag, the nodal magnitudes of the same
  !> shares, summed at the nodes the ranks share; scale, their largest
  !> over the grid. Collective; one rank: scale = maxval(mag).
  subroutine complete_residual(sc, r, mag, scale)
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(inout) :: r(:), mag(:, :)
    real(dp), intent(out) :: scale
    real(dp) :: col(size(mag, 2))
    integer :: d
    if (sc%exchange%nranks() > 1) then
      call sc%exchange%sum_reals(r)
      do d = 1, size(mag, 1)
        col = mag(d, :)
        call sc%exchange%nodes_sum(col)
        mag(d, :) = col
      end do
    end if
    scale = 0.0_dp
    if (size(mag) > 0) scale = maxval(mag)
    call sc%exchange%max_real(scale)
  end subroutine complete_residual

end module wellposed_mpm_implicit_dofs
