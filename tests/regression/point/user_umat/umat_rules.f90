! A free-form test UMAT for the UMAT host's rules in the point driver:
! linear elasticity from PROPS(1) = K, PROPS(2) = G, misbehaving as
! PROPS(3) says: 1 refuses (PNEWDT = -1), 2 returns a NaN stress from the
! third increment on, 3 asks for a cut-back (PNEWDT = 0.5) for axial
! increments above 2e-4, 4 raises an error through STDB_ABQERR (LOP = -2).
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
                stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, &
                ndi, nshr, ntens, nstatv, props, nprops, coords, drot, pnewdt, &
                celent, dfgrd0, dfgrd1, noel, npt, layer, kspt, kstep, kinc)
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  character(len=80), intent(in) :: cmname
  integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, kstep, kinc
  real(dp), intent(inout) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
  real(dp), intent(inout) :: sse, spd, scd, rpl, ddsddt(ntens), drplde(ntens), drpldt
  real(dp), intent(in) :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
  real(dp), intent(in) :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3)
  real(dp), intent(inout) :: pnewdt
  real(dp), intent(in) :: celent, dfgrd0(3, 3), dfgrd1(3, 3)
  real(dp) :: lam
  integer :: i, mode
  mode = nint(props(3))
  if (mode == 1) then
    write (*, '(a)') 'umat_rules: mode 1 refuses every input'
    pnewdt = -1.0_dp
    return
  end if
  if (mode == 3 .and. abs(dstran(1)) > 2.0e-4_dp) then
    pnewdt = 0.5_dp
    return
  end if
  if (mode == 4) then
    call stdb_abqerr(-2, 'umat_rules: mode %I raises an error', [mode], [0.0_dp], ['        '])
    return
  end if
  lam = props(1) - 2.0_dp*props(2)/3.0_dp
  ddsdde = 0.0_dp
  ddsdde(1:ndi, 1:ndi) = lam
  do i = 1, ndi
    ddsdde(i, i) = lam + 2.0_dp*props(2)
  end do
  do i = ndi + 1, ntens
    ddsdde(i, i) = props(2)
  end do
  stress = stress + matmul(ddsdde, dstran)
  statev(1) = statev(1) + 1.0_dp
  if (mode == 2 .and. kinc >= 3) then
    ! a quiet NaN (0/0 would trap in a Debug build, -ffpe-trap=invalid)
    stress(2) = ieee_value(stress(2), ieee_quiet_nan)
  end if
end subroutine umat
