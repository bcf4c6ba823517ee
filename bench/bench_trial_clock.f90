!> The MPM benchmarks' yardstick: CPU nanoseconds of one elastic trial
!> stress (bench_elastic_trial, bench_trial.f90: sigma + C : dstran in
!> Abaqus layout behind a real call, with the resets of a UMAT call), timed
!> as bench_umat times it, so that an MPM step per particle reads as a
!> ratio to the same kernel measured in the same run.
module bench_trial_clock
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: trial_ns

  interface
    subroutine bench_elastic_trial(stress, statev, ddsdde, dstran, nstatv)
      import :: dp
      integer, intent(in) :: nstatv
      real(dp), intent(inout) :: stress(6), statev(nstatv)
      real(dp), intent(in) :: ddsdde(6, 6), dstran(6)
    end subroutine bench_elastic_trial
  end interface

contains

  !> CPU ns per trial over `ncalls` calls (the case-study moduli K = 4 GPa,
  !> G = 1.5 GPa, bench_umat's cone increment); `sink` keeps the result live.
  function trial_ns(ncalls, sink) result(ns)
    integer, intent(in) :: ncalls
    real(dp), intent(inout) :: sink
    real(dp) :: ns, stress(6), statev(12), c(6, 6), s0(6), de(6), t0, t1
    integer :: i
    s0 = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    de = [1.0e-4_dp, -2.0e-5_dp, 3.0e-5_dp, 4.0e-5_dp, -1.0e-5_dp, 2.0e-5_dp]
    c = 0.0_dp
    c(1:3, 1:3) = 4.0e9_dp - 1.0e9_dp
    do i = 1, 3
      c(i, i) = 4.0e9_dp + 2.0e9_dp
      c(i + 3, i + 3) = 1.5e9_dp
    end do
    call cpu_time(t0)
    do i = 1, ncalls
      stress = s0
      statev = 0.0_dp
      call bench_elastic_trial(stress, statev, c, de, 12)
      sink = sink + stress(1)
    end do
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/ncalls
  end function trial_ns

end module bench_trial_clock
