!> The bar scene of wellposed-mpm: the explicit MPM of section 4.3 on the
!> 1D uniaxial-strain scenes of chapter 2 (Sandler-Rubin case study), for a
!> deck whose &scene kind is 'bar'. Writes ROOT/NAME/ (the deck, run.h5,
!> run.xdmf, summary.txt, stations.png) through ROOT/NAME.partial, renamed
!> at the end; errors to standard error, exit status 1. The steps are the
!> one run loop's (wellposed_mpm_run_loop) over the bar's outputs
!> (wellposed_mpm_bar_outputs); checkpoints and --restart on any number of
!> ranks. Outputs: docs/guide/mpm.md; ranks: docs/guide/parallel.md.
module wellposed_mpm_bar_run
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_bar_config
  use wellposed_mpm_bar_deck, only: read_bar_deck, bar_options_t
  use wellposed_mpm_bar_checks, only: check_bar_deck
  use wellposed_mpm_bar_station_summary, only: head_speed
  use wellposed_mpm_nonlocal_summary, only: add_nonlocal_summary
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, timer_umat, timer_transfer, timer_grid
  use wellposed_mpm_bar_kind, only: bar_modulus_plastic
  use wellposed_mpm_paths, only: find_data, stations_plot_name
  use wellposed_mpm_bar_reference, only: reference_plot_args
  use wellposed_mpm_memory, only: resident_bytes_per_particle
  use wellposed_mpm_nonlocal, only: nl_scheme_names
  use wellposed_mpi, only: comm_t, allreduce_sum, allreduce_max
  use wellposed_mpm_ranks, only: mpm_ranks_t, new_mpm_ranks
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t, h5_writer_name
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: shell_quote
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_stop, only: stop_alone, stop_all
  use wellposed_mpm_run_files, only: open_run_files
  use wellposed_mpm_output, only: output_list_t, stage_start, stage_finish
  use wellposed_mpm_snapshots, only: new_snapshot_store
  use wellposed_mpm_checkpoints, only: run_checkpoints_t, new_run_checkpoints
  use wellposed_mpm_run_loop, only: checkpoint_every, run_steps, loop_end_t
  use wellposed_mpm_bar_outputs, only: bar_stations_t, bar_energy_t, bar_nonlocal_t, &
                                       bar_snapshots_t, bar_progress_t
  use wellposed_mpm_bar_dissipation, only: bar_dissipation_t
  use wellposed_mpm_method, only: implicit_scheme, scheme_newmark
  use wellposed_mpm_implicit_stepper, only: implicit_stepper_t
  use wellposed_mpm_implicit_run, only: start_implicit, implicit_summary, write_newton_csv
  implicit none
  private
  public :: run_bar

  !> A bar run: its deck, scene, files and outputs (the outputs point at
  !> one another and at h5, so a bar_run_t is a target and never copied).
  type :: bar_run_t
    type(bar_config_t) :: cfg
    type(bar_options_t) :: opts
    type(mpm_scene_t) :: scene
    type(mpm_ranks_t) :: ranks
    type(run_dir_t) :: rd
    type(h5_parallel_file_t) :: h5
    type(summary_t) :: sm
    type(bar_stations_t) :: stations
    type(bar_energy_t) :: energy
    type(bar_dissipation_t) :: dissipation
    type(bar_snapshots_t) :: snaps
    type(bar_nonlocal_t) :: nonlocal
    type(bar_progress_t) :: progress
    type(output_list_t) :: outs
    type(run_checkpoints_t) :: cks
    character(len=:), allocatable :: deck_text
    integer :: ntotal = 0, ghost = 0, nsteps_est = 0
    !> the implicit scheme's steps (&time scheme = 'implicit')
    logical :: implicit = .false.
    type(implicit_stepper_t) :: stepper
  end type bar_run_t

contains

  !> Run the bar deck cli%deck_path as the command line `cli` asks, on the
  !> ranks of `comm` (collective). Stops the program on an error.
  subroutine run_bar(cli, comm)
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(bar_run_t), target :: r
    type(loop_end_t) :: ended
    type(error_t), allocatable :: err, err2
    call open_bar(r, cli, comm)
    call begin_bar(r, cli, comm)
    if (r%implicit) then
      call run_steps(r%scene, r%cfg%t_end, r%outs, r%cks, comm, .false., ended, err, r%stepper)
    else
      call run_steps(r%scene, r%cfg%t_end, r%outs, r%cks, comm, .false., ended, err)
    end if
    if (allocated(err)) then
      ! (every rank has the error: the step's errors are collective) close
      ! what was written (under its temporary name) and report the error
      call r%h5%close(err2)
      call stop_all(comm, r%rd, cli%deck_path//': '//err%message)
    end if
    call finish_bar(r, cli, comm)
  end subroutine run_bar

  !> The deck, the scene on every rank (its strip), the run folder and
  !> run.h5, the outputs and the opening lines (collective).
  subroutine open_bar(r, cli, comm)
    type(bar_run_t), target, intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    logical :: root
    root = comm%rank == 0
    call read_bar_deck(cli%deck_path, cli%overrides, cli%kinds, r%cfg, r%opts, r%deck_text, err)
    if (.not. allocated(err)) call check_bar_deck(cli%deck_path, r%cfg, err, cli%force)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    if (len(cli%run_name) > 0) r%cfg%name = cli%run_name
    ! every rank builds the scene and keeps its strip (errors: the same on all)
    call new_mpm_ranks(r%ranks, comm)
    call new_scene(r%scene, r%cfg, err, r%ranks)
    r%implicit = implicit_scheme(r%cfg%scheme)
    if (.not. allocated(err) .and. r%implicit) &
      call start_implicit(r%scene, r%cfg%implicit_dt, r%cfg%linear_solver, &
                         r%cfg%scheme == scheme_newmark, cli%restart, r%stepper, err)
    if (allocated(err)) call stop_all(comm, r%rd, cli%deck_path//': '//err%message)
    r%ghost = r%scene%exchange%ghost_layers()
    ! rank 0 makes the run folder; run.h5 in it is written by every rank
    call open_run_files(r%rd, r%h5, comm, cli%out_root, r%cfg%name, cli%deck_path)
    r%ntotal = r%scene%parts%n
    call allreduce_sum(comm, r%ntotal)
    call add_outputs(r, comm)
    r%nsteps_est = ceiling(r%cfg%t_end/r%scene%dt)
    r%cks = new_run_checkpoints(cli%out_root, r%cfg%name, &
                                checkpoint_every(cli%ck_every, r%nsteps_est), cli%ck_file, &
                                r%deck_text, r%rd)
    ! the snapshots' rows go into files of the checkpoint folder, for the checkpoints
    call r%snaps%store%keep_files(r%cks%dir, r%cks%every > 0)
    if (root) call say_opening(r, comm)
  end subroutine open_bar

  !> The bar's outputs, in the order the loop asks them (that of their
  !> run.h5 datasets): stations, energies, snapshots, Algorithm 1's record.
  subroutine add_outputs(r, comm)
    type(bar_run_t), target, intent(inout) :: r
    type(comm_t), intent(inout) :: comm
    call r%stations%setup(r%cfg, r%scene, r%ntotal, comm)
    r%stations%c_e = sqrt(r%scene%modulus_elastic/r%cfg%density)
    r%stations%c_p = sqrt(bar_modulus_plastic(r%scene)/r%cfg%density)
    r%stations%head = head_speed(r%cfg, r%scene%nl%active, r%stations%c_p)
    call r%energy%setup(r%stations, r%scene)
    call r%dissipation%setup(r%energy, r%scene)
    r%snaps%name = 'snapshots'
    r%snaps%h5 => r%h5
    r%snaps%interval = r%cfg%snapshot_dt
    call new_snapshot_store(r%snaps%store, [character(len=8) :: 'x', 'x0', 'velocity', &
                            'sigma_xx', 'sigma_yy', 'z'], [1, 1, 1, 1, 1, 1], time_first=.true.)
    r%nonlocal%name = 'nonlocal_records'
    r%progress%name = 'progress'
    r%progress%on = r%cfg%progress .and. comm%rank == 0
    r%progress%t_end = r%cfg%t_end
    call r%outs%add(r%stations)
    call r%outs%add(r%energy)
    call r%outs%add(r%dissipation)
    call r%outs%add(r%snaps)
    call r%outs%add(r%nonlocal)
    call r%outs%add(r%progress)
  end subroutine add_outputs

  !> The opening lines (rank 0).
  subroutine say_opening(r, comm)
    type(bar_run_t), intent(in) :: r
    type(comm_t), intent(in) :: comm
    associate (cfg => r%cfg, scene => r%scene)
      write (output_unit, '(a)') 'wellposed-mpm '//wellposed_version//': scene '//cfg%name// &
        ' ('//trim(cfg%title)//')'
      write (output_unit, '(a,i0,a,i0,a,es10.3,a,i0,a)') '  ', r%ntotal, ' particles, ', &
        scene%grid%nnodes, ' nodes, dt = ', scene%dt, ' s, ~', r%nsteps_est, ' steps'
      write (output_unit, '(a,a,a,a,a,f9.2,a,f9.2,a)') '  shape ', &
        trim(shape_names(cfg%shape)), ', scheme ', trim(scheme_names(cfg%scheme)), ', C_E = ', &
        r%stations%c_e, ' m/s, C_P = ', r%stations%c_p, ' m/s (UMAT moduli at the initial state)'
      if (allocated(r%opts%mass_note)) write (output_unit, '(a)') '  '//r%opts%mass_note
      if (scene%nl%active) write (output_unit, '(a)') '  nonlocal: L = '// &
        real_text(scene%nl%length)//' m, Gaussian support radius '// &
        real_text(scene%nl%radius)//' m = '//real_text(scene%nl%radius/cfg%dx)//' cells'
      if (comm%size > 1) write (output_unit, '(a)') '  on '//int_text(comm%size)// &
        ' ranks, strips of cells with '//int_text(r%ghost)//' ghost node layers; run.h5: '// &
        h5_writer_name(comm)
      write (output_unit, '(a)') '  writing '//r%rd%partial//' (renamed to '//r%rd%final// &
        ' when done)'
      flush (output_unit)
    end associate
  end subroutine say_opening

  !> A fresh run's first snapshot, or on --restart the scene and outputs of
  !> the checkpoint and the snapshots before it written again (collective).
  subroutine begin_bar(r, cli, comm)
    type(bar_run_t), intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    if (.not. cli%restart) then
      call r%outs%ask(stage_start, r%scene, comm, err)
      if (allocated(err)) call stop_all(comm, r%rd, err)
      call r%progress%clock%start(2.0_dp)
      return
    end if
    call r%cks%open(cli%deck_path, err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    call r%cks%resume(r%scene, r%outs, comm, err)
    if (allocated(err)) call stop_alone(comm, r%rd, err)
    if (r%snaps%store%n /= r%snaps%taken) &
      call stop_all(comm, r%rd, r%cks%file//': the snapshot count is garbled')
    call r%snaps%store%write_stored(r%h5, comm, err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    call r%progress%clock%start(2.0_dp)
    if (comm%rank /= 0) return
    write (output_unit, '(a)') '  restarted from '//r%cks%file//' (step '// &
      int_text(r%scene%nstep)//', t = '//real_text(r%scene%t)//' s; '// &
      int_text(r%snaps%taken)//' snapshots written again)'
    flush (output_unit)
  end subroutine begin_bar

  !> After the last step: the outputs' measures, summary.txt, run.h5's
  !> datasets, run.xdmf, the plot; the folder renamed (collective).
  subroutine finish_bar(r, cli, comm)
    type(bar_run_t), intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable :: err
    real(dp) :: wall
    integer :: substeps, i
    logical :: plotted
    wall = r%progress%wall()
    call r%outs%ask(stage_finish, r%scene, comm, err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    substeps = r%scene%max_substeps
    call allreduce_max(comm, substeps)
    if (comm%rank == 0) then
      call summary_head(r, comm, wall, substeps)
      call r%outs%summarise(r%sm)
      call r%sm%write(r%rd%path('summary.txt'), err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end if
    call write_attrs(r, cli)
    call r%outs%write_h5(r%h5)
    call r%h5%close(err)
    if (allocated(err)) call stop_all(comm, r%rd, err)
    call r%snaps%store%close()
    if (comm%rank /= 0) return
    if (r%implicit) then
      call write_newton_csv(r%rd%path('newton.csv'), r%stepper, err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end if
    ! the particle snapshots for ParaView: points on the x axis over time
    if (r%snaps%taken > 0) then
      call r%snaps%store%write_xdmf(r%rd%path('run.xdmf'), 'run.h5', 'particles', r%ntotal, &
                                    1, 'x', err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end if
    plotted = r%opts%plot .and. .not. cli%no_plot
    if (plotted) then
      call run_plot(find_data(stations_plot_name), shell_quote(r%rd%path('run.h5'))//' '// &
                    shell_quote(r%rd%path('stations.png'))//reference_plot_args(cli%out_root, &
                    cli%deck_path, r%opts%reference, r%opts%reference_label), err)
      if (allocated(err)) call stop_alone(comm, r%rd, err)
    end if
    call r%rd%commit(err)
    if (allocated(err)) call stop_alone(comm, r%rd, err)
    call r%cks%finish(cli%keep_checkpoints)
    write (output_unit, '(a,f8.2,a,i0,a,g0.4,a)') '  done in ', wall, ' s (', r%scene%nstep, &
      ' steps, ', 1.0e9_dp*wall/max(1.0_dp, real(r%scene%nstep, dp)*r%ntotal), &
      ' ns per particle-step)'
    associate (st => r%stations%st, meas => r%stations%meas)
      do i = 1, st%n
        write (output_unit, '(a,f7.1,a,f8.3,a,f8.2,a,f8.2,a)') '  station ', st%x(i), &
          ' m: peak ', meas%peak(i)/1e6_dp, ' MPa, head ', meas%t_head(i)*1e3_dp, &
          ' ms, tail ', meas%t_tail(i)*1e3_dp, ' ms'
      end do
    end associate
    write (output_unit, '(a)') '  results in '//r%rd%final//'/ (summary.txt, run.h5'// &
      trim(merge(', run.xdmf', '          ', r%snaps%taken > 0))// &
      trim(merge(', stations.png', '              ', plotted))//')'
  end subroutine finish_bar

  !> The summary lines of the run itself, before its outputs' (rank 0).
  subroutine summary_head(r, comm, wall, substeps)
    type(bar_run_t), intent(inout) :: r
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: wall
    integer, intent(in) :: substeps
    associate (sm => r%sm, cfg => r%cfg, scene => r%scene)
      call sm%add('scene', cfg%name)
      call sm%add('version', wellposed_version)
      call sm%add('git_revision', wellposed_git_revision)
      call sm%add('shape', trim(shape_names(cfg%shape)))
      call sm%add('scheme', trim(scheme_names(cfg%scheme)))
      if (r%implicit) call implicit_summary(sm, '', r%stepper)
      if (allocated(r%opts%mass_note)) then
        call sm%add('mass', trim(mass_names(cfg%mass)), r%opts%mass_note)
      else
        call sm%add('mass', trim(mass_names(cfg%mass)), 'the grid acceleration''s mass matrix')
      end if
      call sm%add('dx', cfg%dx, 'm')
      call sm%add('ppc', cfg%ppc)
      call sm%add('cfl', cfg%cfl)
      call sm%add('dt', scene%dt, 's')
      call sm%add('steps', scene%nstep)
      call sm%add('particles', r%ntotal)
      call sm%add('ranks', comm%size, 'MPI ranks (strips of cells)')
      call sm%add('h5_writer', h5_writer_name(comm), 'how run.h5 was written: every rank '// &
                  'its rows through MPI-IO (mpio-collective), or rank 0 alone (rank0-gather)')
      call sm%add('ghost_layers', r%ghost, 'node layers beyond a patch: shape support '// &
                  'or the nonlocal Gaussian''s, the wider')
      call sm%add('t_end', scene%t, 's')
      call sm%add('wall_time', wall, 's, time loop only')
      ! a scene of zero steps (t_end = 0: a probe of the initial state) has no rate
      call sm%add('ns_per_particle_step', 1.0e9_dp*wall/max(1.0_dp, real(scene%nstep, dp)*r%ntotal))
      call sm%add('bytes_per_particle', resident_bytes_per_particle(real(r%ntotal, dp)/comm%size), &
                  'peak resident growth over the run, every buffer counted')
      call sm%add('share_umat', share(scene, timer_umat))
      call sm%add('share_transfers', share(scene, timer_transfer))
      call sm%add('share_grid', share(scene, timer_grid))
      call sm%add('max_umat_substeps', substeps, '1: no cut-back was needed')
      call sm%add('nonlocal', scene%nl%active, 'Algorithm 1 iterates (h_zeta /= 0)')
      if (scene%nl%active) then
        call sm%add('nonlocal_scheme', trim(nl_scheme_names(cfg%nonlocal%scheme)))
        call sm%add('nonlocal_support_radius', scene%nl%radius, 'm, where the Gaussian '// &
                    'falls below weight_cutoff')
        call sm%add('nonlocal_sweep_order', 'Gauss-Seidel by owning cell, then particle '// &
                    'id, pipelined across ranks')
        call add_nonlocal_summary(sm, '', scene%nl)
      end if
      call sm%add('c_elastic', r%stations%c_e, 'm/s, from the UMAT unloading modulus at the '// &
                  'initial state')
      call sm%add('c_plastic', r%stations%c_p, 'm/s, from the UMAT loading (extension) modulus')
    end associate
  end subroutine summary_head

  !> The share of timer `id` in the scene's step time.
  real(dp) function share(scene, id)
    type(mpm_scene_t), intent(in) :: scene
    integer, intent(in) :: id
    share = real(scene%ticks(id), dp)/max(1.0_dp, real(sum(scene%ticks), dp))
  end function share

  !> run.h5's attributes, before the outputs' datasets (collective: the
  !> values are rank 0's).
  subroutine write_attrs(r, cli)
    type(bar_run_t), intent(inout) :: r
    type(mpm_cli_t), intent(in) :: cli
    associate (h5 => r%h5, cfg => r%cfg)
      call h5%write_attr('scene', cfg%name)
      call h5%write_attr('title', trim(cfg%title))
      call h5%write_attr('deck', r%deck_text)
      call h5%write_attr('cli%deck_path', cli%deck_path)
      call h5%write_attr('version', wellposed_version)
      call h5%write_attr('git_revision', wellposed_git_revision)
      call h5%write_attr('props', cfg%props(1:cfg%nprops))
      call h5%write_attr('shape', trim(shape_names(cfg%shape)))
      call h5%write_attr('scheme', trim(scheme_names(cfg%scheme)))
      call h5%write_attr('mass', trim(mass_names(cfg%mass)))
      call h5%write_attr('numbers', [cfg%dx, r%scene%dt, cfg%cfl, r%stations%c_e, &
                                     r%stations%c_p, cfg%load_peak, cfg%load_duration, &
                                     cfg%density, real(cfg%ppc, dp)])
      call h5%write_attr('numbers_names', 'dx dt cfl c_elastic c_plastic load_peak '// &
                         'load_duration density ppc')
    end associate
  end subroutine write_attrs

end module wellposed_mpm_bar_run
