!> The minimal reference bench_umat compares the UMAT against: the elastic
!> trial, the closed-form return of the linear Drucker-Prager cone (perfect
!> plasticity, eq. 4.36) or to its apex, and the consistent tangent, NTENS
!> = 6, with no validation, checks, options, status or energies: the
!> arithmetic a UMAT cannot avoid. props = K, G, beta, beta_p, k0. In its
!> own file (no link-time inlining), so it is a real call as umat is.
subroutine bench_reference(stress, statev, ddsdde, dstran, props, tangent)
  use wellposed_kinds, only: dp
  implicit none
  real(dp), intent(inout) :: stress(6), statev(12), ddsdde(6, 6)
  real(dp), intent(in) :: dstran(6), props(5)
  logical, intent(in) :: tangent
  real(dp), parameter :: r2 = 1.4142135623730950488_dp
  real(dp) :: bulk, shear, beta, beta_p, tr, sig(6), s(6), i1, q, f, n_m, a, x, x_max, sh(6)
  real(dp) :: cm(6), cn(6), g2, dep(6), rn, rq
  integer :: i, j

  bulk = props(1); shear = props(2); beta = props(3); beta_p = props(4)
  tr = dstran(1) + dstran(2) + dstran(3)
  sig(1:3) = stress(1:3) + 2.0_dp*shear*(dstran(1:3) - tr*(1.0_dp/3.0_dp)) + bulk*tr
  sig(4:6) = stress(4:6) + shear*dstran(4:6)
  i1 = sig(1) + sig(2) + sig(3)
  s(1:3) = sig(1:3) - i1*(1.0_dp/3.0_dp)
  s(4:6) = sig(4:6)
  q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
  f = q*(1.0_dp/r2) + beta*i1 - props(5)
  if (f <= 0.0_dp) then
    stress = sig
    statev(12) = 0.0_dp
    if (tangent) then
      ddsdde = 0.0_dp
      ddsdde(1:3, 1:3) = bulk - 2.0_dp*shear*(1.0_dp/3.0_dp)
      do i = 1, 3
        ddsdde(i, i) = ddsdde(i, i) + 2.0_dp*shear
        ddsdde(i + 3, i + 3) = shear
      end do
    end if
    return
  end if
  n_m = sqrt(0.5_dp + 3.0_dp*beta_p**2)
  rn = 1.0_dp/n_m
  a = (shear + 9.0_dp*bulk*beta*beta_p)*rn
  x = f/a
  x_max = q*n_m*(1.0_dp/r2)/shear
  if (x < x_max) then
    rq = 1.0_dp/q
    sh = s*rq
    stress = (1.0_dp - x/x_max)*s
    stress(1:3) = stress(1:3) + (i1 - 9.0_dp*bulk*beta_p*x*rn)*(1.0_dp/3.0_dp)
    dep = (x*rn*(1.0_dp/r2))*sh
    dep(1:3) = dep(1:3) + x*beta_p*rn
    statev(5:10) = statev(5:10) + dep*[1, 1, 1, 2, 2, 2]
    statev(1) = statev(1) + x
    statev(12) = 1.0_dp
    if (tangent) then
      cm = r2*shear*sh
      cn = cm
      cm(1:3) = cm(1:3) + 3.0_dp*bulk*beta_p
      cn(1:3) = cn(1:3) + 3.0_dp*bulk*beta
      cm = cm*(rn/a)
      g2 = x*2.0_dp*r2*shear**2*rn*rq
      do j = 1, 6
        do i = 1, 6
          ddsdde(i, j) = g2*sh(i)*sh(j) - cm(i)*cn(j)
        end do
      end do
      ddsdde(1:3, 1:3) = ddsdde(1:3, 1:3) + bulk + (g2 - 2.0_dp*shear)*(1.0_dp/3.0_dp)
      do i = 1, 3
        ddsdde(i, i) = ddsdde(i, i) + 2.0_dp*shear - g2
        ddsdde(i + 3, i + 3) = ddsdde(i + 3, i + 3) + shear - 0.5_dp*g2
      end do
    end if
  else
    ! Apex (perfect plasticity): sigma = k0/(3 beta) I, d eps^p = C^-1 : (trial - apex).
    rq = 1.0_dp/beta
    dep = s*(0.5_dp/shear)
    dep(1:3) = dep(1:3) + (i1 - props(5)*rq)*((1.0_dp/9.0_dp)/bulk)
    stress(1:3) = props(5)*rq*(1.0_dp/3.0_dp)
    stress(4:6) = 0.0_dp
    statev(5:10) = statev(5:10) + dep*[1, 1, 1, 2, 2, 2]
    statev(1) = statev(1) + sqrt(dep(1)**2 + dep(2)**2 + dep(3)**2 + &
                                 2.0_dp*(dep(4)**2 + dep(5)**2 + dep(6)**2))
    statev(12) = 2.0_dp
    if (tangent) ddsdde = 0.0_dp
  end if
end subroutine bench_reference

!> The reference behind the contract's input checks, done by the same
!> library procedures as in the UMAT: layout, PROPS and DTIME
!> (check_props), finiteness of STRESS, STRAN, DSTRAN and STATEV 1-12 as one
!> carry. What a UMAT that keeps those checks cannot go below; no energies,
!> no STATEV bookkeeping past the reference's.
subroutine bench_reference_checked(stress, statev, ddsdde, stran, dstran, dtime, props, nprops)
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_finite, only: finite_carry
  use wellposed_dp_params, only: dp_params_t
  use wellposed_umat_adapter, only: check_props
  implicit none
  integer, intent(in) :: nprops
  real(dp), intent(inout) :: stress(6), statev(12), ddsdde(6, 6)
  real(dp), intent(in) :: stran(6), dstran(6), dtime, props(nprops)
  interface
    subroutine bench_reference(stress, statev, ddsdde, dstran, props, tangent)
      import :: dp
      real(dp), intent(inout) :: stress(6), statev(12), ddsdde(6, 6)
      real(dp), intent(in) :: dstran(6), props(5)
      logical, intent(in) :: tangent
    end subroutine bench_reference
  end interface
  type(dp_params_t) :: p
  integer(int64) :: carry
  integer :: fault
  logical :: want_tangent

  call check_props(3, 3, 6, 12, nprops, props, dtime, p, want_tangent, fault)
  if (fault /= 0) return
  carry = ior(ior(finite_carry(stress), finite_carry(dstran)), &
              ior(finite_carry(stran), finite_carry(statev)))
  if (carry < 0) return
  call bench_reference(stress, statev, ddsdde, dstran, props(1:5), want_tangent)
end subroutine bench_reference_checked
