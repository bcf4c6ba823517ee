!> Particle snapshots and the progress line as outputs of the run loop
!> (wellposed_mpm_output), the parts every scene kind shares: a snapshot
!> output keeps its store (wellposed_mpm_snapshots) and its cadence and
!> puts both under 'snapshots/'; a kind says which rows a snapshot holds
!> and when one is due. A progress output keeps the run's wall clock, its
!> time before a restart under 'progress/'; a kind says what it prints.
module wellposed_mpm_snapshot_output
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_snapshots, only: snapshot_store_t
  use wellposed_mpm_output, only: mpm_output_t
  use wellposed_mpm_run_loop, only: run_clock_t
  implicit none
  private
  public :: snapshot_output_t, progress_output_t

  !> Snapshots of the particles into run.h5 (`h5`, kept by the run).
  type, abstract, extends(mpm_output_t) :: snapshot_output_t
    type(snapshot_store_t) :: store
    type(h5_parallel_file_t), pointer :: h5 => null()
    integer :: taken = 0             !< snapshots of this case so far
    real(dp) :: next = 0.0_dp        !< the next scheduled snapshot time (s)
    real(dp) :: interval = 0.0_dp    !< between snapshots (s; <= 0: none scheduled)
  contains
    procedure(rows_i), deferred :: rows
    procedure :: take => snapshot_take
    procedure :: last_due => snapshot_last_due
    procedure :: put => snapshot_put
    procedure :: get => snapshot_get
  end type snapshot_output_t

  abstract interface
    !> The group of snapshot self%taken and this rank's rows of it.
    subroutine rows_i(self, sc, group, rows)
      import :: snapshot_output_t, mpm_scene_t, dp
      class(snapshot_output_t), intent(in) :: self
      type(mpm_scene_t), intent(in) :: sc
      character(len=:), allocatable, intent(out) :: group
      real(dp), allocatable, intent(out) :: rows(:, :)
    end subroutine rows_i
  end interface

  !> The run's wall clock and its progress line every `interval` seconds.
  type, abstract, extends(mpm_output_t) :: progress_output_t
    type(run_clock_t) :: clock
    real(dp) :: before = 0.0_dp      !< wall time before the restart (s)
  contains
    procedure :: wall => progress_wall
    procedure :: put => progress_put
    procedure :: get => progress_get
  end type progress_output_t

contains

  !> The run's last state wants a snapshot of its own: none was scheduled,
  !> or the last scheduled one lies more than half a step back.
  pure logical function snapshot_last_due(self, sc) result(due)
    class(snapshot_output_t), intent(in) :: self
    type(mpm_scene_t), intent(in) :: sc
    due = self%interval <= 0.0_dp .or. self%next - self%interval < sc%t - 0.5_dp*sc%dt
  end function snapshot_last_due

  !> A snapshot now (collective): every rank its own particles' rows.
  subroutine snapshot_take(self, sc, comm, err)
    class(snapshot_output_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: group
    real(dp), allocatable :: rows(:, :)
    self%taken = self%taken + 1
    call self%rows(sc, group, rows)
    call self%store%take(self%h5, comm, group, sc%t, sc%parts%gid(1:sc%parts%n), rows, err)
  end subroutine snapshot_take

  !> The store (how far every rank's snapshot file reached) and the cadence.
  subroutine snapshot_put(self, ck, comm)
    class(snapshot_output_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    call self%store%put(ck, comm, self%name//'/')
    if (comm%rank /= 0) return
    call ck%put(self%name//'/taken', self%taken)
    call ck%put(self%name//'/next', self%next)
  end subroutine snapshot_put

  !> The store (its files checked) and the cadence; the snapshots are not
  !> written again here (the kind knows in which order).
  subroutine snapshot_get(self, ck, comm, err)
    class(snapshot_output_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%store%get(ck, comm, self%name//'/', err); if (allocated(err)) return
    call ck%get(self%name//'/taken', self%taken, err); if (allocated(err)) return
    call ck%get(self%name//'/next', self%next, err)
  end subroutine snapshot_get

  !> Wall time of the run's loop so far, restarts included (s).
  real(dp) function progress_wall(self)
    class(progress_output_t), intent(in) :: self
    progress_wall = self%before + self%clock%elapsed()
  end function progress_wall

  subroutine progress_put(self, ck, comm)
    class(progress_output_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (comm%rank == 0) call ck%put(self%name//'/wall', self%wall())
  end subroutine progress_put

  subroutine progress_get(self, ck, comm, err)
    class(progress_output_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call ck%get(self%name//'/wall', self%before, err)
  end subroutine progress_get

end module wellposed_mpm_snapshot_output
