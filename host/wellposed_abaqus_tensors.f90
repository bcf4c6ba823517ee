!> The tensor utilities of Abaqus/Standard that legacy UMATs call, with
!> Abaqus' documented meaning (Abaqus User Subroutines Reference, "Utility
!> routines"); host/abaqus_externals.f90 exposes them under their
!> Abaqus names. A tensor travels as an Abaqus vector of NDI direct
!> components (11, 22, 33 as far as NDI reaches) followed by NSHR shears
!> (12, 13, 23 as far as NSHR reaches); LSTR = 1 marks a stress, LSTR = 2 a
!> strain, whose shears are engineering shears (gamma = 2 eps).
module wellposed_abaqus_tensors
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_lapack, only: sym_eigen
  implicit none
  private
  public :: abaqus_matrix, abaqus_vector, abaqus_sinv, abaqus_sprind, abaqus_rotsig

  integer, parameter :: shear_i(3) = [1, 1, 2], shear_j(3) = [2, 3, 3]

contains

  !> The symmetric 3x3 tensor of an Abaqus vector (absent components 0).
  pure function abaqus_matrix(s, lstr, ndi, nshr) result(t)
    integer, intent(in) :: lstr, ndi, nshr
    real(dp), intent(in) :: s(ndi + nshr)
    real(dp) :: t(3, 3), f
    integer :: k
    t = 0.0_dp
    do k = 1, ndi
      t(k, k) = s(k)
    end do
    f = 1.0_dp
    if (lstr == 2) f = 0.5_dp
    do k = 1, nshr
      t(shear_i(k), shear_j(k)) = f*s(ndi + k)
      t(shear_j(k), shear_i(k)) = f*s(ndi + k)
    end do
  end function abaqus_matrix

  !> The Abaqus vector of a symmetric 3x3 tensor (inverse of abaqus_matrix).
  pure function abaqus_vector(t, lstr, ndi, nshr) result(s)
    integer, intent(in) :: lstr, ndi, nshr
    real(dp), intent(in) :: t(3, 3)
    real(dp) :: s(ndi + nshr), f
    integer :: k
    do k = 1, ndi
      s(k) = t(k, k)
    end do
    f = 1.0_dp
    if (lstr == 2) f = 2.0_dp
    do k = 1, nshr
      s(ndi + k) = f*0.5_dp*(t(shear_i(k), shear_j(k)) + t(shear_j(k), shear_i(k)))
    end do
  end function abaqus_vector

  !> SINV: SINV1 = trace/3 (the mean stress) and SINV2 = sqrt(3/2 S:S)
  !> (the Mises equivalent stress, S the deviator) of a stress vector.
  pure subroutine abaqus_sinv(s, ndi, nshr, sinv1, sinv2)
    integer, intent(in) :: ndi, nshr
    real(dp), intent(in) :: s(ndi + nshr)
    real(dp), intent(out) :: sinv1, sinv2
    real(dp) :: t(3, 3)
    integer :: k
    t = abaqus_matrix(s, 1, ndi, nshr)
    sinv1 = (t(1, 1) + t(2, 2) + t(3, 3))/3.0_dp
    do k = 1, 3
      t(k, k) = t(k, k) - sinv1
    end do
    sinv2 = sqrt(1.5_dp*sum(t**2))
  end subroutine abaqus_sinv

  !> SPRIND (and SPRINC without `an`): principal values `ps` in ascending
  !> order and, in row K of `an`, the unit direction of ps(K): an(K, 1:3)
  !> are its 1, 2, 3 components. Strains (LSTR = 2) give principal strains.
  subroutine abaqus_sprind(s, lstr, ndi, nshr, ps, an, err)
    integer, intent(in) :: lstr, ndi, nshr
    real(dp), intent(in) :: s(ndi + nshr)
    real(dp), intent(out) :: ps(3)
    real(dp), intent(out), optional :: an(3, 3)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: v(3, 3)
    call sym_eigen(abaqus_matrix(s, lstr, ndi, nshr), ps, v, err)
    if (present(an)) an = transpose(v)
  end subroutine abaqus_sprind

  !> ROTSIG: the vector of R T R^T, T the tensor of `s` (LSTR = 1 stress,
  !> 2 strain with engineering shears): a stress or strain carried by the
  !> rotation increment DROT of the UMAT call.
  pure function abaqus_rotsig(s, r, lstr, ndi, nshr) result(sp)
    integer, intent(in) :: lstr, ndi, nshr
    real(dp), intent(in) :: s(ndi + nshr), r(3, 3)
    real(dp) :: sp(ndi + nshr), t(3, 3), rt(3, 3)
    t = abaqus_matrix(s, lstr, ndi, nshr)
    rt = matmul(t, transpose(r))
    t = matmul(r, rt)
    sp = abaqus_vector(t, lstr, ndi, nshr)
  end function abaqus_rotsig

end module wellposed_abaqus_tensors
