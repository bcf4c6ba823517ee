!> The checked write layer of every program: a text output written under a
!> temporary name, every write, flush and close checked, renamed into place
!> only when complete (`out_file_t`); the one way a program ends on an error
!> (`end_run`: message flushed to standard error whatever it is connected to,
!> exit status 1); and, in a build with WELLPOSED_WRITE_FAULTS, a write made
!> to fail on purpose: WELLPOSED_FAIL_WRITE=<text> fails every output whose
!> file name contains <text> (the full-disk tests, docs/guide/outputs.md).
module wellposed_checked_io
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: rename_path, remove_file, process_id, int_text
  use wellposed_build_info, only: write_faults_enabled
  implicit none
  private
  public :: out_file_t, write_fault, end_run, say_error

  !> A text file being written: open, put/note ..., close.
  type :: out_file_t
    integer :: unit = -1
    character(len=:), allocatable :: path, tmp
    character(len=:), allocatable :: failure  !< the first failed write, if any
  contains
    procedure :: open => out_open
    !> put(line): one line of text; put_bytes(text): `text` as it is (a file
    !> opened with stream = .true.).
    procedure :: put => out_put
    procedure :: put_bytes => out_put_bytes
    !> note(ios, msg): the outcome of the caller's own `write (f%unit, ...)`.
    procedure :: note => out_note
    procedure :: close => out_close
  end type out_file_t

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
      'no space left on device (injected by WELLPOSED_FAIL_WRITE='//value(1:n)//')'
  end function write_fault

  !> Start writing `path` (under `<path>.tmp.<pid>`): formatted lines, or
  !> bytes when `stream` is true.
  subroutine out_open(self, path, err, stream)
    class(out_file_t), intent(inout) :: self
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: stream
    integer :: ios
    character(len=512) :: msg
    logical :: raw
    raw = .false.
    if (present(stream)) raw = stream
    self%path = path
    self%tmp = path//'.tmp.'//int_text(process_id())
    if (allocated(self%failure)) deallocate (self%failure)
    if (raw) then
      open (newunit=self%unit, file=self%tmp, access='stream', form='unformatted', &
            status='replace', action='write', iostat=ios, iomsg=msg)
    else
      open (newunit=self%unit, file=self%tmp, status='replace', action='write', &
            iostat=ios, iomsg=msg)
    end if
    if (ios /= 0) then
      self%unit = -1
      call new_error(err, status_invalid, path, 'cannot write "'//path//'": '//trim(msg))
    end if
  end subroutine out_open

  subroutine out_put(self, line)
    class(out_file_t), intent(inout) :: self
    character(len=*), intent(in) :: line
    integer :: ios
    character(len=512) :: msg
    if (allocated(self%failure) .or. self%unit == -1) return
    write (self%unit, '(a)', iostat=ios, iomsg=msg) line
    call self%note(ios, msg)
  end subroutine out_put

  subroutine out_put_bytes(self, text)
    class(out_file_t), intent(inout) :: self
    character(len=*), intent(in) :: text
    integer :: ios
    character(len=512) :: msg
    if (allocated(self%failure) .or. self%unit == -1) return
    write (self%unit, iostat=ios, iomsg=msg) text
    call self%note(ios, msg)
  end subroutine out_put_bytes

  subroutine out_note(self, ios, msg)
    class(out_file_t), intent(inout) :: self
    integer, intent(in) :: ios
    character(len=*), intent(in) :: msg
    if (ios /= 0 .and. .not. allocated(self%failure)) self%failure = trim(msg)
  end subroutine out_note

  !> Flush and close the file and rename it to its name; a failed write,
  !> flush or close (a full disk shows at any of them) removes the temporary
  !> file and `err` names the file and the reason.
  subroutine out_close(self, err)
    class(out_file_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer :: ios
    character(len=512) :: msg
    logical :: removed
    if (self%unit == -1) then
      call new_error(err, status_invalid, 'output', 'close of an output that is not open')
      return
    end if
    if (.not. allocated(self%failure)) then
      flush (self%unit, iostat=ios, iomsg=msg)
      call self%note(ios, msg)
    end if
    close (self%unit, iostat=ios, iomsg=msg)
    call self%note(ios, msg)
    self%unit = -1
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
