!> The memory check of every program: a deck's estimate (bytes, from the
!> program's measured bytes per particle or per increment) against the
!> machine's available memory (MemAvailable of /proc/meminfo) or the limit
!> of --max-memory SIZE; a deck over either is refused, naming the estimate
!> and the deck, before anything is allocated (docs/guide/outputs.md).
module wellposed_memory
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  implicit none
  private
  public :: check_memory, parse_memory, mem_available, memory_text, proc_bytes

contains

  !> Refuse (err) a deck whose estimate exceeds `limit` (bytes, from
  !> --max-memory; <= 0: none) or the machine's available memory; `ncount`
  !> `items` (particles, increments) sized it.
  subroutine check_memory(path, bytes, ncount, items, limit, err)
    character(len=*), intent(in) :: path, items
    real(dp), intent(in) :: bytes, ncount, limit
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: avail
    character(len=:), allocatable :: what
    if (ncount < 2.0e9_dp) then
      what = int_text(nint(ncount))
    else
      what = real_text(ncount)
    end if
    what = path//': the deck needs about '//memory_text(bytes)//' ('//what//' '//items//')'
    if (limit > 0.0_dp .and. bytes > limit) then
      call new_error(err, status_invalid, path, what//', more than --max-memory '// &
        memory_text(limit)//'; nothing was allocated')
      return
    end if
    avail = mem_available()
    if (avail > 0.0_dp .and. bytes > avail) then
      call new_error(err, status_invalid, path, what//', more than the machine has '// &
        'available ('//memory_text(avail)//', MemAvailable in /proc/meminfo); nothing '// &
        'was allocated')
    end if
  end subroutine check_memory

  !> MemAvailable of /proc/meminfo in bytes (-1 when it cannot be read).
  real(dp) function mem_available() result(avail)
    avail = proc_bytes('/proc/meminfo', 'MemAvailable')
  end function mem_available

  !> The line `key:  <n> kB` of a /proc file (meminfo, self/status) in
  !> bytes (-1 when absent).
  real(dp) function proc_bytes(file, key) result(bytes)
    character(len=*), intent(in) :: file, key
    integer :: unit, ios
    character(len=256) :: line
    real(dp) :: kb
    bytes = -1.0_dp
    open (newunit=unit, file=file, status='old', action='read', iostat=ios)
    if (ios /= 0) return
    do
      read (unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (index(line, key//':') /= 1) cycle
      read (line(len(key) + 2:), *, iostat=ios) kb
      if (ios == 0) bytes = kb*1024.0_dp
      exit
    end do
    close (unit)
  end function proc_bytes

  !> "4G", "512M", "800k" or a plain number of bytes (binary multiples);
  !> err for anything else.
  subroutine parse_memory(text, bytes, err)
    character(len=*), intent(in) :: text
    real(dp), intent(out) :: bytes
    type(error_t), allocatable, intent(out) :: err
    integer :: n, ios
    real(dp) :: scale
    bytes = 0.0_dp
    n = len_trim(text)
    scale = 1.0_dp
    if (n > 0) then
      select case (text(n:n))
      case ('k', 'K'); scale = 1024.0_dp
      case ('m', 'M'); scale = 1024.0_dp**2
      case ('g', 'G'); scale = 1024.0_dp**3
      case ('t', 'T'); scale = 1024.0_dp**4
      end select
      if (scale > 1.0_dp) n = n - 1
    end if
    ios = 1
    if (n > 0) then
      if (verify(text(1:n), '0123456789.') == 0) read (text(1:n), *, iostat=ios) bytes
    end if
    if (ios /= 0 .or. .not. bytes > 0.0_dp) then
      call new_error(err, status_invalid, '--max-memory', '--max-memory needs a size such '// &
        'as 4G, 512M or 800k, not "'//trim(text)//'"')
      return
    end if
    bytes = bytes*scale
  end subroutine parse_memory

  !> Bytes as "1.2 GiB", "340 MiB", "12 kiB".
  function memory_text(bytes) result(text)
    real(dp), intent(in) :: bytes
    character(len=:), allocatable :: text
    character(len=32) :: buf
    if (bytes >= 1024.0_dp**3) then
      write (buf, '(f0.1,a)') bytes/1024.0_dp**3, ' GiB'
    else if (bytes >= 1024.0_dp**2) then
      write (buf, '(i0,a)') nint(bytes/1024.0_dp**2), ' MiB'
    else
      write (buf, '(i0,a)') nint(bytes/1024.0_dp), ' kiB'
    end if
    text = trim(buf)
  end function memory_text

end module wellposed_memory
