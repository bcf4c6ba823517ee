!> bench_mpm2d: nanoseconds per particle per step of the plane-strain MPM
!> (wellposed_mpm_plane_strain) with the plastic UMAT, for linear, GIMP and
!> CPDI weights, and the cost of one nonlocal sweep (Algorithm 1) against a
!> local stress update of the same particles. Prints measures and their
!> ratios to the targets (linear 150, GIMP 250, CPDI 450 ns; sweep
!> 1.5x); never a pass/fail on wall time.
!>
!> Scene: the 4 m x 5 m plate at h = 0.25 m (1280 particles), von Mises with
!> k0 = 40 MPa so that nearly every particle is plastic after ~60 steps;
!> timed over the following `nsteps` steps.
program bench_mpm2d
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_plane_strain, only: ps_config_t
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, timer_umat
  use wellposed_mpm_shape_2d, only: shape2d_linear, shape2d_cpdi, shape2d_names
  use wellposed_mpm_materials, only: add_material
  implicit none
  integer, parameter :: nwarm = 150, nsteps = 400
  real(dp), parameter :: targets(3) = [150.0_dp, 250.0_dp, 450.0_dp]
  type(ps_config_t) :: cfg
  type(mpm_scene_t) :: sc
  type(error_t), allocatable :: err
  integer :: kind, k, nplastic
  integer(int64) :: t0, t1, rate
  real(dp) :: ns, ratio

  write (output_unit, '(a)') 'bench_mpm2d: plane-strain plate, h = 0.25 m, 2 x 2 particles '// &
    'per cell, plastic von Mises (k0 = 40 MPa)'
  write (output_unit, '(a)') '  shape     ns/particle/step   target   ratio   plastic share   UMAT share'
  do kind = shape2d_linear, shape2d_cpdi
    cfg = plate(kind, 0.0_dp)
    call new_scene(sc, cfg, err)
    if (allocated(err)) error stop 'bench_mpm2d: scene'
    do k = 1, nwarm
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm2d: warm-up'
    end do
    sc%ticks = 0
    call system_clock(t0, rate)
    do k = 1, nsteps
      call advance(sc, err)
      if (allocated(err)) error stop 'bench_mpm2d: step'
    end do
    call system_clock(t1)
    nplastic = count(sc%parts%statev(2, 1:sc%parts%n) > 0.0_dp)
    ns = real(t1 - t0, dp)/rate*1.0e9_dp/(real(sc%parts%n, dp)*nsteps)
    write (output_unit, '(2x,a8,f14.1,f12.0,f9.2,f11.2,f15.2)') shape2d_names(kind), ns, &
      targets(kind), ns/targets(kind), real(nplastic, dp)/sc%parts%n, &
      real(sc%ticks(timer_umat), dp)/max(sum(sc%ticks), 1_int64)
  end do

  ! one nonlocal sweep against one local update (CPDI, overlocal, L = 0.5 m)
  cfg = plate(shape2d_cpdi, 0.5_dp)
  call new_scene(sc, cfg, err)
  if (allocated(err)) error stop 'bench_mpm2d: nonlocal scene'
  do k = 1, nwarm + nsteps/4
    call advance(sc, err)
    if (allocated(err)) error stop 'bench_mpm2d: nonlocal step'
  end do
  ratio = (real(sc%nl%ticks_sweeps, dp)/max(sc%nl%calls_sweeps, 1_int64))/ &
          (real(max(sc%nl%ticks_local, 1_int64), dp)/max(sc%nl%calls_local, 1_int64))
  write (output_unit, '(a,f6.2,a,f6.2,a,f6.2)') '  nonlocal sweep / local update: ', ratio, &
    '   target 1.5, ratio ', ratio/1.5_dp, ';  mean sweeps per step ', &
    real(sc%nl%iterations_total, dp)/max(sc%nl%steps_iterated, 1)

contains

  function plate(kind, length) result(c)
    integer, intent(in) :: kind
    real(dp), intent(in) :: length
    type(ps_config_t) :: c
    type(error_t), allocatable :: err
    real(dp) :: weak(14)
    c = ps_config_t()
    c%dx = 0.25_dp
    c%shape = kind
    c%props = 0.0_dp
    c%props(1:6) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 40.0e6_dp, 0.0_dp]
    if (length > 0.0_dp) then
      c%props(6) = 2.0e9_dp
      c%props(12) = -4.0e9_dp
      c%props(13) = length
    end if
    c%props(14) = 1.0_dp
    c%nprops = 14
    ! the body, and the weak corner [0, 1] x [0, 1] m with k0 = 38 MPa
    c%materials%ndim = 2
    call add_material(c%materials, c%props(1:14), 12, .true., .false., err)
    weak = c%props(1:14)
    weak(5) = 38.0e6_dp
    call add_material(c%materials, weak, 12, .true., .false., err, [0.0_dp, 0.0_dp], &
                      [1.0_dp, 1.0_dp])
    c%t_end = 1.0_dp
  end function plate

end program bench_mpm2d
