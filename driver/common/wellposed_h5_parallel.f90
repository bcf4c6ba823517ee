!> One HDF5 file written by every rank of a communicator, with the layout of
!> the serial writer wellposed_h5, so XDMF files and plot scripts read it
!> unchanged. Through MPI-IO with parallel HDF5 on more than one rank (every
!> call collective), else gathered to rank 0 (`h5_uses_mpio` says which).
!> `write_rows` writes particle rows (contiguous blocks, or rows named by
!> global id through `new_row_order`); `write`/`write_attr` write rank 0's data.
!> A failure on any rank fails every rank and leaves no finished-looking file.
!> Row orders, redistribution and error sharing: docs/parallel.md.
module wellposed_h5_parallel
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc
  use hdf5
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: rename_path, remove_file, path_exists, process_id, int_text
  use wellposed_h5, only: h5_file_t
  use wellposed_h5_mpio, only: h5_mpio_available, h5_fapl_mpio, h5_dxpl_collective, &
                               h5_dxpl_was_collective
  use wellposed_mpi, only: comm_t, broadcast, allreduce_sum, allreduce_min, allreduce_max, &
                           allreduce_any, exscan_sum, gatherv_real, gatherv_int, &
                           alltoall_counts, alltoallv_real, alltoallv_int, legacy_handles
  implicit none
  private
  public :: h5_parallel_file_t, h5_row_order_t, new_row_order, h5_uses_mpio, h5_writer_name
  public :: order_redistribute, order_points, order_hyperslabs

  !> How rows in global-id order reach the file under MPI-IO.
  integer, parameter :: order_redistribute = 1  !< all-to-all into id blocks, then contiguous writes
  integer, parameter :: order_points = 2        !< each rank writes its rows in place, point selection
  integer, parameter :: order_hyperslabs = 3    !< in place, a union of hyperslabs over id runs

  !> Where the rows of a rank go when written in global-id order; built by
  !> `new_row_order` for one distribution of ids over the ranks.
  type :: h5_row_order_t
    integer :: method = order_redistribute
    logical :: mpio = .false.                !< built for MPI-IO writes (else gathered)
    integer :: n_total = 0                   !< rows of the dataset (ids 1..n_total)
    integer :: n_local = 0                   !< rows this rank holds
    integer :: first = 1                     !< first id of this rank's block (redistribute)
    integer :: n_block = 0                   !< ids in this rank's block
    integer, allocatable :: send_perm(:)     !< local rows in sending order
    integer, allocatable :: scount(:), sdispl(:), rcount(:), rdispl(:)  !< in rows, 0:size-1
    integer, allocatable :: recv_slot(:)     !< received row k -> row of the block
    integer, allocatable :: sorted(:)        !< local rows by ascending id (points, hyperslabs)
    integer, allocatable :: run_first(:), run_len(:)  !< runs of consecutive ids (hyperslabs)
    integer, allocatable :: root_gid(:)      !< gathered ids, on rank 0 (gather)
  end type h5_row_order_t

  !> Rows on their way to the file: real(dp) or integer, row-major (the
  !> n_cols values of a row are adjacent).
  type :: payload_t
    real(dp), allocatable :: r(:)
    integer, allocatable :: i(:)
  end type payload_t

  !> An HDF5 file being written by all ranks of a communicator.
  type :: h5_parallel_file_t
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
    procedure :: close => pf_close
  end type h5_parallel_file_t

contains

  !> True when files on `comm` are written through MPI-IO (parallel HDF5
  !> and more than one rank); false when rank 0 writes them.
  logical function h5_uses_mpio(comm) result(uses)
    type(comm_t), intent(in) :: comm
    uses = h5_mpio_available .and. comm%size > 1
  end function h5_uses_mpio

  !> How files on `comm` are written, in a word for a run's summary:
  !> 'mpio-collective' (every rank writes its rows through MPI-IO) or
  !> 'rank0-gather' (rank 0 gathers the rows and writes alone: one rank,
  !> or serial HDF5).
  function h5_writer_name(comm) result(name)
    type(comm_t), intent(in) :: comm
    character(len=:), allocatable :: name
    if (h5_uses_mpio(comm)) then
      name = 'mpio-collective'
    else
      name = 'rank0-gather'
    end if
  end function h5_writer_name

  ! -------------------------------------------------------------------------
  ! Opening and closing
  ! -------------------------------------------------------------------------

  !> Start writing `path` on every rank of `comm` (collective). On failure
  !> every rank gets the same error and no file is left.
  subroutine pf_create(self, comm, path, err)
    class(h5_parallel_file_t), intent(inout) :: self
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
    call h5open_f(hdferr)
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
    class(h5_parallel_file_t), intent(inout) :: self
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
    call h5fclose_f(self%id, hdferr)
    call fail(self, 'cannot close '//self%tmp, hdferr)
    call sync(self)
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
    class(h5_parallel_file_t), intent(inout) :: self
    character(len=*), intent(in) :: what
    integer, intent(in) :: hdferr
    if (hdferr /= 0 .and. .not. allocated(self%failure)) self%failure = what
  end subroutine fail

  !> Make every rank hold the failure of the lowest rank that has one
  !> (collective), so all ranks take the same branches afterwards.
  subroutine sync(self)
    class(h5_parallel_file_t), intent(inout) :: self
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
    class(h5_parallel_file_t), intent(inout) :: self
    ready = self%is_open .and. .not. allocated(self%failure)
    if (.not. self%is_open .and. .not. allocated(self%failure)) &
      self%failure = 'write before create'
  end function ready

  ! -------------------------------------------------------------------------
  ! MPI-IO building blocks (collective)
  ! -------------------------------------------------------------------------

  !> Create the groups on the way to `name` ("a/b/x" makes a and a/b).
  subroutine make_groups(self, name)
    class(h5_parallel_file_t), intent(inout) :: self
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
    class(h5_parallel_file_t), intent(inout) :: self
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
    class(h5_parallel_file_t), intent(inout) :: self
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
    class(h5_parallel_file_t), intent(inout) :: self
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
    class(h5_parallel_file_t), intent(inout) :: self
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

  ! -------------------------------------------------------------------------
  ! Moving rows between ranks
  ! -------------------------------------------------------------------------

  !> q = the rows of p (n_cols values each) in the order `perm`.
  subroutine permute_rows(p, perm, n_cols, q)
    type(payload_t), intent(in) :: p
    integer, intent(in) :: perm(:), n_cols
    type(payload_t), intent(out) :: q
    integer :: k, a, b
    if (allocated(p%r)) then
      allocate (q%r(n_cols*size(perm)))
    else
      allocate (q%i(n_cols*size(perm)))
    end if
    do k = 1, size(perm)
      a = (perm(k) - 1)*n_cols
      b = (k - 1)*n_cols
      if (allocated(p%r)) then
        q%r(b + 1:b + n_cols) = p%r(a + 1:a + n_cols)
      else
        q%i(b + 1:b + n_cols) = p%i(a + 1:a + n_cols)
      end if
    end do
  end subroutine permute_rows

  !> The rows of this rank's id block (q, in id order) from the rows every
  !> rank holds (p, in its local order): one all-to-all.
  subroutine redistribute(comm, order, n_cols, p, q)
    type(comm_t), intent(in) :: comm
    type(h5_row_order_t), intent(in) :: order
    integer, intent(in) :: n_cols
    type(payload_t), intent(in) :: p
    type(payload_t), intent(out) :: q
    type(payload_t) :: s
    real(dp), allocatable :: rr(:)
    integer, allocatable :: ri(:)
    integer :: k, a, b, nrecv
    call permute_rows(p, order%send_perm, n_cols, s)
    nrecv = sum(order%rcount)
    if (allocated(p%r)) then
      allocate (rr(n_cols*nrecv), q%r(n_cols*order%n_block))
      call alltoallv_real(comm, s%r, n_cols*order%scount, n_cols*order%sdispl, rr, &
                          n_cols*order%rcount, n_cols*order%rdispl)
    else
      allocate (ri(n_cols*nrecv), q%i(n_cols*order%n_block))
      call alltoallv_int(comm, s%i, n_cols*order%scount, n_cols*order%sdispl, ri, &
                         n_cols*order%rcount, n_cols*order%rdispl)
    end if
    do k = 1, nrecv
      a = (k - 1)*n_cols
      b = (order%recv_slot(k) - 1)*n_cols
      if (allocated(p%r)) then
        q%r(b + 1:b + n_cols) = rr(a + 1:a + n_cols)
      else
        q%i(b + 1:b + n_cols) = ri(a + 1:a + n_cols)
      end if
    end do
  end subroutine redistribute

  !> Gather mode: every rank's rows on rank 0, in rank order, or placed by
  !> global id with `order`; then rank 0 writes them with the serial writer.
  subroutine gather_rows(self, name, ndims, n_cols, p, order)
    class(h5_parallel_file_t), intent(inout) :: self
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

  !> q row gid(k) = p row k.
  subroutine place_rows(p, gid, n_cols, q)
    type(payload_t), intent(in) :: p
    integer, intent(in) :: gid(:), n_cols
    type(payload_t), intent(out) :: q
    integer :: k, a, b
    if (allocated(p%r)) then
      allocate (q%r(n_cols*size(gid)))
    else
      allocate (q%i(n_cols*size(gid)))
    end if
    do k = 1, size(gid)
      a = (k - 1)*n_cols
      b = (gid(k) - 1)*n_cols
      if (allocated(p%r)) then
        q%r(b + 1:b + n_cols) = p%r(a + 1:a + n_cols)
      else
        q%i(b + 1:b + n_cols) = p%i(a + 1:a + n_cols)
      end if
    end do
  end subroutine place_rows

  ! -------------------------------------------------------------------------
  ! Rows in global-id order
  ! -------------------------------------------------------------------------

  !> Prepare writing rows named by global ids `gid` (this rank's rows, in
  !> its local order; over all ranks a permutation of 1..N) in id order
  !> (collective). `method` (MPI-IO only): order_redistribute (default),
  !> order_points or order_hyperslabs. Ids outside 1..N, or repeated, give
  !> the same error on every rank.
  subroutine new_row_order(comm, gid, order, err, method)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: gid(:)
    type(h5_row_order_t), intent(out) :: order
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: method
    integer, allocatable :: dest(:), rgid(:), hits(:), fill(:)
    integer :: np, b, r, q, k, nrecv
    logical :: bad
    if (present(method)) order%method = method
    order%mpio = h5_uses_mpio(comm)
    order%n_local = size(gid)
    order%n_total = order%n_local
    call allreduce_sum(comm, order%n_total)
    if (allreduce_any(comm, any(gid < 1 .or. gid > order%n_total))) then
      call refuse(); return
    end if
    if (.not. order%mpio) then
      call gatherv_int(comm, gid, order%root_gid, 0)
      bad = .false.
      if (comm%rank == 0) then
        allocate (hits(order%n_total))
        hits = 0
        do k = 1, size(order%root_gid)
          hits(order%root_gid(k)) = hits(order%root_gid(k)) + 1
        end do
        bad = any(hits /= 1)
      end if
      call broadcast(comm, bad, 0)
      if (bad) call refuse()
      return
    end if
    ! Blocks of ids: rank q holds ids first(q) .. first(q)+n_block(q)-1, the
    ! first mod(N, P) ranks one more than the others.
    np = comm%size
    b = order%n_total/np
    r = mod(order%n_total, np)
    order%first = comm%rank*b + min(comm%rank, r) + 1
    order%n_block = b
    if (comm%rank < r) order%n_block = b + 1
    allocate (dest(order%n_local), order%scount(0:np - 1), order%sdispl(0:np - 1), &
              order%rcount(0:np - 1), order%rdispl(0:np - 1))
    do k = 1, order%n_local
      if (gid(k) - 1 < r*(b + 1)) then
        dest(k) = (gid(k) - 1)/(b + 1)
      else
        dest(k) = r + (gid(k) - 1 - r*(b + 1))/b
      end if
    end do
    order%scount = 0
    do k = 1, order%n_local
      order%scount(dest(k)) = order%scount(dest(k)) + 1
    end do
    order%sdispl(0) = 0
    do q = 1, np - 1
      order%sdispl(q) = order%sdispl(q - 1) + order%scount(q - 1)
    end do
    ! Counting sort by destination, stable: rows keep their local order.
    allocate (order%send_perm(order%n_local), fill(0:np - 1))
    fill = order%sdispl
    do k = 1, order%n_local
      fill(dest(k)) = fill(dest(k)) + 1
      order%send_perm(fill(dest(k))) = k
    end do
    call alltoall_counts(comm, order%scount, order%rcount)
    order%rdispl(0) = 0
    do q = 1, np - 1
      order%rdispl(q) = order%rdispl(q - 1) + order%rcount(q - 1)
    end do
    nrecv = sum(order%rcount)
    allocate (rgid(nrecv))
    call alltoallv_int(comm, gid(order%send_perm), order%scount, order%sdispl, rgid, &
                       order%rcount, order%rdispl)
    order%recv_slot = rgid - order%first + 1
    allocate (hits(order%n_block))
    hits = 0
    bad = nrecv /= order%n_block
    if (.not. bad) then
      do k = 1, nrecv
        hits(order%recv_slot(k)) = hits(order%recv_slot(k)) + 1
      end do
      bad = any(hits /= 1)
    end if
    if (allreduce_any(comm, bad)) then
      call refuse(); return
    end if
    if (order%method /= order_redistribute) then
      call sort_by_key(gid, order%sorted)
      call runs_of(gid(order%sorted), order%method == order_points, order%run_first, &
                   order%run_len)
    end if
  contains
    subroutine refuse()
      call new_error(err, status_invalid, 'h5', 'the global ids of the rows are not a '// &
        'permutation of 1..'//int_text(order%n_total)//' over the ranks')
    end subroutine refuse
  end subroutine new_row_order

  !> perm such that key(perm) ascends (merge sort, stable).
  pure subroutine sort_by_key(key, perm)
    integer, intent(in) :: key(:)
    integer, allocatable, intent(out) :: perm(:)
    integer, allocatable :: tmp(:)
    integer :: n, width, lo, mid, hi, i, j, k
    n = size(key)
    perm = [(k, k=1, n)]
    allocate (tmp(n))
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width - 1, n)
        hi = min(lo + 2*width - 1, n)
        i = lo
        j = mid + 1
        do k = lo, hi
          if (j > hi) then
            tmp(k) = perm(i); i = i + 1
          else if (i > mid) then
            tmp(k) = perm(j); j = j + 1
          else if (key(perm(j)) < key(perm(i))) then
            tmp(k) = perm(j); j = j + 1
          else
            tmp(k) = perm(i); i = i + 1
          end if
        end do
      end do
      perm = tmp
      width = 2*width
    end do
  end subroutine sort_by_key

  !> Ascending ids as runs of consecutive ids (first id, length); with
  !> `singles`, every id is its own run (the point selection's coordinates).
  pure subroutine runs_of(ids, singles, first, length)
    integer, intent(in) :: ids(:)
    logical, intent(in) :: singles
    integer, allocatable, intent(out) :: first(:), length(:)
    integer :: k, m
    allocate (first(size(ids)), length(size(ids)))
    m = 0
    do k = 1, size(ids)
      if (m > 0 .and. .not. singles) then
        if (ids(k) == first(m) + length(m)) then
          length(m) = length(m) + 1
          cycle
        end if
      end if
      m = m + 1
      first(m) = ids(k)
      length(m) = 1
    end do
    first = first(1:m)
    length = length(1:m)
  end subroutine runs_of

  ! -------------------------------------------------------------------------
  ! Public writes
  ! -------------------------------------------------------------------------

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
