!> Physical consistency of an MPM deck, checked after reading and before
!> anything is set up (docs/guide/decks.md, "Refused decks"), every message
!> with its numbers: the bar's initial stress balances the traction at t = 0
!> (unless out_of_equilibrium) and lies inside the yield surface (a zero
!> increment through the material's interface: eq. 2.3, 2.10); stations,
!> samples, snapshots and the pulse inside the run; a step count t_end/dt,
!> dt = cfl dx/c as the run sets it, of 1 to max_steps (beyond only with
!> --force); a plate's top slower than the elastic wave speed.
module wellposed_mpm_deck_checks
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_finite, only: all_finite
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_deck, only: unheld_stress_note
  use wellposed_mpm_bar_config, only: bar_config_t, bc_free, pulse_ramp_sine
  use wellposed_mpm_bar_loads, only: surface_stress
  use wellposed_mpm_bar_build, only: probe_moduli
  use wellposed_mpm_materials, only: mpm_materials_t
  use wellposed_mpm_plate_build, only: plate_config_t
  use wellposed_mpm_plate_deck, only: plate_study_t
  use wellposed_mpm_vumat_call, only: material_update
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_error, vumat_is_ours, &
                                 verdict_ok, verdict_cutback, umat_is_ours
  implicit none
  private
  public :: check_bar_deck, check_plate_deck, equilibrium_tol, yield_tol, max_steps

  !> Relative mismatch of traction and initial stress taken as equilibrium
  !> (decks write both as the same decimal number: round-off only).
  real(dp), parameter :: equilibrium_tol = 1.0e-9_dp
  !> Relative (to |sigma_0|) yield function or stress change taken as "on
  !> the yield surface" (round-off of the UMAT's arithmetic).
  real(dp), parameter :: yield_tol = 1.0e-9_dp

  !> STATEV(11) of the UMAT contract: the yield function f at the end of
  !> the increment; PROPS(11): the Duvaut-Lions relaxation time tau.
  integer, parameter :: slot_f = 11, slot_tau = 11

  !> Most time steps a run takes without --force (docs/guide/decks.md).
  real(dp), parameter :: max_steps = 1.0e7_dp

contains

  !> The bar deck `path` read into cfg: err when it is not physically
  !> consistent (see the module comment).
  subroutine check_bar_deck(path, cfg, err, force)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: force
    real(dp) :: last
    if (cfg%nstations > 0) then
      last = cfg%station_first + (cfg%nstations - 1)*cfg%station_spacing
      if (cfg%station_first < 0.0_dp .or. last > cfg%length .or. last < 0.0_dp) then
        call fail('stations', 'the stations run from x = '//real_text(cfg%station_first)// &
          ' m to x = '//real_text(last)//' m, outside the bar [0, '//real_text(cfg%length)// &
          '] m (&grid length)')
        return
      end if
    end if
    call check_times(path, cfg%t_end, cfg%sample_dt, cfg%snapshot_dt, err)
    if (allocated(err)) return
    if (cfg%pulse /= pulse_ramp_sine .and. cfg%load_peak /= 0.0_dp) then   ! a pulse
      if (cfg%load_start + cfg%load_duration > cfg%t_end) then
        call fail('load', 'the pulse runs from start = '//real_text(cfg%load_start)// &
          ' s to start + duration = '//real_text(cfg%load_start + cfg%load_duration)// &
          ' s, past the end of the run (&time t_end = '//real_text(cfg%t_end)//' s)')
        return
      end if
      if (cfg%load_duration == 0.0_dp) then
        call fail('load', 'a pulse of peak = '//real_text(cfg%load_peak)//' Pa and '// &
          'duration = 0 s carries nothing: give duration > 0 s, or peak = 0 for the base '// &
          'load alone')
        return
      end if
    end if
    if (.not. cfg%out_of_equilibrium) then
      call check_equilibrium(path, cfg, err)
      if (allocated(err)) return
    end if
    call check_yield(path, cfg, err)
    if (allocated(err)) return
    call bar_steps(path, cfg, present_true(force), err)
  contains
    subroutine fail(group, what)
      character(len=*), intent(in) :: group, what
      call new_error(err, status_invalid, group, path//': &'//group//': '//what)
    end subroutine fail
  end subroutine check_bar_deck

  !> The plate deck `path` (cfg, study): samples and snapshots inside the
  !> run; stations inside the plate, sampled at a fixed interval.
  subroutine check_plate_deck(path, cfg, study, err, force)
    character(len=*), intent(in) :: path
    type(plate_config_t), intent(in) :: cfg
    type(plate_study_t), intent(in) :: study
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: force
    integer :: s
    call check_times(path, cfg%t_end, study%sample_dt, study%snapshot_dt, err)
    if (allocated(err)) return
    call plate_steps(path, cfg, minval(study%dx(1:study%ncases)), present_true(force), err)
    if (allocated(err) .or. study%nstations == 0) return
    if (.not. study%sample_dt > 0.0_dp) then
      call new_error(err, status_invalid, 'sample_dt', path//': &stations: the station '// &
        'histories need &output sample_dt > 0 s (it is '//real_text(study%sample_dt)//' s)')
      return
    end if
    do s = 1, study%nstations
      if (study%station_x(s) < 0.0_dp .or. study%station_x(s) > cfg%width .or. &
          study%station_y(s) < 0.0_dp .or. study%station_y(s) > cfg%height) then
        call new_error(err, status_invalid, 'stations', path//': &stations: point '// &
          int_text(s)//' (x, y) = ('//real_text(study%station_x(s))//', '// &
          real_text(study%station_y(s))//') m lies outside the plate [0, '// &
          real_text(cfg%width)//'] x [0, '//real_text(cfg%height)//'] m (&plate)')
        return
      end if
    end do
  end subroutine check_plate_deck

  !> Samples and snapshots at most t_end apart: one after t = 0 at least.
  subroutine check_times(path, t_end, sample_dt, snapshot_dt, err)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: t_end, sample_dt, snapshot_dt
    type(error_t), allocatable, intent(out) :: err
    if (.not. (t_end > 0.0_dp)) return        ! the scene's own check names t_end
    if (sample_dt > t_end) then
      call new_error(err, status_invalid, 'sample_dt', path//': &output: sample_dt = '// &
        real_text(sample_dt)//' s is longer than the run (&time t_end = '//real_text(t_end)// &
        ' s): no sample would be taken after t = 0')
    else if (snapshot_dt > t_end) then
      call new_error(err, status_invalid, 'snapshot_dt', path//': &output: snapshot_dt = '// &
        real_text(snapshot_dt)//' s is longer than the run (&time t_end = '// &
        real_text(t_end)//' s): no snapshot would be taken after t = 0 (0: none)')
    end if
  end subroutine check_times

  !> sigma_xx(0) against the surface traction sigma_b(0) and, with a free
  !> far end, against 0.
  subroutine check_equilibrium(path, cfg, err)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: sb, sx, scale
    character(len=*), parameter :: hint = ' (&initial out_of_equilibrium = .true. starts '// &
      'it so on purpose)'
    sb = surface_stress(cfg, 0.0_dp)
    sx = cfg%stress0(1)
    ! A non-finite stress or load is the scene's to name (no ordered
    ! comparison with a NaN: a trap under -ffpe-trap=invalid).
    if (.not. all_finite([sb, sx, cfg%load_peak])) return
    scale = max(abs(sb), abs(sx), abs(cfg%load_peak))
    if (abs(sb - sx) > equilibrium_tol*scale) then
      call new_error(err, status_invalid, 'stress', path//': &initial: stress(1) = '// &
        mpa(sx)//' MPa is not in equilibrium with the surface traction at t = 0, '// &
        '&load base + pulse(0) = '//mpa(sb)//' MPa (they differ by '//mpa(sx - sb)// &
        ' MPa; tolerance '//real_text(equilibrium_tol)//' relative)'//hint)
      return
    end if
    if (cfg%bc_far == bc_free .and. abs(sx) > equilibrium_tol*scale) then
      call new_error(err, status_invalid, 'stress', path//': &initial: stress(1) = '// &
        mpa(sx)//' MPa is not in equilibrium with the free far end (&grid far_end = '// &
        "'free' holds sigma_xx = 0 there)"//hint)
    end if
  end subroutine check_equilibrium

  !> The initial stress inside or on the yield surface (module comment) of
  !> every material of the bar: each region starts from the same stress.
  subroutine check_yield(path, cfg, err)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: which
    integer :: k
    if (cfg%materials%n == 0) then
      call check_yield_of(path, cfg, cfg%props(1:cfg%nprops), 'its &material', err)
      return
    end if
    do k = 1, cfg%materials%n
      which = '&material group '//int_text(k)
      if (cfg%materials%n == 1) which = 'its &material'
      call check_yield_of(path, cfg, cfg%materials%props(1:cfg%materials%nprops(k), k), which, err, &
                          cfg%materials%vumat(k) .and. .not. vumat_is_ours())
      if (allocated(err)) return
    end do
  end subroutine check_yield

  !> check_yield for one material of PROPS `mat_props`, named `which`.
  subroutine check_yield_of(path, cfg, mat_props, which, err, user_vumat)
    character(len=*), intent(in) :: path, which
    type(bar_config_t), intent(in) :: cfg
    real(dp), intent(in) :: mat_props(:)
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: user_vumat  !< the zero increment through a user's VUMAT
    type(umat_host_t) :: h
    real(dp) :: props(max(size(mat_props), slot_tau)), s(6), sv(cfg%nstatv), zero(6), f, moved, &
                scale
    integer :: verdict, np, nsub
    real(dp) :: e(6)
    logical :: via
    np = size(mat_props)
    if (cfg%nstatv < 12 .or. np < 1) return   ! the scene's own checks say why
    call new_umat_host(h, 6, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    h%celent = cfg%dx
    h%dtime = 0.0_dp
    zero = 0.0_dp
    scale = max(norm2(cfg%stress0), 1.0_dp)
    ! a zero increment from the initial state: a state the material can hold
    ! comes back unchanged
    props = 0.0_dp
    props(1:np) = mat_props
    s = cfg%stress0
    sv = 0.0_dp
    via = .false.
    if (present(user_vumat)) via = user_vumat
    verdict = verdict_ok
    if (via) then
      e = zero
      call material_update(h, props(1:np), .true., s, sv, e, zero, nsub, err)
      if (allocated(err)) err%message = path//': '//err%message
      if (allocated(err)) return
    else
      call host_call(h, props(1:np), s, sv, zero, zero, verdict)
    end if
    if (verdict == verdict_cutback) then
      call new_error(err, status_invalid, 'stress', path//': &initial: '//trim(which)// &
        ' asks for a smaller step on a zero increment from the initial stress (through the '// &
        'UMAT)'//unheld_stress_note(cfg%stress0))
      return
    else if (verdict /= verdict_ok) then
      call host_error(h, verdict, err, 'a zero increment from the initial stress')
      err%message = path//': '//err%message
      return
    end if
    moved = norm2(s - cfg%stress0)
    f = 0.0_dp
    if (umat_is_ours()) then
      ! the yield function of the initial stress itself: with tau > 0 and
      ! DTIME = 0 the Duvaut-Lions update is the elastic trial (eq. 2.10)
      if (props(slot_tau) <= 0.0_dp) props(slot_tau) = 1.0_dp
      s = cfg%stress0
      sv = 0.0_dp
      call host_call(h, props, s, sv, zero, zero, verdict)
      if (verdict == verdict_ok) f = sv(slot_f)
    end if
    if (f > yield_tol*scale) then
      call new_error(err, status_invalid, 'stress', path//': &initial: stress = '// &
        stress_text(cfg%stress0)//' MPa is outside the yield surface of '//trim(which)//' by '// &
        'f = sqrt(J2) + beta I1 - k = '//mpa(f)//' MPa (eq. 2.3; a zero-increment UMAT '// &
        'call, STATEV(11)): no state the material can hold')
    else if (moved > yield_tol*scale) then
      call new_error(err, status_invalid, 'stress', path//': &initial: stress = '// &
        stress_text(cfg%stress0)//' MPa is outside the yield surface of '//trim(which)//': a '// &
        'zero strain increment from it moves it by '//mpa(moved)//' MPa (through the UMAT)')
    end if
  end subroutine check_yield_of

  !> A stress in MPa, short: three decimals ("-50.0", "9.096"), or
  !> real_text below 0.01 MPa.
  pure function mpa(x) result(text)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    real(dp) :: v
    v = x/1.0e6_dp
    if (abs(v) < 0.01_dp .and. v /= 0.0_dp) then
      text = real_text(v)
      return
    end if
    write (buffer, '(f0.3)') abs(v)
    text = trim(buffer)
    if (text(1:1) == '.') text = '0'//text
    do while (text(len(text):len(text)) == '0' .and. text(len(text) - 1:len(text) - 1) /= '.')
      text = text(1:len(text) - 1)
    end do
    if (v < 0.0_dp) text = '-'//text
  end function mpa

  !> The six components in MPa: (s11, s22, s33, s12, s13, s23).
  pure function stress_text(s) result(text)
    real(dp), intent(in) :: s(6)
    character(len=:), allocatable :: text
    integer :: i
    text = '('//mpa(s(1))
    do i = 2, 6
      text = text//', '//mpa(s(i))
    end do
    text = text//')'
  end function stress_text

  !> The bar's time step as the scene sets it, dt = cfl dx / sqrt(M/rho)
  !> with M the largest elastic or loading uniaxial-strain modulus of its
  !> materials at the initial stress (probe_moduli), checked by check_steps.
  subroutine bar_steps(path, cfg, force, err)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    logical, intent(in) :: force
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: m, m_el, m_pl
    integer :: k
    character(len=:), allocatable :: which
    if (.not. step_inputs(cfg%t_end, cfg%cfl, cfg%dx, cfg%density)) return
    m = 0.0_dp
    do k = 1, max(cfg%materials%n, 1)
      if (cfg%materials%n == 0) then
        call probe_moduli(cfg, cfg%props(1:cfg%nprops), m_el, m_pl, err)
      else
        call probe_moduli(cfg, cfg%materials%props(1:cfg%materials%nprops(k), k), m_el, &
                          m_pl, err, cfg%materials%vumat(k))
      end if
      if (allocated(err)) then
        if (err%key == 'material') then      ! a modulus <= 0: say which, with its value
          which = '&material'
          if (cfg%materials%n > 1) which = '&material group '//int_text(k)
          err%message = path//': '//which//': '//modulus_reason(m_el, m_pl)
        else
          err%message = path//': '//err%message//' (probing the moduli for the time step)'
        end if
        return
      end if
      m = max(m, m_el, m_pl)
    end do
    call check_steps(path, cfg%t_end, cfg%cfl, cfg%dx, cfg%density, m, force, err)
  end subroutine bar_steps

  !> Why a bar's probed moduli give no time step: the elastic one or the
  !> loading one (eq. 2.19: a wave needs M > 0) is not > 0.
  pure function modulus_reason(m_el, m_pl) result(text)
    real(dp), intent(in) :: m_el, m_pl
    character(len=:), allocatable :: text
    if (.not. m_el > 0.0_dp) then
      text = 'the elastic uniaxial-strain modulus at the initial stress is M = '// &
        real_text(m_el)//' Pa (probed through the UMAT): it must be > 0 for a wave to travel'
    else
      text = 'the loading (plastic) uniaxial-strain modulus at the initial stress is '// &
        real_text(m_pl)//' Pa (elastic M = '//real_text(m_el)//' Pa; probed through the '// &
        'UMAT by slow increments): a loading wave needs it > 0 (else its speed is imaginary: '// &
        'loss of hyperbolicity, chapter 2), so this '// &
        'material cannot be loaded in the bar'
    end if
  end function modulus_reason

  !> The plate's time step as the scene sets it, dt = cfl dx / sqrt(M/rho)
  !> with M the largest plane-strain uniaxial modulus of its materials from
  !> the natural state (a -1e-7 strain increment through the UMAT), at the
  !> finest case `dx`; and the top's speed below the elastic wave speed
  !> sqrt(M/rho) (faster, the impact strain |v|/c would pass 1).
  subroutine plate_steps(path, cfg, dx, force, err)
    character(len=*), intent(in) :: path
    type(plate_config_t), intent(in) :: cfg
    real(dp), intent(in) :: dx
    logical, intent(in) :: force
    type(error_t), allocatable, intent(out) :: err
    type(umat_host_t) :: h
    real(dp) :: m, s(4), sv(cfg%nstatv), e(4), d(4), c
    integer :: k, verdict, nsub
    if (.not. step_inputs(cfg%t_end, cfg%cfl, dx, cfg%density) .or. cfg%materials%n == 0) return
    call new_umat_host(h, 4, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    h%dtime = 1.0e-6_dp
    d = [-1.0e-7_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    m = 0.0_dp
    do k = 1, cfg%materials%n
      s = 0.0_dp; sv = 0.0_dp; e = 0.0_dp
      if (cfg%materials%vumat(k)) then
        ! through the VUMAT its particles are called through, as the scene probes it
        call material_update(h, cfg%materials%props(1:cfg%materials%nprops(k), k), .true., s, &
                             sv, e, d, nsub, err)
        if (allocated(err)) then
          err%message = path//': '//err%message//' (probing the moduli for the time step)'
          return
        end if
        m = max(m, -s(1)/1.0e-7_dp)
        cycle
      end if
      call host_call(h, cfg%materials%props(1:cfg%materials%nprops(k), k), s, sv, e, d, verdict)
      if (verdict /= verdict_ok .and. verdict /= verdict_cutback) then
        call host_error(h, verdict, err, 'probing the moduli for the time step')
        err%message = path//': '//err%message
        return
      end if
      if (verdict == verdict_ok) m = max(m, -s(1)/1.0e-7_dp)
    end do
    if (.not. (m > 0.0_dp .and. ieee_is_finite(m))) return   ! the scene's check says why
    call check_steps(path, cfg%t_end, cfg%cfl, dx, cfg%density, m, force, err)
    if (allocated(err)) return
    c = sqrt(m/cfg%density)
    if (.not. abs(cfg%top_velocity) < c) then
      call new_error(err, status_invalid, 'top_velocity', path//': &boundary: top_velocity = '// &
        real_text(cfg%top_velocity)//' m/s is not below the elastic wave speed c = '// &
        real_text(c)//' m/s of the plate (sqrt(M/density), M probed through the UMAT): the '// &
        'impact strain |v|/c would reach 1')
    end if
  end subroutine plate_steps

  !> True when t_end, cfl, dx and density are finite and > 0 (else the
  !> scene's own checks name the key).
  pure logical function step_inputs(t_end, cfl, dx, density) result(ok)
    real(dp), intent(in) :: t_end, cfl, dx, density
    ok = all_finite([t_end, cfl, dx, density])
    if (ok) ok = t_end > 0.0_dp .and. cfl > 0.0_dp .and. dx > 0.0_dp .and. density > 0.0_dp
  end function step_inputs

  !> Error unless the run takes 1 to max_steps steps of dt = cfl dx /
  !> sqrt(modulus/density) to t_end (more only with `force`): a run of no
  !> step would write a finished-looking result, one of too many would not end.
  subroutine check_steps(path, t_end, cfl, dx, density, modulus, force, err)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: t_end, cfl, dx, density, modulus
    logical, intent(in) :: force
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: dt, nsteps
    character(len=:), allocatable :: how
    dt = cfl*dx/sqrt(modulus/density)
    nsteps = t_end/dt
    how = ' (dt = cfl dx / c = '//real_text(dt)//' s with c = sqrt(M/density) = '// &
      real_text(sqrt(modulus/density))//' m/s, M probed through the UMAT)'
    if (.not. nsteps >= 1.0_dp) then
      call new_error(err, status_invalid, 't_end', path//': &time: t_end = '// &
        real_text(t_end)//' s is shorter than one time step'//how//': the run would take '// &
        'no step (check &time t_end, &grid dx and the &material density)')
    else if (nsteps > real(huge(1), dp)) then
      call new_error(err, status_invalid, 't_end', path//': &time: t_end = '// &
        real_text(t_end)//' s needs about '//real_text(nsteps)//' time steps'//how// &
        ', more than a run can count ('//int_text(huge(1))//'), even with --force')
    else if (nsteps > max_steps .and. .not. force) then
      call new_error(err, status_invalid, 't_end', path//': &time: t_end = '// &
        real_text(t_end)//' s needs about '//real_text(nsteps)//' time steps'//how// &
        ', more than the limit of '//real_text(max_steps)//' (docs/guide/decks.md): check '// &
        '&time t_end, &grid dx and the &material density, or pass --force to run it')
    end if
  end subroutine check_steps

  !> `flag` when present, else false.
  pure logical function present_true(flag)
    logical, intent(in), optional :: flag
    present_true = .false.
    if (present(flag)) present_true = flag
  end function present_true
end module wellposed_mpm_deck_checks
