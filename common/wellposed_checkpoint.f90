!> Checkpoints of a run: a set of named 1-D arrays (real(dp) or integer; a
!> text as its character codes) written as one HDF5 file with a manifest, a
!> Fletcher-64 checksum and a `complete` flag, through a temporary name, and
!> read back whole or not at all: a damaged file gives an error naming it and
!> what is wrong. Files `<dir>/checkpoint_<step, 10 digits>.h5`, the newest
!> `keep` kept. File layout: docs/guide/parallel.md.
module wellposed_checkpoint
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_fs, only: make_dirs, remove_file, path_exists, shell_quote, process_id
  use wellposed_deck, only: read_text_file
  use wellposed_h5, only: h5_file_t
  use wellposed_h5_read, only: h5_reader_t
  implicit none
  private
  public :: checkpoint_t, write_checkpoint, read_checkpoint, list_checkpoints, &
            latest_checkpoint, checkpoint_path, checkpoint_format

  character(len=*), parameter :: checkpoint_format = 'wellposed-checkpoint 1'

  type :: entry_t
    character(len=:), allocatable :: name
    real(dp), allocatable :: r(:)
    integer, allocatable :: i(:)
  end type entry_t

  !> Named arrays in the order they were put.
  type :: checkpoint_t
    type(entry_t), allocatable :: entries(:)
    integer :: n = 0
  contains
    procedure, private :: put_r1, put_i1, put_r0, put_i0
    !> put(name, values): a real(dp) or integer array or scalar.
    generic :: put => put_r1, put_i1, put_r0, put_i0
    procedure, private :: get_r1, get_i1, get_r0, get_i0
    !> get(name, values, err): the array (allocated to its length) or scalar.
    generic :: get => get_r1, get_i1, get_r0, get_i0
    procedure :: has => ckpt_has
    procedure :: put_moved => ckpt_put_moved
    !> put_text(name, text): a text as [0, its character codes].
    procedure :: put_text => ckpt_put_text
    !> get_text(name, text, err): the text put by put_text.
    procedure :: get_text => ckpt_get_text
  end type checkpoint_t

contains

  !> e into the set (replacing an entry of its name), its arrays moved, not
  !> copied: a checkpoint holds each array once (particle records are most
  !> of a run's memory at that moment).
  subroutine add_entry(self, e)
    class(checkpoint_t), intent(inout) :: self
    type(entry_t), intent(inout) :: e
    type(entry_t), allocatable :: grown(:)
    integer :: k
    if (.not. allocated(self%entries)) allocate (self%entries(16))
    do k = 1, self%n
      if (self%entries(k)%name == e%name) then
        call move_entry(e, self%entries(k))
        return
      end if
    end do
    if (self%n == size(self%entries)) then
      allocate (grown(2*self%n))
      do k = 1, self%n
        call move_entry(self%entries(k), grown(k))
      end do
      call move_alloc(grown, self%entries)
    end if
    self%n = self%n + 1
    call move_entry(e, self%entries(self%n))
  end subroutine add_entry

  !> to takes from's name and arrays (from's arrays deallocated).
  subroutine move_entry(from, to)
    type(entry_t), intent(inout) :: from, to
    call move_alloc(from%name, to%name)
    if (allocated(to%r)) deallocate (to%r)
    if (allocated(to%i)) deallocate (to%i)
    if (allocated(from%r)) call move_alloc(from%r, to%r)
    if (allocated(from%i)) call move_alloc(from%i, to%i)
  end subroutine move_entry

  subroutine put_r1(self, name, values)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    type(entry_t) :: e
    e%name = name
    e%r = values
    call add_entry(self, e)
  end subroutine put_r1

  !> put_moved(name, values): the array taken over without a copy (values
  !> is deallocated on return).
  subroutine ckpt_put_moved(self, name, values)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), allocatable, intent(inout) :: values(:)
    type(entry_t) :: e
    e%name = name
    call move_alloc(values, e%r)
    call add_entry(self, e)
  end subroutine ckpt_put_moved

  subroutine put_i1(self, name, values)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: values(:)
    type(entry_t) :: e
    e%name = name
    e%i = values
    call add_entry(self, e)
  end subroutine put_i1

  subroutine put_r0(self, name, value)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value
    call put_r1(self, name, [value])
  end subroutine put_r0

  subroutine put_i0(self, name, value)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    call put_i1(self, name, [value])
  end subroutine put_i0

  subroutine ckpt_put_text(self, name, text)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name, text
    integer :: k
    call put_i1(self, name, [0, (iachar(text(k:k)), k=1, len(text))])
  end subroutine ckpt_put_text

  subroutine ckpt_get_text(self, name, text, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: c(:)
    integer :: k
    call get_i1(self, name, c, err)
    if (allocated(err)) return
    if (size(c) >= 1) then
      if (c(1) == 0 .and. all(c(2:) >= 0 .and. c(2:) <= 255)) then
        allocate (character(len=size(c) - 1) :: text)
        do k = 2, size(c)
          text(k - 1:k - 1) = achar(c(k))
        end do
        return
      end if
    end if
    call new_error(err, status_invalid, name, 'checkpoint entry "'//name//'" is not a text')
  end subroutine ckpt_get_text

  integer function find(self, name) result(k)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    do k = 1, self%n
      if (self%entries(k)%name == name) return
    end do
    k = 0
  end function find

  logical function ckpt_has(self, name)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    ckpt_has = find(self, name) > 0
  end function ckpt_has

  subroutine missing(name, kind, err)
    character(len=*), intent(in) :: name, kind
    type(error_t), allocatable, intent(out) :: err
    call new_error(err, status_invalid, name, 'the checkpoint holds no '//kind//' array "'// &
      name//'" (written by another version of the program?)')
  end subroutine missing

  subroutine get_r1(self, name, values, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    real(dp), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    k = find(self, name)
    if (k > 0) then
      if (allocated(self%entries(k)%r)) then
        values = self%entries(k)%r
        return
      end if
    end if
    call missing(name, 'real', err)
  end subroutine get_r1

  subroutine get_i1(self, name, values, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    integer, allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    k = find(self, name)
    if (k > 0) then
      if (allocated(self%entries(k)%i)) then
        values = self%entries(k)%i
        return
      end if
    end if
    call missing(name, 'integer', err)
  end subroutine get_i1

  subroutine get_r0(self, name, value, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: value
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: v(:)
    call get_r1(self, name, v, err)
    if (allocated(err)) return
    if (size(v) /= 1) then
      call new_error(err, status_invalid, name, 'checkpoint entry "'//name//'" is not a scalar')
      return
    end if
    value = v(1)
  end subroutine get_r0

  subroutine get_i0(self, name, value, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: v(:)
    call get_i1(self, name, v, err)
    if (allocated(err)) return
    if (size(v) /= 1) then
      call new_error(err, status_invalid, name, 'checkpoint entry "'//name//'" is not a scalar')
      return
    end if
    value = v(1)
  end subroutine get_i0

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
