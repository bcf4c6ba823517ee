!> mpirun -np N parallel_handoff_2d_main: the MPM domain decomposition on a
!> 2D grid (nodes numbered i + (nx+1) j, strips of cell rows per rank, so a
!> patch is one contiguous node range) with bilinear particles that circle
!> across the rank boundaries for 300 steps. Checks as the 1D test: the
!> particle set unchanged bit for bit after every hand-off (mass, position,
!> momentum exact), supports inside their patches, ghost-summed nodal mass
!> and momentum (2 components) equal to a serial pass within 1e-14, and
!> every copy of a node bitwise its owner's value. Non-zero exit on failure.
program parallel_handoff_2d_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, allreduce_sum, allreduce_max, &
                           gatherv_real
  use wellposed_mpm_grid, only: grid_t, new_grid, grid_reset
  use wellposed_mpm_particles, only: particles_t, new_particles
  use wellposed_mpm_decomposition
  implicit none

  integer, parameter :: nx = 12, ny = 24, ppc = 2, nsteps = 300, pad = 3
  real(dp), parameter :: h = 0.5_dp, radius = 1.2_dp, period = 60.0_dp
  type(comm_t) :: comm
  type(decomposition_t) :: dec
  type(grid_t) :: grid
  type(particles_t) :: parts
  type(error_t), allocatable :: err
  real(dp), allocatable :: x0(:, :), mass0(:), now(:, :), held(:, :), gathered(:), ref(:, :)
  real(dp) :: worst, ang, shift(2), scale
  integer :: p, a, b, c, d, step, nall, moved, total_moved, failures, mism, k, i, nn

  call comm_start(comm, err)
  if (allocated(err)) error stop 2
  failures = 0
  ! the whole grid, then this rank's patch of cell rows (axis 2)
  call new_grid(grid, 2, 0.0_dp, h, (nx + 1)*(ny + 1), 0, (nx + 1)*(ny + 1) - 1)
  call new_decomposition(dec, comm, ny, nx + 1, 1, 2, 0.0_dp, h, err)
  call stop_on(err)
  call restrict_grid(dec, grid)

  nall = (nx - 2*pad)*(ny - 2*pad)*ppc*ppc
  call new_particles(parts, nall, 2, 4, 12)
  p = 0
  do b = pad*ppc, (ny - pad)*ppc - 1
    do a = pad*ppc, (nx - pad)*ppc - 1
      p = p + 1
      parts%gid(p) = p
      parts%x0(:, p) = ([a, b] + 0.5_dp)*h/ppc
      parts%lp(:, p) = 0.5_dp*h/ppc
      parts%mass(p) = 1.0_dp + 0.001_dp*p
      parts%vol0(p) = (h/ppc)**2
      parts%vol(p) = parts%vol0(p)
      parts%defgrad(:, :, p) = 0.0_dp
      parts%stress(:, p) = real(p, dp)
      parts%stran(:, p) = 0.0_dp
      parts%statev(:, p) = -real(p, dp)
    end do
  end do
  parts%n = nall
  parts%x = parts%x0
  parts%v = 0.0_dp
  allocate (x0, source=parts%x0(:, 1:nall))
  allocate (mass0, source=parts%mass(1:nall))
  call restrict_particles(dec, parts, err)
  call stop_on(err)

  total_moved = 0
  worst = 0.0_dp
  mism = 0
  shift = 0.0_dp
  do step = 1, nsteps
    ang = 2.0_dp*acos(-1.0_dp)*step/period
    do p = 1, parts%n
      parts%v(:, p) = radius*[cos(ang), sin(ang)] - shift
      parts%x(:, p) = parts%x0(:, p) + radius*[cos(ang), sin(ang)]
    end do
    shift = radius*[cos(ang), sin(ang)]
    call hand_off_particles(dec, comm, parts, err, moved)
    call stop_on(err)
    total_moved = total_moved + moved
    call bilinear(parts)
    call check_support(dec, parts, grid, err)
    call stop_on(err)
    call grid_reset(grid)
    do p = 1, parts%n
      do k = 1, 4
        i = parts%node(k, p)
        grid%mass(i) = grid%mass(i) + parts%phi(k, p)*parts%mass(p)
        grid%momentum(:, i) = grid%momentum(:, i) + parts%phi(k, p)*parts%mass(p)*parts%v(:, p)
      end do
    end do
    call sum_ghost_grid(dec, comm, grid, .false.)
    if (mod(step, 25) == 0) call compare()
  end do
  call allreduce_sum(comm, total_moved)
  call allreduce_max(comm, worst)
  call allreduce_sum(comm, mism)
  call gather_state(now)
  if (comm%rank == 0) then
    call check(size(now, 2) == nall, 'every particle still there once')
    call check(all(now(1, :) == mass0), 'masses bitwise unchanged after all hand-offs')
    call check(all(now(2, :) == x0(1, :) + shift(1)) .and. all(now(3, :) == x0(2, :) + shift(2)), &
               'positions are the prescribed ones')
    call check(all(now(4, :) == [(real(p, dp), p=1, nall)]), 'stress travels with its particle')
  end if
  call check(worst <= 1.0e-14_dp, 'ghost-summed mass and momentum equal the serial sums within 1e-14')
  call check(mism == 0, 'every copy of a node holds bitwise its owner''s sum')
  if (comm%rank == 0) then
    write (output_unit, '(a,i0,a,i0,a,es9.2)') 'ranks ', comm%size, ', particle hand-offs ', &
      total_moved, ', worst nodal difference ', worst
    if (comm%size > 1 .and. total_moved < 100*(comm%size - 1)) call check(.false., &
      'enough hand-offs to test anything')
  end if
  call allreduce_sum(comm, failures)
  call comm_stop(comm)
  if (failures > 0) error stop 1

contains

  !> Bilinear weights (standard MPM) of the particles' cells.
  subroutine bilinear(pt)
    type(particles_t), intent(inout) :: pt
    integer :: q, ci, cj
    real(dp) :: fx, fy
    do q = 1, pt%n
      ci = floor(pt%x(1, q)/h)
      cj = floor(pt%x(2, q)/h)
      fx = pt%x(1, q)/h - ci
      fy = pt%x(2, q)/h - cj
      pt%node(:, q) = [ci + (nx + 1)*cj, ci + 1 + (nx + 1)*cj, ci + (nx + 1)*(cj + 1), &
                       ci + 1 + (nx + 1)*(cj + 1)]
      pt%phi(:, q) = [(1 - fx)*(1 - fy), fx*(1 - fy), (1 - fx)*fy, fx*fy]
    end do
  end subroutine bilinear

  subroutine stop_on(e)
    type(error_t), allocatable, intent(in) :: e
    if (.not. allocated(e)) return
    write (error_unit, '(a,i0,a)') 'rank ', comm%rank, ': '//e%message
    error stop 1
  end subroutine stop_on

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) failures = failures + 1
    if (comm%rank == 0) write (output_unit, '(a)') merge('ok:   ', 'FAIL: ', ok)//what
  end subroutine check

  !> (mass, x, y, stress_1, vx, vy) of all particles by id on rank 0.
  subroutine gather_state(state)
    real(dp), allocatable, intent(out) :: state(:, :)
    real(dp) :: v(6, parts%n)
    v(1, :) = parts%mass(1:parts%n)
    v(2:3, :) = parts%x(:, 1:parts%n)
    v(4, :) = parts%stress(1, 1:parts%n)
    v(5:6, :) = parts%v(:, 1:parts%n)
    call gather_by_gid(comm, parts%gid(1:parts%n), v, 0, state)
  end subroutine gather_state

  !> Serial P2G on rank 0 against every rank's owned nodes (rank order
  !> concatenates to the whole grid); ghosts against their owners.
  subroutine compare()
    real(dp), allocatable :: st(:, :), mine(:)
    type(particles_t) :: one
    integer :: q, j, r, off
    call gather_state(st)
    nn = grid%ihi - grid%ilo + 1
    mine = [grid%mass(grid%ilo:grid%ihi), grid%momentum(1, grid%ilo:grid%ihi), &
            grid%momentum(2, grid%ilo:grid%ihi)]
    call gatherv_real(comm, mine, gathered, 0)
    if (comm%rank == 0) then
      allocate (ref(3, 0:(nx + 1)*(ny + 1) - 1))
      ref = 0.0_dp
      call new_particles(one, 1, 2, 4, 12)
      one%n = 1
      do q = 1, size(st, 2)
        one%x(:, 1) = st(2:3, q)
        call bilinear(one)
        do j = 1, 4
          ref(1, one%node(j, 1)) = ref(1, one%node(j, 1)) + one%phi(j, 1)*st(1, q)
          ref(2:3, one%node(j, 1)) = ref(2:3, one%node(j, 1)) + one%phi(j, 1)*st(1, q)*st(5:6, q)
        end do
      end do
      off = 0
      do r = 0, comm%size - 1
        c = dec%cell_lo(r)*(nx + 1)
        d = dec%cell_lo(r + 1)*(nx + 1) - 1
        if (r == comm%size - 1) d = (ny + 1)*(nx + 1) - 1
        nn = d - c + 1
        do k = 1, 3
          scale = max(maxval(abs(ref(k, :))), 1.0e-300_dp)
          worst = max(worst, maxval(abs(gathered(off + (k - 1)*nn + 1:off + k*nn) - &
                                        ref(k, c:d)))/scale)
        end do
        off = off + 3*nn
      end do
      deallocate (ref)
    end if
    held = reshape(grid%mass, [1, size(grid%mass)])
    call copy_owned_to_ghosts(dec, comm, held)
    if (any(held(1, :) /= grid%mass)) mism = mism + 1
  end subroutine compare

end program parallel_handoff_2d_main
