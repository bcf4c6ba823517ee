!> The cost of gfortran's floating-point environment save and restore on
!> this CPU, for bench_umat's entry row: two procedures with the same one
!> addition, one with an IEEE intrinsic module in its scope (gfortran then
!> saves the environment on entry and restores it on return, whether or not
!> the procedure uses the module's names), one without. Kept in their own
!> file (no link-time inlining) so that both are real calls.
subroutine bench_fp_env_saved(x)
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  implicit none
  real(dp), intent(inout) :: x
  x = x + 1.0_dp
end subroutine bench_fp_env_saved

subroutine bench_fp_env_plain(x)
  use wellposed_kinds, only: dp
  implicit none
  real(dp), intent(inout) :: x
  x = x + 1.0_dp
end subroutine bench_fp_env_plain
