!> wellposed-mpm --check: a deck and its overrides read and checked as a
!> run reads and checks them before its set-up (every refusal at reading,
!> docs/guide/decks.md "Refused decks"), and nothing run or written: the
!> cheap form of a documented command (docs/guide/testing.md).
module wellposed_mpm_deck_verify
  use wellposed_error, only: error_t
  use wellposed_mpm_scene_kind, only: scene_kind_plate
  use wellposed_mpm_bar_config, only: bar_config_t
  use wellposed_mpm_plate_build, only: plate_config_t
  use wellposed_mpm_bar_deck, only: read_bar_deck, bar_options_t
  use wellposed_mpm_plate_deck, only: read_plate_deck, plate_study_t
  use wellposed_mpm_deck_checks, only: check_bar_deck, check_plate_deck
  implicit none
  private
  public :: verify_mpm_deck

contains

  !> Read deck `path` of scene kind `kind` with `overrides`, and check it
  !> (`force`: past the step limit); err as a run would report it.
  subroutine verify_mpm_deck(path, overrides, kind, force, err)
    character(len=*), intent(in) :: path, overrides(:)
    integer, intent(in) :: kind
    logical, intent(in) :: force
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: text
    type(bar_config_t) :: cfg
    type(bar_options_t) :: opts
    type(plate_config_t) :: cfg0
    type(plate_study_t) :: study
    if (kind == scene_kind_plate) then
      call read_plate_deck(path, overrides, cfg0, study, text, err)
      if (.not. allocated(err)) call check_plate_deck(path, cfg0, study, err, force)
    else
      call read_bar_deck(path, overrides, cfg, opts, text, err)
      if (.not. allocated(err)) call check_bar_deck(path, cfg, err, force)
    end if
  end subroutine verify_mpm_deck

end module wellposed_mpm_deck_verify
