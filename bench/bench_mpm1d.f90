!> bench_mpm1d: CPU nanoseconds per particle per step of the 1D explicit MPM
!> on the default Sandler-Rubin scene (5600 plastic particles, dx = 0.25 m)
!> for linear and GIMP weights, as a ratio to the elastic trial stress
!> (bench_trial_clock) timed in the same run, with the step's shares; rows 3
!> and 4: every particle through its own UMAT call, and &time mass =
!> 'blended'. The fastest of `nrounds` rounds is kept. Never a pass/fail.
!> Usage: bench_mpm1d [NSTEPS [ROW]] (ROW 1-4: that row alone, for a
!> profile). Targets and method: docs/guide/performance.md.
program bench_mpm1d
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use wellposed_kinds, only: dp
  use bench_args, only: int_arg, most_args
  use wellposed_error, only: error_t
  use wellposed_mpm_bar_config, only: bar_config_t, shape_gimp, shape_linear, shape_names, &
                                  mass_lumped, mass_blended
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, timer_umat, &
                                  timer_transfer, timer_grid, plastic_count
  use wellposed_mpm_particles, only: particle_bytes
  use wellposed_umat_layout, only: prop_bulk, prop_shear, prop_beta, prop_k0, prop_explicit
  use wellposed_umat_interface, only: umat
  use bench_trial_clock, only: trial_ns
  implicit none
  integer, parameter :: nwarm = 200, nrounds = 10, trial_calls = 200000
  real(dp), parameter :: target_ratio = 6.0_dp   !< GIMP, x trial
  integer :: nsteps = 2000                 !< first argument, if given
  type(bar_config_t) :: cfg
  type(mpm_scene_t) :: sc
  type(error_t), allocatable :: err
  integer :: kind, k, round, per_round, nplastic, row, row_first, row_last
  character(len=6) :: label
  real(dp) :: ns, trial, t0, t1, tot, sink

  call most_args('bench_mpm1d', 2, 'bench_mpm1d [NSTEPS [ROW]]')
  if (command_argument_count() >= 1) nsteps = int_arg('bench_mpm1d', 1, 'NSTEPS', 1, 10**7)
  row_first = 1
  row_last = 4
  if (command_argument_count() >= 2) then
    row_first = int_arg('bench_mpm1d', 2, 'ROW', 1, 4)
    row_last = row_first
  end if
  per_round = max(1, nsteps/nrounds)
  sink = 0.0_dp
  write (output_unit, '(a)') 'bench_mpm1d: Sandler-Rubin default scene, 700 m, dx = 0.25 m, '// &
    '2 particles per cell, MUSL, plastic Drucker-Prager'
  write (output_unit, '(a,i0,a,i0,a)') '  CPU time, fastest of ', nrounds, ' rounds of ', &
    per_round, ' steps; the trial timed in every round'
  write (output_unit, '(a)') '  shape   ns/particle/step  trial ns  /trial  target  plastic'// &
    '  stress-update share  transfer share  grid share  bytes/particle'
  do row = row_first, row_last
    kind = merge(shape_linear, shape_gimp, row == 1)
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
    cfg%mass = merge(mass_blended, mass_lumped, row == 4)
    cfg%cfl = 0.2_dp   ! every row the same step
    call new_scene(sc, cfg, err)
    if (allocated(err)) error stop 'bench_mpm1d: scene'
    label = shape_names(kind)
    if (row == 3) then
      sc%host%fn => umat     ! the per-particle path of a user's UMAT
      label = 'gimp*'
    end if
    if (row == 4) label = 'gimp+M'
    do k = 1, nwarm
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm1d: warm-up'
    end do
    sc%ticks = 0
    ns = huge(1.0_dp)
    trial = huge(1.0_dp)
    nplastic = 0
    do round = 1, nrounds
      trial = min(trial, trial_ns(trial_calls, sink))
      call cpu_time(t0)
      do k = 1, per_round
        call advance(sc, err)
        if (allocated(err)) error stop 'bench_mpm1d: step'
        nplastic = max(nplastic, plastic_count(sc))
      end do
      call cpu_time(t1)
      ns = min(ns, (t1 - t0)*1.0e9_dp/(real(per_round, dp)*sc%parts%n))
    end do
    tot = max(1.0_dp, real(sum(sc%ticks), dp))
    write (output_unit, '(2x,a6,f14.1,f12.1,f8.2,f8.1,i9,f15.3,f17.3,f13.3,i12)') &
      label, ns, trial, ns/trial, merge(target_ratio, 0.0_dp, kind == shape_gimp), &
      nplastic, real(sc%ticks(timer_umat), dp)/tot, real(sc%ticks(timer_transfer), dp)/tot, &
      real(sc%ticks(timer_grid), dp)/tot, particle_bytes(1, sc%parts%nsup, cfg%nstatv)
  end do
  write (output_unit, '(a)') '  (target: GIMP <= 6x the trial; gimp*: one UMAT call per '// &
    'particle, as for a user''s UMAT; gimp+M: &time mass = ''blended'', counted in the grid '// &
    'share; plastic: the most particles plastic in one timed step; shares of the step''s '// &
    'wall ticks)'
  if (sink == 0.0_dp) write (output_unit, '(a)') ''
end program bench_mpm1d
