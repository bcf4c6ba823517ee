!> The lower bound the UMAT benchmark compares against: the elastic trial
!> stress sigma + C : dstran in Abaqus layout, with the same array traffic
!> as a UMAT call (stress and STATEV copied in and out). Kept in its own file
!> so the compiler cannot inline it into the timing loop, just as it cannot
!> inline the library's umat.
subroutine bench_elastic_trial(stress, statev, ddsdde, dstran, nstatv)
  use wellposed_kinds, only: dp
  implicit none
  integer, intent(in) :: nstatv
  real(dp), intent(inout) :: stress(6), statev(nstatv)
  real(dp), intent(in) :: ddsdde(6, 6), dstran(6)
  stress = stress + matmul(ddsdde, dstran)
  statev(12) = 0.0_dp
end subroutine bench_elastic_trial
