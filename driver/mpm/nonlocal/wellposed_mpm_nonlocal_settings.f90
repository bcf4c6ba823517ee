!> The deck's choices for the dissertation's nonlocal Algorithm 1 (the
!> &nonlocal group, docs/decks.md): the iteration scheme and its
!> tolerances, limits and weight cut-off (wellposed_mpm_algorithm1).
module wellposed_mpm_nonlocal_settings
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: nonlocal_settings_t, nl_fixed_point, nl_anderson, nl_scheme_names, nl_scheme_id

  !> Iteration schemes: the dissertation's Gauss-Seidel fixed point of eq. 4.39,
  !> and Anderson acceleration of the same sweep.
  integer, parameter :: nl_fixed_point = 1, nl_anderson = 2
  character(len=11), parameter :: nl_scheme_names(2) = [character(len=11) :: 'fixed_point', &
                                                        'anderson']

  !> What a deck chooses (&nonlocal group). Tolerances are on dlambda, a
  !> strain increment (dimensionless).
  type :: nonlocal_settings_t
    integer :: scheme = nl_fixed_point
    real(dp) :: tolerance = 1.0e-14_dp      !< absolute on max |dlambda^{k+1} - dlambda^k|
    real(dp) :: rel_tolerance = 1.0e-8_dp   !< times max_p dlambda_p, added to tolerance
    integer :: max_iterations = 200         !< sweeps per step-2 round
    integer :: stall_iterations = 10        !< sweeps without a new smallest error: diverging
    integer :: max_rounds = 50              !< step 2 -> step 3 -> step 2 rounds per step
    integer :: anderson_depth = 16          !< m, differences kept
    real(dp) :: anderson_mixing = 1.0_dp    !< beta in (0, 1]
    real(dp) :: weight_cutoff = 1.0e-6_dp   !< alpha below this is dropped (eq. 4.27)
  end type nonlocal_settings_t

contains

  !> The deck's scheme word as a scheme id, 0 when it is none.
  pure integer function nl_scheme_id(word) result(id)
    character(len=*), intent(in) :: word
    do id = 1, size(nl_scheme_names)
      if (trim(word) == trim(nl_scheme_names(id))) return
    end do
    id = 0
  end function nl_scheme_id

end module wellposed_mpm_nonlocal_settings
