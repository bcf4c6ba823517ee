!> The Abaqus/Standard UMAT entry point of wellposed (contract:
!> docs/guide/umat.md): an external subroutine with the exact Abaqus signature,
!> callable from free- or fixed-form Fortran without any module. All work is
!> done by wellposed_umat_adapter; this routine forwards, and a failure goes
!> to wellposed_umat_report (a message once per material and kind).
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
                stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, &
                ndi, nshr, ntens, nstatv, props, nprops, coords, drot, pnewdt, &
                celent, dfgrd0, dfgrd1, noel, npt, layer, kspt, kstep, kinc)
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_adapter, only: umat_update
  use wellposed_umat_report, only: umat_report
  implicit none
  character(len=80), intent(in) :: cmname
  integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, kstep, kinc
  real(dp), intent(inout) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
  real(dp), intent(inout) :: sse, spd, scd, rpl, ddsddt(ntens), drplde(ntens), drpldt
  real(dp), intent(in) :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
  real(dp), intent(in) :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3)
  real(dp), intent(inout) :: pnewdt
  real(dp), intent(in) :: celent, dfgrd0(3, 3), dfgrd1(3, 3)
  type(error_t), allocatable :: err

  call umat_update(stress, statev, ddsdde, sse, spd, dstran, stran, dtime, ndi, nshr, &
                   ntens, nstatv, props, nprops, pnewdt, err)
  if (allocated(err)) call umat_report(err, cmname, noel, npt)

end subroutine umat
