!> One strain increment of the wellposed Drucker-Prager model: the typed
!> entry point behind the UMAT, usable directly by Fortran hosts.
!> Order: nonlocal strength zeta += h_zeta `<dlambda>` (eq. 4.24), elastic
!> trial, rate-independent return (regular, or the EFR of eq. 2.7), and when
!> tau > 0 the Duvaut-Lions relaxation (eq. 2.10) by backward Euler,
!> sigma = sigma_qs + w (sigma_trial - sigma_qs), w = tau/(tau + dt).
!> A feature whose parameter is zero costs nothing. See docs/research/theory.md.
module wellposed_dp_model
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_tensor, only: ntens6
  use wellposed_elasticity, only: apply_stiffness, stiffness
  use wellposed_hardening, only: strength
  use wellposed_drucker_prager, only: yield_value
  use wellposed_dp_params, only: dp_params_t
  use wellposed_return_mapping, only: return_t, regular_return, state_elastic
  use wellposed_efr, only: efr_return
  implicit none
  private
  public :: dp_state_t, dp_output_t, dp_update

  !> Internal state carried from increment to increment (Mandel eps_p).
  type :: dp_state_t
    real(dp) :: z = 0.0_dp                !< cumulative equivalent plastic strain
    real(dp) :: zeta = 0.0_dp             !< nonlocal strength (eq. 2.12, 4.34)
    real(dp) :: eps_p(ntens6) = 0.0_dp    !< plastic strain
  end type dp_state_t

  !> What an increment reports besides stress, state and tangent.
  type :: dp_output_t
    real(dp) :: dlambda = 0.0_dp  !< ||d eps^p|| of this increment (what a nonlocal host averages)
    real(dp) :: f = 0.0_dp        !< yield function at the end (may be > 0 with tau > 0)
    integer :: status = 0         !< 0 elastic, 1 plastic, 2 apex return
  end type dp_output_t

contains

  !> Advance `sig` (Mandel, in: start of increment, out: end) and `state` by
  !> the strain increment `deps` over `dtime`. `avg_dlambda` is the host's
  !> nonlocal average `<dlambda>` (0 for a local host). `tangent`, when present,
  !> is d sigma/d deps of this increment; leave it out when the host does not
  !> use it (explicit hosts) and no tangent is computed. On error `sig` and
  !> `state` are left as they came in.
  pure subroutine dp_update(p, sig, state, deps, dtime, avg_dlambda, out, tangent, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6)
    type(dp_state_t), intent(inout) :: state
    real(dp), intent(in) :: deps(ntens6), dtime, avg_dlambda
    type(dp_output_t), intent(out) :: out
    real(dp), intent(out), optional :: tangent(ntens6, ntens6)
    type(error_t), allocatable, intent(out) :: err
    type(return_t) :: ret
    real(dp) :: sig_tr(ntens6), zeta, w

    zeta = state%zeta + p%h_zeta*avg_dlambda
    sig_tr = sig + apply_stiffness(p%el, deps)
    if (p%efr) then
      call efr_return(p, sig_tr, deps, state%z, zeta, ret, tangent, err)
    else
      call regular_return(p, sig_tr, state%z, zeta, ret, tangent, err)
    end if
    if (allocated(err)) return

    if (p%tau > 0.0_dp .and. ret%state /= state_elastic) then
      w = p%tau/(p%tau + dtime)
      ret%sig = ret%sig + w*(sig_tr - ret%sig)
      ret%deps_p = (1.0_dp - w)*ret%deps_p
      ret%dz = (1.0_dp - w)*ret%dz
      ret%f = yield_value(ret%sig, p%beta, strength(p%hard, state%z + ret%dz) + zeta)
      if (present(tangent)) tangent = tangent + w*(stiffness(p%el) - tangent)
    end if

    sig = ret%sig
    state%z = state%z + ret%dz
    state%zeta = zeta
    state%eps_p = state%eps_p + ret%deps_p
    out%dlambda = ret%dz
    out%f = ret%f
    out%status = ret%state
  end subroutine dp_update

end module wellposed_dp_model
