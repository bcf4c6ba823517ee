!> Physical consistency of a plate deck, checked after reading and before
!> anything is set up (docs/guide/decks.md, "Refused decks"): samples and
!> snapshots inside the run, stations inside the plate and sampled at a
!> fixed interval, the step count (wellposed_mpm_deck_checks) and the top
!> slower than the elastic wave speed. verify_plate_deck: wellposed-mpm --check.
module wellposed_mpm_plate_checks
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_text, only: int_text, real_text
  use wellposed_umat_host, only: umat_host_t, new_umat_host
  use wellposed_mpm_method, only: implicit_scheme
  use wellposed_mpm_deck_checks, only: check_times, step_inputs, check_steps
  use wellposed_mpm_plate_config, only: plate_config_t
  use wellposed_mpm_plate_deck, only: read_plate_deck, plate_study_t
  use wellposed_mpm_plate_kind, only: probe_stress
  implicit none
  private
  public :: check_plate_deck, verify_plate_deck

contains

  !> wellposed-mpm --check for a plate: the deck of `cli` with its
  !> overrides read and checked as a run reads and checks it (--force: past
  !> the step limit).
  subroutine verify_plate_deck(cli, err)
    type(mpm_cli_t), intent(in) :: cli
    type(error_t), allocatable, intent(out) :: err
    type(plate_config_t) :: cfg
    type(plate_study_t) :: study
    character(len=:), allocatable :: text
    call read_plate_deck(cli%deck_path, cli%overrides, cli%kinds, cfg, study, text, err)
    if (.not. allocated(err)) call check_plate_deck(cli%deck_path, cfg, study, err, cli%force)
  end subroutine verify_plate_deck

  !> The plate deck `path` (cfg, study): samples and snapshots inside the
  !> run; stations inside the plate, sampled at a fixed interval.
  subroutine check_plate_deck(path, cfg, study, err, force)
    character(len=*), intent(in) :: path
    type(plate_config_t), intent(in) :: cfg
    type(plate_study_t), intent(in) :: study
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in) :: force
    integer :: s
    call check_times(path, cfg%t_end, study%sample_dt, study%snapshot_dt, err)
    if (allocated(err)) return
    call plate_steps(path, cfg, minval(study%dx(1:study%ncases)), force, err)
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

  !> The plate's time step as the scene sets it, dt = cfl dx / sqrt(M/rho)
  !> with M the largest plane-strain uniaxial modulus of its materials from
  !> the natural state (the scene's probe_stress), at the finest case `dx`;
  !> and the top's speed below the elastic wave speed sqrt(M/rho) (faster,
  !> the impact strain |v|/c would pass 1).
  subroutine plate_steps(path, cfg, dx, force, err)
    character(len=*), intent(in) :: path
    type(plate_config_t), intent(in) :: cfg
    real(dp), intent(in) :: dx
    logical, intent(in) :: force
    type(error_t), allocatable, intent(out) :: err
    type(umat_host_t) :: h
    real(dp) :: m, ds(4), c
    integer :: k
    if (.not. step_inputs(cfg%t_end, cfg%cfl, dx, cfg%density) .or. cfg%materials%n == 0) return
    call new_umat_host(h, 4, cfg%nstatv, err, what='particle')
    if (allocated(err)) return
    m = 0.0_dp
    do k = 1, cfg%materials%n
      ds = probe_stress(h, cfg%materials, k, [-1.0e-7_dp, 0.0_dp, 0.0_dp, 0.0_dp], cfg%nstatv, &
                        'probing the moduli for the time step', err)
      if (allocated(err)) then
        err%message = path//': '//err%message
        return
      end if
      m = max(m, -ds(1)/1.0e-7_dp)
    end do
    if (.not. (m > 0.0_dp .and. ieee_is_finite(m))) return   ! the scene's check says why
    call check_steps(path, cfg%t_end, cfg%cfl, dx, cfg%density, m, force, err, &
                     merge(cfg%implicit_dt, 0.0_dp, implicit_scheme(cfg%scheme)))
    if (allocated(err)) return
    c = sqrt(m/cfg%density)
    if (.not. abs(cfg%top_velocity) < c) then
      call new_error(err, status_invalid, 'top_velocity', path//': &boundary: top_velocity = '// &
        real_text(cfg%top_velocity)//' m/s is not below the elastic wave speed c = '// &
        real_text(c)//' m/s of the plate (sqrt(M/density), M probed through the UMAT): the '// &
        'impact strain |v|/c would reach 1')
    end if
  end subroutine plate_steps

end module wellposed_mpm_plate_checks
