!> The memory a wellposed-mpm deck needs, estimated before anything is
!> allocated, for wellposed_memory's check, from measured bytes per particle
!> (peak resident size against the particle count, nodes included at the
!> deck's own ratio; docs/guide/outputs.md says how), outputs on and off;
!> and the memory a run took per particle, measured, for its summary.
module wellposed_mpm_memory
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_memory, only: proc_bytes
  use wellposed_mpm_scene_kind, only: scene_kind_plate
  use wellposed_mpm_bar_config, only: bar_config_t
  use wellposed_mpm_bar_deck, only: read_bar_deck, bar_options_t
  use wellposed_mpm_plate_build, only: plate_config_t
  use wellposed_mpm_plate_deck, only: read_plate_deck, plate_study_t
  implicit none
  private
  public :: deck_memory, resident_start, resident_bytes_per_particle

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
    type(bar_config_t) :: cfg
    type(bar_options_t) :: opts
    type(plate_config_t) :: pcfg
    type(plate_study_t) :: study
    character(len=:), allocatable :: text
    integer :: ic
    real(dp) :: n
    logical :: outputs
    bytes = 0.0_dp
    nparticles = 0.0_dp
    if (kind == scene_kind_plate) then
      call read_plate_deck(path, overrides, pcfg, study, text, err)
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
      call read_bar_deck(path, overrides, cfg, opts, text, err)
      if (allocated(err)) return
      nparticles = anint(cfg%length/cfg%dx)*real(cfg%ppc, dp)
      outputs = checkpoints .or. cfg%snapshot_dt > 0.0_dp
      bytes = base_bytes + nparticles*merge(bar_out, bar_quiet, outputs)
    end if
  end subroutine deck_memory

  !> Note the resident size before anything of a run is allocated.
  subroutine resident_start()
    resident0 = proc_bytes('/proc/self/status', 'VmRSS')
  end subroutine resident_start

  !> What the run's buffers took per particle, all of them counted: the
  !> growth of this process's peak resident size (VmHWM) since
  !> resident_start, over its share `nparticles` of the particles (0 when
  !> /proc/self/status cannot be read).
  integer function resident_bytes_per_particle(nparticles) result(bytes)
    real(dp), intent(in) :: nparticles
    real(dp) :: peak
    bytes = 0
    peak = proc_bytes('/proc/self/status', 'VmHWM')
    if (peak < 0.0_dp .or. resident0 < 0.0_dp .or. nparticles < 1.0_dp) return
    bytes = nint(max(peak - resident0, 0.0_dp)/nparticles)
  end function resident_bytes_per_particle

end module wellposed_mpm_memory
