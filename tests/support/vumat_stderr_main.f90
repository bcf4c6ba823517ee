!> Calls the external vumat the way Abaqus/Explicit does, with a block of
!> three points whose PROPS are invalid: the VUMAT must print one line on
!> standard error and stop the analysis with a non-zero exit code (there
!> is no PNEWDT to cut back with). check_vumat_stderr.cmake runs it.
program vumat_stderr_main
  use wellposed_kinds, only: dp
  use wellposed_vumat_interface, only: vumat
  implicit none
  real(dp) :: props(6), so(3, 6), sn(3, 6), de(3, 6), sto(3, 12), stn(3, 12), dens(3)
  real(dp) :: e0(3), e1(3), e2(3), e3(3), coord(3, 3), cl(3), spin(3, 3), temp(3)
  real(dp) :: stretch(3, 6), fgrad(3, 9), field(3, 1)
  character(len=80) :: cmname
  props = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp, -1.0e10_dp]
  so = 0.0_dp; de = 1.0e-4_dp; sto = 0.0_dp; dens = 2500.0_dp; e0 = 0.0_dp; e1 = 0.0_dp
  coord = 0.0_dp; cl = 1.0_dp; spin = 0.0_dp; temp = 0.0_dp; stretch = 0.0_dp; fgrad = 0.0_dp
  field = 0.0_dp; sn = 0.0_dp; stn = 0.0_dp; e2 = 0.0_dp; e3 = 0.0_dp
  cmname = 'ROCK'
  call vumat(3, 3, 3, 12, 1, 6, 0, 0.1_dp, 0.1_dp, 1.0e-6_dp, cmname, coord, cl, props, dens, &
             de, spin, temp, stretch, fgrad, field, so, sto, e0, e1, temp, stretch, fgrad, &
             field, sn, stn, e2, e3)
  write (*, '(a)') 'the VUMAT returned from invalid PROPS'
end program vumat_stderr_main
