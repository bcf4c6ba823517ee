!> The library's dispersion relation of the overlocal model in uniaxial strain
!> (section 2.5.4, fig. 2.10 left) at given frequencies, for the regression
!> test and mpm/plots/mpm_dispersion.py:
!>   mpm_dispersion_oracle DENSITY S11 .. S23 PROPS(1:13) F1 [F2 ...]
!> Solves omega = kappa c(kappa) by bisection, rho c^2 from
!> overlocal_uniaxial_modulus (Fourier transform of eq. 2.15/4.27); prints
!> the bounds and phase and group velocities. Arguments and output:
!> docs/research/verification.md. Exit status 1 with a message on bad arguments.
program mpm_dispersion_oracle
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_dp_params, only: dp_params_t, new_dp_params
  use wellposed_tangent_analysis, only: uniaxial_modulus, overlocal_uniaxial_modulus
  implicit none
  integer, parameter :: nfixed = 1 + 6 + 13
  real(dp), parameter :: two_pi = 6.28318530717958647692_dp
  real(dp) :: fixed(nfixed), rho, sig(6), props(13), f, omega, kappa, c, cg
  real(dp) :: c_e, c_0, c_inf
  type(dp_params_t) :: p
  type(error_t), allocatable :: err
  integer :: i, nf

  nf = command_argument_count() - nfixed
  if (nf < 1) call fail('usage: mpm_dispersion_oracle DENSITY S11 S22 S33 S12 S13 S23 '// &
    'K G beta beta_p k0 h k_lim z_ref P_v P_d tau h_zeta L F1 [F2 ...]')
  do i = 1, nfixed
    fixed(i) = argument(i)
  end do
  rho = fixed(1)
  sig = fixed(2:7)
  props = fixed(8:20)
  if (.not. rho > 0.0_dp) call fail('DENSITY must be > 0 kg/m^3')
  call new_dp_params(p, props(1), props(2), props(3), props(4), props(5), props(6), &
                     props(7), props(8), props(9), props(10), props(11), props(12), &
                     props(13), err)
  if (allocated(err)) call fail(err%message)
  if (.not. p%length > 0.0_dp) call fail('L must be > 0 m (the model is not nonlocal)')
  ! sig is given in the Abaqus order 11 22 33 12 13 23; the library's ntens6
  ! vectors are Mandel (shear times sqrt 2): the test states have no shear
  if (any(sig(4:6) /= 0.0_dp)) call fail('S12, S13, S23 must be 0 (uniaxial strain)')
  c_e = sqrt(uniaxial_modulus(p, sig, 0.0_dp, -1.0_dp)/rho)
  c_0 = speed(0.0_dp)
  ! kappa L = 100: the Gaussian factor is exp(-517), zero in double precision
  c_inf = speed(1.0e2_dp/p%length)
  write (output_unit, '(a,3(1x,es23.16))') 'bounds', c_e, c_0, c_inf
  do i = 1, nf
    f = argument(nfixed + i)
    if (.not. f > 0.0_dp) call fail('frequencies must be > 0 Hz')
    omega = two_pi*f
    kappa = wavenumber(omega)
    c = omega/kappa
    cg = (omega_of(kappa*(1.0_dp + 1.0e-6_dp)) - omega_of(kappa*(1.0_dp - 1.0e-6_dp))) &
         /(2.0e-6_dp*kappa)
    write (output_unit, '(a,1x,es23.16,4(1x,a,1x,es23.16))') 'f', f, 'omega', omega, 'kappa', kappa, &
      'c_phase', c, 'c_group', cg
  end do

contains

  !> Phase velocity c(kappa) (m/s) of the linearised overlocal model.
  real(dp) function speed(kap)
    real(dp), intent(in) :: kap
    real(dp) :: m
    m = overlocal_uniaxial_modulus(p, sig, 0.0_dp, 1.0_dp, kap)
    if (.not. m > 0.0_dp) call fail('the linearised model has no real wave speed '// &
      '(rho c^2 <= 0): it localizes, and there is no dispersion curve to draw')
    speed = sqrt(m/rho)
  end function speed

  !> omega(kappa) = kappa c(kappa) (rad/s).
  real(dp) function omega_of(kap)
    real(dp), intent(in) :: kap
    omega_of = kap*speed(kap)
  end function omega_of

  !> The wavenumber of frequency w: bisection of kappa c(kappa) = w between
  !> w/c_max and w/c_min to a relative width of 1e-15.
  real(dp) function wavenumber(w)
    real(dp), intent(in) :: w
    real(dp) :: lo, hi, mid
    integer :: it
    lo = w/max(c_0, c_inf)
    hi = w/min(c_0, c_inf)
    do it = 1, 200
      mid = 0.5_dp*(lo + hi)
      if (omega_of(mid) < w) then
        lo = mid
      else
        hi = mid
      end if
      if (hi - lo <= 1.0e-15_dp*hi) exit
    end do
    wavenumber = 0.5_dp*(lo + hi)
  end function wavenumber

  !> Command-line argument i as a real; stops with a message if it is not one.
  real(dp) function argument(i)
    integer, intent(in) :: i
    character(len=64) :: text
    integer :: ios
    call get_command_argument(i, text)
    read (text, *, iostat=ios) argument
    if (ios /= 0) call fail('argument '//trim(text)//' is not a number')
  end function argument

  subroutine fail(message)
    character(len=*), intent(in) :: message
    write (error_unit, '(a)') 'mpm_dispersion_oracle: '//message
    stop 1, quiet=.true.
  end subroutine fail

end program mpm_dispersion_oracle
