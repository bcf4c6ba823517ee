!> The checkpoints of an MPM run, for every scene kind: every STEPS steps
!> the scene (wellposed_mpm_restart) and every output of the run, each
!> under its own name, into ROOT/NAME.checkpoints (the newest two kept);
!> on --restart the newest one, or the one --restart-from names, read
!> whole, checked to be of this deck, and given back to the scene and the
!> outputs. A finished run removes the folder unless --keep-checkpoints.
!> File layout and entries: docs/guide/parallel.md.
module wellposed_mpm_checkpoints
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpi, only: comm_t
  use wellposed_checkpoint, only: checkpoint_t, read_checkpoint, latest_checkpoint, &
                                  write_checkpoint
  use wellposed_mpm_snapshots, only: check_snapshots_format
  use wellposed_mpm_restart, only: save_scene, restore_scene
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_output, only: output_list_t
  use wellposed_mpm_stop, only: stop_alone
  use wellposed_run_dir, only: run_dir_t
  use wellposed_deck, only: deck_essence
  use wellposed_fs, only: path_exists, remove_tree
  implicit none
  private
  public :: run_checkpoints_t, new_run_checkpoints, open_restart_checkpoint

  !> Where and how often a run checkpoints, and on --restart the checkpoint
  !> it continues from (`ck`, read on every rank).
  type :: run_checkpoints_t
    character(len=:), allocatable :: dir        !< ROOT/NAME.checkpoints
    character(len=:), allocatable :: file       !< the checkpoint continued from, or ''
    character(len=:), allocatable :: deck_text  !< the deck as read, for the restart's check
    integer :: every = 0                        !< steps between checkpoints (0: none)
    !> steps of the run's earlier cases, so that the file names grow over a deck
    integer :: steps_before = 0
    type(checkpoint_t) :: ck
    type(run_dir_t), pointer :: rd => null()    !< for an error writing one
  contains
    procedure :: write => checkpoints_write
    procedure :: open => checkpoints_open
    procedure :: resume => checkpoints_resume
    procedure :: finish => checkpoints_finish
  end type run_checkpoints_t

  !> Checkpoints kept in the folder (the newest ones).
  integer, parameter :: keep_newest = 2

contains

  !> Checkpoints of run NAME under ROOT, every `every` steps (0: none),
  !> continuing from `file` on --restart (''; the newest).
  function new_run_checkpoints(root, name, every, file, deck_text, rd) result(self)
    character(len=*), intent(in) :: root, name, file, deck_text
    integer, intent(in) :: every
    type(run_dir_t), target, intent(in) :: rd
    type(run_checkpoints_t) :: self
    self%dir = root//'/'//name//'.checkpoints'
    self%every = every
    self%file = file
    self%deck_text = deck_text
    self%rd => rd
  end function new_run_checkpoints

  !> The run's state after this step (collective; rank 0 writes): the
  !> scene, then every output of `outs` under its name, then the deck.
  subroutine checkpoints_write(self, sc, outs, comm)
    class(run_checkpoints_t), intent(inout) :: self
    type(mpm_scene_t), intent(inout) :: sc
    type(output_list_t), intent(inout) :: outs
    type(comm_t), intent(inout) :: comm
    type(checkpoint_t) :: ck
    type(error_t), allocatable :: e
    character(len=:), allocatable :: path
    call save_scene(sc, ck)
    call outs%put(ck, comm)
    if (comm%rank /= 0) return
    call ck%put_text('run/deck', self%deck_text)
    call write_checkpoint(ck, self%dir, self%steps_before + sc%nstep, keep_newest, path, e)
    if (allocated(e)) call stop_alone(comm, self%rd, e%message)
  end subroutine checkpoints_write

  !> --restart: read the checkpoint to continue from into self%ck (every
  !> rank; self%file names it on return).
  subroutine checkpoints_open(self, deck_path, err)
    class(run_checkpoints_t), intent(inout) :: self
    character(len=*), intent(in) :: deck_path
    type(error_t), allocatable, intent(out) :: err
    call open_restart_checkpoint(self%dir, deck_path, self%deck_text, self%file, self%ck, err)
  end subroutine checkpoints_open

  !> --restart, in the case the checkpoint interrupted: the scene and every
  !> output of `outs` as they were (every rank).
  subroutine checkpoints_resume(self, sc, outs, comm, err)
    class(run_checkpoints_t), intent(inout) :: self
    type(mpm_scene_t), intent(inout) :: sc
    type(output_list_t), intent(inout) :: outs
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call restore_scene(sc, self%ck, err)
    if (.not. allocated(err)) call outs%get(self%ck, comm, err)
    if (allocated(err)) err%message = self%file//': '//err%message
  end subroutine checkpoints_resume

  !> The run is complete (rank 0): its checkpoints have served, and go
  !> unless `keep` (--keep-checkpoints). A folder left is only a warning.
  subroutine checkpoints_finish(self, keep)
    class(run_checkpoints_t), intent(inout) :: self
    logical, intent(in) :: keep
    type(error_t), allocatable :: e
    if (keep .or. .not. path_exists(self%dir)) return
    call remove_tree(self%dir, e)
    if (allocated(e)) write (error_unit, '(a)') 'wellposed-mpm: warning: '//e%message
  end subroutine checkpoints_finish

  !> Read into ck the checkpoint ck_file (when '' on entry: the newest of
  !> ck_dir, whose path ck_file is on return) and check that it was written
  !> for deck_text (the deck deck_path as read, overrides aside), compared
  !> as their namelists read them (deck_essence: comments do not count).
  subroutine open_restart_checkpoint(ck_dir, deck_path, deck_text, ck_file, ck, err)
    character(len=*), intent(in) :: ck_dir, deck_path, deck_text
    character(len=:), allocatable, intent(inout) :: ck_file
    type(checkpoint_t), intent(out) :: ck
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    character(len=:), allocatable :: saved
    if (len(ck_file) == 0) then
      call latest_checkpoint(ck_dir, ck_file, e)
      if (allocated(e)) then
        call refuse_restart(err, e%message//' (run with --checkpoint-every STEPS first)'); return
      end if
    end if
    call read_checkpoint(ck_file, ck, e)
    if (allocated(e)) then
      call refuse_restart(err, e%message//'; an older checkpoint of '//ck_dir// &
                          ' may be given with --restart-from FILE'); return
    end if
    ! where the particle snapshot files of this checkpoint are (wellposed_mpm_snapshots)
    call ck%put_text('run/read_from', ck_file(1:max(index(ck_file, '/', back=.true.) - 1, 0)))
    if (index(ck_file, '/') == 0) call ck%put_text('run/read_from', '.')
    call check_snapshots_format(ck, 'snapshots/', e)
    if (allocated(e)) then
      call refuse_restart(err, ck_file//': '//e%message); return
    end if
    call ck%get_text('run/deck', saved, e)
    if (allocated(e)) then
      call refuse_restart(err, ck_file//': '//e%message//' (a checkpoint of an earlier '// &
                          'version of this program: restart is from this version''s '// &
                          'checkpoints only)'); return
    end if
    if (deck_essence(saved) /= deck_essence(deck_text)) &
      call refuse_restart(err, ck_file//' was written for another deck than '//deck_path// &
                          ': their namelist values differ (comments, spacing and letter '// &
                          'case outside quotes do not count)')
  end subroutine open_restart_checkpoint

  !> The refusal of a restart, and why.
  subroutine refuse_restart(err, text)
    type(error_t), allocatable, intent(inout) :: err
    character(len=*), intent(in) :: text
    call new_error(err, status_invalid, 'restart', text)
  end subroutine refuse_restart

end module wellposed_mpm_checkpoints
