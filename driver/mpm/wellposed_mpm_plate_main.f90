!> wellposed-mpm2d: the plane-strain MPM on the plate of seed chapter 4
!> (fig. 4.1-4.6), one or more cases per deck (meshes, sizes: &study).
!>
!>   wellposed-mpm2d [--out ROOT] [--name NAME] [--no-plot] DECK [group.key=value ...]
!>
!> Writes ROOT/NAME/ (NAME = the deck's &scene name): the deck, run.h5
!> (per case: particle snapshots, the stress-strain curve, nonlocal
!> iterations per step; metadata), one <case>.xdmf per case beside it so
!> ParaView opens the particle fields, <case>_curve.csv,
!> <case>_iterations.csv, summary.txt and the plots (plastic strain
!> contours, stress-strain curves). Everything goes to ROOT/NAME.partial and
!> is renamed at the end, so a failed run leaves nothing that looks
!> finished. Errors go to standard error and the exit status is 1.
program wellposed_mpm2d
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_plane_strain, only: ps_config_t, ps_scene_t, new_ps_scene, ps_advance, &
                                        ps_applied_stress, ps_plastic_strain
  use wellposed_mpm_shape_2d, only: shape2d_names
  use wellposed_mpm_nonlocal, only: nl_scheme_names
  use wellposed_mpm_ps_deck, only: read_ps_deck, ps_study_t
  use wellposed_mpm_paths, only: source_dir, install_data_dir
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5, only: h5_file_t
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_fs, only: path_exists, shell_quote
  implicit none

  type(ps_config_t) :: cfg0, cfg
  type(ps_study_t) :: study
  type(ps_scene_t) :: sc, prev
  logical :: ended_early, measured
  real(dp) :: band_t
  character(len=512) :: end_message
  type(run_dir_t) :: rd
  type(h5_file_t) :: h5
  type(summary_t) :: sm
  type(error_t), allocatable :: err
  character(len=:), allocatable :: deck_path, out_root, run_name, deck_text, arg, tag, script
  character(len=512), allocatable :: overrides(:)
  character(len=32), allocatable :: tags(:)
  logical :: no_plot
  integer :: i, nargs, ic, nsteps_est, nsnap, ncurve, nit, u
  integer(int64) :: c0, c1, crate, clast
  real(dp) :: wall, next_snap, next_sample, s, fwhm, peak_x, peak_v, yline
  real(dp), allocatable :: curve(:, :), peaks(:, :), widths(:), walls(:), bounds(:, :)
  integer, allocatable :: its(:), nplast(:)
  real(dp), allocatable :: curves_all(:, :, :)
  integer, allocatable :: ncurves(:)

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
  if (len(deck_path) == 0) call die_text('no deck given (see --help)')

  call read_ps_deck(deck_path, overrides, cfg0, study, deck_text, err)
  if (allocated(err)) call die(err%message)
  if (len(run_name) > 0) cfg0%name = run_name
  ! check every case before writing anything
  do ic = 1, study%ncases
    do i = 1, ic - 1
      if (case_tag(i) == case_tag(ic)) call die(deck_path//': &study: cases '//int_text(i)// &
        ' and '//int_text(ic)//' are both "'//trim(case_tag(ic))//'"; give distinct '// &
        'dx/scale or labels')
    end do
    cfg = case_config(ic)
    call new_ps_scene(sc, cfg, err)
    if (allocated(err)) call die(deck_path//' (case '//int_text(ic)//'): '//err%message)
  end do
  call rd%create(out_root, cfg0%name, deck_path, err)
  if (allocated(err)) call die(err%message)
  call h5%create(rd%path('run.h5'), err)
  if (allocated(err)) call die(err%message)
  call h5%write_attr('wellposed_version', wellposed_version)
  call h5%write_attr('git_revision', wellposed_git_revision)
  call h5%write_attr('deck', deck_text)
  call h5%write_attr('props', cfg0%props(1:cfg0%nprops))

  write (output_unit, '(a)') 'wellposed-mpm2d '//wellposed_version//': '//cfg0%name//' ('// &
    trim(cfg0%title)//'), '//int_text(study%ncases)//' case(s)'
  write (output_unit, '(a)') '  writing '//rd%partial//' (renamed to '//rd%final//' when done)'
  flush (output_unit)
  call sm%add('scene', cfg0%name)
  call sm%add('cases', study%ncases)
  call sm%add('shape', trim(shape2d_names(cfg0%shape)))
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
  allocate (tags(study%ncases), peaks(2, study%ncases), widths(study%ncases), &
            walls(study%ncases))
  allocate (curves_all(3, 20000, study%ncases), ncurves(study%ncases))

  do ic = 1, study%ncases
    cfg = case_config(ic)
    s = study%scale(ic)
    tag = case_tag(ic)
    tags(ic) = tag
    call new_ps_scene(sc, cfg, err)
    if (allocated(err)) call die(err%message)
    nsteps_est = ceiling(cfg%t_end/sc%dt)
    write (output_unit, '(a)') '  case '//tag//': '//int_text(sc%parts%n)//' particles, '// &
      int_text(sc%nnodes)//' nodes, dt = '//real_text(sc%dt)//' s, ~'// &
      int_text(nsteps_est)//' steps, c = '//real_text(sc%c_max)//' m/s'
    if (sc%nl%active) write (output_unit, '(a)') '    nonlocal: L = '// &
      real_text(sc%nl%length)//' m, support radius '//real_text(sc%nl%radius)// &
      ' m, |h_zeta/(a + h_eta)| = '//real_text(sc%nl%bound_43)//' (eq. 4.43), '// &
      '|(h_eta + h_zeta)/a| = '//real_text(sc%nl%bound_45)//' (eq. 4.45), scheme '// &
      trim(nl_scheme_names(cfg%nonlocal%scheme))
    flush (output_unit)
    allocate (curve(3, nsteps_est + 10), its(nsteps_est + 10), nplast(nsteps_est + 10), &
              bounds(3, nsteps_est + 10))
    ncurve = 0
    nit = 0
    nsnap = 0
    next_snap = 0.0_dp
    next_sample = 0.0_dp
    call system_clock(c0, crate)
    clast = c0
    call snapshot()
    ended_early = .false.
    measured = .false.
    end_message = ''
    do while (sc%t < cfg%t_end - 0.5_dp*sc%dt)
      if (study%stop_on_cutback) prev = sc
      call ps_advance(sc, err, log_unit=output_unit)
      if (allocated(err)) then
        if (.not. (study%stop_on_cutback .and. err%status == status_cutback)) &
          call die('case '//tag//': '//err%message)
        ! the material gave out: end the case at the last complete step
        sc = prev
        ended_early = .true.
        end_message = err%message
        write (output_unit, '(a)') '    '//tag//': ended at t = '//real_text(sc%t)// &
          ' s (&time stop_on_cutback): '//err%message
        exit
      end if
      nit = nit + 1
      if (study%band_time > 0.0_dp .and. .not. measured .and. sc%t >= study%band_time) &
        call measure_band()
      its(nit) = sc%nl%last%iterations
      nplast(nit) = sc%nl%last%n_plastic
      bounds(:, nit) = [sc%nl%last%n_alpha, sc%nl%last%bound_seed, sc%nl%last%error]
      if (sc%t >= next_sample - 1.0e-12_dp) then
        ncurve = ncurve + 1
        curve(:, ncurve) = [sc%t, -sc%top_disp/cfg%height, ps_applied_stress(sc)]
        next_sample = next_sample + study%sample_dt
      end if
      if (study%snapshot_dt > 0.0_dp .and. sc%t >= next_snap - 1.0e-12_dp) call snapshot()
      call system_clock(c1)
      if (study%progress .and. real(c1 - clast, dp)/crate > 10.0_dp) then
        clast = c1
        write (output_unit, '(a)') '    '//tag//': step '//int_text(sc%nstep)//'/'// &
          int_text(nsteps_est)//', t = '//real_text(sc%t)//' s, stress = '// &
          real_text(ps_applied_stress(sc)*1.0e-6_dp)//' MPa, plastic '// &
          int_text(sc%nl%last%n_plastic)//', iterations '//int_text(sc%nl%last%iterations)// &
          ', ~'//int_text(nint(real(c1 - c0, dp)/crate*(nsteps_est - sc%nstep)/ &
          max(sc%nstep, 1)))//' s left'
        flush (output_unit)
      end if
    end do
    if (study%snapshot_dt <= 0.0_dp .or. next_snap - study%snapshot_dt < sc%t - 0.5_dp*sc%dt) &
      call snapshot()
    call system_clock(c1)
    wall = real(c1 - c0, dp)/crate
    walls(ic) = wall
    ! ---- measures
    if (.not. measured) call measure_band()
    widths(ic) = fwhm
    i = maxloc(curve(3, 1:ncurve), dim=1)
    peaks(:, ic) = [curve(2, i), curve(3, i)]
    ncurves(ic) = min(ncurve, size(curves_all, 2))
    curves_all(:, 1:ncurves(ic), ic) = curve(:, 1:ncurves(ic))
    call sm%add(tag//'.dx', cfg%dx, 'm')
    call sm%add(tag//'.scale', s)
    call sm%add(tag//'.particles', sc%parts%n)
    call sm%add(tag//'.steps', sc%nstep)
    call sm%add(tag//'.dt', sc%dt, 's')
    call sm%add(tag//'.wall_time', wall, 's')
    call sm%add(tag//'.ns_per_particle_step', wall*1.0e9_dp/(real(sc%parts%n, dp)*sc%nstep))
    call sm%add(tag//'.peak_stress', peaks(2, ic)*1.0e-6_dp, 'MPa, compression +')
    call sm%add(tag//'.strain_at_peak', peaks(1, ic), 'apparent axial strain')
    call sm%add(tag//'.final_stress', curve(3, ncurve)*1.0e-6_dp, 'MPa')
    call sm%add(tag//'.final_strain', curve(2, ncurve))
    call sm%add(tag//'.max_plastic_strain', maxval(ps_plastic_strain(sc)))
    call sm%add(tag//'.band_fwhm', fwhm, 'm, along the band line at '//real_text(yline)//' m')
    call sm%add(tag//'.band_peak_at', peak_x, 'm, along the band line')
    call sm%add(tag//'.band_time', band_t, 's, when the band width was measured')
    call sm%add(tag//'.band_peak_plastic_strain', peak_v)
    call sm%add(tag//'.max_substeps', sc%max_substeps)
    call sm%add(tag//'.ended_early', ended_early, 'true: the UMAT could not go on '// &
                '(stop_on_cutback); the curve ends at final_strain')
    if (ended_early) call sm%add(tag//'.end_reason', trim(end_message))
    if (sc%nl%active) then
      call sm%add(tag//'.nonlocal_steps_iterated', sc%nl%steps_iterated)
      call sm%add(tag//'.nonlocal_iterations_mean', &
                  real(sc%nl%iterations_total, dp)/max(sc%nl%steps_iterated, 1))
      call sm%add(tag//'.nonlocal_iterations_max', sc%nl%iterations_max)
      call sm%add(tag//'.lipschitz_eq4_43_sharp', sc%nl%bound_43, 'N_alpha = 1')
      call sm%add(tag//'.lipschitz_eq4_45_sharp', sc%nl%bound_45, 'N_alpha = 1')
      if (sc%nl%calls_sweeps > 0 .and. sc%nl%calls_local > 0) &
        call sm%add(tag//'.sweep_cost_over_local_update', &
                    (real(sc%nl%ticks_sweeps, dp)/sc%nl%calls_sweeps)/ &
                    (real(max(sc%nl%ticks_local, 1_int64), dp)/sc%nl%calls_local), &
                    'time per particle of one sweep (average + UMAT + eq. 4.49-4.50) '// &
                    'over one local UMAT update')
    end if
    call h5%write('cases/'//tag//'/curve', transpose(curve(:, 1:ncurve)))
    call h5%write('cases/'//tag//'/iterations', its(1:nit))
    call h5%write('cases/'//tag//'/n_plastic', nplast(1:nit))
    call write_csv_curve(rd%path(tag//'_curve.csv'), curve(:, 1:ncurve))
    call write_csv_iterations(rd%path(tag//'_iterations.csv'), its(1:nit), nplast(1:nit), sc%dt, &
                              bounds(:, 1:nit), sc%nl%bound_43)
    call write_xdmf(rd%path(tag//'.xdmf'), tag, nsnap, sc%parts%n)
    write (output_unit, '(a)') '    done in '//real_text(wall)//' s: peak '// &
      real_text(peaks(2, ic)*1.0e-6_dp)//' MPa at strain '//real_text(peaks(1, ic))// &
      ', band FWHM '//real_text(fwhm)//' m along the line at '//real_text(yline)//' m'
    if (sc%nl%active) write (output_unit, '(a)') '    nonlocal iterations per step: mean '// &
      real_text(real(sc%nl%iterations_total, dp)/max(sc%nl%steps_iterated, 1))//', max '// &
      int_text(sc%nl%iterations_max)//' over '//int_text(sc%nl%steps_iterated)// &
      ' plastic steps'
    flush (output_unit)
    deallocate (curve, its, nplast, bounds)
  end do

  ! ---- across cases: successive meshes, sizes
  do ic = 2, study%ncases
    call sm%add(trim(tags(ic))//'.curve_difference_to_'//trim(tags(ic - 1)), &
                curve_difference(ic - 1, ic)*1.0e-6_dp, &
                'MPa: max |stress difference| over the common strain range')
    call sm%add(trim(tags(ic))//'.band_fwhm_ratio_to_'//trim(tags(ic - 1)), &
                widths(ic)/widths(ic - 1))
  end do
  call sm%add('total_wall_time', sum(walls), 's')
  call h5%close(err)
  if (allocated(err)) call die(err%message)
  call sm%write(rd%path('summary.txt'), err)
  if (allocated(err)) call die(err%message)
  if (study%plot .and. .not. no_plot) then
    script = find_script()
    block
      character(len=:), allocatable :: args
      args = shell_quote(rd%partial)
      do ic = 1, study%ncases
        args = args//' '//shell_quote(trim(tags(ic)))
      end do
      call run_plot(script, args, err)
    end block
    if (allocated(err)) call die(err%message)
  end if
  call rd%commit(err)
  if (allocated(err)) call die(err%message)
  write (output_unit, '(a)') '  finished: '//rd%final//' (total '//real_text(sum(walls))//' s)'

contains

  !> The case's name: its label, else h<dx>[_s<scale>].
  function case_tag(k) result(t)
    integer, intent(in) :: k
    character(len=:), allocatable :: t
    t = trim(study%label(k))
    if (len(t) > 0) return
    t = 'h'//trim(short(study%dx(k)))
    if (study%scale(k) /= 1.0_dp) t = t//'_s'//trim(short(study%scale(k)))
  end function case_tag

  function case_config(k) result(c)
    integer, intent(in) :: k
    type(ps_config_t) :: c
    real(dp) :: f
    c = cfg0
    f = study%scale(k)
    c%dx = study%dx(k)
    c%width = cfg0%width*f
    c%height = cfg0%height*f
    c%weak_x = cfg0%weak_x*f
    c%weak_y = cfg0%weak_y*f
    c%top_velocity = cfg0%top_velocity*f
  end function case_config

  !> The band width now (fwhm, peak_x, peak_v, yline, band_t, measured).
  subroutine measure_band()
    if (study%band_axis == 'x') then
      yline = study%band_y*study%scale(ic)
      call band_width(sc, 1, yline, fwhm, peak_x, peak_v)
    else
      yline = study%band_x*study%scale(ic)
      call band_width(sc, 2, yline, fwhm, peak_x, peak_v)
    end if
    band_t = sc%t
    measured = .true.
  end subroutine measure_band

  !> Particle fields of the current state into run.h5: cases/<tag>/snap_<n>/.
  subroutine snapshot()
    character(len=:), allocatable :: g
    real(dp), allocatable :: xy(:, :)
    integer :: n
    nsnap = nsnap + 1
    n = sc%parts%n
    g = 'cases/'//tag//'/snap_'//int_text(nsnap)//'/'
    xy = transpose(sc%parts%x(:, 1:n))
    call h5%write(g//'xy', xy)
    call h5%write(g//'plastic_strain', ps_plastic_strain(sc))
    call h5%write(g//'sigma_xx', sc%parts%stress(1, 1:n))
    call h5%write(g//'sigma_yy', sc%parts%stress(2, 1:n))
    call h5%write(g//'sigma_xy', sc%parts%stress(4, 1:n))
    call h5%write(g//'dlambda', sc%parts%statev(2, 1:n))
    call h5%write(g//'zeta', sc%parts%statev(4, 1:n))
    call h5%write(g//'time', [sc%t])
    next_snap = next_snap + study%snapshot_dt
  end subroutine snapshot

  !> FWHM of ||eps^p|| along a line: axis 1, the horizontal line y = yl (m);
  !> axis 2, the vertical line x = yl. From the particles within half a
  !> particle spacing of it, sorted along it; the half maximum crossings are
  !> interpolated linearly. Where a crossing lies beyond the body the
  !> body's edge counts.
  subroutine band_width(scn, axis, yl, w, xpk, vpk)
    type(ps_scene_t), intent(in) :: scn
    integer, intent(in) :: axis
    real(dp), intent(in) :: yl
    real(dp), intent(out) :: w, xpk, vpk
    real(dp), allocatable :: xs(:), vs(:), ep(:)
    real(dp) :: half, xl, xr, tx, tv
    integer :: p, m, j, k, ipk, across
    allocate (ep(scn%parts%n))
    ep = ps_plastic_strain(scn)
    allocate (xs(0), vs(0))
    across = 3 - axis
    do p = 1, scn%parts%n
      if (abs(scn%parts%x(across, p) - yl) <= 0.5_dp*scn%cfg%dx/scn%cfg%ppc) then
        xs = [xs, scn%parts%x(axis, p)]
        vs = [vs, ep(p)]
      end if
    end do
    m = size(xs)
    w = 0.0_dp; xpk = 0.0_dp; vpk = 0.0_dp
    if (m < 3) return
    do j = 2, m
      tx = xs(j); tv = vs(j)
      k = j - 1
      do while (k >= 1)
        if (xs(k) <= tx) exit
        xs(k + 1) = xs(k); vs(k + 1) = vs(k)
        k = k - 1
      end do
      xs(k + 1) = tx; vs(k + 1) = tv
    end do
    ipk = maxloc(vs, dim=1)
    vpk = vs(ipk)
    xpk = xs(ipk)
    if (vpk <= 0.0_dp) return
    half = 0.5_dp*vpk
    xl = xs(1)
    do j = ipk, 2, -1
      if (vs(j - 1) < half) then
        xl = xs(j - 1) + (half - vs(j - 1))*(xs(j) - xs(j - 1))/(vs(j) - vs(j - 1))
        exit
      end if
    end do
    xr = xs(m)
    do j = ipk, m - 1
      if (vs(j + 1) < half) then
        xr = xs(j) + (vs(j) - half)*(xs(j + 1) - xs(j))/(vs(j) - vs(j + 1))
        exit
      end if
    end do
    w = xr - xl
  end subroutine band_width

  !> Max |stress_b(e) - stress_a(e)| (Pa) over the common strain range,
  !> curve b interpolated linearly at a's strains.
  real(dp) function curve_difference(a, b) result(d)
    integer, intent(in) :: a, b
    integer :: j, k
    real(dp) :: e, sb, emax
    d = 0.0_dp
    emax = min(curves_all(2, ncurves(a), a), curves_all(2, ncurves(b), b))
    k = 1
    do j = 1, ncurves(a)
      e = curves_all(2, j, a)
      if (e > emax) exit
      do while (k < ncurves(b) - 1 .and. curves_all(2, k + 1, b) < e)
        k = k + 1
      end do
      if (curves_all(2, k + 1, b) == curves_all(2, k, b)) cycle
      sb = curves_all(3, k, b) + (e - curves_all(2, k, b))* &
           (curves_all(3, k + 1, b) - curves_all(3, k, b))/ &
           (curves_all(2, k + 1, b) - curves_all(2, k, b))
      d = max(d, abs(sb - curves_all(3, j, a)))
    end do
  end function curve_difference

  subroutine write_csv_curve(path, c)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: c(:, :)
    integer :: j
    open (newunit=u, file=path, status='replace', action='write')
    write (u, '(a)') 'time_s,apparent_strain,applied_stress_Pa'
    do j = 1, size(c, 2)
      write (u, '(es16.8,2(",",es16.8))') c(:, j)
    end do
    close (u)
  end subroutine write_csv_curve

  !> One line per step with plastic particles: iterations, and the bounds
  !> of eq. 4.43 (the seed's with N_alpha, and the sharp one) of that step.
  subroutine write_csv_iterations(path, it, np, dt, b, sharp)
    character(len=*), intent(in) :: path
    integer, intent(in) :: it(:), np(:)
    real(dp), intent(in) :: dt, b(:, :), sharp
    integer :: j
    open (newunit=u, file=path, status='replace', action='write')
    write (u, '(a)') 'step,time_s,plastic_particles,iterations,n_alpha,'// &
      'lipschitz_eq4_43_seed,lipschitz_eq4_43_sharp,final_error'
    do j = 1, size(it)
      if (np(j) > 0) write (u, '(i0,",",es14.6,",",i0,",",i0,4(",",es12.4))') j, j*dt, &
        np(j), it(j), b(1, j), b(2, j), sharp, b(3, j)
    end do
    close (u)
  end subroutine write_csv_iterations

  !> An XDMF 2 file: a temporal collection of polyvertex grids whose
  !> geometry and attributes are the snapshot datasets in run.h5.
  subroutine write_xdmf(path, tg, ns, n)
    character(len=*), intent(in) :: path, tg
    integer, intent(in) :: ns, n
    integer :: j, f
    character(len=*), parameter :: fields(7) = [character(len=14) :: 'plastic_strain', &
      'sigma_xx', 'sigma_yy', 'sigma_xy', 'dlambda', 'zeta', 'plastic_strain']
    character(len=:), allocatable :: g
    open (newunit=u, file=path, status='replace', action='write')
    write (u, '(a)') '<?xml version="1.0" ?>'
    write (u, '(a)') '<Xdmf Version="2.0">'
    write (u, '(a)') ' <Domain>'
    write (u, '(a)') '  <Grid Name="'//tg//'" GridType="Collection" CollectionType="Temporal">'
    do j = 1, ns
      g = 'run.h5:/cases/'//tg//'/snap_'//int_text(j)//'/'
      write (u, '(a)') '   <Grid Name="snap_'//int_text(j)//'" GridType="Uniform">'
      write (u, '(a)') '    <Time Value="'//real_text(snap_time(j))//'"/>'
      write (u, '(a)') '    <Topology TopologyType="Polyvertex" NumberOfElements="'// &
        int_text(n)//'"/>'
      write (u, '(a)') '    <Geometry GeometryType="XY">'
      write (u, '(a)') '     <DataItem Dimensions="'//int_text(n)//' 2" Format="HDF" '// &
        'NumberType="Float" Precision="8">'//g//'xy</DataItem>'
      write (u, '(a)') '    </Geometry>'
      do f = 1, 6
        write (u, '(a)') '    <Attribute Name="'//trim(fields(f))//'" Center="Node">'
        write (u, '(a)') '     <DataItem Dimensions="'//int_text(n)//'" Format="HDF" '// &
          'NumberType="Float" Precision="8">'//g//trim(fields(f))//'</DataItem>'
        write (u, '(a)') '    </Attribute>'
      end do
      write (u, '(a)') '   </Grid>'
    end do
    write (u, '(a)') '  </Grid>'
    write (u, '(a)') ' </Domain>'
    write (u, '(a)') '</Xdmf>'
    close (u)
  end subroutine write_xdmf

  !> Time of snapshot j (the snapshots are every snapshot_dt, the last at the end).
  real(dp) function snap_time(j)
    integer, intent(in) :: j
    if (study%snapshot_dt > 0.0_dp) then
      snap_time = min((j - 1)*study%snapshot_dt, sc%t)
    else
      snap_time = merge(0.0_dp, sc%t, j == 1)
    end if
  end function snap_time

  function short(x) result(text)
    real(dp), intent(in) :: x
    character(len=16) :: text
    write (text, '(f0.4)') x
    do while (len_trim(text) > 1 .and. text(len_trim(text):len_trim(text)) == '0')
      text(len_trim(text):len_trim(text)) = ' '
    end do
    if (text(len_trim(text):len_trim(text)) == '.') text(len_trim(text):len_trim(text)) = ' '
    if (text(1:1) == '.') text = '0'//text(1:len(text) - 1)
  end function short

  function find_script() result(path)
    character(len=:), allocatable :: path
    path = source_dir//'/driver/mpm/plots/mpm_plate.py'
    if (path_exists(path)) return
    path = install_data_dir//'/driver/mpm/plots/mpm_plate.py'
  end function find_script

  function get_arg(k) result(a)
    integer, intent(in) :: k
    character(len=:), allocatable :: a
    integer :: length
    call get_command_argument(k, length=length)
    allocate (character(len=length) :: a)
    call get_command_argument(k, a)
  end function get_arg

  subroutine usage()
    write (output_unit, '(a)') 'usage: wellposed-mpm2d [--out ROOT] [--name NAME] [--no-plot] '// &
      'DECK [group.key=value ...]'
    write (output_unit, '(a)') '  the plane-strain plate of seed chapter 4; decks in inputs/fig4_*.nml'
  end subroutine usage

  subroutine die_text(message)
    character(len=*), intent(in) :: message
    write (error_unit, '(a)') 'wellposed-mpm2d: error: '//message
    if (allocated(rd%partial)) write (error_unit, '(a)') 'wellposed-mpm2d: the run did not '// &
      'finish; its partial output is in '//rd%partial
    error stop 1
  end subroutine die_text

  subroutine die(message)
    character(len=*), intent(in) :: message
    call die_text(message)
  end subroutine die

end program wellposed_mpm2d
