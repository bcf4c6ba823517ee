!> The memory a wellposed-mpm deck needs, estimated before anything is
!> allocated, for wellposed_memory's check, from the kind's measured bytes
!> per particle (peak resident size against the particle count, nodes
!> included at the deck's own ratio; docs/guide/outputs.md says how),
!> outputs on and off; and the memory a run took per particle, measured,
!> for its summary.
module wellposed_mpm_memory
  use wellposed_kinds, only: dp
  use wellposed_memory, only: proc_bytes
  implicit none
  private
  public :: deck_bytes, resident_start, resident_bytes_per_particle

  !> Measured: the program without particles (each kind measures its bytes
  !> per particle: wellposed_mpm_bar_memory, wellposed_mpm_plate_memory).
  real(dp), parameter :: base_bytes = 30.0e6_dp
  !> The resident size when the program started (bytes; resident_start).
  real(dp), save :: resident0 = -1.0_dp

contains

  !> The estimate (bytes) of a deck of `nparticles` particles (its largest
  !> case's) that takes `per_out` bytes a particle with outputs on, `per_quiet`
  !> with them off (the kind's measured numbers).
  pure real(dp) function deck_bytes(nparticles, per_out, per_quiet, outputs) result(bytes)
    real(dp), intent(in) :: nparticles, per_out, per_quiet
    logical, intent(in) :: outputs
    bytes = base_bytes + nparticles*merge(per_out, per_quiet, outputs)
  end function deck_bytes

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
