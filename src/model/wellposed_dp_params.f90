!> Parameters of the Drucker-Prager family of wellposed (yield eq. 2.3/4.34,
!> potential eq. 4.35, hardening eq. 2.6, extended flow rule eq. 2.7,
!> Duvaut-Lions eq. 2.10, overlocal eq. 2.12-2.14), validated once by
!> new_dp_params. A zero switches an optional feature off.
module wellposed_dp_params
  use wellposed_kinds, only: dp
  use wellposed_finite, only: is_finite
  use wellposed_text, only: real_text
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_elasticity, only: elastic_t
  use wellposed_hardening, only: hardening_t, min_strength_slope
  use wellposed_drucker_prager, only: normal_norm
  use wellposed_tensor, only: sqrt3
  implicit none
  private
  public :: dp_params_t, new_dp_params

  !> The validated material. Derived constants are filled by new_dp_params.
  type :: dp_params_t
    type(elastic_t) :: el              !< K, G
    real(dp) :: beta = 0.0_dp          !< friction slope of the yield cone
    real(dp) :: beta_p = 0.0_dp        !< dilatation slope of the potential
    type(hardening_t) :: hard          !< k0, h, k_lim, z_ref
    real(dp) :: p_v = 0.0_dp           !< EFR volumetric parameter (eq. 2.7)
    real(dp) :: p_d = 0.0_dp           !< EFR deviatoric parameter (eq. 2.7)
    real(dp) :: tau = 0.0_dp           !< Duvaut-Lions relaxation time (eq. 2.10)
    real(dp) :: h_zeta = 0.0_dp        !< nonlocal hardening modulus (eq. 4.24)
    real(dp) :: length = 0.0_dp        !< nonlocal length scale L (eq. 2.15)
    ! derived
    real(dp) :: n_m = 0.0_dp           !< ||dg/dsigma|| = sqrt(1/2 + 3 beta_p^2)
    real(dp) :: a_m = 0.0_dp           !< N:C:M_hat = (G + 9 K beta beta_p)/n_m (eq. 4.36)
    logical :: efr = .false.           !< extended flow rule on (p_v or p_d /= 0)
  end type dp_params_t

contains

  !> Validate and store the parameters; on failure `err` names the symbol,
  !> its value and the valid range, and `self` must not be used.
  pure subroutine new_dp_params(self, bulk, shear, beta, beta_p, k0, h, k_lim, z_ref, &
                                p_v, p_d, tau, h_zeta, length, err)
    type(dp_params_t), intent(out) :: self
    real(dp), intent(in) :: bulk, shear, beta, beta_p, k0, h, k_lim, z_ref
    real(dp), intent(in) :: p_v, p_d, tau, h_zeta, length
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: values(13), slope
    character(len=6), parameter :: names(13) = [character(len=6) :: 'K', 'G', 'beta', &
      'beta_p', 'k0', 'h', 'k_lim', 'z_ref', 'P_v', 'P_d', 'tau', 'h_zeta', 'L']
    integer :: i

    values = [bulk, shear, beta, beta_p, k0, h, k_lim, z_ref, p_v, p_d, tau, h_zeta, length]
    do i = 1, size(values)
      if (.not. is_finite(values(i))) then
        call new_error(err, status_invalid, trim(names(i)), trim(names(i))//' = '// &
          real_text(values(i))//' is not a finite number')
        return
      end if
    end do
    if (.not. bulk > 0.0_dp) then
      call out_of_range(err, 'K', bulk, '> 0'); return
    end if
    if (.not. shear > 0.0_dp) then
      call out_of_range(err, 'G', shear, '> 0'); return
    end if
    if (beta < 0.0_dp) then
      call out_of_range(err, 'beta', beta, '>= 0'); return
    end if
    if (.not. k0 > 0.0_dp) then
      call out_of_range(err, 'k0', k0, '> 0'); return
    end if
    if (k_lim < 0.0_dp) then
      call out_of_range(err, 'k_lim', k_lim, '> 0, or 0 for no exponential hardening'); return
    end if
    if (k_lim > 0.0_dp .and. .not. z_ref > 0.0_dp) then
      call out_of_range(err, 'z_ref', z_ref, '> 0 when k_lim > 0'); return
    end if
    if (z_ref < 0.0_dp) then
      call out_of_range(err, 'z_ref', z_ref, '>= 0'); return
    end if
    if (tau < 0.0_dp) then
      call out_of_range(err, 'tau', tau, '>= 0 (0: rate-independent)'); return
    end if
    if (length < 0.0_dp .or. (h_zeta /= 0.0_dp .and. .not. length > 0.0_dp)) then
      call out_of_range(err, 'L', length, '> 0 when h_zeta /= 0'); return
    end if

    self%el = elastic_t(bulk, shear)
    self%beta = beta
    self%beta_p = beta_p
    self%hard = hardening_t(k0, h, k_lim, z_ref)
    self%p_v = p_v
    self%p_d = p_d
    self%tau = tau
    self%h_zeta = h_zeta
    self%length = length
    self%n_m = normal_norm(beta_p)
    self%a_m = (shear + 9.0_dp*bulk*beta*beta_p)/self%n_m
    self%efr = p_v /= 0.0_dp .or. p_d /= 0.0_dp

    if (.not. self%a_m > 0.0_dp) then
      call out_of_range(err, 'beta_p', beta_p, 'such that G + 9 K beta beta_p > 0 '// &
        '(plastic flow must lower f)'); return
    end if
    slope = min_strength_slope(self%hard)
    if (.not. self%a_m + slope > 0.0_dp) then
      call new_error(err, status_invalid, 'h', 'h = '//real_text(h)//' softens too '// &
        'strongly: the smallest dk/dz = '//real_text(slope)//' must exceed -(G + 9 K '// &
        'beta beta_p)/sqrt(1/2 + 3 beta_p^2) = '//real_text(-self%a_m)// &
        ' for a unique local return')
      return
    end if
    if (beta > 0.0_dp .and. slope < 0.0_dp .and. &
        .not. 9.0_dp*bulk*beta + sqrt3*slope > 0.0_dp) then
      call new_error(err, status_invalid, 'h', 'h = '//real_text(h)//' softens too '// &
        'strongly for a unique return to the apex: the smallest dk/dz = '// &
        real_text(slope)//' must exceed -9 K beta/sqrt(3) = '// &
        real_text(-9.0_dp*bulk*beta/sqrt3))
      return
    end if

  contains

    pure subroutine out_of_range(err, name, value, range)
      type(error_t), allocatable, intent(out) :: err
      character(len=*), intent(in) :: name, range
      real(dp), intent(in) :: value
      call new_error(err, status_invalid, name, name//' = '//real_text(value)// &
        ' is out of range: valid is '//range)
    end subroutine out_of_range

  end subroutine new_dp_params

end module wellposed_dp_params
