!> `--batch FILE` of the drivers: the jobs of a batch file (wellposed_batch)
!> shared over the ranks of an MPI run, each job its own process, and one
!> summary. The batch folder `<out_root>/<batch file name>/` is written as
!> `<...>.partial/` and renamed when every job has ended (failed jobs
!> included: the summary says which failed and why); it holds a copy of the
!> batch file, every job's folder, log and record, batch_summary.txt and
!> batch_summary.csv. Collective over `comm`.
module wellposed_batch_run
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t, barrier, allreduce_any, broadcast
  use wellposed_batch, only: batch_job_t, read_batch, run_batch_jobs, write_batch_summary
  use wellposed_run_dir, only: run_dir_t
  implicit none
  private
  public :: run_batch, batch_name, default_figures

contains

  !> The summary.txt figures a batch summary shows for a driver, by the
  !> driver's executable name (none for an unknown driver).
  function default_figures(driver) result(figures)
    character(len=*), intent(in) :: driver
    character(len=64), allocatable :: figures(:)
    character(len=:), allocatable :: base
    base = driver(index(driver, '/', back=.true.) + 1:)
    select case (base)
    case ('wellposed-mpm')
      figures = [character(len=64) :: 'steps', 'particles', 'c_head', 'c_tail', &
                 'peak_growth', 'energy_balance_error']
    case ('wellposed-point')
      figures = [character(len=64) :: 'n_materials', 'wall_time_s']
    case default
      allocate (figures(0))
    end select
  end function default_figures

  !> The batch folder's name: the batch file's base name without extension.
  pure function batch_name(path) result(name)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: name
    integer :: slash, dot
    slash = index(path, '/', back=.true.)
    name = path(slash + 1:)
    dot = index(name, '.', back=.true.)
    if (dot > 1) name = name(1:dot - 1)
    if (len(name) == 0) name = 'batch'
  end function batch_name

  !> Run the batch file `batch_path` with `command` (the driver executable
  !> and fixed options, shell-quoted) on every rank's share of the jobs,
  !> then summarise on rank 0 and print the summary there. `nfailed` (on
  !> every rank) counts the jobs that failed; `err` is for the batch itself
  !> (unreadable batch file, no output folder).
  subroutine run_batch(comm, batch_path, command, out_root, figures, nfailed, err)
    type(comm_t), intent(in) :: comm
    character(len=*), intent(in) :: batch_path, command, out_root
    character(len=*), intent(in) :: figures(:)
    integer, intent(out) :: nfailed
    type(error_t), allocatable, intent(out) :: err
    type(batch_job_t), allocatable :: jobs(:)
    type(run_dir_t) :: rd
    character(len=:), allocatable :: report, dir
    logical :: bad
    nfailed = 0
    call read_batch(batch_path, jobs, err)
    if (allocated(err)) return            ! every rank reads the same file
    if (comm%rank == 0) then
      call rd%create(out_root, batch_name(batch_path), batch_path, err)
      if (.not. allocated(err)) then
        write (output_unit, '(a)') 'batch '//batch_path//': '//int_text(size(jobs))// &
          ' jobs on '//int_text(comm%size)//' rank(s), writing '//rd%partial
        flush (output_unit)
      end if
    end if
    bad = allocated(err)
    call broadcast(comm, bad, 0)
    if (bad) then
      if (.not. allocated(err)) call new_error(err, status_invalid, 'batch', &
        'rank 0 could not create the batch folder')
      return
    end if
    ! the same folder name on every rank (run_dir_t's rule: <root>/<name>.partial)
    dir = trim(out_root)
    if (len(dir) == 0) dir = '.'
    dir = dir//'/'//batch_name(batch_path)//'.partial'
    call run_batch_jobs(jobs, command, dir, comm%rank, comm%size, err)
    bad = allreduce_any(comm, allocated(err))
    if (bad) then
      if (.not. allocated(err)) call new_error(err, status_invalid, 'batch', &
        'another rank could not run its jobs')
      return
    end if
    call barrier(comm)
    if (comm%rank == 0) then
      call write_batch_summary(jobs, batch_path, dir, figures, nfailed, report, err)
      if (.not. allocated(err)) call rd%commit(err)
      if (.not. allocated(err)) then
        write (output_unit, '(a)', advance='no') report
        write (output_unit, '(a)') 'batch summary: '//rd%final//'/batch_summary.txt and '// &
          'batch_summary.csv'
        flush (output_unit)
      end if
    end if
    bad = allocated(err)
    call broadcast(comm, bad, 0)
    call broadcast(comm, nfailed, 0)
    if (bad .and. .not. allocated(err)) call new_error(err, status_invalid, 'batch', &
      'rank 0 could not write the batch summary')
  end subroutine run_batch

end module wellposed_batch_run
