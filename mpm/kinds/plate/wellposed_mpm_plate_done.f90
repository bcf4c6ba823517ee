!> The finished cases of a plate run (&study, wellposed_mpm_plate_cases):
!> what each left for the files written at the end (its curve, counts and
!> stations), which case runs now, the steps of the cases before it and
!> the summary lines so far. A component of the run loop that samples
!> nothing: it puts all that under 'cases/' in a checkpoint and gets it
!> back on --restart, before the case it interrupted is rebuilt.
module wellposed_mpm_plate_done
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_plate_deck, only: plate_study_t
  use wellposed_mpm_plate_cases, only: case_out_t, put_case_out, get_case_out
  use wellposed_mpm_plate_stations, only: plate_stations_t, restore_plate_stations
  use wellposed_mpm_output, only: mpm_output_t
  implicit none
  private
  public :: plate_done_t, checkpoint_case

  type, extends(mpm_output_t) :: plate_done_t
    type(case_out_t), allocatable :: outs(:)
    type(plate_stations_t), allocatable :: st(:)
    integer :: current = 1        !< the case running
    integer :: steps_before = 0   !< steps of the cases before it
    type(summary_t), pointer :: sm => null()
    type(plate_study_t) :: study
    real(dp) :: t_end = 0.0_dp
  contains
    procedure :: setup => done_setup
    procedure :: put => done_put
    procedure :: get => done_get
    procedure :: write_case => done_write_case
  end type plate_done_t

contains

  !> Room for the cases of `study` (each run to t_end); `sm` the run's summary.
  subroutine done_setup(self, study, t_end, sm)
    class(plate_done_t), intent(inout) :: self
    type(plate_study_t), intent(in) :: study
    real(dp), intent(in) :: t_end
    type(summary_t), target, intent(in) :: sm
    self%name = 'cases'
    self%study = study
    self%t_end = t_end
    self%sm => sm
    allocate (self%outs(study%ncases), self%st(study%ncases))
  end subroutine done_setup

  !> The case running, the steps before it, the finished cases and the
  !> summary lines (rank 0).
  subroutine done_put(self, ck, comm)
    class(plate_done_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    character(len=:), allocatable :: pre, lines
    integer :: k
    if (comm%rank /= 0) return
    call ck%put(self%name//'/current', self%current)
    call ck%put(self%name//'/steps_before', self%steps_before)
    do k = 1, self%current - 1
      pre = self%name//'/done_'//int_text(k)//'/'
      call put_case_out(ck, pre, self%outs(k))
      call self%st(k)%put(ck, pre//'stations/')
    end do
    lines = ''
    do k = 1, self%sm%n
      lines = lines//self%sm%lines(k)%text//new_line('a')
    end do
    call ck%put_text(self%name//'/summary', lines)
  end subroutine done_put

  !> The finished cases (every rank; stations on rank 0) and on rank 0 the
  !> summary lines; self%current must have been read (checkpoint_case).
  subroutine done_get(self, ck, comm, err)
    class(plate_done_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: pre, lines, line
    integer :: k, at, n, eq
    call ck%get(self%name//'/steps_before', self%steps_before, err); if (allocated(err)) return
    do k = 1, self%current - 1
      pre = self%name//'/done_'//int_text(k)//'/'
      call get_case_out(ck, pre, self%outs(k), err); if (allocated(err)) return
      call restore_plate_stations(self%st(k), self%study, self%t_end, comm, ck, &
                                  pre//'stations/', err)
      if (allocated(err)) return
    end do
    if (comm%rank /= 0) return
    call ck%get_text(self%name//'/summary', lines, err); if (allocated(err)) return
    at = 1
    do while (at <= len(lines))
      n = index(lines(at:), new_line('a'))
      line = lines(at:at + n - 2)
      at = at + n
      eq = index(line, ' = ')
      call self%sm%add(line(1:eq - 1), line(eq + 3:))
    end do
  end subroutine done_get

  !> The run.h5 datasets of finished case k beside its snapshots
  !> (collective; rank 0's values).
  subroutine done_write_case(self, h5, k)
    class(plate_done_t), intent(in) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    integer, intent(in) :: k
    associate (o => self%outs(k))
      call h5%write('cases/'//o%tag//'/curve', transpose(o%curve))
      call h5%write('cases/'//o%tag//'/iterations', o%its)
      call h5%write('cases/'//o%tag//'/n_plastic', o%nplast)
      call self%st(k)%write_h5(h5, 'cases/'//o%tag//'/stations/')
    end associate
  end subroutine done_write_case

  !> The case a checkpoint of a run of `ncases` cases interrupted.
  subroutine checkpoint_case(ck, ncases, ic, err)
    type(checkpoint_t), intent(in) :: ck
    integer, intent(in) :: ncases
    integer, intent(out) :: ic
    type(error_t), allocatable, intent(out) :: err
    call ck%get('cases/current', ic, err)
    if (allocated(err)) return
    if (ic < 1 .or. ic > ncases) call new_error(err, status_invalid, 'checkpoint', &
      'case '//int_text(ic)//' is not a case of this deck')
  end subroutine checkpoint_case

end module wellposed_mpm_plate_done
