!> Rows named by global ids, on their way to one HDF5 file written by every
!> rank of a communicator (wellposed_h5_parallel): where each rank's rows go
!> in id order (`new_row_order`), and the moves between ranks that put them
!> there (permutation, all-to-all redistribution, placement on rank 0).
!> No HDF5 here: the file side is wellposed_h5_collective. docs/guide/parallel.md.
module wellposed_h5_row_order
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: int_text
  use wellposed_h5_mpio, only: h5_mpio_available
  use wellposed_mpi, only: comm_t, broadcast, allreduce_sum, allreduce_any, gatherv_int, &
                           alltoall_counts, alltoallv_real, alltoallv_int
  implicit none
  private
  public :: h5_row_order_t, new_row_order, h5_uses_mpio, h5_writer_name, payload_t
  public :: order_redistribute, order_points, order_hyperslabs
  public :: permute_rows, redistribute, place_rows

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
  !> q row gid(k) = p row k.
  subroutine place_rows(p, gid, n_cols, q)
    type(payload_t), intent(in) :: p
    integer, intent(in) :: gid(:), n_cols
    type(payload_t), intent(out) :: q
    integer :: inverse(size(gid)), k
    ! gid is a permutation of 1..size(gid) (new_row_order checked it)
    do k = 1, size(gid)
      inverse(gid(k)) = k
    end do
    call permute_rows(p, inverse, n_cols, q)
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

end module wellposed_h5_row_order
