!> What every MPM kind's deck checks share (docs/guide/decks.md, "Refused
!> decks"): samples and snapshots inside the run, and a step count t_end/dt,
!> dt = cfl dx/c as the run sets it, of 1 to max_steps (beyond only with
!> --force), and the implicit schemes' &time keys. Each kind's own checks:
!> wellposed_mpm_bar_checks, wellposed_mpm_plate_checks.
module wellposed_mpm_deck_checks
  use wellposed_kinds, only: dp
  use wellposed_finite, only: all_finite
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_deck, only: check_finite
  use wellposed_mpm_method, only: scheme_names, implicit_scheme, no_viscosity, mass_lumped, &
                                  mass_names
  use wellposed_mpm_linear_solver, only: linear_solver_available
  implicit none
  private
  public :: check_times, step_inputs, check_steps, max_steps, check_implicit

  !> Most time steps a run takes without --force (docs/guide/decks.md).
  real(dp), parameter :: max_steps = 1.0e7_dp

contains

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
  !> `implicit_dt` > 0: the implicit schemes' largest step in its place.
  subroutine check_steps(path, t_end, cfl, dx, density, modulus, force, err, implicit_dt)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: t_end, cfl, dx, density, modulus
    logical, intent(in) :: force
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: implicit_dt
    real(dp) :: dt, nsteps
    character(len=:), allocatable :: how, keys
    dt = cfl*dx/sqrt(modulus/density)
    how = ' (dt = cfl dx / c = '//real_text(dt)//' s with c = sqrt(M/density) = '// &
      real_text(sqrt(modulus/density))//' m/s, M probed through the UMAT)'
    keys = '&time t_end, &grid dx and the &material density'
    if (present(implicit_dt)) then
      if (implicit_dt > 0.0_dp) then
        dt = implicit_dt
        how = ' (&time dt = '//real_text(dt)//' s, the implicit schemes'' largest step)'
        keys = '&time t_end and dt'
      end if
    end if
    nsteps = t_end/dt
    if (.not. nsteps >= 1.0_dp) then
      call new_error(err, status_invalid, 't_end', path//': &time: t_end = '// &
        real_text(t_end)//' s is shorter than one time step'//how//': the run would take '// &
        'no step (check '//keys//')')
    else if (nsteps > real(huge(1), dp)) then
      call new_error(err, status_invalid, 't_end', path//': &time: t_end = '// &
        real_text(t_end)//' s needs about '//real_text(nsteps)//' time steps'//how// &
        ', more than a run can count ('//int_text(huge(1))//'), even with --force')
    else if (nsteps > max_steps .and. .not. force) then
      call new_error(err, status_invalid, 't_end', path//': &time: t_end = '// &
        real_text(t_end)//' s needs about '//real_text(nsteps)//' time steps'//how// &
        ', more than the limit of '//real_text(max_steps)//' (docs/guide/decks.md): check '// &
        keys//', or pass --force to run it')
    end if
  end subroutine check_steps
  !> &time dt of the implicit schemes (docs/research/implicit.md): refused
  !> with an explicit scheme (`scheme`, wellposed_mpm_method's id), without
  !> PETSc in the build, with bulk viscosity `visc` (a1, a2) and with a
  !> given &time mass other than the lumped one; dt defaults to t_end/100
  !> and must lie in (0, t_end].
  subroutine check_implicit(path, scheme, t_end, visc, mass_given, mass, dt, err)
    character(len=*), intent(in) :: path
    integer, intent(in) :: scheme, mass
    real(dp), intent(in) :: t_end, visc(2)
    logical, intent(in) :: mass_given
    real(dp), intent(inout) :: dt
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: named
    call check_finite(path, 'time', 'dt', dt, err); if (allocated(err)) return
    if (.not. implicit_scheme(scheme)) then
      if (dt /= 0.0_dp) call bad('dt', 'dt = '//real_text(dt)//' s is the implicit '// &
        'schemes'' step (scheme = ''implicit'' or ''newmark''); the explicit step follows cfl')
      return
    end if
    named = 'scheme = '''//trim(scheme_names(scheme))//''''
    if (.not. linear_solver_available) then
      call bad('scheme', named//' needs PETSc, which this build lacks: install Debian''s '// &
               'petsc-dev and build again (docs/guide/building.md)'); return
    end if
    if (dt == 0.0_dp) dt = t_end/100.0_dp
    if (.not. (dt > 0.0_dp .and. dt <= t_end)) then
      call bad('dt', 'dt = '//real_text(dt)//' s must lie in (0, t_end = '// &
               real_text(t_end)//' s]'); return
    end if
    if (any(visc > 0.0_dp)) then
      call bad('scheme', named//': '//no_viscosity); return
    end if
    if (mass_given .and. mass /= mass_lumped) call bad('mass', 'mass = '''// &
      trim(mass_names(mass))//''' is the explicit bar''s grid acceleration; '//named// &
      ' takes the lumped mass (eq. 4.9): leave mass out or set it to ''lumped''')
  contains
    subroutine bad(key, what)
      character(len=*), intent(in) :: key, what
      call new_error(err, status_invalid, key, path//': &time: '//what)
    end subroutine bad
  end subroutine check_implicit

end module wellposed_mpm_deck_checks
