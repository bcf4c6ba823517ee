!> Helpers shared by the unit tests: a UMAT call with the contract's
!> defaults, a central-difference tangent of the UMAT itself, and the
!> case-study properties (docs/research/cases.md, case A).
module wellposed_test_support
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
  implicit none
  private
  public :: call_umat, fd_tangent, case_props, case_stress, nsv, axial_increment

  !> STATEV length used by the tests (the contract's minimum).
  integer, parameter :: nsv = 12

contains

  !> Sandler-Rubin case study (section 2.3, reference defaults for K and G):
  !> K = 4 GPa, G = 1.5 GPa, beta = 0.315, beta_p = 0, k0 = 5.066 MPa.
  pure function case_props() result(props)
    real(dp) :: props(14)
    props = 0.0_dp
    props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  end function case_props

  !> The case study's initial stress (Abaqus order, tension positive).
  pure function case_stress() result(s)
    real(dp) :: s(6)
    s = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  end function case_stress

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

  !> One increment of axial strain `de_axial` (component 1) with the lateral
  !> stresses (2, 3) held at their start values and shear strains zero, as in
  !> uniaxial-stress and triaxial tests: Newton on the lateral strains with
  !> DDSDDE, backtracking when the residual grows (an incrementally nonlinear
  !> model switches branch as the lateral strains change). Returns the
  !> iteration count, or -1 without convergence.
  function axial_increment(props, stress, statev, de_axial) result(iterations)
    real(dp), intent(in) :: props(:), de_axial
    real(dp), intent(inout) :: stress(6), statev(:)
    integer :: iterations
    real(dp) :: s0(6), sv0(size(statev)), de(6), step(2), r(2), rnorm, trial_norm, dd(6, 6)
    real(dp) :: a(2, 2), lam
    integer :: it, cut
    s0 = stress; sv0 = statev
    de = 0.0_dp; de(1) = de_axial
    call residual(de, r, dd)
    rnorm = norm2(r)
    iterations = -1
    do it = 1, 50
      if (rnorm <= 1.0e-9_dp*maxval(abs(stress))) then
        iterations = it - 1
        return
      end if
      a = dd(2:3, 2:3)
      step = -[a(2, 2)*r(1) - a(1, 2)*r(2), a(1, 1)*r(2) - a(2, 1)*r(1)] &
             /(a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1))
      lam = 1.0_dp
      do cut = 1, 30
        de(2:3) = de(2:3) + lam*step
        call residual(de, r, dd)
        trial_norm = norm2(r)
        if (trial_norm < rnorm) exit
        de(2:3) = de(2:3) - lam*step
        lam = 0.5_dp*lam
      end do
      rnorm = trial_norm
    end do
  contains
    subroutine residual(e, res, tangent)
      real(dp), intent(in) :: e(6)
      real(dp), intent(out) :: res(2), tangent(6, 6)
      stress = s0; statev = sv0
      call call_umat(props, stress, statev, tangent, e, 6)
      res = stress(2:3) - s0(2:3)
    end subroutine residual
  end function axial_increment

end module wellposed_test_support
