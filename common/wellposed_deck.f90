!> Deck reading for the drivers: a deck is a text file of Fortran namelist
!> groups (`&group key = value, ... /`, `!` a comment). A driver defaults
!> every key (required ones to `unset`), reads the group, turns a failure
!> into a message (`namelist_error`) and validates each value
!> (`check_required`, `check_finite`, `check_range`); every message names
!> the file, the group, the key and what was expected. The text of a deck
!> (its groups, a READ's message): wellposed_deck_text, whose procedures
!> this module passes on. Decks: docs/guide/decks.md.
module wellposed_deck
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text, int_text
  use wellposed_deck_text, only: read_text_file, read_deck_text, check_deck_text, &
                                 namelist_error, has_group, lower, deck_essence, &
                                 check_group_names
  implicit none
  private
  public :: read_text_file, read_deck_text, check_deck_text, namelist_error, check_required, &
            check_finite, check_range, unset, is_set, value_text, has_group, lower, check_word, &
            deck_essence, check_group_names, unheld_stress_note

  !> Sentinel for "not given in the deck": a required real key is set to
  !> `unset` before the READ and tested with `is_set` after it.
  real(dp), parameter :: unset = -huge(1.0_dp)

  !> Validate that a real value is finite (scalar or array).
  interface check_finite
    module procedure check_finite_scalar, check_finite_array
  end interface check_finite

  !> Validate lo <= value <= hi (reals or integers).
  interface check_range
    module procedure check_range_real, check_range_int
  end interface check_range

contains

  !> True when a real key was given (differs from the sentinel `unset`).
  elemental logical function is_set(x)
    real(dp), intent(in) :: x
    is_set = x /= unset
  end function is_set


  !> Error unless `is_set`: the required key `key` of group `group` is missing.
  subroutine check_required(path, group, key, is_set, err)
    character(len=*), intent(in) :: path, group, key
    logical, intent(in) :: is_set
    type(error_t), allocatable, intent(out) :: err
    if (.not. is_set) then
      call new_error(err, status_invalid, key, path//': &'//group//': key '//key// &
        ' is required but not given')
    end if
  end subroutine check_required

  !> Error unless `value` is a finite number (not NaN, not Inf).
  subroutine check_finite_scalar(path, group, key, value, err)
    character(len=*), intent(in) :: path, group, key
    real(dp), intent(in) :: value
    type(error_t), allocatable, intent(out) :: err
    if (.not. ieee_is_finite(value)) then
      call new_error(err, status_invalid, key, path//': &'//group//': '//key//' = '// &
        value_text(value)//' is not a finite number')
    end if
  end subroutine check_finite_scalar

  !> Error unless every element of `value` is finite; names the first bad one.
  subroutine check_finite_array(path, group, key, value, err)
    character(len=*), intent(in) :: path, group, key
    real(dp), intent(in) :: value(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: i
    character(len=16) :: idx
    do i = 1, size(value)
      if (.not. ieee_is_finite(value(i))) then
        write (idx, '(i0)') i
        call new_error(err, status_invalid, key, path//': &'//group//': '//key//'('// &
          trim(idx)//') = '//value_text(value(i))//' is not a finite number')
        return
      end if
    end do
  end subroutine check_finite_array

  !> Error unless lo <= value <= hi (and value is finite).
  subroutine check_range_real(path, group, key, value, lo, hi, err)
    character(len=*), intent(in) :: path, group, key
    real(dp), intent(in) :: value, lo, hi
    type(error_t), allocatable, intent(out) :: err
    call check_finite_scalar(path, group, key, value, err)
    if (allocated(err)) return
    if (value < lo .or. value > hi) then
      call new_error(err, status_invalid, key, path//': &'//group//': '//key//' = '// &
        value_text(value)//' is out of range: valid is '//range_text(lo, hi))
    end if
  end subroutine check_range_real

  !> "[lo, hi]", or "> 0", ">= lo", "<= hi" where a bound is tiny or huge
  !> (a bound no deck means to state).
  pure function range_text(lo, hi) result(text)
    real(dp), intent(in) :: lo, hi
    character(len=:), allocatable :: text
    if (hi >= huge(1.0_dp)) then
      if (lo == tiny(1.0_dp)) then
        text = '> 0'
      else
        text = '>= '//value_text(lo)
      end if
    else if (lo <= -huge(1.0_dp)) then
      text = '<= '//value_text(hi)
    else
      text = '['//value_text(lo)//', '//value_text(hi)//']'
    end if
  end function range_text

  !> Error unless lo <= value <= hi.
  subroutine check_range_int(path, group, key, value, lo, hi, err)
    character(len=*), intent(in) :: path, group, key
    integer, intent(in) :: value, lo, hi
    type(error_t), allocatable, intent(out) :: err
    character(len=24) :: v, l, h
    if (value < lo .or. value > hi) then
      write (v, '(i0)') value
      write (l, '(i0)') lo
      write (h, '(i0)') hi
      call new_error(err, status_invalid, key, path//': &'//group//': '//key//' = '// &
        trim(v)//' is out of range: valid is ['//trim(l)//', '//trim(h)//']')
    end if
  end subroutine check_range_int

  !> A deck value as the messages show it: plain decimals from 0.1 to 1e6,
  !> else real_text's short ES form; NaN, Inf and `unset` spelled out.
  pure function value_text(x) result(text)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    if (x == unset) then
      text = '(not set)'
      return
    end if
    if (.not. ieee_is_finite(x)) then
      ! No ordered comparison of a NaN: it raises "invalid" (a trap in Debug
      ! builds, which run with -ffpe-trap=invalid).
      text = real_text(x)
      return
    end if
    ! plain decimals from 0.1 (g0 writes smaller ones as 0.1...E-1)
    if (abs(x) >= 0.1_dp .and. abs(x) < 1.0e6_dp .or. x == 0.0_dp) then
      write (buffer, '(g0)') x
      text = trim(adjustl(buffer))
      ! trim trailing zeros of g0's long mantissa
      if (index(text, '.') > 0 .and. index(text, 'E') == 0) then
        do while (text(len(text):len(text)) == '0')
          text = text(1:len(text) - 1)
        end do
        if (text(len(text):len(text)) == '.') text = text//'0'
      end if
    else
      text = real_text(x)
    end if
  end function value_text

  !> `id` is the index of the word `value` (case-insensitive, trailing
  !> blanks ignored) in `names` (lower case); when it is none of them, id = 0
  !> and `err` names the file, the group, the key and the valid words.
  subroutine check_word(path, group, key, value, names, id, err)
    character(len=*), intent(in) :: path, group, key, value, names(:)
    integer, intent(out) :: id
    type(error_t), allocatable, intent(out) :: err
    integer :: j
    character(len=:), allocatable :: valid
    do id = 1, size(names)
      if (lower(trim(value)) == trim(names(id))) return
    end do
    id = 0
    valid = ''
    do j = 1, size(names)
      valid = valid//merge(', ', '  ', j > 1)//"'"//trim(names(j))//"'"
    end do
    call new_error(err, status_invalid, key, path//': &'//group//': '//key//" = '"// &
      trim(value)//"' is not one of"//valid(2:))
  end subroutine check_word


  !> Why a UMAT asks for a smaller step on a zero increment from `stress`:
  !> the largest component and our UMAT's stress limit (docs/guide/umat.md).
  pure function unheld_stress_note(stress) result(text)
    real(dp), intent(in) :: stress(:)
    character(len=:), allocatable :: text
    text = ': it cannot hold that stress (largest |component| = '// &
      real_text(maxval(abs(stress)))//' Pa; our UMAT takes stresses below 2^448 min(1, K, '// &
      'G), docs/guide/umat.md)'
  end function unheld_stress_note

end module wellposed_deck
