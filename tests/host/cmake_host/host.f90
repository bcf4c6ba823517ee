!> A free-form host of an installed wellposed, built with
!> find_package(wellposed) and target_link_libraries(... wellposed::...).
!> It uses an installed module (wellposed_kinds), so the package's include
!> directory is exercised, and calls the UMAT through its own interface block.
!> One elastic increment: K = 4e9, G = 1.5e9, beta = 0.315, beta_p = 0,
!> k0 = 5.066e6, DSTRAN = (1e-6, 0, 0, 0, 0, 0); expected STRESS = (6000, 3000,
!> 3000, 0, 0, 0) Pa.
program cmake_host
  use wellposed_kinds, only: dp
  implicit none

  interface
    subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
                    stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname,    &
                    ndi, nshr, ntens, nstatv, props, nprops, coords, drot, pnewdt,     &
                    celent, dfgrd0, dfgrd1, noel, npt, layer, kspt, kstep, kinc)
      import :: dp
      integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
      integer, intent(in) :: noel, npt, layer, kspt, kstep, kinc
      real(dp), intent(inout) :: stress(ntens), statev(nstatv)
      real(dp), intent(inout) :: ddsdde(ntens, ntens)
      real(dp), intent(inout) :: sse, spd, scd, rpl
      real(dp), intent(inout) :: ddsddt(ntens), drplde(ntens), drpldt
      real(dp), intent(in) :: stran(ntens), dstran(ntens), time(2), dtime
      real(dp), intent(in) :: temp, dtemp, predef(1), dpred(1)
      character(len=80), intent(in) :: cmname
      real(dp), intent(in) :: props(nprops), coords(3), drot(3, 3)
      real(dp), intent(inout) :: pnewdt
      real(dp), intent(in) :: celent, dfgrd0(3, 3), dfgrd1(3, 3)
    end subroutine umat
  end interface

  integer, parameter :: ntens = 6, nstatv = 12, nprops = 5
  real(dp) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
  real(dp) :: ddsddt(ntens), drplde(ntens), stran(ntens), dstran(ntens)
  real(dp) :: time(2), predef(1), dpred(1), props(nprops), coords(3)
  real(dp) :: drot(3, 3), dfgrd0(3, 3), dfgrd1(3, 3)
  real(dp) :: sse, spd, scd, rpl, drpldt, dtime, temp, dtemp, pnewdt, celent
  character(len=80) :: cmname
  real(dp), parameter :: eye(3, 3) = reshape([1.0_dp, 0.0_dp, 0.0_dp, &
                                              0.0_dp, 1.0_dp, 0.0_dp, &
                                              0.0_dp, 0.0_dp, 1.0_dp], [3, 3])
  integer :: i

  stress = 0.0_dp
  statev = 0.0_dp
  ddsdde = 0.0_dp
  ddsddt = 0.0_dp
  drplde = 0.0_dp
  stran = 0.0_dp
  dstran = [1.0e-6_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  props = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  time = 0.0_dp
  dtime = 1.0_dp
  temp = 0.0_dp
  dtemp = 0.0_dp
  predef = 0.0_dp
  dpred = 0.0_dp
  sse = 0.0_dp
  spd = 0.0_dp
  scd = 0.0_dp
  rpl = 0.0_dp
  drpldt = 0.0_dp
  pnewdt = 1.0_dp
  celent = 1.0_dp
  coords = 0.0_dp
  drot = eye
  dfgrd0 = eye
  dfgrd1 = eye
  cmname = 'WELLPOSED'

  call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
            stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname,    &
            3, 3, ntens, nstatv, props, nprops, coords, drot, pnewdt,          &
            celent, dfgrd0, dfgrd1, 1, 1, 1, 1, 1, 1)

  do i = 1, ntens
    write (*, '(a,i1,a,f16.4)') 'STRESS(', i, ') = ', stress(i)
  end do
  write (*, '(a,es14.6)') 'DDSDDE(1,1) = ', ddsdde(1, 1)
  write (*, '(a,es14.6)') 'DDSDDE(1,2) = ', ddsdde(1, 2)
  write (*, '(a,f8.3)') 'STATUS = ', statev(12)
  write (*, '(a,f8.3)') 'PNEWDT = ', pnewdt
end program cmake_host
