!> Checkpoints of a run: the set of named arrays of wellposed_checkpoint_set
!> written as one HDF5 file with a manifest, a Fletcher-64 checksum and a
!> `complete` flag, through a temporary name, and read back whole or not at
!> all: a damaged file gives an error naming it and what is wrong. Files
!> `<dir>/checkpoint_<step, 10 digits>.h5`, the newest `keep` kept. File
!> layout: docs/guide/parallel.md.
module wellposed_checkpoint
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_fs, only: make_dirs, remove_file, path_exists, shell_quote, process_id
  use wellposed_deck, only: read_text_file
  use wellposed_h5, only: h5_file_t
  use wellposed_h5_read, only: h5_reader_t
  use wellposed_checkpoint_set, only: checkpoint_t, entry_t, add_entry
  implicit none
  private
  public :: checkpoint_t, write_checkpoint, read_checkpoint, list_checkpoints, &
            latest_checkpoint, checkpoint_path, checkpoint_format

  character(len=*), parameter :: checkpoint_format = 'wellposed-checkpoint 1'

contains

  !> `<dir>/checkpoint_<step>.h5` (step with 10 digits, so names sort).
  pure function checkpoint_path(dir, step) result(path)
    character(len=*), intent(in) :: dir
    integer, intent(in) :: step
    character(len=:), allocatable :: path
    character(len=10) :: buf
    write (buf, '(i10.10)') step
    path = dir//'/checkpoint_'//buf//'.h5'
  end function checkpoint_path

  ! ---- the checksum: Fletcher-64 over 32-bit words (no overflow: int64
  ! sums reduced modulo 2**32 - 1 after every word).

  pure subroutine fletcher_words(words, s1, s2)
    integer(int32), intent(in) :: words(:)
    integer(int64), intent(inout) :: s1, s2
    integer(int64), parameter :: m = 4294967295_int64
    integer :: k
    do k = 1, size(words)
      s1 = mod(s1 + iand(int(words(k), int64), m), m)
      s2 = mod(s2 + s1, m)
    end do
  end subroutine fletcher_words

  pure subroutine fletcher_text(text, s1, s2)
    character(len=*), intent(in) :: text
    integer(int64), intent(inout) :: s1, s2
    integer :: k
    do k = 1, len(text)
      call fletcher_words([int(iachar(text(k:k)), int32)], s1, s2)
    end do
  end subroutine fletcher_text

  !> Checksum of the entries (names, kinds, lengths, data bits) as 16 hex digits.
  function entries_checksum(entries, n) result(hex)
    type(entry_t), intent(in) :: entries(:)
    integer, intent(in) :: n
    character(len=16) :: hex
    ! the data bits a chunk at a time: no copy of a whole array
    integer, parameter :: chunk = 1024
    integer(int64) :: s1, s2
    integer :: k, j, m
    integer(int32) :: w(2*chunk)
    s1 = 1_int64
    s2 = 0_int64
    do k = 1, n
      call fletcher_text(entries(k)%name, s1, s2)
      if (allocated(entries(k)%r)) then
        call fletcher_words([int(size(entries(k)%r), int32), 1_int32], s1, s2)
        do j = 1, size(entries(k)%r), chunk
          m = min(chunk, size(entries(k)%r) - j + 1)
          w(1:2*m) = transfer(entries(k)%r(j:j + m - 1), w, 2*m)
          call fletcher_words(w(1:2*m), s1, s2)
        end do
      else
        call fletcher_words([int(size(entries(k)%i), int32), 2_int32], s1, s2)
        if (size(entries(k)%i) > 0) call fletcher_words(int(entries(k)%i, int32), s1, s2)
      end if
    end do
    write (hex, '(z8.8,z8.8)') s2, s1
  end function entries_checksum

  !> Write `ckpt` as checkpoint `step` in folder `dir` (created if missing),
  !> atomically, then keep only the newest `keep` checkpoints of `dir`.
  !> `path` returns the file written.
  subroutine write_checkpoint(ckpt, dir, step, keep, path, err)
    type(checkpoint_t), intent(in) :: ckpt
    character(len=*), intent(in) :: dir
    integer, intent(in) :: step, keep
    character(len=:), allocatable, intent(out) :: path
    type(error_t), allocatable, intent(out) :: err
    type(h5_file_t) :: h5
    character(len=:), allocatable :: manifest
    character(len=24), allocatable :: all(:)
    integer :: k
    logical :: removed
    call make_dirs(dir, err)
    if (allocated(err)) return
    path = checkpoint_path(dir, step)
    call h5%create(path, err)
    if (allocated(err)) return
    manifest = ''
    do k = 1, ckpt%n
      associate (e => ckpt%entries(k))
        if (allocated(e%r)) then
          call h5%write('data/'//e%name, e%r)
          manifest = manifest//e%name//' real '//int_text(size(e%r))//new_line('a')
        else
          call h5%write('data/'//e%name, e%i)
          manifest = manifest//e%name//' integer '//int_text(size(e%i))//new_line('a')
        end if
      end associate
    end do
    call h5%write_attr('format', checkpoint_format)
    call h5%write_attr('manifest', manifest)
    call h5%write_attr('checksum', entries_checksum(ckpt%entries, ckpt%n))
    call h5%write_attr('complete', 'yes')
    call h5%close(err)
    if (allocated(err)) return
    call list_checkpoints(dir, all)
    do k = 1, size(all) - max(keep, 1)
      removed = remove_file(dir//'/'//trim(all(k)))
    end do
  end subroutine write_checkpoint

  !> Read checkpoint file `path` into `ckpt`, all of it or nothing (see the
  !> module comment). On error `ckpt` is empty and the message says which
  !> file is refused and why.
  subroutine read_checkpoint(path, ckpt, err)
    character(len=*), intent(in) :: path
    type(checkpoint_t), intent(out) :: ckpt
    type(error_t), allocatable, intent(out) :: err
    type(h5_reader_t) :: h5
    type(checkpoint_t) :: tmp
    type(entry_t) :: e
    character(len=:), allocatable :: text, manifest, line, kind, sum_stored, why
    character(len=256) :: name
    integer :: start, stop_, n, ios, k1, k2
    call h5%open(path, err)
    if (allocated(err)) then
      why = err%message
      call refuse(why)
      return
    end if
    call h5%attr_text('format', text, err)
    if (allocated(err)) then
      call refuse('no format attribute: not a wellposed checkpoint')
    else if (trim(text) /= checkpoint_format) then
      call refuse('format "'//trim(text)//'", this program reads "'//checkpoint_format//'"')
    end if
    if (.not. allocated(err)) then
      call h5%attr_text('complete', text, err)
      if (allocated(err)) then
        call refuse('no complete flag: the writer stopped before finishing it')
      else if (trim(text) /= 'yes') then
        call refuse('complete flag is "'//trim(text)//'"')
      end if
    end if
    if (.not. allocated(err)) then
      call h5%attr_text('manifest', manifest, err)
      if (allocated(err)) call refuse('no manifest')
    end if
    if (.not. allocated(err)) then
      call h5%attr_text('checksum', sum_stored, err)
      if (allocated(err)) call refuse('no checksum')
    end if
    if (allocated(err)) then
      call h5%close()
      return
    end if
    start = 1
    do while (start <= len(manifest))
      stop_ = index(manifest(start:), new_line('a'))
      if (stop_ == 0) stop_ = len(manifest) - start + 2
      line = manifest(start:start + stop_ - 2)
      start = start + stop_
      if (len_trim(line) == 0) cycle
      ! "name kind length" (not list-directed: a '/' in a name would end it)
      line = trim(adjustl(line))
      k1 = index(line, ' ')
      k2 = index(line, ' ', back=.true.)
      ios = 1
      if (k1 > 1 .and. k2 > k1) then
        name = line(1:k1 - 1)
        kind = trim(adjustl(line(k1 + 1:k2 - 1)))
        read (line(k2 + 1:), *, iostat=ios) n
      else
        kind = ''
      end if
      if (ios /= 0 .or. n < 0 .or. (kind /= 'real' .and. kind /= 'integer')) then
        call refuse('manifest line "'//line//'" is garbled')
        exit
      end if
      e%name = trim(name)
      if (allocated(e%r)) deallocate (e%r)
      if (allocated(e%i)) deallocate (e%i)
      if (kind == 'real') then
        allocate (e%r(n))
        call h5%read('data/'//e%name, e%r, err)
      else
        allocate (e%i(n))
        call h5%read('data/'//e%name, e%i, err)
      end if
      if (allocated(err)) then
        why = err%message
        call refuse(why)
        exit
      end if
      call add_entry(tmp, e)
    end do
    call h5%close()
    if (allocated(err)) return
    if (entries_checksum(tmp%entries, tmp%n) /= trim(sum_stored)) then
      call refuse('the data are damaged: checksum '//entries_checksum(tmp%entries, tmp%n)//' of the data read '// &
        'differs from the stored '//trim(sum_stored))
      return
    end if
    ckpt = tmp
  contains
    subroutine refuse(reason)
      character(len=*), intent(in) :: reason
      call new_error(err, status_invalid, path, 'checkpoint "'//path//'" is refused '// &
        '(damaged, truncated or not a checkpoint): '//reason)
    end subroutine refuse
  end subroutine read_checkpoint

  !> The checkpoint files of `dir` (base names, 24 characters), oldest first.
  subroutine list_checkpoints(dir, names)
    character(len=*), intent(in) :: dir
    character(len=24), allocatable, intent(out) :: names(:)
    character(len=:), allocatable :: listing, lst, name
    character(len=24), allocatable :: found(:)
    type(error_t), allocatable :: err
    integer :: estat, cstat, start, stop_
    logical :: removed
    allocate (found(0))
    if (path_exists(dir)) then
      lst = dir//'/.checkpoints.'//int_text(process_id())
      call execute_command_line('ls -1 '//shell_quote(dir)//' > '//shell_quote(lst)// &
        ' 2>/dev/null', exitstat=estat, cmdstat=cstat)
      if (cstat == 0 .and. estat == 0) then
        call read_text_file(lst, listing, err)
        if (.not. allocated(err)) then
          start = 1
          do while (start <= len(listing))
            stop_ = index(listing(start:), new_line('a'))
            if (stop_ == 0) stop_ = len(listing) - start + 2
            name = listing(start:start + stop_ - 2)
            start = start + stop_
            ! checkpoint_0000000123.h5 exactly: not the writer's .tmp files
            if (len(name) /= 24) cycle
            if (name(1:11) /= 'checkpoint_' .or. name(22:24) /= '.h5') cycle
            if (verify(name(12:21), '0123456789') /= 0) cycle
            found = [character(len=24) :: found, name]
          end do
        end if
      end if
      removed = remove_file(lst)
    end if
    call move_alloc(found, names)      ! ls sorts; the digits are fixed-width
  end subroutine list_checkpoints

  !> The newest checkpoint file of `dir`; an error when there is none.
  subroutine latest_checkpoint(dir, path, err)
    character(len=*), intent(in) :: dir
    character(len=:), allocatable, intent(out) :: path
    type(error_t), allocatable, intent(out) :: err
    character(len=24), allocatable :: names(:)
    call list_checkpoints(dir, names)
    if (size(names) == 0) then
      call new_error(err, status_invalid, dir, 'no checkpoint to restart from in "'//dir//'"')
      path = ''
      return
    end if
    path = dir//'/'//trim(names(size(names)))
  end subroutine latest_checkpoint

end module wellposed_checkpoint
