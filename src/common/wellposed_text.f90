!> Numbers as short text for messages: the one place that formats them, so
!> every error names values the same way.
module wellposed_text
  use wellposed_kinds, only: dp
  use wellposed_finite, only: is_finite
  ! No IEEE intrinsic module (bit tests instead): a procedure that uses a
  ! module depending on one, such as the UMAT's entry, saves and restores
  ! the floating-point environment on every call.
  implicit none
  private
  public :: int_text, real_text

contains

  !> An integer without padding.
  pure function int_text(i) result(text)
    integer, intent(in) :: i
    character(len=:), allocatable :: text
    character(len=16) :: buffer
    write (buffer, '(i0)') i
    text = trim(buffer)
  end function int_text

  !> A real with up to 8 significant digits and the mantissa's trailing
  !> zeros dropped ("-1.0E+10", "-3.6769553E+10"), so round values read
  !> cleanly and a value just past a bound does not print like the bound;
  !> NaN and Infinity spelled out.
  pure function real_text(x) result(text)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    integer :: e, last
    logical :: wide
    ! three exponent digits where two cannot hold it (ES with E2 writes
    ! asterisks for 1e-300 or huge()); nested: no ordered comparison of a NaN
    wide = .false.
    if (is_finite(x)) then
      if (x /= 0.0_dp) wide = abs(x) >= 9.99999995e99_dp .or. abs(x) < 1.0e-99_dp
    end if
    if (wide) then
      write (buffer, '(es16.7e3)') x
    else
      write (buffer, '(es15.7e2)') x
    end if
    text = trim(adjustl(buffer))
    e = index(text, 'E')
    if (e == 0) return
    last = e - 1
    do while (text(last:last) == '0' .and. text(last - 1:last - 1) /= '.')
      last = last - 1
    end do
    text = text(1:last)//text(e:)
  end function real_text

end module wellposed_text
