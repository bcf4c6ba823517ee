!> The checked write layer of every program: a text output written under a
!> temporary name through C stdio (gfortran's own writes report no error on
!> a full disk), every write, flush and close checked, renamed into place
!> only when complete (`out_file_t`); the one way a program ends on an error
!> (`end_run`: message flushed to standard error, exit status 1); and, in a
!> build with WELLPOSED_WRITE_FAULTS, WELLPOSED_FAIL_WRITE=<text> failing
!> every output whose file name contains <text> (docs/guide/outputs.md).
module wellposed_checked_io
  use, intrinsic :: iso_fortran_env, only: error_unit
  use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_char, c_int, &
                                         c_size_t, c_null_char, c_f_pointer
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: rename_path, remove_file, process_id, int_text
  use wellposed_build_info, only: write_faults_enabled
  implicit none
  private
  public :: out_file_t, write_fault, end_run, say_error

  !> Bytes kept before they are handed to fwrite.
  integer, parameter :: chunk = 65536

  !> A text file being written: open, put ... , close.
  type :: out_file_t
    type(c_ptr) :: file = c_null_ptr
    character(len=:), allocatable :: path, tmp
    character(len=:), allocatable :: failure  !< the first failed write, if any
    character(len=:), allocatable :: buf
    integer :: nbuf = 0
  contains
    procedure :: open => out_open
    !> put(line): one line of text (a newline added); put_bytes(text): as it is.
    procedure :: put => out_put
    procedure :: put_bytes => out_put_bytes
    procedure :: close => out_close
  end type out_file_t

  interface
    function c_fopen(path, mode) bind(C, name='fopen') result(f)
      import :: c_ptr, c_char
      character(kind=c_char), intent(in) :: path(*), mode(*)
      type(c_ptr) :: f
    end function c_fopen
    function c_fwrite(buf, size, n, f) bind(C, name='fwrite') result(done)
      import :: c_ptr, c_char, c_size_t
      character(kind=c_char), intent(in) :: buf(*)
      integer(c_size_t), value :: size, n
      type(c_ptr), value :: f
      integer(c_size_t) :: done
    end function c_fwrite
    function c_fflush(f) bind(C, name='fflush') result(rc)
      import :: c_ptr, c_int
      type(c_ptr), value :: f
      integer(c_int) :: rc
    end function c_fflush
    function c_fclose(f) bind(C, name='fclose') result(rc)
      import :: c_ptr, c_int
      type(c_ptr), value :: f
      integer(c_int) :: rc
    end function c_fclose
    function c_errno_location() bind(C, name='__errno_location') result(p)
      import :: c_ptr
      type(c_ptr) :: p
    end function c_errno_location
    function c_strerror(errnum) bind(C, name='strerror') result(p)
      import :: c_ptr, c_int
      integer(c_int), value :: errnum
      type(c_ptr) :: p
    end function c_strerror
  end interface

contains

  !> The injected failure for `path` ('' when none): the reason a write of
  !> that file fails on purpose in a build with WELLPOSED_WRITE_FAULTS.
  function write_fault(path) result(reason)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: reason
    character(len=256) :: value
    integer :: n, stat, slash
    reason = ''
    if (.not. write_faults_enabled) return
    call get_environment_variable('WELLPOSED_FAIL_WRITE', value, n, stat)
    if (stat /= 0 .or. n == 0) return
    slash = index(path, '/', back=.true.)
    if (index(path(slash + 1:), value(1:n)) > 0) reason = &
      'No space left on device (injected by WELLPOSED_FAIL_WRITE='//value(1:n)//')'
  end function write_fault

  !> The C library's text for the last failed call (strerror(errno)).
  function os_reason() result(text)
    character(len=:), allocatable :: text
    integer(c_int), pointer :: errno
    character(kind=c_char), pointer :: chars(:)
    integer :: n
    call c_f_pointer(c_errno_location(), errno)
    call c_f_pointer(c_strerror(errno), chars, [256])
    n = 0
    do while (n < 256)
      if (chars(n + 1) == c_null_char) exit
      n = n + 1
    end do
    allocate (character(len=n) :: text)
    text = transfer(chars(1:n), text)
  end function os_reason

  !> Start writing `path` (under `<path>.tmp.<pid>`).
  subroutine out_open(self, path, err)
    class(out_file_t), intent(inout) :: self
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    self%path = path
    self%tmp = path//'.tmp.'//int_text(process_id())
    if (allocated(self%failure)) deallocate (self%failure)
    if (.not. allocated(self%buf)) allocate (character(len=chunk) :: self%buf)
    self%nbuf = 0
    self%file = c_fopen(self%tmp//c_null_char, 'wb'//c_null_char)
    if (.not. c_associated(self%file)) call new_error(err, status_invalid, path, &
      'cannot write "'//path//'": '//os_reason())
  end subroutine out_open

  !> Hand the kept bytes to fwrite; a short count is the failure.
  subroutine drain(self)
    class(out_file_t), intent(inout) :: self
    integer(c_size_t) :: done
    if (self%nbuf == 0 .or. allocated(self%failure)) return
    done = c_fwrite(self%buf(1:self%nbuf), 1_c_size_t, int(self%nbuf, c_size_t), self%file)
    if (done /= int(self%nbuf, c_size_t)) self%failure = os_reason()
    self%nbuf = 0
  end subroutine drain

  subroutine out_put_bytes(self, text)
    class(out_file_t), intent(inout) :: self
    character(len=*), intent(in) :: text
    integer :: at, n
    if (allocated(self%failure) .or. .not. c_associated(self%file)) return
    at = 1
    do while (at <= len(text))
      if (self%nbuf == chunk) call drain(self)
      n = min(chunk - self%nbuf, len(text) - at + 1)
      self%buf(self%nbuf + 1:self%nbuf + n) = text(at:at + n - 1)
      self%nbuf = self%nbuf + n
      at = at + n
    end do
  end subroutine out_put_bytes

  subroutine out_put(self, line)
    class(out_file_t), intent(inout) :: self
    character(len=*), intent(in) :: line
    call self%put_bytes(line//new_line('a'))
  end subroutine out_put

  !> Flush and close the file and rename it to its name; a failed write,
  !> flush or close (a full disk shows at any of them) removes the temporary
  !> file and `err` names the file and the reason.
  subroutine out_close(self, err)
    class(out_file_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    logical :: removed
    if (.not. c_associated(self%file)) then
      call new_error(err, status_invalid, 'output', 'close of an output that is not open')
      return
    end if
    call drain(self)
    if (.not. allocated(self%failure)) then
      if (c_fflush(self%file) /= 0) self%failure = os_reason()
    end if
    if (c_fclose(self%file) /= 0 .and. .not. allocated(self%failure)) &
      self%failure = os_reason()
    self%file = c_null_ptr
    if (.not. allocated(self%failure)) then
      if (len(write_fault(self%path)) > 0) self%failure = write_fault(self%path)
    end if
    if (allocated(self%failure)) then
      removed = remove_file(self%tmp)
      call new_error(err, status_invalid, self%path, 'cannot write "'//self%path//'": '// &
        self%failure)
      return
    end if
    call rename_path(self%tmp, self%path, err)
  end subroutine out_close

  !> Write `line` to standard error and flush it, so that it reaches the
  !> user when standard error is a file or a pipe (it is buffered then).
  subroutine say_error(line)
    character(len=*), intent(in) :: line
    integer :: ios
    write (error_unit, '(a)', iostat=ios) line
    flush (error_unit, iostat=ios)
  end subroutine say_error

  !> End the program on an error: `<program>: error: <message>`, and where
  !> the unfinished output is when `partial` is given; exit status 1.
  subroutine end_run(program, message, partial)
    character(len=*), intent(in) :: program, message
    character(len=*), intent(in), optional :: partial
    call say_error(program//': error: '//message)
    if (present(partial)) then
      if (len(partial) > 0) call say_error(program//': the run did not finish; its '// &
                                           'partial output is in '//partial)
    end if
    stop 1, quiet=.true.
  end subroutine end_run

end module wellposed_checked_io
