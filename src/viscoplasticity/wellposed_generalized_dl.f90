!> Generalized Duvaut-Lions viscoplasticity (eq. 2.8-2.10, section 2.5.3):
!> the overstress a = sigma - sigma_qs over the rate-independent quasi-static
!> state obeys da/dt = C : deps/dt - dsigma_qs/dt - a/tau, integrated exactly
!> for constant rates: a_{n+1} = e a_n + r (C : de - dsigma_qs),
!> e = exp(-dt/tau), r = (1 - e) tau/dt; z relaxes toward z_qs alike.
!> The state carries a and z - z_qs. Derivation: docs/research/theory.md.
module wellposed_generalized_dl
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_tensor, only: ntens6
  use wellposed_dp_params, only: dp_params_t
  use wellposed_hardening, only: strength
  use wellposed_dp_point, only: point_update, voigt_stiffness
  use wellposed_return_mapping, only: state_elastic, state_plastic
  implicit none
  private
  public :: gdl_update, relaxation_weights

contains

  !> e = exp(-x) and r = (1 - exp(-x))/x of x = dt/tau >= 0 (r = 1 at
  !> x = 0), without cancellation for small x.
  elemental subroutine relaxation_weights(x, e, r)
    real(dp), intent(in) :: x
    real(dp), intent(out) :: e, r
    e = exp(-x)
    if (x > 1.0e-3_dp) then
      r = (1.0_dp - e)/x
    else
      r = 1.0_dp - x*(0.5_dp - x*(1.0_dp/6.0_dp - x/24.0_dp))
    end if
  end subroutine relaxation_weights

  !> One increment of the generalized Duvaut-Lions model in tensor
  !> components (arguments as point_update), with `over` = sigma - sigma_qs
  !> and `z_over` = z - z_qs carried from increment to increment. tau = 0 is
  !> point_update itself (the rate-independent answer bit for bit) with a
  !> zero overstress. `tangent` = (1 - r) T_qs + r C, T_qs the
  !> rate-independent tangent. `status` is that of the quasi-static return,
  !> or 1 (plastic) when only the overstress flows. On error nothing changes.
  pure subroutine gdl_update(p, sig, eps_p, z, zeta, over, z_over, avg_dlambda, de, dtime, &
                             dlambda, f, status, n, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta, over(ntens6), z_over
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    type(error_t), allocatable, intent(out) :: err
    type(dp_params_t) :: p_qs
    real(dp) :: sig_qs(ntens6), sig_qs_n(ntens6), dep_qs(ntens6), z_qs, zeta_new, dl_qs, f_qs
    real(dp) :: e, r, tr, c_de(ntens6), over_new(ntens6), comp(ntens6), dz, i1, s(ntens6)
    real(dp) :: c(ntens6, ntens6)

    if (.not. p%tau > 0.0_dp) then
      call point_update(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, f, status, &
                        n, tangent, err)
      if (.not. allocated(err)) then
        over = 0.0_dp
        z_over = 0.0_dp
      end if
      return
    end if

    ! The quasi-static state: the rate-independent model on the same path.
    p_qs = p
    p_qs%tau = 0.0_dp
    sig_qs_n = sig - over
    sig_qs = sig_qs_n
    dep_qs = 0.0_dp
    z_qs = z - z_over
    zeta_new = zeta
    call point_update(p_qs, sig_qs, dep_qs, z_qs, zeta_new, avg_dlambda, de, dtime, dl_qs, &
                      f_qs, status, n, tangent, err)
    if (allocated(err)) return

    call relaxation_weights(dtime/p%tau, e, r)
    ! C : de (eq. 1.5) and C^-1 : a (the viscoplastic strain of eq. 2.10).
    tr = de(1) + de(2) + de(3)
    c_de = 2.0_dp*p%el%shear*de
    c_de(1:3) = c_de(1:3) + (p%el%bulk - 2.0_dp*p%el%shear/3.0_dp)*tr
    tr = over(1) + over(2) + over(3)
    comp = over/(2.0_dp*p%el%shear)
    comp(1:3) = comp(1:3) + tr*(1.0_dp/(9.0_dp*p%el%bulk) - 1.0_dp/(6.0_dp*p%el%shear))

    over_new = e*over + r*(c_de - (sig_qs - sig_qs_n))
    ! eps^p - eps^p_qs = -C^-1 : a, so d eps^p = (1 - r) d eps^p_qs + (1 - e) C^-1 : a_n.
    eps_p = eps_p + (1.0_dp - r)*dep_qs + (1.0_dp - e)*comp
    dz = (1.0_dp - r)*dl_qs - (1.0_dp - e)*z_over
    z_over = e*z_over - r*dl_qs
    sig = sig_qs + over_new
    over = over_new
    z = z + dz
    zeta = zeta_new
    dlambda = dz
    if (status == state_elastic .and. dz > 0.0_dp) status = state_plastic

    i1 = sig(1) + sig(2) + sig(3)
    s = sig
    s(1:3) = s(1:3) - i1/3.0_dp
    f = sqrt(0.5_dp*(s(1)**2 + s(2)**2 + s(3)**2) + s(4)**2 + s(5)**2 + s(6)**2) &
        + p%beta*i1 - strength(p%hard, z) - zeta
    if (present(tangent)) then
      ! A fixed-size C (the leading n x n block is used): no heap.
      call voigt_stiffness(p%el%bulk, p%el%shear, ntens6, c)
      tangent = (1.0_dp - r)*tangent + r*c(1:n, 1:n)
    end if
  end subroutine gdl_update

end module wellposed_generalized_dl
