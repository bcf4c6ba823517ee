!> Helpers shared by the unit tests: a UMAT call with the contract's
!> defaults, a central-difference tangent of the UMAT itself, and the
!> case-study properties (shared reference: cases.md, A).
module wellposed_test_support
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  private
  public :: call_umat, fd_tangent, seed_props, seed_stress, nsv

  !> STATEV length used by the tests (the contract's minimum).
  integer, parameter :: nsv = 12

contains

  !> Sandler-Rubin case study (seed 2.3, reference defaults for K and G):
  !> K = 4 GPa, G = 1.5 GPa, beta = 0.315, beta_p = 0, k0 = 5.066 MPa.
  pure function seed_props() result(props)
    real(dp) :: props(14)
    props = 0.0_dp
    props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  end function seed_props

  !> The case study's initial stress (Abaqus order, tension positive).
  pure function seed_stress() result(s)
    real(dp) :: s(6)
    s = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  end function seed_stress

  !> One UMAT increment with NDI = 3 and NSHR = ntens - 3; returns PNEWDT.
  subroutine call_umat(props, stress, statev, ddsdde, dstran, ntens, dtime, pnewdt, nstatv)
    real(dp), intent(in) :: props(:)
    integer, intent(in) :: ntens
    real(dp), intent(inout) :: stress(ntens), statev(:)
    real(dp), intent(out) :: ddsdde(ntens, ntens)
    real(dp), intent(in) :: dstran(ntens)
    real(dp), intent(in), optional :: dtime
    real(dp), intent(out), optional :: pnewdt
    integer, intent(in), optional :: nstatv
    real(dp) :: sse, spd, scd, rpl, ddsddt(ntens), drplde(ntens), drpldt, stran(ntens)
    real(dp) :: time(2), dt, predef(1), dpred(1), coords(3), drot(3, 3), pnew, f(3, 3)
    integer :: nsv_used
    character(len=80) :: cmname
    sse = 0.0_dp; spd = 0.0_dp; scd = 0.0_dp; rpl = 0.0_dp; drpldt = 0.0_dp
    ddsddt = 0.0_dp; drplde = 0.0_dp; stran = 0.0_dp; time = 0.0_dp
    predef = 0.0_dp; dpred = 0.0_dp; coords = 0.0_dp; drot = 0.0_dp; f = 0.0_dp
    ddsdde = 0.0_dp
    cmname = 'WELLPOSED'
    dt = 1.0e-3_dp
    if (present(dtime)) dt = dtime
    nsv_used = size(statev)
    if (present(nstatv)) nsv_used = nstatv
    pnew = 1.0_dp
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
              dstran, time, dt, 0.0_dp, 0.0_dp, predef, dpred, cmname, 3, ntens - 3, &
              ntens, nsv_used, props, size(props), coords, drot, pnew, 1.0_dp, f, f, &
              1, 1, 1, 1, 1, 1)
    if (present(pnewdt)) pnewdt = pnew
  end subroutine call_umat

  !> Central differences of the UMAT's stress with respect to DSTRAN, from
  !> the same start state, step h in each component.
  function fd_tangent(props, stress0, statev0, dstran, ntens, h, dtime) result(t)
    real(dp), intent(in) :: props(:)
    integer, intent(in) :: ntens
    real(dp), intent(in) :: stress0(ntens), statev0(:), dstran(ntens), h
    real(dp), intent(in), optional :: dtime
    real(dp) :: t(ntens, ntens), sp(ntens), sm(ntens), e(ntens), d(ntens, ntens)
    real(dp) :: sv(size(statev0))
    integer :: j
    do j = 1, ntens
      e = dstran; e(j) = e(j) + h
      sp = stress0; sv = statev0
      call call_umat(props, sp, sv, d, e, ntens, dtime)
      e = dstran; e(j) = e(j) - h
      sm = stress0; sv = statev0
      call call_umat(props, sm, sv, d, e, ntens, dtime)
      t(:, j) = (sp - sm)/(2.0_dp*h)
    end do
  end function fd_tangent

end module wellposed_test_support
