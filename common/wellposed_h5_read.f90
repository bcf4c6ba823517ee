!> Reading HDF5 files back (the other half of the HDF5 adapter
!> wellposed_h5, which only writes): 1-D real(dp) and integer datasets and
!> text attributes on the root, as written by h5_file_t. Every call
!> returns an error value instead of printing HDF5's error stack (automatic
!> error printing is switched off while a file is open), so a damaged file
!> is reported in one sentence by the caller.
module wellposed_h5_read
  use hdf5
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_h5, only: h5_start
  implicit none
  private
  public :: h5_reader_t

  !> An HDF5 file open for reading.
  type :: h5_reader_t
    integer(hid_t) :: id = -1
    character(len=:), allocatable :: path
    logical :: is_open = .false.
  contains
    procedure :: open => reader_open
    procedure :: exists => reader_exists
    procedure :: length => reader_length
    procedure :: attr_text => reader_attr_text
    procedure, private :: read_r1, read_i1
    !> read(name, data, err): a whole 1-D dataset of the size of `data`.
    generic :: read => read_r1, read_i1
    procedure :: close => reader_close
  end type h5_reader_t

contains

  !> Open `path` read-only.
  subroutine reader_open(self, path, err)
    class(h5_reader_t), intent(inout) :: self
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    integer :: hdferr
    logical :: exists, is_h5
    self%path = path
    inquire (file=path, exist=exists)
    if (.not. exists) then
      call new_error(err, status_invalid, path, '"'//path//'" does not exist')
      return
    end if
    call h5_start(hdferr)
    call h5eset_auto_f(0, hdferr)
    call h5fis_hdf5_f(path, is_h5, hdferr)
    if (hdferr /= 0 .or. .not. is_h5) then
      call new_error(err, status_invalid, path, '"'//path//'" is not an HDF5 file '// &
        '(damaged or truncated)')
      return
    end if
    call h5fopen_f(path, H5F_ACC_RDONLY_F, self%id, hdferr)
    if (hdferr /= 0) then
      call new_error(err, status_invalid, path, 'cannot open "'//path//'" as HDF5 '// &
        '(damaged or truncated)')
      return
    end if
    self%is_open = .true.
  end subroutine reader_open

  !> True when the dataset (or attribute on the root, with attribute=.true.)
  !> `name` exists.
  logical function reader_exists(self, name, attribute) result(exists)
    class(h5_reader_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    logical, intent(in), optional :: attribute
    integer :: hdferr
    logical :: attr
    exists = .false.
    if (.not. self%is_open) return
    attr = .false.
    if (present(attribute)) attr = attribute
    if (attr) then
      call h5aexists_f(self%id, name, exists, hdferr)
    else
      call h5lexists_f(self%id, name, exists, hdferr)
    end if
    if (hdferr /= 0) exists = .false.
  end function reader_exists

  !> Number of elements of the 1-D dataset `name`.
  subroutine reader_length(self, name, n, err)
    class(h5_reader_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(out) :: n
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset, space
    integer(hsize_t) :: dims(1), maxdims(1)
    integer :: hdferr, rank, e2
    n = -1
    call h5dopen_f(self%id, name, dset, hdferr)
    if (hdferr /= 0) then
      call new_error(err, status_invalid, name, 'no dataset "'//name//'" in "'//self%path//'"')
      return
    end if
    call h5dget_space_f(dset, space, hdferr)
    if (hdferr == 0) call h5sget_simple_extent_ndims_f(space, rank, hdferr)
    if (hdferr == 0 .and. rank == 1) then
      call h5sget_simple_extent_dims_f(space, dims, maxdims, hdferr)
      if (hdferr >= 0) then
        hdferr = 0
        n = int(dims(1))
      end if
    else if (hdferr == 0) then
      hdferr = -1
    end if
    call h5sclose_f(space, e2)
    call h5dclose_f(dset, e2)
    if (hdferr /= 0) call new_error(err, status_invalid, name, 'dataset "'//name//'" of "'// &
      self%path//'" is not a readable 1-D array')
  end subroutine reader_length

  !> A text attribute of the root group.
  subroutine reader_attr_text(self, name, text, err)
    class(h5_reader_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: attr, atype
    integer(size_t) :: nchar
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2
    logical :: exists
    call h5aexists_f(self%id, name, exists, hdferr)
    if (hdferr /= 0 .or. .not. exists) then
      call new_error(err, status_invalid, name, 'no attribute "'//name//'" in "'// &
        self%path//'"')
      return
    end if
    call h5aopen_f(self%id, name, attr, hdferr)
    if (hdferr == 0) call h5aget_type_f(attr, atype, hdferr)
    if (hdferr == 0) call h5tget_size_f(atype, nchar, hdferr)
    if (hdferr == 0) then
      allocate (character(len=int(nchar)) :: text)
      dims = 1
      call h5aread_f(attr, atype, text, dims, hdferr)
      call h5tclose_f(atype, e2)
      call h5aclose_f(attr, e2)
    end if
    if (hdferr /= 0) then
      call new_error(err, status_invalid, name, 'cannot read attribute "'//name//'" of "'// &
        self%path//'"')
      if (allocated(text)) deallocate (text)
    end if
  end subroutine reader_attr_text

  subroutine read_r1(self, name, data, err)
    class(h5_reader_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: data(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2, n
    call reader_length(self, name, n, err)
    if (allocated(err)) return
    if (n /= size(data)) then
      call new_error(err, status_invalid, name, 'dataset "'//name//'" of "'//self%path// &
        '" has '//int_text(n)//' values, expected '//int_text(size(data)))
      return
    end if
    dims = int(n, hsize_t)
    call h5dopen_f(self%id, name, dset, hdferr)
    if (hdferr == 0) then
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, data, dims, hdferr)
      call h5dclose_f(dset, e2)
    end if
    if (hdferr /= 0) call new_error(err, status_invalid, name, 'cannot read dataset "'// &
      name//'" of "'//self%path//'" (damaged or truncated)')
  end subroutine read_r1

  subroutine read_i1(self, name, data, err)
    class(h5_reader_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(out) :: data(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2, n
    call reader_length(self, name, n, err)
    if (allocated(err)) return
    if (n /= size(data)) then
      call new_error(err, status_invalid, name, 'dataset "'//name//'" of "'//self%path// &
        '" has '//int_text(n)//' values, expected '//int_text(size(data)))
      return
    end if
    dims = int(n, hsize_t)
    call h5dopen_f(self%id, name, dset, hdferr)
    if (hdferr == 0) then
      call h5dread_f(dset, H5T_NATIVE_INTEGER, data, dims, hdferr)
      call h5dclose_f(dset, e2)
    end if
    if (hdferr /= 0) call new_error(err, status_invalid, name, 'cannot read dataset "'// &
      name//'" of "'//self%path//'" (damaged or truncated)')
  end subroutine read_i1

  !> Close the file (harmless when it is not open).
  subroutine reader_close(self)
    class(h5_reader_t), intent(inout) :: self
    integer :: hdferr
    if (.not. self%is_open) return
    call h5fclose_f(self%id, hdferr)
    self%is_open = .false.
  end subroutine reader_close

end module wellposed_h5_read
