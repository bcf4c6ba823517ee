!> Physical consistency of a bar deck, checked after reading and before
!> anything is set up (docs/guide/decks.md, "Refused decks"), every message
!> with its numbers: the initial stress balances the traction at t = 0
!> (unless out_of_equilibrium) and lies inside the yield surface (a zero
!> increment through the material's interface: eq. 2.3, 2.10); stations,
!> samples, snapshots and the pulse inside the run; the step count
!> (wellposed_mpm_deck_checks). verify_bar_deck: wellposed-mpm --check (and
!> the default mass's fallback note).
module wellposed_mpm_bar_checks
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_finite, only: all_finite
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_text, only: int_text, real_text
  use wellposed_deck, only: unheld_stress_note
  use wellposed_mpm_method, only: implicit_scheme
  use wellposed_mpm_deck_checks, only: check_times, step_inputs, check_steps
  use wellposed_mpm_bar_config, only: bar_config_t, bc_free, pulse_ramp_sine
  use wellposed_mpm_bar_deck, only: read_bar_deck, bar_options_t
  use wellposed_mpm_bar_loads, only: surface_stress
  use wellposed_mpm_bar_build, only: probe_moduli
  use wellposed_mpm_vumat_call, only: material_update
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_error, vumat_is_ours, &
                                 verdict_ok, verdict_cutback, umat_is_ours
  implicit none
  private
  public :: check_bar_deck, verify_bar_deck, equilibrium_tol, yield_tol

  !> Relative mismatch of traction and initial stress taken as equilibrium
  !> (decks write both as the same decimal number: round-off only).
  real(dp), parameter :: equilibrium_tol = 1.0e-9_dp
  !> Relative (to |sigma_0|) yield function or stress change taken as "on
  !> the yield surface" (round-off of the UMAT's arithmetic).
  real(dp), parameter :: yield_tol = 1.0e-9_dp

  !> STATEV(11) of the UMAT contract: the yield function f at the end of
  !> the increment; PROPS(11): the Duvaut-Lions relaxation time tau.
  integer, parameter :: slot_f = 11, slot_tau = 11

contains

  !> wellposed-mpm --check for a bar: the deck of `cli` with its overrides
  !> read and checked as a run reads and checks it (--force: past the step
  !> limit).
  subroutine verify_bar_deck(cli, err)
    type(mpm_cli_t), intent(in) :: cli
    type(error_t), allocatable, intent(out) :: err
    type(bar_config_t) :: cfg
    type(bar_options_t) :: opts
    character(len=:), allocatable :: text
    call read_bar_deck(cli%deck_path, cli%overrides, cli%kinds, cfg, opts, text, err)
    if (.not. allocated(err)) call check_bar_deck(cli%deck_path, cfg, err, cli%force)
    ! the run would print this note too: the default mass it falls back from
    if (.not. allocated(err) .and. allocated(opts%mass_note)) &
      write (output_unit, '(a)') cli%deck_path//': '//opts%mass_note
  end subroutine verify_bar_deck

  !> The bar deck `path` read into cfg: err when it is not physically
  !> consistent (see the module comment).
  subroutine check_bar_deck(path, cfg, err, force)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in) :: force
    call check_stations(path, cfg, err); if (allocated(err)) return
    call check_times(path, cfg%t_end, cfg%sample_dt, cfg%snapshot_dt, err)
    if (allocated(err)) return
    call check_pulse(path, cfg, err); if (allocated(err)) return
    if (.not. cfg%out_of_equilibrium) then
      call check_equilibrium(path, cfg, err)
      if (allocated(err)) return
    end if
    call check_yield(path, cfg, err)
    if (allocated(err)) return
    call bar_steps(path, cfg, force, err)
  end subroutine check_bar_deck

  !> The stations on the bar [0, length].
  subroutine check_stations(path, cfg, err)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: last
    if (cfg%nstations == 0) return
    last = cfg%station_first + (cfg%nstations - 1)*cfg%station_spacing
    if (cfg%station_first < 0.0_dp .or. last > cfg%length .or. last < 0.0_dp) &
      call fail(err, path, 'stations', 'the stations run from x = '// &
        real_text(cfg%station_first)//' m to x = '//real_text(last)//' m, outside the bar [0, '// &
        real_text(cfg%length)//'] m (&grid length)')
  end subroutine check_stations

  !> A pulse inside the run, and one that carries something.
  subroutine check_pulse(path, cfg, err)
    character(len=*), intent(in) :: path
    type(bar_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    if (cfg%pulse == pulse_ramp_sine .or. cfg%load_peak == 0.0_dp) return   ! no pulse
    if (cfg%load_start + cfg%load_duration > cfg%t_end) then
      call fail(err, path, 'load', 'the pulse runs from start = '//real_text(cfg%load_start)// &
        ' s to start + duration = '//real_text(cfg%load_start + cfg%load_duration)// &
        ' s, past the end of the run (&time t_end = '//real_text(cfg%t_end)//' s)')
    else if (cfg%load_duration == 0.0_dp) then
      call fail(err, path, 'load', 'a pulse of peak = '//real_text(cfg%load_peak)//' Pa and '// &
        'duration = 0 s carries nothing: give duration > 0 s, or peak = 0 for the base '// &
        'load alone')
    end if
  end subroutine check_pulse

  !> err keyed `group`: "path: &group: what".
  subroutine fail(err, path, group, what)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in) :: path, group, what
    call new_error(err, status_invalid, group, path//': &'//group//': '//what)
  end subroutine fail

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
    call check_steps(path, cfg%t_end, cfg%cfl, cfg%dx, cfg%density, m, force, err, &
                     merge(cfg%implicit_dt, 0.0_dp, implicit_scheme(cfg%scheme)))
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

end module wellposed_mpm_bar_checks
