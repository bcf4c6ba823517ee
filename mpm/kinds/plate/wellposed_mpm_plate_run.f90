!> The plate scene of wellposed-mpm: the plane-strain MPM on the plate of
!> chapter 4 (fig. 4.1-4.6), one or more cases per deck (&study;
!> wellposed_mpm_plate_cases). Writes ROOT/NAME/ (the deck, run.h5, a
!> <case>.xdmf, curve and iteration CSVs per case, summary.txt, plots)
!> through ROOT/NAME.partial, renamed at the end. Each case is the one run
!> loop (wellposed_mpm_run_loop) over the plate's outputs
!> (wellposed_mpm_plate_outputs); ranks write run.h5 collectively, rank 0
!> the rest. Checkpoints and --restart as the bar's. Outputs: docs/guide/mpm.md.
module wellposed_mpm_plate_run
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_plate_build, only: plate_config_t
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, max_substeps
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpm_shape_2d, only: shape2d_names
  use wellposed_mpm_method, only: scheme_names
  use wellposed_mpm_nonlocal, only: nl_scheme_names
  use wellposed_mpm_plate_deck, only: read_plate_deck, plate_study_t
  use wellposed_mpm_plate_checks, only: check_plate_deck
  use wellposed_mpm_paths, only: find_data, plate_plot_name
  use wellposed_mpm_plate_cases, only: case_out_t, case_tag, case_config, curve_difference, &
                                       write_csv_curve, write_csv_iterations
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_nonlocal_summary, only: add_nonlocal_summary, bound_text
  use wellposed_mpm_plate_band_watch, only: new_band_watch
  use wellposed_mpm_statev_outputs, only: plate_field_names, plate_field_widths, &
                                          slot_plastic_strain
  use wellposed_mpm_plate_stations, only: new_plate_stations
  use wellposed_mpm_stop, only: stop_alone, stop_all
  use wellposed_mpm_run_files, only: open_run_files
  use wellposed_mpm_snapshots, only: new_snapshot_store
  use wellposed_mpi, only: comm_t, allreduce_sum
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_writer_name
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: shell_quote
  use wellposed_mpm_output, only: output_list_t, stage_start, stage_finish
  use wellposed_mpm_checkpoints, only: run_checkpoints_t, new_run_checkpoints
  use wellposed_mpm_run_loop, only: checkpoint_every, run_steps, loop_end_t
  use wellposed_mpm_method, only: implicit_scheme, scheme_newmark
  use wellposed_mpm_implicit_stepper, only: implicit_stepper_t
  use wellposed_mpm_implicit_run, only: start_implicit, implicit_summary, write_newton_csv
  use wellposed_mpm_plate_outputs, only: plate_curve_t, plate_band_t, plate_watch_t, &
                                         plate_stations_output_t, plate_snapshots_t, &
                                         plate_progress_t
  use wellposed_mpm_plate_done, only: plate_done_t, checkpoint_case
  implicit none
  private
  public :: run_plate

  !> A plate run: its deck, files, finished cases and the snapshots of
  !> every case (a target, never copied: the outputs point into it).
  type :: plate_run_t
    type(plate_config_t) :: cfg0
    type(plate_study_t) :: study
    type(mpm_ranks_t) :: ranks
    type(run_dir_t) :: rd
    type(h5_parallel_file_t) :: h5
    type(summary_t) :: sm
    type(plate_done_t) :: done
    type(plate_snapshots_t) :: snaps
    type(run_checkpoints_t) :: cks
    character(len=:), allocatable :: deck_text
    integer :: ic0 = 1               !< the first case to run (--restart: the interrupted one)
  end type plate_run_t

  !> One case: its scene and outputs (a target, never copied).
  type :: plate_case_t
    integer :: ic = 0, nsteps_est = 0
    type(plate_config_t) :: cfg
    type(mpm_scene_t) :: sc
    character(len=:), allocatable :: tag
    type(plate_curve_t) :: curve
    type(plate_band_t) :: band
    type(plate_watch_t) :: watch
    type(plate_stations_output_t) :: stations
    type(plate_progress_t) :: progress
    !> every output, and those a --restart gets back into the case
    type(output_list_t) :: outs, resumed
    type(loop_end_t) :: ended
    !> the implicit scheme's steps (&time scheme = 'implicit')
    logical :: implicit = .false.
    type(implicit_stepper_t) :: stepper
  end type plate_case_t

contains

  !> Run the plate deck cli%deck_path as the command line `cli` asks, on
  !> the ranks of `comm` (collective). Stops the program on an error.
  subroutine run_plate(cli, comm)
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(plate_run_t), target :: r
    integer :: ic
    call open_plate(r, cli, comm)
    do ic = r%ic0, r%study%ncases
      call run_case(r, ic, cli, comm)
    end do
    call finish_plate(r, cli, comm)
  end subroutine run_plate

  !> The deck (every case checked before anything is written), on
  !> --restart the checkpoint, the run folder, run.h5 and the opening
  !> lines (collective).
  subroutine open_plate(r, cli, comm)
    type(plate_run_t), target, intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    logical :: root
    root = comm%rank == 0
    call new_mpm_ranks(r%ranks, comm)
    call read_plate_deck(cli%deck_path, cli%overrides, cli%kinds, r%cfg0, r%study, &
                         r%deck_text, err)
    if (.not. allocated(err)) &
      call check_plate_deck(cli%deck_path, r%cfg0, r%study, err, cli%force)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    if (len(cli%run_name) > 0) r%cfg0%name = cli%run_name
    call check_cases(r, cli, comm)
    r%cks = new_run_checkpoints(cli%out_root, r%cfg0%name, cli%ck_every, cli%ck_file, &
                                r%deck_text, r%rd)
    call new_snapshot_store(r%snaps%store, plate_field_names(r%cfg0%nstatv), &
                            plate_field_widths(r%cfg0%nstatv), time_first=.false.)
    r%snaps%name = 'snapshots'
    r%snaps%h5 => r%h5
    r%snaps%interval = r%study%snapshot_dt
    call r%snaps%store%keep_files(r%cks%dir, cli%ck_every /= 0)
    call r%done%setup(r%study, r%cfg0%t_end, r%sm)
    if (cli%restart) then
      call r%cks%open(cli%deck_path, err)
      if (.not. allocated(err)) call checkpoint_case(r%cks%ck, r%study%ncases, r%ic0, err)
      if (allocated(err)) call stop_all(comm, r%rd, err)
      r%done%current = r%ic0
    end if
    ! rank 0 makes the run folder; run.h5 in it is written by every rank
    call open_run_files(r%rd, r%h5, comm, cli%out_root, r%cfg0%name, cli%deck_path)
    call r%h5%write_attr('wellposed_version', wellposed_version)
    call r%h5%write_attr('git_revision', wellposed_git_revision)
    call r%h5%write_attr('deck', r%deck_text)
    call r%h5%write_attr('props', r%cfg0%props(1:r%cfg0%nprops))
    if (root) then
      write (output_unit, '(a)') 'wellposed-mpm '//wellposed_version//': '//r%cfg0%name// &
        ' ('//trim(r%cfg0%title)//'), '//int_text(r%study%ncases)//' case(s)'
      if (comm%size > 1) write (output_unit, '(a)') '  on '//int_text(comm%size)// &
        ' ranks (strips of cell rows; run.h5: '//h5_writer_name(comm)//')'
      write (output_unit, '(a)') '  writing '//r%rd%partial//' (renamed to '//r%rd%final// &
        ' when done)'
      flush (output_unit)
    end if
    if (cli%restart) then
      call resume_run(r, comm)
    else if (root) then
      call summary_head(r)
    end if
  end subroutine open_plate

  !> Every case's tag distinct and its scene buildable (and steppable by
  !> the implicit scheme when the deck asks for it; collective).
  subroutine check_cases(r, cli, comm)
    type(plate_run_t), intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(mpm_scene_t) :: sc
    type(implicit_stepper_t) :: st
    type(error_t), allocatable :: err
    integer :: i, ic
    do ic = 1, r%study%ncases
      do i = 1, ic - 1
        if (case_tag(r%study, i) == case_tag(r%study, ic)) call stop_all(comm, r%rd, &
          cli%deck_path//': &study: cases '//int_text(i)//' and '//int_text(ic)// &
          ' are both "'//trim(case_tag(r%study, ic))//'"; give distinct dx/scale or labels')
      end do
      call new_scene(sc, case_config(r%cfg0, r%study, ic), err, r%ranks)
      if (.not. allocated(err) .and. implicit_scheme(r%cfg0%scheme)) &
        call start_implicit(sc, r%cfg0%implicit_dt, r%cfg0%linear_solver, &
                           r%cfg0%scheme == scheme_newmark, cli%restart, st, err)
      if (allocated(err)) call stop_all(comm, r%rd, cli%deck_path//' (case '//int_text(ic)// &
                                        '): '//err%message)
    end do
  end subroutine check_cases

  !> The run's summary lines before its cases' (rank 0).
  subroutine summary_head(r)
    type(plate_run_t), intent(inout) :: r
    associate (sm => r%sm, study => r%study, cfg0 => r%cfg0)
      call sm%add('scene', cfg0%name)
      call sm%add('cases', study%ncases)
      call sm%add('shape', trim(shape2d_names(cfg0%shape)))
      call sm%add('scheme', trim(scheme_names(cfg0%scheme)), 'USL, MUSL, implicit '// &
                  'or newmark (&time scheme)')
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
    end associate
  end subroutine summary_head

  !> --restart, before the cases: the finished cases, the snapshots, on
  !> rank 0 the summary lines, and run.h5 as it was at the checkpoint.
  subroutine resume_run(r, comm)
    type(plate_run_t), intent(inout) :: r
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: e
    integer :: k
    call r%done%get(r%cks%ck, comm, e)
    if (.not. allocated(e)) call r%snaps%get(r%cks%ck, comm, e)
    if (allocated(e)) call stop_alone(comm, r%rd, r%cks%file//': '//e%message)
    r%cks%steps_before = r%done%steps_before
    ! run.h5 in the order the interrupted run wrote it
    do k = 1, r%ic0 - 1
      call r%snaps%store%write_stored(r%h5, comm, e, prefix='cases/'//r%done%outs(k)%tag//'/')
      if (allocated(e)) call stop_all(comm, r%rd, e)
      call r%done%write_case(r%h5, k)
    end do
    call r%snaps%store%write_stored(r%h5, comm, e, prefix='cases/'//case_tag(r%study, r%ic0)//'/')
    if (allocated(e)) call stop_all(comm, r%rd, e)
    if (comm%rank /= 0) return
    write (output_unit, '(a)') '  restarted from '//r%cks%file//' (case '// &
      int_text(r%ic0)//', '//int_text(r%done%steps_before)//' steps of earlier cases)'
    flush (output_unit)
  end subroutine resume_run

  !> Case ic from its start (or, on --restart, from the checkpoint) to its
  !> end, its outputs recorded with the finished cases (collective).
  subroutine run_case(r, ic, cli, comm)
    type(plate_run_t), target, intent(inout) :: r
    integer, intent(in) :: ic
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(plate_case_t), target :: c
    type(error_t), allocatable :: err
    call new_case(r, c, ic, cli, comm)
    call c%progress%clock%start(10.0_dp)
    if (cli%restart .and. ic == r%ic0) then
      call r%cks%resume(c%sc, c%resumed, comm, err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
      if (comm%rank == 0) write (output_unit, '(a)') '    '//c%tag//': continuing at step '// &
        int_text(c%sc%nstep)//', t = '//real_text(c%sc%t)//' s'
    else
      call c%outs%ask(stage_start, c%sc, comm, err)
      if (allocated(err)) call stop_all(comm, r%rd, 'case '//c%tag//': '//err%message)
    end if
    if (c%implicit) then
      call run_steps(c%sc, c%cfg%t_end, c%outs, r%cks, comm, r%study%stop_on_cutback, &
                     c%ended, err, c%stepper)
    else
      call run_steps(c%sc, c%cfg%t_end, c%outs, r%cks, comm, r%study%stop_on_cutback, &
                     c%ended, err)
    end if
    if (allocated(err)) call stop_all(comm, r%rd, 'case '//c%tag//': '//err%message)
    ! the material gave out: the case ends at the last complete step
    if (c%ended%early .and. comm%rank == 0) write (output_unit, '(a)') '    '//c%tag// &
      ': ended at t = '//real_text(c%sc%t)//' s (&time stop_on_cutback): '// &
      trim(c%ended%message)
    call end_case(r, c, comm)
  end subroutine run_case

  !> Case ic's scene, its opening lines and its outputs, in the order the
  !> loop asks them (collective).
  subroutine new_case(r, c, ic, cli, comm)
    type(plate_run_t), target, intent(inout) :: r
    type(plate_case_t), target, intent(inout) :: c
    integer, intent(in) :: ic
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    real(dp) :: s
    c%ic = ic
    c%cfg = case_config(r%cfg0, r%study, ic)
    c%tag = case_tag(r%study, ic)
    s = r%study%scale(ic)
    call new_scene(c%sc, c%cfg, err, r%ranks)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    c%implicit = implicit_scheme(c%cfg%scheme)
    if (c%implicit) then
      call start_implicit(c%sc, c%cfg%implicit_dt, c%cfg%linear_solver, &
                          c%cfg%scheme == scheme_newmark, cli%restart .and. ic == r%ic0, &
                          c%stepper, err)
      if (allocated(err)) call stop_all(comm, r%rd, err)
    end if
    c%nsteps_est = ceiling(c%cfg%t_end/c%sc%dt)
    r%cks%every = checkpoint_every(cli%ck_every, c%nsteps_est)
    r%done%current = ic
    if (comm%rank == 0) call say_case(c)
    call c%curve%setup(c%tag, c%nsteps_est, r%study%sample_dt)
    c%band%name = 'band'
    c%band%tag = c%tag
    c%band%axis = r%study%band_axis
    c%band%line = merge(r%study%band_y, r%study%band_x, r%study%band_axis == 'x')*s
    c%band%half_spacing = 0.5_dp*c%cfg%dx/c%cfg%ppc
    c%band%band_time = r%study%band_time
    c%band%nstatv = c%sc%parts%nstatv
    c%watch%name = 'band_watch'
    c%watch%tag = c%tag
    c%watch%bw = new_band_watch(c%sc, r%study%band_drop, r%study%band_onset_strain)
    c%watch%curve => c%curve
    c%watch%nstatv = c%sc%parts%nstatv
    c%stations%name = 'stations'
    c%stations%tag = c%tag
    call new_plate_stations(c%stations%pst, r%study, ic, c%sc, c%cfg%t_end, comm)
    r%snaps%tag = c%tag
    r%snaps%watch => c%watch
    c%progress%name = 'progress'
    c%progress%on = r%study%progress .and. comm%rank == 0
    c%progress%tag = c%tag
    c%progress%nsteps_est = c%nsteps_est
    c%progress%t_end = c%cfg%t_end
    c%progress%curve => c%curve
    call c%outs%add(c%curve)
    call c%outs%add(c%band)
    call c%outs%add(c%watch)
    call c%outs%add(c%stations)
    call c%outs%add(r%snaps)
    call c%outs%add(r%done)
    call c%outs%add(c%progress)
    call c%resumed%add(c%curve)
    call c%resumed%add(c%band)
    call c%resumed%add(c%watch)
    call c%resumed%add(c%stations)
    call c%resumed%add(c%progress)
  end subroutine new_case

  !> The case's opening lines (rank 0).
  subroutine say_case(c)
    type(plate_case_t), intent(in) :: c
    associate (sc => c%sc)
      write (output_unit, '(a)') '  case '//c%tag//': '//int_text(sc%ntotal)//' particles, '// &
        int_text(sc%grid%nnodes)//' nodes, dt = '//real_text(sc%dt)//' s, ~'// &
        int_text(c%nsteps_est)//' steps, c = '//real_text(sc%c_max)//' m/s'
      if (sc%nl%active) write (output_unit, '(a)') '    nonlocal: L = '// &
        real_text(sc%nl%length)//' m, support radius '//real_text(sc%nl%radius)// &
        ' m, |h_zeta/(a + h_eta)| = '//bound_text(sc%nl%bound_43, real_text(sc%nl%bound_43))// &
        ' (eq. 4.43), |(h_eta + h_zeta)/a| = '//bound_text(sc%nl%bound_45, &
        real_text(sc%nl%bound_45))//' (eq. 4.45), scheme '// &
        trim(nl_scheme_names(c%cfg%nonlocal%scheme))
      flush (output_unit)
    end associate
  end subroutine say_case

  !> After the case's last step: its outputs' measures, its record among
  !> the finished cases, its summary lines and run.h5 datasets (collective).
  subroutine end_case(r, c, comm)
    type(plate_run_t), intent(inout) :: r
    type(plate_case_t), intent(inout) :: c
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    real(dp) :: wall
    integer :: nsub, moved
    call c%outs%ask(stage_finish, c%sc, comm, err)
    if (allocated(err)) call stop_all(comm, r%rd, 'case '//c%tag//': '//err%message)
    wall = c%progress%wall()
    nsub = max_substeps(c%sc)
    moved = c%sc%moved
    if (comm%size > 1) call allreduce_sum(comm, moved)
    r%done%steps_before = r%done%steps_before + c%sc%nstep
    r%cks%steps_before = r%done%steps_before
    ! (on every rank: the curves and counts are alike on all)
    associate (o => r%done%outs(c%ic), cv => c%curve)
      o%tag = c%tag; o%curve = cv%curve(:, 1:cv%ncurve)
      o%its = cv%its(1:cv%nit); o%nplast = cv%nplast(1:cv%nit)
      o%bounds = cv%bounds(:, 1:cv%nit); o%nsnap = r%snaps%taken
      o%nparticles = c%sc%ntotal; o%nsteps = c%sc%nstep
      o%scal(1:4) = [c%sc%dt, c%sc%t, c%sc%nl%bound_43, wall]
      o%scal(7) = c%band%fwhm
    end associate
    r%done%st(c%ic) = c%stations%pst
    if (comm%rank == 0) call case_summary(r, c, nsub, moved, wall, comm%size)
    if (comm%rank == 0 .and. c%implicit) then
      call write_newton_csv(r%rd%path(c%tag//'_newton.csv'), c%stepper, err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end if
    call r%done%write_case(r%h5, c%ic)
  end subroutine end_case

  !> The summary lines of the case just finished and its closing lines
  !> (rank 0); `nsub` the largest UMAT cut-back split over the ranks.
  subroutine case_summary(r, c, nsub, moved, wall, nranks)
    type(plate_run_t), intent(inout) :: r
    type(plate_case_t), intent(inout) :: c
    integer, intent(in) :: nsub, moved, nranks
    real(dp), intent(in) :: wall
    character(len=:), allocatable :: band_text, tag
    integer :: j
    tag = c%tag
    associate (o => r%done%outs(c%ic), sm => r%sm, sc => c%sc)
      j = maxloc(o%curve(3, :), dim=1)
      o%scal(5:6) = [o%curve(2, j), o%curve(3, j)]
      call sm%add(tag//'.dx', c%cfg%dx, 'm')
      call sm%add(tag//'.scale', r%study%scale(c%ic))
      call sm%add(tag//'.particles', sc%ntotal)
      call sm%add(tag//'.steps', sc%nstep)
      call sm%add(tag//'.dt', sc%dt, 's')
      call sm%add(tag//'.wall_time', wall, 's')
      call sm%add(tag//'.ns_per_particle_step', &
                  wall*1.0e9_dp/max(1.0_dp, real(sc%ntotal, dp)*sc%nstep))
      call c%outs%summarise(sm)
      if (c%watch%bw%staged .and. c%watch%bw%fit%found) o%scal(8) = c%watch%bw%fit%fwhm
      call sm%add(tag//'.max_substeps', nsub)
      if (c%implicit) call implicit_summary(sm, tag//'.', c%stepper)
      call sm%add(tag//'.ended_early', c%ended%early, 'true: the UMAT could not go on '// &
                  '(stop_on_cutback); the curve ends at final_strain')
      if (c%ended%early) call sm%add(tag//'.end_reason', trim(c%ended%message))
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
        real_text(c%band%fwhm)//' m along the line at '//real_text(c%band%line)//' m'
      write (output_unit, '(a)') '    done in '//real_text(wall)//' s: peak '// &
        real_text(o%scal(6)*1.0e-6_dp)//' MPa at strain '//real_text(o%scal(5))//', '// &
        band_text
      if (sc%nl%active) write (output_unit, '(a)') '    nonlocal iterations per step: '// &
        'mean '//real_text(real(sc%nl%iterations_total, dp)/max(sc%nl%steps_iterated, 1))// &
        ', max '//int_text(sc%nl%iterations_max)//' over '// &
        int_text(sc%nl%steps_iterated)//' plastic steps'
      if (nranks > 1) write (output_unit, '(a)') '    particles handed between ranks: '// &
        int_text(moved)
      flush (output_unit)
    end associate
  end subroutine case_summary

  !> After the cases: run.h5 closed, the lines across cases, summary.txt,
  !> the CSVs and XDMF of every case, the plots; the folder renamed.
  subroutine finish_plate(r, cli, comm)
    type(plate_run_t), intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    character(len=:), allocatable :: args
    integer :: ic
    real(dp) :: total
    call r%h5%close(err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    call r%snaps%store%close()
    if (comm%rank /= 0) return
    associate (outs => r%done%outs, sm => r%sm)
      ! across cases: successive meshes, sizes
      do ic = 2, r%study%ncases
        call sm%add(outs(ic)%tag//'.curve_difference_to_'//outs(ic - 1)%tag, &
                    curve_difference(outs(ic - 1)%curve, outs(ic)%curve)*1.0e-6_dp, &
                    'MPa: max |stress difference| over the common strain range')
        call width_ratio(sm, outs(ic - 1), outs(ic), 'band_fwhm', 7)
        call width_ratio(sm, outs(ic - 1), outs(ic), 'band_fwhm_normal', 8)
      end do
      total = sum([(outs(ic)%scal(4), ic=1, r%study%ncases)])
      call sm%add('h5_writer', h5_writer_name(comm), 'how run.h5 was written: every rank its '// &
                  'rows through MPI-IO (mpio-collective), or rank 0 alone (rank0-gather)')
      call sm%add('total_wall_time', total, 's')
      call sm%write(r%rd%path('summary.txt'), err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
      do ic = 1, r%study%ncases
        associate (o => outs(ic))
          call write_csv_curve(r%rd%path(o%tag//'_curve.csv'), o%curve, err)
          if (allocated(err)) call stop_alone(comm, r%rd, err)
          call write_csv_iterations(r%rd%path(o%tag//'_iterations.csv'), o%its, o%nplast, &
                                    o%scal(1), o%bounds, o%scal(3), err)
          if (allocated(err)) call stop_alone(comm, r%rd, err)
          call r%snaps%store%write_xdmf(r%rd%path(o%tag//'.xdmf'), 'run.h5', o%tag, &
                                        o%nparticles, 2, 'xy', err, prefix='cases/'//o%tag//'/')
          if (allocated(err)) call stop_alone(comm, r%rd, err)
        end associate
      end do
      if (r%study%plot .and. .not. cli%no_plot) then
        args = shell_quote(r%rd%partial)
        do ic = 1, r%study%ncases
          args = args//' '//shell_quote(outs(ic)%tag)
        end do
        call run_plot(find_data(plate_plot_name), args, err)
        if (allocated(err)) call stop_alone(comm, r%rd, err)
      end if
    end associate
    call r%rd%commit(err)
    if (allocated(err)) call stop_alone(comm, r%rd, err)
    call r%cks%finish(cli%keep_checkpoints)
    write (output_unit, '(a)') '  finished: '//r%rd%final//' (total '//real_text(total)//' s)'
  end subroutine finish_plate

  !> A band width of case b over case a's (scal slot k), if both have one.
  subroutine width_ratio(sm, a, b, key, k)
    type(summary_t), intent(inout) :: sm
    type(case_out_t), intent(in) :: a, b
    character(len=*), intent(in) :: key
    integer, intent(in) :: k
    character(len=:), allocatable :: name
    name = b%tag//'.'//key//'_ratio_to_'//a%tag
    if (b%scal(k) > 0.0_dp .and. a%scal(k) > 0.0_dp) then
      call sm%add(name, b%scal(k)/a%scal(k))
    else if (a%scal(k) <= 0.0_dp) then
      call sm%not_applicable(name, 'case '//a%tag//' has no band width (its '//key//')')
    else
      call sm%not_applicable(name, 'case '//b%tag//' has no band width (its '//key//')')
    end if
  end subroutine width_ratio

end module wellposed_mpm_plate_run
