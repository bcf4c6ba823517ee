!> [mpirun -np N] parallel_snapshots_main MODE DIR [ARG]: the snapshot store
!> of the MPM programs (wellposed_mpm_snapshots) on its own, rows scattered
!> over the ranks as particles are, against the serial writer's file. Modes
!> reference, write, read, old, downgrade: docs/research/verification.md.
!> Row g of snapshot k holds k*1000 + g + c/8 in value c (exact); the
!> rows go into the snapshot files of the checkpoint folder DIR/ck_npN.
!> Exits non-zero on any failure.
program parallel_snapshots_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, allreduce_sum, barrier
  use wellposed_fs, only: remove_file, truncate_file, remove_tree
  use wellposed_h5, only: h5_file_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_checkpoint, only: checkpoint_t, write_checkpoint, read_checkpoint, &
                                  latest_checkpoint
  use wellposed_mpm_snapshots, only: snapshot_store_t, new_snapshot_store, &
                                     check_snapshots_format, snapshots_version
  implicit none

  integer, parameter :: nsnap = 3, ncols = 3
  !> rows of each snapshot; groups (two "cases", as wellposed-mpm2d writes)
  integer, parameter :: nrows(nsnap) = [37, 37, 3]
  character(len=*), parameter :: groups(nsnap) = [character(len=15) :: 'cases/a/snap_1/', &
                                                  'cases/a/snap_2/', 'cases/b/snap_1/']
  type(comm_t) :: comm
  type(error_t), allocatable :: err
  character(len=256) :: mode, dir, arg
  integer :: failures

  call comm_start(comm, err)
  call stop_on(err)
  call get_command_argument(1, mode)
  call get_command_argument(2, dir)
  call get_command_argument(3, arg)
  failures = 0
  select case (trim(mode))
  case ('reference')
    call reference()
  case ('write')
    call write_scattered()
  case ('read')
    call read_restored()
  case ('old')
    call old_format()
  case ('downgrade')
    call downgrade()
  case default
    write (error_unit, '(a)') 'usage: parallel_snapshots_main reference|write|read|old|'// &
      'downgrade DIR [ARG]'
    failures = 1
  end select
  call allreduce_sum(comm, failures)
  if (comm%rank == 0) write (output_unit, '(a)') trim(mode)//' on '// &
    int_text(comm%size)//' ranks: '//merge('ok      ', 'FAILURES', failures == 0)
  call comm_stop(comm)
  if (failures > 0) error stop 1

contains

  !> The store of these tests: a 2-wide field, a 1-wide one, time last.
  subroutine new_store(store)
    type(snapshot_store_t), intent(out) :: store
    call new_snapshot_store(store, [character(len=2) :: 'xy', 'v'], [2, 1], time_first=.false.)
  end subroutine new_store

  !> Value c of row g of snapshot k.
  pure real(dp) function value(k, g, c)
    integer, intent(in) :: k, g, c
    value = 1000.0_dp*k + g + 0.125_dp*c
  end function value

  pure real(dp) function time_of(k)
    integer, intent(in) :: k
    time_of = 0.001_dp*k
  end function time_of

  subroutine reference()
    type(h5_file_t) :: h5
    real(dp), allocatable :: xy(:, :), v(:)
    integer :: k, g
    call h5%create(trim(dir)//'/reference.h5', err)
    call stop_on(err)
    do k = 1, nsnap
      allocate (xy(nrows(k), 2), v(nrows(k)))
      do g = 1, nrows(k)
        xy(g, :) = [value(k, g, 1), value(k, g, 2)]
        v(g) = value(k, g, 3)
      end do
      call h5%write(trim(groups(k))//'xy', xy)
      call h5%write(trim(groups(k))//'v', v)
      call h5%write(trim(groups(k))//'time', [time_of(k)])
      deallocate (xy, v)
    end do
    call h5%close(err)
    call stop_on(err)
  end subroutine reference

  subroutine write_scattered()
    call write_snapshots(trim(dir)//'/written_np'//int_text(comm%size)//'.h5', &
                         trim(dir)//'/ck_np'//int_text(comm%size))
  end subroutine write_scattered

  !> The snapshots scattered over the ranks into `file` and into the
  !> snapshot files of folder `ckdir`, with checkpoint 1 there.
  subroutine write_snapshots(file, ckdir)
    character(len=*), intent(in) :: file, ckdir
    type(snapshot_store_t) :: store
    type(h5_parallel_file_t) :: h5
    type(checkpoint_t) :: ck
    integer, allocatable :: gid(:)
    real(dp), allocatable :: rows(:, :)
    character(len=:), allocatable :: path
    integer :: k, g, j
    if (comm%rank == 0) call remove_tree(ckdir, err)   ! an earlier run's files
    call stop_on(err)
    call barrier(comm)
    call new_store(store)
    call store%keep_files(ckdir, .true.)
    call h5%create(comm, file, err)
    call stop_on(err)
    do k = 1, nsnap
      gid = pack([(g, g=nrows(k), 1, -1)], &
                 mod(7*[(g, g=nrows(k), 1, -1)] + k, comm%size) == comm%rank)
      allocate (rows(ncols, size(gid)))
      do j = 1, size(gid)
        rows(:, j) = [value(k, gid(j), 1), value(k, gid(j), 2), value(k, gid(j), 3)]
      end do
      call store%take(h5, comm, trim(groups(k)), time_of(k), gid, rows, err)
      call stop_on(err)
      deallocate (rows)
    end do
    call h5%close(err)
    call stop_on(err)
    call store%put(ck, comm, 'snapshots/')
    call store%close()
    if (comm%rank == 0) then
      call write_checkpoint(ck, ckdir, 1, 2, path, err)
      call stop_on(err)
    end if
    call barrier(comm)     ! the checkpoint is there before anyone reads it
  end subroutine write_snapshots

  subroutine read_restored()
    type(snapshot_store_t) :: store
    type(h5_parallel_file_t) :: h5
    type(checkpoint_t) :: ck
    character(len=:), allocatable :: path
    integer :: k
    call latest_checkpoint(trim(dir)//'/'//trim(arg), path, err)
    call stop_on(err)
    call read_checkpoint(path, ck, err)
    call stop_on(err)
    call new_store(store)
    call store%keep_files(trim(dir)//'/'//trim(arg), .false.)
    call store%get(ck, comm, 'snapshots/', err)
    call stop_on(err)
    call expect(store%n == nsnap, 'the store holds '//int_text(store%n)//' snapshots')
    do k = 1, min(store%n, nsnap)
      call expect(store%snaps(k)%group == trim(groups(k)) .and. &
                  store%snaps(k)%time == time_of(k), &
                  'snapshot '//int_text(k)//' is "'//store%snaps(k)%group//'"')
    end do
    call h5%create(comm, trim(dir)//'/restored_'//trim(arg)//'_np'//int_text(comm%size)// &
                   '.h5', err)
    call stop_on(err)
    call store%write_stored(h5, comm, err, prefix='cases/a/')
    call stop_on(err)
    call store%write_stored(h5, comm, err, prefix='cases/b/')
    call stop_on(err)
    call h5%close(err)
    call stop_on(err)
  end subroutine read_restored

  subroutine old_format()
    type(snapshot_store_t) :: store
    type(checkpoint_t) :: ck, back
    character(len=:), allocatable :: path, ckdir, victim
    logical :: gone
    ! the earlier programs' checkpoints: their own entries, no store
    call ck%put('main/counts', [1, 1, 37, 0])
    call ck%put('main/snapshots', [0.5_dp, 1.5_dp])
    if (comm%rank == 0) then
      call write_checkpoint(ck, trim(dir)//'/old_np'//int_text(comm%size), 1, 2, path, err)
      call stop_on(err)
    end if
    call barrier(comm)     ! the file is there before anyone reads it
    call latest_checkpoint(trim(dir)//'/old_np'//int_text(comm%size), path, err)
    call stop_on(err)
    call read_checkpoint(path, back, err)
    call stop_on(err)
    call check_snapshots_format(back, 'snapshots/', err)
    call refused('no store entries', 'written by an earlier version of the program')
    call new_store(store)
    call store%get(back, comm, 'snapshots/', err)
    call refused('no store entries (get)', 'written by an earlier version of the program')
    ! version 2: the rows held in the checkpoint itself
    call back%put('snapshots/version', 2)
    call back%put('snapshots/count', 0)
    call back%put('snapshots/columns', ncols)
    call back%put('snapshots/fields', 2)
    call check_snapshots_format(back, 'snapshots/', err)
    call refused('version 2', 'held the particle snapshots in the checkpoint')
    ! a later version of the entries
    call back%put('snapshots/version', snapshots_version + 1)
    call check_snapshots_format(back, 'snapshots/', err)
    call refused('another version', 'version '//int_text(snapshots_version + 1)// &
                 ', this program reads version '//int_text(snapshots_version))
    ! the right version, other fields
    call back%put('snapshots/version', snapshots_version)
    call back%put('snapshots/columns', ncols + 1)
    call store%get(back, comm, 'snapshots/', err)
    call refused('other fields', 'values per particle')
    ! a snapshot file truncated, then missing: refused, naming it
    ckdir = trim(dir)//'/damaged_np'//int_text(comm%size)
    call write_snapshots(trim(dir)//'/damaged_np'//int_text(comm%size)//'.h5', ckdir)
    call latest_checkpoint(ckdir, path, err)
    call stop_on(err)
    call read_checkpoint(path, ck, err)
    call stop_on(err)
    victim = ckdir//'/snapshots_0001_rank000000.bin'
    if (comm%rank == 0) call expect(truncate_file(victim), 'cannot truncate '//victim)
    call barrier(comm)
    call new_store(store)
    call store%keep_files(ckdir, .false.)
    call store%get(ck, comm, 'snapshots/', err)
    call refused('truncated file', '"'//victim//'" is truncated: it has 0 bytes')
    call barrier(comm)
    if (comm%rank == 0) then
      gone = remove_file(victim)
      call expect(gone, 'cannot remove '//victim)
    end if
    call barrier(comm)
    call store%get(ck, comm, 'snapshots/', err)
    call refused('missing file', '"'//victim//'" is missing')
  end subroutine old_format

  !> Checkpoint file `dir` (here a file) without its 'snapshots/' entries,
  !> into folder `arg` as checkpoint 1.
  subroutine downgrade()
    type(checkpoint_t) :: ck, old
    character(len=:), allocatable :: path
    integer :: k
    call read_checkpoint(trim(dir), ck, err)
    call stop_on(err)
    do k = 1, ck%n
      associate (e => ck%entries(k))
        if (index(e%name, 'snapshots/') == 1) cycle
        if (allocated(e%r)) then
          call old%put(e%name, e%r)
        else
          call old%put(e%name, e%i)
        end if
      end associate
    end do
    call write_checkpoint(old, trim(arg), 1, 1, path, err)
    call stop_on(err)
    write (output_unit, '(a)') path
  end subroutine downgrade

  subroutine refused(what, words)
    character(len=*), intent(in) :: what, words
    if (.not. allocated(err)) then
      call expect(.false., what//': not refused')
    else
      call expect(index(err%message, words) > 0, what//': refused with "'//err%message// &
                  '", expected "'//words//'"')
      if (comm%rank == 0 .and. index(err%message, words) > 0) write (output_unit, '(a)') &
        '  '//what//': refused: '//err%message
      deallocate (err)
    end if
  end subroutine refused

  subroutine expect(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (ok) return
    failures = failures + 1
    write (error_unit, '(a)') 'rank '//int_text(comm%rank)//': '//what
  end subroutine expect

  subroutine stop_on(e)
    type(error_t), allocatable, intent(in) :: e
    if (.not. allocated(e)) return
    write (error_unit, '(a)') 'rank '//int_text(comm%rank)//': '//e%message
    error stop 1
  end subroutine stop_on

end program parallel_snapshots_main
