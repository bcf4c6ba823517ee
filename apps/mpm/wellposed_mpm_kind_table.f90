!> The scene kinds wellposed-mpm runs, registered in one place: for the
!> deck's &scene kind (wellposed_mpm_scene_kind), the kind's memory
!> estimate, its --check (read and check, nothing run) and its run. A new
!> kind writes its files in mpm/kinds/<kind>/ and one line here
!> (docs/guide/mpm.md, "Scene kinds: what a new kind writes").
module wellposed_mpm_kind_table
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_scene_kind, only: scene_kind_bar, scene_kind_plate
  use wellposed_mpm_bar_memory, only: bar_deck_memory
  use wellposed_mpm_bar_checks, only: verify_bar_deck
  use wellposed_mpm_bar_run, only: run_bar
  use wellposed_mpm_plate_memory, only: plate_deck_memory
  use wellposed_mpm_plate_checks, only: verify_plate_deck
  use wellposed_mpm_plate_run, only: run_plate
  implicit none
  private
  public :: mpm_kind_entry_t, kind_entry

  abstract interface
    !> The estimate (bytes) and particle count of deck `path` with `overrides`.
    subroutine deck_memory_i(path, overrides, checkpoints, bytes, nparticles, err)
      import :: dp, error_t
      character(len=*), intent(in) :: path, overrides(:)
      logical, intent(in) :: checkpoints
      real(dp), intent(out) :: bytes, nparticles
      type(error_t), allocatable, intent(out) :: err
    end subroutine deck_memory_i
    !> Deck `path` with `overrides` read and checked as a run would.
    subroutine verify_deck_i(path, overrides, force, err)
      import :: error_t
      character(len=*), intent(in) :: path, overrides(:)
      logical, intent(in) :: force
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
    procedure(deck_memory_i), pointer, nopass :: memory => null()
    procedure(verify_deck_i), pointer, nopass :: verify => null()
    procedure(run_kind_i), pointer, nopass :: run => null()
  end type mpm_kind_entry_t

contains

  !> The entry of scene kind `kind` (an id of wellposed_mpm_scene_kind).
  function kind_entry(kind) result(entry)
    integer, intent(in) :: kind
    type(mpm_kind_entry_t) :: entry
    select case (kind)
    case (scene_kind_bar)
      entry = mpm_kind_entry_t(bar_deck_memory, verify_bar_deck, run_bar)
    case (scene_kind_plate)
      entry = mpm_kind_entry_t(plate_deck_memory, verify_plate_deck, run_plate)
    end select
  end function kind_entry

end module wellposed_mpm_kind_table
