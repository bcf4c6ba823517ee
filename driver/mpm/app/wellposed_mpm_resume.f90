!> The checkpoint a --restart continues from, for every scene kind: the
!> newest of the run's checkpoint folder or the one --restart-from names,
!> read whole (checksums checked), its snapshot layout this program's, and
!> written for this very deck. Errors are returned as values.
module wellposed_mpm_resume
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_checkpoint, only: checkpoint_t, read_checkpoint, latest_checkpoint
  use wellposed_mpm_snapshots, only: check_snapshots_format
  use wellposed_deck, only: deck_essence
  implicit none
  private
  public :: open_restart_checkpoint

contains

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
        call fail(e%message//' (run with --checkpoint-every STEPS first)'); return
      end if
    end if
    call read_checkpoint(ck_file, ck, e)
    if (allocated(e)) then
      call fail(e%message//'; an older checkpoint of '//ck_dir// &
                ' may be given with --restart-from FILE'); return
    end if
    call check_snapshots_format(ck, 'snapshots/', e)
    if (allocated(e)) then
      call fail(ck_file//': '//e%message); return
    end if
    call ck%get_text('main/deck', saved, e)
    if (allocated(e)) then
      call fail(ck_file//': '//e%message); return
    end if
    if (deck_essence(saved) /= deck_essence(deck_text)) &
      call fail(ck_file//' was written for another deck than '//deck_path//': their '// &
                'namelist values differ (comments, spacing and letter case outside quotes '// &
                'do not count)')
  contains
    subroutine fail(text)
      character(len=*), intent(in) :: text
      call new_error(err, status_invalid, 'restart', text)
    end subroutine fail
  end subroutine open_restart_checkpoint

end module wellposed_mpm_resume
