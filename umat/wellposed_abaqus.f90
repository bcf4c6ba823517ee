!> Abaqus component order and engineering shears <-> the Mandel 6-vectors
!> of src/. Abaqus: 11, 22, 33, 12, 13, 23 (NTENS = 6) or 11, 22, 33, 12
!> (NTENS = 4: plane strain, axisymmetric), strains with gamma = 2 eps.
!> Mandel: the same order with sqrt(2) on the shears of stress and strain.
module wellposed_abaqus
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: ntens6, sqrt2
  implicit none
  private
  public :: stress_to_mandel, stress_from_mandel, strain_to_mandel, strain_from_mandel, &
            tangent_from_mandel

contains

  !> Abaqus stress (ntens) to Mandel; missing shears are zero.
  pure function stress_to_mandel(s, ntens) result(m)
    integer, intent(in) :: ntens
    real(dp), intent(in) :: s(ntens)
    real(dp) :: m(ntens6)
    m = 0.0_dp
    m(1:ntens) = s
    m(4:ntens) = sqrt2*s(4:ntens)
  end function stress_to_mandel

  !> Mandel stress to Abaqus order (first ntens components), written into
  !> the caller's array (no temporary of run-time size).
  pure subroutine stress_from_mandel(m, ntens, s)
    integer, intent(in) :: ntens
    real(dp), intent(in) :: m(ntens6)
    real(dp), intent(out) :: s(ntens)
    s = m(1:ntens)
    s(4:ntens) = m(4:ntens)/sqrt2
  end subroutine stress_from_mandel

  !> Abaqus strain (engineering shears) to Mandel; missing shears are zero.
  pure function strain_to_mandel(e, ntens) result(m)
    integer, intent(in) :: ntens
    real(dp), intent(in) :: e(ntens)
    real(dp) :: m(ntens6)
    m = 0.0_dp
    m(1:ntens) = e
    m(4:ntens) = e(4:ntens)/sqrt2
  end function strain_to_mandel

  !> Mandel strain to Abaqus order with engineering shears (all six).
  pure function strain_from_mandel(m) result(e)
    real(dp), intent(in) :: m(ntens6)
    real(dp) :: e(ntens6)
    e = m
    e(4:6) = sqrt2*m(4:6)
  end function strain_from_mandel

  !> DDSDDE = d sigma_abaqus / d strain_abaqus from the Mandel tangent:
  !> D^-1 T D^-1 with D = diag(1, 1, 1, sqrt2, sqrt2, sqrt2), cut to ntens,
  !> written into the caller's array.
  pure subroutine tangent_from_mandel(t, ntens, d)
    integer, intent(in) :: ntens
    real(dp), intent(in) :: t(ntens6, ntens6)
    real(dp), intent(out) :: d(ntens, ntens)
    integer :: i, j
    real(dp), parameter :: scale(ntens6) = [1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp/sqrt2, &
                                             1.0_dp/sqrt2, 1.0_dp/sqrt2]
    do j = 1, ntens
      do i = 1, ntens
        d(i, j) = t(i, j)*(scale(i)*scale(j))
      end do
    end do
  end subroutine tangent_from_mandel

end module wellposed_abaqus
