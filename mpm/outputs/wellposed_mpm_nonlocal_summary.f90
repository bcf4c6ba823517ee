!> The Algorithm 1 figures of an MPM summary.txt (the dissertation's eq.
!> 4.46-4.50), the same for bars and plates: steps iterated, sweeps per
!> step, and the contraction bounds of eq. 4.43 and 4.45. The bounds are
!> closed forms of our model's h_eta, h_zeta and a; for a user's UMAT
!> (nonlocal_contract) they are not known and are written
!> `not_applicable  # why` (docs/guide/decks.md, "Summary figures").
module wellposed_mpm_nonlocal_summary
  use wellposed_kinds, only: dp
  use wellposed_summary, only: summary_t
  use wellposed_mpm_nonlocal, only: nonlocal_t
  implicit none
  private
  public :: add_nonlocal_summary, bound_text

  character(len=*), parameter :: no_bound = 'a user''s UMAT (nonlocal_contract): the '// &
    'bound is a closed form of our model''s h_eta, h_zeta and a, which its PROPS need not hold'

contains

  !> The figures of `nl` under keys prefix//'nonlocal_...' (prefix: '' for
  !> a bar, '<case>.' for a plate case).
  subroutine add_nonlocal_summary(sm, prefix, nl)
    type(summary_t), intent(inout) :: sm
    character(len=*), intent(in) :: prefix
    type(nonlocal_t), intent(in) :: nl
    call sm%add(prefix//'nonlocal_steps_iterated', nl%steps_iterated)
    call sm%add(prefix//'nonlocal_iterations_mean', real(nl%iterations_total, dp)/ &
                max(nl%steps_iterated, 1), 'sweeps per step with plastic particles')
    call sm%add(prefix//'nonlocal_iterations_max', nl%iterations_max)
    call add_bound(sm, prefix//'lipschitz_eq4_43_sharp', nl%bound_43, &
                   '|h_zeta/(a + h_eta)|, eq. 4.43 with N_alpha = 1')
    call add_bound(sm, prefix//'lipschitz_eq4_45_sharp', nl%bound_45, &
                   '|(h_eta + h_zeta)/a|, eq. 4.45 with N_alpha = 1')
  end subroutine add_nonlocal_summary

  !> A contraction bound under `key`, or why it is not known (bound < 0).
  subroutine add_bound(sm, key, bound, what)
    type(summary_t), intent(inout) :: sm
    character(len=*), intent(in) :: key, what
    real(dp), intent(in) :: bound
    if (bound >= 0.0_dp) then
      call sm%add(key, bound, what)
    else
      call sm%not_applicable(key, no_bound)
    end if
  end subroutine add_bound

  !> A bound for a progress line: the number, or why it is not known.
  function bound_text(bound, number) result(text)
    real(dp), intent(in) :: bound
    character(len=*), intent(in) :: number
    character(len=:), allocatable :: text
    text = number
    if (.not. bound >= 0.0_dp) text = 'not known (a user''s UMAT)'
  end function bound_text

end module wellposed_mpm_nonlocal_summary
