!> The axisymmetric kind's MPM deck: the shared groups (wellposed_mpm_deck_shared,
!> with this kind's defaults: the thick-walled cylinder under internal
!> pressure) and its own &cylinder, &boundary, &stations into an axi_config_t; the
!> checks a run makes before anything is set up (--check), and the memory
!> estimate. Overrides `group.key=value` are read after the deck. Keys:
!> docs/guide/axisymmetric.md.
module wellposed_mpm_axisymmetric_deck
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text, int_text
  use wellposed_deck, only: check_finite, lower, check_word, unset, is_set
  use wellposed_mpm_cli, only: mpm_cli_t
  use wellposed_mpm_memory, only: deck_bytes
  use wellposed_mpm_deck_shared, only: shared_deck_t, read_shared_deck
  use wellposed_mpm_deck_file, only: deck_groups_t, read_sources, sets_list
  use wellposed_mpm_scene_kind, only: kind_words_t
  use wellposed_mpm_materials, only: first_material
  use wellposed_mpm_material_deck, only: check_boxes
  use wellposed_mpm_shape_2d, only: shape2d_names
  use wellposed_mpm_plate_config, only: plate_bc_names, platen_names, bc_velocity, &
                                        bc_plate_free, bc_roller, platen_contact
  use wellposed_mpm_plate_deck, only: plate_study_t
  use wellposed_mpm_plate_checks, only: check_plate_deck
  use wellposed_mpm_axisymmetric_config, only: axi_config_t, closed_form_names, &
                                               check_axi_config, axi_max_stations
  implicit none
  private
  public :: axi_words, read_axi_deck, check_axi_deck, verify_axi_deck, axi_deck_memory

  character(len=16), parameter :: axi_groups(3) = [character(len=16) :: 'cylinder', 'boundary', &
                                                   'stations']
  !> Bytes per particle with outputs on and off: the plate's (the same
  !> particle and grid arrays; docs/guide/performance.md).
  real(dp), parameter :: axi_out = 1700.0_dp, axi_quiet = 1310.0_dp

  !> &cylinder and &boundary as read, before their checks.
  type, extends(deck_groups_t) :: axi_keys_t
    real(dp) :: r_inner = 1.0_dp, r_outer = 2.0_dp, height = 0.5_dp
    real(dp) :: p_inner = 100.0e6_dp, p_outer = 0.0_dp, pressure_ramp = 1.0e-2_dp
    real(dp) :: confining = 0.0_dp
    character(len=16) :: closed_form = 'lame'
    character(len=16) :: bottom = 'roller', top = 'velocity', top_lateral = 'free', &
                         platen = 'grid', sides = 'free'
    real(dp) :: top_velocity = 0.0_dp, ramp_time = 0.0_dp
    real(dp) :: r(axi_max_stations) = unset, z(axi_max_stations) = unset
  contains
    procedure :: read_group => read_axi_group
  end type axi_keys_t

contains

  !> What decks say of the axisymmetric kind: &scene kind = 'axisymmetric',
  !> or a deck with &cylinder; of the shared groups' kind-only keys it takes
  !> &time stop_on_cutback.
  pure function axi_words() result(words)
    type(kind_words_t) :: words
    words%name = 'axisymmetric'
    words%what = 'the axisymmetric cylinder'
    allocate (words%groups, source=axi_groups)
    allocate (words%marks, source=[character(len=16) :: 'cylinder'])
    allocate (words%keys, source=[character(len=32) :: 'time.stop_on_cutback'])
  end function axi_words

  !> Read `path` and the overrides into cfg (with &output's settings);
  !> `kinds`: the program's scene kinds (for messages on their keys).
  subroutine read_axi_deck(path, overrides, kinds, cfg, text, err)
    character(len=*), intent(in) :: path, overrides(:)
    type(kind_words_t), intent(in) :: kinds(:)
    type(axi_config_t), intent(out) :: cfg
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    type(shared_deck_t) :: sh
    type(axi_keys_t) :: k
    call axi_defaults(sh)
    call read_shared_deck(path, overrides, kinds, 'axisymmetric', shape2d_names, &
                          [character(len=1) ::], sh, text, err)
    if (allocated(err)) return
    call read_sources(k, path, text, overrides, axi_groups, err)
    if (allocated(err)) return
    associate (s => cfg%section)
      s%name = trim(sh%name); s%title = trim(sh%title)
      s%dx = sh%dx; s%ppc = sh%ppc; s%pad_cells = sh%pad_cells
      s%shape = sh%shape_id; s%scheme = sh%scheme_id
      s%t_end = sh%t_end; s%cfl = sh%cfl
      s%implicit_dt = sh%implicit_dt; s%linear_solver = sh%linear_solver_id
      s%visc_a1 = sh%visc_a1; s%visc_a2 = sh%visc_a2
      s%materials = sh%materials; s%density = sh%density; s%nonlocal = sh%nonlocal
      cfg%snapshot_dt = sh%snapshot_dt; cfg%sample_dt = sh%sample_dt
      cfg%progress = sh%progress; cfg%plot = sh%plot; cfg%stop_on_cutback = sh%stop_on_cutback
      call cylinder(path, k, cfg, err); if (allocated(err)) return
      call check_boxes(s%materials, [s%width, s%height], 'the section [0, '// &
        real_text(s%width)//'] x [0, '//real_text(s%height)//'] m (x = r - r_inner, y = z)', err)
      if (allocated(err)) return
      call first_material(s%materials, s%props, s%nprops, s%nstatv)
      call ends(path, k, cfg, err); if (allocated(err)) return
      call station_points(path, k, cfg, err)
    end associate
  end subroutine read_axi_deck

  !> The kind's defaults of the shared groups: an elastic steel-like
  !> cylinder (K = 76 GPa, G = 26 GPa, no yield), h = 0.125 m, to 10 ms.
  subroutine axi_defaults(sh)
    type(shared_deck_t), intent(inout) :: sh
    sh%ndim = 2
    sh%title = 'thick-walled cylinder under internal pressure (Lame)'
    sh%dx = 0.125_dp; sh%ppc = 2; sh%pad_cells = 2; sh%shape = 'cpdi'
    sh%t_end = 1.0e-2_dp; sh%cfl = 0.2_dp; sh%scheme = 'musl'
    sh%visc_a1 = 0.4_dp; sh%visc_a2 = 4.0_dp
    sh%mdef%density = 1000.0_dp; sh%mdef%nstatv = 12
    sh%mdef%named = 0.0_dp
    sh%mdef%named(1:6) = [76.0e9_dp, 26.0e9_dp, 0.0_dp, 0.0_dp, 4.0e12_dp, 0.0_dp]
  end subroutine axi_defaults

  !> &cylinder: finite values, r_outer > r_inner >= 0, the section a whole
  !> number of cells (the section's own check), the closed form's word.
  subroutine cylinder(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(axi_keys_t), intent(in) :: k
    type(axi_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    call check_finite(path, 'cylinder', 'r_inner', k%r_inner, err); if (allocated(err)) return
    call check_finite(path, 'cylinder', 'r_outer', k%r_outer, err); if (allocated(err)) return
    call check_finite(path, 'cylinder', 'height', k%height, err); if (allocated(err)) return
    call check_finite(path, 'cylinder', 'p_inner', k%p_inner, err); if (allocated(err)) return
    call check_finite(path, 'cylinder', 'p_outer', k%p_outer, err); if (allocated(err)) return
    call check_finite(path, 'cylinder', 'pressure_ramp', k%pressure_ramp, err)
    if (allocated(err)) return
    call check_finite(path, 'cylinder', 'confining', k%confining, err); if (allocated(err)) return
    if (.not. (k%r_inner >= 0.0_dp .and. k%r_outer > k%r_inner .and. k%height > 0.0_dp)) then
      call new_error(err, status_invalid, 'r_outer', path//': &cylinder: r_inner = '// &
        real_text(k%r_inner)//' m, r_outer = '//real_text(k%r_outer)//' m, height = '// &
        real_text(k%height)//' m: need 0 <= r_inner < r_outer and height > 0'); return
    end if
    cfg%r_inner = k%r_inner
    cfg%section%width = k%r_outer - k%r_inner
    cfg%section%height = k%height
    cfg%p_inner = k%p_inner; cfg%p_outer = k%p_outer; cfg%pressure_ramp = k%pressure_ramp
    cfg%confining = k%confining
    call check_word(path, 'cylinder', 'closed_form', k%closed_form, closed_form_names, &
                    cfg%closed_form, err)
  end subroutine cylinder

  !> &boundary: the ends z = 0 and z = height as the plate's bottom and top;
  !> the lateral surfaces free (they carry the pressures) or on rollers
  !> (sides); the axis of a solid cylinder holds v_r = 0 whatever they say.
  subroutine ends(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(axi_keys_t), intent(in) :: k
    type(axi_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    associate (s => cfg%section)
      call check_word(path, 'boundary', 'bottom', k%bottom, plate_bc_names, s%bottom, err)
      if (allocated(err)) return
      call check_word(path, 'boundary', 'top', k%top, plate_bc_names, s%top, err)
      if (allocated(err)) return
      if (s%bottom == bc_velocity .or. .not. (s%top == bc_velocity .or. s%top == bc_plate_free)) &
        then
        call new_error(err, status_invalid, 'boundary', path//": &boundary: bottom is "// &
          "'roller', 'fixed' or 'free'; top is 'velocity' (a platen) or 'free'"); return
      end if
      call check_finite(path, 'boundary', 'top_velocity', k%top_velocity, err)
      if (allocated(err)) return
      call check_finite(path, 'boundary', 'ramp_time', k%ramp_time, err)
      if (allocated(err)) return
      s%top_velocity = k%top_velocity; s%ramp_time = k%ramp_time
      select case (lower(trim(k%top_lateral)))
      case ('fixed', 'free')
        s%top_lateral_fixed = lower(trim(k%top_lateral)) == 'fixed'
      case default
        call new_error(err, status_invalid, 'top_lateral', path//": &boundary: top_lateral "// &
          "= '"//trim(k%top_lateral)//"' is not one of 'fixed' (a rough platen, v_r = 0), "// &
          "'free' (frictionless)"); return
      end select
      call check_word(path, 'boundary', 'platen', k%platen, platen_names, s%platen, err)
      if (allocated(err)) return
      call check_word(path, 'boundary', 'sides', k%sides, plate_bc_names, s%sides, err)
      if (allocated(err)) return
      if (.not. (s%sides == bc_plate_free .or. s%sides == bc_roller)) then
        call new_error(err, status_invalid, 'sides', path//": &boundary: sides = '"// &
          trim(k%sides)//"': the lateral surfaces are 'free' (they carry &cylinder p_inner, "// &
          "p_outer) or 'roller' (v_r = 0 on them: uniaxial strain along the axis)"); return
      end if
      if (s%sides == bc_roller .and. (cfg%p_inner /= 0.0_dp .or. cfg%p_outer /= 0.0_dp)) then
        call new_error(err, status_invalid, 'sides', path//": &boundary: sides = 'roller' "// &
          "holds the lateral surfaces, so &cylinder p_inner and p_outer would act on nothing"// &
          ": give them as 0, or sides = 'free'"); return
      end if
      if (s%platen == platen_contact .and. s%top == bc_velocity) then
        call new_error(err, status_invalid, 'platen', path//": &boundary: platen = "// &
          "'contact' is not offered on a cylinder (its push acts on a plate's width); use "// &
          "'grid' or 'surface'"); return
      end if
    end associate
  end subroutine ends

  !> &stations r(:), z(:): as many of each, finite, without gaps, inside
  !> the cylinder, and sampled at a fixed interval (&output sample_dt > 0).
  subroutine station_points(path, k, cfg, err)
    character(len=*), intent(in) :: path
    type(axi_keys_t), intent(in) :: k
    type(axi_config_t), intent(inout) :: cfg
    type(error_t), allocatable, intent(out) :: err
    integer :: n, s
    n = count(is_set(k%r))
    if (n == 0 .and. count(is_set(k%z)) == 0) return
    if (count(is_set(k%z)) /= n .or. .not. all(is_set(k%r(1:n))) .or. &
        .not. all(is_set(k%z(1:n)))) then
      call new_error(err, status_invalid, 'r', path//': &stations: r and z must give the '// &
        'same number of points, without gaps (up to '//int_text(axi_max_stations)//')'); return
    end if
    call check_finite(path, 'stations', 'r', k%r(1:n), err); if (allocated(err)) return
    call check_finite(path, 'stations', 'z', k%z(1:n), err); if (allocated(err)) return
    do s = 1, n
      if (k%r(s) < cfg%r_inner .or. k%r(s) > cfg%r_inner + cfg%section%width .or. &
          k%z(s) < 0.0_dp .or. k%z(s) > cfg%section%height) then
        call new_error(err, status_invalid, 'stations', path//': &stations: point '// &
          int_text(s)//' (r, z) = ('//real_text(k%r(s))//', '//real_text(k%z(s))// &
          ') m lies outside the cylinder ['//real_text(cfg%r_inner)//', '// &
          real_text(cfg%r_inner + cfg%section%width)//'] x [0, '// &
          real_text(cfg%section%height)//'] m (&cylinder)'); return
      end if
    end do
    if (.not. cfg%sample_dt > 0.0_dp) then
      call new_error(err, status_invalid, 'sample_dt', path//': &stations: the station '// &
        'histories need &output sample_dt > 0 s (it is '//real_text(cfg%sample_dt)//' s)')
      return
    end if
    cfg%nstations = n
    cfg%station_r(1:n) = k%r(1:n)
    cfg%station_z(1:n) = k%z(1:n)
  end subroutine station_points

  !> One READ of group `grp` from the deck (`unit`) or an override `line`.
  subroutine read_axi_group(self, grp, ios, msg, unit, line)
    class(axi_keys_t), intent(inout) :: self
    character(len=*), intent(in) :: grp
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: r_inner, r_outer, height, p_inner, p_outer, pressure_ramp, top_velocity, &
                ramp_time, confining
    character(len=16) :: closed_form, bottom, top, top_lateral, platen, sides
    real(dp) :: r(axi_max_stations), z(axi_max_stations)
    namelist /cylinder/ r_inner, r_outer, height, p_inner, p_outer, pressure_ramp, closed_form, &
                        confining
    namelist /boundary/ bottom, top, top_velocity, ramp_time, top_lateral, platen, sides
    namelist /stations/ r, z
    r_inner = self%r_inner; r_outer = self%r_outer; height = self%height
    p_inner = self%p_inner; p_outer = self%p_outer; pressure_ramp = self%pressure_ramp
    closed_form = self%closed_form; confining = self%confining
    bottom = self%bottom; top = self%top; top_velocity = self%top_velocity
    ramp_time = self%ramp_time; top_lateral = self%top_lateral; platen = self%platen
    sides = self%sides; r = self%r; z = self%z
    ios = 0
    select case (grp)
    case ('cylinder')
      if (present(unit)) read (unit, nml=cylinder, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=cylinder, iostat=ios, iomsg=msg)
    case ('boundary')
      if (present(unit)) read (unit, nml=boundary, iostat=ios, iomsg=msg)
      if (present(line)) read (line, nml=boundary, iostat=ios, iomsg=msg)
    case ('stations')
      if (present(unit)) read (unit, nml=stations, iostat=ios, iomsg=msg)
      if (present(line)) then
        ! an override of a list replaces the whole list
        if (sets_list(line, 'r')) r = unset
        if (sets_list(line, 'z')) z = unset
        read (line, nml=stations, iostat=ios, iomsg=msg)
      end if
    end select
    self%r_inner = r_inner; self%r_outer = r_outer; self%height = height
    self%p_inner = p_inner; self%p_outer = p_outer; self%pressure_ramp = pressure_ramp
    self%closed_form = closed_form; self%confining = confining
    self%bottom = bottom; self%top = top; self%top_velocity = top_velocity
    self%ramp_time = ramp_time; self%top_lateral = top_lateral; self%platen = platen
    self%sides = sides; self%r = r; self%z = z
  end subroutine read_axi_group

  !> The deck's physical checks: snapshots inside the run, the step count
  !> and the platen below the wave speed (the section's, as a plate's).
  subroutine check_axi_deck(path, cfg, err, force)
    character(len=*), intent(in) :: path
    type(axi_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in) :: force
    type(plate_study_t) :: one
    call check_axi_config(cfg, err)
    if (allocated(err)) then
      err%message = path//': '//err%message
      return
    end if
    one%ncases = 1
    one%dx(1) = cfg%section%dx
    one%snapshot_dt = cfg%snapshot_dt
    one%sample_dt = cfg%sample_dt
    call check_plate_deck(path, cfg%section, one, err, force)
  end subroutine check_axi_deck

  !> wellposed-mpm --check: the deck of `cli` read and checked as a run would.
  subroutine verify_axi_deck(cli, err)
    type(mpm_cli_t), intent(in) :: cli
    type(error_t), allocatable, intent(out) :: err
    type(axi_config_t) :: cfg
    character(len=:), allocatable :: text
    call read_axi_deck(cli%deck_path, cli%overrides, cli%kinds, cfg, text, err)
    if (.not. allocated(err)) call check_axi_deck(cli%deck_path, cfg, err, cli%force)
  end subroutine verify_axi_deck

  !> The estimate (bytes) and particle count of the deck of `cli`.
  subroutine axi_deck_memory(cli, bytes, nparticles, err)
    type(mpm_cli_t), intent(in) :: cli
    real(dp), intent(out) :: bytes, nparticles
    type(error_t), allocatable, intent(out) :: err
    type(axi_config_t) :: cfg
    character(len=:), allocatable :: text
    bytes = 0.0_dp
    nparticles = 0.0_dp
    call read_axi_deck(cli%deck_path, cli%overrides, cli%kinds, cfg, text, err)
    if (allocated(err)) return
    nparticles = anint(cfg%section%width/cfg%section%dx)*anint(cfg%section%height/ &
                 cfg%section%dx)*real(cfg%section%ppc, dp)**2
    bytes = deck_bytes(nparticles, axi_out, axi_quiet, cli%ck_every /= 0 .or. &
                       cfg%snapshot_dt > 0.0_dp)
  end subroutine axi_deck_memory

end module wellposed_mpm_axisymmetric_deck
