!> Particle snapshots of an MPM run, kept where they were taken: each rank
!> writes its own particles' rows collectively into run.h5 (row gid at
!> [gid-1]) and, in a run that checkpoints, appends them to its own file of
!> the checkpoint folder (wellposed_mpm_snapshot_files); memory keeps each
!> snapshot's group and time only. `put` records how far every file
!> reached, `get` checks the files, `write_stored` reads them back into
!> run.h5 bit for bit on any rank count. A snapshot is a group with its time
!> and a dataset per field (width 1: N rows; 2: (N, 2)). docs/guide/parallel.md.
module wellposed_mpm_snapshots
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, gatherv_int, allreduce_any, broadcast
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_row_order_t, new_row_order
  use wellposed_xdmf, only: write_particle_xdmf
  use wellposed_fs, only: make_dirs
  use wellposed_mpm_snapshot_files, only: snapshot_file_t, spool_t, spool_name, &
                                          check_spool_file, read_spool_rows, copy_spool_file
  implicit none
  private
  public :: snapshot_store_t, new_snapshot_store, check_snapshots_format, snapshots_version

  !> Version of the checkpoint entries: 3 records the snapshot files of the
  !> checkpoint folder; 2 held the rows in the checkpoint itself, 1 (and the
  !> programs before, with no entries) on rank 0: both refused.
  integer, parameter :: snapshots_version = 3

  !> One snapshot: where it goes and when it was taken (its rows are in
  !> run.h5 and the files).
  type :: snapshot_t
    character(len=:), allocatable :: group   !< dataset prefix, ends with '/'
    real(dp) :: time = 0.0_dp                !< s
    integer :: mine = 0                      !< its rows in this rank's file
  end type snapshot_t

  !> The snapshots taken so far, and what a snapshot holds.
  type :: snapshot_store_t
    character(len=32), allocatable :: names(:)  !< field dataset names, in writing order
    integer, allocatable :: widths(:)           !< values per row of each field (1 or 2)
    integer :: ncols = 0                        !< values per row, sum(widths)
    logical :: time_first = .true.              !< `<group>time` before the fields, else after
    type(snapshot_t), allocatable :: snaps(:)
    integer :: n = 0                            !< snapshots taken
    character(len=:), allocatable :: dir        !< the files' folder ('': none)
    logical :: append = .false.                 !< new snapshots go into a file of dir
    type(spool_t) :: spool                      !< this rank's file of this start or restart
    type(snapshot_file_t), allocatable :: files(:)  !< those of a checkpoint (get)
  contains
    procedure :: keep_files => store_keep_files
    procedure :: take => store_take
    procedure :: write_stored => store_write_stored
    procedure :: put => store_put
    procedure :: get => store_get
    procedure :: write_xdmf => store_write_xdmf
    procedure :: close => store_close
  end type snapshot_store_t

contains

  !> An empty store of snapshots with the fields `names` (datasets of
  !> `widths` values per particle: 1 or 2), the time written before them
  !> (`time_first`) or after; no files kept until keep_files.
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
    allocate (self%snaps(8), self%files(0))
    self%n = 0
    self%dir = ''
  end subroutine new_snapshot_store

  !> The files of the snapshots are in folder `dir` (the run's checkpoint
  !> folder), where `get` finds a checkpoint's; with `append`, every
  !> snapshot taken from now on is appended to this rank's file there (a
  !> run that checkpoints; without, no file is written).
  subroutine store_keep_files(self, dir, append)
    class(snapshot_store_t), intent(inout) :: self
    character(len=*), intent(in) :: dir
    logical, intent(in) :: append
    self%dir = dir
    self%append = append .and. len(dir) > 0
  end subroutine store_keep_files

  !> Take a snapshot (collective): this rank's particles `gid` with their
  !> values `rows(ncols, size(gid))` (the fields' values one after
  !> another), at time `t`, under `group`; written into `h5` and, with
  !> keep_files' `append`, into this rank's file. The ids over all ranks
  !> must be a permutation of 1..N (else `err`, the same on every rank).
  subroutine store_take(self, h5, comm, group, t, gid, rows, err)
    class(snapshot_store_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: group
    real(dp), intent(in) :: t
    integer, intent(in) :: gid(:)
    real(dp), intent(in) :: rows(:, :)
    type(error_t), allocatable, intent(out) :: err
    call room(self, self%n + 1)
    self%n = self%n + 1
    self%snaps(self%n)%group = group
    self%snaps(self%n)%time = t
    self%snaps(self%n)%mine = 0
    call write_one(self, self%snaps(self%n), h5, comm, gid, rows, err)
    if (allocated(err) .or. .not. self%append) return
    if (self%spool%segment == 0) then
      call self%spool%open(self%dir, comm, self%ncols, err)
      if (allocated(err)) return
    end if
    call self%spool%append(gid, rows, comm, err)
    if (.not. allocated(err)) self%snaps(self%n)%mine = size(gid)
  end subroutine store_take

  !> Write the snapshots of the checkpoint `get` read into `h5` again
  !> (collective; on restart), all of them or those whose group begins
  !> with `prefix`: each rank reads the files f = rank + 1, rank + 1 +
  !> ranks, ... one snapshot at a time, whatever ranks wrote them.
  subroutine store_write_stored(self, h5, comm, err, prefix)
    class(snapshot_store_t), intent(in) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(in) :: comm
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: prefix
    type(error_t), allocatable :: e
    integer, allocatable :: gid(:)
    real(dp), allocatable :: rows(:, :)
    integer :: k, f, m, st
    do k = 1, self%n
      if (.not. selected(self, k, prefix)) cycle
      m = 0
      do f = comm%rank + 1, size(self%files), comm%size
        if (k <= size(self%files(f)%rows)) m = m + self%files(f)%rows(k)
      end do
      allocate (gid(m), rows(self%ncols, m), stat=st)
      if (st /= 0) call out_of_memory('snapshot rows', int(self%ncols + 1, int64)*m, st)
      m = 0
      do f = comm%rank + 1, size(self%files), comm%size
        if (k > size(self%files(f)%rows)) cycle
        call read_spool_rows(self%dir, self%files(f), self%ncols, k, gid, rows, m, e)
        if (allocated(e)) exit
      end do
      if (allreduce_any(comm, allocated(e))) then
        if (allocated(e)) then
          call move_alloc(e, err)
        else
          call new_error(err, status_invalid, 'checkpoint', 'another rank could not '// &
                         'read its particle snapshot files')
        end if
        return
      end if
      call write_one(self, self%snaps(k), h5, comm, gid, rows, err)
      if (allocated(err)) return
      deallocate (gid, rows)
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

  !> Snapshot `s` into `h5` (collective): this rank's rows `gid` with their
  !> values, every field in global-id order, and its time before or after
  !> them (`time_first`).
  subroutine write_one(self, s, h5, comm, gid, rows, err)
    class(snapshot_store_t), intent(in) :: self
    type(snapshot_t), intent(in) :: s
    type(h5_parallel_file_t), intent(inout) :: h5
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: gid(:)
    real(dp), intent(in) :: rows(:, :)
    type(error_t), allocatable, intent(out) :: err
    type(h5_row_order_t) :: order
    integer :: f, c, w
    call new_row_order(comm, gid, order, err)
    if (allocated(err)) return
    if (self%time_first) call h5%write(s%group//'time', [s%time])
    c = 0
    do f = 1, size(self%names)
      w = self%widths(f)
      if (w == 1) then
        call h5%write_rows(s%group//trim(self%names(f)), rows(c + 1, :), order)
      else
        call h5%write_rows(s%group//trim(self%names(f)), transpose(rows(c + 1:c + w, :)), &
                           order)
      end if
      c = c + w
    end do
    if (.not. self%time_first) call h5%write(s%group//'time', [s%time])
  end subroutine write_one

  !> This rank's file closed (the run is done with its snapshots).
  subroutine store_close(self)
    class(snapshot_store_t), intent(inout) :: self
    call self%spool%close()
  end subroutine store_close

  !> Room for at least n snapshots (doubling).
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
      grown(k)%mine = self%snaps(k)%mine
    end do
    call move_alloc(grown, self%snaps)
  end subroutine room

  !> Into checkpoint `ckpt` under `prefix` (collective; rank 0's `ckpt` is
  !> the one written): the snapshots' groups and times, and every file that
  !> holds rows of them with the rows of each snapshot it holds, which is
  !> how far it reached (the files of the checkpoint the run continued
  !> from, then this start's or restart's, one a rank).
  subroutine store_put(self, ckpt, comm, prefix)
    class(snapshot_store_t), intent(in) :: self
    type(checkpoint_t), intent(inout) :: ckpt
    type(comm_t), intent(inout) :: comm
    character(len=*), intent(in) :: prefix
    integer, allocatable :: counts(:), rows(:)
    character(len=:), allocatable :: groups, names
    integer :: k, f, q, n
    n = self%n
    call gatherv_int(comm, [(self%snaps(k)%mine, k=1, n)], counts, 0)
    if (comm%rank /= 0) return
    groups = ''
    do k = 1, n
      groups = groups//self%snaps(k)%group//new_line('a')
    end do
    names = ''
    rows = [0]
    do f = 1, size(self%files)
      names = names//self%files(f)%name//new_line('a')
      rows = [rows, self%files(f)%rows, (0, k=size(self%files(f)%rows) + 1, n)]
    end do
    if (self%spool%segment > 0) then
      do q = 0, comm%size - 1
        if (.not. any(counts(q*n + 1:(q + 1)*n) > 0)) cycle
        names = names//spool_name(self%spool%segment, q)//new_line('a')
        rows = [rows, counts(q*n + 1:(q + 1)*n)]
      end do
    end if
    call ckpt%put(prefix//'version', snapshots_version)
    call ckpt%put(prefix//'count', n)
    call ckpt%put(prefix//'columns', self%ncols)
    call ckpt%put(prefix//'fields', size(self%names))
    call ckpt%put(prefix//'times', [0.0_dp, (self%snaps(k)%time, k=1, n)])
    call ckpt%put_text(prefix//'groups', groups)
    call ckpt%put_text(prefix//'files', names)
    call ckpt%put(prefix//'file_rows', rows)
  end subroutine store_put

  !> Refuse a checkpoint without the store's entries under `prefix`, or
  !> with another version of them (the caller adds the file's name): one
  !> written by the programs that kept every snapshot on rank 0 (no
  !> entries, or version 1) or in the checkpoint itself (version 2).
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
    if (version == 2) then
      call new_error(err, status_invalid, 'checkpoint', 'it was written by an earlier '// &
        'version of the program, which held the particle snapshots in the checkpoint '// &
        '(snapshot version 2); this version keeps them in snapshot files of the '// &
        'checkpoint folder (version 3) and cannot continue it: run the deck from the '// &
        'start, or finish the run with the version that wrote it')
    else if (version /= snapshots_version) then
      call new_error(err, status_invalid, 'checkpoint', 'its particle snapshots are of '// &
        'version '//int_text(version)//', this program reads version '// &
        int_text(snapshots_version))
    end if
  end subroutine check_snapshots_format

  !> The store back from `ckpt` (which every rank holds; collective): the
  !> snapshots' groups and times and the files that hold their rows, each
  !> checked in the folder the checkpoint was read from (its text entry
  !> 'run/read_from', else the folder of keep_files): there, of these rows,
  !> as long as the checkpoint records; else `err` names it, the same on
  !> every rank. Files of another folder are copied into keep_files' one.
  !> `self` must have been made by new_snapshot_store with the fields of
  !> the run that wrote `ckpt`; anything else is refused. The next
  !> snapshot taken opens a new file of the folder.
  subroutine store_get(self, ckpt, comm, prefix, err)
    class(snapshot_store_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ckpt
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: prefix
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: rows(:)
    real(dp), allocatable :: times(:)
    character(len=:), allocatable :: groups, names, from
    integer :: nsnap, nc, nfields, nfiles, k, f, at, nl
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
    call ckpt%get(prefix//'times', times, err); if (allocated(err)) return
    call ckpt%get_text(prefix//'groups', groups, err); if (allocated(err)) return
    call ckpt%get_text(prefix//'files', names, err); if (allocated(err)) return
    call ckpt%get(prefix//'file_rows', rows, err); if (allocated(err)) return
    nfiles = lines(names)
    if (size(times) /= nsnap + 1 .or. lines(groups) /= nsnap .or. &
        size(rows) /= 1 + nfiles*nsnap) then
      call refuse(err, 'its snapshot counts are garbled'); return
    end if
    if (any(rows < 0)) then
      call refuse(err, 'its snapshots are garbled'); return
    end if
    from = self%dir
    if (ckpt%has('run/read_from')) then
      call ckpt%get_text('run/read_from', from, err); if (allocated(err)) return
    end if
    deallocate (self%snaps, self%files)
    allocate (self%snaps(max(nsnap, 8)), self%files(nfiles))
    call self%spool%close()
    self%n = nsnap
    at = 1
    do k = 1, nsnap
      nl = index(groups(at:), new_line('a'))
      self%snaps(k)%group = groups(at:at + nl - 2)
      self%snaps(k)%time = times(k + 1)
      at = at + nl
    end do
    at = 1
    do f = 1, nfiles
      nl = index(names(at:), new_line('a'))
      self%files(f)%name = names(at:at + nl - 2)
      self%files(f)%rows = rows(2 + (f - 1)*nsnap:1 + f*nsnap)
      at = at + nl
      call check_spool_file(from, self%files(f), nc, err)
      if (allocated(err)) return
    end do
    if (from /= self%dir .and. len(self%dir) > 0) call adopt(self, from, comm, err)
  end subroutine store_get

  !> The files of `self` copied from folder `from` into self%dir (created
  !> if missing; collective, each rank a share): a checkpoint continued
  !> from another folder (--restart-from) leaves the run's own
  !> checkpoints with their files beside them.
  subroutine adopt(self, from, comm, err)
    class(snapshot_store_t), intent(inout) :: self
    character(len=*), intent(in) :: from
    type(comm_t), intent(in) :: comm
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    integer :: f, made
    made = 1
    if (comm%rank == 0) then
      call make_dirs(self%dir, e)
      if (allocated(e)) made = 0
    end if
    call broadcast(comm, made, 0)
    if (made == 1) then
      do f = comm%rank + 1, size(self%files), comm%size
        call copy_spool_file(from, self%dir, self%files(f), self%ncols, e)
        if (allocated(e)) exit
      end do
    end if
    if (.not. allreduce_any(comm, allocated(e)) .and. made == 1) return
    if (allocated(e)) then
      call move_alloc(e, err)
    else
      call new_error(err, status_invalid, self%dir, 'cannot copy the particle snapshot '// &
                     'files of '//from//' into '//self%dir)
    end if
  end subroutine adopt

  !> Lines of `text` (each ended by new_line).
  pure integer function lines(text)
    character(len=*), intent(in) :: text
    integer :: j
    lines = count([(text(j:j) == new_line('a'), j=1, len(text))])
  end function lines

  !> A checkpoint's snapshots refused, and why.
  subroutine refuse(err, what)
    type(error_t), allocatable, intent(inout) :: err
    character(len=*), intent(in) :: what
    call new_error(err, status_invalid, 'checkpoint', what)
  end subroutine refuse

end module wellposed_mpm_snapshots
