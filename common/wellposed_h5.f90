!> HDF5 output of the drivers, one process writing (wellposed_h5_read reads
!> back; wellposed_h5_parallel writes one file from many ranks). A file is
!> written as `<path>.tmp.<pid>` and renamed by `close`, so a crashed run
!> leaves no file that looks complete. a(n_rows, n_cols) is stored so that
!> h5py sees f['x'][i, j] == a(i+1, j+1). `write` keeps its first failure
!> for `close` to report, which then leaves no file behind.
module wellposed_h5
  use hdf5
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: rename_path, remove_file, process_id, int_text, truncate_file
  use wellposed_checked_io, only: write_fault
  implicit none
  private
  public :: h5_file_t, h5_start

  !> An HDF5 file being written.
  type :: h5_file_t
    integer(hid_t) :: id = -1
    character(len=:), allocatable :: path, tmp
    character(len=:), allocatable :: failure  !< first failure, if any
    logical :: is_open = .false.
  contains
    procedure :: create => h5_create
    procedure, private :: write_r1, write_r2, write_i1
    !> write(name, data): real(dp) 1-D or 2-D, integer 1-D datasets.
    generic :: write => write_r1, write_r2, write_i1
    procedure, private :: attr_text, attr_r1
    !> write_attr(name, value): a text or real(dp) 1-D attribute on the root.
    generic :: write_attr => attr_text, attr_r1
    procedure :: close => h5_close
  end type h5_file_t

contains

  !> Open the HDF5 library (h5open_f), first telling it not to close files
  !> in an exit handler: HDF5 1.10 keeps a file whose close failed (a full
  !> disk) in its tables and its exit handler crashes on it (H5F__close_cb);
  !> every file is closed by its writer, so the handler has nothing to do.
  subroutine h5_start(hdferr)
    integer, intent(out) :: hdferr
    logical, save :: started = .false.
    integer :: e2
    if (.not. started) call h5dont_atexit_f(e2)
    started = .true.
    call h5open_f(hdferr)
  end subroutine h5_start

  !> Start writing `path` (under its temporary name).
  subroutine h5_create(self, path, err)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    integer :: hdferr, e2
    self%path = path
    self%tmp = path//'.tmp.'//int_text(process_id())
    if (allocated(self%failure)) deallocate (self%failure)
    call h5_start(hdferr)
    ! Failures are reported in one sentence (here, or by close); HDF5's own
    ! error stack is not printed while the file is open.
    if (hdferr == 0) call h5eset_auto_f(0, hdferr)
    if (hdferr == 0) call h5fcreate_f(self%tmp, H5F_ACC_TRUNC_F, self%id, hdferr)
    if (hdferr /= 0) then
      call h5eset_auto_f(1, e2)
      call new_error(err, status_invalid, path, 'cannot create the HDF5 file "'//self%tmp//'"')
      return
    end if
    self%is_open = .true.
  end subroutine h5_create

  !> Record the first failure.
  subroutine fail(self, what, hdferr)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: what
    integer, intent(in) :: hdferr
    if (hdferr /= 0 .and. .not. allocated(self%failure)) self%failure = what
  end subroutine fail

  !> Create the groups on the way to dataset `name` ("a/b/x" makes a and a/b).
  subroutine make_groups(self, name)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer :: i, hdferr
    logical :: exists
    integer(hid_t) :: gid
    do i = 2, len(name)
      if (name(i:i) /= '/') cycle
      call h5lexists_f(self%id, name(1:i - 1), exists, hdferr)
      if (.not. exists) then
        call h5gcreate_f(self%id, name(1:i - 1), gid, hdferr)
        call fail(self, 'cannot create group '//name(1:i - 1), hdferr)
        if (hdferr == 0) call h5gclose_f(gid, hdferr)
      end if
    end do
  end subroutine make_groups

  logical function ready(self)
    class(h5_file_t), intent(inout) :: self
    ready = self%is_open .and. .not. allocated(self%failure)
    if (.not. self%is_open .and. .not. allocated(self%failure)) &
      self%failure = 'write before create'
  end function ready

  subroutine write_r1(self, name, data)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: data(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: space, dset
    integer :: hdferr, e2
    if (.not. ready(self)) return
    call make_groups(self, name)
    dims = int(size(data), hsize_t)
    call h5screate_simple_f(1, dims, space, hdferr)
    if (hdferr == 0) then
      call h5dcreate_f(self%id, name, H5T_NATIVE_DOUBLE, space, dset, hdferr)
      if (hdferr == 0) then
        call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, data, dims, hdferr)
        call h5dclose_f(dset, e2)
      end if
      call h5sclose_f(space, e2)
    end if
    call fail(self, 'cannot write dataset '//name, hdferr)
  end subroutine write_r1

  subroutine write_r2(self, name, data)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: data(:, :)
    integer(hsize_t) :: dims(2)
    integer(hid_t) :: space, dset
    integer :: hdferr, e2
    real(dp), allocatable :: t(:, :)
    if (.not. ready(self)) return
    call make_groups(self, name)
    ! HDF5's Fortran API reverses the dimensions; store the transpose so
    ! that row-major readers see a(i, j) at [i-1, j-1].
    allocate (t(size(data, 2), size(data, 1)))
    t = transpose(data)
    dims = int(shape(t), hsize_t)
    call h5screate_simple_f(2, dims, space, hdferr)
    if (hdferr == 0) then
      call h5dcreate_f(self%id, name, H5T_NATIVE_DOUBLE, space, dset, hdferr)
      if (hdferr == 0) then
        call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, t, dims, hdferr)
        call h5dclose_f(dset, e2)
      end if
      call h5sclose_f(space, e2)
    end if
    call fail(self, 'cannot write dataset '//name, hdferr)
  end subroutine write_r2

  subroutine write_i1(self, name, data)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: data(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: space, dset
    integer :: hdferr, e2
    if (.not. ready(self)) return
    call make_groups(self, name)
    dims = int(size(data), hsize_t)
    call h5screate_simple_f(1, dims, space, hdferr)
    if (hdferr == 0) then
      call h5dcreate_f(self%id, name, H5T_NATIVE_INTEGER, space, dset, hdferr)
      if (hdferr == 0) then
        call h5dwrite_f(dset, H5T_NATIVE_INTEGER, data, dims, hdferr)
        call h5dclose_f(dset, e2)
      end if
      call h5sclose_f(space, e2)
    end if
    call fail(self, 'cannot write dataset '//name, hdferr)
  end subroutine write_i1

  subroutine attr_text(self, name, text)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name, text
    integer(hid_t) :: atype, space, attr
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2
    character(len=max(len(text), 1)) :: buf
    if (.not. ready(self)) return
    buf = text
    dims = 1
    call h5tcopy_f(H5T_FORTRAN_S1, atype, hdferr)
    if (hdferr == 0) call h5tset_size_f(atype, int(len(buf), size_t), hdferr)
    if (hdferr == 0) call h5screate_f(H5S_SCALAR_F, space, hdferr)
    if (hdferr == 0) then
      call h5acreate_f(self%id, name, atype, space, attr, hdferr)
      if (hdferr == 0) then
        call h5awrite_f(attr, atype, buf, dims, hdferr)
        call h5aclose_f(attr, e2)
      end if
      call h5sclose_f(space, e2)
      call h5tclose_f(atype, e2)
    end if
    call fail(self, 'cannot write attribute '//name, hdferr)
  end subroutine attr_text

  subroutine attr_r1(self, name, values)
    class(h5_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    integer(hid_t) :: space, attr
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2
    if (.not. ready(self)) return
    dims = int(size(values), hsize_t)
    call h5screate_simple_f(1, dims, space, hdferr)
    if (hdferr == 0) then
      call h5acreate_f(self%id, name, H5T_NATIVE_DOUBLE, space, attr, hdferr)
      if (hdferr == 0) then
        call h5awrite_f(attr, H5T_NATIVE_DOUBLE, values, dims, hdferr)
        call h5aclose_f(attr, e2)
      end if
      call h5sclose_f(space, e2)
    end if
    call fail(self, 'cannot write attribute '//name, hdferr)
  end subroutine attr_r1

  !> Close the file and rename it to its final name; on any earlier
  !> failure the temporary file is removed and `err` says what failed.
  subroutine h5_close(self, err)
    class(h5_file_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer :: hdferr, e2
    logical :: removed, cut
    if (.not. self%is_open) then
      call new_error(err, status_invalid, 'h5', 'close of an HDF5 file that is not open')
      return
    end if
    ! Flush first: a full disk fails here, while the file is still whole.
    ! Then a failed file gives its space back (it is removed anyway) so that
    ! the close, which writes the metadata once more, cannot fail as well.
    if (.not. allocated(self%failure)) then
      call h5fflush_f(self%id, H5F_SCOPE_LOCAL_F, hdferr)
      if (hdferr /= 0) call fail(self, 'cannot write '//self%tmp//' (disk full?)', hdferr)
    end if
    if (allocated(self%failure)) cut = truncate_file(self%tmp)
    call h5fclose_f(self%id, hdferr)
    call h5eset_auto_f(1, e2)
    self%is_open = .false.
    if (hdferr /= 0) call fail(self, 'cannot close '//self%tmp, hdferr)
    if (.not. allocated(self%failure) .and. len(write_fault(self%path)) > 0) &
      self%failure = write_fault(self%path)
    if (allocated(self%failure)) then
      removed = remove_file(self%tmp)
      call new_error(err, status_invalid, self%path, 'HDF5 output "'//self%path//'": '// &
        self%failure)
      return
    end if
    call rename_path(self%tmp, self%path, err)
  end subroutine h5_close

end module wellposed_h5
