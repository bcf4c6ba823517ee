!> wellposed-demo: one material point of the Sandler-Rubin case study
!> (section 2.3) strained in uniaxial-strain extension through the UMAT
!> host (host), for the regular nonassociative flow rule and the
!> extended flow rule
!> (eq. 2.7, P_v = 0.5), printed as a table: the axial stress rises faster
!> than elastic for the nonassociative model (the Sandler-Rubin stiffening)
!> and never does for the EFR. The table goes to standard output by write(2),
!> checked (gfortran reports no failed write): a full disk ends it, exit 1.
program wellposed_demo
  use, intrinsic :: iso_fortran_env, only: error_unit
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_size_t, c_long
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_error, verdict_ok
  implicit none
  integer, parameter :: nsteps = 10
  real(dp), parameter :: bulk = 4.0e9_dp, shear = 1.5e9_dp, deps = 2.0e-5_dp
  real(dp) :: props(14)
  integer :: model
  character(len=160) :: line

  interface
    function c_write(fd, buf, n) bind(C, name='write') result(done)
      import :: c_int, c_char, c_size_t, c_long
      integer(c_int), value :: fd
      character(kind=c_char), intent(in) :: buf(*)
      integer(c_size_t), value :: n
      integer(c_long) :: done
    end function c_write
  end interface

  call put('wellposed demo: uniaxial-strain extension from the '// &
           'Sandler-Rubin initial state')
  call put('  sigma = (-100, -17.55, -17.55) MPa, K = 4 GPa, G = 1.5 GPa, '// &
           'beta = 0.315, k0 = 5.066 MPa')
  write (line, '(a,f0.1,a)') '  elastic constrained modulus K + 4G/3 = ', &
    (bulk + 4*shear/3)/1e9_dp, ' GPa'
  call put(trim(line))
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
    real(dp) :: stress(6), statev(12), dstran(6), stran(6), energy(3), sig_prev
    character(len=*), parameter :: status_name(0:2) = ['elastic', 'plastic', 'apex   ']
    type(umat_host_t) :: h
    type(error_t), allocatable :: err
    integer :: step, verdict
    call new_umat_host(h, 6, 12, err, cmname='WELLPOSED', what='element')
    if (allocated(err)) call fail(err)
    stress = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    statev = 0.0_dp; stran = 0.0_dp; energy = 0.0_dp
    dstran = [deps, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    h%dtime = 1.0e-3_dp
    call put('')
    call put(merge('regular nonassociative flow rule (beta_p = 0)  ', &
                   'extended flow rule (beta_p = beta, P_v = 0.5)  ', model == 1))
    call put('   step   eps_11    sigma_11 MPa  sigma_22 MPa  '// &
             'd sigma_11/d eps_11 GPa     z         status')
    do step = 1, nsteps
      sig_prev = stress(1)
      ! uniaxial strain along 1 without rotation: F = I + eps
      h%kinc = step
      h%time = (step - 1)*h%dtime
      h%dfgrd0(1, 1) = 1.0_dp + stran(1)
      h%dfgrd1(1, 1) = 1.0_dp + stran(1) + dstran(1)
      call host_call(h, props, stress, statev, stran, dstran, verdict, energy)
      if (verdict /= verdict_ok) then
        call host_error(h, verdict, err, 'increment '//int_text(step))
        call fail(err)
      end if
      stran = stran + dstran
      write (line, '(i6,es11.3,2f14.4,f20.3,es15.4,3x,a)') step, stran(1), &
        stress(1)/1e6_dp, stress(2)/1e6_dp, (stress(1) - sig_prev)/deps/1e9_dp, statev(1), &
        trim(status_name(nint(statev(12))))
      call put(trim(line))
    end do
  end subroutine run

  !> One line of the table on standard output (file descriptor 1), checked.
  subroutine put(text)
    character(len=*), intent(in) :: text
    integer :: ios
    if (c_write(1_c_int, text//new_line('a'), int(len(text) + 1, c_size_t)) == len(text) + 1) &
      return
    write (error_unit, '(a)', iostat=ios) 'wellposed-demo: error: cannot write the table '// &
      'to standard output (a full disk or a closed pipe)'
    flush (error_unit, iostat=ios)
    stop 1, quiet=.true.
  end subroutine put

  subroutine fail(e)
    type(error_t), intent(in) :: e
    integer :: ios
    write (error_unit, '(a)', iostat=ios) 'wellposed-demo: '//e%message
    flush (error_unit, iostat=ios)
    error stop 1
  end subroutine fail

end program wellposed_demo
