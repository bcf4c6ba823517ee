!> The grid acceleration of a bar with the particles' mass matrix
!> M_P = sum_p m_p phi_p phi_p^T instead of the lumped M_L (eq. 4.4; &time
!> mass): 'consistent' solves M_P a = f, the lumped-mass finite-element
!> update of the rebuilt velocity; 'blended' solves M_P a = M_L H^-1 f,
!> H = (M_L + M_P)/2, whose dispersion error cancels to second order.
!> Banded (3 nodes), factored by LAPACK every step; on many ranks every rank
!> solves the whole bar's system. Why: docs/research/waves.md, "The wake oscillation".
module wellposed_mpm_mass_matrix
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_lapack, only: spd_band_solve
  use wellposed_mpm_method, only: mass_consistent, mass_blended
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_nonlocal_ranks, only: nonlocal_ranks_t
  implicit none
  private
  public :: mass_matrix_update

contains

  !> After the grid update (eq. 4.9-4.10 with the boundary conditions):
  !> replace the acceleration of every free node (mass above `mmin`, no
  !> condition on it) by the solve of `kind` and its velocity by
  !> p_i/m_i + a_i dt. Particles 1 .. n, their supports nnz(:). With
  !> `ranks` of more than one rank (collective) the system is the whole
  !> bar's, assembled on every rank from the patches (whole_bar).
  subroutine mass_matrix_update(kind, g, pt, n, nnz, dt, mmin, err, ranks)
    integer, intent(in) :: kind, n, nnz(:)
    type(grid_t), intent(inout) :: g
    type(particles_t), intent(in) :: pt
    real(dp), intent(in) :: dt, mmin
    type(error_t), allocatable, intent(out) :: err
    class(nonlocal_ranks_t), intent(inout), optional :: ranks
    real(dp), allocatable :: mp(:, :), mass(:), a(:)
    logical, allocatable :: free(:), free_rows(:)
    integer :: i, kd, lo
    logical :: many
    character(len=:), allocatable :: failed

    kd = max(1, pt%nsup - 1)
    allocate (free(g%glo:g%ghi))
    free = g%mass > mmin .and. .not. (g%fixed(1, :) .or. g%given(1, :))
    call particle_mass(g%glo, kd, free, pt, n, nnz, mp)
    many = .false.
    if (present(ranks)) many = ranks%nranks() > 1
    if (many) then
      call whole_bar(ranks, g, kd, free, mp, mass, a, free_rows)
      lo = 0
    else
      free_rows = free
      mass = g%mass
      a = merge(g%fint(1, :) + g%fext(1, :), 0.0_dp, free)
      lo = g%glo
    end if
    call solve_rows(kind, kd, free_rows, mass, mp, a, failed)
    if (allocated(failed)) then
      call new_error(err, status_cutback, 'mass', 'the mass matrix '//failed//' is not '// &
        'positive definite on the nodes that carry mass (a node seen by too few particles); '// &
        '&time mass = ''lumped'' does not need it')
      return
    end if
    do i = g%glo, g%ghi
      if (.not. free(i)) cycle
      g%accel(1, i) = a(i - lo + 1)
      g%velocity(1, i) = g%momentum(1, i)/g%mass(i) + g%accel(1, i)*dt
    end do
  end subroutine mass_matrix_update

  !> The system over the nodes of `free` (their lumped `mass`, the lower
  !> band `mp` of M_P as assembled, kd + 1 rows): on entry `a` the free
  !> nodes' forces (0 elsewhere), on exit their accelerations. `failed`
  !> names the factor that is not positive definite.
  subroutine solve_rows(kind, kd, free, mass, mp, a, failed)
    integer, intent(in) :: kind, kd
    logical, intent(in) :: free(:)
    real(dp), intent(in) :: mass(:)
    real(dp), intent(inout) :: mp(:, :), a(:)
    character(len=:), allocatable, intent(out) :: failed
    real(dp), allocatable :: h(:, :)
    logical :: lumped(size(mass)), ok
    integer :: j, k
    ! A node its particles see only faintly (M_P's diagonal below a quarter
    ! of its lumped mass; 5/8 for a full node at ppc 2) keeps the lumped row:
    ! M_P would give it an acceleration of order f/(phi m_p), phi -> 0. Its
    ! couplings move onto its neighbours' diagonals, so every row still sums
    ! to its lumped mass (dropped, they pumped a grid-scale oscillation in
    ! from a drifting surface; docs/research/waves.md, "Against the continuum").
    lumped = free .and. mp(1, :) < 0.25_dp*mass
    do j = 1, size(mass)
      if (lumped(j)) then
        ! A(j + k, j) and A(j, j - k) onto A(j + k, j + k) and A(j - k, j - k)
        do k = 1, min(kd, size(mp, 2) - j)
          mp(1, j + k) = mp(1, j + k) + mp(1 + k, j)
          mp(1 + k, j) = 0.0_dp
        end do
        do k = 1, min(kd, j - 1)
          mp(1, j - k) = mp(1, j - k) + mp(1 + k, j - k)
          mp(1 + k, j - k) = 0.0_dp
        end do
        mp(1, j) = mass(j)
      else if (.not. free(j)) then
        mp(1, j) = 1.0_dp    ! x_j = 0: an identity row (assembled empty)
      end if
    end do
    if (kind == mass_blended) then
      h = 0.5_dp*mp
      do j = 1, size(mass)
        if (free(j)) h(1, j) = h(1, j) + 0.5_dp*mass(j)
      end do
      call spd_band_solve(h, a, ok)
      if (.not. ok) then
        failed = '(M_L + M_P)/2'; return
      end if
      a = merge(mass*a, 0.0_dp, free)
    end if
    if (kind == mass_consistent .or. kind == mass_blended) then
      call spd_band_solve(mp, a, ok)
      if (.not. ok) failed = 'M_P'
    end if
  end subroutine solve_rows

  !> The whole bar's system on every rank (collective): each rank's patch
  !> [glo, ghi] sends its particles' partial band `mp` and its nodes' mass,
  !> force and freedom; the partial bands are added in ascending rank order
  !> (as the ghost sums add the grid's, so every rank assembles the same
  !> bits) and each node takes its first holder's values (all holders have
  !> the same after the grid's ghost sums). Nodes 0 .. nnodes - 1.
  subroutine whole_bar(ranks, g, kd, free, mp, mass, a, free_all)
    class(nonlocal_ranks_t), intent(inout) :: ranks
    type(grid_t), intent(in) :: g
    integer, intent(in) :: kd
    logical, intent(in) :: free(g%glo:)
    real(dp), allocatable, intent(inout) :: mp(:, :)
    real(dp), allocatable, intent(out) :: mass(:), a(:)
    logical, allocatable, intent(out) :: free_all(:)
    real(dp), allocatable :: bounds(:), rows(:), all(:), mine(:, :)
    logical, allocatable :: seen(:)
    integer :: r, i, j, at, lo, hi, nw
    nw = kd + 4   ! per node: the band column, mass, force, freedom
    call ranks%gather_all([real(g%glo, dp), real(g%ghi, dp)], bounds)
    allocate (mine(nw, g%glo:g%ghi))
    mine(1:kd + 1, :) = mp
    mine(kd + 2, :) = g%mass
    mine(kd + 3, :) = merge(g%fint(1, :) + g%fext(1, :), 0.0_dp, free)
    mine(kd + 4, :) = merge(1.0_dp, 0.0_dp, free)
    rows = reshape(mine, [size(mine)])
    call ranks%gather_all(rows, all)
    deallocate (mp)
    allocate (mp(kd + 1, g%nnodes), mass(g%nnodes), a(g%nnodes), free_all(g%nnodes), &
              seen(g%nnodes))
    mp = 0.0_dp
    mass = 0.0_dp
    a = 0.0_dp
    free_all = .false.
    seen = .false.
    at = 0
    do r = 1, size(bounds)/2
      lo = nint(bounds(2*r - 1))
      hi = nint(bounds(2*r))
      do i = lo, hi
        j = i + 1
        mp(:, j) = mp(:, j) + all(at + 1:at + kd + 1)
        if (.not. seen(j)) then
          mass(j) = all(at + kd + 2)
          a(j) = all(at + kd + 3)
          free_all(j) = all(at + kd + 4) > 0.5_dp
          seen(j) = .true.
        end if
        at = at + nw
      end do
    end do
  end subroutine whole_bar

  !> The particles' mass matrix sum_p m_p phi_p phi_p^T over the free nodes,
  !> lower band (kd + 1, nodes from `glo`): mp(1 + i - j, j) = M(i, j).
  pure subroutine particle_mass(glo, kd, free, pt, n, nnz, mp)
    integer, intent(in) :: glo, kd, n, nnz(:)
    logical, intent(in) :: free(glo:)
    type(particles_t), intent(in) :: pt
    real(dp), allocatable, intent(out) :: mp(:, :)
    integer :: p, a, b, ia, ib
    real(dp) :: wa
    allocate (mp(kd + 1, size(free)))
    mp = 0.0_dp
    do p = 1, n
      do a = 1, nnz(p)
        ia = pt%node(a, p)
        if (.not. free(ia)) cycle
        wa = pt%phi(a, p)*pt%mass(p)
        do b = 1, nnz(p)
          ib = pt%node(b, p)
          if (ib > ia .or. ia - ib > kd) cycle
          if (.not. free(ib)) cycle
          mp(1 + ia - ib, ib - glo + 1) = mp(1 + ia - ib, ib - glo + 1) + wa*pt%phi(b, p)
        end do
      end do
    end do
  end subroutine particle_mass

end module wellposed_mpm_mass_matrix
