!> summary.txt of a run: one `key = value` line per figure that matters,
!> optionally followed by `  # comment`. Reals are written with 16
!> significant digits (ES format), logicals as true/false, integers plain.
!> Regression tests read these lines back and compare with tolerances.
!> A summary never holds NaN or Inf: a figure that does not apply is
!> written `key = not_applicable  # why` (`add` with `why`, or
!> `not_applicable`), and a non-finite figure added without a reason makes
!> `write` fail naming it, so the run fails rather than look finished.
module wellposed_summary
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: int_text
  use wellposed_checked_io, only: out_file_t
  implicit none
  private
  public :: summary_t

  type :: line_t
    character(len=:), allocatable :: text
  end type line_t

  !> The lines of a summary, in the order added.
  type :: summary_t
    type(line_t), allocatable :: lines(:)
    integer :: n = 0
    !> The first figure added as NaN or Inf without a reason ('' if none).
    character(len=:), allocatable :: nonfinite
  contains
    procedure, private :: add_real, add_int, add_logical, add_char
    !> add(key, value[, comment]) for real(dp), integer, logical, character;
    !> for real(dp) also add(key, value, comment, why): `why` is said when
    !> the value is not finite.
    generic :: add => add_real, add_int, add_logical, add_char
    !> not_applicable(key, why): `key = not_applicable  # why`.
    procedure :: not_applicable => add_not_applicable
    procedure :: write => summary_write
  end type summary_t

contains

  subroutine push(self, key, value, comment)
    class(summary_t), intent(inout) :: self
    character(len=*), intent(in) :: key, value
    character(len=*), intent(in), optional :: comment
    type(line_t), allocatable :: grown(:)
    character(len=:), allocatable :: line
    if (.not. allocated(self%lines)) allocate (self%lines(16))
    if (self%n == size(self%lines)) then
      allocate (grown(2*self%n))
      grown(1:self%n) = self%lines(1:self%n)
      call move_alloc(grown, self%lines)
    end if
    line = trim(key)//' = '//value
    if (present(comment)) then
      if (len_trim(comment) > 0) line = line//'  # '//trim(comment)
    end if
    self%n = self%n + 1
    self%lines(self%n)%text = line
  end subroutine push

  subroutine add_real(self, key, value, comment, why)
    class(summary_t), intent(inout) :: self
    character(len=*), intent(in) :: key
    real(dp), intent(in) :: value
    character(len=*), intent(in), optional :: comment, why
    character(len=32) :: buffer
    if (.not. ieee_is_finite(value)) then
      if (present(why)) then
        call self%not_applicable(key, why)
        return
      end if
      if (.not. allocated(self%nonfinite)) self%nonfinite = trim(key)
    end if
    write (buffer, '(es23.15e3)') value
    call push(self, key, trim(adjustl(buffer)), comment)
  end subroutine add_real

  subroutine add_int(self, key, value, comment)
    class(summary_t), intent(inout) :: self
    character(len=*), intent(in) :: key
    integer, intent(in) :: value
    character(len=*), intent(in), optional :: comment
    call push(self, key, int_text(value), comment)
  end subroutine add_int

  subroutine add_logical(self, key, value, comment)
    class(summary_t), intent(inout) :: self
    character(len=*), intent(in) :: key
    logical, intent(in) :: value
    character(len=*), intent(in), optional :: comment
    if (value) then
      call push(self, key, 'true', comment)
    else
      call push(self, key, 'false', comment)
    end if
  end subroutine add_logical

  subroutine add_char(self, key, value, comment)
    class(summary_t), intent(inout) :: self
    character(len=*), intent(in) :: key, value
    character(len=*), intent(in), optional :: comment
    call push(self, key, trim(value), comment)
  end subroutine add_char

  !> `key = not_applicable  # why`: a figure this run has no value for.
  subroutine add_not_applicable(self, key, why)
    class(summary_t), intent(inout) :: self
    character(len=*), intent(in) :: key, why
    call push(self, key, 'not_applicable', why)
  end subroutine add_not_applicable

  !> Write the lines to `path` (wellposed_checked_io: a temporary name, every
  !> write checked, then rename); refused, writing nothing, when a figure is
  !> NaN or Inf without a reason.
  subroutine summary_write(self, path, err)
    class(summary_t), intent(in) :: self
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    type(out_file_t) :: out
    integer :: i
    if (allocated(self%nonfinite)) then
      call new_error(err, status_invalid, self%nonfinite, 'summary figure '// &
        self%nonfinite//' is not a finite number, and no reason was given why it does not '// &
        'apply: the run is not written as finished')
      return
    end if
    call out%open(path, err)
    if (allocated(err)) return
    do i = 1, self%n
      call out%put(self%lines(i)%text)
    end do
    call out%close(err)
  end subroutine summary_write

end module wellposed_summary
