!> bench_umat: nanoseconds per UMAT call (NTENS 6) for elastic, plastic-cone
!> and apex increments of the case-study material, with DDSDDE and without
!> it (PROPS(14) = 1, an explicit host), and the ratio of each to the cost of
!> the elastic trial stress alone (bench_elastic_trial), all measured in this
!> one run: the ratios hold on a shared machine where absolute times drift.
!>
!> Usage: bench_umat [calls per case]   (default 2,000,000; use a small number
!> under valgrind --tool=callgrind for instruction counts)
program bench_umat
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  interface
    subroutine bench_elastic_trial(stress, statev, ddsdde, dstran, nstatv)
      import :: dp
      integer, intent(in) :: nstatv
      real(dp), intent(inout) :: stress(6), statev(nstatv)
      real(dp), intent(in) :: ddsdde(6, 6), dstran(6)
    end subroutine bench_elastic_trial
  end interface
  character(len=*), parameter :: names(3) = ['elastic     ', 'plastic cone', 'apex        ']
  real(dp) :: strains(6, 3), base_stress(6, 3), t_trial, t_case(3, 2), sink
  integer :: ncalls, icase, itan
  character(len=32) :: arg

  ncalls = 2000000
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    read (arg, *) ncalls
  end if
  ! Elastic: a small increment inside the cone; cone: extension from the
  ! case-study state (fig. 2.2); apex: strong hydrostatic tension from zero.
  base_stress(:, 1) = [-100.0e6_dp, -30.0e6_dp, -30.0e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  strains(:, 1) = [1.0e-6_dp, 0.0_dp, 0.0_dp, 1.0e-7_dp, 0.0_dp, 0.0_dp]
  base_stress(:, 2) = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  strains(:, 2) = [1.0e-4_dp, -2.0e-5_dp, 3.0e-5_dp, 4.0e-5_dp, -1.0e-5_dp, 2.0e-5_dp]
  base_stress(:, 3) = 0.0_dp
  strains(:, 3) = [3.0e-3_dp, 2.0e-3_dp, 2.5e-3_dp, 1.0e-4_dp, -2.0e-4_dp, 3.0e-4_dp]

  sink = 0.0_dp
  t_trial = time_trial(base_stress(:, 2), strains(:, 2))
  do itan = 1, 2
    do icase = 1, 3
      t_case(icase, itan) = time_umat(base_stress(:, icase), strains(:, icase), icase, itan == 2)
    end do
  end do

  write (output_unit, '(a,i0,a)') 'bench_umat: ', ncalls, ' calls per case, NTENS = 6'
  write (output_unit, '(a,f8.1,a)') '  elastic trial alone (lower bound):   ', t_trial, ' ns'
  write (output_unit, '(a)') '  case            with DDSDDE   ratio   without   ratio'
  do icase = 1, 3
    write (output_unit, '(2x,a,f13.1,a,f6.2,f9.1,a,f6.2)') names(icase), t_case(icase, 1), &
      ' ns', t_case(icase, 1)/t_trial, t_case(icase, 2), ' ns', t_case(icase, 2)/t_trial
  end do
  if (sink == 1.2345_dp) write (output_unit, '(a)') 'checksum hit'

contains

  !> ns per call of umat for one case, resetting stress and state each call.
  function time_umat(s0, de, icase, explicit) result(ns)
    real(dp), intent(in) :: s0(6), de(6)
    integer, intent(in) :: icase
    logical, intent(in) :: explicit
    real(dp) :: ns
    real(dp) :: props(14), stress(6), statev(12), ddsdde(6, 6), sse, spd, scd, rpl, ddsddt(6)
    real(dp) :: drplde(6), drpldt, stran(6), time(2), predef(1), coords(3), drot(3, 3), f(3, 3)
    real(dp) :: pnewdt
    character(len=80) :: cmname
    integer(int64) :: t0, t1, rate
    integer :: i
    props = 0.0_dp
    props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
    if (explicit) props(14) = 1.0_dp
    sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; stran = 0
    time = 0; predef = 0; coords = 0; drot = 0; f = 0; cmname = 'BENCH'; ddsdde = 0
    stress = s0; statev = 0; pnewdt = 1
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, de, &
              time, 1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, props, 14, &
              coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, 1)
    if (nint(statev(12)) /= icase - 1) error stop 'bench_umat: a case is not in its regime'
    call system_clock(t0, rate)
    do i = 1, ncalls
      stress = s0; statev = 0.0_dp
      call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, de, &
                time, 1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, props, 14, &
                coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, 1)
      sink = sink + stress(1)
    end do
    call system_clock(t1)
    ns = real(t1 - t0, dp)/real(rate, dp)*1.0e9_dp/ncalls
  end function time_umat

  !> ns per elastic trial stress, with the same resets.
  function time_trial(s0, de) result(ns)
    real(dp), intent(in) :: s0(6), de(6)
    real(dp) :: ns, stress(6), statev(12), c(6, 6)
    integer(int64) :: t0, t1, rate
    integer :: i
    c = 0.0_dp
    c(1:3, 1:3) = 4.0e9_dp - 1.0e9_dp
    do i = 1, 3
      c(i, i) = 4.0e9_dp + 2.0e9_dp
      c(i + 3, i + 3) = 1.5e9_dp
    end do
    call system_clock(t0, rate)
    do i = 1, ncalls
      stress = s0; statev = 0.0_dp
      call bench_elastic_trial(stress, statev, c, de, 12)
      sink = sink + stress(1)
    end do
    call system_clock(t1)
    ns = real(t1 - t0, dp)/real(rate, dp)*1.0e9_dp/ncalls
  end function time_trial

end program bench_umat
