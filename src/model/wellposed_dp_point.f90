!> One increment of the Drucker-Prager model at one point in the components
!> hosts store: stress and strain [11, 22, 33, 12, 13, 23] with tensor
!> shears, the tangent in Voigt form (engineering shears, as DDSDDE).
!> point_update: every model, the closed form (point_closed_form of
!> wellposed_dp_closed_form, eq. 4.36-4.39, 2.10) where it applies, else
!> dp_update (eq. 2.6, 2.7).
module wellposed_dp_point
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, status_cutback
  use wellposed_tensor, only: ntens6, sqrt2
  use wellposed_dp_params, only: dp_params_t
  use wellposed_hardening, only: is_linear
  use wellposed_dp_model, only: dp_state_t, dp_output_t, dp_update
  use wellposed_return_mapping, only: state_elastic
  use wellposed_efr, only: efr_has_direction
  use wellposed_dp_closed_form, only: point_closed_form
  use wellposed_dp_tangent, only: voigt_stiffness
  implicit none
  private
  public :: point_update, point_closed_form, has_closed_form, voigt_stiffness, &
            elastic_energy

  real(dp), parameter :: rsqrt2 = 1.0_dp/sqrt2
  !> Shear scale between tensor and Mandel components.
  real(dp), parameter :: mandel(ntens6) = [1.0_dp, 1.0_dp, 1.0_dp, sqrt2, sqrt2, sqrt2]
  real(dp), parameter :: rmandel(ntens6) = [1.0_dp, 1.0_dp, 1.0_dp, rsqrt2, rsqrt2, rsqrt2]

contains

  !> True when point_closed_form serves the model: regular flow rule and
  !> linear hardening (k = k0 + h z).
  elemental function has_closed_form(p) result(yes)
    type(dp_params_t), intent(in) :: p
    logical :: yes
    yes = .not. p%efr .and. is_linear(p%hard)
  end function has_closed_form

  !> Advance `sig` and the state (z, zeta, eps_p) by the strain increment
  !> `de` over `dtime`, for any model. Arguments as point_closed_form; on
  !> error `err` is allocated and nothing is changed.
  pure subroutine point_update(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, &
                               status, n, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    type(error_t), allocatable, intent(out) :: err

    if (has_closed_form(p) .or. (is_linear(p%hard) .and. .not. efr_has_direction(p, de))) then
      call point_closed_form(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, &
                             status, n, tangent)
      if (status /= status_cutback) return
    end if
    ! Newton models, and the rare closed-form case with no answer (the
    ! general return then finds the answer or explains why there is none).
    call point_general(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, status, n, &
                       tangent, err)
  end subroutine point_update

  !> point_update through dp_update (Mandel components, derived types): a
  !> procedure of its own so that a closed-form call does not initialise
  !> them.
  pure subroutine point_general(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, &
                                status, n, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    type(error_t), allocatable, intent(out) :: err
    type(dp_state_t) :: state
    type(dp_output_t) :: out
    real(dp) :: sig_m(ntens6), t(ntens6, ntens6)
    integer :: i, j

    sig_m = sig*mandel
    state%z = z
    state%zeta = zeta
    state%eps_p = eps_p*mandel
    if (present(tangent)) then
      call dp_update(p, sig_m, state, de*mandel, dtime, avg_dlambda, out, t, err)
    else
      call dp_update(p, sig_m, state, de*mandel, dtime, avg_dlambda, out, err=err)
    end if
    if (allocated(err)) return
    sig = sig_m/mandel
    zeta = state%zeta
    ! An elastic step leaves the plastic state bit for bit: the Mandel
    ! round trip of eps_p (x sqrt(2), / sqrt(2)) is not exact.
    if (out%status /= state_elastic) then
      z = state%z
      eps_p = state%eps_p/mandel
    end if
    dlambda = out%dlambda
    f = out%f
    status = out%status
    if (present(tangent)) then
      ! Mandel T to Voigt: D^-1 T D^-1, D = diag(mandel); engineering shears.
      ! Multiplications by 1, 1/sqrt(2) and 1/2: no division.
      do j = 1, n
        do i = 1, n
          tangent(i, j) = t(i, j)*(rmandel(i)*rmandel(j))
        end do
      end do
    end if
  end subroutine point_general

  !> Elastic energy density sigma : C^-1 : sigma / 2 of a stress in tensor
  !> components: ||S||^2/(4G) + I1^2/(18K).
  pure function elastic_energy(bulk, shear, sig) result(e)
    real(dp), intent(in) :: bulk, shear, sig(ntens6)
    real(dp) :: e, i1, s(3)
    i1 = sig(1) + sig(2) + sig(3)
    s = sig(1:3) - i1/3.0_dp
    e = (s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(sig(4)**2 + sig(5)**2 + sig(6)**2)) &
        /(4.0_dp*shear) + i1**2/(18.0_dp*bulk)
  end function elastic_energy

end module wellposed_dp_point
