!> The axisymmetric scene of wellposed-mpm: one cylinder per deck, the one
!> run loop (wellposed_mpm_run_loop) over this kind's outputs
!> (wellposed_mpm_axisymmetric_outputs). Writes ROOT/NAME/ (the deck,
!> run.h5 with the snapshots, run.xdmf, curve.csv, summary.txt, plots)
!> through ROOT/NAME.partial, renamed at the end (curve.csv: the
!> specimen's stresses against its axial strain); ranks write run.h5
!> collectively, rank 0 the rest. Checkpoints and --restart as the others'.
module wellposed_mpm_axisymmetric_run
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text, real_text
  use wellposed_mpi, only: comm_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_solver, only: max_substeps
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_mpm_shape_2d, only: shape2d_names
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_paths, only: find_data
  use wellposed_mpm_stop, only: stop_alone, stop_all
  use wellposed_mpm_run_files, only: open_run_files
  use wellposed_mpm_snapshots, only: new_snapshot_store
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_writer_name
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: shell_quote
  use wellposed_mpm_output, only: output_list_t, stage_start, stage_finish
  use wellposed_mpm_checkpoints, only: run_checkpoints_t, new_run_checkpoints
  use wellposed_mpm_run_loop, only: checkpoint_every, run_steps, loop_end_t
  use wellposed_mpm_axisymmetric_config, only: axi_config_t, closed_form_lame, &
                                               closed_form_hill, closed_form_names
  use wellposed_mpm_axisymmetric_kind, only: new_axi_scene
  use wellposed_mpm_axisymmetric_deck, only: read_axi_deck, check_axi_deck
  use wellposed_mpm_axisymmetric_outputs, only: axi_snapshots_t, axi_progress_t, axi_curve_t, &
                                                axi_stations_t, axi_field_names, axi_field_widths
  use wellposed_mpm_plate_deck, only: plate_study_t
  use wellposed_mpm_plate_stations, only: new_plate_stations
  use wellposed_mpm_axisymmetric_closed_forms, only: axi_closed_form_t
  use wellposed_checked_io, only: out_file_t
  use wellposed_mpm_method, only: implicit_scheme, scheme_newmark, scheme_names
  use wellposed_mpm_implicit_stepper, only: implicit_stepper_t
  use wellposed_mpm_implicit_run, only: start_implicit, implicit_summary, write_newton_csv
  implicit none
  private
  public :: run_axi

  character(len=*), parameter :: axi_plot_name = 'mpm/plots/mpm_axisymmetric.py'

  !> A run: its deck, files, scene and outputs (targets: the lists point into it).
  type :: axi_run_t
    type(axi_config_t) :: cfg
    character(len=:), allocatable :: deck_text
    type(mpm_ranks_t) :: ranks
    type(run_dir_t) :: rd
    type(h5_parallel_file_t) :: h5
    type(summary_t) :: sm
    type(run_checkpoints_t) :: cks
    type(mpm_scene_t) :: sc
    type(axi_snapshots_t) :: snaps
    type(axi_progress_t) :: progress_line
    type(axi_closed_form_t) :: closed
    type(axi_curve_t) :: curve
    type(axi_stations_t) :: stations
    type(output_list_t) :: outs, resumed
    type(loop_end_t) :: ended
    !> the implicit schemes' steps (&time scheme = 'implicit' or 'newmark')
    logical :: implicit = .false.
    type(implicit_stepper_t) :: stepper
  end type axi_run_t

contains

  !> Run the axisymmetric deck cli%deck_path as `cli` asks, on the ranks
  !> of `comm` (collective). Stops the program on an error.
  subroutine run_axi(cli, comm)
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(axi_run_t), target :: r
    type(error_t), allocatable :: err
    call open_axi(r, cli, comm)
    call r%progress_line%clock%start(10.0_dp)
    if (cli%restart) then
      call r%cks%open(cli%deck_path, err)
      if (.not. allocated(err)) call r%cks%resume(r%sc, r%resumed, comm, err)
      if (.not. allocated(err)) call r%snaps%get(r%cks%ck, comm, err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
      ! run.h5 gets the snapshots the interrupted run had written
      call r%snaps%store%write_stored(r%h5, comm, err)
      if (allocated(err)) call stop_all(comm, r%rd, err)
      if (comm%rank == 0) write (output_unit, '(a)') '  restarted from '//r%cks%file// &
        ': continuing at step '//int_text(r%sc%nstep)//', t = '//real_text(r%sc%t)//' s'
    else
      call r%outs%ask(stage_start, r%sc, comm, err)
      if (allocated(err)) call stop_all(comm, r%rd, err)
    end if
    if (r%implicit) then
      call run_steps(r%sc, r%cfg%section%t_end, r%outs, r%cks, comm, r%cfg%stop_on_cutback, &
                     r%ended, err, r%stepper)
    else
      call run_steps(r%sc, r%cfg%section%t_end, r%outs, r%cks, comm, r%cfg%stop_on_cutback, &
                     r%ended, err)
    end if
    if (allocated(err)) call stop_all(comm, r%rd, err)
    if (r%ended%early .and. comm%rank == 0) write (output_unit, '(a)') '  ended at t = '// &
      real_text(r%sc%t)//' s (&time stop_on_cutback): '//trim(r%ended%message)
    call r%outs%ask(stage_finish, r%sc, comm, err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    call finish_axi(r, cli, comm)
  end subroutine run_axi

  !> The deck (checked before anything is written), the scene, the run
  !> folder, run.h5, the outputs and the opening lines (collective).
  subroutine open_axi(r, cli, comm)
    type(axi_run_t), target, intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    integer :: nsteps_est
    call new_mpm_ranks(r%ranks, comm)
    call read_axi_deck(cli%deck_path, cli%overrides, cli%kinds, r%cfg, r%deck_text, err)
    if (.not. allocated(err)) call check_axi_deck(cli%deck_path, r%cfg, err, cli%force)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    if (len(cli%run_name) > 0) r%cfg%section%name = cli%run_name
    call new_axi_scene(r%sc, r%cfg, err, r%ranks)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    r%implicit = implicit_scheme(r%cfg%section%scheme)
    if (r%implicit) then
      call start_implicit(r%sc, r%cfg%section%implicit_dt, r%cfg%section%linear_solver, &
                          r%cfg%section%scheme == scheme_newmark, cli%restart, r%stepper, err)
      if (allocated(err)) call stop_all(comm, r%rd, cli%deck_path//': '//err%message)
    end if
    nsteps_est = ceiling(r%cfg%section%t_end/r%sc%dt)
    r%cks = new_run_checkpoints(cli%out_root, r%cfg%section%name, cli%ck_every, cli%ck_file, &
                                r%deck_text, r%rd)
    r%cks%every = checkpoint_every(cli%ck_every, nsteps_est)
    call open_run_files(r%rd, r%h5, comm, cli%out_root, r%cfg%section%name, cli%deck_path)
    call r%h5%write_attr('wellposed_version', wellposed_version)
    call r%h5%write_attr('git_revision', wellposed_git_revision)
    call r%h5%write_attr('deck', r%deck_text)
    call r%h5%write_attr('props', r%cfg%section%props(1:r%cfg%section%nprops))
    call new_snapshot_store(r%snaps%store, axi_field_names, axi_field_widths, time_first=.false.)
    r%snaps%name = 'snapshots'
    r%snaps%h5 => r%h5
    r%snaps%interval = r%cfg%snapshot_dt
    r%snaps%r_inner = r%cfg%r_inner
    call r%snaps%store%keep_files(r%cks%dir, r%cks%every > 0)
    r%progress_line%name = 'progress'
    r%progress_line%on = r%cfg%progress .and. comm%rank == 0
    r%progress_line%nsteps_est = nsteps_est
    r%closed%name = 'closed_form'
    r%closed%form = r%cfg%closed_form
    r%curve%name = 'curve'
    r%curve%sample_dt = r%cfg%sample_dt
    r%curve%r_inner = r%cfg%r_inner
    call station_points(r, comm)
    call r%outs%add(r%curve)
    call r%outs%add(r%stations)
    call r%outs%add(r%snaps)
    call r%outs%add(r%progress_line)
    call r%outs%add(r%closed)
    call r%resumed%add(r%curve)
    call r%resumed%add(r%stations)
    call r%resumed%add(r%progress_line)
    call r%resumed%add(r%closed)
    if (comm%rank /= 0) return
    associate (s => r%cfg%section, sc => r%sc)
      write (output_unit, '(a)') 'wellposed-mpm '//wellposed_version//': '//s%name//' ('// &
        trim(s%title)//')'
      if (comm%size > 1) write (output_unit, '(a)') '  on '//int_text(comm%size)// &
        ' ranks (strips of cell rows; run.h5: '//h5_writer_name(comm)//')'
      write (output_unit, '(a)') '  cylinder '//real_text(r%cfg%r_inner)//' <= r <= '// &
        real_text(r%cfg%r_inner + s%width)//' m, height '//real_text(s%height)//' m: '// &
        int_text(sc%ntotal)//' particles, '//int_text(sc%grid%nnodes)//' nodes, dt = '// &
        real_text(sc%dt)//' s, ~'//int_text(nsteps_est)//' steps'
      write (output_unit, '(a)') '  writing '//r%rd%partial//' (renamed to '//r%rd%final// &
        ' when done)'
      flush (output_unit)
      call r%sm%add('scene', s%name)
      call r%sm%add('kind', 'axisymmetric')
      call r%sm%add('shape', trim(shape2d_names(s%shape)))
      call r%sm%add('scheme', trim(scheme_names(s%scheme)), 'USL, MUSL, implicit or '// &
                    'newmark (&time scheme)')
      call r%sm%add('r_inner', r%cfg%r_inner, 'm')
      call r%sm%add('r_outer', r%cfg%r_inner + s%width, 'm')
      call r%sm%add('height', s%height, 'm')
      call r%sm%add('p_inner', r%cfg%p_inner, 'Pa')
      call r%sm%add('p_outer', r%cfg%p_outer, 'Pa')
      call r%sm%add('pressure_ramp', r%cfg%pressure_ramp, 's, half-cosine')
      call r%sm%add('confining', r%cfg%confining, 'Pa, the isotropic start')
      call r%sm%add('closed_form', trim(closed_form_names(r%cfg%closed_form)))
      call r%sm%add('dx', s%dx, 'm')
      call r%sm%add('particles', sc%ntotal)
      call r%sm%add('dt', sc%dt, 's')
    end associate
  end subroutine open_axi

  !> After the last step: run.h5 closed, summary.txt, run.xdmf, the plot;
  !> the folder renamed (rank 0 after the collective parts).
  subroutine finish_axi(r, cli, comm)
    type(axi_run_t), intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    real(dp) :: wall
    integer :: nsub
    nsub = max_substeps(r%sc)
    call r%outs%write_h5(r%h5)
    call r%h5%close(err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    call r%snaps%store%close()
    if (comm%rank /= 0) return
    wall = r%progress_line%wall()
    associate (sm => r%sm, sc => r%sc)
      call sm%add('steps', sc%nstep)
      call sm%add('final_time', sc%t, 's')
      call sm%add('wall_time', wall, 's')
      call sm%add('ns_per_particle_step', &
                  wall*1.0e9_dp/max(1.0_dp, real(sc%ntotal, dp)*sc%nstep))
      call sm%add('max_substeps', nsub)
      if (r%implicit) call implicit_summary(sm, '', r%stepper)
      call sm%add('max_plastic_strain', r%curve%peak_at(1))
      call sm%add('ended_early', r%ended%early, 'true: the UMAT could not go on '// &
                  '(&time stop_on_cutback); the run ends at final_time')
      if (r%ended%early) call sm%add('end_reason', trim(r%ended%message))
      call r%outs%summarise(sm)
      call sm%add('h5_writer', h5_writer_name(comm))
      call sm%write(r%rd%path('summary.txt'), err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
      call r%snaps%store%write_xdmf(r%rd%path('run.xdmf'), 'run.h5', 'cylinder', sc%ntotal, &
                                    2, 'rz', err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
      call write_curve(r%rd%path('curve.csv'), r%curve, err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
      if (r%implicit) call write_newton_csv(r%rd%path('newton.csv'), r%stepper, err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end associate
    if (r%cfg%plot .and. .not. cli%no_plot) then
      call run_plot(find_data(axi_plot_name), shell_quote(r%rd%partial), err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end if
    call r%rd%commit(err)
    if (allocated(err)) call stop_alone(comm, r%rd, err)
    call r%cks%finish(cli%keep_checkpoints)
    write (output_unit, '(a)') '  finished: '//r%rd%final//' in '//real_text(wall)//' s'
    if (r%closed%form == closed_form_lame) write (output_unit, '(a)') '  against Lame: '// &
      'stress error '//real_text(r%closed%err_stress)//', hoop '// &
      real_text(r%closed%err_hoop)//', outer displacement '//real_text(r%closed%err_u_outer)
    if (r%closed%form == closed_form_hill) write (output_unit, '(a)') '  against Hill: '// &
      'stress error '//real_text(r%closed%err_stress)//', hoop '// &
      real_text(r%closed%err_hoop)//', plastic radius '//real_text(r%closed%c_mpm)// &
      ' m (exact '//real_text(r%closed%c_exact)//' m)'
  end subroutine finish_axi

  !> The deck's stations on the fresh scene (collective): the plate's, on
  !> the section (x = r - r_inner), as one case of scale 1.
  subroutine station_points(r, comm)
    type(axi_run_t), intent(inout) :: r
    type(comm_t), intent(inout) :: comm
    type(plate_study_t) :: one
    integer :: n
    n = r%cfg%nstations
    r%stations%name = 'stations'
    r%stations%r_inner = r%cfg%r_inner
    one%nstations = n
    one%station_x(1:n) = r%cfg%station_r(1:n) - r%cfg%r_inner
    one%station_y(1:n) = r%cfg%station_z(1:n)
    one%sample_dt = r%cfg%sample_dt
    call new_plate_stations(r%stations%pst, one, 1, r%sc, r%cfg%section%t_end, comm)
  end subroutine station_points

  !> The curve's rows as CSV (rank 0).
  subroutine write_curve(path, curve, err)
    character(len=*), intent(in) :: path
    type(axi_curve_t), intent(in) :: curve
    type(error_t), allocatable, intent(out) :: err
    type(out_file_t) :: out
    character(len=100) :: row
    integer :: j
    call out%open(path, err)
    if (allocated(err)) return
    call out%put('time_s,axial_strain,axial_stress_Pa,lateral_stress_Pa,max_plastic_strain')
    do j = 1, curve%n
      write (row, '(es16.8,4(",",es16.8))') curve%rows(:, j)
      call out%put(trim(row))
    end do
    call out%close(err)
  end subroutine write_curve

end module wellposed_mpm_axisymmetric_run
