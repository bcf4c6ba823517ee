!> The Abaqus/Standard UMAT entry point of wellposed (contract:
!> docs/umat.md): an external subroutine with the exact Abaqus signature,
!> callable from free- or fixed-form Fortran without any module. All work is
!> done by wellposed_umat_adapter; this routine forwards and, for invalid
!> input (status -1), writes one line to standard error.
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
                stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, &
                ndi, nshr, ntens, nstatv, props, nprops, coords, drot, pnewdt, &
                celent, dfgrd0, dfgrd1, noel, npt, layer, kspt, kstep, kinc)
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, status_invalid
  use wellposed_umat_adapter, only: umat_update
  use wellposed_text, only: int_text
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
  if (allocated(err)) then
    if (err%status == status_invalid) then
      write (error_unit, '(a)') 'wellposed UMAT error (element '//int_text(noel)//', point '// &
        int_text(npt)//'): '//err%message
    end if
  end if

end subroutine umat
