!> The memory a wellposed-mpm deck needs, estimated before anything is
!> allocated, against what the machine has (MemAvailable of /proc/meminfo) or
!> the limit given by --max-memory: a deck over either is refused, naming the
!> estimate and the deck. The bytes per particle are measured (peak resident
!> size against the particle count, nodes included at the deck's own ratio;
!> docs/guide/outputs.md says how), with outputs on and off.
module wellposed_mpm_memory
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_scene_kind, only: scene_kind_plate
  use wellposed_mpm_config, only: mpm_config_t
  use wellposed_mpm_deck, only: read_mpm_deck, mpm_options_t
  use wellposed_mpm_plane_strain, only: ps_config_t
  use wellposed_mpm_ps_deck, only: read_ps_deck, ps_study_t
  implicit none
  private
  public :: deck_memory, check_memory, parse_memory, mem_available, memory_text, &
            resident_start, resident_bytes_per_particle

  !> Measured: the program without particles, and the bytes per particle of
  !> a bar (two particles per cell, half a node each) and of a plate (four
  !> per cell, a quarter node each), with snapshots or checkpoints on
  !> ('out') and with both off.
  real(dp), parameter :: base_bytes = 30.0e6_dp
  real(dp), parameter :: bar_out = 3430.0_dp, bar_quiet = 1420.0_dp
  real(dp), parameter :: plate_out = 2900.0_dp, plate_quiet = 1310.0_dp
  !> The resident size when the program started (bytes; resident_start).
  real(dp), save :: resident0 = -1.0_dp

contains

  !> The estimate (bytes) and particle count of the deck at `path` with
  !> `overrides`, for the scene `kind`, with checkpoints on or off.
  subroutine deck_memory(path, overrides, kind, checkpoints, bytes, nparticles, err)
    character(len=*), intent(in) :: path, overrides(:)
    integer, intent(in) :: kind
    logical, intent(in) :: checkpoints
    real(dp), intent(out) :: bytes, nparticles
    type(error_t), allocatable, intent(out) :: err
    type(mpm_config_t) :: cfg
    type(mpm_options_t) :: opts
    type(ps_config_t) :: pcfg
    type(ps_study_t) :: study
    character(len=:), allocatable :: text
    integer :: ic
    real(dp) :: n
    logical :: outputs
    bytes = 0.0_dp
    nparticles = 0.0_dp
    if (kind == scene_kind_plate) then
      call read_ps_deck(path, overrides, pcfg, study, text, err)
      if (allocated(err)) return
      ! the cases run one after another: the largest one counts
      do ic = 1, study%ncases
        n = anint(pcfg%width*study%scale(ic)/study%dx(ic))* &
            anint(pcfg%height*study%scale(ic)/study%dx(ic))*real(pcfg%ppc, dp)**2
        nparticles = max(nparticles, n)
      end do
      outputs = checkpoints .or. study%snapshot_dt > 0.0_dp
      bytes = base_bytes + nparticles*merge(plate_out, plate_quiet, outputs)
    else
      call read_mpm_deck(path, overrides, cfg, opts, text, err)
      if (allocated(err)) return
      nparticles = anint(cfg%length/cfg%dx)*real(cfg%ppc, dp)
      outputs = checkpoints .or. cfg%snapshot_dt > 0.0_dp
      bytes = base_bytes + nparticles*merge(bar_out, bar_quiet, outputs)
    end if
  end subroutine deck_memory

  !> Refuse (err) a deck whose estimate exceeds `limit` (bytes, from
  !> --max-memory; <= 0: none) or the machine's available memory.
  subroutine check_memory(path, bytes, nparticles, limit, err)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: bytes, nparticles, limit
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: avail
    character(len=:), allocatable :: what
    if (nparticles < 2.0e9_dp) then
      what = int_text(nint(nparticles))
    else
      what = real_text(nparticles)
    end if
    what = path//': the deck needs about '//memory_text(bytes)//' ('//what//' particles)'
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
    integer :: unit, ios
    character(len=256) :: line
    real(dp) :: kb
    avail = -1.0_dp
    open (newunit=unit, file='/proc/meminfo', status='old', action='read', iostat=ios)
    if (ios /= 0) return
    do
      read (unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (index(line, 'MemAvailable:') /= 1) cycle
      read (line(14:), *, iostat=ios) kb
      if (ios == 0) avail = kb*1024.0_dp
      exit
    end do
    close (unit)
  end function mem_available

  !> A line `key:  <n> kB` of /proc/self/status in bytes (-1 if absent).
  real(dp) function status_bytes(key) result(bytes)
    character(len=*), intent(in) :: key
    integer :: unit, ios
    character(len=256) :: line
    real(dp) :: kb
    bytes = -1.0_dp
    open (newunit=unit, file='/proc/self/status', status='old', action='read', iostat=ios)
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
  end function status_bytes

  !> Note the resident size before anything of a run is allocated.
  subroutine resident_start()
    resident0 = status_bytes('VmRSS')
  end subroutine resident_start

  !> What the run's buffers took per particle, all of them counted: the
  !> growth of this process's peak resident size (VmHWM) since
  !> resident_start, over its share `nparticles` of the particles (0 when
  !> /proc/self/status cannot be read).
  integer function resident_bytes_per_particle(nparticles) result(bytes)
    real(dp), intent(in) :: nparticles
    real(dp) :: peak
    bytes = 0
    peak = status_bytes('VmHWM')
    if (peak < 0.0_dp .or. resident0 < 0.0_dp .or. nparticles < 1.0_dp) return
    bytes = nint(max(peak - resident0, 0.0_dp)/nparticles)
  end function resident_bytes_per_particle

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

end module wellposed_mpm_memory
