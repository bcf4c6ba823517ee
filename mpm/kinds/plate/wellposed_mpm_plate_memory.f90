!> The memory a plate deck needs, estimated before anything is allocated
!> (wellposed_mpm_memory): the particle count of its largest case (the
!> cases run one after another), and the bytes per particle measured for
!> a plate (four particles per cell, a quarter node each) with snapshots
!> or checkpoints on ('out') and with both off.
module wellposed_mpm_plate_memory
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_memory, only: deck_bytes
  use wellposed_mpm_plate_config, only: plate_config_t
  use wellposed_mpm_plate_deck, only: read_plate_deck, plate_study_t
  implicit none
  private
  public :: plate_deck_memory

  real(dp), parameter :: plate_out = 1700.0_dp, plate_quiet = 1310.0_dp

contains

  !> The estimate (bytes) and particle count of the plate deck of `cli`
  !> with its overrides, with checkpoints on or off.
  subroutine plate_deck_memory(cli, bytes, nparticles, err)
    type(mpm_cli_t), intent(in) :: cli
    real(dp), intent(out) :: bytes, nparticles
    type(error_t), allocatable, intent(out) :: err
    type(plate_config_t) :: cfg
    type(plate_study_t) :: study
    character(len=:), allocatable :: text
    integer :: ic
    real(dp) :: n
    bytes = 0.0_dp
    nparticles = 0.0_dp
    call read_plate_deck(cli%deck_path, cli%overrides, cli%kinds, cfg, study, text, err)
    if (allocated(err)) return
    do ic = 1, study%ncases
      n = anint(cfg%width*study%scale(ic)/study%dx(ic))* &
          anint(cfg%height*study%scale(ic)/study%dx(ic))*real(cfg%ppc, dp)**2
      nparticles = max(nparticles, n)
    end do
    bytes = deck_bytes(nparticles, plate_out, plate_quiet, &
                       cli%ck_every /= 0 .or. study%snapshot_dt > 0.0_dp)
  end subroutine plate_deck_memory

end module wellposed_mpm_plate_memory
