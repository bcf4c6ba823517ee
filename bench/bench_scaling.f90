!> bench_scaling: strong and weak scaling of the plane-strain MPM over
!> ranks and the cost of a checkpoint, in one run:
!>   mpirun -np 2 bench_scaling [CHECKPOINT_DIR | --overlocal]
!> A 200 000-particle CPDI plate in pure shear (S1, W1, P timed in
!> interleaved rounds), then the overlocal plate of fig. 4.4 (O1, OP, O1J:
!> Algorithm 1's sweeps and exchanges); --overlocal: that part alone.
!> Prints measures and ratios, never a pass/fail on wall time.
!> Scene, targets and method: docs/research/scaling.md, docs/guide/parallel.md.
program bench_scaling
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t, comm_start, comm_stop, comm_self, barrier, allreduce_max, &
                           allreduce_sum
  use wellposed_mpm_plate_build, only: plate_config_t, bc_plate_free
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, plastic_count
  use wellposed_mpm_nonlocal, only: ours_bounds, nl_sweep_names, nl_jacobi
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpm_restart, only: save_scene
  use wellposed_mpm_shape_2d, only: shape2d_cpdi
  use wellposed_checkpoint, only: checkpoint_t, write_checkpoint
  use wellposed_fs, only: remove_tree
  use wellposed_text, only: int_text
  implicit none
  integer, parameter :: nwarm = 25, nrounds = 6, nsteps = 4, nwrites = 2
  !> the overlocal plate: warmed to t_plastic (s), then rounds of nl_steps
  real(dp), parameter :: t_plastic = 0.0075_dp
  integer, parameter :: nl_steps = 20
  type(comm_t) :: world
  type(mpm_scene_t) :: s1, w1, p
  type(error_t), allocatable :: err
  character(len=:), allocatable :: ckdir
  character(len=512) :: arg
  real(dp) :: ts1(nrounds), tw1(nrounds), tp(nrounds), t_s1, t_w1, t_p, ck_p, ck_s1, mb_p, mb_s1
  integer :: r, nplastic

  call comm_start(world, err)
  if (allocated(err)) error stop 'bench_scaling: MPI did not start'
  ckdir = 'bench_scaling.checkpoints'
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    if (trim(arg) == '--overlocal') then
      call overlocal_scaling()
      call comm_stop(world)
      stop
    end if
    ckdir = trim(arg)
  end if
  if (world%rank == 0) then
    write (output_unit, '(a)') 'bench_scaling: plane-strain plate, CPDI, h = 0.02 m, 2 x 2 '// &
      'particles per cell, plastic von Mises, '//int_text(world%size)//' rank(s); '// &
      int_text(nrounds)//' rounds of '//int_text(nsteps)//' steps per scene after '//int_text(nwarm)
    flush (output_unit)
    call build(s1, comm_self(), 5.0_dp)
    call build(w1, comm_self(), 2.5_dp)
  end if
  if (world%size > 1) call build(p, world, 5.0_dp)
  ts1 = 0.0_dp
  tw1 = 0.0_dp
  tp = 0.0_dp
  do r = 1, nrounds
    call barrier(world)
    if (world%rank == 0) ts1(r) = timed(s1, comm_self(), nsteps)
    call barrier(world)
    if (world%rank == 0) tw1(r) = timed(w1, comm_self(), nsteps)
    call barrier(world)
    if (world%size > 1) tp(r) = timed(p, world, nsteps)
  end do
  t_s1 = minval(ts1)
  t_w1 = minval(tw1)
  t_p = minval(tp)
  if (world%rank == 0) then
    write (output_unit, '(a,i0,a,2f9.4,a,f8.1,a)') '  S1  1 rank : ', s1%ntotal, &
      ' particles, ', t_s1, median(ts1), ' s/step (fastest, median), ', &
      t_s1*1.0e9_dp/s1%ntotal, ' ns/particle-step'
    write (output_unit, '(a,i0,a,2f9.4,a,f8.1,a)') '  W1  1 rank : ', w1%ntotal, &
      ' particles, ', t_w1, median(tw1), ' s/step (fastest, median), ', &
      t_w1*1.0e9_dp/w1%ntotal, ' ns/particle-step'
    flush (output_unit)
  end if
  if (world%size > 1) then
    call checkpoints(p, world, ck_p, mb_p)
    nplastic = plastic_count(p)
    call allreduce_sum(world, nplastic)
    if (world%rank == 0) then
      write (output_unit, '(a,i0,a,i0,a,2f9.4,a,i0,a)') '  P   ', world%size, ' ranks: ', &
        p%ntotal, ' particles, ', t_p, median(tp), ' s/step (fastest, median; ', &
        nplastic, ' plastic)'
      write (output_unit, '(a,f6.1,a,f6.2,a,f6.1,a)') '  strong scaling 1 -> '// &
        int_text(world%size)//' ranks: efficiency ', 100.0_dp*t_s1/(world%size*t_p), &
        ' % (speed-up ', t_s1/t_p, '; from the medians ', &
        100.0_dp*median(ts1)/(world%size*median(tp)), ' %; target >= 85 %)'
      write (output_unit, '(a,f6.1,a,f6.1,a)') '  weak scaling ('//int_text(w1%ntotal)// &
        ' particles per rank): efficiency ', 100.0_dp*t_w1/t_p, ' % (from the medians ', &
        100.0_dp*median(tw1)/median(tp), ' %)'
      write (output_unit, '(a,f8.4,a,f6.2,a,f7.1,a,f6.3,a)') '  checkpoint on '// &
        int_text(world%size)//' ranks: ', ck_p, ' s = ', ck_p/t_p, ' steps (', mb_p, &
        ' MB); every 1000 steps: ', 100.0_dp*ck_p/(1000.0_dp*t_p), ' % of the run'
    end if
  end if
  if (world%rank == 0) then
    call checkpoints(s1, comm_self(), ck_s1, mb_s1)
    write (output_unit, '(a,f8.4,a,f6.2,a,f6.3,a)') '  checkpoint on 1 rank : ', ck_s1, &
      ' s = ', ck_s1/t_s1, ' steps; every 1000 steps: ', 100.0_dp*ck_s1/(1000.0_dp*t_s1), &
      ' % of the run'
    call remove_tree(ckdir, err)
  end if
  call overlocal_scaling()
  call comm_stop(world)

contains

  !> The overlocal plate on rank 0 alone (O1; O1J with the Jacobi sweep) and
  !> on all ranks (OP), timed in interleaved rounds in the plastic phase,
  !> with the shares of a step in Algorithm 1 (step 1: the UMAT calls of a
  !> local model too; the sweeps of steps 2-3; of those, the exchanges and
  !> reductions).
  subroutine overlocal_scaling()
    type(mpm_scene_t) :: o1, op, o1j
    real(dp) :: to1(nrounds), top(nrounds), to1j(nrounds), sh1(3), shp(3), sh1j(3), t1, tpar
    integer :: r, n1
    if (world%rank == 0) then
      write (output_unit, '(a)') 'bench_scaling: the overlocal plate of fig. 4.4 (4 m x 5 m, '// &
        'h = 0.125 m, CPDI, h_eta = 2 GPa, h_zeta = -4 GPa, L = 0.5 m, rel. tol. 1e-6, no '// &
        'weak corner), warmed to 7.5 ms; '//int_text(nrounds)//' rounds of '// &
        int_text(nl_steps)//' steps'
      flush (output_unit)
      call build_overlocal(o1, comm_self())
      call build_overlocal(o1j, comm_self(), nl_jacobi)
    end if
    if (world%size > 1) call build_overlocal(op, world)
    to1 = 0.0_dp
    top = 0.0_dp
    to1j = 0.0_dp
    do r = 1, nrounds
      call barrier(world)
      if (world%rank == 0) to1(r) = timed_nl(o1, comm_self(), sh1)
      if (world%rank == 0) to1j(r) = timed_nl(o1j, comm_self(), sh1j)
      call barrier(world)
      if (world%size > 1) top(r) = timed_nl(op, world, shp)
    end do
    if (world%rank /= 0) return
    t1 = minval(to1)
    n1 = plastic_count(o1)
    write (output_unit, '(a,i0,a,2f9.4,a,i0,a,3(f5.1,a))') '  O1  1 rank : ', o1%ntotal, &
      ' particles, ', t1, median(to1), ' s/step (fastest, median; ', n1, ' plastic); '// &
      trim(nl_sweep_names(o1%nl%sweep))//': step 1 ', 100*sh1(1), ' %, sweeps ', &
      100*sh1(2), ' %, their exchanges ', 100*sh1(3), ' % of a step'
    write (output_unit, '(a,2f9.4,a,2(f5.1,a))') '  O1J 1 rank : the same with '// &
      trim(nl_sweep_names(o1j%nl%sweep))//' sweeps, ', minval(to1j), median(to1j), &
      ' s/step (fastest, median); step 1 ', 100*sh1j(1), ' %, sweeps ', 100*sh1j(2), &
      ' % of a step'
    if (world%size == 1) return
    tpar = minval(top)
    write (output_unit, '(a,i0,a,2f9.4,a,3(f5.1,a))') '  OP  '//int_text(world%size)// &
      ' ranks: ', op%ntotal, ' particles, ', tpar, median(top), ' s/step (fastest, '// &
      'median); '//trim(nl_sweep_names(op%nl%sweep))//': step 1 ', 100*shp(1), &
      ' %, sweeps ', 100*shp(2), ' %, their exchanges ', 100*shp(3), ' % of a step'
    write (output_unit, '(a,f6.1,a,f6.3,a,f6.3,a)') '  overlocal strong scaling 1 -> '// &
      int_text(world%size)//' ranks: efficiency ', 100.0_dp*t1/(world%size*tpar), &
      ' % (time ratio ', tpar/t1, '; from the medians ', median(top)/median(to1), ')'
    write (output_unit, '(a,f6.1,a,f6.3,a,f6.3,a)') '  the same sweep on both (OP against '// &
      'O1J): efficiency ', 100.0_dp*minval(to1j)/(world%size*tpar), ' % (time ratio ', &
      tpar/minval(to1j), '; from the medians ', median(top)/median(to1j), ')'
    flush (output_unit)
  end subroutine overlocal_scaling

  !> The overlocal plate on `comm`, advanced to t_plastic (`sweep`: the
  !> &nonlocal sweep, else 'auto').
  subroutine build_overlocal(sc, comm, sweep)
    type(mpm_scene_t), intent(out) :: sc
    type(comm_t), intent(in) :: comm
    integer, intent(in), optional :: sweep
    type(error_t), allocatable :: e
    type(mpm_ranks_t) :: ranks
    type(plate_config_t) :: c
    c = plate_config_t()
    c%name = 'bench_scaling_overlocal'
    c%title = 'overlocal plate'
    c%dx = 0.125_dp
    c%props = 0.0_dp
    c%props(1:6) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 400.0e6_dp, 2.0e9_dp]
    c%props(12:14) = [-4.0e9_dp, 0.5_dp, 1.0_dp]
    c%nprops = 14
    c%nonlocal%active = .true.
    c%nonlocal%length = 0.5_dp
    c%nonlocal%h_zeta = -4.0e9_dp
    c%nonlocal%rel_tolerance = 1.0e-6_dp
    if (present(sweep)) c%nonlocal%sweep = sweep
    call ours_bounds(c%props, c%nonlocal%bound_43, c%nonlocal%bound_45)
    call new_mpm_ranks(ranks, comm)
    call new_scene(sc, c, e, ranks)
    if (allocated(e)) error stop 'bench_scaling: the overlocal scene was refused'
    do while (sc%t < t_plastic)
      call advance(sc, e)
      if (allocated(e)) error stop 'bench_scaling: an overlocal warm-up step failed'
    end do
  end subroutine build_overlocal

  !> Seconds per step over nl_steps steps of the overlocal `sc` (the slowest
  !> rank's) and the shares of a step (the largest over the ranks): step 1
  !> of Algorithm 1, its sweeps, their exchanges.
  real(dp) function timed_nl(sc, comm, share) result(t)
    type(mpm_scene_t), intent(inout) :: sc
    type(comm_t), intent(in) :: comm
    real(dp), intent(out) :: share(3)
    type(error_t), allocatable :: e
    integer(int64) :: c0, c1, rate, l0, s0, x0
    integer :: k
    call barrier(comm)
    l0 = sc%nl%ticks_local
    s0 = sc%nl%ticks_sweeps
    x0 = sc%nl%ticks_exchange
    call system_clock(c0, rate)
    do k = 1, nl_steps
      call advance(sc, e)
      if (allocated(e)) error stop 'bench_scaling: an overlocal step failed'
    end do
    call system_clock(c1)
    share = real([sc%nl%ticks_local - l0, sc%nl%ticks_sweeps - s0, sc%nl%ticks_exchange - x0], &
                 dp)/real(max(c1 - c0, 1_int64), dp)
    t = real(c1 - c0, dp)/rate/nl_steps
    call allreduce_max(comm, t)
    do k = 1, 3
      call allreduce_max(comm, share(k))
    end do
  end function timed_nl

  !> The plate of height `height` on `comm`, after nwarm steps.
  subroutine build(sc, comm, height)
    type(mpm_scene_t), intent(out) :: sc
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: height
    type(error_t), allocatable :: e
    type(mpm_ranks_t) :: ranks
    integer :: k
    call new_mpm_ranks(ranks, comm)
    call new_scene(sc, plate(height), e, ranks)
    if (allocated(e)) error stop 'bench_scaling: the scene was refused'
    do k = 1, nwarm
      call advance(sc, e)
      if (allocated(e)) error stop 'bench_scaling: a warm-up step failed'
    end do
  end subroutine build

  !> Seconds per step over `steps` steps of `sc` (the slowest rank's).
  real(dp) function timed(sc, comm, steps) result(t)
    type(mpm_scene_t), intent(inout) :: sc
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: steps
    type(error_t), allocatable :: e
    integer(int64) :: c0, c1, rate
    integer :: k
    call barrier(comm)
    call system_clock(c0, rate)
    do k = 1, steps
      call advance(sc, e)
      if (allocated(e)) error stop 'bench_scaling: a step failed'
    end do
    call system_clock(c1)
    t = real(c1 - c0, dp)/rate/steps
    call allreduce_max(comm, t)
  end function timed

  !> Seconds per checkpoint of `sc` (nwrites of them, rank 0 writes) and
  !> the size of the file in MB.
  subroutine checkpoints(sc, comm, t_ckpt, mbytes)
    type(mpm_scene_t), intent(inout) :: sc
    type(comm_t), intent(in) :: comm
    real(dp), intent(out) :: t_ckpt, mbytes
    type(checkpoint_t) :: ck
    type(error_t), allocatable :: e
    character(len=:), allocatable :: path
    integer(int64) :: c0, c1, rate, bytes
    integer :: k
    call barrier(comm)
    call system_clock(c0, rate)
    do k = 1, nwrites
      ck = checkpoint_t()
      call save_scene(sc, ck)
      if (comm%rank == 0) then
        call write_checkpoint(ck, ckdir, sc%nstep + k, 2, path, e)
        if (allocated(e)) error stop 'bench_scaling: the checkpoint was not written'
      end if
      call barrier(comm)
    end do
    call system_clock(c1)
    t_ckpt = real(c1 - c0, dp)/rate/nwrites
    call allreduce_max(comm, t_ckpt)
    mbytes = 0.0_dp
    if (comm%rank == 0) then
      inquire (file=path, size=bytes)
      mbytes = real(bytes, dp)/1.0e6_dp
    end if
  end subroutine checkpoints

  !> Median of a few values.
  pure real(dp) function median(a) result(m)
    real(dp), intent(in) :: a(:)
    real(dp) :: b(size(a)), t
    integer :: i, j
    b = a
    do i = 2, size(b)
      t = b(i)
      j = i - 1
      do while (j >= 1)
        if (b(j) <= t) exit
        b(j + 1) = b(j)
        j = j - 1
      end do
      b(j + 1) = t
    end do
    m = 0.5_dp*(b((size(b) + 1)/2) + b(size(b)/2 + 1))
  end function median

  !> The plate: 4 m wide, `height` m high, h = 0.02 m, CPDI, von Mises
  !> (k0 = 40 MPa, no hardening), free edges, initial pure shear.
  function plate(height) result(c)
    real(dp), intent(in) :: height
    type(plate_config_t) :: c
    c = plate_config_t()
    c%name = 'bench_scaling'
    c%title = 'scaling plate'
    c%width = 4.0_dp
    c%height = height
    c%dx = 0.02_dp
    c%shape = shape2d_cpdi
    c%props = 0.0_dp
    c%props(1:5) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 40.0e6_dp]
    c%props(14) = 1.0_dp
    c%nprops = 14
    c%bottom = bc_plate_free
    c%top = bc_plate_free
    c%velocity_gradient0 = reshape([-100.0_dp, 0.0_dp, 0.0_dp, 100.0_dp], [2, 2])
    c%t_end = 1.0_dp
  end function plate

end program bench_scaling
