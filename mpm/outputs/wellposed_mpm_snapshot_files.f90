!> The files of a run's checkpoint folder that hold its particle snapshots:
!> each rank appends every snapshot's rows (ids, then values) as it is
!> taken to its own file `snapshots_<segment>_rank<rank>.bin`, a new
!> segment for every start and restart; a checkpoint records how many rows
!> of each snapshot every file holds (so how far each reached), and a
!> restart checks each file is there and long enough and reads the rows
!> back. Layout: docs/guide/parallel.md.
module wellposed_mpm_snapshot_files
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, broadcast, allreduce_any
  use wellposed_fs, only: make_dirs, path_exists, rename_path
  implicit none
  private
  public :: snapshot_file_t, spool_t, spool_name, spool_bytes, check_spool_file, &
            read_spool_rows, copy_spool_file

  !> The first bytes of every file: this text, then the values per row
  !> (int32) and four bytes of zero.
  character(len=16), parameter :: magic = 'wellposed-snap 1'
  integer(int64), parameter :: header_bytes = 24_int64

  !> A file of the folder as a checkpoint records it: its name there and
  !> the rows of every snapshot of the run it holds (0: none).
  type :: snapshot_file_t
    character(len=:), allocatable :: name
    integer, allocatable :: rows(:)
  end type snapshot_file_t

  !> This rank's file of the segment the run writes (open once the run's
  !> first snapshot after its start or restart is taken).
  type :: spool_t
    integer :: unit = 0         !< (newunit numbers are negative)
    integer :: segment = 0      !< 0: none open
    character(len=:), allocatable :: path
  contains
    procedure :: open => spool_open
    procedure :: append => spool_append
    procedure :: close => spool_close
  end type spool_t

contains

  !> The name in the folder of rank `rank`'s file of segment `segment`.
  pure function spool_name(segment, rank) result(name)
    integer, intent(in) :: segment, rank
    character(len=:), allocatable :: name
    character(len=32) :: buf
    write (buf, '(a,i4.4,a,i6.6,a)') 'snapshots_', segment, '_rank', rank, '.bin'
    name = trim(buf)
  end function spool_name

  !> The bytes of a file of rows of `ncols` values holding `rows` rows in all.
  pure integer(int64) function spool_bytes(ncols, rows) result(bytes)
    integer, intent(in) :: ncols, rows(:)
    bytes = header_bytes + sum(int(rows, int64))*(4_int64 + 8_int64*ncols)
  end function spool_bytes

  !> A new segment in folder `dir` (created if missing; collective): the
  !> first whose rank-0 file does not exist yet (so no earlier start's or
  !> restart's file is ever written again), this rank's file of it opened
  !> with its header for rows of `ncols` values. `err` the same on every rank.
  subroutine spool_open(self, dir, comm, ncols, err)
    class(spool_t), intent(inout) :: self
    character(len=*), intent(in) :: dir
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: ncols
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    integer :: seg, st
    seg = 0
    if (comm%rank == 0) then
      call make_dirs(dir, e)
      if (.not. allocated(e)) then
        seg = 1
        do while (path_exists(dir//'/'//spool_name(seg, 0)))
          seg = seg + 1
        end do
      end if
    end if
    call broadcast(comm, seg, 0)
    if (seg == 0) then
      call new_error(err, status_invalid, dir, 'cannot create the checkpoint folder "'// &
                     dir//'" for the particle snapshots')
      return
    end if
    self%segment = seg
    self%path = dir//'/'//spool_name(seg, comm%rank)
    open (newunit=self%unit, file=self%path, access='stream', form='unformatted', &
          status='replace', action='readwrite', iostat=st)
    if (st == 0) write (self%unit, iostat=st) magic, int(ncols, int32), 0_int32
    if (st == 0) flush (self%unit, iostat=st)
    if (st /= 0) self%segment = 0
    call collective(st /= 0, self%path, 'cannot write', comm, err)
  end subroutine spool_open

  !> Rows `gid` with their values `rows(:, j)` at the end of this rank's
  !> file, on disk before it returns (collective, for a common `err`).
  subroutine spool_append(self, gid, rows, comm, err)
    class(spool_t), intent(inout) :: self
    integer, intent(in) :: gid(:)
    real(dp), intent(in) :: rows(:, :)
    type(comm_t), intent(in) :: comm
    type(error_t), allocatable, intent(out) :: err
    integer :: st
    write (self%unit, iostat=st) int(gid, int32), rows
    if (st == 0) flush (self%unit, iostat=st)
    call collective(st /= 0, self%path, 'cannot append the particle snapshot to', comm, err)
  end subroutine spool_append

  subroutine spool_close(self)
    class(spool_t), intent(inout) :: self
    if (self%segment > 0) close (self%unit)
    self%segment = 0
  end subroutine spool_close

  !> `err` on every rank when `failed` on any: naming `path` where it failed.
  subroutine collective(failed, path, what, comm, err)
    logical, intent(in) :: failed
    character(len=*), intent(in) :: path, what
    type(comm_t), intent(in) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. allreduce_any(comm, failed)) return
    if (failed) then
      call new_error(err, status_invalid, path, what//' the particle snapshot file "'// &
                     path//'" (disk full or not writable?)')
    else
      call new_error(err, status_invalid, path, what//' a particle snapshot file of '// &
                     'another rank (disk full or not writable?)')
    end if
  end subroutine collective

  !> File `f` of folder `dir` is there, of rows of `ncols` values, and
  !> holds at least the rows the checkpoint records (a longer file: rows
  !> of snapshots taken after the checkpoint, not read). Else `err` names
  !> the file and what is wrong with it.
  subroutine check_spool_file(dir, f, ncols, err)
    character(len=*), intent(in) :: dir
    type(snapshot_file_t), intent(in) :: f
    integer, intent(in) :: ncols
    type(error_t), allocatable, intent(out) :: err
    character(len=16) :: head
    integer(int32) :: nc, pad
    integer(int64) :: size_now, needed
    integer :: u, st
    character(len=:), allocatable :: path
    path = dir//'/'//f%name
    if (.not. path_exists(path)) then
      call refuse(err, path, 'is missing')
      return
    end if
    needed = spool_bytes(ncols, f%rows)
    inquire (file=path, size=size_now)
    if (size_now < needed) then
      call refuse(err, path, 'is truncated: it has '//bytes_text(size_now)//' bytes, the '// &
                  'checkpoint records '//bytes_text(needed))
      return
    end if
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=st)
    head = ''
    nc = -1
    if (st == 0) then
      read (u, iostat=st) head, nc, pad
      close (u)
    end if
    if (st /= 0 .or. head /= magic .or. nc /= ncols) &
      call refuse(err, path, 'is not a particle snapshot file of this run (its header '// &
                  'is not that of rows of '//int_text(ncols)//' values)')
  end subroutine check_spool_file

  !> File `f` of folder `from` into folder `to` (which exists), as far as
  !> the checkpoint records it, through a temporary name.
  subroutine copy_spool_file(from, to, f, ncols, err)
    character(len=*), intent(in) :: from, to
    type(snapshot_file_t), intent(in) :: f
    integer, intent(in) :: ncols
    type(error_t), allocatable, intent(out) :: err
    integer(int64), parameter :: chunk = 1048576_int64
    character(len=:), allocatable :: part
    character(len=1), allocatable :: buf(:)
    integer(int64) :: left, n
    integer :: ui, uo, st
    part = to//'/'//f%name//'.part'
    allocate (buf(chunk))
    open (newunit=ui, file=from//'/'//f%name, access='stream', form='unformatted', &
          status='old', action='read', iostat=st)
    if (st /= 0) then
      call refuse(err, from//'/'//f%name, 'cannot be read'); return
    end if
    open (newunit=uo, file=part, access='stream', form='unformatted', status='replace', &
          action='write', iostat=st)
    left = spool_bytes(ncols, f%rows)
    do while (st == 0 .and. left > 0)
      n = min(chunk, left)
      read (ui, iostat=st) buf(1:n)
      if (st == 0) write (uo, iostat=st) buf(1:n)
      left = left - n
    end do
    close (ui)
    if (st == 0) close (uo, iostat=st)
    if (st == 0) call rename_path(part, to//'/'//f%name, err)
    if (st /= 0) call new_error(err, status_invalid, part, 'cannot copy the particle '// &
      'snapshot file "'//from//'/'//f%name//'" to "'//part//'" (disk full?)')
  end subroutine copy_spool_file

  !> A byte count as text.
  pure function bytes_text(n) result(text)
    integer(int64), intent(in) :: n
    character(len=:), allocatable :: text
    character(len=24) :: buf
    write (buf, '(i0)') n
    text = trim(buf)
  end function bytes_text

  !> The refusal of file `path`: what is wrong with it.
  subroutine refuse(err, path, what)
    type(error_t), allocatable, intent(inout) :: err
    character(len=*), intent(in) :: path, what
    call new_error(err, status_invalid, 'checkpoint', 'the particle snapshot file "'// &
                   path//'" '//what//'; the checkpoint cannot be continued without it')
  end subroutine refuse

  !> Snapshot k's rows in file `f` of folder `dir` (rows of `ncols` values),
  !> appended to `gid(1:m)` and `rows(:, 1:m)` (room made by the caller).
  subroutine read_spool_rows(dir, f, ncols, k, gid, rows, m, err)
    character(len=*), intent(in) :: dir
    type(snapshot_file_t), intent(in) :: f
    integer, intent(in) :: ncols, k
    integer, intent(inout) :: gid(:)
    real(dp), intent(inout) :: rows(:, :)
    integer, intent(inout) :: m
    type(error_t), allocatable, intent(out) :: err
    integer(int32), allocatable :: ids(:)
    integer(int64) :: at
    integer :: u, st, n
    n = f%rows(k)
    if (n == 0) return
    at = spool_bytes(ncols, f%rows(1:k - 1)) + 1_int64
    allocate (ids(n))
    open (newunit=u, file=dir//'/'//f%name, access='stream', form='unformatted', &
          status='old', action='read', iostat=st)
    if (st == 0) read (u, pos=at, iostat=st) ids, rows(:, m + 1:m + n)
    if (st == 0) close (u)
    if (st /= 0) then
      call refuse(err, dir//'/'//f%name, 'cannot be read')
      return
    end if
    gid(m + 1:m + n) = ids
    m = m + n
  end subroutine read_spool_rows

end module wellposed_mpm_snapshot_files
