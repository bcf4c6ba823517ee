!> Parameters of the Drucker-Prager family of wellposed (yield eq. 2.3/4.34,
!> potential eq. 4.35, hardening eq. 2.6, extended flow rule eq. 2.7,
!> Duvaut-Lions eq. 2.10, overlocal eq. 2.12-2.14), validated by
!> fill_dp_params (no text: cheap enough for every UMAT call) or by
!> new_dp_params (which also builds the message). A zero switches an
!> optional feature off.
module wellposed_dp_params
  use wellposed_kinds, only: dp
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_finite, only: is_finite, all_finite, exponent_bits
  use wellposed_text, only: real_text
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_elasticity, only: elastic_t
  use wellposed_hardening, only: hardening_t, min_strength_slope
  use wellposed_drucker_prager, only: normal_norm
  use wellposed_tensor, only: sqrt3
  implicit none
  private
  public :: dp_params_t, new_dp_params, fill_dp_params, set_dl_form, n_params, max_magnitude, &
            max_ratio

  !> Number of material parameters (PROPS 1-13 of the UMAT contract).
  integer, parameter :: n_params = 13
  ! Faults of fill_dp_params past 1-13 (a non-finite parameter), in the
  ! order the ranges are checked.
  integer, parameter :: fault_bulk = 14, fault_shear = 15, fault_beta = 16, fault_k0 = 17, &
                        fault_k_lim = 18, fault_z_ref_lim = 19, fault_z_ref = 20, &
                        fault_tau = 21, fault_length = 22, fault_a_m = 23, &
                        fault_softening = 24, fault_apex_softening = 25, fault_magnitude = 26

  !> Largest stress or modulus (times min(1, K, G)) and largest
  !> dimensionless parameter the model takes: it squares stresses (||S||,
  !> energies) and multiplies moduli pairwise (tangents), so 2^448 leaves
  !> 2^128 of headroom below huge = 2^1024 for the sums, the constant
  !> factors and the 2^53 by which a + h may divide (docs/guide/umat.md).
  real(dp), parameter :: max_magnitude = 2.0_dp**448
  !> Largest dimensionless parameter (beta, beta_p, P_v, P_d) and K/G ratio.
  real(dp), parameter :: max_ratio = 2.0_dp**32

  !> The validated material. Derived constants are filled by new_dp_params.
  type :: dp_params_t
    type(elastic_t) :: el              !< K, G
    real(dp) :: beta = 0.0_dp          !< friction slope of the yield cone
    real(dp) :: beta_p = 0.0_dp        !< dilatation slope of the potential
    type(hardening_t) :: hard          !< k0, h, k_lim, z_ref
    real(dp) :: p_v = 0.0_dp           !< EFR volumetric parameter (eq. 2.7)
    real(dp) :: p_d = 0.0_dp           !< EFR deviatoric parameter (eq. 2.7)
    real(dp) :: tau = 0.0_dp           !< Duvaut-Lions relaxation time (eq. 2.10)
    logical :: gdl = .false.           !< generalized Duvaut-Lions (tracked sigma_qs, z_qs)
    real(dp) :: h_zeta = 0.0_dp        !< nonlocal hardening modulus (eq. 4.24)
    real(dp) :: length = 0.0_dp        !< nonlocal length scale L (eq. 2.15)
    ! derived
    real(dp) :: n_m = 0.0_dp           !< ||dg/dsigma|| = sqrt(1/2 + 3 beta_p^2)
    real(dp) :: a_m = 0.0_dp           !< N:C:M_hat = (G + 9 K beta beta_p)/n_m (eq. 4.36)
    logical :: efr = .false.           !< extended flow rule on (p_v or p_d /= 0)
    !> exponent_bits of the largest stress and strain an increment takes
    !> (max_magnitude min(1, K, G), and that over the largest modulus).
    integer(int64) :: stress_limit = 0, strain_limit = 0
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
    real(dp) :: values(n_params)
    integer :: fault

    values = [bulk, shear, beta, beta_p, k0, h, k_lim, z_ref, p_v, p_d, tau, h_zeta, length]
    call fill_dp_params(self, values, fault)
    if (fault /= 0) call fault_error(self, values, fault, err)
  end subroutine new_dp_params

  !> Store the 13 parameters (order of PROPS 1-13) with their derived
  !> constants, and check every range: `fault` is 0 when all hold, else the
  !> first check that fails (fault_error turns it into a message). No text
  !> and no allocation, so a host may call it on every increment. Every
  !> component is assigned (gdl .false.; set_dl_form sets it), so `self` is
  !> intent(inout): intent(out) would default-initialise it first on every
  !> call. On a fault `self` holds no meaning.
  pure subroutine fill_dp_params(self, v, fault)
    type(dp_params_t), intent(inout) :: self
    real(dp), intent(in) :: v(n_params)
    integer, intent(out) :: fault
    real(dp) :: slope, smax, hmax
    integer :: i

    if (.not. all_finite(v)) then
      do i = 1, n_params
        if (.not. is_finite(v(i))) exit
      end do
      fault = i; return
    end if
    fault = fault_bulk
    if (.not. v(1) > 0.0_dp) return
    fault = fault_shear
    if (.not. v(2) > 0.0_dp) return
    fault = fault_beta
    if (v(3) < 0.0_dp) return
    fault = fault_k0
    if (.not. v(5) > 0.0_dp) return
    fault = fault_k_lim
    if (v(7) < 0.0_dp) return
    fault = fault_z_ref_lim
    if (v(7) > 0.0_dp .and. .not. v(8) > 0.0_dp) return
    fault = fault_z_ref
    if (v(8) < 0.0_dp) return
    fault = fault_tau
    if (v(11) < 0.0_dp) return
    fault = fault_length
    if (v(13) < 0.0_dp .or. (v(12) /= 0.0_dp .and. .not. v(13) > 0.0_dp)) return
    fault = fault_magnitude
    smax = max_magnitude*min(1.0_dp, v(1), v(2))
    hmax = 0.0_dp
    if (v(7) > 0.0_dp) hmax = abs(v(7) - v(5))/v(8)
    if (max(v(1), v(2)) > max_magnitude .or. max(v(5), abs(v(6)), v(7), abs(v(12)), hmax) > smax &
        .or. max(v(3), abs(v(4)), abs(v(9)), abs(v(10))) > max_ratio .or. &
        (v(3) > 0.0_dp .and. v(3) < 1.0_dp/max_ratio) .or. &
        max(v(1), v(2)) > max_ratio*min(v(1), v(2)) .or. &
        min(v(5), merge(v(7), v(5), v(7) > 0.0_dp)) < max(v(1), v(2))/max_magnitude) return
    self%stress_limit = exponent_bits(smax)
    self%strain_limit = exponent_bits(smax/max(3.0_dp*v(1) + 4.0_dp*v(2), abs(v(6)), &
                                                abs(v(12)), hmax))

    self%el = elastic_t(v(1), v(2))
    self%beta = v(3)
    self%beta_p = v(4)
    self%hard = hardening_t(v(5), v(6), v(7), v(8))
    self%p_v = v(9)
    self%p_d = v(10)
    self%tau = v(11)
    self%gdl = .false.
    self%h_zeta = v(12)
    self%length = v(13)
    self%n_m = normal_norm(v(4))
    self%a_m = (v(2) + 9.0_dp*v(1)*v(3)*v(4))/self%n_m
    self%efr = v(9) /= 0.0_dp .or. v(10) /= 0.0_dp

    fault = fault_a_m
    if (.not. self%a_m > 0.0_dp) return
    slope = min_strength_slope(self%hard)
    fault = fault_softening
    if (.not. self%a_m + slope > 0.0_dp) return
    fault = fault_apex_softening
    if (v(3) > 0.0_dp .and. slope < 0.0_dp .and. .not. 9.0_dp*v(1)*v(3) + sqrt3*slope > 0.0_dp) &
      return
    fault = 0
  end subroutine fill_dp_params

  !> Select the Duvaut-Lions form from its switch (PROPS(15)): 0 the
  !> default form (sigma_qs the return of the current trial), 1 the
  !> generalized form with a tracked quasi-static state
  !> (wellposed_generalized_dl). `valid` is false for any other value.
  pure subroutine set_dl_form(self, value, valid)
    type(dp_params_t), intent(inout) :: self
    real(dp), intent(in) :: value
    logical, intent(out) :: valid
    valid = value == 0.0_dp .or. value == 1.0_dp
    self%gdl = value == 1.0_dp
  end subroutine set_dl_form

  !> The message of a fault of fill_dp_params: symbol, value, valid range.
  pure subroutine fault_error(self, v, fault, err)
    type(dp_params_t), intent(in) :: self
    real(dp), intent(in) :: v(n_params)
    integer, intent(in) :: fault
    type(error_t), allocatable, intent(out) :: err
    character(len=6), parameter :: names(n_params) = [character(len=6) :: 'K', 'G', 'beta', &
      'beta_p', 'k0', 'h', 'k_lim', 'z_ref', 'P_v', 'P_d', 'tau', 'h_zeta', 'L']
    real(dp) :: slope

    select case (fault)
    case (1:n_params)
      call new_error(err, status_invalid, trim(names(fault)), trim(names(fault))//' = '// &
        real_text(v(fault))//' is not a finite number')
    case (fault_bulk)
      call out_of_range(err, 'K', v(1), '> 0')
    case (fault_shear)
      call out_of_range(err, 'G', v(2), '> 0')
    case (fault_beta)
      call out_of_range(err, 'beta', v(3), '>= 0')
    case (fault_k0)
      call out_of_range(err, 'k0', v(5), '> 0')
    case (fault_k_lim)
      call out_of_range(err, 'k_lim', v(7), '> 0, or 0 for no exponential hardening')
    case (fault_z_ref_lim)
      call out_of_range(err, 'z_ref', v(8), '> 0 when k_lim > 0')
    case (fault_z_ref)
      call out_of_range(err, 'z_ref', v(8), '>= 0')
    case (fault_tau)
      call out_of_range(err, 'tau', v(11), '>= 0 (0: rate-independent)')
    case (fault_length)
      call out_of_range(err, 'L', v(13), '> 0 when h_zeta /= 0')
    case (fault_a_m)
      call out_of_range(err, 'beta_p', v(4), 'such that G + 9 K beta beta_p > 0 '// &
        '(plastic flow must lower f)')
    case (fault_softening)
      slope = min_strength_slope(self%hard)
      call new_error(err, status_invalid, 'h', 'h = '//real_text(v(6))//' softens too '// &
        'strongly: the smallest dk/dz = '//real_text(slope)//' must exceed -(G + 9 K '// &
        'beta beta_p)/sqrt(1/2 + 3 beta_p^2) = '//real_text(-self%a_m)// &
        ' for a unique local return')
    case (fault_magnitude)
      call magnitude_error(v, err)
    case default
      slope = min_strength_slope(self%hard)
      call new_error(err, status_invalid, 'h', 'h = '//real_text(v(6))//' softens too '// &
        'strongly for a unique return to the apex: the smallest dk/dz = '// &
        real_text(slope)//' must exceed -9 K beta/sqrt(3) = '// &
        real_text(-9.0_dp*v(1)*v(3)/sqrt3))
    end select

  contains

    !> The first parameter beyond max_magnitude (moduli; stresses times
    !> min(1, K, G)) or max_ratio (dimensionless).
    pure subroutine magnitude_error(v, err)
      real(dp), intent(in) :: v(n_params)
      type(error_t), allocatable, intent(out) :: err
      integer, parameter :: stresses(4) = [5, 6, 7, 12], ratios(4) = [3, 4, 9, 10]
      real(dp) :: smax
      integer :: j
      character(len=*), parameter :: why = ' (the model squares stresses and multiplies'// &
        ' moduli: their products must stay finite)'
      smax = max_magnitude*min(1.0_dp, v(1), v(2))
      do j = 1, 2
        if (v(j) > max_magnitude) then
          call out_of_range(err, trim(names(j)), v(j), '< 2^448 = '// &
            real_text(max_magnitude)//why)
          return
        end if
      end do
      do j = 5, 7, 2
        if (v(j) > 0.0_dp .and. v(j) < max(v(1), v(2))/max_magnitude) then
          ! k0/G and k0/K are strains whose products must not underflow.
          call out_of_range(err, trim(names(j)), v(j), '>= max(K, G)/2^448 = '// &
            real_text(max(v(1), v(2))/max_magnitude)//' (the yield strain k/G must not '// &
            'underflow in products)')
          return
        end if
      end do
      if (max(v(1), v(2)) > max_ratio*min(v(1), v(2))) then
        ! K/G scales the shift of I1 along a nonassociative or EFR return.
        call out_of_range(err, 'G', v(2), 'within 2^32 of K = '//real_text(v(1))//why)
        return
      end if
      do j = 1, 4
        if (abs(v(stresses(j))) > smax) then
          call out_of_range(err, trim(names(stresses(j))), v(stresses(j)), '|value| < '// &
            '2^448 min(1, K, G) = '//real_text(smax)//why)
          return
        end if
      end do
      if (v(3) > 0.0_dp .and. v(3) < 1.0_dp/max_ratio) then
        ! beta divides strengths: the apex is at I1 = k/beta.
        call out_of_range(err, 'beta', v(3), '0 or >= 2^-32 = '//real_text(1.0_dp/max_ratio)// &
          ' (the apex I1 = k/beta must stay finite)')
        return
      end if
      do j = 1, 4
        if (abs(v(ratios(j))) > max_ratio) then
          call out_of_range(err, trim(names(ratios(j))), v(ratios(j)), '|value| < 2^32 = '// &
            real_text(max_ratio)//why)
          return
        end if
      end do
      call out_of_range(err, 'z_ref', v(8), 'such that |k_lim - k0|/z_ref < 2^448 min(1, K, '// &
        'G) = '//real_text(smax)//why)
    end subroutine magnitude_error

    pure subroutine out_of_range(err, name, value, range)
      type(error_t), allocatable, intent(out) :: err
      character(len=*), intent(in) :: name, range
      real(dp), intent(in) :: value
      call new_error(err, status_invalid, name, name//' = '//real_text(value)// &
        ' is out of range: valid is '//range)
    end subroutine out_of_range

  end subroutine fault_error

end module wellposed_dp_params
