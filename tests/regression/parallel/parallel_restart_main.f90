!> mpirun -np N parallel_restart_main write|read DIR: checkpoints of an MPM
!> scene spread over ranks (save_scene, restore_scene) written
!> and read back on the same or another number of ranks; every rank must get
!> exactly its particles back, bit for bit, in id order, with time, step and
!> partial sums. Cases: docs/research/verification.md. Exits non-zero on any failure.
program parallel_restart_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, allreduce_sum, barrier
  use wellposed_mpm_bar_config, only: bar_config_t, mass_lumped
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance
  use wellposed_mpm_decomposition, only: decomposition_t, new_decomposition, &
                                         restrict_particles, owner_of_position
  use wellposed_mpm_restart, only: save_scene, restore_scene
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_checkpoint, only: checkpoint_t, write_checkpoint, read_checkpoint, &
                                  latest_checkpoint
  implicit none

  integer, parameter :: nsteps = 40
  type(comm_t) :: comm
  type(bar_config_t) :: cfg
  type(mpm_scene_t) :: ref, scene
  type(decomposition_t) :: dec
  type(mpm_ranks_t) :: ranks
  type(checkpoint_t) :: ckpt
  type(error_t), allocatable :: err
  character(len=256) :: mode, dir
  character(len=:), allocatable :: path
  real(dp), allocatable :: partials(:)
  integer :: k, p, q, failures, mine, nsaved, nbad
  real(dp) :: total
  real(dp), allocatable :: mysums(:)

  call comm_start(comm, err)
  call stop_on(err)
  call get_command_argument(1, mode)
  call get_command_argument(2, dir)
  failures = 0
  cfg%name = 'restart'
  cfg%title = 'restart test'
  cfg%length = 60.0_dp
  cfg%dx = 0.5_dp
  cfg%t_end = 0.02_dp
  cfg%nprops = 14
  cfg%props = 0.0_dp
  cfg%props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  cfg%props(14) = 1.0_dp
  cfg%station_first = 10.0_dp
  cfg%station_spacing = 10.0_dp
  cfg%nstations = 3
  cfg%progress = .false.
  cfg%mass = mass_lumped   ! the scene of the stored expectations
  cfg%cfl = 0.2_dp
  call new_scene(ref, cfg, err)
  call stop_on(err)
  do k = 1, nsteps
    call advance(ref, err)
    call stop_on(err)
  end do
  call new_decomposition(dec, comm, ref%grid%nnodes - 1, 1, 1, 1, ref%grid%origin, &
                         ref%grid%dx, err)
  call stop_on(err)

  call new_mpm_ranks(ranks, comm)
  select case (trim(mode))
  case ('write')
    ! the scene on the ranks, holding the serial run's particles of its cells
    ! (their material and viscous pressure are uniform here: 1 and 0)
    call new_scene(scene, cfg, err, ranks)
    call stop_on(err)
    scene%parts = ref%parts
    call restrict_particles(dec, scene%parts, err)
    call stop_on(err)
    scene%q = ref%q
    scene%mat = ref%mat
    scene%t = ref%t
    scene%nstep = ref%nstep
    call scene%kind%set_partial_sums([1000.0_dp*comm%rank + 0.1_dp, &
                                      2000.0_dp*comm%rank + 0.2_dp, 3000.0_dp*comm%rank + 0.3_dp])
    call save_scene(scene, ckpt)
    if (comm%rank == 0) then
      call write_checkpoint(ckpt, trim(dir), scene%nstep, 2, path, err)
      call stop_on(err)
      write (output_unit, '(a,i0,a)') 'wrote '//path//' on ', comm%size, ' ranks'
    end if
    call barrier(comm)
  case ('read')
    call latest_checkpoint(trim(dir), path, err)
    call stop_on(err)
    call read_checkpoint(path, ckpt, err)
    call stop_on(err)
    call ckpt%get('mpm/partials', partials, err)
    call stop_on(err)
    nsaved = size(partials)/3
    call new_scene(scene, cfg, err, ranks)
    call stop_on(err)
    call restore_scene(scene, ckpt, err)
    call stop_on(err)
    call check(scene%nstep == nsteps .and. scene%t == ref%t, 'time and step restored')
    mine = count([(owner_of_position(dec, ref%parts%x(1, p)) == comm%rank, &
                   p=1, ref%parts%n)])
    call check(scene%parts%n == mine, 'every rank holds exactly the particles of its cells')
    nbad = 0
    do p = 1, scene%parts%n
      q = scene%parts%gid(p)
      if (p > 1) then
        if (q <= scene%parts%gid(p - 1)) nbad = nbad + 1
      end if
      if (owner_of_position(dec, scene%parts%x(1, p)) /= comm%rank) nbad = nbad + 1
      if (any(scene%parts%x(:, p) /= ref%parts%x(:, q)) .or. &
          any(scene%parts%v(:, p) /= ref%parts%v(:, q)) .or. &
          any(scene%parts%stress(:, p) /= ref%parts%stress(:, q)) .or. &
          any(scene%parts%stran(:, p) /= ref%parts%stran(:, q)) .or. &
          any(scene%parts%statev(:, p) /= ref%parts%statev(:, q)) .or. &
          any(scene%parts%defgrad(:, :, p) /= ref%parts%defgrad(:, :, q)) .or. &
          scene%parts%mass(p) /= ref%parts%mass(q) .or. scene%parts%vol(p) /= ref%parts%vol(q) &
          .or. any(scene%parts%x0(:, p) /= ref%parts%x0(:, q)) .or. &
          any(scene%parts%lp(:, p) /= ref%parts%lp(:, q))) nbad = nbad + 1
    end do
    call allreduce_sum(comm, nbad)
    call check(nbad == 0, 'particles bitwise those of the reference run, in id order')
    if (nsaved == comm%size) then
      mysums = scene%kind%partial_sums()
      call check(mysums(1) == 1000.0_dp*comm%rank + 0.1_dp .and. &
                 mysums(3) == 3000.0_dp*comm%rank + 0.3_dp, &
                 'same rank count: every rank has its own partial sums back')
    else
      mysums = scene%kind%partial_sums()
      total = mysums(1)
      call allreduce_sum(comm, total)
      call check(total == sum(partials(1::3)), 'other rank count: the partial sums total')
    end if
    k = scene%parts%n
    call allreduce_sum(comm, k)
    if (comm%rank == 0) write (output_unit, '(a,i0,a,i0,a,i0,a)') 'restored ', k, &
      ' particles written on ', nsaved, ' ranks onto ', comm%size, ' ranks'
  case default
    write (error_unit, '(a)') 'usage: parallel_restart_main write|read DIR'
    error stop 2
  end select
  call allreduce_sum(comm, failures)
  if (comm%rank == 0 .and. failures > 0) write (output_unit, '(a,i0,a)') 'FAIL: ', failures, &
    ' failed checks'
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
    if (.not. ok) failures = failures + 1
    if (comm%rank == 0) write (output_unit, '(a)') merge('ok:   ', 'FAIL: ', ok)//what
  end subroutine check

end program parallel_restart_main
