!> bench_checkpoint [DX]: the cost of a checkpoint of the MPM scene
!> (wellposed_mpm_restart + wellposed_checkpoint) as a share of a step, on
!> the default Sandler-Rubin scene (700 m, GIMP, 2 particles per cell;
!> dx = 0.25 m unless given). Prints the time of a step, of writing one
!> checkpoint (save, HDF5 through a temporary name, rename, keep two), of
!> reading and restoring it, the file size, and the ratios. No pass/fail.
program bench_checkpoint
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use wellposed_kinds, only: dp
  use bench_args, only: real_arg, most_args
  use wellposed_error, only: error_t
  use wellposed_mpm_bar_config, only: bar_config_t, mass_lumped
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance
  use wellposed_mpm_restart, only: save_scene, restore_scene
  use wellposed_checkpoint, only: checkpoint_t, write_checkpoint, read_checkpoint
  use wellposed_fs, only: remove_tree
  implicit none
  integer, parameter :: nsteps = 200, nwrites = 5
  type(bar_config_t) :: cfg
  type(mpm_scene_t) :: scene, again
  type(checkpoint_t) :: ck, back
  type(error_t), allocatable :: err
  character(len=:), allocatable :: path
  integer(int64) :: c0, c1, rate, bytes
  integer :: k
  real(dp) :: t_step, t_write, t_read

  cfg%name = 'bench_checkpoint'
  cfg%title = 'Sandler-Rubin default scene'
  call most_args('bench_checkpoint', 1, 'bench_checkpoint [DX]')
  if (command_argument_count() >= 1) &
    cfg%dx = real_arg('bench_checkpoint', 1, 'DX (m)', 0.01_dp, 5.0_dp)
  cfg%nprops = 14
  cfg%props = 0.0_dp
  cfg%props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  cfg%props(14) = 1.0_dp
  cfg%progress = .false.
  cfg%mass = mass_lumped   ! the default scene (inputs/sandler_rubin_default.nml)
  cfg%cfl = 0.2_dp
  call new_scene(scene, cfg, err)
  if (allocated(err)) error stop 'new_scene failed'
  call system_clock(c0, rate)
  do k = 1, nsteps
    call advance(scene, err)
    if (allocated(err)) error stop 'advance failed'
  end do
  call system_clock(c1)
  t_step = real(c1 - c0, dp)/rate/nsteps
  call remove_tree('bench_checkpoint.ckpt', err)
  call system_clock(c0)
  do k = 1, nwrites
    call save_scene(scene, ck)
    call write_checkpoint(ck, 'bench_checkpoint.ckpt', scene%nstep + k, 2, path, err)
    if (allocated(err)) error stop 'write_checkpoint failed'
  end do
  call system_clock(c1)
  t_write = real(c1 - c0, dp)/rate/nwrites
  inquire (file=path, size=bytes)
  call system_clock(c0)
  call read_checkpoint(path, back, err)
  if (allocated(err)) error stop 'read_checkpoint failed'
  call new_scene(again, cfg, err)
  call restore_scene(again, back, err)
  if (allocated(err)) error stop 'restore_scene failed'
  call system_clock(c1)
  t_read = real(c1 - c0, dp)/rate
  write (output_unit, '(a,i0,a,f6.3,a)') 'particles: ', scene%parts%n, ' (dx = ', cfg%dx, ' m)'
  write (output_unit, '(a,es10.3,a)') 'step:                     ', t_step, ' s'
  write (output_unit, '(a,es10.3,a,f7.2,a)') 'checkpoint write:         ', t_write, ' s = ', &
    t_write/t_step, ' steps'
  write (output_unit, '(a,es10.3,a,f7.2,a)') 'read + restore (+ scene): ', t_read, ' s = ', &
    t_read/t_step, ' steps'
  write (output_unit, '(a,i0,a,f6.1,a)') 'file: ', bytes, ' bytes (', &
    real(bytes, dp)/scene%parts%n, ' per particle)'
  write (output_unit, '(a,f6.2,a)') 'a checkpoint every 1000 steps costs ', &
    100.0_dp*t_write/(1000.0_dp*t_step), ' % of the run'
  call remove_tree('bench_checkpoint.ckpt', err)
end program bench_checkpoint
