!> Batch runs of a driver: a batch file names one job per line (a deck path
!> and optional driver arguments; `#` or `!` comments). Every job runs as its
!> own process, so a failing job cannot take the batch with it; job k writes
!> into `<dir>/jobs/k/`, `k.log` and `k.result`. Jobs are shared over ranks
!> round-robin (the caller passes rank and size; no MPI here), and
!> `write_batch_summary` writes batch_summary.txt and .csv.
!> File format and outcomes: docs/guide/parallel.md.
module wellposed_batch
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text
  use wellposed_fs, only: make_dirs, path_exists, shell_quote
  use wellposed_checked_io, only: out_file_t
  use wellposed_deck, only: read_text_file, lower
  implicit none
  private
  public :: batch_job_t, read_batch, run_batch_jobs, run_one_job, write_batch_summary, &
            job_tag, read_key_values, clean_mpi_environment

  !> One line of a batch file.
  type :: batch_job_t
    integer :: line = 0                         !< line number in the batch file
    character(len=:), allocatable :: deck       !< deck path as resolved
    character(len=:), allocatable :: args       !< further arguments, blank-separated
  end type batch_job_t

  !> A shell prefix that removes Open MPI's and PMIx's launch variables, so
  !> that a job started from inside an mpirun is a fresh singleton rather
  !> than a confused member of the parent's job (OMPI_ALLOW_RUN_AS_ROOT* stay).
  character(len=*), parameter :: clean_mpi_environment = &
    'for v in $(env | sed -n ''s/^\(OMPI_[A-Za-z0-9_]*\|PMIX_[A-Za-z0-9_]*\)=.*/\1/p''); '// &
    'do case $v in OMPI_ALLOW_RUN_AS_ROOT*) ;; *) unset "$v";; esac; done; '

contains

  !> Read the jobs of batch file `path`: one per non-blank line after
  !> comments (# or ! to the end of the line) are removed. An empty batch,
  !> or a missing file, is an error.
  subroutine read_batch(path, jobs, err)
    character(len=*), intent(in) :: path
    type(batch_job_t), allocatable, intent(out) :: jobs(:)
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: text, line, folder, word, deck
    integer :: start, stop_, lineno, c, k
    type(batch_job_t) :: job
    call read_text_file(path, text, err)
    if (allocated(err)) then
      err%message = 'batch file: '//err%message
      return
    end if
    folder = ''
    k = index(path, '/', back=.true.)
    if (k > 0) folder = path(1:k)
    allocate (jobs(0))
    start = 1
    lineno = 0
    do while (start <= len(text))
      stop_ = index(text(start:), new_line('a'))
      if (stop_ == 0) then
        stop_ = len(text) + 1
      else
        stop_ = start + stop_ - 1
      end if
      line = text(start:stop_ - 1)
      start = stop_ + 1
      lineno = lineno + 1
      c = scan(line, '#!')
      if (c > 0) line = line(1:c - 1)
      line = trim(adjustl(untab(line)))
      if (len(line) == 0) cycle
      k = index(line, ' ')
      if (k == 0) k = len(line) + 1
      deck = line(1:k - 1)
      line = line(k:)
      if (deck(1:1) /= '/' .and. len(folder) > 0) then
        if (path_exists(folder//deck)) deck = folder//deck
      end if
      job%line = lineno
      job%deck = deck
      job%args = ''
      do while (len_trim(line) > 0)
        line = adjustl(line)
        k = index(line, ' ')
        if (k == 0) k = len(line) + 1
        word = line(1:k - 1)
        line = line(k:)
        job%args = trim(adjustl(job%args//' '//word))
      end do
      jobs = [jobs, job]
    end do
    if (size(jobs) == 0) then
      call new_error(err, status_invalid, path, 'batch file "'//path//'" names no job '// &
        '(one deck per line; # and ! start comments)')
    end if
  contains
    pure function untab(s) result(r)
      character(len=*), intent(in) :: s
      character(len=len(s)) :: r
      integer :: i
      r = s
      do i = 1, len(r)
        if (r(i:i) == achar(9) .or. r(i:i) == achar(13)) r(i:i) = ' '
      end do
    end function untab
  end subroutine read_batch

  !> Blank-separated words, each single-quoted for the shell, each after a blank.
  pure function quoted_words(words) result(q)
    character(len=*), intent(in) :: words
    character(len=:), allocatable :: q, rest
    integer :: k
    q = ''
    rest = trim(adjustl(words))
    do while (len(rest) > 0)
      k = index(rest, ' ')
      if (k == 0) k = len(rest) + 1
      q = q//' '//shell_quote(rest(1:k - 1))
      rest = trim(adjustl(rest(k:)))
    end do
  end function quoted_words

  !> "0007": job numbers as fixed-width text, so folders sort in order.
  pure function job_tag(k) result(tag)
    integer, intent(in) :: k
    character(len=:), allocatable :: tag
    character(len=12) :: buf
    write (buf, '(i4.4)') k
    tag = trim(buf)
  end function job_tag

  !> Run this rank's share of `jobs` (job k when mod(k-1, nranks) == rank),
  !> one after the other, each as `command --out <dir>/jobs/k DECK ARGS`;
  !> `command` is the driver executable and its fixed options, ready for
  !> the shell. Errors only for what stops the whole batch (no folder).
  subroutine run_batch_jobs(jobs, command, dir, rank, nranks, err)
    type(batch_job_t), intent(in) :: jobs(:)
    character(len=*), intent(in) :: command, dir
    integer, intent(in) :: rank, nranks
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    call make_dirs(dir//'/jobs', err)
    if (allocated(err)) return
    do k = 1, size(jobs)
      if (mod(k - 1, nranks) /= rank) cycle
      call run_one_job(jobs(k), k, command, dir, rank, err)
      if (allocated(err)) return
    end do
  end subroutine run_batch_jobs

  !> Run job k and record its outcome in <dir>/jobs/k.result.
  subroutine run_one_job(job, k, command, dir, rank, err)
    type(batch_job_t), intent(in) :: job
    integer, intent(in) :: k
    character(len=*), intent(in) :: command, dir
    integer, intent(in) :: rank
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: jobdir, log, cmd, status, message, run
    character(len=512) :: cmsg
    integer :: estat, cstat
    integer(int64) :: c0, c1, rate
    real(dp) :: wall
    jobdir = dir//'/jobs/'//job_tag(k)
    log = jobdir//'.log'
    call make_dirs(jobdir, err)
    if (allocated(err)) return
    cmd = clean_mpi_environment//command//' --out '//shell_quote(jobdir)//' '// &
          shell_quote(job%deck)//quoted_words(job%args)//' > '//shell_quote(log)// &
          ' 2>&1 < /dev/null'
    estat = -1
    cstat = 0
    cmsg = ''
    call system_clock(c0, rate)
    call execute_command_line(cmd, wait=.true., exitstat=estat, cmdstat=cstat, cmdmsg=cmsg)
    call system_clock(c1)
    wall = real(c1 - c0, dp)/real(rate, dp)
    run = ''
    message = ''
    if (cstat /= 0) then
      status = 'failed'
      message = 'could not start the job: '//trim(cmsg)
    else if (estat /= 0) then
      status = 'failed'
      message = last_error_line(log)
    else
      run = finished_run(jobdir)
      if (len(run) == 0) then
        status = 'failed'
        message = 'exit status 0 but no finished run folder with a summary.txt in '//jobdir
      else
        status = 'ok'
        run = 'jobs/'//job_tag(k)//'/'//run     ! relative to the batch folder
      end if
    end if
    call write_result(dir//'/jobs/'//job_tag(k)//'.result', err)
  contains
    subroutine write_result(path, e)
      character(len=*), intent(in) :: path
      type(error_t), allocatable, intent(out) :: e
      type(out_file_t) :: out
      character(len=32) :: wbuf
      call out%open(path, e)
      if (allocated(e)) return
      write (wbuf, '(f14.3)') wall
      call out%put('job = '//int_text(k))
      call out%put('line = '//int_text(job%line))
      call out%put('deck = '//job%deck)
      call out%put('args = '//job%args)
      call out%put('status = '//status)
      call out%put('exit_code = '//int_text(estat))
      call out%put('wall_time = '//trim(adjustl(wbuf)))
      call out%put('rank = '//int_text(rank))
      call out%put('run_dir = '//run)       ! relative to the batch folder
      call out%put('log = '//log)
      call out%put('error = '//message)
      call out%close(e)
    end subroutine write_result
  end subroutine run_one_job

  !> The finished run folder the driver left in `jobdir` (a subfolder with
  !> a summary.txt, not a .partial one), by name, or '' when there is none.
  function finished_run(jobdir) result(run)
    character(len=*), intent(in) :: jobdir
    character(len=:), allocatable :: run
    character(len=:), allocatable :: listing, name
    type(error_t), allocatable :: err
    integer :: estat, cstat, start, stop_
    run = ''
    call execute_command_line('ls -1 '//shell_quote(jobdir)//' > '// &
      shell_quote(jobdir//'.ls')//' 2>/dev/null', exitstat=estat, cmdstat=cstat)
    if (cstat /= 0 .or. estat /= 0) return
    call read_text_file(jobdir//'.ls', listing, err)
    if (allocated(err)) return
    start = 1
    do while (start <= len(listing))
      stop_ = index(listing(start:), new_line('a'))
      if (stop_ == 0) stop_ = len(listing) - start + 2
      name = listing(start:start + stop_ - 2)
      start = start + stop_
      if (len(name) == 0) cycle
      if (index(name, '.partial') > 0) cycle
      if (path_exists(jobdir//'/'//name//'/summary.txt')) then
        run = name
        return
      end if
    end do
  end function finished_run

  !> The last line of a job's log that mentions an error (else its last
  !> non-blank line), for the summary: what went wrong, in the driver's words.
  function last_error_line(log) result(line)
    character(len=*), intent(in) :: log
    character(len=:), allocatable :: line
    character(len=:), allocatable :: text, cur
    type(error_t), allocatable :: err
    integer :: start, stop_
    character(len=:), allocatable :: last_any
    line = ''
    last_any = 'the job failed without a message'
    call read_text_file(log, text, err)
    if (allocated(err)) return
    start = 1
    do while (start <= len(text))
      stop_ = index(text(start:), new_line('a'))
      if (stop_ == 0) stop_ = len(text) - start + 2
      cur = trim(text(start:start + stop_ - 2))
      start = start + stop_
      if (len(cur) == 0) cycle
      last_any = cur
      if (index(lower(cur), 'error') > 0 .and. index(cur, 'Error termination') == 0 .and. &
          index(cur, 'ERROR STOP') == 0) line = cur
    end do
    if (len(line) == 0) line = last_any
    if (len(line) > 400) line = line(1:400)//' ...'
  end function last_error_line

  !> The `key = value` lines of a summary.txt or job record: keys(i) and
  !> values(i) (value without its `# comment`; keys up to 256 characters,
  !> values up to 1024). A missing file gives none.
  subroutine read_key_values(path, keys, values)
    character(len=*), intent(in) :: path
    character(len=256), allocatable, intent(out) :: keys(:)
    character(len=1024), allocatable, intent(out) :: values(:)
    character(len=:), allocatable :: text, cur, k, v
    character(len=256), allocatable :: kk(:)
    character(len=1024), allocatable :: vv(:)
    type(error_t), allocatable :: err
    integer :: start, stop_, eq, c
    allocate (kk(0), vv(0))
    call read_text_file(path, text, err)
    if (.not. allocated(err)) then
      start = 1
      do while (start <= len(text))
        stop_ = index(text(start:), new_line('a'))
        if (stop_ == 0) stop_ = len(text) - start + 2
        cur = text(start:start + stop_ - 2)
        start = start + stop_
        eq = index(cur, ' = ')
        if (eq == 0) cycle
        k = trim(adjustl(cur(1:eq - 1)))
        v = cur(eq + 3:)
        c = index(v, '  # ')
        if (c > 0) v = v(1:c - 1)
        kk = [character(len=256) :: kk, k]
        vv = [character(len=1024) :: vv, v]
      end do
    end if
    call move_alloc(kk, keys)
    call move_alloc(vv, values)
  end subroutine read_key_values

  !> Value of `key` among keys/values, '' when absent.
  function lookup(keys, values, key) result(v)
    character(len=*), intent(in) :: keys(:), values(:), key
    character(len=:), allocatable :: v
    integer :: i
    v = ''
    do i = 1, size(keys)
      if (trim(keys(i)) == key) then
        v = trim(values(i))
        return
      end if
    end do
  end function lookup

  !> After every job of `jobs` has run (on whatever rank): read the job
  !> records in <dir>/jobs/ and the `figures` (summary.txt keys) of each
  !> finished run, and write <dir>/batch_summary.txt and
  !> <dir>/batch_summary.csv (both through temporary names). `nfailed`
  !> counts failed and lost jobs; `report` is the text summary, for the
  !> terminal.
  subroutine write_batch_summary(jobs, batch_path, dir, figures, nfailed, report, err)
    type(batch_job_t), intent(in) :: jobs(:)
    character(len=*), intent(in) :: batch_path, dir
    character(len=*), intent(in) :: figures(:)
    integer, intent(out) :: nfailed
    character(len=:), allocatable, intent(out) :: report
    type(error_t), allocatable, intent(out) :: err
    character(len=256), allocatable :: rk(:), sk(:)
    character(len=1024), allocatable :: rv(:), sv(:)
    character(len=:), allocatable :: csv, status, wall, run, msg, line, nl, val
    integer :: k, f, nok
    nl = new_line('a')
    nfailed = 0
    nok = 0
    csv = 'job,line,deck,args,status,exit_code,wall_time_s,rank,run_dir'
    do f = 1, size(figures)
      csv = csv//','//trim(figures(f))
    end do
    csv = csv//',error'//nl
    report = ''
    do k = 1, size(jobs)
      call read_key_values(dir//'/jobs/'//job_tag(k)//'.result', rk, rv)
      status = lookup(rk, rv, 'status')
      if (len(status) == 0) then
        status = 'lost'
        msg = 'no record: the rank that ran it stopped before writing one'
      else
        msg = lookup(rk, rv, 'error')
      end if
      wall = lookup(rk, rv, 'wall_time')
      run = lookup(rk, rv, 'run_dir')
      if (status == 'ok') then
        nok = nok + 1
      else
        nfailed = nfailed + 1
      end if
      line = 'job '//job_tag(k)//'  '//status//repeat(' ', max(0, 7 - len(status)))// &
             '  '//wall//' s  '//trim(jobs(k)%deck//' '//jobs(k)%args)
      csv = csv//int_text(k)//','//int_text(jobs(k)%line)//','//csv_field(jobs(k)%deck)//','// &
            csv_field(jobs(k)%args)//','//status//','// &
            lookup(rk, rv, 'exit_code')//','//wall//','//lookup(rk, rv, 'rank')//','// &
            csv_field(run)
      if (status == 'ok') then
        call read_key_values(dir//'/'//run//'/summary.txt', sk, sv)
        line = line//nl//'    -> '//run
        do f = 1, size(figures)
          val = lookup(sk, sv, trim(figures(f)))
          csv = csv//','//csv_field(val)
          if (len(val) > 0) line = line//nl//'    '//trim(figures(f))//' = '//val
        end do
      else
        do f = 1, size(figures)
          csv = csv//','
        end do
        line = line//nl//'    error: '//msg
      end if
      csv = csv//','//csv_field(msg)//nl
      report = report//line//nl
    end do
    report = 'batch '//batch_path//': '//int_text(size(jobs))//' jobs, '//int_text(nok)// &
             ' ok, '//int_text(nfailed)//' failed'//nl//report
    call write_text(dir//'/batch_summary.txt', report)
    if (allocated(err)) return
    call write_text(dir//'/batch_summary.csv', csv)
  contains
    subroutine write_text(path, text)
      character(len=*), intent(in) :: path, text
      type(out_file_t) :: out
      call out%open(path, err)
      if (allocated(err)) return
      call out%put_bytes(text)
      call out%close(err)
    end subroutine write_text
  end subroutine write_batch_summary

  !> A CSV field, quoted when it holds a comma, a quote or a blank.
  pure function csv_field(s) result(f)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: f
    integer :: i
    if (scan(s, ',"'' ') == 0) then
      f = s
      return
    end if
    f = '"'
    do i = 1, len(s)
      if (s(i:i) == '"') then
        f = f//'""'
      else
        f = f//s(i:i)
      end if
    end do
    f = f//'"'
  end function csv_field

end module wellposed_batch
