!> The bar scene of wellposed-mpm: the explicit MPM of section 4.3 on the
!> 1D uniaxial-strain scenes of chapter 2 (Sandler-Rubin case study), for a
!> deck whose &scene kind is 'bar'. Writes ROOT/NAME/ (the deck, run.h5,
!> run.xdmf, summary.txt, stations.png) through ROOT/NAME.partial, renamed
!> at the end; errors to standard error, exit status 1. On N ranks the bar
!> is cut into strips (wellposed_mpm_ranks) and run.h5 written collectively;
!> checkpoints every STEPS steps, --restart on any number of ranks.
!> Outputs: docs/guide/mpm.md; ranks and checkpoints: docs/guide/parallel.md.
module wellposed_mpm_bar_run
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_config
  use wellposed_mpm_deck, only: read_mpm_deck, mpm_options_t
  use wellposed_mpm_deck_checks, only: check_bar_deck
  use wellposed_mpm_station_summary, only: add_station_summary, head_speed, head_speed_t
  use wellposed_mpm_nonlocal_summary, only: add_nonlocal_summary
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, kinetic_energy, &
                                  total_momentum, timer_umat, timer_transfer, timer_grid
  use wellposed_mpm_stations, only: stations_t, new_stations, sample_stations, &
                                    station_measures_t, measure_stations, field_sxx, &
                                    field_syy, field_v, field_z, field_apex, nfields
  use wellposed_mpm_wake, only: wake_t, station_wake, wake_start
  use wellposed_mpm_paths, only: find_data, stations_plot_name
  use wellposed_mpm_reference, only: reference_plot_args
  use wellposed_mpm_particles, only: particle_bytes, particles_t
  use wellposed_mpm_nonlocal, only: nl_scheme_names
  use wellposed_mpi, only: comm_t, allreduce_sum, &
                           allreduce_max, broadcast
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpm_parallel_io, only: station_proxy_t, gather_particles, make_station_proxy, &
                                       fill_station_proxy, put_stations, get_stations
  use wellposed_checkpoint, only: checkpoint_t, write_checkpoint
  use wellposed_mpm_resume, only: open_restart_checkpoint
  use wellposed_mpm_restart, only: save_scene, restore_scene
  use wellposed_mpm_snapshots, only: snapshot_store_t, new_snapshot_store
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_writer_name
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: path_exists, shell_quote, remove_tree
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_stop, only: stop_alone, stop_all
  use wellposed_mpm_run_loop, only: run_clock_t, checkpoint_every, checkpoint_due, snapshot_due
  implicit none
  private
  public :: run_bar

contains

  !> Run the bar deck cli%deck_path as the command line `cli` asks, on the
  !> ranks of `comm` (collective). Stops the program on an error.
  subroutine run_bar(cli, comm)
      type(mpm_cli_t), intent(in) :: cli
      type(comm_t), intent(inout) :: comm

    type(mpm_config_t) :: cfg
    integer, allocatable :: nl_its(:), nl_plastic(:)  ! Algorithm 1: sweeps, step
    real(dp), allocatable :: nl_bound(:)
    integer :: nl_n = 0
    type(mpm_options_t) :: opts
    type(mpm_scene_t) :: scene
    type(stations_t) :: st
    type(station_measures_t) :: meas
    type(head_speed_t) :: head
    type(run_dir_t) :: rd
    type(h5_parallel_file_t) :: h5
    type(summary_t) :: sm
    type(error_t), allocatable :: err, err2
    ! ranks: the communicator, the scene's exchange, the stations' proxy
    type(mpm_ranks_t) :: ranks
    type(station_proxy_t) :: proxy
    type(particles_t) :: everyone
    logical :: root, sampled
    integer :: ntotal, substeps, ghost
    real(dp) :: sums(3), ke_end, p_end
    ! checkpoints: every ck_every steps into <out>/<name>.checkpoints (keep two)
    integer :: ck_every
    character(len=:), allocatable :: ck_dir, ck_file
    !> particle snapshots: each rank keeps the rows of its own particles
    type(snapshot_store_t) :: snaps
    character(len=:), allocatable :: deck_text, script, h5_path
    integer :: i, nsnap, nenergy, s, nsteps_est
    type(run_clock_t) :: clock
    real(dp) :: wall, next_snap, c_e, c_p, escale, ebal, t_target
    real(dp), allocatable :: energy(:, :)
    character(len=16) :: tag

    root = comm%rank == 0
    ck_every = cli%ck_every
    ck_file = cli%ck_file

    ! ---- deck and scene
    call read_mpm_deck(cli%deck_path, cli%overrides, cfg, opts, deck_text, err)
    if (.not. allocated(err)) call check_bar_deck(cli%deck_path, cfg, err, cli%force)
    if (allocated(err)) call stop_all(comm, rd, err)
    if (len(cli%run_name) > 0) cfg%name = cli%run_name
    ! every rank builds the scene and keeps its strip (errors: the same on all)
    call new_mpm_ranks(ranks, comm)
    call new_scene(scene, cfg, err, ranks)
    if (allocated(err)) then
      err%message = cli%deck_path//': '//err%message
      call stop_all(comm, rd, err)
    end if
    ghost = scene%exchange%ghost_layers()
    c_e = sqrt(scene%modulus_elastic/cfg%density)
    c_p = sqrt(scene%modulus_plastic/cfg%density)
    head = head_speed(cfg, scene%nl%active, c_p)
    ! rank 0 makes the run folder; run.h5 in it is written by every rank
    h5_path = ''
    if (root) then
      call rd%create(cli%out_root, cfg%name, cli%deck_path, err)
      if (allocated(err)) call stop_alone(comm, rd, err)
      h5_path = rd%path('run.h5')
    end if
    call broadcast(comm, h5_path, 0)
    call h5%create(comm, h5_path, err)
    if (allocated(err)) call stop_all(comm, rd, err)
    ! stations on rank 0 over every particle in id order, read through a
    ! proxy (a gather for setting them up; the other ranks hold none)
    ntotal = scene%parts%n
    call allreduce_sum(comm, ntotal)
    call gather_particles(comm, scene%parts, 0, everyone)
    if (root) then
      call new_stations(st, cfg, everyone, cfg%t_end)
    else
      allocate (st%x(0), st%time(0), st%hist(nfields, 0, 0))
    end if
    call make_station_proxy(st, comm, ntotal, scene%parts, proxy)

    nsteps_est = ceiling(cfg%t_end/scene%dt)
    if (root) then
      write (output_unit, '(a)') 'wellposed-mpm '//wellposed_version//': scene '//cfg%name// &
        ' ('//trim(cfg%title)//')'
      write (output_unit, '(a,i0,a,i0,a,es10.3,a,i0,a)') '  ', ntotal, ' particles, ', &
        scene%grid%nnodes, ' nodes, dt = ', scene%dt, ' s, ~', nsteps_est, ' steps'
      write (output_unit, '(a,a,a,a,a,f9.2,a,f9.2,a)') '  shape ', &
        trim(shape_names(cfg%shape)), ', scheme ', trim(scheme_names(cfg%scheme)), ', C_E = ', &
        c_e, ' m/s, C_P = ', c_p, ' m/s (UMAT moduli at the initial state)'
      if (scene%nl%active) write (output_unit, '(a)') '  nonlocal: L = '// &
        real_text(scene%nl%length)//' m, Gaussian support radius '// &
        real_text(scene%nl%radius)//' m = '//real_text(scene%nl%radius/cfg%dx)//' cells'
      if (comm%size > 1) write (output_unit, '(a)') '  on '//int_text(comm%size)// &
        ' ranks, strips of cells with '//int_text(ghost)//' ghost node layers; run.h5: '// &
        h5_writer_name(comm)
      write (output_unit, '(a)') '  writing '//rd%partial//' (renamed to '//rd%final// &
        ' when done)'
      flush (output_unit)
    end if

    ! ---- time loop
    allocate (energy(5, max(size(st%time), 1)))
    call new_snapshot_store(snaps, [character(len=8) :: 'x', 'x0', 'velocity', 'sigma_xx', &
                                    'sigma_yy', 'z'], [1, 1, 1, 1, 1, 1], time_first=.true.)
    nenergy = 1
    energy(:, 1) = [0.0_dp, scene%kinetic0, 0.0_dp, 0.0_dp, scene%momentum0]
    nsnap = 0
    next_snap = 0.0_dp
    ck_dir = cli%out_root//'/'//cfg%name//'.checkpoints'
    ck_every = checkpoint_every(ck_every, nsteps_est)
    if (cli%restart) then
      call resume()
    else if (cfg%snapshot_dt > 0.0_dp) then
      call snapshot()
    end if
    call clock%start(2.0_dp)
    t_target = cfg%t_end - 0.5_dp*scene%dt
    do while (scene%t < t_target)
      call advance(scene, err)
      if (.not. allocated(err) .and. scene%nl%active .and. scene%nl%last%n_plastic > 0) then
        if (.not. allocated(nl_its)) allocate (nl_its(1024), nl_plastic(1024), nl_bound(1024))
        if (nl_n == size(nl_its)) then
          nl_its = [nl_its, nl_its]; nl_plastic = [nl_plastic, nl_plastic]
          nl_bound = [nl_bound, nl_bound]
        end if
        nl_n = nl_n + 1
        nl_its(nl_n) = scene%nl%last%iterations
        nl_plastic(nl_n) = scene%nstep
        nl_bound(nl_n) = scene%nl%last%bound_printed
      end if
      if (allocated(err)) then
        ! (every rank has the error: the step's errors are collective) close
        ! what was written (under its temporary name) and report the error
        call h5%close(err2)
        call stop_all(comm, rd, cli%deck_path//': '//err%message)
      end if
      call fill_station_proxy(proxy, comm, scene%parts)
      sampled = .false.
      if (root) then
        s = st%ns
        call sample_stations(st, proxy%parts, scene%t)
        sampled = st%ns > s .and. nenergy < size(energy, 2)
      end if
      call broadcast(comm, sampled, 0)
      if (sampled) then
        ke_end = kinetic_energy(scene)
        p_end = total_momentum(scene)
        sums = [scene%work_internal, scene%work_external, scene%impulse]
        call allreduce_sum(comm, sums)
        if (root) then
          nenergy = nenergy + 1
          energy(:, nenergy) = [scene%t, ke_end, sums(1), sums(2), p_end - sums(3)]
        end if
      end if
      if (snapshot_due(cfg%snapshot_dt, scene%t, next_snap, 0.5_dp*scene%dt)) call snapshot()
      if (checkpoint_due(ck_every, scene%nstep, scene%t, cfg%t_end, scene%dt)) call checkpoint()
      if (cfg%progress .and. root) then
        if (clock%progress_due()) then
          wall = clock%elapsed()
          write (output_unit, '(a,f9.2,a,f5.1,a,i0,a,f7.1,a,f7.1,a)') '  t = ', &
            scene%t*1e3_dp, ' ms (', 100*scene%t/cfg%t_end, ' %), step ', scene%nstep, ', ', &
            wall, ' s elapsed, ~', wall*(cfg%t_end - scene%t)/scene%t, ' s left'
          flush (output_unit)
        end if
      end if
    end do
    wall = clock%elapsed()
    ! totals over the ranks, for the summary (collective)
    ke_end = kinetic_energy(scene)
    p_end = total_momentum(scene)
    sums = [scene%work_internal, scene%work_external, scene%impulse]
    call allreduce_sum(comm, sums)
    substeps = scene%max_substeps
    call allreduce_max(comm, substeps)
    scene%work_internal = sums(1)
    scene%work_external = sums(2)
    scene%impulse = sums(3)
    scene%max_substeps = substeps

    ! ---- measures (rank 0's stations; empty elsewhere) and outputs
    call measure_stations(st%time(1:st%ns), st%hist(field_sxx, :, 1:st%ns), st%x, &
                          0.5_dp*cfg%load_peak, meas)
    escale = abs(scene%work_external) + scene%kinetic0
    ebal = ke_end - scene%kinetic0 + scene%work_internal - scene%work_external
    if (root) then
      call write_summary()
      call sm%write(rd%path('summary.txt'), err)
      if (allocated(err)) call stop_alone(comm, rd, err)
    end if
    call write_h5()
    call h5%close(err)
    if (allocated(err)) call stop_all(comm, rd, err)
    if (.not. root) return
    ! the particle snapshots for ParaView: points on the x axis over time
    if (nsnap > 0) then
      call snaps%write_xdmf(rd%path('run.xdmf'), 'run.h5', 'particles', ntotal, 1, 'x', err)
      if (allocated(err)) call stop_alone(comm, rd, err)
    end if
    if (opts%plot .and. .not. cli%no_plot) then
      script = find_data(stations_plot_name)
      call run_plot(script, shell_quote(rd%path('run.h5'))//' '// &
                    shell_quote(rd%path('stations.png'))//reference_plot_args(cli%out_root, &
                    cli%deck_path, opts%reference, opts%reference_label), err)
      if (allocated(err)) call stop_alone(comm, rd, err)
    end if
    call rd%commit(err)
    if (allocated(err)) call stop_alone(comm, rd, err)
    ! the run is complete: its checkpoints have served
    if (path_exists(ck_dir)) then
      call remove_tree(ck_dir, err)
      if (allocated(err)) write (error_unit, '(a)') 'wellposed-mpm: warning: '//err%message
    end if
    write (output_unit, '(a,f8.2,a,i0,a,f7.1,a)') '  done in ', wall, ' s (', scene%nstep, &
      ' steps, ', 1.0e9_dp*wall/max(1.0_dp, real(scene%nstep, dp)*ntotal), ' ns per particle-step)'
    do i = 1, st%n
      write (output_unit, '(a,f7.1,a,f8.3,a,f8.2,a,f8.2,a)') '  station ', st%x(i), &
        ' m: peak ', meas%peak(i)/1e6_dp, ' MPa, head ', meas%t_head(i)*1e3_dp, ' ms, tail ', &
        meas%t_tail(i)*1e3_dp, ' ms'
    end do
    write (output_unit, '(a)') '  results in '//rd%final//'/ (summary.txt, run.h5'// &
      trim(merge(', run.xdmf', '          ', nsnap > 0))// &
      trim(merge(', stations.png', '              ', opts%plot .and. .not. cli%no_plot))//')'

  contains

    !> Particle fields now into run.h5 (collective): every rank its own
    !> particles' rows, which `snaps` keeps for checkpoints.
    subroutine snapshot()
      integer :: n
      real(dp), allocatable :: rows(:, :)
      type(error_t), allocatable :: e
      nsnap = nsnap + 1
      n = scene%parts%n
      allocate (rows(6, n))
      rows(1, :) = scene%parts%x(1, 1:n)
      rows(2, :) = scene%parts%x0(1, 1:n)
      rows(3, :) = scene%parts%v(1, 1:n)
      rows(4, :) = scene%parts%stress(1, 1:n)
      rows(5, :) = scene%parts%stress(2, 1:n)
      rows(6, :) = scene%parts%statev(1, 1:n)
      write (tag, '(i4.4)') nsnap
      call snaps%take(h5, comm, 'snapshots/'//trim(tag)//'/', scene%t, scene%parts%gid(1:n), &
                      rows, e)
      if (allocated(e)) call stop_all(comm, rd, e)
      next_snap = nsnap*cfg%snapshot_dt
    end subroutine snapshot

    !> The run's state at the end of a step (collective): the scene (every
    !> rank's particles and partial sums) and the snapshots so far (every
    !> rank's rows), and from rank 0 the stations, the energy rows, the
    !> nonlocal records so far, the deck text; rank 0 writes it atomically and
    !> keeps the newest two.
    subroutine checkpoint()
      type(checkpoint_t) :: ck
      type(error_t), allocatable :: e
      character(len=:), allocatable :: path
      call save_scene(scene, ck)
      call snaps%put(ck, comm, 'snapshots/')
      if (.not. root) return
      call put_stations(ck, 'stations/', st)
      call ck%put('main/counts', [nenergy, nsnap, ntotal, nl_n])
      call ck%put('main/next_snap', next_snap)
      call ck%put('main/energy', reshape(energy(:, 1:nenergy), [5*nenergy]))
      if (nl_n > 0) then
        call ck%put('main/nl_step', nl_plastic(1:nl_n))
        call ck%put('main/nl_iterations', nl_its(1:nl_n))
        call ck%put('main/nl_bound', nl_bound(1:nl_n))
      end if
      call ck%put_text('main/deck', deck_text)
      call write_checkpoint(ck, ck_dir, scene%nstep, 2, path, e)
      if (allocated(e)) call stop_alone(comm, rd, e)
    end subroutine checkpoint

    !> --restart: continue from the newest checkpoint of ck_dir, or from
    !> --restart-from FILE, on this run's ranks (collective; every rank reads
    !> the file), and write the snapshots taken before it into run.h5 again.
    !> A damaged file, one of another deck or one of an earlier version of
    !> this program is refused.
    subroutine resume()
      type(checkpoint_t) :: ck
      type(error_t), allocatable :: e
      integer, allocatable :: counts(:), ia(:)
      real(dp), allocatable :: a(:)
      call open_restart_checkpoint(ck_dir, cli%deck_path, deck_text, ck_file, ck, e)
      if (allocated(e)) call stop_all(comm, rd, e)
      call ck%get('main/counts', counts, e)
      if (allocated(e)) call stop_all(comm, rd, e)
      if (size(counts) /= 4) call stop_all(comm, rd, ck_file//': the run counts are garbled')
      if (counts(3) /= ntotal) call stop_all(comm, rd, ck_file//' holds '//int_text(counts(3))// &
        ' particles, this deck '//int_text(ntotal))
      call restore_scene(scene, ck, e)
      if (allocated(e)) call stop_all(comm, rd, e)
      call ck%get('main/next_snap', next_snap, e)
      if (allocated(e)) call stop_all(comm, rd, e)
      nsnap = counts(2)
      call snaps%get(ck, comm, 'snapshots/', e)
      if (allocated(e)) call stop_all(comm, rd, ck_file//': '//e%message)
      if (snaps%n /= nsnap) call stop_all(comm, rd, ck_file//': the snapshot count is garbled')
      call snaps%write_stored(h5, comm, e)
      if (allocated(e)) call stop_all(comm, rd, e)
      if (.not. root) return
      call get_stations(ck, 'stations/', st, e)
      if (allocated(e)) call stop_alone(comm, rd, e)
      nenergy = counts(1)
      call ck%get('main/energy', a, e)
      if (allocated(e)) call stop_alone(comm, rd, e)
      if (nenergy > size(energy, 2) .or. size(a) /= 5*nenergy) &
        call stop_alone(comm, rd, ck_file//': the energy rows do not fit this deck')
      energy(:, 1:nenergy) = reshape(a, [5, nenergy])
      nl_n = counts(4)
      if (nl_n > 0) then
        allocate (nl_its(nl_n + 1024), nl_plastic(nl_n + 1024), nl_bound(nl_n + 1024))
        call ck%get('main/nl_step', ia, e)
        if (allocated(e)) call stop_alone(comm, rd, e)
        if (size(ia) /= nl_n) call stop_alone(comm, rd, ck_file//': nonlocal records garbled')
        nl_plastic(1:nl_n) = ia
        call ck%get('main/nl_iterations', ia, e)
        if (allocated(e)) call stop_alone(comm, rd, e)
        if (size(ia) /= nl_n) call stop_alone(comm, rd, ck_file//': nonlocal records garbled')
        nl_its(1:nl_n) = ia
        call ck%get('main/nl_bound', a, e)
        if (allocated(e)) call stop_alone(comm, rd, e)
        if (size(a) /= nl_n) call stop_alone(comm, rd, ck_file//': nonlocal records garbled')
        nl_bound(1:nl_n) = a
      end if
      write (output_unit, '(a)') '  restarted from '//ck_file//' (step '// &
        int_text(scene%nstep)//', t = '//real_text(scene%t)//' s; '//int_text(nsnap)// &
        ' snapshots written again)'
      flush (output_unit)
    end subroutine resume

    subroutine write_summary()
      call sm%add('scene', cfg%name)
      call sm%add('version', wellposed_version)
      call sm%add('git_revision', wellposed_git_revision)
      call sm%add('shape', trim(shape_names(cfg%shape)))
      call sm%add('scheme', trim(scheme_names(cfg%scheme)))
      call sm%add('mass', trim(mass_names(cfg%mass)), 'the grid acceleration''s mass matrix')
      call sm%add('dx', cfg%dx, 'm')
      call sm%add('ppc', cfg%ppc)
      call sm%add('cfl', cfg%cfl)
      call sm%add('dt', scene%dt, 's')
      call sm%add('steps', scene%nstep)
      call sm%add('particles', ntotal)
      call sm%add('ranks', comm%size, 'MPI ranks (strips of cells)')
      call sm%add('h5_writer', h5_writer_name(comm), 'how run.h5 was written: every rank '// &
                  'its rows through MPI-IO (mpio-collective), or rank 0 alone (rank0-gather)')
      call sm%add('ghost_layers', ghost, 'node layers beyond a patch: shape support '// &
                  'or the nonlocal Gaussian''s, the wider')
      call sm%add('t_end', scene%t, 's')
      call sm%add('wall_time', wall, 's, time loop only')
      ! a scene of zero steps (t_end = 0: a probe of the initial state) has no rate
      call sm%add('ns_per_particle_step', 1.0e9_dp*wall/max(1.0_dp, real(scene%nstep, dp)*ntotal))
      call sm%add('bytes_per_particle', particle_bytes(1, scene%parts%nsup, cfg%nstatv))
      call sm%add('share_umat', share(timer_umat))
      call sm%add('share_transfers', share(timer_transfer))
      call sm%add('share_grid', share(timer_grid))
      call sm%add('max_umat_substeps', scene%max_substeps, '1: no cut-back was needed')
      call sm%add('nonlocal', scene%nl%active, 'Algorithm 1 iterates (h_zeta /= 0)')
      if (scene%nl%active) then
        call sm%add('nonlocal_scheme', trim(nl_scheme_names(cfg%nonlocal%scheme)))
        call sm%add('nonlocal_support_radius', scene%nl%radius, 'm, where the Gaussian '// &
                    'falls below weight_cutoff')
        call sm%add('nonlocal_sweep_order', 'Gauss-Seidel by owning cell, then particle '// &
                    'id, pipelined across ranks')
        call add_nonlocal_summary(sm, '', scene%nl)
      end if
      call sm%add('c_elastic', c_e, 'm/s, from the UMAT unloading modulus at the initial state')
      call sm%add('c_plastic', c_p, 'm/s, from the UMAT loading (extension) modulus')
      call add_station_summary(sm, cfg, st%x, st%time(1:st%ns), st%hist(field_sxx, :, 1:st%ns), &
                               st%hist(field_apex, :, 1:st%ns), meas, c_e, c_p, head)
      call add_wake()
      call sm%add('energy_input', escale, 'J/m^2, |W_ext| + E_kin0: the work of the '// &
                  'surface load and the initial kinetic energy')
      call sm%add('energy_balance_error', ebal/max(escale, tiny(1.0_dp)), &
                  '(E_kin - E_kin0 + W_int - W_ext)/energy_input at the end')
      call sm%add('momentum_error', &
                  (p_end - scene%momentum0 - scene%impulse)/ &
                  max(abs(scene%impulse), maxval(abs(energy(5, 1:nenergy))), tiny(1.0_dp)), &
                  '(P - P0 - impulse)/max|impulse|')
    end subroutine write_summary

    !> The wake behind the pulse at every station (wellposed_mpm_wake) and
    !> the largest over the stations whose record reaches the window.
    subroutine add_wake()
      type(wake_t) :: w
      character(len=:), allocatable :: why
      real(dp) :: worst, worst_grid
      logical :: any_window
      integer :: i
      why = 'the record ends before the wake window starts'
      if (cfg%pulse == pulse_ramp_sine) why = "pulse = 'ramp_sine' is a ramp, not a pulse"
      call sm%add('wake_definition', 'max and RMS of |sigma_xx(t) - sigma_xx(0)| at a '// &
                  'station over t >= x/C_E + 2 tau (the ideal elastic tail plus one pulse '// &
                  'duration) to t_end, where the continuum is at or near its initial '// &
                  'stress; _grid: max |sigma_xx - its centred moving average over 4 dx/C_E|, '// &
                  'the grid-scale part, without the smooth signal a plastic pulse leaves')
      worst = 0.0_dp
      worst_grid = 0.0_dp
      any_window = .false.
      do i = 1, st%n
        w = station_wake(st%time(1:st%ns), st%hist(field_sxx, i, 1:st%ns), &
                         wake_start(st%x(i), c_e, cfg%load_duration), 4.0_dp*cfg%dx/c_e)
        if (cfg%pulse == pulse_ramp_sine) w%samples = 0
        tag = 'station_'//int_text(i)
        if (w%samples > 1) then
          call sm%add(trim(tag)//'_wake_amplitude', w%amplitude, 'Pa')
          call sm%add(trim(tag)//'_wake_rms', w%rms, 'Pa')
          call sm%add(trim(tag)//'_wake_grid', w%grid, 'Pa')
          any_window = .true.
          worst = max(worst, w%amplitude)
          worst_grid = max(worst_grid, w%grid)
        else
          call sm%not_applicable(trim(tag)//'_wake_amplitude', why)
          call sm%not_applicable(trim(tag)//'_wake_rms', why)
          call sm%not_applicable(trim(tag)//'_wake_grid', why)
        end if
      end do
      if (any_window) then
        call sm%add('wake_amplitude', worst, 'Pa, the largest station_<i>_wake_amplitude')
        call sm%add('wake_grid_amplitude', worst_grid, 'Pa, the largest station_<i>_wake_grid')
      else
        why = 'no station''s record reaches its wake window'
        call sm%not_applicable('wake_amplitude', why)
        call sm%not_applicable('wake_grid_amplitude', why)
      end if
    end subroutine add_wake

    real(dp) function share(id)
      integer, intent(in) :: id
      share = real(scene%ticks(id), dp)/max(1.0_dp, real(sum(scene%ticks), dp))
    end function share

    !> The datasets and attributes beside the snapshots (collective: the
    !> values are rank 0's; the others pass their own, which are ignored).
    subroutine write_h5()
      integer :: k
      call h5%write_attr('scene', cfg%name)
      call h5%write_attr('title', trim(cfg%title))
      call h5%write_attr('deck', deck_text)
      call h5%write_attr('cli%deck_path', cli%deck_path)
      call h5%write_attr('version', wellposed_version)
      call h5%write_attr('git_revision', wellposed_git_revision)
      call h5%write_attr('props', cfg%props(1:cfg%nprops))
      call h5%write_attr('shape', trim(shape_names(cfg%shape)))
      call h5%write_attr('scheme', trim(scheme_names(cfg%scheme)))
      call h5%write_attr('mass', trim(mass_names(cfg%mass)))
      call h5%write_attr('numbers', [cfg%dx, scene%dt, cfg%cfl, c_e, c_p, cfg%load_peak, &
                                     cfg%load_duration, cfg%density, real(cfg%ppc, dp)])
      call h5%write_attr('numbers_names', 'dx dt cfl c_elastic c_plastic load_peak '// &
                         'load_duration density ppc')
      call h5%write('stations/time', st%time(1:st%ns))
      call h5%write('stations/x', st%x)
      call h5%write('stations/sigma_xx', st%hist(field_sxx, :, 1:st%ns))
      call h5%write('stations/sigma_yy', st%hist(field_syy, :, 1:st%ns))
      call h5%write('stations/velocity', st%hist(field_v, :, 1:st%ns))
      call h5%write('stations/z', st%hist(field_z, :, 1:st%ns))
      call h5%write('measures/peak', meas%peak)
      call h5%write('measures/t_head', meas%t_head)
      call h5%write('measures/t_tail', meas%t_tail)
      call h5%write('measures/width', meas%width)
      call h5%write('energy/time', energy(1, 1:nenergy))
      call h5%write('energy/kinetic', energy(2, 1:nenergy))
      call h5%write('energy/internal_work', energy(3, 1:nenergy))
      call h5%write('energy/external_work', energy(4, 1:nenergy))
      call h5%write('energy/momentum_minus_impulse', energy(5, 1:nenergy))
      k = nsnap
      call h5%write('snapshots/count', [k])
      if (nl_n > 0) then
        ! Algorithm 1 per step with plastic particles: the step, its sweeps and
        ! the dissertation's bound of eq. 4.43 (N_alpha |h_zeta/(a + h_eta)|)
        call h5%write('nonlocal/step', nl_plastic(1:nl_n))
        call h5%write('nonlocal/iterations', nl_its(1:nl_n))
        call h5%write('nonlocal/lipschitz_eq4_43_printed', nl_bound(1:nl_n))
      end if
    end subroutine write_h5

  end subroutine run_bar

end module wellposed_mpm_bar_run
