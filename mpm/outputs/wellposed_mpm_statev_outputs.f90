!> The plate's outputs that read our model's STATEV slots (2 dlambda,
!> 4 zeta, 5-10 the plastic strain: docs/guide/umat.md), left out where the
!> scene's NSTATV has no such slot (a user's UMAT with a shorter STATEV):
!> snapshot fields are dropped, summary figures are
!> `not_applicable  # the UMAT's STATEV has no <what> slot (NSTATV = N)`.
module wellposed_mpm_statev_outputs
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use wellposed_kinds, only: dp
  use wellposed_text, only: int_text, real_text
  use wellposed_summary, only: summary_t
  implicit none
  private
  public :: slot_plastic_strain, no_slot_why, plate_field_names, plate_field_widths, &
            plate_field_rows, add_plate_band

  integer, parameter :: slot_plastic_strain = 10   !< last STATEV slot ||eps^p|| reads
  !> the plate's snapshot fields, their widths and the STATEV slot each needs
  character(len=14), parameter :: names(7) = [character(len=14) :: 'xy', 'plastic_strain', &
    'sigma_xx', 'sigma_yy', 'sigma_xy', 'dlambda', 'zeta']
  integer, parameter :: widths(7) = [2, 1, 1, 1, 1, 1, 1]
  integer, parameter :: needs(7) = [0, slot_plastic_strain, 0, 0, 0, 2, 4]

contains

  !> Why a figure is not applicable: the STATEV has no `what` slot.
  pure function no_slot_why(what, nstatv) result(s)
    character(len=*), intent(in) :: what
    integer, intent(in) :: nstatv
    character(len=:), allocatable :: s
    s = 'the UMAT''s STATEV has no '//what//' slot (NSTATV = '//int_text(nstatv)//')'
  end function no_slot_why

  !> The plate's snapshot fields a STATEV of nstatv entries gives.
  pure function plate_field_names(nstatv) result(s)
    integer, intent(in) :: nstatv
    character(len=14), allocatable :: s(:)
    s = pack(names, needs <= nstatv)
  end function plate_field_names

  pure function plate_field_widths(nstatv) result(w)
    integer, intent(in) :: nstatv
    integer, allocatable :: w(:)
    w = pack(widths, needs <= nstatv)
  end function plate_field_widths

  !> Rows of the full field table (x, y, then one row per other field) kept.
  pure function plate_field_rows(nstatv) result(r)
    integer, intent(in) :: nstatv
    integer, allocatable :: r(:)
    integer :: i
    r = pack([(i, i=1, 8)], [needs(1), needs] <= nstatv)
  end function plate_field_rows

  !> The case's plastic strain and band-line figures under `tag.` (rank 0),
  !> not applicable without the plastic strain slots.
  subroutine add_plate_band(sm, tag, nstatv, epmax, fwhm, yline, band_t, peak_x, peak_v)
    type(summary_t), intent(inout) :: sm
    character(len=*), intent(in) :: tag
    integer, intent(in) :: nstatv
    real(dp), intent(in) :: epmax, fwhm, yline, band_t, peak_x, peak_v
    character(len=24), parameter :: keys(5) = [character(len=24) :: 'max_plastic_strain', &
      'band_fwhm', 'band_peak_at', 'band_time', 'band_peak_plastic_strain']
    integer :: i
    if (nstatv < slot_plastic_strain) then
      do i = 1, size(keys)
        call sm%not_applicable(tag//'.'//trim(keys(i)), no_slot_why('plastic strain', nstatv))
      end do
      return
    end if
    call sm%add(tag//'.max_plastic_strain', epmax)
    call sm%add(tag//'.band_fwhm', merge(fwhm, ieee_value(fwhm, ieee_quiet_nan), fwhm > 0.0_dp), &
      'm, along the band line at '//real_text(yline)//' m', 'no particle within half a '// &
      'particle spacing of the band line had plastic strain at t = '//real_text(band_t)//' s')
    call sm%add(tag//'.band_peak_at', peak_x, 'm, along the band line')
    call sm%add(tag//'.band_time', band_t, 's, when the band width was measured')
    call sm%add(tag//'.band_peak_plastic_strain', peak_v)
  end subroutine add_plate_band
end module wellposed_mpm_statev_outputs
