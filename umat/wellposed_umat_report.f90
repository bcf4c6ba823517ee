!> What the external UMAT says about a failed call (docs/guide/umat.md, "Status
!> codes, errors and PNEWDT"): invalid input (status -1) and non-finite input
!> (status -2, key 'non_finite') are reported on standard error once per
!> material and distinct message, not once per point; a cut-back of a local
!> iteration stays silent (the host cures it). With the environment variable
!> WELLPOSED_UMAT_ON_ERROR=stop either also ends the process (error stop 2).
!> Reached only on the failure path: no cost for a valid call.
module wellposed_umat_report
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_error, only: error_t, status_invalid
  use wellposed_text, only: int_text
  implicit none
  private
  public :: umat_report

  !> Distinct (material, status, message) keys remembered; fixed-length
  !> storage so that concurrent callers at worst print a line twice.
  integer, parameter :: max_seen = 64, key_len = 256
  character(len=key_len), save :: seen(max_seen) = ''
  integer, save :: n_seen = 0
  logical, save :: told_full = .false.
  !> WELLPOSED_UMAT_ON_ERROR, read at the first report: -1 unread, 0 no, 1 stop.
  integer, save :: stop_mode = -1

contains

  !> Report a failed UMAT call of material `cmname` at element `noel`,
  !> point `npt`, then stop when the user asked for a hard stop.
  subroutine umat_report(err, cmname, noel, npt)
    type(error_t), intent(in) :: err
    character(len=*), intent(in) :: cmname
    integer, intent(in) :: noel, npt
    character(len=key_len) :: key
    integer :: i

    if (err%status /= status_invalid .and. err%key /= 'non_finite') return
    key = trim(cmname)//achar(9)//int_text(err%status)//achar(9)//err%message
    if (.not. any(seen(1:n_seen) == key)) then
      if (n_seen < max_seen) then
        write (error_unit, '(a)') 'wellposed UMAT error (material '//trim(cmname)// &
          ', element '//int_text(noel)//', point '//int_text(npt)//'): '//err%message// &
          ' [reported once for this material]'
        i = n_seen + 1
        seen(i) = key
        n_seen = i
      else if (.not. told_full) then
        told_full = .true.
        write (error_unit, '(a)') 'wellposed UMAT: more than '//int_text(max_seen)// &
          ' distinct errors; further ones are not reported'
      end if
    end if
    if (stop_wanted()) then
      write (error_unit, '(a)') 'wellposed UMAT: stopping the analysis '// &
        '(WELLPOSED_UMAT_ON_ERROR=stop)'
      error stop 2
    end if
  end subroutine umat_report

  !> Whether WELLPOSED_UMAT_ON_ERROR asks for a hard stop (read once).
  logical function stop_wanted()
    character(len=16) :: value
    integer :: length, stat
    if (stop_mode < 0) then
      call get_environment_variable('WELLPOSED_UMAT_ON_ERROR', value, length, stat)
      stop_mode = 0
      if (stat == 0 .and. (value == 'stop' .or. value == 'STOP')) then
        stop_mode = 1
      else if (stat /= 1 .and. length > 0) then
        write (error_unit, '(a)') 'wellposed UMAT: WELLPOSED_UMAT_ON_ERROR = '// &
          value(1:min(length, len(value)))//' is ignored: the one value is stop'
      end if
    end if
    stop_wanted = stop_mode == 1
  end function stop_wanted

end module wellposed_umat_report
