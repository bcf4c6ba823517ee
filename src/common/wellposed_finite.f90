!> Finiteness test for hot paths. ieee_arithmetic's ieee_is_finite makes
!> gfortran save and restore the floating-point environment around every
!> procedure that uses the module (hundreds of cycles per UMAT call); an
!> ordered comparison is false for NaN and for +-Inf alike and costs nothing.
module wellposed_finite
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: is_finite, all_finite

contains

  !> True for a finite real (neither NaN nor +-Inf).
  elemental function is_finite(x) result(finite)
    real(dp), intent(in) :: x
    logical :: finite
    finite = abs(x) <= huge(x)
  end function is_finite

  !> True when every entry of `x` is finite (one call per array on hot paths).
  pure function all_finite(x) result(finite)
    real(dp), intent(in) :: x(:)
    logical :: finite
    integer :: i
    finite = .false.
    do i = 1, size(x)
      if (.not. abs(x(i)) <= huge(x(i))) return
    end do
    finite = .true.
  end function all_finite

end module wellposed_finite
