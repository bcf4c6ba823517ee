!> The benchmarks' command-line arguments: argument i as an integer or a
!> real within stated bounds, or a message naming the program, the argument
!> and what was given, on standard error, and exit status 1 before anything
!> is measured.
module bench_args
  use, intrinsic :: iso_fortran_env, only: error_unit, dp => real64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: int_arg, real_arg, most_args

contains

  !> At most n arguments, else the usage line and exit status 1.
  subroutine most_args(prog, n, usage)
    character(len=*), intent(in) :: prog, usage
    integer, intent(in) :: n
    if (command_argument_count() <= n) return
    write (error_unit, '(a)') prog//': too many arguments; usage: '//usage
    stop 1, quiet=.true.
  end subroutine most_args

  !> Argument i read as an integer in [lo, hi]; prog and what name it.
  integer function int_arg(prog, i, what, lo, hi) result(v)
    character(len=*), intent(in) :: prog, what
    integer, intent(in) :: i, lo, hi
    character(len=256) :: arg, range
    integer :: ios
    call get_command_argument(i, arg)
    read (arg, *, iostat=ios) v
    if (ios == 0 .and. verify(trim(arg), '+-0123456789') /= 0) ios = 1
    if (ios /= 0 .or. v < lo .or. v > hi) then
      write (range, '(a,i0,a,i0)') 'an integer from ', lo, ' to ', hi
      call refuse(prog, what, trim(range), arg)
    end if
  end function int_arg

  !> Argument i read as a finite real in [lo, hi].
  real(dp) function real_arg(prog, i, what, lo, hi) result(v)
    character(len=*), intent(in) :: prog, what
    integer, intent(in) :: i
    real(dp), intent(in) :: lo, hi
    character(len=256) :: arg, range
    integer :: ios
    logical :: ok
    call get_command_argument(i, arg)
    read (arg, *, iostat=ios) v
    ! nested: a NaN or infinity is refused before any ordered comparison
    ! (which traps on a NaN in a Debug build, -ffpe-trap=invalid)
    ok = ios == 0
    if (ok) ok = ieee_is_finite(v)
    if (ok) ok = v >= lo .and. v <= hi
    if (.not. ok) then
      range = 'a number from '//num_text(lo)//' to '//num_text(hi)
      call refuse(prog, what, trim(range), arg)
    end if
  end function real_arg

  !> x in plain decimals, no trailing zeros (0.01, 5): bounds of a message.
  pure function num_text(x) result(t)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: t
    character(len=40) :: buf
    integer :: k
    write (buf, '(f0.6)') x
    k = len_trim(buf)
    do while (buf(k:k) == '0')
      k = k - 1
    end do
    if (buf(k:k) == '.') k = k - 1
    t = buf(1:k)
    if (t(1:1) == '.') t = '0'//t
    if (t(1:min(2, len(t))) == '-.') t = '-0'//t(2:)
  end function num_text

  subroutine refuse(prog, what, range, arg)
    character(len=*), intent(in) :: prog, what, range, arg
    write (error_unit, '(a)') prog//': '//what//' must be '//range//', not "'//trim(arg)//'"'
    stop 1, quiet=.true.
  end subroutine refuse

end module bench_args
