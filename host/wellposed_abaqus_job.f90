!> The job facts Abaqus' utility routines report to a UMAT (GETOUTDIR,
!> GETJOBNAME) and an error a UMAT raised through STDB_ABQERR (LOP = -2),
!> which the UMAT host turns into its verdict after the call. One job per
!> process, as in Abaqus: the drivers set it once when the run folder exists.
module wellposed_abaqus_job
  use, intrinsic :: iso_fortran_env, only: error_unit
  implicit none
  private
  public :: abaqus_abort, abaqus_put, abaqus_set_job, abaqus_outdir, abaqus_jobname, abaqus_raise, abaqus_take_error

  character(len=:), allocatable :: outdir_  ! output folder of the running job
  character(len=:), allocatable :: jobname_ ! name of the running job
  character(len=:), allocatable :: pending_ ! an error raised during the current call

contains

  !> End the run now, as Abaqus' XIT does: `why` on standard error, exit
  !> status 3; the run folder stays <name>.partial (nothing looks finished).
  !> A plain STOP (no backtrace: the UMAT's own message says why); under
  !> mpirun a rank ending without MPI_Finalize ends the whole job.
  subroutine abaqus_abort(why)
    character(len=*), intent(in) :: why
    write (error_unit, '(a)') 'wellposed: '//why//'; the run stops here and its output '// &
      'stays unfinished (<name>.partial)'
    stop 3
  end subroutine abaqus_abort

  !> The running job's output folder (where a UMAT may write its own files)
  !> and name.
  subroutine abaqus_set_job(outdir, jobname)
    character(len=*), intent(in) :: outdir, jobname
    outdir_ = outdir
    jobname_ = jobname
  end subroutine abaqus_set_job

  !> The output folder ('.' before a driver sets one).
  function abaqus_outdir() result(dir)
    character(len=:), allocatable :: dir
    dir = set_or(outdir_, '.')
  end function abaqus_outdir

  !> The job name ('wellposed' before a driver sets one).
  function abaqus_jobname() result(name)
    character(len=:), allocatable :: name
    name = set_or(jobname_, 'wellposed')
  end function abaqus_jobname

  !> `text` into the caller's fixed-length `out` and its length `n` (cut
  !> to len(out)), as GETOUTDIR and GETJOBNAME return them.
  pure subroutine abaqus_put(text, out, n)
    character(len=*), intent(in) :: text
    character(len=*), intent(out) :: out
    integer, intent(out) :: n
    out = text
    n = min(len(text), len(out))
  end subroutine abaqus_put

  !> `value` when set, else `default`.
  pure function set_or(value, default) result(text)
    character(len=:), allocatable, intent(in) :: value
    character(len=*), intent(in) :: default
    character(len=:), allocatable :: text
    text = default
    if (allocated(value)) text = value
  end function set_or

  !> Record an error of the UMAT being called (the first one of a call wins).
  subroutine abaqus_raise(message)
    character(len=*), intent(in) :: message
    if (.not. allocated(pending_)) pending_ = message
  end subroutine abaqus_raise

  !> Hand over (and clear) the error raised during the last call; `message`
  !> is left unallocated when there was none.
  subroutine abaqus_take_error(message)
    character(len=:), allocatable, intent(out) :: message
    if (allocated(pending_)) call move_alloc(pending_, message)
  end subroutine abaqus_take_error

end module wellposed_abaqus_job
