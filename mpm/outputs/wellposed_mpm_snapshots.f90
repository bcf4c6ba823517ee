!> Particle snapshots of an MPM run, kept where they were taken: each rank
!> holds its own particles' rows and writes them collectively into run.h5
!> (wellposed_h5_parallel, row gid at [gid-1]). For a restart, `put`
!> gathers the rows to rank 0's checkpoint in id order and `get` hands each
!> rank a block of ids on any rank count; `write_stored` writes them again,
!> bit for bit. A snapshot is a group (`snapshots/0001/`) with its time and
!> one dataset per field (width 1: N rows; width 2: (N, 2)).
!> Entries and layout: docs/guide/parallel.md.
module wellposed_mpm_snapshots
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, gatherv_real, gatherv_int
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_row_order_t, new_row_order
  use wellposed_xdmf, only: write_particle_xdmf
  implicit none
  private
  public :: snapshot_store_t, new_snapshot_store, check_snapshots_format, snapshots_version

  !> Version of the checkpoint entries; checkpoints of the programs before
  !> this store (snapshots kept whole on rank 0) have none and are refused.
  integer, parameter :: snapshots_version = 2

  !> One snapshot: this rank's rows of it.
  type :: snapshot_t
    character(len=:), allocatable :: group   !< dataset prefix, ends with '/'
    real(dp) :: time = 0.0_dp                !< s
    integer, allocatable :: gid(:)           !< global ids of the rows held here
    real(dp), allocatable :: rows(:, :)      !< (values per row, rows held here)
  end type snapshot_t

  !> The snapshots taken so far, and what a snapshot holds.
  type :: snapshot_store_t
    character(len=32), allocatable :: names(:)  !< field dataset names, in writing order
    integer, allocatable :: widths(:)           !< values per row of each field (1 or 2)
    integer :: ncols = 0                        !< values per row, sum(widths)
    logical :: time_first = .true.              !< `<group>time` before the fields, else after
    type(snapshot_t), allocatable :: snaps(:)
    integer :: n = 0                            !< snapshots taken
  contains
    procedure :: take => store_take
    procedure :: write_stored => store_write_stored
    procedure :: put => store_put
    procedure :: get => store_get
    procedure :: write_xdmf => store_write_xdmf
  end type snapshot_store_t

contains

  !> An empty store of snapshots with the fields `names` (datasets of
  !> `widths` values per particle: 1 or 2), the time written before them
  !> (`time_first`) or after.
  subroutine new_snapshot_store(self, names, widths, time_first)
    type(snapshot_store_t), intent(out) :: self
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: widths(:)
    logical, intent(in) :: time_first
    integer :: f
    allocate (self%names(size(names)))
    do f = 1, size(names)
      self%names(f) = names(f)
    end do
    self%widths = widths
    self%ncols = sum(widths)
    self%time_first = time_first
    allocate (self%snaps(8))
    self%n = 0
  end subroutine new_snapshot_store

  !> Take a snapshot (collective): this rank's particles `gid` with their
  !> values `rows(ncols, size(gid))` (the fields' values one after
  !> another), at time `t`, under `group`; kept and written into `h5`.
  !> The ids over all ranks must be a permutation of 1..N (else `err`,
  !> the same on every rank).
  subroutine store_take(self, h5, comm, group, t, gid, rows, err)
    class(snapshot_store_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: group
    real(dp), intent(in) :: t
    integer, intent(in) :: gid(:)
    real(dp), intent(in) :: rows(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer :: st
    call room(self, self%n + 1)
    self%n = self%n + 1
    associate (s => self%snaps(self%n))
      s%group = group
      s%time = t
      if (allocated(s%gid)) deallocate (s%gid)
      if (allocated(s%rows)) deallocate (s%rows)
      allocate (s%gid(size(gid)), s%rows(size(rows, 1), size(rows, 2)), stat=st)
      if (st /= 0) call out_of_memory('snapshot rows', int(size(rows), int64), st)
      s%gid = gid
      s%rows = rows
    end associate
    call write_one(self, self%n, h5, comm, err)
  end subroutine store_take

  !> Write the stored snapshots into `h5` again (collective; on restart),
  !> all of them or those whose group begins with `prefix`.
  subroutine store_write_stored(self, h5, comm, err, prefix)
    class(snapshot_store_t), intent(in) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(in) :: comm
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: prefix
    integer :: k
    do k = 1, self%n
      if (.not. selected(self, k, prefix)) cycle
      call write_one(self, k, h5, comm, err)
      if (allocated(err)) return
    end do
  end subroutine store_write_stored

  !> The XDMF file `path` for the stored snapshots (all, or those whose
  !> group begins with `prefix`) of `n` particles in the HDF5 file
  !> `h5_name` beside it: positions from the field `geometry` (`ndim` = 1
  !> or 2 values per particle), every other field a point attribute, each
  !> snapshot at the time it was taken. Any rank may call it alone.
  subroutine store_write_xdmf(self, path, h5_name, grid_name, n, ndim, geometry, err, prefix)
    class(snapshot_store_t), intent(in) :: self
    character(len=*), intent(in) :: path, h5_name, grid_name, geometry
    integer, intent(in) :: n, ndim
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: prefix
    character(len=256) :: groups(self%n)
    real(dp) :: times(self%n)
    integer :: k, m
    m = 0
    do k = 1, self%n
      if (.not. selected(self, k, prefix)) cycle
      if (len(self%snaps(k)%group) > len(groups)) then
        call new_error(err, status_invalid, 'xdmf', path//': snapshot group name longer '// &
          'than '//int_text(len(groups))//' characters: '//self%snaps(k)%group)
        return
      end if
      m = m + 1
      groups(m) = self%snaps(k)%group
      times(m) = self%snaps(k)%time
    end do
    call write_particle_xdmf(path, h5_name, grid_name, groups(1:m), times(1:m), n, ndim, &
                             geometry, pack(self%names, self%names /= geometry), err)
  end subroutine store_write_xdmf

  !> Snapshot k is one of those asked for: all without `prefix`, else
  !> those whose group begins with it.
  logical function selected(self, k, prefix)
    class(snapshot_store_t), intent(in) :: self
    integer, intent(in) :: k
    character(len=*), intent(in), optional :: prefix
    selected = .true.
    if (present(prefix)) selected = index(self%snaps(k)%group, prefix) == 1
  end function selected

  !> Snapshot k into `h5` (collective): every field in global-id order,
  !> and its time before or after them (`time_first`).
  subroutine write_one(self, k, h5, comm, err)
    class(snapshot_store_t), intent(in) :: self
    integer, intent(in) :: k
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(in) :: comm
    type(error_t), allocatable, intent(out) :: err
    type(h5_row_order_t) :: order
    integer :: f, c, w
    associate (s => self%snaps(k))
      call new_row_order(comm, s%gid, order, err)
      if (allocated(err)) return
      if (self%time_first) call h5%write(s%group//'time', [s%time])
      c = 0
      do f = 1, size(self%names)
        w = self%widths(f)
        if (w == 1) then
          call h5%write_rows(s%group//trim(self%names(f)), s%rows(c + 1, :), order)
        else
          call h5%write_rows(s%group//trim(self%names(f)), transpose(s%rows(c + 1:c + w, :)), &
                             order)
        end if
        c = c + w
      end do
      if (.not. self%time_first) call h5%write(s%group//'time', [s%time])
    end associate
  end subroutine write_one

  !> Room for at least n snapshots (doubling; the rows move, not copied).
  subroutine room(self, n)
    class(snapshot_store_t), intent(inout) :: self
    integer, intent(in) :: n
    type(snapshot_t), allocatable :: grown(:)
    integer :: k
    if (.not. allocated(self%snaps)) allocate (self%snaps(8))
    if (size(self%snaps) >= n) return
    allocate (grown(max(n, 2*size(self%snaps))))
    do k = 1, self%n
      call move_alloc(self%snaps(k)%group, grown(k)%group)
      grown(k)%time = self%snaps(k)%time
      call move_alloc(self%snaps(k)%gid, grown(k)%gid)
      call move_alloc(self%snaps(k)%rows, grown(k)%rows)
    end do
    call move_alloc(grown, self%snaps)
  end subroutine room

  !> The store into checkpoint `ckpt` under `prefix` (collective): rank 0
  !> receives every rank's rows and puts them in global-id order; the other
  !> ranks' `ckpt` is left as it is (rank 0 writes the file).
  subroutine store_put(self, ckpt, comm, prefix)
    class(snapshot_store_t), intent(in) :: self
    type(checkpoint_t), intent(inout) :: ckpt
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: prefix
    integer, allocatable :: mine_n(:), mine_gid(:), all_n(:), all_gid(:), n_rows(:)
    real(dp), allocatable :: mine_rows(:), all_rows(:), values(:)
    integer, allocatable :: first(:)
    character(len=:), allocatable :: groups
    integer :: k, m, nc
    nc = self%ncols
    allocate (mine_n(self%n))
    do k = 1, self%n
      mine_n(k) = size(self%snaps(k)%gid)
    end do
    allocate (mine_gid(sum(mine_n)), mine_rows(merge(nc*sum(mine_n), 0, comm%size > 1)))
    m = 0
    do k = 1, self%n
      associate (s => self%snaps(k))
        mine_gid(m + 1:m + mine_n(k)) = s%gid
        if (comm%size > 1) mine_rows(nc*m + 1:nc*(m + mine_n(k))) = &
          reshape(s%rows, [nc*mine_n(k)])
        m = m + mine_n(k)
      end associate
    end do
    if (comm%size == 1) then
      call assemble(1, mine_n, mine_gid)   ! one rank: from the store, no gathered copy
    else
      call gatherv_int(comm, mine_n, all_n, 0)
      call gatherv_int(comm, mine_gid, all_gid, 0)
      call gatherv_real(comm, mine_rows, all_rows, 0)
      deallocate (mine_rows)
      if (comm%rank /= 0) return
      call assemble(comm%size, all_n, all_gid, all_rows)
      deallocate (all_rows)
    end if
    groups = ''
    do k = 1, self%n
      groups = groups//self%snaps(k)%group//new_line('a')
    end do
    call ckpt%put(prefix//'version', snapshots_version)
    call ckpt%put(prefix//'count', self%n)
    call ckpt%put(prefix//'columns', nc)
    call ckpt%put(prefix//'fields', size(self%names))
    call ckpt%put(prefix//'rows', [0, n_rows])
    call ckpt%put(prefix//'times', [0.0_dp, (self%snaps(k)%time, k=1, self%n)])
    call ckpt%put_text(prefix//'groups', groups)
    call ckpt%put_moved(prefix//'values', values)

  contains

    !> values: snapshot after snapshot, each row to row gid; rank q's rows
    !> (counts n(q*self%n + k), ids gid) from `rows`, or from the store.
    subroutine assemble(nranks, n, gid, rows)
      integer, intent(in) :: nranks, n(:), gid(:)
      real(dp), intent(in), optional :: rows(:)
      integer :: q, k, j, m, b, a
      allocate (n_rows(self%n), first(self%n))
      n_rows = 0
      do q = 0, nranks - 1
        n_rows = n_rows + n(q*self%n + 1:(q + 1)*self%n)
      end do
      allocate (values(1 + nc*sum(n_rows)))
      values(1) = 0.0_dp
      a = 1
      do k = 1, self%n
        first(k) = a
        a = a + nc*n_rows(k)
      end do
      m = 0
      do q = 0, nranks - 1
        do k = 1, self%n
          do j = 1, n(q*self%n + k)
            m = m + 1
            b = first(k) + nc*(gid(m) - 1)
            if (present(rows)) then
              values(b + 1:b + nc) = rows(nc*(m - 1) + 1:nc*m)
            else
              values(b + 1:b + nc) = self%snaps(k)%rows(:, j)
            end if
          end do
        end do
      end do
    end subroutine assemble
  end subroutine store_put

  !> Refuse a checkpoint without the store's entries under `prefix`, or
  !> with another version of them: one written by the programs that kept
  !> every snapshot on rank 0 (the caller adds the file's name); version 1
  !> held the header as one positional `layout` entry.
  subroutine check_snapshots_format(ckpt, prefix, err)
    type(checkpoint_t), intent(in) :: ckpt
    character(len=*), intent(in) :: prefix
    type(error_t), allocatable, intent(out) :: err
    integer :: version
    if (.not. ckpt%has(prefix//'version') .and. .not. ckpt%has(prefix//'layout')) then
      call new_error(err, status_invalid, 'checkpoint', 'it was written by an earlier '// &
        'version of the program, which kept every particle snapshot on rank 0; this '// &
        'version keeps them with the ranks and cannot continue it: run the deck from the '// &
        'start, or finish the run with the version that wrote it')
      return
    end if
    version = 1
    if (ckpt%has(prefix//'version')) then
      call ckpt%get(prefix//'version', version, err)
      if (allocated(err)) return
    end if
    if (version /= snapshots_version) then
      call new_error(err, status_invalid, 'checkpoint', 'its particle snapshots are of '// &
        'version '//int_text(version)//', this program reads version '// &
        int_text(snapshots_version))
    end if
  end subroutine check_snapshots_format

  !> The store back from `ckpt` (which every rank holds; collective by
  !> nature, no messages): each rank takes a contiguous block of global ids
  !> of every snapshot (rank q of P the q-th of P near-equal blocks, the
  !> first mod(N, P) one longer), on any number of ranks. `self` must have
  !> been made by new_snapshot_store with the fields of the run that wrote
  !> `ckpt`; anything else is refused.
  subroutine store_get(self, ckpt, comm, prefix, err)
    class(snapshot_store_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ckpt
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: prefix
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: n_rows(:)
    real(dp), allocatable :: times(:), values(:)
    character(len=:), allocatable :: groups
    integer :: nsnap, nc, nfields, k, b, r, first, nb, j, at, nl, a
    call check_snapshots_format(ckpt, prefix, err)
    if (allocated(err)) return
    call ckpt%get(prefix//'count', nsnap, err); if (allocated(err)) return
    call ckpt%get(prefix//'columns', nc, err); if (allocated(err)) return
    call ckpt%get(prefix//'fields', nfields, err); if (allocated(err)) return
    if (nc /= self%ncols .or. nfields /= size(self%names) .or. nsnap < 0) then
      call refuse(err, 'its snapshots hold '//int_text(nfields)//' fields of '// &
                  int_text(nc)//' values per particle; this program writes '// &
                  int_text(size(self%names))//' of '//int_text(self%ncols)); return
    end if
    call ckpt%get(prefix//'rows', n_rows, err); if (allocated(err)) return
    call ckpt%get(prefix//'times', times, err); if (allocated(err)) return
    call ckpt%get_text(prefix//'groups', groups, err); if (allocated(err)) return
    call ckpt%get(prefix//'values', values, err); if (allocated(err)) return
    if (size(n_rows) /= nsnap + 1 .or. size(times) /= nsnap + 1) then
      call refuse(err, 'its snapshot counts are garbled'); return
    end if
    n_rows = n_rows(2:)
    if (any(n_rows < 0) .or. size(values) /= 1 + nc*sum(n_rows) .or. &
        count([(groups(j:j) == new_line('a'), j=1, len(groups))]) /= nsnap) then
      call refuse(err, 'its snapshots are garbled'); return
    end if
    deallocate (self%snaps)
    allocate (self%snaps(max(nsnap, 8)))
    self%n = nsnap
    a = 1
    at = 1
    do k = 1, nsnap
      associate (s => self%snaps(k))
        nl = index(groups(at:), new_line('a'))
        s%group = groups(at:at + nl - 2)
        at = at + nl
        s%time = times(k + 1)
        b = n_rows(k)/comm%size
        r = mod(n_rows(k), comm%size)
        first = comm%rank*b + min(comm%rank, r) + 1
        nb = b
        if (comm%rank < r) nb = b + 1
        s%gid = [(first + j - 1, j=1, nb)]
        s%rows = reshape(values(a + nc*(first - 1) + 1:a + nc*(first - 1 + nb)), [nc, nb])
        a = a + nc*n_rows(k)
      end associate
    end do
  end subroutine store_get

  !> A checkpoint's snapshots refused, and why.
  subroutine refuse(err, what)
    type(error_t), allocatable, intent(inout) :: err
    character(len=*), intent(in) :: what
    call new_error(err, status_invalid, 'checkpoint', what)
  end subroutine refuse

end module wellposed_mpm_snapshots
