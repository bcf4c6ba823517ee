!> One HDF5 file written by every rank of a communicator: opening and
!> closing it (atomically: a temporary name renamed when complete), the
!> failure every rank shares, and the collective transfers under MPI-IO
!> (or the gather to rank 0 without it). The public writes on top of it are
!> wellposed_h5_parallel's; the row orders are wellposed_h5_row_order's.
module wellposed_h5_collective
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc
  use hdf5
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: rename_path, remove_file, path_exists, process_id, int_text, &
                          truncate_file
  use wellposed_checked_io, only: write_fault
  use wellposed_h5, only: h5_file_t, h5_start
  use wellposed_h5_mpio, only: h5_fapl_mpio, h5_dxpl_collective, h5_dxpl_was_collective
  use wellposed_h5_row_order, only: h5_row_order_t, payload_t, h5_uses_mpio, permute_rows, &
                                    redistribute, place_rows, order_redistribute, &
                                    order_points, order_hyperslabs
  use wellposed_mpi, only: comm_t, broadcast, allreduce_sum, allreduce_min, allreduce_any, &
                           exscan_sum, gatherv_real, gatherv_int, legacy_handles
  implicit none
  private
  public :: h5_collective_file_t, fail, sync, ready, file_dims, mpio_rows, mpio_root, gather_rows

  !> An HDF5 file being written by all ranks of a communicator.
  type :: h5_collective_file_t
    type(comm_t) :: comm
    logical :: mpio = .false.               !< MPI-IO (else rank 0 writes `serial`)
    type(h5_file_t) :: serial
    integer(hid_t) :: id = -1, dxpl = -1
    character(len=:), allocatable :: path, tmp
    character(len=:), allocatable :: failure  !< first failure (the same on every rank)
    logical :: is_open = .false.
    !> The last dataset was written by a collective MPI-IO transfer (as
    !> reported by HDF5; false when gathered).
    logical :: last_collective = .false.
  contains
    procedure :: create => pf_create
    procedure :: close => pf_close
  end type h5_collective_file_t

contains

  ! -------------------------------------------------------------------------
  ! Opening and closing
  ! -------------------------------------------------------------------------

  !> Start writing `path` on every rank of `comm` (collective). On failure
  !> every rank gets the same error and no file is left.
  subroutine pf_create(self, comm, path, err)
    class(h5_collective_file_t), intent(inout) :: self
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    integer :: hdferr, comm_f, info_f, e2, slash
    integer(hid_t) :: fapl
    logical :: failed, removed
    character(len=:), allocatable :: text
    self%comm = comm
    self%mpio = h5_uses_mpio(comm)
    self%path = path
    self%is_open = .false.
    self%last_collective = .false.
    if (allocated(self%failure)) deallocate (self%failure)
    if (.not. self%mpio) then
      if (comm%rank == 0) call self%serial%create(path, e)
      text = message_of(e)
      call share_outcome(comm, text, err)
      self%is_open = .not. allocated(err)
      return
    end if
    text = ''
    if (comm%rank == 0) text = path//'.tmp.'//int_text(process_id())
    call broadcast(comm, text, 0)
    self%tmp = text
    call h5_start(hdferr)
    ! One sentence per rank instead of HDF5's error stack from every rank.
    if (hdferr == 0) call h5eset_auto_f(0, hdferr)
    call legacy_handles(comm, comm_f, info_f)
    if (hdferr == 0) call h5_fapl_mpio(comm_f, info_f, fapl, hdferr)
    if (hdferr == 0) then
      call h5fcreate_f(self%tmp, H5F_ACC_TRUNC_F, self%id, hdferr, access_prp=fapl)
      call h5pclose_f(fapl, e2)
    end if
    if (hdferr == 0) then
      call h5_dxpl_collective(self%dxpl, hdferr)
      if (hdferr /= 0) call h5fclose_f(self%id, e2)
    end if
    failed = allreduce_any(comm, hdferr /= 0)
    if (failed .and. hdferr == 0) then
      call h5pclose_f(self%dxpl, e2)
      call h5fclose_f(self%id, e2)
    end if
    if (failed) then
      text = ''
      if (comm%rank == 0) then
        removed = remove_file(self%tmp)
        slash = index(path, '/', back=.true.)
        text = 'cannot create the HDF5 file "'//self%tmp//'" on '//int_text(comm%size)// &
               ' ranks'
        if (slash > 1) then
          if (path_exists(path(1:slash - 1))) then
            text = text//' (is "'//path(1:slash - 1)//'" a folder this user can write to?)'
          else
            text = text//': its folder "'//path(1:slash - 1)//'" does not exist'
          end if
        end if
      end if
      call share_outcome(comm, text, err)
      call h5eset_auto_f(1, e2)
      return
    end if
    self%is_open = .true.
  end subroutine pf_create

  !> Close the file (collective) and rename it to its final name; after
  !> any failure on any rank the temporary file is removed and every rank
  !> gets the same error.
  subroutine pf_close(self, err)
    class(h5_collective_file_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    integer :: hdferr, e2
    logical :: removed
    character(len=:), allocatable :: text
    if (.not. self%is_open) then
      call new_error(err, status_invalid, 'h5', 'close of an HDF5 file that is not open')
      return
    end if
    self%is_open = .false.
    if (.not. self%mpio) then
      if (self%comm%rank == 0) then
        ! a failure found by all ranks (rows that do not fit) is the file's
        if (allocated(self%failure) .and. .not. allocated(self%serial%failure)) &
          self%serial%failure = self%failure
        call self%serial%close(e)
      end if
      text = message_of(e)
      call share_outcome(self%comm, text, err)
      return
    end if
    call h5pclose_f(self%dxpl, e2)
    ! As wellposed_h5's close: flush (collective) while the file is whole,
    ! and a failed file gives its space back before the close writes again.
    call sync(self)
    if (.not. allocated(self%failure)) then
      call h5fflush_f(self%id, H5F_SCOPE_LOCAL_F, hdferr)
      call fail(self, 'cannot write '//self%tmp//' (disk full?)', hdferr)
      call sync(self)
    end if
    if (allocated(self%failure) .and. self%comm%rank == 0) removed = truncate_file(self%tmp)
    call h5fclose_f(self%id, hdferr)
    call fail(self, 'cannot close '//self%tmp, hdferr)
    call sync(self)
    if (.not. allocated(self%failure) .and. len(write_fault(self%path)) > 0) &
      self%failure = write_fault(self%path)
    text = ''
    if (self%comm%rank == 0) then
      if (allocated(self%failure)) then
        removed = remove_file(self%tmp)
        text = 'HDF5 output "'//self%path//'": '//self%failure
      else
        call rename_path(self%tmp, self%path, e)
        if (allocated(e)) text = e%message
      end if
    end if
    call share_outcome(self%comm, text, err)
    call h5eset_auto_f(1, e2)
  end subroutine pf_close

  !> The message of `e`, empty when there is no error.
  function message_of(e) result(text)
    type(error_t), allocatable, intent(in) :: e
    character(len=:), allocatable :: text
    if (allocated(e)) then
      text = e%message
    else
      text = ''
    end if
  end function message_of

  !> Rank 0's outcome on every rank: `text` empty on rank 0 is success,
  !> anything else is the error message every rank returns.
  subroutine share_outcome(comm, text, err)
    type(comm_t), intent(in) :: comm
    character(len=:), allocatable, intent(inout) :: text
    type(error_t), allocatable, intent(out) :: err
    call broadcast(comm, text, 0)
    if (len(text) > 0) call new_error(err, status_invalid, 'h5', text)
  end subroutine share_outcome

  ! -------------------------------------------------------------------------
  ! Failures: kept per file, shared by all ranks after every operation
  ! -------------------------------------------------------------------------

  subroutine fail(self, what, hdferr)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: what
    integer, intent(in) :: hdferr
    if (hdferr /= 0 .and. .not. allocated(self%failure)) self%failure = what
  end subroutine fail

  !> Make every rank hold the failure of the lowest rank that has one
  !> (collective), so all ranks take the same branches afterwards.
  subroutine sync(self)
    class(h5_collective_file_t), intent(inout) :: self
    integer :: first
    character(len=:), allocatable :: text
    if (.not. allreduce_any(self%comm, allocated(self%failure))) return
    first = huge(1)
    if (allocated(self%failure)) first = self%comm%rank
    call allreduce_min(self%comm, first)
    text = ''
    if (self%comm%rank == first) text = self%failure
    call broadcast(self%comm, text, first)
    self%failure = text
  end subroutine sync

  !> The file is open and nothing failed (the same answer on every rank).
  logical function ready(self)
    class(h5_collective_file_t), intent(inout) :: self
    ready = self%is_open .and. .not. allocated(self%failure)
    if (.not. self%is_open .and. .not. allocated(self%failure)) &
      self%failure = 'write before create'
  end function ready

  ! -------------------------------------------------------------------------
  ! MPI-IO building blocks (collective)
  ! -------------------------------------------------------------------------

  !> Create the groups on the way to `name` ("a/b/x" makes a and a/b).
  subroutine make_groups(self, name)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer :: i, hdferr, e2
    logical :: exists
    integer(hid_t) :: gid
    do i = 2, len(name)
      if (name(i:i) /= '/') cycle
      call h5lexists_f(self%id, name(1:i - 1), exists, hdferr)
      if (hdferr == 0 .and. .not. exists) then
        call h5gcreate_f(self%id, name(1:i - 1), gid, hdferr)
        if (hdferr == 0) call h5gclose_f(gid, e2)
      end if
      call fail(self, 'cannot create group '//name(1:i - 1), hdferr)
      if (hdferr /= 0) return
    end do
  end subroutine make_groups

  !> Create dataset `name` (type `dtype`, dimensions `dims` in HDF5's
  !> Fortran order) and its file space, everything selected.
  subroutine open_dataset(self, name, dtype, dims, dset, fspace, ok)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: dtype
    integer(hsize_t), intent(in) :: dims(:)
    integer(hid_t), intent(out) :: dset, fspace
    logical, intent(out) :: ok
    integer :: hdferr, e2
    dset = -1
    fspace = -1
    call make_groups(self, name)
    hdferr = 0
    if (.not. allocated(self%failure)) then
      call h5screate_simple_f(size(dims), dims, fspace, hdferr)
      if (hdferr == 0) then
        call h5dcreate_f(self%id, name, dtype, fspace, dset, hdferr)
        if (hdferr /= 0) call h5sclose_f(fspace, e2)
      end if
      call fail(self, 'cannot write dataset '//name, hdferr)
    end if
    call sync(self)
    ok = .not. allocated(self%failure)
    if (.not. ok .and. hdferr == 0 .and. dset /= -1) then
      call h5dclose_f(dset, e2)
      call h5sclose_f(fspace, e2)
    end if
  end subroutine open_dataset

  !> Write this rank's `n` elements of `p` (in the order of the selection
  !> made on `fspace`; n = 0: this rank writes nothing) collectively, then
  !> close the dataset and its space.
  subroutine transfer(self, name, dtype, dset, fspace, p, n)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: dtype, dset, fspace
    type(payload_t), intent(in), target :: p
    integer, intent(in) :: n
    real(dp), target :: dummy_r(1)
    integer, target :: dummy_i(1)
    type(c_ptr) :: buf
    integer(hid_t) :: mspace
    integer(hsize_t) :: mdims(1)
    integer :: hdferr, e2
    mdims = int(max(n, 1), hsize_t)
    call h5screate_simple_f(1, mdims, mspace, hdferr)
    if (hdferr == 0 .and. n == 0) then
      call h5sselect_none_f(mspace, hdferr)
      if (hdferr == 0) call h5sselect_none_f(fspace, hdferr)
    end if
    dummy_r = 0.0_dp
    dummy_i = 0
    if (allocated(p%r)) then
      buf = c_loc(dummy_r)
      if (n > 0) buf = c_loc(p%r)
    else
      buf = c_loc(dummy_i)
      if (n > 0) buf = c_loc(p%i)
    end if
    ! Every rank must take part in the collective write, even after a local
    ! failure above (then with nothing selected).
    if (hdferr /= 0) then
      call fail(self, 'cannot select the rows of dataset '//name, hdferr)
      call h5sselect_none_f(mspace, e2)
      call h5sselect_none_f(fspace, e2)
    end if
    call h5dwrite_f(dset, dtype, buf, e2, mem_space_id=mspace, file_space_id=fspace, &
                    xfer_prp=self%dxpl)
    call fail(self, 'cannot write dataset '//name, e2)
    if (e2 == 0) self%last_collective = h5_dxpl_was_collective(self%dxpl)
    call h5sclose_f(mspace, e2)
    call h5dclose_f(dset, e2)
    call h5sclose_f(fspace, e2)
    call sync(self)
  end subroutine transfer

  !> Dimensions in HDF5's Fortran order of a dataset of n_rows rows of
  !> n_cols values (ndims = 1: n_cols = 1, a vector).
  pure function file_dims(ndims, n_cols, n_rows) result(dims)
    integer, intent(in) :: ndims, n_cols, n_rows
    integer(hsize_t), allocatable :: dims(:)
    if (ndims == 1) then
      dims = [int(n_rows, hsize_t)]
    else
      dims = [int(n_cols, hsize_t), int(n_rows, hsize_t)]
    end if
  end function file_dims

  !> Select rows first0 .. first0+count-1 (0-based) of every column.
  subroutine select_rows(fspace, ndims, n_cols, first0, count, hdferr)
    integer(hid_t), intent(in) :: fspace
    integer, intent(in) :: ndims, n_cols, first0, count
    integer, intent(out) :: hdferr
    integer(hsize_t) :: start(2), cnt(2)
    if (count == 0) then
      call h5sselect_none_f(fspace, hdferr)
      return
    end if
    if (ndims == 1) then
      start = [int(first0, hsize_t), 0_hsize_t]
      cnt = [int(count, hsize_t), 0_hsize_t]
    else
      start = [0_hsize_t, int(first0, hsize_t)]
      cnt = [int(n_cols, hsize_t), int(count, hsize_t)]
    end if
    call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, start(1:ndims), cnt(1:ndims), hdferr)
  end subroutine select_rows

  !> The core of every row write under MPI-IO: `p` holds `n_mine` rows of
  !> `n_cols` values, row-major; `order` absent: contiguous blocks in rank
  !> order.
  subroutine mpio_rows(self, name, dtype, ndims, n_cols, n_mine, p, order)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: dtype
    integer, intent(in) :: ndims, n_cols, n_mine
    type(payload_t), intent(in) :: p
    type(h5_row_order_t), intent(in), optional :: order
    type(payload_t) :: q
    integer(hid_t) :: dset, fspace
    integer(hsize_t), allocatable :: coord(:, :)
    integer :: n_total, first0, hdferr, k, j, c, m
    logical :: ok
    if (.not. present(order)) then
      n_total = n_mine
      call allreduce_sum(self%comm, n_total)
      first0 = exscan_sum(self%comm, n_mine)
      call open_dataset(self, name, dtype, file_dims(ndims, n_cols, n_total), dset, fspace, ok)
      if (.not. ok) return
      call select_rows(fspace, ndims, n_cols, first0, n_mine, hdferr)
      if (hdferr /= 0) call fail(self, 'cannot select the rows of dataset '//name, hdferr)
      call transfer(self, name, dtype, dset, fspace, p, n_cols*n_mine)
      return
    end if
    select case (order%method)
    case (order_redistribute)
      call redistribute(self%comm, order, n_cols, p, q)
      call open_dataset(self, name, dtype, file_dims(ndims, n_cols, order%n_total), dset, &
                        fspace, ok)
      if (.not. ok) return
      call select_rows(fspace, ndims, n_cols, order%first - 1, order%n_block, hdferr)
      if (hdferr /= 0) call fail(self, 'cannot select the rows of dataset '//name, hdferr)
      call transfer(self, name, dtype, dset, fspace, q, n_cols*order%n_block)
    case (order_points, order_hyperslabs)
      call permute_rows(p, order%sorted, n_cols, q)
      call open_dataset(self, name, dtype, file_dims(ndims, n_cols, order%n_total), dset, &
                        fspace, ok)
      if (.not. ok) return
      hdferr = 0
      m = n_cols*n_mine
      if (m == 0) then
        call h5sselect_none_f(fspace, hdferr)
      else if (order%method == order_points) then
        ! HDF5's Fortran API takes 1-based coordinates in Fortran order.
        allocate (coord(ndims, m))
        j = 0
        do k = 1, n_mine
          do c = 1, n_cols
            j = j + 1
            if (ndims == 1) then
              coord(1, j) = int(order%run_first(k), hsize_t)
            else
              coord(:, j) = [int(c, hsize_t), int(order%run_first(k), hsize_t)]
            end if
          end do
        end do
        call h5sselect_elements_f(fspace, H5S_SELECT_SET_F, ndims, int(m, size_t), coord, &
                                  hdferr)
      else
        call h5sselect_none_f(fspace, hdferr)
        do k = 1, size(order%run_first)
          if (hdferr /= 0) exit
          if (ndims == 1) then
            call h5sselect_hyperslab_f(fspace, H5S_SELECT_OR_F, &
              [int(order%run_first(k) - 1, hsize_t)], [int(order%run_len(k), hsize_t)], hdferr)
          else
            call h5sselect_hyperslab_f(fspace, H5S_SELECT_OR_F, &
              [0_hsize_t, int(order%run_first(k) - 1, hsize_t)], &
              [int(n_cols, hsize_t), int(order%run_len(k), hsize_t)], hdferr)
          end if
        end do
      end if
      if (hdferr /= 0) call fail(self, 'cannot select the rows of dataset '//name, hdferr)
      call transfer(self, name, dtype, dset, fspace, q, m)
    end select
  end subroutine mpio_rows

  !> Rank 0's `p` (n values, dataset dimensions `dims`) into a new dataset.
  subroutine mpio_root(self, name, dtype, dims, p, n)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: dtype
    integer(hsize_t), intent(in) :: dims(:)
    type(payload_t), intent(in) :: p
    integer, intent(in) :: n
    integer(hid_t) :: dset, fspace
    logical :: ok
    call open_dataset(self, name, dtype, dims, dset, fspace, ok)
    if (.not. ok) return
    if (self%comm%rank == 0) then
      call transfer(self, name, dtype, dset, fspace, p, n)
    else
      call transfer(self, name, dtype, dset, fspace, p, 0)
    end if
  end subroutine mpio_root
  !> Gather mode: every rank's rows on rank 0, in rank order, or placed by
  !> global id with `order`; then rank 0 writes them with the serial writer.
  subroutine gather_rows(self, name, ndims, n_cols, p, order)
    class(h5_collective_file_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndims, n_cols
    type(payload_t), intent(in) :: p
    type(h5_row_order_t), intent(in), optional :: order
    type(payload_t) :: all, placed
    integer :: n_rows
    if (allocated(p%r)) then
      call gatherv_real(self%comm, p%r, all%r, 0)
    else
      call gatherv_int(self%comm, p%i, all%i, 0)
    end if
    if (self%comm%rank /= 0) return
    if (present(order)) then
      call place_rows(all, order%root_gid, n_cols, placed)
    else
      call move_alloc(all%r, placed%r)
      call move_alloc(all%i, placed%i)
    end if
    if (allocated(placed%r)) then
      n_rows = size(placed%r)/max(n_cols, 1)
      if (ndims == 1) then
        call self%serial%write(name, placed%r)
      else
        call self%serial%write(name, transpose(reshape(placed%r, [n_cols, n_rows])))
      end if
    else
      call self%serial%write(name, placed%i)
    end if
  end subroutine gather_rows
end module wellposed_h5_collective
