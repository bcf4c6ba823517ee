!> wellposed-demo: one material point of the Sandler-Rubin case study
!> (section 2.3) strained in uniaxial-strain extension through the UMAT,
!> for the regular nonassociative flow rule and the extended flow rule
!> (eq. 2.7, P_v = 0.5), printed as a table: the axial stress rises faster
!> than elastic for the nonassociative model (the Sandler-Rubin stiffening)
!> and never does for the EFR.
program wellposed_demo
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  integer, parameter :: nsteps = 10
  real(dp), parameter :: bulk = 4.0e9_dp, shear = 1.5e9_dp, deps = 2.0e-5_dp
  real(dp) :: props(14)
  integer :: model

  write (output_unit, '(a)') 'wellposed demo: uniaxial-strain extension from the '// &
    'Sandler-Rubin initial state'
  write (output_unit, '(a)') '  sigma = (-100, -17.55, -17.55) MPa, K = 4 GPa, G = 1.5 GPa, '// &
    'beta = 0.315, k0 = 5.066 MPa'
  write (output_unit, '(a,f0.1,a)') '  elastic constrained modulus K + 4G/3 = ', &
    (bulk + 4*shear/3)/1e9_dp, ' GPa'
  do model = 1, 2
    props = 0.0_dp
    props(1:5) = [bulk, shear, 0.315_dp, 0.0_dp, 5.066e6_dp]
    if (model == 2) then
      props(4) = 0.315_dp
      props(9) = 0.5_dp
    end if
    call run(props, model)
  end do

contains

  subroutine run(props, model)
    real(dp), intent(in) :: props(14)
    integer, intent(in) :: model
    real(dp) :: stress(6), statev(12), ddsdde(6, 6), dstran(6), stran(6), time(2), pnewdt
    real(dp) :: sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt, predef(1), coords(3)
    real(dp) :: drot(3, 3), f33(3, 3), sig_prev
    character(len=80) :: cmname
    character(len=*), parameter :: status_name(0:2) = ['elastic', 'plastic', 'apex   ']
    integer :: step
    stress = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    statev = 0.0_dp; stran = 0.0_dp; time = 0.0_dp; sse = 0.0_dp; spd = 0.0_dp
    scd = 0.0_dp; rpl = 0.0_dp; ddsddt = 0.0_dp; drplde = 0.0_dp; drpldt = 0.0_dp
    predef = 0.0_dp; coords = 0.0_dp; drot = 0.0_dp; f33 = 0.0_dp
    dstran = [deps, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    cmname = 'WELLPOSED'
    write (output_unit, '(/,a)') merge('regular nonassociative flow rule (beta_p = 0)  ', &
                                       'extended flow rule (beta_p = beta, P_v = 0.5)  ', &
                                       model == 1)
    write (output_unit, '(a)') '   step   eps_11    sigma_11 MPa  sigma_22 MPa  '// &
      'd sigma_11/d eps_11 GPa     z         status'
    do step = 1, nsteps
      sig_prev = stress(1)
      pnewdt = 1.0_dp
      call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
                dstran, time, 1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, &
                12, props, 14, coords, drot, pnewdt, 1.0_dp, f33, f33, 1, 1, 0, 0, 1, step)
      if (pnewdt < 1.0_dp) then
        write (error_unit, '(a,i0)') 'wellposed-demo: the UMAT refused increment ', step
        error stop 1
      end if
      stran = stran + dstran
      write (output_unit, '(i6,es11.3,2f14.4,f20.3,es15.4,3x,a)') step, stran(1), &
        stress(1)/1e6_dp, stress(2)/1e6_dp, (stress(1) - sig_prev)/deps/1e9_dp, statev(1), &
        trim(status_name(nint(statev(12))))
    end do
  end subroutine run

end program wellposed_demo
