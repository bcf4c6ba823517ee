!> bench_mpm1d: nanoseconds per particle per step of the 1D explicit MPM
!> (wellposed_mpm_solver, the driver of `wellposed-mpm`) on the default
!> Sandler-Rubin scene (700 m, dx = 0.25 m, GIMP, 2 particles per cell,
!> 5600 particles, plastic Drucker-Prager UMAT), for GIMP and linear
!> weights; bytes per particle; the shares of the step spent in the UMAT,
!> the transfers (shape weights, P2G, G2P, MUSL) and the grid update.
!> Prints the ratio to the target of 150 ns (the UMAT alone costs
!> about 85 ns); never a pass/fail on wall time. Timed over `nsteps` steps
!> after `nwarm` warm-up steps (the pulse is then inside the body);
!> usage: bench_mpm1d [NSTEPS] (default 2000; 50 is enough under callgrind).
program bench_mpm1d
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_config, only: mpm_config_t, shape_gimp, shape_linear, shape_names
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, timer_umat, &
                                  timer_transfer, timer_grid
  use wellposed_mpm_particles, only: particle_bytes
  use wellposed_umat_layout, only: prop_bulk, prop_shear, prop_beta, prop_k0, prop_explicit
  implicit none
  integer, parameter :: nwarm = 200
  integer :: nsteps = 2000                 !< first argument, if given
  character(len=32) :: arg
  real(dp), parameter :: target_ns = 150.0_dp
  type(mpm_config_t) :: cfg
  type(mpm_scene_t) :: sc
  type(error_t), allocatable :: err
  integer :: kind, k
  integer(int64) :: t0, t1, rate
  real(dp) :: ns, tot

  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    read (arg, *) nsteps
  end if
  write (output_unit, '(a)') 'bench_mpm1d: Sandler-Rubin default scene, 700 m, dx = 0.25 m, '// &
    '2 particles per cell, MUSL, plastic Drucker-Prager UMAT'
  write (output_unit, '(a)') '  shape    ns/particle/step  target  ratio  bytes/particle'// &
    '  UMAT share  transfer share  grid share'
  do kind = shape_linear, shape_gimp
    cfg%name = 'bench'
    cfg%title = 'bench'
    cfg%shape = kind
    cfg%progress = .false.
    cfg%props = 0.0_dp
    cfg%props(prop_bulk) = 4.0e9_dp
    cfg%props(prop_shear) = 1.5e9_dp
    cfg%props(prop_beta) = 0.315_dp
    cfg%props(prop_k0) = 5.066e6_dp
    cfg%props(prop_explicit) = 1.0_dp
    cfg%nprops = prop_explicit
    call new_scene(sc, cfg, err)
    if (allocated(err)) error stop 'bench_mpm1d: scene'
    do k = 1, nwarm
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm1d: warm-up'
    end do
    sc%ticks = 0
    call system_clock(t0, rate)
    do k = 1, nsteps
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm1d: step'
    end do
    call system_clock(t1)
    ns = 1.0e9_dp*real(t1 - t0, dp)/real(rate, dp)/(real(nsteps, dp)*sc%parts%n)
    tot = max(1.0_dp, real(sum(sc%ticks), dp))
    write (output_unit, '(2x,a6,f14.1,f10.0,f7.2,i12,f14.3,f14.3,f14.3)') &
      shape_names(kind), ns, target_ns, ns/target_ns, &
      particle_bytes(1, sc%parts%nsup, cfg%nstatv), real(sc%ticks(timer_umat), dp)/tot, &
      real(sc%ticks(timer_transfer), dp)/tot, real(sc%ticks(timer_grid), dp)/tot
  end do
end program bench_mpm1d
