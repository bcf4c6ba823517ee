!> bench_mpm2d: CPU ns per particle per step of the plane-strain MPM, the
!> plastic model through the VUMAT on blocks (a deck's default), as a ratio
!> to the elastic trial stress (bench_trial_clock) timed in the same run,
!> with the step's shares, on the 4 m x 5 m plate at h = 0.25 m (linear,
!> GIMP, CPDI under the platen; CPDI in free pure shear, every particle
!> plastic), then a nonlocal sweep (Gauss-Seidel, Jacobi) against a local
!> update. The fastest of `nrounds` rounds is kept; never a pass/fail.
!> Usage: bench_mpm2d [ROW] (1-5: that row). docs/guide/performance.md.
program bench_mpm2d
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use wellposed_kinds, only: dp
  use bench_args, only: int_arg, most_args
  use wellposed_error, only: error_t
  use wellposed_mpm_plate_build, only: plate_config_t
  use wellposed_mpm_plate_config, only: bc_plate_free
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, timer_umat, &
                                  timer_transfer, timer_grid, plastic_count
  use wellposed_mpm_shape_2d, only: shape2d_linear, shape2d_cpdi, shape2d_names
  use wellposed_mpm_materials, only: add_material
  use wellposed_mpm_nonlocal_settings, only: ours_bounds, nl_gauss_seidel, nl_jacobi, &
                                             nl_sweep_names
  use bench_trial_clock, only: trial_ns
  implicit none
  integer, parameter :: nwarm = 150, nrounds = 8, per_round = 50, trial_calls = 200000
  real(dp), parameter :: target_ratio = 20.0_dp   !< CPDI, every particle plastic, x trial
  type(plate_config_t) :: cfg
  type(mpm_scene_t) :: sc
  type(error_t), allocatable :: err
  integer :: kind, k, row, step
  integer, parameter :: sweeps(2) = [nl_gauss_seidel, nl_jacobi]
  real(dp) :: ratio, sink

  sink = 0.0_dp
  row = 0
  call most_args('bench_mpm2d', 1, 'bench_mpm2d [ROW]')
  if (command_argument_count() >= 1) row = int_arg('bench_mpm2d', 1, 'ROW', 1, 5)
  write (output_unit, '(a)') 'bench_mpm2d: plane-strain plate 4 m x 5 m, h = 0.25 m, 2 x 2 '// &
    'particles per cell, von Mises (k0 = 40 MPa)'
  write (output_unit, '(a,i0,a,i0,a)') '  CPU time, fastest of ', nrounds, ' rounds of ', &
    per_round, ' steps (sheared: 10); the trial timed in every round'
  write (output_unit, '(a)') '  scene           ns/particle/step  trial ns  /trial  target'// &
    '  plastic  stress-update share  transfer share  grid share'
  do kind = shape2d_linear, shape2d_cpdi
    if (row /= 0 .and. row /= kind - shape2d_linear + 1) cycle
    cfg = plate(kind, 0.0_dp)
    call measure('loaded '//shape2d_names(kind), 0.0_dp, nwarm, per_round)
  end do
  if (row == 0 .or. row == 4) then
    cfg = plate(shape2d_cpdi, 0.0_dp)
    cfg%bottom = bc_plate_free
    cfg%top = bc_plate_free
    cfg%velocity_gradient0 = reshape([-100.0_dp, 0.0_dp, 0.0_dp, 100.0_dp], [2, 2])
    call measure('sheared cpdi', target_ratio, 20, 10)
  end if
  write (output_unit, '(a)') '  (target: CPDI with every particle plastic <= 20x the trial; '// &
    'plastic: the fewest plastic in one timed step / particles; shares of the wall ticks)'
  if (row /= 0 .and. row /= 5) stop

  ! one nonlocal sweep against one local update (CPDI, overlocal, L = 0.5 m):
  ! the default sweep on one rank (Gauss-Seidel), then the Jacobi sweep
  do k = 1, 2
    cfg = plate(shape2d_cpdi, 0.5_dp)
    cfg%nonlocal%sweep = sweeps(k)
    call new_scene(sc, cfg, err)
    if (allocated(err)) error stop 'bench_mpm2d: nonlocal scene'
    do step = 1, nwarm + 100
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm2d: nonlocal step'
    end do
    ratio = (real(sc%nl%ticks_sweeps, dp)/max(sc%nl%calls_sweeps, 1_int64))/ &
            (real(max(sc%nl%ticks_local, 1_int64), dp)/max(sc%nl%calls_local, 1_int64))
    write (output_unit, '(a,a12,a,f6.2,a,f6.2,a,f6.2)') '  nonlocal sweep (', &
      adjustr(trim(nl_sweep_names(sweeps(k)))), ') / local update: ', ratio, '   target 2.0, ratio ', &
      ratio/2.0_dp, ';  mean sweeps per step ', &
      real(sc%nl%iterations_total, dp)/max(sc%nl%steps_iterated, 1)
  end do
  if (sink == 0.0_dp) write (output_unit, '(a)') ''

contains

  !> Build the scene of cfg, warm it up, time it in rounds and print its row.
  subroutine measure(label, target, warm, steps)
    character(len=*), intent(in) :: label
    real(dp), intent(in) :: target
    integer, intent(in) :: warm, steps
    real(dp) :: ns, trial, t0, t1, tot
    integer :: round, step, nplastic
    call new_scene(sc, cfg, err)
    if (allocated(err)) error stop 'bench_mpm2d: scene'
    do step = 1, warm
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm2d: warm-up'
    end do
    sc%ticks = 0
    ns = huge(1.0_dp)
    trial = huge(1.0_dp)
    nplastic = huge(1)
    do round = 1, nrounds
      trial = min(trial, trial_ns(trial_calls, sink))
      call cpu_time(t0)
      do step = 1, steps
        call advance(sc, err)
        if (allocated(err)) then
          write (output_unit, '(a)') err%message
          error stop 'bench_mpm2d: step'
        end if
        nplastic = min(nplastic, plastic_count(sc))
      end do
      call cpu_time(t1)
      ns = min(ns, (t1 - t0)*1.0e9_dp/(real(steps, dp)*sc%parts%n))
    end do
    tot = max(1.0_dp, real(sum(sc%ticks), dp))
    write (output_unit, '(2x,a14,f14.1,f12.1,f8.2,f8.1,f9.2,f15.3,f17.3,f13.3)') label, ns, &
      trial, ns/trial, target, real(nplastic, dp)/sc%parts%n, &
      real(sc%ticks(timer_umat), dp)/tot, real(sc%ticks(timer_transfer), dp)/tot, &
      real(sc%ticks(timer_grid), dp)/tot
  end subroutine measure

  function plate(kind, length) result(c)
    integer, intent(in) :: kind
    real(dp), intent(in) :: length
    type(plate_config_t) :: c
    type(error_t), allocatable :: err
    real(dp) :: weak(14)
    c = plate_config_t()
    c%dx = 0.25_dp
    c%shape = kind
    c%props = 0.0_dp
    c%props(1:6) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 40.0e6_dp, 0.0_dp]
    if (length > 0.0_dp) then
      c%props(6) = 2.0e9_dp
      c%props(12) = -4.0e9_dp
      c%props(13) = length
      ! Algorithm 1 iterates, with the deck's defaults (&nonlocal)
      c%nonlocal%active = .true.
      c%nonlocal%length = length
      c%nonlocal%h_zeta = c%props(12)
      call ours_bounds(c%props(1:14), c%nonlocal%bound_43, c%nonlocal%bound_45)
    end if
    c%props(14) = 1.0_dp
    c%nprops = 14
    ! the body, and the weak corner [0, 1] x [0, 1] m with k0 = 38 MPa
    c%materials%ndim = 2
    call add_material(c%materials, c%props(1:14), 12, .true., .false., err, vumat=.true.)
    weak = c%props(1:14)
    weak(5) = 38.0e6_dp
    call add_material(c%materials, weak, 12, .true., .false., err, [0.0_dp, 0.0_dp], &
                      [1.0_dp, 1.0_dp], vumat=.true.)
    c%t_end = 1.0_dp
  end function plate

end program bench_mpm2d
