!> Numbers as short text for messages: the one place that formats them, so
!> every error names values the same way.
module wellposed_text
  use wellposed_kinds, only: dp
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

  !> A real in ES format (6 significant digits), NaN and Inf spelled out.
  pure function real_text(x) result(text)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    write (buffer, '(es12.5)') x
    text = trim(adjustl(buffer))
  end function real_text

end module wellposed_text
