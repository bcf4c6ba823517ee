!> A user's UMAT that follows the nonlocal contract of docs/guide/umat.md: it
!> writes its plastic multiplier increment to STATEV(2) and reads the
!> host's nonlocal average of it from STATEV(3). Its own PROPS layout:
!> PROPS(1:7) = K, G, beta, k0, h_eta, h_zeta, L (Drucker-Prager with
!> linear hardening and nonlocal hardening, beta_p = 0). The constitutive
!> work is wellposed's, reached as a library routine (umat_update) with
!> wellposed's PROPS built here, so the MPM sees a user's UMAT whose
!> answer is ours: what Algorithm 1 needs (L) must come from the deck.
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
                stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, &
                ndi, nshr, ntens, nstatv, props, nprops, coords, drot, pnewdt, &
                celent, dfgrd0, dfgrd1, noel, npt, layer, kspt, kstep, kinc)
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_adapter, only: umat_update
  implicit none
  character(len=80), intent(in) :: cmname
  integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, kstep, kinc
  real(dp), intent(inout) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
  real(dp), intent(inout) :: sse, spd, scd, rpl, ddsddt(ntens), drplde(ntens), drpldt
  real(dp), intent(in) :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
  real(dp), intent(in) :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3)
  real(dp), intent(inout) :: pnewdt
  real(dp), intent(in) :: celent, dfgrd0(3, 3), dfgrd1(3, 3)
  type(error_t), allocatable :: err
  real(dp) :: pr(14)
  if (nprops /= 7) then
    write (*, '(a)') 'UMAT_OVERLOCAL: PROPS must be K, G, beta, k0, h_eta, h_zeta, L'
    pnewdt = -1.0_dp
    return
  end if
  ! wellposed's layout (docs/guide/umat.md): K, G, beta, beta_p, k0, h, k_lim,
  ! z_ref, P_v, P_d, tau, h_zeta, L, explicit host
  pr = 0.0_dp
  pr([1, 2, 3, 5, 6, 12, 13]) = props(1:7)
  pr(14) = 1.0_dp
  call umat_update(stress, statev, ddsdde, sse, spd, dstran, stran, dtime, ndi, nshr, &
                   ntens, nstatv, pr, size(pr), pnewdt, err)
  if (allocated(err)) write (*, '(a)') 'UMAT_OVERLOCAL: '//err%message
end subroutine umat
