!> The scene kinds wellposed-mpm runs, registered in one place, one line
!> each: what decks say of the kind (its &scene kind word, marking groups
!> and shared keys, wellposed_mpm_scene_kind), its memory estimate, its
!> --check (read and check, nothing run) and its run. A new kind writes
!> its files in mpm/kinds/<kind>/ and one line here (docs/guide/mpm.md,
!> "Scene kinds: what a new kind writes"). The first kind is the default.
module wellposed_mpm_kind_table
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_scene_kind, only: kind_words_t
  use wellposed_mpm_bar_deck, only: bar_words
  use wellposed_mpm_bar_memory, only: bar_deck_memory
  use wellposed_mpm_bar_checks, only: verify_bar_deck
  use wellposed_mpm_bar_run, only: run_bar
  use wellposed_mpm_plate_deck, only: plate_words
  use wellposed_mpm_plate_memory, only: plate_deck_memory
  use wellposed_mpm_plate_checks, only: verify_plate_deck
  use wellposed_mpm_plate_run, only: run_plate
  use wellposed_mpm_axisymmetric_deck, only: axi_words, axi_deck_memory, verify_axi_deck
  use wellposed_mpm_axisymmetric_run, only: run_axi
  implicit none
  private
  public :: mpm_kind_entry_t, scene_kinds

  abstract interface
    !> What decks say of the kind.
    pure function words_i() result(words)
      import :: kind_words_t
      type(kind_words_t) :: words
    end function words_i
    !> The estimate (bytes) and particle count of the deck of `cli` with
    !> its overrides (checkpoints on unless --checkpoint-every 0).
    subroutine deck_memory_i(cli, bytes, nparticles, err)
      import :: dp, error_t, mpm_cli_t
      type(mpm_cli_t), intent(in) :: cli
      real(dp), intent(out) :: bytes, nparticles
      type(error_t), allocatable, intent(out) :: err
    end subroutine deck_memory_i
    !> The deck of `cli` with its overrides read and checked as a run would.
    subroutine verify_deck_i(cli, err)
      import :: error_t, mpm_cli_t
      type(mpm_cli_t), intent(in) :: cli
      type(error_t), allocatable, intent(out) :: err
    end subroutine verify_deck_i
    !> The run of the deck and options of `cli` (collective).
    subroutine run_kind_i(cli, comm)
      import :: mpm_cli_t, comm_t
      type(mpm_cli_t), intent(in) :: cli
      type(comm_t), intent(inout) :: comm
    end subroutine run_kind_i
  end interface

  !> What the program calls for one scene kind.
  type :: mpm_kind_entry_t
    procedure(words_i), pointer, nopass :: words => null()
    procedure(deck_memory_i), pointer, nopass :: memory => null()
    procedure(verify_deck_i), pointer, nopass :: verify => null()
    procedure(run_kind_i), pointer, nopass :: run => null()
  end type mpm_kind_entry_t

contains

  !> Every scene kind, the default first; a deck without &scene kind is
  !> the first whose marking groups it has (the cylinder's &cylinder
  !> before the plate's &boundary, which a cylinder's deck has too).
  function scene_kinds() result(kinds)
    type(mpm_kind_entry_t), allocatable :: kinds(:)
    kinds = [mpm_kind_entry_t(bar_words, bar_deck_memory, verify_bar_deck, run_bar), &
             mpm_kind_entry_t(axi_words, axi_deck_memory, verify_axi_deck, run_axi), &
             mpm_kind_entry_t(plate_words, plate_deck_memory, verify_plate_deck, run_plate)]
  end function scene_kinds

end module wellposed_mpm_kind_table
