!> wellposed-mpm: the explicit material point method of seed section 4.3 on
!> the 1D uniaxial-strain scenes of chapter 2 (Sandler-Rubin case study).
!>
!>   wellposed-mpm [--out ROOT] [--name NAME] [--no-plot] [DECK] [group.key=value ...]
!>
!> Without DECK: the default scene inputs/sandler_rubin_default.nml. Writes
!> ROOT/NAME/ (ROOT = out, NAME = the deck's &scene name): the deck, run.h5
!> (station histories, particle snapshots, energies, metadata), summary.txt
!> and stations.png. Everything is written into ROOT/NAME.partial and renamed
!> at the end, so a failed run leaves nothing that looks finished. Errors go
!> to standard error and the exit status is 1.
program wellposed_mpm
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_config
  use wellposed_mpm_deck, only: read_mpm_deck, mpm_options_t
  use wellposed_mpm_solver, only: mpm_scene_t, new_scene, advance, kinetic_energy, &
                                  total_momentum, timer_umat, timer_transfer, timer_grid
  use wellposed_mpm_stations, only: stations_t, new_stations, sample_stations, &
                                    station_measures_t, measure_stations, field_sxx, &
                                    field_syy, field_v, field_z
  use wellposed_mpm_paths, only: source_dir, install_data_dir, default_deck_name, &
                                 stations_plot_name
  use wellposed_mpm_particles, only: particle_bytes
  use wellposed_mpm_nonlocal, only: nl_scheme_names
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5, only: h5_file_t
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: path_exists, shell_quote
  implicit none

  type(mpm_config_t) :: cfg
  integer, allocatable :: nl_its(:), nl_plastic(:)  ! Algorithm 1: sweeps, step
  real(dp), allocatable :: nl_bound(:)
  integer :: nl_n = 0
  type(mpm_options_t) :: opts
  type(mpm_scene_t) :: scene
  type(stations_t) :: st
  type(station_measures_t) :: meas
  type(run_dir_t) :: rd
  type(h5_file_t) :: h5
  type(summary_t) :: sm
  type(error_t), allocatable :: err, err2
  character(len=:), allocatable :: deck_path, out_root, run_name, deck_text, arg, script
  character(len=512), allocatable :: overrides(:)
  logical :: no_plot
  integer :: i, nargs, nsnap, nenergy, s, nsteps_est
  integer(int64) :: c0, c1, crate, clast
  real(dp) :: wall, next_snap, c_e, c_p, escale, ebal, t_target
  real(dp), allocatable :: energy(:, :)
  character(len=16) :: tag

  ! ---- arguments
  out_root = 'out'
  run_name = ''
  no_plot = .false.
  deck_path = ''
  allocate (overrides(0))
  nargs = command_argument_count()
  i = 0
  do while (i < nargs)
    i = i + 1
    arg = get_arg(i)
    select case (arg)
    case ('-h', '--help')
      call usage(); stop
    case ('--out')
      i = i + 1; out_root = get_arg(i)
    case ('--name')
      i = i + 1; run_name = get_arg(i)
    case ('--no-plot')
      no_plot = .true.
    case default
      if (index(arg, '=') > 0) then
        overrides = [character(len=512) :: overrides, arg]
      else if (len(deck_path) == 0) then
        deck_path = arg
      else
        call die_text('unexpected argument "'//arg//'" (one DECK only; see --help)')
      end if
    end select
  end do
  if (len(deck_path) == 0) deck_path = find_data(default_deck_name)

  ! ---- deck and scene
  call read_mpm_deck(deck_path, overrides, cfg, opts, deck_text, err)
  if (allocated(err)) call die(err)
  if (len(run_name) > 0) cfg%name = run_name
  call new_scene(scene, cfg, err)
  if (allocated(err)) then
    err%message = deck_path//': '//err%message
    call die(err)
  end if
  c_e = sqrt(scene%modulus_elastic/cfg%density)
  c_p = sqrt(scene%modulus_plastic/cfg%density)
  call rd%create(out_root, cfg%name, deck_path, err)
  if (allocated(err)) call die(err)
  call h5%create(rd%path('run.h5'), err)
  if (allocated(err)) call die(err)
  call new_stations(st, cfg, scene%parts, cfg%t_end)

  nsteps_est = ceiling(cfg%t_end/scene%dt)
  write (output_unit, '(a)') 'wellposed-mpm '//wellposed_version//': scene '//cfg%name// &
    ' ('//trim(cfg%title)//')'
  write (output_unit, '(a,i0,a,i0,a,es10.3,a,i0,a)') '  ', scene%parts%n, ' particles, ', &
    scene%grid%nnodes, ' nodes, dt = ', scene%dt, ' s, ~', nsteps_est, ' steps'
  write (output_unit, '(a,a,a,a,a,f9.2,a,f9.2,a)') '  shape ', trim(shape_names(cfg%shape)), &
    ', scheme ', trim(scheme_names(cfg%scheme)), ', C_E = ', c_e, ' m/s, C_P = ', c_p, &
    ' m/s (UMAT moduli at the initial state)'
  write (output_unit, '(a)') '  writing '//rd%partial//' (renamed to '//rd%final//' when done)'
  flush (output_unit)

  ! ---- time loop
  allocate (energy(5, size(st%time)))
  nenergy = 1
  energy(:, 1) = [0.0_dp, scene%kinetic0, 0.0_dp, 0.0_dp, scene%momentum0]
  nsnap = 0
  next_snap = 0.0_dp
  if (cfg%snapshot_dt > 0.0_dp) call snapshot()
  call system_clock(c0, crate)
  clast = c0
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
      nl_bound(nl_n) = scene%nl%last%bound_seed
    end if
    if (allocated(err)) then
      ! close what was written (under its temporary name) and report the step's error
      call h5%close(err2)
      call die_text(deck_path//': '//err%message)
    end if
    s = st%ns
    call sample_stations(st, scene%parts, scene%t)
    if (st%ns > s .and. nenergy < size(energy, 2)) then
      nenergy = nenergy + 1
      energy(:, nenergy) = [scene%t, kinetic_energy(scene), scene%work_internal, &
                            scene%work_external, total_momentum(scene) - scene%impulse]
    end if
    if (cfg%snapshot_dt > 0.0_dp .and. scene%t >= next_snap - 0.5_dp*scene%dt) call snapshot()
    if (cfg%progress) then
      call system_clock(c1)
      if (real(c1 - clast, dp)/crate > 2.0_dp) then
        clast = c1
        wall = real(c1 - c0, dp)/crate
        write (output_unit, '(a,f9.2,a,f5.1,a,i0,a,f7.1,a,f7.1,a)') '  t = ', &
          scene%t*1e3_dp, ' ms (', 100*scene%t/cfg%t_end, ' %), step ', scene%nstep, ', ', &
          wall, ' s elapsed, ~', wall*(cfg%t_end - scene%t)/scene%t, ' s left'
        flush (output_unit)
      end if
    end if
  end do
  call system_clock(c1)
  wall = real(c1 - c0, dp)/crate

  ! ---- measures and outputs
  call measure_stations(st%time(1:st%ns), st%hist(field_sxx, :, 1:st%ns), st%x, &
                        0.5_dp*abs(cfg%load_peak), meas)
  escale = maxval(energy(2, 1:nenergy)) - scene%kinetic0
  ebal = kinetic_energy(scene) - scene%kinetic0 + scene%work_internal - scene%work_external
  call write_summary()
  call sm%write(rd%path('summary.txt'), err)
  if (allocated(err)) call die(err)
  call write_h5()
  call h5%close(err)
  if (allocated(err)) call die(err)
  if (opts%plot .and. .not. no_plot) then
    script = find_data(stations_plot_name)
    call run_plot(script, shell_quote(rd%path('run.h5'))//' '// &
                  shell_quote(rd%path('stations.png')), err)
    if (allocated(err)) call die(err)
  end if
  call rd%commit(err)
  if (allocated(err)) call die(err)
  write (output_unit, '(a,f8.2,a,i0,a,f7.1,a)') '  done in ', wall, ' s (', scene%nstep, &
    ' steps, ', 1.0e9_dp*wall/(real(scene%nstep, dp)*scene%parts%n), ' ns per particle-step)'
  do i = 1, st%n
    write (output_unit, '(a,f7.1,a,f8.3,a,f8.2,a,f8.2,a)') '  station ', st%x(i), &
      ' m: peak ', meas%peak(i)/1e6_dp, ' MPa, head ', meas%t_head(i)*1e3_dp, ' ms, tail ', &
      meas%t_tail(i)*1e3_dp, ' ms'
  end do
  write (output_unit, '(a)') '  results in '//rd%final//'/ (summary.txt, run.h5'// &
    merge(', stations.png', '              ', opts%plot .and. .not. no_plot)//')'

contains

  function get_arg(k) result(a)
    integer, intent(in) :: k
    character(len=:), allocatable :: a
    integer :: n
    if (k > nargs) call die_text('option "'//get_arg_raw(k - 1)//'" needs a value')
    call get_command_argument(k, length=n)
    allocate (character(len=n) :: a)
    call get_command_argument(k, a)
  end function get_arg

  function get_arg_raw(k) result(a)
    integer, intent(in) :: k
    character(len=:), allocatable :: a
    integer :: n
    call get_command_argument(k, length=n)
    allocate (character(len=n) :: a)
    call get_command_argument(k, a)
  end function get_arg_raw

  !> A data file of the source or install tree, else relative to the cwd.
  function find_data(rel) result(path)
    character(len=*), intent(in) :: rel
    character(len=:), allocatable :: path
    path = source_dir//'/'//rel
    if (path_exists(path)) return
    path = install_data_dir//'/'//rel
    if (path_exists(path)) return
    path = rel
  end function find_data

  subroutine snapshot()
    character(len=:), allocatable :: grp
    integer :: n
    nsnap = nsnap + 1
    write (tag, '(i4.4)') nsnap
    grp = 'snapshots/'//trim(tag)//'/'
    n = scene%parts%n
    call h5%write(grp//'time', [scene%t])
    call h5%write(grp//'x', scene%parts%x(1, 1:n))
    call h5%write(grp//'x0', scene%parts%x0(1, 1:n))
    call h5%write(grp//'velocity', scene%parts%v(1, 1:n))
    call h5%write(grp//'sigma_xx', scene%parts%stress(1, 1:n))
    call h5%write(grp//'sigma_yy', scene%parts%stress(2, 1:n))
    call h5%write(grp//'z', scene%parts%statev(1, 1:n))
    next_snap = nsnap*cfg%snapshot_dt
  end subroutine snapshot

  subroutine write_summary()
    character(len=8) :: k
    call sm%add('scene', cfg%name)
    call sm%add('version', wellposed_version)
    call sm%add('git_revision', wellposed_git_revision)
    call sm%add('shape', trim(shape_names(cfg%shape)))
    call sm%add('scheme', trim(scheme_names(cfg%scheme)))
    call sm%add('dx', cfg%dx, 'm')
    call sm%add('ppc', cfg%ppc)
    call sm%add('cfl', cfg%cfl)
    call sm%add('dt', scene%dt, 's')
    call sm%add('steps', scene%nstep)
    call sm%add('particles', scene%parts%n)
    call sm%add('t_end', scene%t, 's')
    call sm%add('wall_time', wall, 's, time loop only')
    call sm%add('ns_per_particle_step', 1.0e9_dp*wall/(real(scene%nstep, dp)*scene%parts%n))
    call sm%add('bytes_per_particle', particle_bytes(1, scene%parts%nsup, cfg%nstatv))
    call sm%add('share_umat', share(timer_umat))
    call sm%add('share_transfers', share(timer_transfer))
    call sm%add('share_grid', share(timer_grid))
    call sm%add('max_umat_substeps', scene%max_substeps, '1: no cut-back was needed')
    call sm%add('nonlocal', scene%nl%active, 'Algorithm 1 iterates (h_zeta /= 0)')
    if (scene%nl%active) then
      call sm%add('nonlocal_scheme', trim(nl_scheme_names(cfg%nonlocal%scheme)))
      call sm%add('nonlocal_steps_iterated', scene%nl%steps_iterated)
      call sm%add('nonlocal_iterations_mean', real(scene%nl%iterations_total, dp)/ &
                  max(scene%nl%steps_iterated, 1), 'sweeps per step with plastic particles')
      call sm%add('nonlocal_iterations_max', scene%nl%iterations_max)
      call sm%add('lipschitz_eq4_43_sharp', scene%nl%bound_43, '|h_zeta/(a + h_eta)|')
      call sm%add('lipschitz_eq4_45_sharp', scene%nl%bound_45, '|(h_eta + h_zeta)/a|')
    end if
    call sm%add('c_elastic', c_e, 'm/s, from the UMAT unloading modulus at the initial state')
    call sm%add('c_plastic', c_p, 'm/s, from the UMAT loading (extension) modulus')
    call sm%add('c_head', meas%c_head, 'm/s, least-squares fit of x against t_head')
    call sm%add('c_tail', meas%c_tail, 'm/s, least-squares fit of x against t_tail')
    call sm%add('c_head_over_c_plastic', meas%c_head/c_p)
    call sm%add('c_tail_over_c_elastic', meas%c_tail/c_e)
    call sm%add('separation_rate', meas%c_head - meas%c_tail, &
                'm/s, head minus tail speed (ideal Sandler-Rubin: C_P - C_E)')
    call sm%add('c_plastic_minus_c_elastic', c_p - c_e, 'm/s')
    call sm%add('arrival_threshold', meas%threshold, 'Pa, half the load peak')
    call sm%add('arrival_definition', 'head = last upward crossing of arrival_threshold '// &
                'before the station peak, tail = first downward crossing after it '// &
                '(ringing behind the pulse ignored); ideal: x/C_P + tau/4 and x/C_E + 3 tau/4')
    do i = 1, st%n
      write (k, '(i0)') i
      call sm%add('station_'//trim(k)//'_x', st%x(i), 'm')
      call sm%add('station_'//trim(k)//'_peak', meas%peak(i), 'Pa, max of sigma_xx - sigma_xx(0)')
      call sm%add('station_'//trim(k)//'_t_peak', meas%t_peak(i), 's')
      call sm%add('station_'//trim(k)//'_t_head', meas%t_head(i), 's')
      call sm%add('station_'//trim(k)//'_t_tail', meas%t_tail(i), 's')
      call sm%add('station_'//trim(k)//'_width', meas%width(i), 's, t_tail - t_head')
      call sm%add('station_'//trim(k)//'_width_ideal', &
                  st%x(i)*(1.0_dp/c_e - 1.0_dp/c_p) + 0.5_dp*cfg%load_duration, &
                  's, x (1/C_E - 1/C_P) + tau/2 (admissible solution, reference A)')
    end do
    if (st%n >= 2) call sm%add('peak_growth', meas%peak(st%n)/meas%peak(1), &
                               'last station peak over first')
    call sm%add('energy_scale', escale, 'J/m^2, largest kinetic energy gained')
    call sm%add('energy_balance_error', ebal/max(escale, tiny(1.0_dp)), &
                '(E_kin - E_kin0 + W_int - W_ext)/energy_scale at the end')
    call sm%add('momentum_error', &
                (total_momentum(scene) - scene%momentum0 - scene%impulse)/ &
                max(abs(scene%impulse), maxval(abs(energy(5, 1:nenergy))), tiny(1.0_dp)), &
                '(P - P0 - impulse)/max|impulse|')
  end subroutine write_summary

  real(dp) function share(id)
    integer, intent(in) :: id
    share = real(scene%ticks(id), dp)/max(1.0_dp, real(sum(scene%ticks), dp))
  end function share

  subroutine write_h5()
    integer :: k
    call h5%write_attr('scene', cfg%name)
    call h5%write_attr('title', trim(cfg%title))
    call h5%write_attr('deck', deck_text)
    call h5%write_attr('deck_path', deck_path)
    call h5%write_attr('version', wellposed_version)
    call h5%write_attr('git_revision', wellposed_git_revision)
    call h5%write_attr('props', cfg%props(1:cfg%nprops))
    call h5%write_attr('shape', trim(shape_names(cfg%shape)))
    call h5%write_attr('scheme', trim(scheme_names(cfg%scheme)))
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
      ! the seed's bound of eq. 4.43 (N_alpha |h_zeta/(a + h_eta)|)
      call h5%write('nonlocal/step', nl_plastic(1:nl_n))
      call h5%write('nonlocal/iterations', nl_its(1:nl_n))
      call h5%write('nonlocal/lipschitz_eq4_43_seed', nl_bound(1:nl_n))
    end if
  end subroutine write_h5

  subroutine usage()
    write (output_unit, '(a)') 'usage: wellposed-mpm [--out ROOT] [--name NAME] [--no-plot] '// &
      '[DECK] [group.key=value ...]'
    write (output_unit, '(a)') '  DECK defaults to '//default_deck_name// &
      '; results go to ROOT/NAME (ROOT = out, NAME = &scene name)'
    write (output_unit, '(a)') '  overrides, e.g. grid.dx=0.5 time.cfl=0.1 material.h=-5e8'
  end subroutine usage

  subroutine die(e)
    type(error_t), intent(in) :: e
    call die_text(e%message)
  end subroutine die

  subroutine die_text(text)
    character(len=*), intent(in) :: text
    write (error_unit, '(a)') 'wellposed-mpm: error: '//text
    if (allocated(rd%partial)) write (error_unit, '(a)') 'wellposed-mpm: the run did not '// &
      'finish; its partial output is in '//rd%partial
    error stop 1
  end subroutine die_text

end program wellposed_mpm
