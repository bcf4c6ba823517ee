!> Test program of wellposed_h5_parallel: the same particle fields (known
!> functions of the global id) and rank-0 data written by the serial writer
!> (`serial DIR`), on every rank in each row order (`write DIR`), through the
!> error paths (`error DIR`) and timed (`bench DIR N`).
!> check_parallel_h5.py compares the files with the reference bitwise.
!> Modes and files: docs/research/verification.md.
program parallel_h5_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, barrier, allreduce_max, &
                           allreduce_min, broadcast, gatherv_real
  use wellposed_h5, only: h5_file_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_row_order_t, new_row_order, &
                                   h5_uses_mpio, order_redistribute, order_points, &
                                   order_hyperslabs
  use wellposed_fs, only: make_dirs, path_exists, int_text
  use wellposed_run_dir, only: run_dir_t
  implicit none

  integer, parameter :: n_time = 37, n_stat = 5
  type(comm_t) :: comm
  type(error_t), allocatable :: err
  character(len=:), allocatable :: mode, dir
  integer :: n, status
  logical :: rows_collective   !< every row write of put_all was collective

  call comm_start(comm, err)
  if (allocated(err)) then
    write (error_unit, '(a)') err%message
    error stop 1
  end if
  if (command_argument_count() < 2) then
    if (comm%rank == 0) write (error_unit, '(a)') &
      'usage: parallel_h5_main serial|write|error|bench DIR [N [REPS]]'
    call comm_stop(comm)
    error stop 2
  end if
  mode = arg(1)
  dir = arg(2)
  n = 1037
  if (command_argument_count() >= 3) n = int_arg(3)
  if (comm%rank == 0) call make_dirs(dir, err)
  call barrier(comm)
  status = 0
  select case (mode)
  case ('serial')
    call write_reference()
  case ('write')
    call write_contiguous()
    call write_ordered('redistribute', order_redistribute)
    call write_ordered('points', order_points)
    call write_ordered('hyperslabs', order_hyperslabs)
    if (comm%rank == 0) write (output_unit, '(a)') 'wrote '//int_text(n)//' rows on '// &
      int_text(comm%size)//' ranks, MPI-IO: '//merge('yes', 'no ', h5_uses_mpio(comm))
  case ('error')
    call error_cases()
  case ('bench')
    call bench()
  case default
    if (comm%rank == 0) write (error_unit, '(a)') 'unknown mode "'//mode//'"'
    status = 2
  end select
  call comm_stop(comm)
  if (status /= 0) error stop status

contains

  function arg(i) result(text)
    integer, intent(in) :: i
    character(len=:), allocatable :: text
    integer :: length
    call get_command_argument(i, length=length)
    allocate (character(len=length) :: text)
    call get_command_argument(i, text)
  end function arg

  integer function int_arg(i) result(value)
    integer, intent(in) :: i
    character(len=:), allocatable :: text
    text = arg(i)
    read (text, *) value
  end function int_arg

  ! ---- the fields, as functions of the global id g (1..n)

  !> A 1-column field with all 52 mantissa bits in use. Only correctly
  !> rounded operations (no libm), so every rank and every vectorised or
  !> scalar loop computes the same bits.
  elemental real(dp) function field_x(g)
    integer, intent(in) :: g
    field_x = 0.25_dp*g + 1.0_dp/(real(g, dp) + 0.5_dp)
  end function field_x

  !> Column c of the 2-column field (as field_x: exact arithmetic only).
  elemental real(dp) function field_xy(g, c)
    integer, intent(in) :: g, c
    field_xy = real(c, dp)*g/3.0_dp - 1.0_dp/real(g + 7*c, dp)
  end function field_xy

  elemental integer function field_status(g)
    integer, intent(in) :: g
    field_status = mod(7*g, 5) - 2
  end function field_status

  !> The rank-0 data and attributes every file carries.
  subroutine root_data(times, hist, props, deck)
    real(dp), allocatable, intent(out) :: times(:), hist(:, :), props(:)
    character(len=:), allocatable, intent(out) :: deck
    integer :: i, j
    allocate (times(n_time), hist(n_time, n_stat), props(14))
    times = [(1.0e-4_dp*i, i=1, n_time)]
    hist = reshape([((sin(real(i*j, dp)), i=1, n_time), j=1, n_stat)], [n_time, n_stat])
    props = [(1.5_dp**i, i=1, 14)]
    deck = '&scene name = ''test'' /'//new_line('a')//'&grid dx = 0.25 /'
  end subroutine root_data

  ! ---- the serial program's file

  subroutine write_reference()
    type(h5_file_t) :: h5
    real(dp), allocatable :: times(:), hist(:, :), props(:), xy(:, :)
    character(len=:), allocatable :: deck
    integer :: g, c
    if (comm%rank /= 0) return
    call root_data(times, hist, props, deck)
    allocate (xy(n, 2))
    do c = 1, 2
      xy(:, c) = field_xy([(g, g=1, n)], c)
    end do
    call h5%create(dir//'/reference.h5', err)
    if (allocated(err)) call die(err%message)
    call h5%write_attr('deck', deck)
    call h5%write_attr('version', '0.1.0')
    call h5%write_attr('empty', '')
    call h5%write_attr('props', props)
    call h5%write('stations/time', times)
    call h5%write('stations/hist', hist)
    call h5%write('snapshots/count', [3, 1, 4])
    call h5%write('snapshots/snap_1/x', field_x([(g, g=1, n)]))
    call h5%write('snapshots/snap_1/xy', xy)
    call h5%write('snapshots/snap_1/status', field_status([(g, g=1, n)]))
    call h5%write('snapshots/snap_1/id', [(g, g=1, n)])
    call h5%close(err)
    if (allocated(err)) call die(err%message)
  end subroutine write_reference

  ! ---- the same through wellposed_h5_parallel

  !> Rank q holds a block of rows proportional to q + 1 (rank 2 none).
  subroutine write_contiguous()
    type(h5_parallel_file_t) :: f
    integer, allocatable :: w(:), gids(:)
    integer :: q, first, count
    allocate (w(0:comm%size - 1))
    w = [(q + 1, q=0, comm%size - 1)]
    if (comm%size >= 3) w(2) = 0
    first = 1 + (n*sum(w(0:comm%rank - 1)))/sum(w)
    count = (n*sum(w(0:comm%rank)))/sum(w) + 1 - first
    gids = [(first + q, q=0, count - 1)]
    call f%create(comm, dir//'/contiguous.h5', err)
    if (allocated(err)) call die(err%message)
    call put_all(f, gids)
    call f%close(err)
    if (allocated(err)) call die(err%message)
    call report('contiguous', f)
  end subroutine write_contiguous

  !> How the file's particle rows were written (after put_all): through
  !> MPI-IO, and whether HDF5 did every row transfer collectively.
  subroutine report(name, f)
    character(len=*), intent(in) :: name
    type(h5_parallel_file_t), intent(in) :: f
    integer :: all_collective
    all_collective = merge(1, 0, f%last_collective .and. rows_collective)
    call allreduce_min(comm, all_collective)
    if (comm%rank == 0) write (output_unit, '(a)') name//': MPI-IO '// &
      trim(merge('yes', 'no ', f%mpio))//', collective row transfers '// &
      trim(merge('yes', 'no ', all_collective == 1))
  end subroutine report

  !> Rows in runs of five scattered over the ranks, each rank's in
  !> reverse id order, written in id order by `method`.
  subroutine write_ordered(name, method)
    character(len=*), intent(in) :: name
    integer, intent(in) :: method
    type(h5_parallel_file_t) :: f
    type(h5_row_order_t) :: order
    integer, allocatable :: gids(:)
    call scattered_ids(gids)
    call new_row_order(comm, gids, order, err, method)
    if (allocated(err)) call die(err%message)
    call f%create(comm, dir//'/'//name//'.h5', err)
    if (allocated(err)) call die(err%message)
    call put_all(f, gids, order)
    call f%close(err)
    if (allocated(err)) call die(err%message)
    call report(name, f)
  end subroutine write_ordered

  !> This rank's ids: runs of 5 dealt round the ranks with a stride that
  !> skips, in reverse order.
  subroutine scattered_ids(gids)
    integer, allocatable, intent(out) :: gids(:)
    integer :: g
    gids = pack([(g, g=n, 1, -1)], &
                mod(([(g, g=n, 1, -1)] - 1)/5 + ([(g, g=n, 1, -1)] - 1)/17, comm%size) == comm%rank)
  end subroutine scattered_ids

  !> Every dataset and attribute of the reference, in the same order.
  subroutine put_all(f, gids, order)
    type(h5_parallel_file_t), intent(inout) :: f
    integer, intent(in) :: gids(:)
    type(h5_row_order_t), intent(in), optional :: order
    real(dp), allocatable :: times(:), hist(:, :), props(:), xy(:, :)
    character(len=:), allocatable :: deck
    integer :: c
    call root_data(times, hist, props, deck)
    if (comm%rank /= 0) then
      ! only rank 0's values count: the others pass something else
      deallocate (times, hist, props)
      allocate (times(0), hist(0, 0), props(1))
      props = -1.0_dp
      deck = 'not this'
    end if
    allocate (xy(size(gids), 2))
    do c = 1, 2
      xy(:, c) = field_xy(gids, c)
    end do
    call f%write_attr('deck', deck)
    call f%write_attr('version', '0.1.0')
    call f%write_attr('empty', '')
    call f%write_attr('props', props)
    call f%write('stations/time', times)
    call f%write('stations/hist', hist)
    call f%write('snapshots/count', [3, 1, 4])
    rows_collective = .true.
    call f%write_rows('snapshots/snap_1/x', field_x(gids), order)
    rows_collective = rows_collective .and. f%last_collective
    call f%write_rows('snapshots/snap_1/xy', xy, order)
    rows_collective = rows_collective .and. f%last_collective
    call f%write_rows('snapshots/snap_1/status', field_status(gids), order)
    rows_collective = rows_collective .and. f%last_collective
    call f%write_rows('snapshots/snap_1/id', gids, order)
  end subroutine put_all

  ! ---- error paths

  subroutine error_cases()
    type(h5_parallel_file_t) :: f
    type(h5_row_order_t) :: order
    type(run_dir_t) :: rd
    integer :: u, g
    integer, allocatable :: gids(:)
    real(dp), allocatable :: a(:, :)
    character(len=:), allocatable :: path, folder
    character(len=1024) :: left_behind(2)
    ! 1. a path under a regular file: cannot be created, on any rank
    if (comm%rank == 0) then
      open (newunit=u, file=dir//'/plain_file', status='replace', action='write')
      write (u, '(a)') 'not a folder'
      close (u)
    end if
    call barrier(comm)
    path = dir//'/plain_file/run.h5'
    call f%create(comm, path, err)
    call expect_failure('unwritable path', [path])
    ! 2. a failure after some datasets (a dataset written twice), in a run
    !    folder: the error reaches every rank, no run.h5 (nor its temporary
    !    file) is left, and the folder stays <name>.partial
    folder = ''
    if (comm%rank == 0) then
      call rd%create(dir, 'failed_run', dir//'/plain_file', err)
      if (allocated(err)) call die(err%message)
      folder = rd%partial
    end if
    call broadcast(comm, folder, 0)
    call f%create(comm, folder//'/run.h5', err)
    if (allocated(err)) call die(err%message)
    call f%write_attr('version', '0.1.0')
    call f%write_rows('x', [(real(g, dp), g=1, 10)])
    call f%write_rows('x', [(real(g, dp), g=1, 10)])
    call f%write_rows('y', [(real(g, dp), g=1, 10)])
    call f%close(err)
    left_behind(1) = folder//'/run.h5'
    left_behind(2) = dir//'/failed_run'
    call expect_failure('dataset written twice', left_behind)
    ! 3. rows of different widths on different ranks (comm%size > 1) or
    !    rows that do not match the order: found on one rank, refused on all
    call f%create(comm, dir//'/widths.h5', err)
    if (allocated(err)) call die(err%message)
    allocate (a(3, 2 + merge(1, 0, comm%rank == comm%size - 1 .and. comm%size > 1)))
    a = 1.0_dp
    call new_row_order(comm, [(g, g=1 + 3*comm%rank, 3 + 3*comm%rank)], order, err)
    if (allocated(err)) call die(err%message)
    if (comm%size > 1) then
      call f%write_rows('a', a)
    else
      call f%write_rows('a', a(1:2, :), order)
    end if
    call f%close(err)
    call expect_failure('rows of different widths', [dir//'/widths.h5'])
    ! 4. global ids that repeat: not a permutation
    gids = [(g, g=1 + 3*comm%rank, 3 + 3*comm%rank)]
    if (comm%rank == comm%size - 1) gids(3) = 1
    call new_row_order(comm, gids, order, err)
    call expect_failure('repeated global ids', [character(len=0) ::])
  end subroutine error_cases

  !> `err` must hold the same message on every rank, and none of `paths`
  !> (nor a temporary file beside them) may exist.
  subroutine expect_failure(what, paths)
    character(len=*), intent(in) :: what
    character(len=*), intent(in) :: paths(:)
    character(len=:), allocatable :: mine, first
    integer :: failed, same, k
    logical :: left
    failed = 0
    mine = ''
    if (allocated(err)) then
      failed = 1
      mine = err%message
      write (error_unit, '(a)') 'rank '//int_text(comm%rank)//' error ('//what//'): '//mine
    else
      write (error_unit, '(a)') 'rank '//int_text(comm%rank)//' no error ('//what//')'
    end if
    flush (error_unit)
    first = mine
    call broadcast(comm, first, 0)
    same = merge(1, 0, first == mine)
    call allreduce_min(comm, failed)
    call allreduce_min(comm, same)
    left = .false.
    if (comm%rank == 0) then
      do k = 1, size(paths)
        if (path_exists(trim(paths(k)))) left = .true.
        if (tmp_left(trim(paths(k)))) left = .true.
      end do
    end if
    call barrier(comm)
    if (comm%rank /= 0) return
    if (failed == 1 .and. same == 1 .and. .not. left) then
      write (output_unit, '(a)') 'ok: '//what//': the same error on all '// &
        int_text(comm%size)//' ranks, no file left'
    else
      write (output_unit, '(a)') 'FAIL: '//what//trim(merge(' not failed on every rank', &
        '                         ', failed == 0))//trim(merge(' messages differ', &
        '                ', same == 0))//trim(merge(' a file was left', '                ', left))
      status = 1
    end if
    flush (output_unit)
  end subroutine expect_failure

  !> A temporary file `<path>.tmp.*` exists beside `path`.
  logical function tmp_left(path)
    character(len=*), intent(in) :: path
    integer :: stat, cstat
    call execute_command_line('ls -d -- "'//path//'".tmp.* >/dev/null 2>&1', &
                              exitstat=stat, cmdstat=cstat)
    tmp_left = cstat == 0 .and. stat == 0
  end function tmp_left

  ! ---- measurements

  !> Wall time (max over ranks, median of `reps`) of one snapshot: create,
  !> a 2-column and six 1-column fields of n rows per rank, close.
  subroutine bench()
    integer :: reps, r, k, g
    integer, allocatable :: gids(:)
    real(dp), allocatable :: t(:, :), xy(:, :)
    character(len=*), parameter :: names(5) = [character(len=16) :: 'contiguous', &
      'redistribute', 'points', 'hyperslabs', 'gather_rank0']
    reps = 5
    if (command_argument_count() >= 4) reps = int_arg(4)
    allocate (t(reps, 5))
    ! ids dealt in runs of 5 over the ranks (each rank's rows reversed)
    gids = pack([(g, g=n*comm%size, 1, -1)], &
                mod(([(g, g=n*comm%size, 1, -1)] - 1)/5, comm%size) == comm%rank)
    allocate (xy(size(gids), 2))
    xy(:, 1) = field_x(gids)
    xy(:, 2) = -field_x(gids)
    do r = 1, reps
      do k = 1, 5
        t(r, k) = -1.0e-3_dp
        ! in place by points or hyperslab unions grows faster than the rows:
        ! those two ways only up to 20 000 rows per rank
        if ((k == 3 .or. k == 4) .and. n > 20000) cycle
        t(r, k) = timed(k, gids, xy)
      end do
    end do
    if (comm%rank == 0) then
      write (output_unit, '(a)') 'rows per rank '//int_text(n)//', ranks '// &
        int_text(comm%size)//', MPI-IO: '//merge('yes', 'no ', h5_uses_mpio(comm))// &
        ', median of '//int_text(reps)//' (ms per snapshot, 8 values per row)'
      do k = 1, 5
        write (output_unit, '(a16,f10.2)') names(k), 1.0e3_dp*median(t(:, k))
      end do
    end if
  end subroutine bench

  !> One snapshot written the k-th way (see bench); seconds, max over ranks.
  real(dp) function timed(k, gids, xy) result(seconds)
      integer, intent(in) :: k, gids(:)
      real(dp), intent(in) :: xy(:, :)
      type(h5_parallel_file_t) :: f
      type(h5_row_order_t) :: order
      type(h5_file_t) :: h5
      integer(int64) :: c0, c1, rate
      integer :: j, methods(3)
      real(dp), allocatable :: all(:), buf(:)
      call barrier(comm)
      call system_clock(c0, rate)
      select case (k)
      case (1)
        call f%create(comm, dir//'/bench.h5', err)
        call f%write_rows('xy', xy)
        do j = 1, 6
          call f%write_rows('f'//int_text(j), xy(:, 1))
        end do
        call f%close(err)
      case (2:4)
        methods = [order_redistribute, order_points, order_hyperslabs]
        call new_row_order(comm, gids, order, err, methods(k - 1))
        call f%create(comm, dir//'/bench.h5', err)
        call f%write_rows('xy', xy, order)
        do j = 1, 6
          call f%write_rows('f'//int_text(j), xy(:, 1), order)
        end do
        call f%close(err)
      case (5)
        ! what the MPM programs did before: gather to rank 0, which writes
        call gatherv_real(comm, [real(gids, dp)], buf, 0)
        if (comm%rank == 0) call h5%create(dir//'/bench.h5', err)
        call gatherv_real(comm, reshape(transpose(xy), [size(xy)]), all, 0)
        if (comm%rank == 0) call h5%write('xy', transpose(reshape(all, [2, size(buf)])))
        do j = 1, 6
          call gatherv_real(comm, xy(:, 1), all, 0)
          if (comm%rank == 0) call h5%write('f'//int_text(j), all)
        end do
        if (comm%rank == 0) call h5%close(err)
      end select
      if (allocated(err)) call die(err%message)
      call barrier(comm)
      call system_clock(c1)
      seconds = real(c1 - c0, dp)/real(rate, dp)
      call allreduce_max(comm, seconds)
  end function timed

  real(dp) function median(x)
    real(dp), intent(in) :: x(:)
    real(dp) :: s(size(x)), v
    integer :: i, j
    s = x
    do i = 2, size(s)
      v = s(i)
      j = i - 1
      do while (j >= 1)
        if (s(j) <= v) exit
        s(j + 1) = s(j)
        j = j - 1
      end do
      s(j + 1) = v
    end do
    median = s((size(s) + 1)/2)
  end function median

  subroutine die(message)
    character(len=*), intent(in) :: message
    write (error_unit, '(a)') 'rank '//int_text(comm%rank)//': '//message
    error stop 1
  end subroutine die

end program parallel_h5_main
