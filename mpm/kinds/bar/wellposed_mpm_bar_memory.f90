!> The memory a bar deck needs, estimated before anything is allocated
!> (wellposed_mpm_memory): its particle count, and the bytes per particle
!> measured for a bar (two particles per cell, half a node each) with
!> snapshots or checkpoints on ('out') and with both off.
module wellposed_mpm_bar_memory
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_memory, only: deck_bytes
  use wellposed_mpm_bar_config, only: bar_config_t
  use wellposed_mpm_bar_deck, only: read_bar_deck, bar_options_t
  implicit none
  private
  public :: bar_deck_memory

  real(dp), parameter :: bar_out = 1200.0_dp, bar_quiet = 700.0_dp

contains

  !> The estimate (bytes) and particle count of the bar deck of `cli` with
  !> its overrides, with checkpoints on or off.
  subroutine bar_deck_memory(cli, bytes, nparticles, err)
    type(mpm_cli_t), intent(in) :: cli
    real(dp), intent(out) :: bytes, nparticles
    type(error_t), allocatable, intent(out) :: err
    type(bar_config_t) :: cfg
    type(bar_options_t) :: opts
    character(len=:), allocatable :: text
    bytes = 0.0_dp
    nparticles = 0.0_dp
    call read_bar_deck(cli%deck_path, cli%overrides, cli%kinds, cfg, opts, text, err)
    if (allocated(err)) return
    nparticles = anint(cfg%length/cfg%dx)*real(cfg%ppc, dp)
    bytes = deck_bytes(nparticles, bar_out, bar_quiet, &
                       cli%ck_every /= 0 .or. cfg%snapshot_dt > 0.0_dp)
  end subroutine bar_deck_memory

end module wellposed_mpm_bar_memory
