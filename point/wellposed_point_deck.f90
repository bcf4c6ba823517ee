!> The deck of `wellposed-point`: Fortran namelist groups &run, &material,
!> &initial, &leg, &probe and &chapter3 in a plain text file (common:
!> wellposed_deck), each key documented in docs/guide/decks.md. Any other group
!> name is an error (the namelist READ would skip a misspelt group
!> silently); a group may end with "/" or with "&end".
module wellposed_point_deck
  use, intrinsic :: iso_fortran_env, only: iostat_end
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: read_deck_text, namelist_error, check_required, check_finite, &
                            check_range, unset, is_set, has_group, value_text, lower, &
                            check_group_names
  use wellposed_point_material, only: material_t, ntens
  use wellposed_point_path, only: leg_t, solver_t
  use wellposed_point_chapter3, only: ch3_config_t
  use wellposed_point_deck_studies, only: probe_config_t, read_probe, read_chapter3
  use wellposed_point_checks, only: check_point_materials
  use wellposed_fs, only: int_text
  implicit none
  private
  public :: point_deck_t, probe_config_t, read_point_deck, max_props, max_statev

  integer, parameter :: max_props = 64, max_statev = 256, max_materials = 16, max_legs = 1000


  !> Everything a deck says.
  type :: point_deck_t
    character(len=:), allocatable :: path, text, name, out_dir
    logical :: plot = .true.
    real(dp) :: probe_strain = 1.0e-7_dp
    type(solver_t) :: solver
    type(material_t), allocatable :: materials(:)
    real(dp) :: stress0(ntens) = 0.0_dp, strain0(ntens) = 0.0_dp
    real(dp) :: statev0(max_statev) = 0.0_dp
    type(leg_t), allocatable :: legs(:)
    type(probe_config_t) :: probe
    logical :: chapter3 = .false.
    type(ch3_config_t) :: ch3
  end type point_deck_t

contains

  !> Read and validate the deck `path`.
  subroutine read_point_deck(path, deck, err)
    character(len=*), intent(in) :: path
    type(point_deck_t), intent(out) :: deck
    type(error_t), allocatable, intent(out) :: err
    integer :: unit, ios
    character(len=512) :: msg
    deck%path = path
    call read_deck_text(path, deck%text, err)
    if (allocated(err)) return
    call check_group_names(path, deck%text, [character(len=32) :: 'run', 'material', &
      'initial', 'leg', 'probe', 'chapter3'], [character(len=32) :: 'material', 'leg'], err)
    if (allocated(err)) return
    call check_groups(deck, err)
    if (allocated(err)) return
    open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call new_error(err, status_invalid, path, 'cannot open "'//path//'": '//trim(msg))
      return
    end if
    call read_run(deck, unit, err)
    if (.not. allocated(err)) call read_materials(deck, unit, err)
    if (.not. allocated(err)) call read_initial(deck, unit, err)
    if (.not. allocated(err)) call read_legs(deck, unit, err)
    if (.not. allocated(err)) &
      call read_probe(path, deck%text, size(deck%legs), unit, deck%probe, err)
    if (.not. allocated(err)) &
      call read_chapter3(path, deck%text, unit, deck%chapter3, deck%ch3, err)
    close (unit)
    if (.not. allocated(err)) call check_point_materials(path, deck%materials, deck%stress0, &
                                                         deck%statev0, deck%legs, err)
  end subroutine read_point_deck

  !> Every "key =" inside a group (outside comments and strings) must be one
  !> of its keys (gfortran reports an unknown key after an array as bad data
  !> for the array); the groups themselves are check_group_names'.
  subroutine check_groups(deck, err)
    type(point_deck_t), intent(in) :: deck
    type(error_t), allocatable, intent(out) :: err
    character(len=*), parameter :: letters = &
      'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_'
    integer :: i, j, k
    logical :: comment
    character(len=1) :: quote
    character(len=:), allocatable :: t, word, group
    t = deck%text
    comment = .false.
    quote = ' '
    group = ''
    word = ''
    i = 1
    do while (i <= len(t))
      if (t(i:i) == new_line('a')) comment = .false.
      if (.not. comment) then
        if (quote /= ' ') then
          if (t(i:i) == quote) quote = ' '
        else if (t(i:i) == '"' .or. t(i:i) == "'") then
          quote = t(i:i)
        else if (t(i:i) == '!') then
          comment = .true.
        else if (t(i:i) == '/') then
          group = ''
        else if (t(i:i) == '&') then
          j = i + 1
          do while (j <= len(t))
            if (scan(t(j:j), letters) == 0) exit
            j = j + 1
          end do
          word = lower(t(i + 1:j - 1))
          group = word
          if (word == 'end') group = ''
          i = j - 1
        else if (len(group) > 0 .and. scan(t(i:i), letters(1:52)) > 0) then
          ! an identifier: a key when "=" (or "(index) =") follows
          j = i
          do while (j <= len(t))
            if (scan(t(j:j), letters) == 0) exit
            j = j + 1
          end do
          k = j
          if (k <= len(t)) then
            if (t(k:k) == '(') k = k + index(t(k:), ')')
          end if
          do while (k <= len(t))
            if (t(k:k) /= ' ' .and. t(k:k) /= char(9)) exit
            k = k + 1
          end do
          if (k <= len(t)) then
            if (t(k:k) == '=') then
              word = lower(t(i:j - 1))
              if (index(' '//group_keys(group)//' ', ' '//word//' ') == 0) then
                call new_error(err, status_invalid, word, deck%path//': &'//group// &
                  ': unknown key "'//t(i:j - 1)//'" (valid keys: '//group_keys(group)//')')
                return
              end if
            end if
          end if
          i = j - 1
        else if (scan(t(i:i), '0123456789.') > 0) then
          ! skip numbers (1.0e6 is not the key "e6")
          do while (i < len(t))
            if (scan(t(i + 1:i + 1), letters//'.+-') == 0) exit
            i = i + 1
          end do
        end if
      end if
      i = i + 1
    end do
  end subroutine check_groups

  !> The keys of a group, blank-separated.
  pure function group_keys(group) result(keys)
    character(len=*), intent(in) :: group
    character(len=:), allocatable :: keys
    select case (group)
    case ('run')
      keys = 'name out_dir plot probe_strain stress_tol stress_floor max_iter max_cutbacks verbose'
    case ('material')
      keys = 'label props nstatv density'
    case ('initial')
      keys = 'stress strain statev'
    case ('leg')
      keys = 'duration n_inc control target'
    case ('probe')
      keys = 'at_leg rtheta n_theta acoustic n_polar n_azimuth wave wave_sign gudehus '// &
             'gudehus_size n_gudehus n_sub'
    case ('chapter3')
      keys = 'magnitude phi n_cycles analysis_cycle drift_axial n_sub'
    case default
      keys = ''
    end select
  end function group_keys

  subroutine read_run(deck, unit, err)
    type(point_deck_t), intent(inout) :: deck
    integer, intent(in) :: unit
    type(error_t), allocatable, intent(out) :: err
    character(len=256) :: name, out_dir
    logical :: plot, verbose
    real(dp) :: probe_strain, stress_tol, stress_floor
    integer :: max_iter, max_cutbacks, ios, slash, dot
    character(len=512) :: msg
    namelist /run/ name, out_dir, plot, probe_strain, stress_tol, stress_floor, max_iter, &
      max_cutbacks, verbose
    slash = index(deck%path, '/', back=.true.)
    name = deck%path(slash + 1:)
    dot = index(name, '.', back=.true.)
    if (dot > 1) name = name(1:dot - 1)
    out_dir = 'out'
    plot = .true.
    verbose = .true.
    probe_strain = 1.0e-7_dp
    stress_tol = 1.0e-9_dp
    stress_floor = 1.0_dp
    max_iter = 25
    max_cutbacks = 12
    if (has_group(deck%text, 'run')) then
      rewind (unit)
      read (unit, nml=run, iostat=ios, iomsg=msg)
      if (ios /= 0) then
        err = namelist_error(deck%path, 'run', ios, msg, deck%text); return
      end if
    end if
    if (len_trim(name) == 0 .or. index(trim(name), '/') > 0 .or. index(trim(name), ' ') > 0) then
      call new_error(err, status_invalid, 'name', deck%path//': &run: name = "'//trim(name)// &
        '" must be a non-empty folder name without "/" or blanks'); return
    end if
    call check_range(deck%path, 'run', 'probe_strain', probe_strain, 1.0e-14_dp, 1.0e-2_dp, err)
    if (allocated(err)) return
    call check_range(deck%path, 'run', 'stress_tol', stress_tol, 1.0e-15_dp, 1.0e-2_dp, err)
    if (allocated(err)) return
    call check_range(deck%path, 'run', 'stress_floor', stress_floor, tiny(1.0_dp), huge(1.0_dp), err)
    if (allocated(err)) return
    call check_range(deck%path, 'run', 'max_iter', max_iter, 1, 1000, err)
    if (allocated(err)) return
    call check_range(deck%path, 'run', 'max_cutbacks', max_cutbacks, 0, 60, err)
    if (allocated(err)) return
    deck%name = trim(name)
    deck%out_dir = trim(out_dir)
    deck%plot = plot
    deck%probe_strain = probe_strain
    deck%solver%stress_tol = stress_tol
    deck%solver%stress_floor = stress_floor
    deck%solver%max_iter = max_iter
    deck%solver%max_cutbacks = max_cutbacks
    deck%solver%verbose = verbose
  end subroutine read_run

  subroutine read_materials(deck, unit, err)
    type(point_deck_t), intent(inout) :: deck
    integer, intent(in) :: unit
    type(error_t), allocatable, intent(out) :: err
    character(len=64) :: label
    real(dp) :: props(max_props), density
    integer :: nstatv, ios, n, nprops, i, j
    character(len=512) :: msg
    type(material_t) :: mats(max_materials)
    character(len=:), allocatable :: grp
    namelist /material/ label, props, nstatv, density
    rewind (unit)
    n = 0
    do
      label = ''
      props = unset
      nstatv = 12
      density = 0.0_dp
      read (unit, nml=material, iostat=ios, iomsg=msg)
      if (ios == iostat_end) exit
      grp = 'material'
      if (ios /= 0) then
        err = namelist_error(deck%path, grp, ios, msg, deck%text); return
      end if
      n = n + 1
      if (n > max_materials) then
        call new_error(err, status_invalid, 'material', deck%path//': more than '// &
          int_text(max_materials)//' &material groups'); return
      end if
      grp = 'material (number '//int_text(n)//')'
      call check_required(deck%path, grp, 'label', len_trim(label) > 0, err)
      if (allocated(err)) return
      if (verify(trim(label), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-') &
          /= 0) then
        call new_error(err, status_invalid, 'label', deck%path//': &'//grp//': label = "'// &
          trim(label)//'" may use only letters, digits, "_" and "-"'); return
      end if
      do j = 1, n - 1
        if (mats(j)%label == trim(label)) then
          call new_error(err, status_invalid, 'label', deck%path//': &'//grp//': label "'// &
            trim(label)//'" is used twice'); return
        end if
      end do
      nprops = 0
      do i = 1, max_props
        if (is_set(props(i))) nprops = i
      end do
      call check_required(deck%path, grp, 'props', nprops > 0, err)
      if (allocated(err)) return
      do i = 1, nprops
        if (.not. is_set(props(i))) then
          call new_error(err, status_invalid, 'props', deck%path//': &'//grp//': props('// &
            int_text(i)//') is not given but props('//int_text(nprops)//') is: give every '// &
            'slot up to the last (0 switches a feature off)'); return
        end if
      end do
      call check_finite(deck%path, grp, 'props', props(1:nprops), err)
      if (allocated(err)) return
      call check_range(deck%path, grp, 'nstatv', nstatv, 1, max_statev, err)
      if (allocated(err)) return
      call check_range(deck%path, grp, 'density', density, 0.0_dp, huge(1.0_dp), err)
      if (allocated(err)) return
      mats(n)%label = trim(label)
      mats(n)%props = props(1:nprops)
      mats(n)%nstatv = nstatv
      mats(n)%density = density
    end do
    if (n == 0) then
      call new_error(err, status_invalid, 'material', deck%path//': no &material group: '// &
        'a deck needs at least one "&material label = ..., props = ... /"'); return
    end if
    deck%materials = mats(1:n)
  end subroutine read_materials

  subroutine read_initial(deck, unit, err)
    type(point_deck_t), intent(inout) :: deck
    integer, intent(in) :: unit
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: stress(ntens), strain(ntens), statev(max_statev)
    integer :: ios
    character(len=512) :: msg
    namelist /initial/ stress, strain, statev
    stress = 0.0_dp
    strain = 0.0_dp
    statev = 0.0_dp
    if (has_group(deck%text, 'initial')) then
      rewind (unit)
      read (unit, nml=initial, iostat=ios, iomsg=msg)
      if (ios /= 0) then
        err = namelist_error(deck%path, 'initial', ios, msg, deck%text); return
      end if
    end if
    call check_finite(deck%path, 'initial', 'stress', stress, err)
    if (allocated(err)) return
    call check_finite(deck%path, 'initial', 'strain', strain, err)
    if (allocated(err)) return
    call check_finite(deck%path, 'initial', 'statev', statev, err)
    if (allocated(err)) return
    call check_statev_reach(); if (allocated(err)) return
    deck%stress0 = stress
    deck%strain0 = strain
    deck%statev0 = statev
  contains
    !> A statev slot past every material's NSTATV would be dropped unread.
    subroutine check_statev_reach()
      integer :: reach, k
      reach = maxval(deck%materials%nstatv)
      do k = reach + 1, max_statev
        if (statev(k) /= 0.0_dp) then
          call new_error(err, status_invalid, 'statev', deck%path//': &initial: statev('// &
            int_text(k)//') = '//value_text(statev(k))//' lies past every material''s '// &
            'NSTATV (the largest is '//int_text(reach)//'): no UMAT would read it')
          return
        end if
      end do
    end subroutine check_statev_reach
  end subroutine read_initial

  subroutine read_legs(deck, unit, err)
    type(point_deck_t), intent(inout) :: deck
    integer, intent(in) :: unit
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: duration, target(ntens)
    integer :: n_inc, ios, n, i
    character(len=6) :: control
    character(len=512) :: msg
    character(len=:), allocatable :: grp
    type(leg_t), allocatable :: legs(:)
    namelist /leg/ duration, n_inc, control, target
    allocate (legs(max_legs))
    rewind (unit)
    n = 0
    do
      duration = 1.0_dp
      n_inc = -1
      control = 'eeeeee'
      target = unset
      read (unit, nml=leg, iostat=ios, iomsg=msg)
      if (ios == iostat_end) exit
      if (ios /= 0) then
        err = namelist_error(deck%path, 'leg', ios, msg, deck%text); return
      end if
      n = n + 1
      if (n > max_legs) then
        call new_error(err, status_invalid, 'leg', deck%path//': more than '// &
          int_text(max_legs)//' &leg groups'); return
      end if
      grp = 'leg (number '//int_text(n)//')'
      call check_required(deck%path, grp, 'n_inc', n_inc /= -1, err)
      if (allocated(err)) return
      call check_range(deck%path, grp, 'n_inc', n_inc, 1, 10000000, err)
      if (allocated(err)) return
      call check_range(deck%path, grp, 'duration', duration, tiny(1.0_dp), huge(1.0_dp), err)
      if (allocated(err)) return
      if (verify(control, 'eEsS') /= 0 .or. len_trim(control) /= 6) then
        call new_error(err, status_invalid, 'control', deck%path//': &'//grp//': control = "'// &
          control//'" must be six letters, one per component 11 22 33 12 13 23: e (strain '// &
          'target) or s (stress target), e.g. "seeeee"'); return
      end if
      do i = 1, ntens
        if (.not. is_set(target(i))) then
          call new_error(err, status_invalid, 'target', deck%path//': &'//grp//': target('// &
            int_text(i)//') is required (the end-of-leg '//merge('stress', 'strain', &
            scan(control(i:i), 'sS') > 0)//' of component '//int_text(i)//')'); return
        end if
      end do
      call check_finite(deck%path, grp, 'target', target, err)
      if (allocated(err)) return
      legs(n)%duration = duration
      legs(n)%n_inc = n_inc
      do i = 1, ntens
        legs(n)%stress_control(i) = scan(control(i:i), 'sS') > 0
      end do
      legs(n)%target = target
    end do
    deck%legs = legs(1:n)
  end subroutine read_legs

end module wellposed_point_deck
