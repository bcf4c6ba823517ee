!> The kinematic arguments of a UMAT increment from the deformation
!> gradient at its start and end: DFGRD0, DFGRD1 (3 x 3, the driver's
!> ndim x ndim F embedded, the out-of-plane directions unstretched) and
!> DROT, the Hughes-Winget rotation increment of the increment's spin:
!> with dt L = (F1 - F0) F0^-1 and dt W its skew part,
!> DROT = (I - dt W/2)^-1 (I + dt W/2), exactly orthogonal for any W (a
!> Cayley transform) and to second order the rotation of the Jaumann rate
!> (docs/guide/mpm.md, "Hosting a UMAT in the MPM").
module wellposed_step_kinematics
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: step_kinematics, split_kinematics, small_strain_kinematics

contains

  !> DFGRD0, DFGRD1 and DROT of an increment whose F goes from f0 to f1
  !> (ndim x ndim, ndim 1 to 3; det f0 /= 0).
  pure subroutine step_kinematics(f0, f1, dfgrd0, dfgrd1, drot)
    real(dp), intent(in) :: f0(:, :), f1(:, :)
    real(dp), intent(out) :: dfgrd0(3, 3), dfgrd1(3, 3), drot(3, 3)
    call embed(f0, dfgrd0)
    call embed(f1, dfgrd1)
    call rotation(dfgrd0, dfgrd1, drot)
  end subroutine step_kinematics

  !> Part k of nsub equal parts of an increment from f0 to f1 (3 x 3): F
  !> interpolated linearly at the parts' ends (the last ends at f1 itself)
  !> and DROT of the part.
  pure subroutine split_kinematics(f0, f1, k, nsub, dfgrd0, dfgrd1, drot)
    real(dp), intent(in) :: f0(3, 3), f1(3, 3)
    integer, intent(in) :: k, nsub
    real(dp), intent(out) :: dfgrd0(3, 3), dfgrd1(3, 3), drot(3, 3)
    dfgrd0 = f0 + (f1 - f0)*(real(k - 1, dp)/nsub)
    if (k == nsub) then
      dfgrd1 = f1
    else
      dfgrd1 = f0 + (f1 - f0)*(real(k, dp)/nsub)
    end if
    call rotation(dfgrd0, dfgrd1, drot)
  end subroutine split_kinematics

  !> The small-strain kinematics of an increment from strain e to e + de
  !> (NTENS 6: 11 22 33 12 13 23, or 4: 11 22 33 12; engineering shears):
  !> F = I + eps at both ends, DROT = I.
  pure subroutine small_strain_kinematics(e, de, dfgrd0, dfgrd1, drot)
    real(dp), intent(in) :: e(:), de(:)
    real(dp), intent(out) :: dfgrd0(3, 3), dfgrd1(3, 3), drot(3, 3)
    integer :: a
    drot = 0.0_dp
    do a = 1, 3
      drot(a, a) = 1.0_dp
    end do
    call small_strain_f(e, 0.0_dp, dfgrd0)
    call small_strain_f(e, 1.0_dp, dfgrd1)

  contains

    pure subroutine small_strain_f(e, w, f)
      real(dp), intent(in) :: e(:), w
      real(dp), intent(out) :: f(3, 3)
      integer, parameter :: row(3) = [1, 1, 2], col(3) = [2, 3, 3]
      integer :: k
      f = drot
      do k = 1, 3
        f(k, k) = 1.0_dp + (e(k) + w*de(k))
      end do
      do k = 1, size(e) - 3
        f(row(k), col(k)) = 0.5_dp*(e(3 + k) + w*de(3 + k))
        f(col(k), row(k)) = f(row(k), col(k))
      end do
    end subroutine small_strain_f

  end subroutine small_strain_kinematics

  !> f (ndim x ndim) as a 3 x 3 deformation gradient: identity beyond ndim.
  pure subroutine embed(f, f3)
    real(dp), intent(in) :: f(:, :)
    real(dp), intent(out) :: f3(3, 3)
    integer :: nd, a
    nd = size(f, 1)
    f3 = 0.0_dp
    do a = 1, 3
      f3(a, a) = 1.0_dp
    end do
    f3(1:nd, 1:nd) = f
  end subroutine embed

  !> The Hughes-Winget rotation of the increment from f0 to f1 (3 x 3).
  pure subroutine rotation(f0, f1, drot)
    real(dp), intent(in) :: f0(3, 3), f1(3, 3)
    real(dp), intent(out) :: drot(3, 3)
    real(dp) :: g(3, 3), hw(3, 3), a(3, 3), b(3, 3), m(3, 3), df(3, 3)
    integer :: i
    ! dt L = (F1 - F0) F0^-1; half the spin increment dt W / 2
    call inverse(f0, m)
    df = f1 - f0
    call product(df, m, g)
    hw = 0.25_dp*(g - transpose(g))
    a = -hw
    b = hw
    do i = 1, 3
      a(i, i) = 1.0_dp
      b(i, i) = 1.0_dp
    end do
    call inverse(a, m)
    call product(m, b, drot)
  end subroutine rotation

  !> c = a b (3 x 3), written out.
  pure subroutine product(a, b, c)
    real(dp), intent(in) :: a(3, 3), b(3, 3)
    real(dp), intent(out) :: c(3, 3)
    integer :: i, j
    do j = 1, 3
      do i = 1, 3
        c(i, j) = a(i, 1)*b(1, j) + a(i, 2)*b(2, j) + a(i, 3)*b(3, j)
      end do
    end do
  end subroutine product

  !> r, the inverse of a 3 x 3 matrix m through its adjugate (det m /= 0).
  pure subroutine inverse(m, r)
    real(dp), intent(in) :: m(3, 3)
    real(dp), intent(out) :: r(3, 3)
    r(1, 1) = m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)
    r(1, 2) = m(1, 3)*m(3, 2) - m(1, 2)*m(3, 3)
    r(1, 3) = m(1, 2)*m(2, 3) - m(1, 3)*m(2, 2)
    r(2, 1) = m(2, 3)*m(3, 1) - m(2, 1)*m(3, 3)
    r(2, 2) = m(1, 1)*m(3, 3) - m(1, 3)*m(3, 1)
    r(2, 3) = m(1, 3)*m(2, 1) - m(1, 1)*m(2, 3)
    r(3, 1) = m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1)
    r(3, 2) = m(1, 2)*m(3, 1) - m(1, 1)*m(3, 2)
    r(3, 3) = m(1, 1)*m(2, 2) - m(1, 2)*m(2, 1)
    r = r/(m(1, 1)*r(1, 1) + m(1, 2)*r(2, 1) + m(1, 3)*r(3, 1))
  end subroutine inverse

end module wellposed_step_kinematics
