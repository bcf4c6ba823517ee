!> Small file-system helpers for the drivers, through libc (bind(C)) where
!> libc has the call: rename(2), mkdir(2), remove(3), truncate(2), getpid(2).
!> Removing a whole folder tree has no single libc call, so `remove_tree`
!> shells out to `rm -rf` with the path single-quoted. Paths are plain Fortran strings.
module wellposed_fs
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char, c_long
  use wellposed_error, only: error_t, new_error, status_invalid
  ! int_text stays public here for the drivers that took it from this module
  use wellposed_text, only: int_text
  implicit none
  private
  public :: rename_path, make_dir, make_dirs, remove_file, remove_tree, path_exists, &
            process_id, shell_quote, int_text, truncate_file

  interface
    function c_rename(old, new) bind(C, name='rename') result(rc)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: old(*), new(*)
      integer(c_int) :: rc
    end function c_rename
    function c_mkdir(path, mode) bind(C, name='mkdir') result(rc)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
      integer(c_int) :: rc
    end function c_mkdir
    function c_remove(path) bind(C, name='remove') result(rc)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int) :: rc
    end function c_remove
    function c_truncate(path, length) bind(C, name='truncate') result(rc)
      import :: c_int, c_char, c_long
      character(kind=c_char), intent(in) :: path(*)
      integer(c_long), value :: length
      integer(c_int) :: rc
    end function c_truncate
    function c_getpid() bind(C, name='getpid') result(pid)
      import :: c_int
      integer(c_int) :: pid
    end function c_getpid
  end interface

contains

  !> Rename `old` to `new` (atomic within one file system; replaces a file
  !> `new`, or an empty folder `new`).
  subroutine rename_path(old, new, err)
    character(len=*), intent(in) :: old, new
    type(error_t), allocatable, intent(out) :: err
    if (c_rename(old//c_null_char, new//c_null_char) /= 0) then
      call new_error(err, status_invalid, new, 'cannot rename "'//old//'" to "'//new//'"')
    end if
  end subroutine rename_path

  !> Create one folder (mode 0755); an existing folder is not an error.
  subroutine make_dir(path, err)
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    integer(c_int) :: rc
    rc = c_mkdir(path//c_null_char, int(o'755', c_int))
    if (rc == 0) return
    if (.not. path_exists(path)) then
      call new_error(err, status_invalid, path, 'cannot create the folder "'//path//'"')
    end if
  end subroutine make_dir

  !> Create a folder and any missing parents (like `mkdir -p`).
  subroutine make_dirs(path, err)
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    integer :: i
    do i = 2, len(path)
      if (path(i:i) == '/') then
        if (.not. path_exists(path(1:i - 1))) then
          call make_dir(path(1:i - 1), err)
          if (allocated(err)) return
        end if
      end if
    end do
    if (len(path) > 0) call make_dir(path, err)
  end subroutine make_dirs

  !> Remove one file; a missing file is not an error (returns .false.).
  logical function remove_file(path) result(removed)
    character(len=*), intent(in) :: path
    removed = c_remove(path//c_null_char) == 0
  end function remove_file

  !> Cut a file to length 0, freeing its space on disk while it is still
  !> open elsewhere (truncate(2)); .false. when that failed.
  logical function truncate_file(path) result(done)
    character(len=*), intent(in) :: path
    done = c_truncate(path//c_null_char, 0_c_long) == 0
  end function truncate_file

  !> Remove a folder tree (`rm -rf`); a missing path is not an error.
  subroutine remove_tree(path, err)
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    integer :: stat, cstat
    if (.not. path_exists(path)) return
    call execute_command_line('rm -rf -- '//shell_quote(path), exitstat=stat, cmdstat=cstat)
    if (cstat == 0 .and. stat == 0) then
      if (.not. path_exists(path)) return
    end if
    call new_error(err, status_invalid, path, 'cannot remove "'//path//'"')
  end subroutine remove_tree

  !> True when a file or folder of that name exists.
  logical function path_exists(path) result(exists)
    character(len=*), intent(in) :: path
    ! gfortran's INQUIRE(FILE=) is true for folders as well.
    inquire (file=path, exist=exists)
  end function path_exists

  !> This process's id (for unique temporary names).
  integer function process_id() result(pid)
    pid = int(c_getpid())
  end function process_id

  !> A string single-quoted for the POSIX shell ('it''s' -> 'it'\''s').
  pure function shell_quote(text) result(quoted)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: quoted
    integer :: i
    quoted = "'"
    do i = 1, len(text)
      if (text(i:i) == "'") then
        quoted = quoted//"'\''"
      else
        quoted = quoted//text(i:i)
      end if
    end do
    quoted = quoted//"'"
  end function shell_quote

end module wellposed_fs
