!> What Algorithm 1 (the dissertation's eq. 4.46-4.50) knows of a scene's
!> materials, taken from the deck alone: the &nonlocal keys L and h_zeta,
!> defaulting to the named keys of our &material (PROPS 12-13 of the UMAT
!> contract, docs/guide/umat.md). Algorithm 1 runs when a material of ours has
!> h_zeta /= 0 or a material declares nonlocal_contract = .true. (the UMAT
!> reads STATEV 3 and writes STATEV 2); the latter's L can come only from
!> &nonlocal. The contraction bounds of eq. 4.43 and 4.45 are the closed
!> forms of our model's named keys; for a user's UMAT they are not known.
module wellposed_mpm_nonlocal_deck
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text
  use wellposed_deck, only: is_set, check_finite
  use wellposed_umat_layout, only: prop_h_zeta, prop_length
  use wellposed_mpm_materials, only: mpm_materials_t, occurrence
  use wellposed_mpm_nonlocal_settings, only: nonlocal_settings_t, ours_bounds
  implicit none
  private
  public :: resolve_nonlocal

contains

  !> Fill set%active, set%length, set%h_zeta and the bounds from the deck's
  !> &nonlocal `length` and `h_zeta` (the deck's unset value when not given)
  !> and the materials `mats` of deck `path`. A value given in both &nonlocal
  !> and our &material must agree; errors name both.
  subroutine resolve_nonlocal(path, mats, length, h_zeta, set, err)
    character(len=*), intent(in) :: path
    type(mpm_materials_t), intent(in) :: mats
    real(dp), intent(in) :: length, h_zeta
    type(nonlocal_settings_t), intent(inout) :: set
    type(error_t), allocatable, intent(out) :: err
    integer :: k, first
    real(dp) :: mat_l, mat_hz

    if (is_set(length)) then
      call check_finite(path, 'nonlocal', 'L', length, err); if (allocated(err)) return
      if (.not. length > 0.0_dp) then
        call new_error(err, status_invalid, 'L', path//': &nonlocal: L = '// &
          real_text(length)//' m must be > 0 (the nonlocal length of eq. 2.15)'); return
      end if
    end if
    if (is_set(h_zeta)) then
      call check_finite(path, 'nonlocal', 'h_zeta', h_zeta, err); if (allocated(err)) return
    end if
    set%active = .false.
    set%length = merge(length, 0.0_dp, is_set(length))
    set%h_zeta = merge(h_zeta, 0.0_dp, is_set(h_zeta))
    set%bound_43 = -1.0_dp
    set%bound_45 = -1.0_dp
    first = 0
    do k = 1, mats%n
      if (.not. mats%ours(k)) cycle
      mat_hz = mats%props(prop_h_zeta, k)
      mat_l = mats%props(prop_length, k)
      if (is_set(h_zeta) .and. mat_hz /= h_zeta) then
        call conflict('h_zeta', h_zeta, mat_hz, k, 'Pa'); return
      end if
      if (mat_hz == 0.0_dp) cycle     ! a local material of ours: L is not used
      if (is_set(length) .and. mat_l /= length) then
        call conflict('L', length, mat_l, k, 'm'); return
      end if
      if (first == 0) then
        first = k
        set%length = mat_l
        set%h_zeta = mat_hz
        call ours_bounds(mats%props(:, k), set%bound_43, set%bound_45)
      else if (mat_l /= set%length) then
        call new_error(err, status_invalid, 'L', occurrence(mats, k)//': L = '// &
          real_text(mat_l)//' m differs from L = '//real_text(set%length)//' m of '// &
          occurrence(mats, first)//': Algorithm 1 averages over one nonlocal length')
        return
      end if
      set%active = .true.
    end do
    do k = 1, mats%n
      if (mats%ours(k) .or. .not. mats%contract(k)) cycle
      if (.not. is_set(length)) then
        call new_error(err, status_invalid, 'L', occurrence(mats, k)//': nonlocal_contract'// &
          ' = .true. (the UMAT writes STATEV 2 and reads the average from STATEV 3) needs '// &
          'the nonlocal length: give &nonlocal L (m)')
        return
      end if
      set%active = .true.
    end do

  contains

    subroutine conflict(key, given, mat, k, unit)
      character(len=*), intent(in) :: key, unit
      real(dp), intent(in) :: given, mat
      integer, intent(in) :: k
      call new_error(err, status_invalid, key, path//': &nonlocal: '//key//' = '// &
        real_text(given)//' '//unit//' conflicts with '//key//' = '//real_text(mat)//' '// &
        unit//' of '//occurrence(mats, k)//': give it in one place, or the same value in both')
    end subroutine conflict

  end subroutine resolve_nonlocal

end module wellposed_mpm_nonlocal_deck
