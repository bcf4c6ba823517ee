!> Calls the external umat the way a legacy host does, once with invalid
!> PROPS (status -1: one line on standard error) and once with a NaN in
!> DSTRAN (status -2: a silent cut-back request). check_umat_stderr.cmake
!> runs it and checks standard error holds exactly the one line.
program umat_stderr_main
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  real(dp) :: props(6), stress(6), statev(12), ddsdde(6, 6), dstran(6), stran(6), time(2)
  real(dp) :: sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt, predef(1), coords(3)
  real(dp) :: drot(3, 3), f(3, 3), pnewdt(2)
  character(len=80) :: cmname
  integer :: icall
  sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; predef = 0
  coords = 0; drot = 0; f = 0; stran = 0; time = 0; cmname = 'BAD'
  do icall = 1, 2
    props = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp, 0.0_dp]
    dstran = [1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    if (icall == 1) props(6) = -1.0e10_dp
    if (icall == 2) dstran(2) = ieee_value(dstran(2), ieee_quiet_nan)
    stress = 0.0_dp; statev = 0.0_dp; pnewdt(icall) = 1.0_dp
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
              dstran, time, 1.0_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, &
              props, 6, coords, drot, pnewdt(icall), 1.0_dp, f, f, 7, 3, 1, 1, 1, 1)
  end do
  write (*, '(a,2f6.2)') 'PNEWDT', pnewdt
end program umat_stderr_main
