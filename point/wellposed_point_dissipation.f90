!> The plastic dissipation along a point path and the load's work, from the
!> path's stress and plastic strain eps^p = eps - C^-1 sigma: per increment
!> D = (sigma_n + sigma_n+1)/2 . d eps^p and W likewise with d eps (Voigt,
!> engineering shears). The second law asks D >= 0 of every plastic
!> increment: the associative cone has sigma : df/dsigma = k > 0 (eq. 2.3),
!> the EFR (eq. 2.7) need not (docs/research/theory.md, "The extended flow
!> rule and the second law").
module wellposed_point_dissipation
  use wellposed_kinds, only: dp
  use wellposed_summary, only: summary_t
  implicit none
  private
  public :: dissipation_t, path_dissipation, add_dissipation

  !> The path's sums; Pa (J/m^3).
  type :: dissipation_t
    real(dp) :: dissipation = 0.0_dp    !< sum of D over the increments
    real(dp) :: work = 0.0_dp           !< sum of W over the increments
    real(dp) :: least_rate = 0.0_dp     !< min of D/||d eps^p|| over plastic increments
    integer :: plastic = 0              !< increments with plastic strain
    integer :: negative = 0             !< plastic increments with D < 0
  end type dissipation_t

  !> An increment counts as plastic when ||d eps^p|| exceeds this share of
  !> ||d eps|| (below it, d eps^p is the rounding of C^-1 d sigma).
  real(dp), parameter :: plastic_share = 1.0e-8_dp

contains

  !> The sums of the path with rows stress(n, 6), strain(n, 6) and its
  !> plastic strain ep(6, n) (columns, as write_plastic_strain holds it).
  pure function path_dissipation(stress, strain, ep) result(d)
    real(dp), intent(in) :: stress(:, :), strain(:, :), ep(:, :)
    type(dissipation_t) :: d
    real(dp) :: smid(6), dep(6), di, np, ne
    integer :: i
    d%least_rate = huge(1.0_dp)
    do i = 2, size(stress, 1)
      smid = 0.5_dp*(stress(i - 1, :) + stress(i, :))
      dep = ep(:, i) - ep(:, i - 1)
      di = dot_product(smid, dep)
      d%dissipation = d%dissipation + di
      d%work = d%work + dot_product(smid, strain(i, :) - strain(i - 1, :))
      np = tensor_norm(dep)
      ne = tensor_norm(strain(i, :) - strain(i - 1, :))
      if (np <= plastic_share*ne .or. np == 0.0_dp) cycle
      d%plastic = d%plastic + 1
      if (di < 0.0_dp) d%negative = d%negative + 1
      d%least_rate = min(d%least_rate, di/np)
    end do
    if (d%plastic == 0) d%least_rate = 0.0_dp
  end function path_dissipation

  !> ||e|| of a strain in Voigt form with engineering shears.
  pure real(dp) function tensor_norm(e)
    real(dp), intent(in) :: e(6)
    tensor_norm = sqrt(sum(e(1:3)**2) + 0.5_dp*sum(e(4:6)**2))
  end function tensor_norm

  !> The summary keys <lab>.path.plastic_dissipation, .load_work,
  !> .dissipation_to_work, .plastic_increments, .negative_dissipation_increments
  !> and .least_dissipation_rate of path_dissipation's sums.
  subroutine add_dissipation(summary, lab, stress, strain, ep)
    type(summary_t), intent(inout) :: summary
    character(len=*), intent(in) :: lab
    real(dp), intent(in) :: stress(:, :), strain(:, :), ep(:, :)
    type(dissipation_t) :: d
    d = path_dissipation(stress, strain, ep)
    call summary%add(lab//'.path.plastic_dissipation', d%dissipation, &
                     'Pa, sum of (sigma_n + sigma_n+1)/2 . d eps^p; the second law asks >= 0')
    call summary%add(lab//'.path.load_work', d%work, 'Pa, sum of (sigma_n + sigma_n+1)/2 . d eps')
    if (d%work /= 0.0_dp) then
      call summary%add(lab//'.path.dissipation_to_work', d%dissipation/d%work)
    else
      call summary%not_applicable(lab//'.path.dissipation_to_work', 'the load does no work')
    end if
    call summary%add(lab//'.path.plastic_increments', d%plastic)
    call summary%add(lab//'.path.negative_dissipation_increments', d%negative, &
                     'plastic increments with (sigma_n + sigma_n+1)/2 . d eps^p < 0')
    if (d%plastic > 0) then
      call summary%add(lab//'.path.least_dissipation_rate', d%least_rate, &
                       'Pa, min over plastic increments of their dissipation / ||d eps^p||')
    else
      call summary%not_applicable(lab//'.path.least_dissipation_rate', 'the path is elastic')
    end if
  end subroutine add_dissipation

end module wellposed_point_dissipation
