!> The grid acceleration of a bar with the particles' mass matrix
!> M_P = sum_p m_p phi_p phi_p^T instead of the lumped M_L (eq. 4.4; &time
!> mass): 'consistent' solves M_P a = f, the lumped-mass finite-element
!> update of the rebuilt velocity; 'blended' solves M_P a = M_L H^-1 f,
!> H = (M_L + M_P)/2, whose dispersion error cancels to second order.
!> Banded (3 nodes), factored by LAPACK every step; one rank only.
!> Why: docs/research/waves.md, "The wake oscillation".
module wellposed_mpm_mass_matrix
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_cutback
  use wellposed_lapack, only: spd_band_solve
  use wellposed_mpm_method, only: mass_consistent, mass_blended
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_particles, only: particles_t
  implicit none
  private
  public :: mass_matrix_update

contains

  !> After the grid update (eq. 4.9-4.10 with the boundary conditions):
  !> replace the acceleration of every free node (mass above `mmin`, no
  !> condition on it) by the solve of `kind` and its velocity by
  !> p_i/m_i + a_i dt. Particles 1 .. n, their supports nnz(:).
  subroutine mass_matrix_update(kind, g, pt, n, nnz, dt, mmin, err)
    integer, intent(in) :: kind, n, nnz(:)
    type(grid_t), intent(inout) :: g
    type(particles_t), intent(in) :: pt
    real(dp), intent(in) :: dt, mmin
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: mp(:, :), h(:, :), a(:)
    logical, allocatable :: free(:), lumped(:)
    integer :: i, j, k, kd, nn
    logical :: ok

    kd = max(1, pt%nsup - 1)
    nn = g%ghi - g%glo + 1
    allocate (free(g%glo:g%ghi), lumped(g%glo:g%ghi), a(nn))
    free = g%mass > mmin .and. .not. (g%fixed(1, :) .or. g%given(1, :))
    call particle_mass(g%glo, kd, free, pt, n, nnz, mp)
    ! A node its particles see only faintly (M_P's diagonal below a quarter
    ! of its lumped mass; 5/8 for a full node at ppc 2) keeps the lumped row:
    ! M_P would give it an acceleration of order f/(phi m_p), phi -> 0. Its
    ! couplings move onto its neighbours' diagonals, so every row still sums
    ! to its lumped mass (dropped, they pumped a grid-scale oscillation in
    ! from a drifting surface; docs/research/waves.md, "Against the continuum").
    lumped = free .and. mp(1, :) < 0.25_dp*g%mass
    do i = g%glo, g%ghi
      j = i - g%glo + 1
      a(j) = merge(g%fint(1, i) + g%fext(1, i), 0.0_dp, free(i))
      if (lumped(i)) then
        ! A(j + k, j) and A(j, j - k) onto A(j + k, j + k) and A(j - k, j - k)
        do k = 1, min(kd, size(mp, 2) - j)
          mp(1, j + k) = mp(1, j + k) + mp(1 + k, j)
          mp(1 + k, j) = 0.0_dp
        end do
        do k = 1, min(kd, j - 1)
          mp(1, j - k) = mp(1, j - k) + mp(1 + k, j - k)
          mp(1 + k, j - k) = 0.0_dp
        end do
        mp(1, j) = g%mass(i)
      else if (.not. free(i)) then
        mp(1, j) = 1.0_dp    ! x_i = 0: an identity row (assembled empty)
      end if
    end do
    if (kind == mass_blended) then
      h = 0.5_dp*mp
      do i = g%glo, g%ghi
        j = i - g%glo + 1
        if (free(i)) h(1, j) = h(1, j) + 0.5_dp*g%mass(i)
      end do
      call spd_band_solve(h, a, ok)
      if (.not. ok) call fail('(M_L + M_P)/2')
      if (allocated(err)) return
      do i = g%glo, g%ghi
        a(i - g%glo + 1) = merge(g%mass(i)*a(i - g%glo + 1), 0.0_dp, free(i))
      end do
    end if
    if (kind == mass_consistent .or. kind == mass_blended) then
      call spd_band_solve(mp, a, ok)
      if (.not. ok) call fail('M_P')
      if (allocated(err)) return
    end if
    do i = g%glo, g%ghi
      if (.not. free(i)) cycle
      g%accel(1, i) = a(i - g%glo + 1)
      g%velocity(1, i) = g%momentum(1, i)/g%mass(i) + g%accel(1, i)*dt
    end do

  contains

    subroutine fail(what)
      character(len=*), intent(in) :: what
      call new_error(err, status_cutback, 'mass', 'the mass matrix '//what//' is not '// &
        'positive definite on the nodes that carry mass (a node seen by too few particles); '// &
        '&time mass = ''lumped'' does not need it')
    end subroutine fail

  end subroutine mass_matrix_update

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
