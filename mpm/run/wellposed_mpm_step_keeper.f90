!> The last complete step of a scene, for a run that ends at the step
!> before the one whose material gave out (&time stop_on_cutback). A copy
!> before every step is costly, so the keeper copies every `keep_every`
!> steps and, when a step fails, replays the steps since its copy:
!> `advance` is deterministic on any number of ranks, so the replayed scene
!> is bitwise the one the run had.
module wellposed_mpm_step_keeper
  use wellposed_error, only: error_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_solver, only: advance
  implicit none
  private
  public :: step_keeper_t

  !> Steps between copies: the copy's cost over 100 steps against at most
  !> 99 steps replayed once per case.
  integer, parameter :: keep_every = 100

  type :: step_keeper_t
    type(mpm_scene_t), allocatable :: copy
    integer :: last = -1   !< the step the scene had before the latest `keep`
  contains
    procedure :: clear => keeper_clear
    procedure :: keep => keeper_keep
    procedure :: restore => keeper_restore
  end type step_keeper_t

contains

  !> Forget the copy (a new case).
  subroutine keeper_clear(self)
    class(step_keeper_t), intent(inout) :: self
    if (allocated(self%copy)) deallocate (self%copy)
    self%last = -1
  end subroutine keeper_clear

  !> Call before every step: `sc` is complete.
  subroutine keeper_keep(self, sc)
    class(step_keeper_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    logical :: fresh
    fresh = .not. allocated(self%copy)
    if (.not. fresh) fresh = sc%nstep < self%copy%nstep
    if (fresh .or. mod(sc%nstep, keep_every) == 0) self%copy = sc
    self%last = sc%nstep
  end subroutine keeper_keep

  !> `sc` as it was at the latest `keep` (collective: the ranks replay the
  !> same steps). An error of a replayed step is returned (a defect: the
  !> step had passed).
  subroutine keeper_restore(self, sc, err)
    class(step_keeper_t), intent(inout) :: self
    type(mpm_scene_t), intent(inout) :: sc
    type(error_t), allocatable, intent(out) :: err
    sc = self%copy
    do while (sc%nstep < self%last)
      call advance(sc, err)
      if (allocated(err)) then
        err%message = 'replaying a step that had passed: '//err%message
        return
      end if
    end do
  end subroutine keeper_restore

end module wellposed_mpm_step_keeper
