!> Explicit interface of the external `umat` (the Abaqus signature), for
!> Fortran hosts that want argument checking: `use wellposed_umat_interface`.
!> Fixed-form and legacy hosts call `umat` without it.
module wellposed_umat_interface
  implicit none
  private
  public :: umat

  interface
    subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
                    stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, &
                    ndi, nshr, ntens, nstatv, props, nprops, coords, drot, pnewdt, &
                    celent, dfgrd0, dfgrd1, noel, npt, layer, kspt, kstep, kinc)
      use wellposed_kinds, only: dp
      implicit none
      character(len=80), intent(in) :: cmname
      integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, &
                             kstep, kinc
      real(dp), intent(inout) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
      real(dp), intent(inout) :: sse, spd, scd, rpl, ddsddt(ntens), drplde(ntens), drpldt
      real(dp), intent(in) :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
      real(dp), intent(in) :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3)
      real(dp), intent(inout) :: pnewdt
      real(dp), intent(in) :: celent, dfgrd0(3, 3), dfgrd1(3, 3)
    end subroutine umat
  end interface

end module wellposed_umat_interface
