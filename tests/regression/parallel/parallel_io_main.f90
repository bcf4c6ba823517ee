!> mpirun -np N parallel_io_main: the outputs of a scene spread over ranks
!> (wellposed_mpm_parallel_io) equal the serial ones bit for bit. Every rank
!> advances the same serial scene and keeps the particles of its cells, as
!> a decomposed run holds them; then stations placed from the gathered
!> reference positions and read through the proxy give the serial
!> histories, gather_particles the serial particles in id order, and
!> stations survive a checkpoint round trip, all bitwise.
program parallel_io_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, allreduce_sum
  use wellposed_mpm_bar_config, only: bar_config_t, mass_lumped
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_stations, only: stations_t, new_stations, place_stations, sample_stations
  use wellposed_mpm_decomposition, only: decomposition_t, new_decomposition, restrict_particles
  use wellposed_mpm_parallel_io
  use wellposed_checkpoint, only: checkpoint_t
  implicit none

  integer, parameter :: nsteps = 200
  type(comm_t) :: comm
  type(bar_config_t) :: cfg
  type(mpm_scene_t) :: ref
  type(particles_t) :: mine, gathered
  type(decomposition_t) :: dec
  type(stations_t) :: st_ref, st, st2
  type(station_proxy_t) :: proxy
  type(checkpoint_t) :: ckpt
  type(error_t), allocatable :: err
  real(dp), allocatable :: x0(:, :)
  integer :: k, n, failures

  call comm_start(comm, err)
  call stop_on(err)
  failures = 0
  cfg%name = 'io'
  cfg%title = 'parallel io test'
  cfg%length = 60.0_dp
  cfg%dx = 0.5_dp
  cfg%t_end = 0.02_dp
  cfg%nprops = 14
  cfg%props = 0.0_dp
  cfg%props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  cfg%props(14) = 1.0_dp
  cfg%station_first = 5.0_dp
  cfg%station_spacing = 10.0_dp
  cfg%nstations = 5
  cfg%progress = .false.
  cfg%mass = mass_lumped   ! the scene of the stored expectations
  cfg%cfl = 0.2_dp
  call new_scene(ref, cfg, err)
  call stop_on(err)
  n = ref%parts%n
  call new_decomposition(dec, comm, ref%grid%nnodes - 1, 1, 1, 1, ref%grid%origin, &
                         ref%grid%dx, err)
  call stop_on(err)
  call new_stations(st_ref, cfg%station_first, cfg%station_spacing, cfg%nstations, ref%parts, &
                    cfg%sample_dt, cfg%t_end)
  ! the decomposed view, as a run sets it up: stations placed on rank 0 from
  ! the gathered reference positions, started through their proxy
  call distribute()
  call gather_reference_positions(comm, mine, 0, x0)
  if (comm%rank == 0) then
    call check(size(x0, 2) == n, 'gather_reference_positions: every particle')
    if (size(x0, 2) == n) call check(all(x0 == ref%parts%x0(:, 1:n)), &
                                     'gather_reference_positions: bitwise, in id order')
    call place_stations(st, cfg%station_first, cfg%station_spacing, cfg%nstations, x0(1, :))
  end if
  call start_proxied_stations(st, comm, n, mine, cfg%sample_dt, cfg%t_end, proxy)
  do k = 1, nsteps
    call advance(ref, err)
    call stop_on(err)
    call sample_stations(st_ref, ref%parts, ref%t)
    call distribute()
    call fill_station_proxy(proxy, comm, mine)
    if (comm%rank == 0) call sample_stations(st, proxy%parts, ref%t)
  end do
  call gather_particles(comm, mine, 0, gathered)
  if (comm%rank == 0) then
    call check(st%ns == st_ref%ns .and. st%ns > 10, 'as many station samples as serial')
    call check(all_equal(st%hist(:, :, 1:st%ns), st_ref%hist(:, :, 1:st_ref%ns)), &
               'station histories bitwise the serial ones')
    call check(maxval(abs(st_ref%hist(1, 1, 1:st%ns) - st_ref%hist(1, 1, 1))) > 1.0e5_dp, &
               'the wave reached the first station (the test sees something)')
    call check(gathered%n == n, 'gather_particles: every particle')
    call check(all(gathered%x(:, 1:n) == ref%parts%x(:, 1:n)) .and. &
               all(gathered%stress(:, 1:n) == ref%parts%stress(:, 1:n)) .and. &
               all(gathered%statev(:, 1:n) == ref%parts%statev(:, 1:n)) .and. &
               all(gathered%gid(1:n) == ref%parts%gid(1:n)), &
               'gather_particles: bitwise the serial particles, in id order')
    call put_stations(ckpt, 'stations/', st_ref)
    call new_stations(st2, cfg%station_first, cfg%station_spacing, cfg%nstations, ref%parts, &
                      cfg%sample_dt, cfg%t_end)
    call get_stations(ckpt, 'stations/', st2, err)
    call check(.not. allocated(err), 'stations read back from a checkpoint')
    call check(st2%ns == st_ref%ns .and. st2%t_prev == st_ref%t_prev .and. &
               all_equal(st2%hist(:, :, 1:st2%ns), st_ref%hist(:, :, 1:st_ref%ns)) .and. &
               all(st2%prev == st_ref%prev), 'stations round trip bit for bit')
    write (output_unit, '(a,i0,a,i0,a)') 'ranks ', comm%size, ', ', st%ns, ' station samples'
  end if
  call allreduce_sum(comm, failures)
  call comm_stop(comm)
  if (failures > 0) error stop 1

contains

  !> This rank's share of the reference particles, as a decomposed run holds them.
  subroutine distribute()
    mine = ref%parts
    call restrict_particles(dec, mine, err)
    call stop_on(err)
  end subroutine distribute

  logical function all_equal(a, b)
    real(dp), intent(in) :: a(:, :, :), b(:, :, :)
    all_equal = all(shape(a) == shape(b))
    if (all_equal) all_equal = all(a == b .or. (a /= a .and. b /= b))
  end function all_equal

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
    write (output_unit, '(a)') merge('ok:   ', 'FAIL: ', ok)//what
  end subroutine check

end program parallel_io_main
