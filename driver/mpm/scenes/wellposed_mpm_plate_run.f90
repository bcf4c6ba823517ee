!> The plate scene of wellposed-mpm: the plane-strain MPM on the plate of
!> chapter 4 (fig. 4.1-4.6), one or more cases per deck (&study;
!> wellposed_mpm_plate_cases). Writes ROOT/NAME/ (the deck, run.h5, a
!> <case>.xdmf, curve and iteration CSVs per case, summary.txt, plots)
!> through ROOT/NAME.partial, renamed at the end. Ranks advance their strips
!> and write run.h5 collectively; rank 0 writes the rest, in the serial
!> layout. Checkpoints every STEPS steps; `--restart` gives the
!> uninterrupted run's files bit for bit. Outputs: docs/guide/mpm.md.
module wellposed_mpm_plate_run
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_plane_strain, only: ps_config_t, apparent_strain
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, applied_stress, &
                                  plastic_strain, max_substeps, plastic_count
  use wellposed_mpm_restart, only: save_scene, restore_scene
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpm_shape_2d, only: shape2d_names
  use wellposed_mpm_config, only: scheme_names
  use wellposed_mpm_nonlocal, only: nl_scheme_names
  use wellposed_mpm_ps_deck, only: read_ps_deck, ps_study_t
  use wellposed_mpm_deck_checks, only: check_plate_deck
  use wellposed_mpm_paths, only: find_data, plate_plot_name
  use wellposed_mpm_plate_cases, only: case_out_t, case_tag, case_config, put_case_out, &
                                       get_case_out, band_width, curve_difference, &
                                       write_csv_curve, write_csv_iterations
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_nonlocal_summary, only: add_nonlocal_summary, bound_text
  use wellposed_mpm_band_watch, only: band_watch_t, new_band_watch
  use wellposed_mpm_statev_outputs, only: plate_field_names, plate_field_widths, &
                                          plate_field_rows, add_plate_band, no_slot_why, &
                                          slot_plastic_strain
  use wellposed_mpm_plate_stations, only: plate_stations_t, new_plate_stations, &
                                          restore_plate_stations
  use wellposed_mpm_stop, only: stop_alone, stop_all
  use wellposed_mpm_run_loop, only: run_clock_t, checkpoint_every, checkpoint_due, snapshot_due
  use wellposed_mpm_decomposition, only: gather_by_gid
  use wellposed_mpm_snapshots, only: snapshot_store_t, new_snapshot_store
  use wellposed_mpi, only: comm_t, allreduce_max, &
                           allreduce_sum, broadcast
  use wellposed_checkpoint, only: checkpoint_t, write_checkpoint
  use wellposed_mpm_resume, only: open_restart_checkpoint
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_writer_name
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: shell_quote, path_exists, remove_tree
  use wellposed_mpm_step_keeper, only: step_keeper_t
  implicit none
  private
  public :: run_plate

contains

  !> Run the plate deck cli%deck_path as the command line `cli` asks, on
  !> the ranks of `comm` (collective). Stops the program on an error.
  subroutine run_plate(cli, comm)
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(ps_config_t) :: cfg0, cfg
    type(ps_study_t) :: study
    type(mpm_scene_t) :: sc
    !> the last complete step, for stop_on_cutback
    type(step_keeper_t) :: keeper
    type(mpm_ranks_t) :: ranks
    type(case_out_t), allocatable :: outs(:)
    type(band_watch_t) :: bw
    !> the stations of the case being run and of every case (for run.h5)
    type(plate_stations_t) :: pst
    type(plate_stations_t), allocatable :: done_st(:)
    !> particle snapshots of every case: each rank keeps its particles' rows
    type(snapshot_store_t) :: store
    logical :: ended_early, measured, root, resuming
    real(dp) :: band_t
    character(len=512) :: end_message
    type(run_dir_t) :: rd
    type(h5_parallel_file_t) :: h5
    type(summary_t) :: sm
    type(error_t), allocatable :: err
    type(checkpoint_t) :: ck
    character(len=:), allocatable :: deck_text, tag, script
    character(len=:), allocatable :: ck_dir, ck_file, h5_path
    integer :: i, ic, ic0, nsteps_est, nsnap, ncurve, nit, ck_every, ck_every_deck
    integer :: steps_before, ntotal, moved_sum
    type(run_clock_t) :: clock
    real(dp) :: wall, wall_before, next_snap, next_sample, s, fwhm, peak_x, peak_v, yline, epmax
    real(dp), allocatable :: curve(:, :), bounds(:, :)
    integer, allocatable :: its(:), nplast(:)

    root = comm%rank == 0
    call new_mpm_ranks(ranks, comm)
    ck_every_deck = cli%ck_every
    ck_file = cli%ck_file

    call read_ps_deck(cli%deck_path, cli%overrides, cfg0, study, deck_text, err)
    if (.not. allocated(err)) call check_plate_deck(cli%deck_path, cfg0, study, err, cli%force)
    if (allocated(err)) call die(err%message)
    if (len(cli%run_name) > 0) cfg0%name = cli%run_name
    ! check every case before writing anything
    do ic = 1, study%ncases
      do i = 1, ic - 1
        if (case_tag(study, i) == case_tag(study, ic)) call die(cli%deck_path// &
          ': &study: cases '//int_text(i)//' and '//int_text(ic)//' are both "'// &
          trim(case_tag(study, ic))//'"; give distinct dx/scale or labels')
      end do
      cfg = case_config(cfg0, study, ic)
      call new_scene(sc, cfg, err, ranks)
      if (allocated(err)) call die(cli%deck_path//' (case '//int_text(ic)//'): '//err%message)
    end do
    ck_dir = cli%out_root//'/'//cfg0%name//'.checkpoints'
    ic0 = 1
    call new_snapshot_store(store, plate_field_names(cfg0%nstatv), &
                            plate_field_widths(cfg0%nstatv), time_first=.false.)
    if (cli%restart) call read_restart()
    ! rank 0 makes the run folder; run.h5 in it is written by every rank
    h5_path = ''
    if (root) then
      call rd%create(cli%out_root, cfg0%name, cli%deck_path, err)
      if (allocated(err)) call stop_alone(comm, rd, err%message)
      h5_path = rd%path('run.h5')
    end if
    call broadcast(comm, h5_path, 0)
    call h5%create(comm, h5_path, err)
    if (allocated(err)) call die(err%message)
    call h5%write_attr('wellposed_version', wellposed_version)
    call h5%write_attr('git_revision', wellposed_git_revision)
    call h5%write_attr('deck', deck_text)
    call h5%write_attr('props', cfg0%props(1:cfg0%nprops))
    if (root) then
      write (output_unit, '(a)') 'wellposed-mpm '//wellposed_version//': '//cfg0%name// &
        ' ('//trim(cfg0%title)//'), '//int_text(study%ncases)//' case(s)'
      if (comm%size > 1) write (output_unit, '(a)') '  on '//int_text(comm%size)// &
        ' ranks (strips of cell rows; run.h5: '//h5_writer_name(comm)//')'
      write (output_unit, '(a)') '  writing '//rd%partial//' (renamed to '//rd%final// &
        ' when done)'
      flush (output_unit)
    end if
    allocate (outs(study%ncases), done_st(study%ncases))
    steps_before = 0
    if (cli%restart) then
      call resume_run()
    else if (root) then
      call sm%add('scene', cfg0%name)
      call sm%add('cases', study%ncases)
      call sm%add('shape', trim(shape2d_names(cfg0%shape)))
      call sm%add('scheme', trim(scheme_names(cfg0%scheme)), 'USL or MUSL (&time scheme)')
      call sm%add('nonlocal_scheme', trim(nl_scheme_names(cfg0%nonlocal%scheme)))
      if (study%band_axis == 'x') then
        call sm%add('band_line', 'horizontal line y = band_y * scale through the band', &
                    'the FWHM of ||eps^p|| along it, measured on particles within half a '// &
                    'particle spacing of it')
        call sm%add('band_y', study%band_y, 'm (unscaled plate)')
      else
        call sm%add('band_line', 'vertical line x = band_x * scale through the zone', &
                    'the FWHM of ||eps^p|| along it, measured on particles within half a '// &
                    'particle spacing of it')
        call sm%add('band_x', study%band_x, 'm (unscaled plate)')
      end if
    end if

    do ic = ic0, study%ncases
      cfg = case_config(cfg0, study, ic)
      s = study%scale(ic)
      tag = case_tag(study, ic)
      call new_scene(sc, cfg, err, ranks)
      if (allocated(err)) call die(err%message)
      ntotal = sc%ntotal
      nsteps_est = ceiling(cfg%t_end/sc%dt)
      ck_every = ck_every_deck
      ck_every = checkpoint_every(ck_every, nsteps_est)
      if (root) then
        write (output_unit, '(a)') '  case '//tag//': '//int_text(ntotal)//' particles, '// &
          int_text(sc%grid%nnodes)//' nodes, dt = '//real_text(sc%dt)//' s, ~'// &
          int_text(nsteps_est)//' steps, c = '//real_text(sc%c_max)//' m/s'
        if (sc%nl%active) write (output_unit, '(a)') '    nonlocal: L = '// &
          real_text(sc%nl%length)//' m, support radius '//real_text(sc%nl%radius)// &
          ' m, |h_zeta/(a + h_eta)| = '//bound_text(sc%nl%bound_43, real_text(sc%nl%bound_43))// &
          ' (eq. 4.43), |(h_eta + h_zeta)/a| = '//bound_text(sc%nl%bound_45, &
          real_text(sc%nl%bound_45))//' (eq. 4.45), scheme '// &
          trim(nl_scheme_names(cfg%nonlocal%scheme))
        flush (output_unit)
      end if
      allocate (curve(3, nsteps_est + 10), its(nsteps_est + 10), nplast(nsteps_est + 10), &
                bounds(3, nsteps_est + 10))
      ncurve = 0
      nit = 0
      nsnap = 0
      next_snap = 0.0_dp
      next_sample = 0.0_dp
      wall_before = 0.0_dp
      measured = .false.
      bw = new_band_watch(sc, study%band_drop, study%band_onset_strain)
      call new_plate_stations(pst, study, ic, sc, cfg%t_end, comm)
      resuming = cli%restart .and. ic == ic0
      call clock%start(10.0_dp)
      if (resuming) then
        call resume_case()
      else
        call snapshot()
      end if
      ended_early = .false.
      end_message = ''
      call keeper%clear()
      do while (sc%t < cfg%t_end - 0.5_dp*sc%dt)
        if (study%stop_on_cutback) call keeper%keep(sc)
        call advance(sc, err)
        if (allocated(err)) then
          if (.not. (study%stop_on_cutback .and. err%status == status_cutback)) &
            call die('case '//tag//': '//err%message)
          ! the material gave out: end the case at the last complete step
          end_message = err%message
          call keeper%restore(sc, err)
          if (allocated(err)) call die('case '//tag//': '//err%message)
          ended_early = .true.
          if (root) write (output_unit, '(a)') '    '//tag//': ended at t = '// &
            real_text(sc%t)//' s (&time stop_on_cutback): '//trim(end_message)
          exit
        end if
        nit = nit + 1
        call pst%sample(sc, comm)
        if (study%band_time > 0.0_dp .and. .not. measured .and. sc%t >= study%band_time) &
          call measure_band()
        its(nit) = sc%nl%last%iterations
        nplast(nit) = plastic_count(sc)     ! this rank's share, summed at the end
        bounds(:, nit) = [sc%nl%last%n_alpha, sc%nl%last%bound_printed, sc%nl%last%error]
        if (sc%t >= next_sample - 1.0e-12_dp) then
          ncurve = ncurve + 1
          curve(:, ncurve) = [sc%t, apparent_strain(sc), applied_stress(sc)]
          next_sample = next_sample + study%sample_dt
        end if
        call bw%step(sc, comm, curve(:, 1:ncurve))
        if (bw%just_staged .or. snapshot_due(study%snapshot_dt, sc%t, next_snap, 1.0e-12_dp)) call snapshot()
        if (checkpoint_due(ck_every, sc%nstep, sc%t, cfg%t_end, sc%dt)) call checkpoint()
        if (root .and. study%progress) then
          if (clock%progress_due()) then
            write (output_unit, '(a)') '    '//tag//': step '//int_text(sc%nstep)//'/'// &
              int_text(nsteps_est)//', t = '//real_text(sc%t)//' s, stress = '// &
              real_text(curve(3, max(ncurve, 1))*1.0e-6_dp)//' MPa, plastic '// &
              int_text(nplast(nit))// &
              ', iterations '//int_text(sc%nl%last%iterations)// &
              ', ~'//int_text(nint(clock%elapsed()*(nsteps_est - sc%nstep)/ &
              max(sc%nstep, 1)))//' s left'
            flush (output_unit)
          end if
        end if
      end do
      if (study%snapshot_dt <= 0.0_dp .or. next_snap - study%snapshot_dt < sc%t - 0.5_dp*sc%dt) &
        call snapshot()
      wall = wall_before + clock%elapsed()
      ! ---- measures (collective: band width, largest plastic strain, substeps)
      if (.not. measured) call measure_band()
      epmax = maxval(plastic_strain(sc))
      if (comm%size > 1) call allreduce_max(comm, epmax)
      i = max_substeps(sc)
      if (comm%size > 1) call allreduce_sum(comm, nplast(1:nit))
      moved_sum = sc%moved
      if (comm%size > 1) call allreduce_sum(comm, moved_sum)
      steps_before = steps_before + sc%nstep
      ! (on every rank: the curves and counts are alike on all)
      outs(ic)%tag = tag; outs(ic)%curve = curve(:, 1:ncurve)
      outs(ic)%its = its(1:nit); outs(ic)%nplast = nplast(1:nit)
      outs(ic)%bounds = bounds(:, 1:nit); outs(ic)%nsnap = nsnap
      outs(ic)%nparticles = ntotal; outs(ic)%nsteps = sc%nstep
      outs(ic)%scal(1:4) = [sc%dt, sc%t, sc%nl%bound_43, wall]
      outs(ic)%scal(7) = fwhm
      done_st(ic) = pst
      if (root) call finish_case(i)
      call write_case(ic)
      deallocate (curve, its, nplast, bounds)
    end do

    call h5%close(err)
    if (allocated(err)) call die(err%message)
    if (.not. root) return
    ! ---- across cases: successive meshes, sizes
    do ic = 2, study%ncases
      call sm%add(outs(ic)%tag//'.curve_difference_to_'//outs(ic - 1)%tag, &
                  curve_difference(outs(ic - 1)%curve, outs(ic)%curve)*1.0e-6_dp, &
                  'MPa: max |stress difference| over the common strain range')
      call width_ratio('band_fwhm', 7)
      call width_ratio('band_fwhm_normal', 8)
    end do
    call sm%add('h5_writer', h5_writer_name(comm), 'how run.h5 was written: every rank its '// &
                'rows through MPI-IO (mpio-collective), or rank 0 alone (rank0-gather)')
    call sm%add('total_wall_time', sum([(outs(ic)%scal(4), ic=1, study%ncases)]), 's')
    call sm%write(rd%path('summary.txt'), err)
    if (allocated(err)) call stop_alone(comm, rd, err%message)
    do ic = 1, study%ncases
      associate (o => outs(ic))
        call write_csv_curve(rd%path(o%tag//'_curve.csv'), o%curve)
        call write_csv_iterations(rd%path(o%tag//'_iterations.csv'), o%its, o%nplast, &
                                  o%scal(1), o%bounds, o%scal(3))
        call store%write_xdmf(rd%path(o%tag//'.xdmf'), 'run.h5', o%tag, o%nparticles, 2, 'xy', &
                              err, prefix='cases/'//o%tag//'/')
        if (allocated(err)) call stop_alone(comm, rd, err%message)
      end associate
    end do
    if (study%plot .and. .not. cli%no_plot) then
      script = find_data(plate_plot_name)
      block
        character(len=:), allocatable :: args
        args = shell_quote(rd%partial)
        do ic = 1, study%ncases
          args = args//' '//shell_quote(outs(ic)%tag)
        end do
        call run_plot(script, args, err)
      end block
      if (allocated(err)) call stop_alone(comm, rd, err%message)
    end if
    call rd%commit(err)
    if (allocated(err)) call stop_alone(comm, rd, err%message)
    ! the run is complete: its checkpoints have served (as a bar's)
    if (path_exists(ck_dir)) then
      call remove_tree(ck_dir, err)
      if (allocated(err)) write (error_unit, '(a)') 'wellposed-mpm: warning: '//err%message
    end if
    write (output_unit, '(a)') '  finished: '//rd%final//' (total '// &
      real_text(sum([(outs(ic)%scal(4), ic=1, study%ncases)]))//' s)'

  contains

    !> A band width of case ic over case ic - 1's (scal slot k), if both have one.
    subroutine width_ratio(key, k)
      character(len=*), intent(in) :: key
      integer, intent(in) :: k
      if (outs(ic)%scal(k) > 0.0_dp .and. outs(ic - 1)%scal(k) > 0.0_dp) then
        call sm%add(outs(ic)%tag//'.'//key//'_ratio_to_'//outs(ic - 1)%tag, &
                    outs(ic)%scal(k)/outs(ic - 1)%scal(k))
      else
        i = merge(ic - 1, ic, outs(ic - 1)%scal(k) <= 0.0_dp)
        call sm%not_applicable(outs(ic)%tag//'.'//key//'_ratio_to_'//outs(ic - 1)%tag, &
                               'case '//outs(i)%tag//' has no band width (its '//key//')')
      end if
    end subroutine width_ratio

    !> The summary lines of the case just finished (rank 0); `nsub` the
    !> largest UMAT cut-back split over the ranks.
    subroutine finish_case(nsub)
      integer, intent(in) :: nsub
      integer :: j
      character(len=:), allocatable :: band_text
      associate (o => outs(ic))
        j = maxloc(o%curve(3, :), dim=1)
        o%scal(5:6) = [o%curve(2, j), o%curve(3, j)]
        call sm%add(tag//'.dx', cfg%dx, 'm')
        call sm%add(tag//'.scale', s)
        call sm%add(tag//'.particles', ntotal)
        call sm%add(tag//'.steps', sc%nstep)
        call sm%add(tag//'.dt', sc%dt, 's')
        call sm%add(tag//'.wall_time', wall, 's')
        call sm%add(tag//'.ns_per_particle_step', wall*1.0e9_dp/max(1.0_dp, real(ntotal, dp)*sc%nstep))
        call sm%add(tag//'.peak_stress', o%scal(6)*1.0e-6_dp, 'MPa, compression +')
        call sm%add(tag//'.strain_at_peak', o%scal(5), 'apparent axial strain')
        call sm%add(tag//'.final_stress', o%curve(3, size(o%curve, 2))*1.0e-6_dp, 'MPa')
        call sm%add(tag//'.final_strain', o%curve(2, size(o%curve, 2)))
        call add_plate_band(sm, tag, sc%parts%nstatv, epmax, fwhm, yline, band_t, peak_x, peak_v)
        if (sc%parts%nstatv < slot_plastic_strain) then
          call bw%summarise(sm, tag, no_slot_why('plastic strain', sc%parts%nstatv))
        else
          call bw%summarise(sm, tag)
        end if
        call pst%summarise(sm, tag)
        if (bw%staged .and. bw%fit%found) o%scal(8) = bw%fit%fwhm
        call sm%add(tag//'.max_substeps', nsub)
        call sm%add(tag//'.ended_early', ended_early, 'true: the UMAT could not go on '// &
                    '(stop_on_cutback); the curve ends at final_strain')
        if (ended_early) call sm%add(tag//'.end_reason', trim(end_message))
        if (sc%nl%active) then
          call add_nonlocal_summary(sm, tag//'.', sc%nl)
          if (sc%nl%calls_sweeps > 0 .and. sc%nl%calls_local > 0) &
            call sm%add(tag//'.sweep_cost_over_local_update', &
                        (real(sc%nl%ticks_sweeps, dp)/sc%nl%calls_sweeps)/ &
                        (real(max(sc%nl%ticks_local, 1_int64), dp)/sc%nl%calls_local), &
                        'time per particle of one sweep (average + UMAT + eq. 4.49-4.50) '// &
                        'over one local UMAT update')
        end if
        band_text = 'no band: NSTATV = '//int_text(sc%parts%nstatv)//' has no plastic strain'
        if (sc%parts%nstatv >= slot_plastic_strain) band_text = 'band FWHM '// &
          real_text(fwhm)//' m along the line at '//real_text(yline)//' m'
        write (output_unit, '(a)') '    done in '//real_text(wall)//' s: peak '// &
          real_text(o%scal(6)*1.0e-6_dp)//' MPa at strain '//real_text(o%scal(5))//', '// &
          band_text
        if (sc%nl%active) write (output_unit, '(a)') '    nonlocal iterations per step: '// &
          'mean '//real_text(real(sc%nl%iterations_total, dp)/max(sc%nl%steps_iterated, 1))// &
          ', max '//int_text(sc%nl%iterations_max)//' over '// &
          int_text(sc%nl%steps_iterated)//' plastic steps'
        if (comm%size > 1) write (output_unit, '(a)') '    particles handed between ranks: '// &
          int_text(moved_sum)
        flush (output_unit)
      end associate
    end subroutine finish_case

    !> The run.h5 datasets of finished case k beside its snapshots
    !> (collective; rank 0's values).
    subroutine write_case(k)
      integer, intent(in) :: k
      associate (o => outs(k))
        call h5%write('cases/'//o%tag//'/curve', transpose(o%curve))
        call h5%write('cases/'//o%tag//'/iterations', o%its)
        call h5%write('cases/'//o%tag//'/n_plastic', o%nplast)
        call done_st(k)%write_h5(h5, 'cases/'//o%tag//'/stations/')
      end associate
    end subroutine write_case

    !> The band width now (fwhm, peak_x, peak_v on rank 0; yline, band_t,
    !> measured everywhere). Collective: rank 0 gathers the particles.
    subroutine measure_band()
      real(dp), allocatable :: f(:, :), all(:, :)
      integer :: n, axis
      n = sc%parts%n
      allocate (f(3, n))
      f(1:2, :) = sc%parts%x(:, 1:n)
      f(3, :) = plastic_strain(sc)
      call gather_by_gid(comm, sc%parts%gid(1:n), f, 0, all)
      if (study%band_axis == 'x') then
        yline = study%band_y*study%scale(ic)
        axis = 1
      else
        yline = study%band_x*study%scale(ic)
        axis = 2
      end if
      fwhm = 0.0_dp; peak_x = 0.0_dp; peak_v = 0.0_dp
      if (root) call band_width(all(1:2, :), all(3, :), axis, yline, &
                               0.5_dp*cfg%dx/cfg%ppc, fwhm, peak_x, peak_v)
      band_t = sc%t
      measured = .true.
    end subroutine measure_band

    !> Particle fields of the current state into run.h5: cases/<tag>/snap_<n>/
    !> (collective: every rank its own particles' rows, in global-id order in
    !> the file; `store` keeps them); also at the band's stage, off schedule.
    subroutine snapshot()
      real(dp), allocatable :: f(:, :)
      type(error_t), allocatable :: e
      integer :: n
      nsnap = nsnap + 1
      if (snapshot_due(study%snapshot_dt, sc%t, next_snap, 1.0e-12_dp)) next_snap = next_snap + study%snapshot_dt
      n = sc%parts%n
      allocate (f(8, n))
      f(1:2, :) = sc%parts%x(:, 1:n)
      f(3, :) = plastic_strain(sc)
      f(4, :) = sc%parts%stress(1, 1:n)
      f(5, :) = sc%parts%stress(2, 1:n)
      f(6, :) = sc%parts%stress(4, 1:n)
      f(7:8, :) = 0.0_dp
      if (sc%parts%nstatv >= 2) f(7, :) = sc%parts%statev(2, 1:n)
      if (sc%parts%nstatv >= 4) f(8, :) = sc%parts%statev(4, 1:n)
      call store%take(h5, comm, 'cases/'//tag//'/snap_'//int_text(nsnap)//'/', sc%t, &
                      sc%parts%gid(1:n), f(plate_field_rows(sc%parts%nstatv), :), e)
      if (allocated(e)) call die('case '//tag//': '//e%message)
    end subroutine snapshot

    !> The run's state after this step into ROOT/NAME.checkpoints (collective;
    !> rank 0 writes): the scene, the snapshots so far, this case's curves
    !> and counters, the finished cases and the summary lines.
    subroutine checkpoint()
      type(checkpoint_t) :: ckw
      type(error_t), allocatable :: e
      character(len=:), allocatable :: path, pre, lines
      integer :: k
      integer, allocatable :: nplast_all(:)
      call save_scene(sc, ckw)
      call store%put(ckw, comm, 'snapshots/')
      nplast_all = nplast(1:nit)
      if (comm%size > 1) call allreduce_sum(comm, nplast_all)
      if (.not. root) return
      call ckw%put_text('main/deck', deck_text)
      call ckw%put('main/case', [ic, ncurve, nit, nsnap, merge(1, 0, measured), steps_before])
      call ckw%put('main/reals', [next_snap, next_sample, fwhm, peak_x, peak_v, yline, band_t, &
                                  wall_before + clock%elapsed()])
      call ckw%put('main/curve', [0.0_dp, reshape(curve(:, 1:ncurve), [3*ncurve])])
      call ckw%put('main/its', [0, its(1:nit)])
      call ckw%put('main/nplast', [0, nplast_all])
      call ckw%put('main/bounds', [0.0_dp, reshape(bounds(:, 1:nit), [3*nit])])
      call bw%put(ckw, 'main/band_watch/')
      call pst%put(ckw, 'main/stations/')
      do k = 1, ic - 1
        pre = 'main/done_'//int_text(k)//'/'
        call put_case_out(ckw, pre, outs(k))
        call done_st(k)%put(ckw, pre//'stations/')
      end do
      lines = ''
      do k = 1, sm%n
        lines = lines//sm%lines(k)%text//new_line('a')
      end do
      call ckw%put_text('main/summary', lines)
      call write_checkpoint(ckw, ck_dir, steps_before + sc%nstep, 2, path, e)
      if (allocated(e)) call stop_alone(comm, rd, e%message)
    end subroutine checkpoint

    !> --restart: read the newest checkpoint (or --restart-from FILE) on every
    !> rank and check that it belongs to this deck; ic0 is its case.
    subroutine read_restart()
      type(error_t), allocatable :: e
      integer, allocatable :: cs(:)
      call open_restart_checkpoint(ck_dir, cli%deck_path, deck_text, ck_file, ck, e)
      if (allocated(e)) call die(e%message)
      call ck%get('main/case', cs, e)
      if (allocated(e)) call die(ck_file//': '//e%message)
      if (size(cs) /= 6) call die(ck_file//': its case entry is garbled')
      if (cs(1) < 1 .or. cs(1) > study%ncases) call die(ck_file//': case '//int_text(cs(1))// &
        ' is not a case of '//cli%deck_path)
      ic0 = cs(1)
    end subroutine read_restart

    !> --restart, before the cases: the finished cases, steps so far, the
    !> snapshots, on rank 0 the summary lines, and run.h5 as it was at the
    !> checkpoint (collective).
    subroutine resume_run()
      type(error_t), allocatable :: e
      integer, allocatable :: cs(:)
      character(len=:), allocatable :: pre, lines, line
      integer :: k, at, n, eq
      call ck%get('main/case', cs, e)
      steps_before = cs(6)
      do k = 1, ic0 - 1
        pre = 'main/done_'//int_text(k)//'/'
        call get_case_out(ck, pre, outs(k), e)
        if (allocated(e)) call die(ck_file//': '//e%message)
        cfg = case_config(cfg0, study, k)
        call restore_plate_stations(done_st(k), study, cfg%t_end, comm, ck, pre//'stations/', e)
        if (allocated(e)) call stop_alone(comm, rd, ck_file//': '//e%message)
      end do
      call store%get(ck, comm, 'snapshots/', e)
      if (allocated(e)) call die(ck_file//': '//e%message)
      ! run.h5 in the order the interrupted run wrote it
      do k = 1, ic0 - 1
        call store%write_stored(h5, comm, e, prefix='cases/'//outs(k)%tag//'/')
        if (allocated(e)) call die(e%message)
        call write_case(k)
      end do
      call store%write_stored(h5, comm, e, prefix='cases/'//case_tag(study, ic0)//'/')
      if (allocated(e)) call die(e%message)
      if (.not. root) return
      call ck%get_text('main/summary', lines, e); if (allocated(e)) call stop_alone(comm, rd, e)
      at = 1
      do while (at <= len(lines))
        n = index(lines(at:), new_line('a'))
        line = lines(at:at + n - 2)
        at = at + n
        eq = index(line, ' = ')
        call sm%add(line(1:eq - 1), line(eq + 3:))
      end do
      write (output_unit, '(a)') '  restarted from '//ck_file//' (case '// &
        int_text(ic0)//', '//int_text(steps_before)//' steps of earlier cases)'
      flush (output_unit)
    end subroutine resume_run

    !> --restart, in the case it interrupted: the scene on every rank and the
    !> case's curves and counters.
    subroutine resume_case()
      type(error_t), allocatable :: e
      integer, allocatable :: cs(:), iv(:)
      real(dp), allocatable :: a(:)
      call restore_scene(sc, ck, e)
      if (allocated(e)) call die(ck_file//': '//e%message)
      call ck%get('main/case', cs, e)
      ncurve = cs(2)
      nit = cs(3)
      nsnap = cs(4)
      measured = cs(5) == 1
      call ck%get('main/reals', a, e)
      if (allocated(e) .or. size(a) /= 8) call die(ck_file//': its main/reals entry is garbled')
      next_snap = a(1); next_sample = a(2); fwhm = a(3); peak_x = a(4); peak_v = a(5)
      yline = a(6); band_t = a(7); wall_before = a(8)
      call ck%get('main/curve', a, e); if (allocated(e)) call die(ck_file//': '//e%message)
      curve(:, 1:ncurve) = reshape(a(2:), [3, ncurve])
      call ck%get('main/bounds', a, e); if (allocated(e)) call die(ck_file//': '//e%message)
      bounds(:, 1:nit) = reshape(a(2:), [3, nit])
      call ck%get('main/its', iv, e); if (allocated(e)) call die(ck_file//': '//e%message)
      its(1:nit) = iv(2:)
      call ck%get('main/nplast', iv, e); if (allocated(e)) call die(ck_file//': '//e%message)
      nplast(1:nit) = iv(2:)
      call bw%get(ck, 'main/band_watch/', e); if (allocated(e)) call die(ck_file//': '//e%message)
      call pst%get(ck, 'main/stations/', e)
      if (allocated(e)) call stop_alone(comm, rd, ck_file//': '//e%message)
      if (.not. root) nplast(1:nit) = 0      ! rank 0 holds the counts so far
      if (root) write (output_unit, '(a)') '    '//tag//': continuing at step '// &
        int_text(sc%nstep)//', t = '//real_text(sc%t)//' s'
    end subroutine resume_case

    !> Stop every rank with `message` (collective: every rank calls it; rank 0
    !> prints).
    subroutine die(message)
      character(len=*), intent(in) :: message
      call stop_all(comm, rd, message)
    end subroutine die

  end subroutine run_plate

end module wellposed_mpm_plate_run
