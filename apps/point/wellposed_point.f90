!> wellposed-point DECK [--no-plot] [--out ROOT] [--max-memory SIZE]: one element.
!> Drives every &material of a namelist deck (keys in docs/guide/decks.md) through
!> the UMAT along the deck's legs, probes the state and runs the chapter 3
!> virtual experiment when asked, and writes <out_dir>/<name>/ (deck, CSV,
!> results.h5, summary.txt, PNGs). Errors go to standard error with exit
!> status 1 and leave only <name>.partial/ behind. `--batch FILE` runs a
!> batch file, one process per deck, over the ranks of an mpirun.
program wellposed_point
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_fs, only: int_text, shell_quote
  use wellposed_deck, only: value_text
  use wellposed_run_dir, only: run_dir_t
  use wellposed_summary, only: summary_t
  use wellposed_h5, only: h5_file_t
  use wellposed_checked_io, only: out_file_t, end_run, say_error
  use wellposed_memory, only: check_memory, parse_memory
  use wellposed_plot, only: run_plot
  use wellposed_build_info, only: wellposed_version, wellposed_git_revision
  use wellposed_dense, only: solve_dense
  use wellposed_point_material, only: material_t, point_state_t, umat_increment, ntens
  use wellposed_point_path, only: history_t, run_leg
  use wellposed_point_dissipation, only: add_dissipation
  use wellposed_point_probes, only: elastic_stiffness, lode_frame_t, find_lode_frame, &
    rtheta_probe, acoustic_t, acoustic_probe, wave_speeds, gudehus_probe, pi
  use wellposed_point_chapter3, only: ch3_result_t, run_chapter3
  use wellposed_point_deck, only: point_deck_t, read_point_deck
  use wellposed_point_config, only: plot_script
  use wellposed_mpi, only: comm_t, comm_start, comm_stop
  use wellposed_batch_run, only: run_batch, default_figures
  use wellposed_abaqus_job, only: abaqus_set_job
  use wellposed_out_of_memory, only: set_run_label
  implicit none

  type(point_deck_t) :: deck
  type(error_t), allocatable :: err
  type(run_dir_t) :: run
  type(summary_t) :: summary
  type(h5_file_t) :: h5
  character(len=4096) :: arg
  character(len=:), allocatable :: deck_path, out_root, batch_file, max_memory
  logical :: plot, check_only
  integer :: i, nargs, im
  integer(8) :: t0, t1, rate

  call system_clock(t0, rate)
  plot = .true.
  check_only = .false.
  deck_path = ''
  out_root = ''
  batch_file = ''
  max_memory = ''
  nargs = command_argument_count()
  i = 0
  do while (i < nargs)
    i = i + 1
    call get_command_argument(i, arg)
    select case (trim(arg))
    case ('--no-plot')
      plot = .false.
    case ('--check')
      check_only = .true.
    case ('--out', '--batch', '--max-memory')
      if (i == nargs) call fail_usage(trim(arg)//' needs a value')
      i = i + 1
      if (trim(arg) == '--max-memory') then
        call get_command_argument(i, arg)
        max_memory = trim(arg)
      else if (trim(arg) == '--out') then
        call get_command_argument(i, arg)
        out_root = trim(arg)
        if (len(out_root) == 0) call fail_usage('--out needs a non-empty value')
      else
        call get_command_argument(i, arg)
        batch_file = trim(arg)
        if (len(batch_file) == 0) call fail_usage('--batch needs a non-empty value')
      end if
    case ('-h', '--help')
      write (output_unit, '(a)') 'usage: wellposed-point DECK [--no-plot] [--out ROOT] [--check]', &
        '       [mpirun -np N] wellposed-point --batch FILE [--out ROOT] [--no-plot]', &
        '  DECK: namelist deck (groups and keys: docs/guide/decks.md)', &
        '  --no-plot: skip the PNG plots (same as plot = .false. in &run)', &
        '  --out ROOT: write ROOT/<name>/ instead of the deck''s out_dir', &
        '  --max-memory SIZE: refuse a deck needing more (4G, 512M; default MemAvailable)', &
        '  --check: read and check the deck (and its materials), run and write nothing', &
        '  --batch FILE: one deck per line (# comments); summary in ROOT/<FILE name>/'
      stop
    case default
      if (len_trim(arg) == 0) call fail_usage('an empty argument where a DECK was expected')
      if (arg(1:1) == '-') call fail_usage('unknown option "'//trim(arg)//'"')
      if (len(deck_path) > 0) call fail_usage('more than one deck given: '//trim(arg))
      deck_path = trim(arg)
    end select
  end do
  if (len(batch_file) > 0) then
    if (len(deck_path) > 0) call fail_usage('give a deck or --batch FILE, not both')
    call run_point_batch()
  end if
  if (len(deck_path) == 0) call fail_usage('no deck given')

  call set_run_label('wellposed-point', deck_path)
  call read_point_deck(deck_path, deck, err)
  call check(err)
  call memory_check()
  if (check_only) then
    write (output_unit, '(a)') deck_path//': read and checked (--check: nothing run)'
    stop
  end if
  if (len(out_root) > 0) deck%out_dir = out_root
  plot = plot .and. deck%plot
  call run%create(deck%out_dir, deck%name, deck_path, err)
  call check(err)
  ! GETOUTDIR and GETJOBNAME of a user's UMAT: the run folder being written
  call abaqus_set_job(run%partial, deck%name)
  write (output_unit, '(a)') 'wellposed-point '//wellposed_version//': deck '//deck_path// &
    ' -> '//run%final//' ('//int_text(size(deck%materials))//' material(s), '// &
    int_text(size(deck%legs))//' leg(s))'
  call h5%create(run%path('results.h5'), err)
  call check(err)
  call h5%write_attr('deck', deck%text)
  call h5%write_attr('deck_path', deck_path)
  call h5%write_attr('version', wellposed_version)
  call h5%write_attr('git_revision', wellposed_git_revision)
  call h5%write_attr('program', 'wellposed-point')
  call summary%add('version', wellposed_version)
  call summary%add('git_revision', wellposed_git_revision)
  call summary%add('n_materials', size(deck%materials))

  do im = 1, size(deck%materials)
    call run_material(deck%materials(im))
  end do

  call system_clock(t1)
  call summary%add('wall_time_s', real(t1 - t0, dp)/real(rate, dp), &
                   'excluding plots; not a regression figure')
  call summary%write(run%path('summary.txt'), err)
  call check(err)
  call h5%close(err)
  call check(err)
  if (plot) then
    write (output_unit, '(a)') '  plotting ...'
    call run_plot(plot_script, shell_quote(run%partial), err)
    call check(err)
  end if
  call run%commit(err)
  call check(err)
  call system_clock(t1)
  write (output_unit, '(a)') 'done in '//value_text(real(t1 - t0, dp)/real(rate, dp))// &
    ' s: '//run%final

contains

  !> --batch FILE: every deck of FILE through this program, one process
  !> each, shared over the ranks of an mpirun; exit status 1 when any failed.
  subroutine run_point_batch()
    type(comm_t) :: comm
    character(len=4096) :: self
    character(len=:), allocatable :: command
    integer :: nfailed
    call comm_start(comm, err)
    call check(err)
    call get_command_argument(0, self)
    command = shell_quote(trim(self))
    if (.not. plot) command = command//' --no-plot'
    if (len(out_root) == 0) out_root = 'out'
    call run_batch(comm, batch_file, command, out_root, default_figures('wellposed-point'), &
                   nfailed, err)
    call comm_stop(comm)
    call check(err)
    if (nfailed > 0) stop 1, quiet=.true.
    stop
  end subroutine run_point_batch

  !> Refuse a deck whose path history would not fit (--max-memory or
  !> MemAvailable): measured 360 bytes per increment with 12 STATEV, over
  !> the rows of the longest material's history (docs/guide/outputs.md).
  subroutine memory_check()
    real(dp) :: limit, rows, bytes
    limit = 0.0_dp
    if (len(max_memory) > 0) then
      call parse_memory(max_memory, limit, err)
      call check(err)
    end if
    rows = 1.0_dp + sum(real(max(deck%legs%n_inc, 1), dp))
    bytes = 20.0e6_dp + rows*360.0_dp*(13 + maxval(deck%materials%nstatv))/25.0_dp
    call check_memory(deck_path, bytes, rows, 'increments', limit, err)
    call check(err)
  end subroutine memory_check

  subroutine run_material(mat)
    type(material_t), intent(in) :: mat
    type(point_state_t) :: s
    type(point_state_t), allocatable :: saved(:)
    real(dp), allocatable :: d_last(:, :)
    type(history_t) :: hist
    character(len=:), allocatable :: lab
    integer :: il
    lab = mat%label
    write (output_unit, '(a)') '['//lab//'] '//int_text(size(mat%props))//' PROPS, '// &
      int_text(mat%nstatv)//' STATEV'
    call h5%write_attr('props.'//lab, mat%props)
    s%stress = deck%stress0
    s%strain = deck%strain0
    allocate (s%statev(mat%nstatv))
    s%statev = deck%statev0(1:mat%nstatv)
    allocate (saved(0:size(deck%legs)), d_last(ntens, 0:size(deck%legs)))
    d_last = 0.0_dp
    saved(0) = s
    call hist%push(s, 0, 0)
    do il = 1, size(deck%legs)
      call run_leg(mat, s, deck%legs(il), il, deck%solver, err, hist, d_last(:, il), lab)
      if (allocated(err)) err%message = deck_path//': material "'//lab//'": '//err%message
      call check(err)
      saved(il) = s
    end do
    call write_path(mat, hist)
    call write_plastic_strain(mat, hist)
    if (deck%probe%enabled) call run_probes(mat, saved(deck%probe%at_leg), &
                                            d_last(:, max(deck%probe%at_leg, 0)))
    if (deck%chapter3) call run_ch3(mat, s)
  end subroutine run_material

  subroutine write_path(mat, hist)
    type(material_t), intent(in) :: mat
    type(history_t), intent(in) :: hist
    type(out_file_t) :: csv
    integer :: i, n
    character(len=:), allocatable :: lab, header, row
    lab = mat%label
    n = hist%n
    header = 'leg,increment,time,e11,e22,e33,g12,g13,g23,s11,s22,s33,s12,s13,s23'
    do i = 1, mat%nstatv
      header = header//',statev'//int_text(i)
    end do
    call csv%open(run%path(lab//'_path.csv'), err)
    call check(err)
    call csv%put(header)
    allocate (character(len=64 + 25*(1 + 2*ntens + mat%nstatv)) :: row)
    do i = 1, n
      write (row, '(i0,",",i0,*(:,",",es24.16e3))') hist%leg(i), hist%inc(i), hist%time(i), &
        hist%strain(i, :), hist%stress(i, :), hist%statev(i, :)
      call csv%put(trim(row))
    end do
    call csv%close(err)
    call check(err)
    call h5%write(lab//'/path/time', hist%time(1:n))
    call h5%write(lab//'/path/leg', hist%leg(1:n))
    call h5%write(lab//'/path/strain', hist%strain(1:n, :))
    call h5%write(lab//'/path/stress', hist%stress(1:n, :))
    call h5%write(lab//'/path/statev', hist%statev(1:n, :))
    call summary%add(lab//'.path.n_rows', n, 'initial state and one row per increment')
    call summary%add(lab//'.path.cutbacks', hist%cutbacks)
    call summary%add(lab//'.path.fd_jacobians', hist%fd_jacobians)
    do i = 1, ntens
      call summary%add(lab//'.path.final_stress_'//trim(comp(i)), hist%stress(n, i))
    end do
    do i = 1, ntens
      call summary%add(lab//'.path.final_strain_'//trim(comp(i)), hist%strain(n, i), &
                       merge('engineering shear', '                 ', i > 3))
    end do
    do i = 1, min(mat%nstatv, 12)
      call summary%add(lab//'.path.final_statev_'//int_text(i), hist%statev(n, i))
    end do
  end subroutine write_path

  !> Plastic strain accrued along the path, eps - eps_0 - C^-1 (sigma - sigma_0)
  !> with C the UMAT's elastic stiffness at the virgin state: it needs no
  !> knowledge of the UMAT's STATEV, so it holds for a user's UMAT with
  !> linear elasticity too. Written as /<label>/path/plastic_strain; the
  !> summary gives tr(eps^p), ||eps^p|| (tensor norm) and their ratio.
  subroutine write_plastic_strain(mat, hist)
    type(material_t), intent(in) :: mat
    type(history_t), intent(in) :: hist
    real(dp) :: c(ntens, ntens), tr, nrm
    real(dp), allocatable :: ep(:, :)
    logical :: ok
    character(len=:), allocatable :: lab
    integer :: n, i
    lab = mat%label
    n = hist%n
    call elastic_stiffness(mat, deck%probe_strain, c, err)
    call check(err)
    allocate (ep(ntens, n))
    do i = 1, n
      ep(:, i) = hist%stress(i, :) - hist%stress(1, :)
    end do
    call solve_dense(c, ep, ok)
    if (.not. ok) then
      call summary%add(lab//'.path.plastic_volume_ratio', 'not applicable', &
                       'the elastic stiffness at the virgin state is singular')
      return
    end if
    do i = 1, n
      ep(:, i) = hist%strain(i, :) - hist%strain(1, :) - ep(:, i)
    end do
    call h5%write(lab//'/path/plastic_strain', transpose(ep))
    call add_dissipation(summary, lab, hist%stress(1:n, :), hist%strain(1:n, :), ep)
    tr = sum(ep(1:3, n))
    nrm = sqrt(sum(ep(1:3, n)**2) + 0.5_dp*sum(ep(4:6, n)**2))
    call summary%add(lab//'.path.final_plastic_volume', tr, &
                     'tr(eps^p) accrued along the path, eps^p = eps - C^-1 sigma')
    call summary%add(lab//'.path.final_plastic_norm', nrm, '||eps^p||, tensor norm')
    if (nrm > 1.0e-6_dp*max(maxval(abs(hist%strain(n, :) - hist%strain(1, :))), tiny(1.0_dp))) then
      call summary%add(lab//'.path.plastic_volume_ratio', tr/nrm, 'tr(eps^p)/||eps^p||')
    else
      call summary%add(lab//'.path.plastic_volume_ratio', 'not applicable', &
                       'plastic strain below 1e-6 of the strain: the path is elastic')
    end if
  end subroutine write_plastic_strain

  subroutine run_probes(mat, s, d_last)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s
    real(dp), intent(in) :: d_last(ntens)
    character(len=:), allocatable :: lab
    real(dp) :: c(ntens, ntens), t(ntens, ntens), pnewdt, c_e, c_p, mod_p
    real(dp), allocatable :: theta(:), r(:), phi(:), dsig2(:, :), deps2(:, :), depsp2(:, :)
    type(lode_frame_t) :: frame
    type(acoustic_t) :: ac
    type(point_state_t) :: s1
    type(out_file_t) :: csv
    integer :: i, imax, imin
    character(len=200) :: row
    lab = mat%label
    call elastic_stiffness(mat, deck%probe_strain, c, err)
    call check(err)
    call summary%add(lab//'.probe.at_leg', deck%probe%at_leg)
    if (deck%probe%rtheta) then
      write (output_unit, '(a)') '  ['//lab//'] probing R(theta) in '// &
        int_text(deck%probe%n_theta)//' directions'
      call find_lode_frame(mat, s, c, deck%probe_strain, frame, err)
      call check(err)
      allocate (theta(deck%probe%n_theta), r(deck%probe%n_theta))
      theta = [(2.0_dp*pi*(i - 1)/deck%probe%n_theta, i = 1, deck%probe%n_theta)]
      call rtheta_probe(mat, s, c, deck%probe_strain, frame, theta, r, err)
      call check(err)
      call csv%open(run%path(lab//'_rtheta.csv'), err)
      call check(err)
      call csv%put('theta_deg,R')
      do i = 1, size(theta)
        write (row, '(es24.16e3,",",es24.16e3)') theta(i)*180.0_dp/pi, r(i)
        call csv%put(trim(row))
      end do
      call csv%close(err)
      call check(err)
      call h5%write(lab//'/rtheta/theta_deg', theta*180.0_dp/pi)
      call h5%write(lab//'/rtheta/r', r)
      call h5%write(lab//'/rtheta/normal_lode', frame%n2)
      call h5%write(lab//'/rtheta/stress', s%stress)
      imax = maxloc(r, dim=1)
      imin = minloc(r, dim=1)
      call summary%add(lab//'.rtheta.r_max', r(imax), 'eq. 2.5, over the sampled directions')
      call summary%add(lab//'.rtheta.theta_max_deg', theta(imax)*180.0_dp/pi)
      call summary%add(lab//'.rtheta.r_min', r(imin))
      call summary%add(lab//'.rtheta.theta_min_deg', theta(imin)*180.0_dp/pi)
      call summary%add(lab//'.rtheta.sandler_rubin_wedge', r(imax) > 1.0_dp + 1.0e-6_dp, &
                       'R > 1 for some direction: plastic stiffer than elastic')
      call summary%add(lab//'.rtheta.negative_r', r(imin) < -1.0e-6_dp, &
                       'R < 0 for some direction: softening-like response')
      call summary%add(lab//'.rtheta.normal_theta_from_ez_deg', &
                       modulo(atan2(frame%n2(2), frame%n2(1))*180.0_dp/pi, 360.0_dp), &
                       'yield normal in the (E_z, E_r) plane, found from the probes')
    end if
    if (deck%probe%acoustic) then
      write (output_unit, '(a)') '  ['//lab//'] acoustic tensor over '// &
        int_text(deck%probe%n_polar*deck%probe%n_azimuth)//' normals'
      call umat_increment(mat, s, deck%probe_strain*d_last/max(norm2(d_last), tiny(1.0_dp)), &
                          1.0_dp, s1, t, pnewdt, err)
      call check(err)
      call acoustic_probe(t, c, deck%probe%n_polar, deck%probe%n_azimuth, ac, err)
      call check(err)
      call h5%write(lab//'/acoustic/polar_deg', ac%polar_deg)
      call h5%write(lab//'/acoustic/azimuth_deg', ac%azimuth_deg)
      call h5%write(lab//'/acoustic/min_eig', ac%min_eig)
      call h5%write(lab//'/acoustic/tangent', t)
      call summary%add(lab//'.acoustic.min_eig', ac%min_eig_global, &
                       'smallest eigenvalue of sym(n.T.n) over the normals')
      call summary%add(lab//'.acoustic.min_eig_ratio', ac%min_eig_global/ac%elastic_min_eig, &
                       'relative to the elastic n.C.n (G)')
      call summary%add(lab//'.acoustic.loss_of_ellipticity', ac%loss_of_ellipticity)
      call summary%add(lab//'.acoustic.critical_normal_angle_deg', &
                       acos(min(1.0_dp, abs(ac%n_crit(1))))*180.0_dp/pi, 'from axis 1')
      call summary%add(lab//'.acoustic.flutter', ac%flutter, 'complex eigenvalues of n.T.n')
    end if
    if (deck%probe%wave .and. mat%density > 0.0_dp) then
      call wave_speeds(mat, s, c, deck%probe_strain, deck%probe%wave_sign, c_e, c_p, mod_p, err)
      call check(err)
      call summary%add(lab//'.wave.elastic_speed', c_e, 'sqrt(C_1111/density)')
      call summary%add(lab//'.wave.plastic_modulus', mod_p, 'dsigma_11/deps_11 in uniaxial strain')
      call summary%add(lab//'.wave.plastic_speed', c_p)
      call summary%add(lab//'.wave.speed_ratio', c_p/c_e)
      call summary%add(lab//'.wave.plastic_faster', c_p > c_e*(1.0_dp + 1.0e-9_dp), &
                       'Sandler-Rubin condition')
    end if
    if (deck%probe%gudehus) then
      write (output_unit, '(a)') '  ['//lab//'] Gudehus envelope: '// &
        int_text(deck%probe%n_gudehus)//' stress probes'
      allocate (phi(deck%probe%n_gudehus))
      allocate (dsig2(size(phi), 2), deps2(size(phi), 2), depsp2(size(phi), 2))
      phi = [(360.0_dp*(i - 1)/size(phi), i = 1, size(phi))]
      call gudehus_probe(mat, s, deck%solver, deck%probe%gudehus_size, deck%probe%n_sub, phi, &
                         dsig2, deps2, depsp2, err)
      if (allocated(err)) err%message = deck_path//': material "'//lab//'": '//err%message
      call check(err)
      call csv%open(run%path(lab//'_gudehus.csv'), err)
      call check(err)
      call csv%put('phi_deg,dsig_z,dsig_r,deps_z,deps_r,depsp_z,depsp_r')
      do i = 1, size(phi)
        write (row, '(es24.16e3,6(",",es24.16e3))') phi(i), dsig2(i, :), deps2(i, :), &
          depsp2(i, :)
        call csv%put(trim(row))
      end do
      call csv%close(err)
      call check(err)
      call h5%write(lab//'/gudehus/phi_deg', phi)
      call h5%write(lab//'/gudehus/dsig', dsig2)
      call h5%write(lab//'/gudehus/deps', deps2)
      call h5%write(lab//'/gudehus/deps_plastic', depsp2)
      call summary%add(lab//'.gudehus.max_total_strain', maxval(norm2(deps2, dim=2)))
      call summary%add(lab//'.gudehus.max_plastic_strain', maxval(norm2(depsp2, dim=2)))
    end if
  end subroutine run_probes

  subroutine run_ch3(mat, s)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(inout) :: s
    type(ch3_result_t) :: res
    character(len=:), allocatable :: lab
    type(out_file_t) :: csv
    integer :: k
    character(len=200) :: row
    lab = mat%label
    write (output_unit, '(a)') '  ['//lab//'] chapter 3 virtual experiment: '// &
      int_text(deck%ch3%n_cycles)//' cycles of 8 legs'
    call run_chapter3(mat, s, deck%ch3, deck%solver, res, err)
    if (allocated(err)) err%message = deck_path//': material "'//lab//'": '//err%message
    call check(err)
    call csv%open(run%path(lab//'_chapter3.csv'), err)
    call check(err)
    call csv%put('leg,dsig_z,dsig_r,deps_z,deps_r,depsp_z,depsp_r')
    do k = 1, 8
      write (row, '(i0,6(",",es24.16e3))') k, res%s(:, k), res%r(:, k), res%rp(:, k)
      call csv%put(trim(row))
    end do
    call csv%close(err)
    call check(err)
    call h5%write(lab//'/chapter3/s', res%s)
    call h5%write(lab//'/chapter3/r', res%r)
    call h5%write(lab//'/chapter3/rp', res%rp)
    call h5%write(lab//'/chapter3/l', res%l)
    call h5%write(lab//'/chapter3/l_el', res%l_el)
    call h5%write(lab//'/chapter3/m', res%m)
    call h5%write(lab//'/chapter3/n', res%n)
    call h5%write(lab//'/chapter3/seq_deps', res%seq_deps)
    call h5%write(lab//'/chapter3/seq_depsp', res%seq_depsp)
    call summary%add(lab//'.chapter3.theta_m_deg', res%theta_m, &
                     'flow direction from the hydrostatic compression axis (table 3.2)')
    call summary%add(lab//'.chapter3.theta_n_deg', res%theta_n, 'yield normal, same reference')
    call summary%add(lab//'.chapter3.residual', res%residual, &
                     '||R - L S||/||R||, legs A-D (0: incrementally linear there)')
    call summary%add(lab//'.chapter3.residual_elastic', res%residual_el, 'same, reversed legs')
    call summary%add(lab//'.chapter3.rank_ratio', res%rank_ratio, &
                     'small/large eigenvalue of A^T A (0: A = P (x) Q / mu exactly)')
  end subroutine run_ch3

  pure function comp(i) result(name)
    integer, intent(in) :: i
    character(len=2) :: name
    character(len=2), parameter :: names(6) = ['11', '22', '33', '12', '13', '23']
    name = names(i)
  end function comp

  subroutine check(e)
    type(error_t), allocatable, intent(in) :: e
    if (.not. allocated(e)) return
    if (allocated(run%partial)) then
      call end_run('wellposed-point', e%message, run%partial)
    else
      call end_run('wellposed-point', e%message)
    end if
  end subroutine check

  subroutine fail_usage(message)
    character(len=*), intent(in) :: message
    call say_error('wellposed-point: '//message)
    call say_error('usage: wellposed-point DECK [--no-plot] [--out ROOT] | --batch FILE '// &
                   '[--out ROOT] [--no-plot] (see --help)')
    stop 2, quiet=.true.
  end subroutine fail_usage

end program wellposed_point
