!> The &material groups of an MPM deck (bar and plate alike) into the
!> scene's material set (wellposed_mpm_materials); namelists cannot repeat a
!> group in one READ, so each occurrence is one READ, in order. Keys:
!> density, nstatv, model ('wellposed': our model by its named keys, PROPS
!> 1-13, through the VUMAT; 'vumat', 'umat': the linked VUMAT on blocks, the
!> linked UMAT per particle, props as given), nonlocal_contract, region ('rest'|'box')
!> with x(2), y(2). Overrides: material.key=value (the first group),
!> materialN.key=value (the N-th). Keys: docs/guide/decks.md.
module wellposed_mpm_material_deck
  use, intrinsic :: iso_fortran_env, only: iostat_end
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_deck, only: check_finite, is_set, unset, namelist_error, lower
  use wellposed_umat_layout, only: prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_k0, &
                                   prop_h, prop_k_lim, prop_z_ref, prop_p_v, prop_p_d, &
                                   prop_tau, prop_h_zeta, prop_length, prop_explicit
  use wellposed_umat_host, only: umat_is_ours, vumat_is_ours
  use wellposed_mpm_materials, only: mpm_materials_t, max_materials, max_material_props, &
                                     add_material, check_regions, least_nstatv, &
                                     nstatv_why, occurrence
  implicit none
  private
  public :: read_materials, material_defaults_t, is_material_group, check_boxes

  !> A scene's defaults for a &material group.
  type :: material_defaults_t
    real(dp) :: density = 1000.0_dp
    integer :: nstatv = 12
    !> K, G, beta, beta_p, k0, h, k_lim, z_ref, P_v, P_d, tau, h_zeta, L
    real(dp) :: named(13) = 0.0_dp
  end type material_defaults_t

  !> The &material groups as read, one column an occurrence (sentinels:
  !> unset, '').
  type :: material_values_t
    real(dp) :: dens(max_materials) = 0.0_dp, x(2, max_materials) = 0.0_dp
    real(dp) :: y(2, max_materials) = 0.0_dp, named(13, max_materials) = 0.0_dp
    real(dp) :: props(max_material_props, max_materials) = 0.0_dp
    integer :: nstatv(max_materials) = 0
    character(len=16) :: model(max_materials) = '', region(max_materials) = ''
    logical :: contract(max_materials) = .false.
  end type material_values_t

  character(len=6), parameter :: named_keys(13) = [character(len=6) :: 'K', 'G', 'beta', &
    'beta_p', 'k0', 'h', 'k_lim', 'z_ref', 'P_v', 'P_d', 'tau', 'h_zeta', 'L']

contains

  !> True for an override group that names a &material occurrence
  !> ('material', 'material2', ...).
  pure logical function is_material_group(group)
    character(len=*), intent(in) :: group
    is_material_group = .false.
    if (len(group) < 8) return
    if (lower(group(1:8)) /= 'material') return
    is_material_group = verify(group(9:), '0123456789') == 0
  end function is_material_group

  !> Every &material group of deck `path` (its text `text`), then the
  !> overrides, into `mats` (regions of `ndim` dimensions) and the scene's
  !> `density`. Errors name the deck, the occurrence and the key.
  subroutine read_materials(path, text, overrides, ndim, dflt, mats, density, err)
    character(len=*), intent(in) :: path, text, overrides(:)
    integer, intent(in) :: ndim
    type(material_defaults_t), intent(in) :: dflt
    type(mpm_materials_t), intent(out) :: mats
    real(dp), intent(out) :: density
    type(error_t), allocatable, intent(out) :: err
    type(material_values_t) :: v
    integer :: n, k
    mats%deck = path
    mats%ndim = ndim
    density = dflt%density
    call read_occurrences(path, text, dflt, v, n, err); if (allocated(err)) return
    call apply_overrides(overrides, v, n, err); if (allocated(err)) return
    do k = 1, n
      call convert(path, v, k, n, mats, density, err)
      if (allocated(err)) return
    end do
    call check_regions(mats, err)
  end subroutine read_materials

  !> The deck's &material groups, in order, into v (n of them; one of the
  !> defaults when the deck has none).
  subroutine read_occurrences(path, text, dflt, v, n, err)
    character(len=*), intent(in) :: path, text
    type(material_defaults_t), intent(in) :: dflt
    type(material_values_t), intent(inout) :: v
    integer, intent(out) :: n
    type(error_t), allocatable, intent(out) :: err
    character(len=512) :: msg
    integer :: unit, ios, k
    n = 0
    open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call new_error(err, status_invalid, path, 'cannot open "'//path//'": '//trim(msg))
      return
    end if
    do k = 1, max_materials + 1
      call set_defaults(v, k, dflt)
      call read_one(v, k, ios, msg, unit=unit)
      if (ios == iostat_end) exit
      if (ios /= 0) then
        close (unit)
        err = namelist_error(path, label(k, k), ios, msg, text)
        return
      end if
      if (k > max_materials) then
        close (unit)
        call new_error(err, status_invalid, 'material', path//': more than '// &
          int_text(max_materials)//' &material groups'); return
      end if
      n = k
    end do
    close (unit)
    if (n == 0) then
      n = 1
      call set_defaults(v, 1, dflt)
    end if
  end subroutine read_occurrences

  !> The overrides material.key=value (the first group) and
  !> materialN.key=value (the N-th of n) into v.
  subroutine apply_overrides(overrides, v, n, err)
    character(len=*), intent(in) :: overrides(:)
    type(material_values_t), intent(inout) :: v
    integer, intent(in) :: n
    type(error_t), allocatable, intent(out) :: err
    character(len=512) :: msg
    character(len=:), allocatable :: grp
    integer :: i, eq, dot, which, ios
    do i = 1, size(overrides)
      eq = index(overrides(i), '=')
      dot = index(overrides(i), '.')
      if (dot < 2 .or. eq < dot + 2) cycle
      grp = lower(overrides(i)(1:dot - 1))
      if (.not. is_material_group(grp)) cycle
      which = 1
      if (len(grp) > 8) read (grp(9:), *) which
      if (which < 1 .or. which > n) then
        call new_error(err, status_invalid, grp, 'override "'//trim(overrides(i))// &
          '": the deck has '//int_text(n)//' &material group(s)'); return
      end if
      call read_one(v, which, ios, msg, line='&material '//trim(overrides(i)(dot + 1:))//' /')
      if (ios /= 0) then
        err = namelist_error('command line', 'material', ios, msg, trim(overrides(i)))
        return
      end if
    end do
  end subroutine apply_overrides

  !> Occurrence k's values: the scene's defaults (density only for the
  !> first; none past the last occurrence).
  subroutine set_defaults(v, k, dflt)
    type(material_values_t), intent(inout) :: v
    integer, intent(in) :: k
    type(material_defaults_t), intent(in) :: dflt
    if (k > max_materials) return
    v%dens(k) = dflt%density
    if (k > 1) v%dens(k) = unset
    v%nstatv(k) = dflt%nstatv
    v%named(:, k) = dflt%named
    v%props(:, k) = unset
    v%model(k) = ''
    v%region(k) = ''
    v%x(:, k) = unset
    v%y(:, k) = unset
    v%contract(k) = .false.
  end subroutine set_defaults

  !> One READ of the namelist into occurrence occ's values (past the last
  !> occurrence: read from the last's values, nothing kept).
  subroutine read_one(v, occ, ios, msg, unit, line)
    type(material_values_t), intent(inout) :: v
    integer, intent(in) :: occ
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: line
    real(dp) :: density, k, g, beta, beta_p, k0, h, k_lim, z_ref, p_v, p_d, tau, h_zeta, l
    real(dp) :: props(max_material_props), x(2), y(2)
    integer :: nstatv
    character(len=16) :: model, region
    logical :: nonlocal_contract
    namelist /material/ density, k, g, beta, beta_p, k0, h, k_lim, z_ref, p_v, p_d, tau, &
      h_zeta, l, props, nstatv, model, region, x, y, nonlocal_contract
    integer :: kk
    kk = min(occ, max_materials)
    density = v%dens(kk)
    associate (w => v%named(:, kk))
      k = w(1); g = w(2); beta = w(3); beta_p = w(4); k0 = w(5); h = w(6)
      k_lim = w(7); z_ref = w(8); p_v = w(9); p_d = w(10); tau = w(11); h_zeta = w(12)
      l = w(13)
    end associate
    props = v%props(:, kk); x = v%x(:, kk); y = v%y(:, kk)
    nstatv = v%nstatv(kk); model = v%model(kk); region = v%region(kk)
    nonlocal_contract = v%contract(kk)
    ios = 0
    if (present(unit)) read (unit, nml=material, iostat=ios, iomsg=msg)
    if (present(line)) read (line, nml=material, iostat=ios, iomsg=msg)
    if (ios /= 0 .or. occ > max_materials) return
    v%dens(occ) = density
    v%named(:, occ) = [k, g, beta, beta_p, k0, h, k_lim, z_ref, p_v, p_d, tau, h_zeta, l]
    v%props(:, occ) = props; v%x(:, occ) = x; v%y(:, occ) = y
    v%nstatv(occ) = nstatv; v%model(occ) = model; v%region(occ) = region
    v%contract(occ) = nonlocal_contract
  end subroutine read_one

  !> Occurrence k of n into the material set (the first's density the scene's).
  subroutine convert(path, v, k, n, mats, density, err)
    character(len=*), intent(in) :: path
    type(material_values_t), intent(in) :: v
    integer, intent(in) :: k, n
    type(mpm_materials_t), intent(inout) :: mats
    real(dp), intent(inout) :: density
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: g, m
    real(dp) :: pr(max_material_props)
    integer :: np
    logical :: box, via_vumat, mine
    g = label(k, n)
    m = lower(trim(v%model(k)))
    if (len(m) == 0) m = merge('umat     ', 'wellposed', any(is_set(v%props(:, k))))
    m = trim(m)
    via_vumat = m /= 'umat'
    mine = merge(vumat_is_ours(), umat_is_ours(), via_vumat)
    if (k > 1 .and. is_set(v%dens(k))) then
      if (v%dens(k) /= density) then
        call new_error(err, status_invalid, 'density', path//': &'//g//': density = '// &
          real_text(v%dens(k))//' differs from the first group''s '//real_text(density)// &
          ' kg/m^3: a scene takes one density'); return
      end if
    end if
    if (k == 1) then
      call check_finite(path, g, 'density', v%dens(1), err); if (allocated(err)) return
      density = v%dens(1)
    end if
    call material_props(path, g, m, v, k, via_vumat, pr, np, err); if (allocated(err)) return
    ! our model's length where the UMAT is ours or follows the contract
    if (v%nstatv(k) < least_nstatv(mine, v%contract(k))) then
      call new_error(err, status_invalid, 'nstatv', path//': &'//g//': nstatv = '// &
        int_text(v%nstatv(k))//' is below '// &
        int_text(least_nstatv(mine, v%contract(k)))// &
        nstatv_why(mine .or. v%contract(k))); return
    end if
    call material_region(path, g, v, k, mats%ndim, box, err); if (allocated(err)) return
    ! our slots (PROPS 12-14, STATEV 2/3) where the linked routine is
    ! ours, however its PROPS are given; a user's build passes named keys
    ! as plain PROPS
    if (box) then
      call add_material(mats, pr(1:np), v%nstatv(k), mine, v%contract(k), err, &
                        [v%x(1, k), v%y(1, k)], [v%x(2, k), v%y(2, k)], vumat=via_vumat)
    else
      call add_material(mats, pr(1:np), v%nstatv(k), mine, v%contract(k), err, &
                        vumat=via_vumat)
    end if
  end subroutine convert

  !> Occurrence k's PROPS pr(1:np) for model `m` ('wellposed': the named
  !> keys; 'umat', 'vumat': props as given), group label `g`.
  subroutine material_props(path, g, m, v, k, via_vumat, pr, np, err)
    character(len=*), intent(in) :: path, g, m
    type(material_values_t), intent(in) :: v
    integer, intent(in) :: k
    logical, intent(in) :: via_vumat
    real(dp), intent(inout) :: pr(max_material_props)
    integer, intent(out) :: np
    type(error_t), allocatable, intent(out) :: err
    integer :: j
    np = 0
    select case (m)
    case ('wellposed')
      if (any(is_set(v%props(:, k)))) then
        call new_error(err, status_invalid, 'props', path//': &'//g//': props is '// &
          'given with model = ''wellposed'' (our named keys); use model = ''umat'''); return
      end if
      do j = 1, 13
        call check_finite(path, g, trim(named_keys(j)), v%named(j, k), err)
        if (allocated(err)) return
      end do
      pr = 0.0_dp
      pr([prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_k0, prop_h, prop_k_lim, &
          prop_z_ref, prop_p_v, prop_p_d, prop_tau, prop_h_zeta, prop_length]) = v%named(:, k)
      pr(prop_explicit) = 1.0_dp
      np = prop_explicit
    case ('umat', 'vumat')
      if (.not. any(is_set(v%props(:, k)))) then
        call new_error(err, status_invalid, 'props', path//': &'//g//': model = '''// &
          m//''' needs props = <the '//trim(merge('VUMAT', 'UMAT ', via_vumat))// &
          '''s PROPS>'); return
      end if
      np = findloc(is_set(v%props(:, k)), .true., back=.true., dim=1)
      if (.not. all(is_set(v%props(1:np, k)))) then
        call new_error(err, status_invalid, 'props', path//': &'//g//': props has '// &
          'gaps; give every entry up to the last'); return
      end if
      call check_finite(path, g, 'props', v%props(1:np, k), err)
      if (allocated(err)) return
      pr(1:np) = v%props(1:np, k)
    case default
      call new_error(err, status_invalid, 'model', path//': &'//g//': model = '''// &
        trim(v%model(k))//''' is not a known material: ''wellposed'' (our model, named '// &
        'keys), ''vumat'' or ''umat'' (the linked VUMAT or UMAT with props)'); return
    end select
  end subroutine material_props

  !> Occurrence k's region ('rest', or a box of x and, on a plate, y) in
  !> `ndim` dimensions: `box` for a box.
  subroutine material_region(path, g, v, k, ndim, box, err)
    character(len=*), intent(in) :: path, g
    type(material_values_t), intent(in) :: v
    integer, intent(in) :: k, ndim
    logical, intent(out) :: box
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: r
    box = .false.
    r = lower(trim(v%region(k)))
    if (len(r) == 0) r = merge('box ', 'rest', any(is_set(v%x(:, k))))
    r = trim(r)
    select case (r)
    case ('rest')
      if (any(is_set(v%x(:, k))) .or. any(is_set(v%y(:, k)))) then
        call new_error(err, status_invalid, 'region', path//': &'//g//': region = '// &
          '''rest'' takes no x or y (they bound a box)'); return
      end if
    case ('box')
      box = .true.
      if (.not. all(is_set(v%x(:, k)))) then
        call new_error(err, status_invalid, 'x', path//': &'//g//': a box region needs '// &
          'x = lower, upper (m)'); return
      end if
      if (ndim == 1 .and. any(is_set(v%y(:, k)))) then
        call new_error(err, status_invalid, 'y', path//': &'//g//': y is for plates; '// &
          'a bar''s box is x = lower, upper'); return
      end if
      if (ndim == 2 .and. .not. all(is_set(v%y(:, k)))) then
        call new_error(err, status_invalid, 'y', path//': &'//g//': a plate''s box needs '// &
          'y = lower, upper (m) as well as x'); return
      end if
      call check_finite(path, g, 'x', v%x(:, k), err); if (allocated(err)) return
      if (ndim == 2) call check_finite(path, g, 'y', v%y(:, k), err)
      if (allocated(err)) return
    case default
      call new_error(err, status_invalid, 'region', path//': &'//g//': region = '''// &
        trim(v%region(k))//''' is not one of ''rest'', ''box'''); return
    end select
  end subroutine material_region

  !> 'material' for a deck of one group, else 'material (occurrence k)'.
  function label(k, n) result(s)
    integer, intent(in) :: k, n
    character(len=:), allocatable :: s
    s = 'material'
    if (n > 1) s = s//' (occurrence '//int_text(k)//')'
  end function label

  !> Error unless every box region of `mats` has extent (upper > lower) and
  !> reaches into the body [0, body(d)] of each axis d (named `body_name`,
  !> e.g. "the plate [0, 5] x [0, 5] m (&plate)"): a box outside it holds
  !> no particle, and the run would have no such material.
  subroutine check_boxes(mats, body, body_name, err)
    type(mpm_materials_t), intent(in) :: mats
    real(dp), intent(in) :: body(:)
    character(len=*), intent(in) :: body_name
    type(error_t), allocatable, intent(out) :: err
    character(len=1), parameter :: axis(2) = ['x', 'y']
    integer :: k, d
    do k = 1, mats%n
      if (mats%rest(k)) cycle
      do d = 1, mats%ndim
        associate (lo => mats%lo(d, k), hi => mats%hi(d, k))
          if (.not. hi > lo) then
            call new_error(err, status_invalid, axis(d), occurrence(mats, k)//': region: '// &
              axis(d)//' = '//real_text(lo)//', '//real_text(hi)//' m has no extent (the '// &
              'upper bound must exceed the lower)'); return
          end if
          if (hi <= 0.0_dp .or. lo >= body(d)) then
            call new_error(err, status_invalid, axis(d), occurrence(mats, k)//': region: '// &
              axis(d)//' = '//real_text(lo)//', '//real_text(hi)//' m lies outside '// &
              body_name//': the box would hold no particle'); return
          end if
        end associate
      end do
    end do
  end subroutine check_boxes

end module wellposed_mpm_material_deck
