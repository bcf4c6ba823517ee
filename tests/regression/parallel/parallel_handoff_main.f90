!> mpirun -np N parallel_handoff_main: the MPM domain decomposition on a 1D
!> bar of GIMP particles sloshing across rank boundaries for many steps.
!> Checks that hand-offs lose, duplicate and alter no particle (mass and
!> momentum exact), that supports stay in their patch, and that ghost-summed
!> nodal mass and momentum match a serial pass within 1e-14 relative.
!> Prints one line per check and exits non-zero on any failure.
program parallel_handoff_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, allreduce_sum, allreduce_max, &
                           gatherv_real
  use wellposed_mpm_grid, only: grid_t, new_grid_1d, grid_reset
  use wellposed_mpm_particles, only: particles_t, new_particles
  use wellposed_mpm_shape, only: shape_1d, support_size
  use wellposed_mpm_config, only: shape_gimp
  use wellposed_mpm_decomposition
  implicit none

  integer, parameter :: ncells = 60, ppc = 2, nsteps = 400, pad = 4
  real(dp), parameter :: dx = 0.5_dp, amp = 1.6_dp, period = 100.0_dp
  type(comm_t) :: comm
  type(decomposition_t) :: dec
  type(grid_t) :: grid, full
  type(particles_t) :: parts, all_parts
  type(error_t), allocatable :: err
  real(dp), allocatable :: now(:, :), gathered(:), mass0(:)
  integer :: p, step, nall, moved, total_moved, i, k, failures, ghost_mismatch
  real(dp) :: worst, shift, shift_new, xc

  call comm_start(comm, err)
  if (allocated(err)) error stop 2
  failures = 0
  call new_grid_1d(grid, 0.0_dp, dx, ncells)
  call new_decomposition(dec, comm, ncells, 1, 1, 1, 0.0_dp, dx, err)
  call stop_on(err)
  call restrict_grid(dec, grid)

  ! particles of the body: cells pad .. ncells-pad-1, ppc per cell
  nall = (ncells - 2*pad)*ppc
  call new_particles(parts, nall, 1, support_size(shape_gimp), 12)
  do p = 1, nall
    xc = pad*dx + (real(p, dp) - 0.5_dp)*dx/ppc
    parts%gid(p) = p
    parts%x0(1, p) = xc
    parts%x(1, p) = xc
    parts%v(1, p) = 0.0_dp
    parts%lp(1, p) = 0.5_dp*dx/ppc
    parts%mass(p) = 1.0_dp + 0.01_dp*p     ! distinct masses: a swap would show
    parts%vol0(p) = dx/ppc
    parts%vol(p) = dx/ppc
    parts%defgrad(:, :, p) = 0.0_dp
    parts%stress(:, p) = real(p, dp)
    parts%stran(:, p) = -real(p, dp)
    parts%statev(:, p) = 0.5_dp*p
  end do
  parts%n = nall
  all_parts = parts
  allocate (mass0, source=parts%mass(1:nall))
  call restrict_particles(dec, parts, err)
  call stop_on(err)
  k = parts%n
  call allreduce_sum(comm, k)
  call check(k == nall, 'restrict_particles keeps every particle once')

  total_moved = 0
  ghost_mismatch = 0
  worst = 0.0_dp
  shift = 0.0_dp
  do step = 1, nsteps
    ! rigid slosh: every particle at x0 + amp sin(2 pi step / period) (m),
    ! so the bar crosses each rank boundary many times
    shift_new = amp*sin(2.0_dp*acos(-1.0_dp)*step/period)
    do p = 1, parts%n
      parts%v(1, p) = (shift_new - shift)
      parts%x(1, p) = parts%x0(1, p) + shift_new
    end do
    shift = shift_new
    call hand_off_particles(dec, comm, parts, err, moved)
    call stop_on(err)
    total_moved = total_moved + moved
    do p = 1, parts%n
      call shape_1d(shape_gimp, parts%x(1, p), parts%lp(1, p), grid%origin, grid%dx, &
                    parts%node(:, p), parts%phi(:, p), parts%grad(1, :, p))
    end do
    call check_support(dec, parts, grid, err)
    call stop_on(err)
    ! particle to grid on the patch, then the ghost sum
    call grid_reset(grid)
    do p = 1, parts%n
      do k = 1, parts%nsup
        i = parts%node(k, p)
        grid%mass(i) = grid%mass(i) + parts%phi(k, p)*parts%mass(p)
        grid%momentum(1, i) = grid%momentum(1, i) + parts%phi(k, p)*parts%mass(p)*parts%v(1, p)
      end do
    end do
    call sum_ghost_grid(dec, comm, grid, .false.)
    if (mod(step, 20) == 0 .or. step == nsteps) call compare_with_serial()
  end do
  call allreduce_sum(comm, total_moved)

  ! the particle set after all hand-offs: same ids, bitwise the same masses
  call gather_state(now)
  if (comm%rank == 0) then
    call check(all(now(1, :) == mass0), 'masses bitwise unchanged after all hand-offs')
    call check(all(now(2, :) == all_parts%x0(1, 1:nall) + shift), &
               'positions are the prescribed ones (no particle lost or duplicated)')
    call check(all(now(3, :) == real([(p, p=1, nall)], dp)), 'stress travels with its particle')
    call check(all(now(4, :) == 0.5_dp*[(p, p=1, nall)]), 'STATEV travels with its particle')
    call check(sum(now(1, :)*now(5, :)) == sum(mass0*now(5, :)), &
               'momentum sum m v over the gathered particles is exact')
  end if
  call allreduce_max(comm, worst)
  call allreduce_sum(comm, ghost_mismatch)
  call check(ghost_mismatch == 0, 'every copy of a node holds bitwise its owner''s sum')
  call check(worst <= 1.0e-14_dp, 'ghost-summed nodal mass and momentum equal the serial '// &
             'sums within 1e-14 relative')
  if (comm%rank == 0) then
    write (output_unit, '(a,i0,a,i0,a,i0,a,es9.2)') 'ranks ', comm%size, ', steps ', nsteps, &
      ', particle hand-offs ', total_moved, ', worst nodal difference ', worst
    if (comm%size > 1 .and. total_moved < 50*(comm%size - 1)) then
      write (output_unit, '(a)') 'FAIL: too few hand-offs to test anything'
      failures = failures + 1
    end if
  end if
  call allreduce_sum(comm, failures)
  call comm_stop(comm)
  if (failures > 0) error stop 1

contains

  subroutine stop_on(e)
    type(error_t), allocatable, intent(in) :: e
    if (.not. allocated(e)) return
    write (error_unit, '(a,i0,a)') 'rank ', comm%rank, ': '//e%message
    error stop 1
  end subroutine stop_on

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (comm%rank /= 0) then
      if (.not. ok) failures = failures + 1
      return
    end if
    if (ok) then
      write (output_unit, '(a)') 'ok:   '//what
    else
      write (output_unit, '(a)') 'FAIL: '//what
      failures = failures + 1
    end if
  end subroutine check

  !> (mass, x, stress_1, statev_1, v) of all particles by id on rank 0.
  subroutine gather_state(state)
    real(dp), allocatable, intent(out) :: state(:, :)
    real(dp) :: v(5, parts%n)
    v(1, :) = parts%mass(1:parts%n)
    v(2, :) = parts%x(1, 1:parts%n)
    v(3, :) = parts%stress(1, 1:parts%n)
    v(4, :) = parts%statev(1, 1:parts%n)
    v(5, :) = parts%v(1, 1:parts%n)
    call gather_by_gid(comm, parts%gid(1:parts%n), v, 0, state)
  end subroutine gather_state

  !> Serial P2G over all particles on rank 0 against the owned nodes of
  !> every rank; ghosts against their owners' values.
  subroutine compare_with_serial()
    real(dp), allocatable :: st(:, :), mine(:), held(:, :)
    integer :: q, j, nn
    real(dp) :: a, b, scale
    call gather_state(st)
    ! owned node values of every rank, concatenated in rank order: the grid
    mine = [(grid%mass(i), i=grid%ilo, grid%ihi), (grid%momentum(1, i), i=grid%ilo, grid%ihi)]
    call gatherv_real(comm, mine, gathered, 0)
    if (comm%rank == 0) then
      call new_grid_1d(full, 0.0_dp, dx, ncells)
      call grid_reset(full)
      do q = 1, nall
        block
          integer :: nodes(3)
          real(dp) :: phi(3), grad(3)
          call shape_1d(shape_gimp, st(2, q), all_parts%lp(1, q), 0.0_dp, dx, nodes, phi, grad)
          do j = 1, 3
            full%mass(nodes(j)) = full%mass(nodes(j)) + phi(j)*st(1, q)
            full%momentum(1, nodes(j)) = full%momentum(1, nodes(j)) + phi(j)*st(1, q)*st(5, q)
          end do
        end block
      end do
      ! gathered = per rank [mass(owned), momentum(owned)]: unpack in order
      j = 0
      do q = 0, comm%size - 1
        nn = dec%cell_lo(q + 1) - dec%cell_lo(q)
        if (q == comm%size - 1) nn = nn + 1
        do i = 1, nn
          a = gathered(j + i)
          b = full%mass(dec%cell_lo(q) + i - 1)
          scale = max(abs(b), 1.0e-300_dp)
          worst = max(worst, abs(a - b)/scale)
          a = gathered(j + nn + i)
          b = full%momentum(1, dec%cell_lo(q) + i - 1)
          scale = max(maxval(abs(full%momentum)), 1.0e-300_dp)
          worst = max(worst, abs(a - b)/scale)
        end do
        j = j + 2*nn
      end do
    end if
    ! every holder of a node has the owner's value, bitwise
    held = reshape(grid%mass, [1, size(grid%mass)])
    call copy_owned_to_ghosts(dec, comm, held)
    if (any(held(1, :) /= grid%mass)) ghost_mismatch = ghost_mismatch + 1
  end subroutine compare_with_serial

end program parallel_handoff_main
