!> One HDF5 file written by every rank of a communicator, with the layout of
!> the serial writer wellposed_h5, so XDMF files and plot scripts read it
!> unchanged. Through MPI-IO with parallel HDF5 on more than one rank (every
!> call collective), else gathered to rank 0 (`h5_uses_mpio` says which).
!> `write_rows` writes particle rows (contiguous blocks, or rows named by
!> global id through `new_row_order`); `write`/`write_attr` write rank 0's data.
!> A failure on any rank fails every rank and leaves no finished-looking file.
!> Row orders, redistribution and error sharing: docs/guide/parallel.md.
module wellposed_h5_parallel
  use hdf5
  use wellposed_kinds, only: dp
  use wellposed_h5_collective, only: h5_collective_file_t, fail, sync, ready, file_dims, &
                                     mpio_rows, mpio_root, gather_rows
  use wellposed_h5_row_order, only: h5_row_order_t, payload_t, new_row_order, h5_uses_mpio, &
                                    h5_writer_name, order_redistribute, order_points, &
                                    order_hyperslabs
  use wellposed_mpi, only: broadcast, allreduce_min, allreduce_max, allreduce_any
  implicit none
  private
  public :: h5_parallel_file_t, h5_row_order_t, new_row_order, h5_uses_mpio, h5_writer_name
  public :: order_redistribute, order_points, order_hyperslabs

  !> An HDF5 file being written by all ranks of a communicator
  !> (create and close: wellposed_h5_collective).
  type, extends(h5_collective_file_t) :: h5_parallel_file_t
  contains
    procedure, private :: write_r1, write_r2, write_i1
    !> write(name, data): rank 0's real(dp) 1-D or 2-D, or integer 1-D data.
    generic :: write => write_r1, write_r2, write_i1
    procedure, private :: rows_r1, rows_r2, rows_i1
    !> write_rows(name, mine[, order]): every rank's rows of a real(dp)
    !> 1-D or 2-D, or integer 1-D dataset.
    generic :: write_rows => rows_r1, rows_r2, rows_i1
    procedure, private :: attr_text, attr_r1
    !> write_attr(name, value): rank 0's text or real(dp) 1-D attribute on the root.
    generic :: write_attr => attr_text, attr_r1
  end type h5_parallel_file_t

contains

  !> Checks shared by every row write: the width of the rows is the same on
  !> every rank and matches `order` (collective).
  logical function rows_agree(self, name, n_cols, n_mine, order) result(ok)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: n_cols, n_mine
    type(h5_row_order_t), intent(in), optional :: order
    integer :: lo, hi
    logical :: bad
    lo = n_cols
    hi = n_cols
    call allreduce_min(self%comm, lo)
    call allreduce_max(self%comm, hi)
    bad = lo /= hi
    if (present(order)) bad = bad .or. n_mine /= order%n_local .or. &
                              (order%mpio .neqv. self%mpio)
    if (allreduce_any(self%comm, bad)) then
      if (.not. allocated(self%failure)) self%failure = 'cannot write dataset '//name// &
        ': the ranks'' rows differ in width or do not match the row order'
    end if
    ok = .not. allocated(self%failure)
  end function rows_agree

  !> Every rank's `mine` as rows of a 1-D dataset (collective).
  subroutine rows_r1(self, name, mine, order)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: mine(:)
    type(h5_row_order_t), intent(in), optional :: order
    type(payload_t) :: p
    if (.not. ready(self)) return
    if (.not. rows_agree(self, name, 1, size(mine), order)) return
    if (.not. self%mpio .and. self%comm%size == 1 .and. .not. present(order)) then
      call self%serial%write(name, mine)   ! exactly the serial program's call
      return
    end if
    p%r = mine
    if (self%mpio) then
      call mpio_rows(self, name, H5T_NATIVE_DOUBLE, 1, 1, size(mine), p, order)
    else
      call gather_rows(self, name, 1, 1, p, order)
    end if
  end subroutine rows_r1

  !> Every rank's `mine(n_mine, n_cols)` as rows of a 2-D dataset
  !> (collective; n_cols the same on every rank).
  subroutine rows_r2(self, name, mine, order)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: mine(:, :)
    type(h5_row_order_t), intent(in), optional :: order
    type(payload_t) :: p
    integer :: n_cols
    if (.not. ready(self)) return
    n_cols = size(mine, 2)
    if (.not. rows_agree(self, name, n_cols, size(mine, 1), order)) return
    if (.not. self%mpio .and. self%comm%size == 1 .and. .not. present(order)) then
      call self%serial%write(name, mine)
      return
    end if
    p%r = reshape(transpose(mine), [size(mine)])
    if (self%mpio) then
      call mpio_rows(self, name, H5T_NATIVE_DOUBLE, 2, n_cols, size(mine, 1), p, order)
    else
      call gather_rows(self, name, 2, n_cols, p, order)
    end if
  end subroutine rows_r2

  !> Every rank's integer `mine` as rows of a 1-D dataset (collective).
  subroutine rows_i1(self, name, mine, order)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: mine(:)
    type(h5_row_order_t), intent(in), optional :: order
    type(payload_t) :: p
    if (.not. ready(self)) return
    if (.not. rows_agree(self, name, 1, size(mine), order)) return
    if (.not. self%mpio .and. self%comm%size == 1 .and. .not. present(order)) then
      call self%serial%write(name, mine)
      return
    end if
    p%i = mine
    if (self%mpio) then
      call mpio_rows(self, name, H5T_NATIVE_INTEGER, 1, 1, size(mine), p, order)
    else
      call gather_rows(self, name, 1, 1, p, order)
    end if
  end subroutine rows_i1

  !> Rank 0's `data` as a 1-D dataset (collective).
  subroutine write_r1(self, name, data)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: data(:)
    type(payload_t) :: p
    integer :: n
    if (.not. ready(self)) return
    if (.not. self%mpio) then
      if (self%comm%rank == 0) call self%serial%write(name, data)
      return
    end if
    n = size(data)
    call broadcast(self%comm, n, 0)
    p%r = data
    call mpio_root(self, name, H5T_NATIVE_DOUBLE, [int(n, hsize_t)], p, n)
  end subroutine write_r1

  !> Rank 0's `data(n_rows, n_cols)` as a 2-D dataset (collective).
  subroutine write_r2(self, name, data)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: data(:, :)
    type(payload_t) :: p
    integer :: n(2)
    if (.not. ready(self)) return
    if (.not. self%mpio) then
      if (self%comm%rank == 0) call self%serial%write(name, data)
      return
    end if
    n = shape(data)
    call broadcast(self%comm, n, 0)
    p%r = reshape(transpose(data), [size(data)])
    call mpio_root(self, name, H5T_NATIVE_DOUBLE, file_dims(2, n(2), n(1)), p, n(1)*n(2))
  end subroutine write_r2

  !> Rank 0's integer `data` as a 1-D dataset (collective).
  subroutine write_i1(self, name, data)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: data(:)
    type(payload_t) :: p
    integer :: n
    if (.not. ready(self)) return
    if (.not. self%mpio) then
      if (self%comm%rank == 0) call self%serial%write(name, data)
      return
    end if
    n = size(data)
    call broadcast(self%comm, n, 0)
    p%i = data
    call mpio_root(self, name, H5T_NATIVE_INTEGER, [int(n, hsize_t)], p, n)
  end subroutine write_i1

  !> Rank 0's text as attribute `name` of the root group (collective).
  subroutine attr_text(self, name, text)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name, text
    character(len=:), allocatable :: buf
    integer(hid_t) :: atype, space, attr
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2
    if (.not. ready(self)) return
    if (.not. self%mpio) then
      if (self%comm%rank == 0) call self%serial%write_attr(name, text)
      return
    end if
    buf = text
    call broadcast(self%comm, buf, 0)
    if (len(buf) == 0) buf = ' '      ! as the serial writer: at least one character
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
    call sync(self)
  end subroutine attr_text

  !> Rank 0's values as attribute `name` of the root group (collective).
  subroutine attr_r1(self, name, values)
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    real(dp), allocatable :: v(:)
    integer(hid_t) :: space, attr
    integer(hsize_t) :: dims(1)
    integer :: hdferr, e2, n
    if (.not. ready(self)) return
    if (.not. self%mpio) then
      if (self%comm%rank == 0) call self%serial%write_attr(name, values)
      return
    end if
    n = size(values)
    call broadcast(self%comm, n, 0)
    allocate (v(n))
    if (self%comm%rank == 0) v = values
    call broadcast(self%comm, v, 0)
    dims = int(n, hsize_t)
    call h5screate_simple_f(1, dims, space, hdferr)
    if (hdferr == 0) then
      call h5acreate_f(self%id, name, H5T_NATIVE_DOUBLE, space, attr, hdferr)
      if (hdferr == 0) then
        call h5awrite_f(attr, H5T_NATIVE_DOUBLE, v, dims, hdferr)
        call h5aclose_f(attr, e2)
      end if
      call h5sclose_f(space, e2)
    end if
    call fail(self, 'cannot write attribute '//name, hdferr)
    call sync(self)
  end subroutine attr_r1

end module wellposed_h5_parallel
