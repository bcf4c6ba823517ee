!> A test UMAT that checks the kinematic arguments the MPM passes, then
!> answers as linear elasticity (PROPS(1) = K, PROPS(2) = G, as
!> hooke_step.f): STRAN the sum of earlier DSTRAN, DFGRD0 the previous
!> DFGRD1, sym((DFGRD1 - DFGRD0) DFGRD0^-1) = DSTRAN in plane, DROT the
!> Hughes-Winget rotation of the spin in closed form; without F (the
!> probes) F = I + eps and DROT = I. PROPS(3) = 1 expects identities
!> instead. A failed check: a message on unit 6 and PNEWDT = -1.
!> NSTATV >= 27; STATEV(1:12) are left as they are.
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
                dstran, time, dtime, temp, dtemp, predef, dpred, cmname, ndi, nshr, ntens, &
                nstatv, props, nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1, noel, &
                npt, layer, kspt, kstep, kinc)
  use, intrinsic :: iso_fortran_env, only: error_unit
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, kstep, kinc
  real(dp), intent(inout) :: stress(ntens), statev(nstatv), sse, spd, scd, rpl, pnewdt
  real(dp), intent(out) :: ddsdde(ntens, ntens), ddsddt(ntens), drplde(ntens), drpldt
  real(dp), intent(in) :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
  real(dp), intent(in) :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3)
  real(dp), intent(in) :: celent, dfgrd0(3, 3), dfgrd1(3, 3)
  character(len=80), intent(in) :: cmname
  real(dp), parameter :: tol = 1.0e-13_dp
  real(dp) :: f_ss0(3, 3), f_ss1(3, 3), f_prev(3, 3), g(3, 3), inv(3, 3), rot(3, 3), eye(3, 3), sym(6), a, c, s
  real(dp) :: bulk, shear, trace
  integer :: i, j
  logical, save :: stretch_seen = .false., rotation_seen = .false.
  if (nstatv < 27 .or. nprops < 2) then
    write (6, '(a)') ' UMAT_KINEMATICS: needs NSTATV >= 27 and PROPS(1:2) = K, G'
    pnewdt = -1.0_dp
    return
  end if
  eye = 0.0_dp
  do i = 1, 3
    eye(i, i) = 1.0_dp
  end do
  ! STRAN: the earlier increments' sum
  if (maxval(abs(stran - statev(22:21 + ntens))) > 1.0e-15_dp) then
    call refuse('STRAN is not the sum of the earlier DSTRAN')
    return
  end if
  ! the host's small-strain kinematics of a call without F (the scenes'
  ! probes of the moduli): F = I + eps of STRAN and STRAN + DSTRAN, DROT = I
  call small_strain_f(stran, f_ss0)
  call small_strain_f(stran + dstran, f_ss1)
  if (all(dfgrd0 == f_ss0) .and. all(dfgrd1 == f_ss1) .and. all(drot == eye)) then
    s = 0.0_dp
  else if (.not. finite_strain_ok()) then
    return
  end if
  if (.not. stretch_seen .and. maxval(abs(dstran)) > 1.0e-9_dp .and. .not. &
      all(dfgrd1 == f_ss1)) then
    stretch_seen = .true.
    write (error_unit, '(a, es10.3, a, i0)') ' UMAT_KINEMATICS: checked a stretch of ', &
      maxval(abs(dstran)), ' at particle ', noel
  end if
  if (.not. rotation_seen .and. abs(s) > 1.0e-9_dp) then
    rotation_seen = .true.
    write (error_unit, '(a, es10.3, a, i0)') ' UMAT_KINEMATICS: checked a rotation of ', s, &
      ' rad at particle ', noel
  end if
  statev(13:21) = reshape(dfgrd1, [9])
  statev(22:21 + ntens) = statev(22:21 + ntens) + dstran
  ! linear elasticity, as hooke_step.f
  bulk = props(1)
  shear = props(2)
  ddsdde = 0.0_dp
  do j = 1, ndi
    do i = 1, ndi
      ddsdde(i, j) = bulk - 2.0_dp*shear/3.0_dp
    end do
    ddsdde(j, j) = ddsdde(j, j) + 2.0_dp*shear
  end do
  do i = ndi + 1, ntens
    ddsdde(i, i) = shear
  end do
  trace = sum(dstran(1:ndi))
  do i = 1, ndi
    stress(i) = stress(i) + (2.0_dp*shear*(dstran(i) - trace/3.0_dp) + bulk*trace)
  end do
  do i = ndi + 1, ntens
    stress(i) = stress(i) + shear*dstran(i)
  end do

contains

  !> The MPM step's kinematics: the chain, dt L against DSTRAN, DROT.
  logical function finite_strain_ok() result(ok)
    ok = .false.
    if (nprops >= 3) then
      if (props(3) == 1.0_dp .and. any([dfgrd0 - eye, dfgrd1 - eye, drot - eye] /= 0.0_dp)) then
        call refuse('DFGRD0, DFGRD1 and DROT are not the identity')
        return
      end if
    end if
    ! DFGRD0: the previous increment's DFGRD1
    f_prev = reshape(statev(13:21), [3, 3])
    if (all(f_prev == 0.0_dp)) f_prev = eye
    if (maxval(abs(dfgrd0 - f_prev)) > 0.0_dp) then
      call refuse('DFGRD0 is not the previous increment''s DFGRD1')
      return
    end if
    ! dt L and its symmetric part against DSTRAN
    inv = inverse(dfgrd0)
    g = matmul(dfgrd1 - dfgrd0, inv)
    sym(1) = g(1, 1)
    sym(2) = g(2, 2)
    sym(3) = g(3, 3)
    sym(4) = g(1, 2) + g(2, 1)
    sym(5) = g(1, 3) + g(3, 1)
    sym(6) = g(2, 3) + g(3, 2)
    if (maxval(abs(sym(1:ntens) - dstran)) > tol .or. any(sym(ntens + 1:6) /= 0.0_dp) .or. &
        any(dfgrd1(1:2, 3) /= 0.0_dp) .or. any(dfgrd1(3, 1:2) /= 0.0_dp) .or. &
        dfgrd1(3, 3) /= 1.0_dp) then
      call refuse('DFGRD1 - DFGRD0 does not give DSTRAN')
      return
    end if
    ! DROT: orthogonal, det 1, the closed form
    a = 0.25_dp*(g(1, 2) - g(2, 1))
    c = (1.0_dp - a*a)/(1.0_dp + a*a)
    s = 2.0_dp*a/(1.0_dp + a*a)
    rot = eye
    rot(1, 1) = c
    rot(1, 2) = s
    rot(2, 1) = -s
    rot(2, 2) = c
    if (maxval(abs(matmul(transpose(drot), drot) - eye)) > tol .or. &
        abs(det(drot) - 1.0_dp) > tol .or. maxval(abs(drot - rot)) > tol) then
      call refuse('DROT is not the Hughes-Winget rotation of the spin')
      return
    end if
    ok = .true.
  end function finite_strain_ok

  !> I + eps of a strain e (NTENS order, engineering shears), as the host.
  pure subroutine small_strain_f(e, f)
    real(dp), intent(in) :: e(:)
    real(dp), intent(out) :: f(3, 3)
    integer, parameter :: row(3) = [1, 1, 2], col(3) = [2, 3, 3]
    integer :: k
    f = eye
    do k = 1, 3
      f(k, k) = 1.0_dp + e(k)
    end do
    do k = 1, size(e) - 3
      f(row(k), col(k)) = 0.5_dp*e(3 + k)
      f(col(k), row(k)) = f(row(k), col(k))
    end do
  end subroutine small_strain_f

  subroutine refuse(what)
    character(len=*), intent(in) :: what
    write (6, '(a, a, a, i0, a, i0)') ' UMAT_KINEMATICS: ', what, ' (particle ', noel, &
      ', increment ', kinc, ')'
    pnewdt = -1.0_dp
  end subroutine refuse

  pure function inverse(m) result(r)
    real(dp), intent(in) :: m(3, 3)
    real(dp) :: r(3, 3)
    r(1, 1) = m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)
    r(1, 2) = m(1, 3)*m(3, 2) - m(1, 2)*m(3, 3)
    r(1, 3) = m(1, 2)*m(2, 3) - m(1, 3)*m(2, 2)
    r(2, 1) = m(2, 3)*m(3, 1) - m(2, 1)*m(3, 3)
    r(2, 2) = m(1, 1)*m(3, 3) - m(1, 3)*m(3, 1)
    r(2, 3) = m(1, 3)*m(2, 1) - m(1, 1)*m(2, 3)
    r(3, 1) = m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1)
    r(3, 2) = m(1, 2)*m(3, 1) - m(1, 1)*m(3, 2)
    r(3, 3) = m(1, 1)*m(2, 2) - m(1, 2)*m(2, 1)
    r = r/det(m)
  end function inverse

  pure real(dp) function det(m)
    real(dp), intent(in) :: m(3, 3)
    det = m(1, 1)*(m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)) - m(1, 2)*(m(2, 1)*m(3, 3) - &
          m(2, 3)*m(3, 1)) + m(1, 3)*(m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1))
  end function det

end subroutine umat
