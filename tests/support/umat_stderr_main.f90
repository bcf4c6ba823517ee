!> Calls the external umat the way legacy hosts do and prints PNEWDT after
!> each call: material BAD with PNEWDT = 1 on entry (Abaqus's and our
!> drivers' convention), invalid PROPS, a NaN in DSTRAN, invalid PROPS again
!> at another element; then material OTHER with PNEWDT = -1 on entry
!> (CalculiX's), invalid PROPS and a NaN in STATEV. check_umat_stderr.cmake
!> checks one line per material and kind on standard error and the PNEWDT
!> each host needs; with WELLPOSED_UMAT_ON_ERROR=stop, the stop at call 1.
program umat_stderr_main
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  real(dp) :: props(6), stress(6), statev(12), ddsdde(6, 6), dstran(6), stran(6), time(2)
  real(dp) :: sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt, predef(1), coords(3)
  real(dp) :: drot(3, 3), f(3, 3), pnewdt(5)
  character(len=80) :: cmname
  integer :: icall, noel
  sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; predef = 0
  coords = 0; drot = 0; f = 0; stran = 0; time = 0
  do icall = 1, 5
    props = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp, 0.0_dp]
    dstran = [1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    stress = 0.0_dp; statev = 0.0_dp
    cmname = merge('BAD  ', 'OTHER', icall <= 3)
    pnewdt(icall) = merge(1.0_dp, -1.0_dp, icall <= 3)
    noel = merge(8, 7, icall == 3)
    if (any(icall == [1, 3, 4])) props(6) = -1.0e10_dp
    if (icall == 2) dstran(2) = ieee_value(dstran(2), ieee_quiet_nan)
    if (icall == 5) statev(1) = ieee_value(statev(1), ieee_quiet_nan)
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
              dstran, time, 1.0_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, &
              props, 6, coords, drot, pnewdt(icall), 1.0_dp, f, f, noel, 3, 1, 1, 1, 1)
  end do
  write (*, '(a,5f6.2)') 'PNEWDT', pnewdt
end program umat_stderr_main
