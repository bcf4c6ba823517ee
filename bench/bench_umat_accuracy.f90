!> bench_umat_accuracy: the speed/accuracy trade of the UMAT's time
!> integration. A non-proportional strain path (uniaxial-strain extension,
!> then shear) cut into N increments per leg, its end stress compared with
!> N = 65536 and its cost timed in the same run, for the regular flow rule,
!> eq. 2.6 and the EFR (backward Euler: error ~ 1/N on non-radial paths).
!> Usage: bench_umat_accuracy [csv file]. Results: docs/guide/performance.md.
program bench_umat_accuracy
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  integer, parameter :: nmodels = 3, nlevels = 11, nref = 65536
  character(len=*), parameter :: names(nmodels) = [character(len=28) :: &
    'nonassociative DP', 'exponential hardening eq.2.6', 'EFR P_v = 0.5']
  real(dp) :: props(14), s_ref(6), s(6), err(nlevels, nmodels), cost(nlevels, nmodels)
  real(dp) :: order(nlevels, nmodels)
  real(dp), parameter :: s_start(6) = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, &
                                       0.0_dp]
  integer :: model, level, n, unit
  character(len=256) :: csv

  do model = 1, nmodels
    props = 0.0_dp
    props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
    if (model == 2) props(7:8) = [10.0e6_dp, 1.0e-3_dp]
    if (model == 3) then
      props(4) = 0.315_dp; props(9) = 0.5_dp
    end if
    props(14) = 1.0_dp  ! explicit-style: the stress is what is measured
    call run_path(props, nref, s_ref)
    do level = 1, nlevels
      n = 2**(level - 1)
      cost(level, model) = timed_path(props, n, s)
      err(level, model) = norm2(s - s_ref)/norm2(s_ref - s_start)
    end do
    order(1, model) = 0.0_dp
    order(2:, model) = log(err(:nlevels - 1, model)/err(2:, model))/log(2.0_dp)
  end do

  write (output_unit, '(a)') 'bench_umat_accuracy: end-stress error of a non-proportional '// &
    'path against N = 65536 increments per leg'
  do model = 1, nmodels
    write (output_unit, '(/,2x,a)') trim(names(model))
    write (output_unit, '(a)') '    N per leg   relative error   order   cost per path (us)'
    write (output_unit, '(a)') '                (of the change)  (0 at N = 1)'
    do level = 1, nlevels
      write (output_unit, '(i13,es17.3,f8.2,f16.2)') 2**(level - 1), err(level, model), &
        order(level, model), cost(level, model)*1.0e6_dp
    end do
  end do
  if (command_argument_count() >= 1) then
    call get_command_argument(1, csv)
    open (newunit=unit, file=trim(csv), status='replace', action='write')
    write (unit, '(a)') 'model,increments_per_leg,relative_error,cost_s'
    do model = 1, nmodels
      do level = 1, nlevels
        write (unit, '(a,",",i0,",",es16.8,",",es16.8)') trim(names(model)), 2**(level - 1), &
          err(level, model), cost(level, model)
      end do
    end do
    close (unit)
  end if

contains

  !> Seconds per path, repeated until at least 0.05 s has been measured.
  function timed_path(props, n, s) result(seconds)
    real(dp), intent(in) :: props(14)
    integer, intent(in) :: n
    real(dp), intent(out) :: s(6)
    real(dp) :: seconds
    integer(int64) :: t0, t1, rate
    integer :: reps
    reps = 0
    call system_clock(t0, rate)
    do
      call run_path(props, n, s)
      reps = reps + 1
      call system_clock(t1)
      if (real(t1 - t0, dp)/real(rate, dp) >= 0.05_dp) exit
    end do
    seconds = real(t1 - t0, dp)/real(rate, dp)/reps
  end function timed_path

  !> The two-leg path in n increments per leg; returns the end stress.
  subroutine run_path(props, n, s)
    real(dp), intent(in) :: props(14)
    integer, intent(in) :: n
    real(dp), intent(out) :: s(6)
    real(dp) :: statev(12), ddsdde(6, 6), sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt
    real(dp) :: stran(6), dstran(6), time(2), predef(1), coords(3), drot(3, 3), f(3, 3)
    real(dp) :: pnewdt
    character(len=80) :: cmname
    integer :: leg, i
    s = s_start
    statev = 0; sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0
    stran = 0; time = 0; predef = 0; coords = 0; drot = 0; f = 0; cmname = 'BENCH'
    do leg = 1, 2
      if (leg == 1) dstran = [4.0e-4_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]/n
      if (leg == 2) dstran = [0.0_dp, 0.0_dp, 0.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp]/n
      do i = 1, n
        pnewdt = 1.0_dp
        call umat(s, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
                  dstran, time, 1.0e-3_dp/n, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, &
                  12, props, 14, coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, i)
        if (pnewdt < 1.0_dp) error stop 'bench_umat_accuracy: the UMAT refused an increment'
        stran = stran + dstran
      end do
    end do
  end subroutine run_path

end program bench_umat_accuracy
