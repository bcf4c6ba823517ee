!> bench_umat: CPU ns per UMAT call (NTENS 6), elastic, cone and apex, with
!> and without DDSDDE, as ratios to two lower bounds timed in the same run
!> (bench_elastic_trial, bench_reference); then the EFR against the cone, the
!> VUMAT per point of a block (blocks of 1 and 16 also against the checked
!> reference), the entry points' own share, a floating-point environment save
!> and a cone call's shares; the fastest of 30 rounds of every case. Usage:
!> bench_umat [calls per case and round] (default 20,000; a small number under
!> callgrind). Method: docs/guide/performance.md.
program bench_umat
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use bench_args, only: int_arg, most_args
  use wellposed_umat_interface, only: umat
  use wellposed_vumat_interface, only: vumat
  use wellposed_dp_params, only: dp_params_t, fill_dp_params
  use wellposed_dp_point, only: point_closed_form
  use wellposed_umat_adapter, only: umat_update
  use wellposed_vumat_adapter, only: vumat_update
  use wellposed_error, only: error_t
  implicit none
  ! The same source builds bench_umat (the static library, the host's usual
  ! link) and bench_umat_shared (libwellposed.so): the header says which.
#ifdef BENCH_UMAT_SHARED
  character(len=*), parameter :: bench_name = 'bench_umat_shared', &
    linked = 'libwellposed.so (a host linked with -lwellposed, shared)'
#else
  character(len=*), parameter :: bench_name = 'bench_umat', &
    linked = 'libwellposed.a (linked statically, without LTO into the bench)'
#endif
  interface
    subroutine bench_elastic_trial(stress, statev, ddsdde, dstran, nstatv)
      import :: dp
      integer, intent(in) :: nstatv
      real(dp), intent(inout) :: stress(6), statev(nstatv)
      real(dp), intent(in) :: ddsdde(6, 6), dstran(6)
    end subroutine bench_elastic_trial
    subroutine bench_reference(stress, statev, ddsdde, dstran, props, tangent)
      import :: dp
      real(dp), intent(inout) :: stress(6), statev(12), ddsdde(6, 6)
      real(dp), intent(in) :: dstran(6), props(5)
      logical, intent(in) :: tangent
    end subroutine bench_reference
    subroutine bench_reference_checked(stress, statev, ddsdde, stran, dstran, dtime, props, &
                                       nprops)
      import :: dp
      integer, intent(in) :: nprops
      real(dp), intent(inout) :: stress(6), statev(12), ddsdde(6, 6)
      real(dp), intent(in) :: stran(6), dstran(6), dtime, props(nprops)
    end subroutine bench_reference_checked
    subroutine bench_fp_env_saved(x)
      import :: dp
      real(dp), intent(inout) :: x
    end subroutine bench_fp_env_saved
    subroutine bench_fp_env_plain(x)
      import :: dp
      real(dp), intent(inout) :: x
    end subroutine bench_fp_env_plain
  end interface
  integer, parameter :: nrounds = 30
  !> Points per VUMAT call timed (Abaqus/Explicit's usual block is 136 at
  !> most; an MPM host may pass more).
  integer, parameter :: nblocks(4) = [1, 16, 128, 1024]
  character(len=*), parameter :: vnames(4) = ['elastic     ', 'plastic cone', 'apex        ', &
                                              'mixed       ']
  character(len=*), parameter :: names(3) = ['elastic     ', 'plastic cone', 'apex        ']
  character(len=34), parameter :: efr_names(3) = [character(len=34) :: 'regular flow rule', &
    'EFR P_v = 0.5 (the dissertation)', 'EFR P_d = 0.5 (the deviator turns)']
  real(dp) :: strains(6, 3), base_stress(6, 3), props(14)
  real(dp) :: t_trial, t_case(3, 2), t_ref(3, 2), t_efr(3, 2), t_check, t_kernel, sink
  real(dp) :: t_vumat(4, 4), t_mixed, t_entry(2, 2), t_env(2), t_checked(3, 2)
  integer :: ncalls, icase, itan, iround, i

  ncalls = 20000
  call most_args(bench_name, 1, bench_name//' [CALLS]')
  if (command_argument_count() >= 1) ncalls = int_arg(bench_name, 1, 'CALLS', 1, 10**8)
  ! Elastic: a small increment inside the cone; cone: extension from the
  ! case-study state (fig. 2.2); apex: strong hydrostatic tension from zero.
  base_stress(:, 1) = [-100.0e6_dp, -30.0e6_dp, -30.0e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  strains(:, 1) = [1.0e-6_dp, 0.0_dp, 0.0_dp, 1.0e-7_dp, 0.0_dp, 0.0_dp]
  base_stress(:, 2) = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  strains(:, 2) = [1.0e-4_dp, -2.0e-5_dp, 3.0e-5_dp, 4.0e-5_dp, -1.0e-5_dp, 2.0e-5_dp]
  base_stress(:, 3) = 0.0_dp
  strains(:, 3) = [3.0e-3_dp, 2.0e-3_dp, 2.5e-3_dp, 1.0e-4_dp, -2.0e-4_dp, 3.0e-4_dp]
  props = 0.0_dp
  props(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
  sink = 0.0_dp
  call check_reference()
  t_trial = huge(1.0_dp); t_case = huge(1.0_dp); t_ref = huge(1.0_dp); t_efr = huge(1.0_dp)
  t_check = huge(1.0_dp); t_kernel = huge(1.0_dp); t_vumat = huge(1.0_dp)
  t_entry = huge(1.0_dp); t_env = huge(1.0_dp); t_checked = huge(1.0_dp)
  do iround = 1, nrounds
    t_trial = min(t_trial, time_trial(base_stress(:, 2), strains(:, 2)))
    do itan = 1, 2
      do icase = 1, 3
        t_case(icase, itan) = min(t_case(icase, itan), time_umat(props, base_stress(:, icase), &
          strains(:, icase), icase - 1, itan == 2, ncalls))
        t_ref(icase, itan) = min(t_ref(icase, itan), time_reference(base_stress(:, icase), &
          strains(:, icase), itan == 1))
        t_checked(icase, itan) = min(t_checked(icase, itan), &
          time_reference(base_stress(:, icase), strains(:, icase), itan == 1, checked=.true.))
      end do
      do i = 1, 3
        t_efr(i, itan) = min(t_efr(i, itan), time_umat(efr_props(i), base_stress(:, 2), &
                             strains(:, 2), 1, itan == 2, max(1, ncalls/20)))
      end do
    end do
    do icase = 1, 4
      do i = 1, 4
        t_vumat(icase, i) = min(t_vumat(icase, i), time_vumat(nblocks(i), icase))
      end do
    end do
    do i = 1, 2
      t_entry(1, i) = min(t_entry(1, i), time_umat(props, base_stress(:, 1), strains(:, 1), 0, &
                          .false., ncalls, i == 2))
      t_entry(2, i) = min(t_entry(2, i), time_vumat(1, 1, i == 2))
      t_env(i) = min(t_env(i), time_env(i == 1))
    end do
    t_check = min(t_check, time_check())
    t_kernel = min(t_kernel, time_kernel(base_stress(:, 2), strains(:, 2)))
  end do

  write (output_unit, '(a,i0,a,i0,a)') bench_name//': ', ncalls, ' calls per case and round, ', &
    nrounds, ' rounds (fastest kept), NTENS = 6'
  write (output_unit, '(a)') '  the umat of '//linked
  write (output_unit, '(a,f7.1,a)') '  elastic trial alone (lower bound):  ', t_trial, ' ns'
  write (output_unit, '(a)') '  case          DDSDDE  ref ns  umat ns  /trial  /ref  |'// &
    '  explicit  ref ns  umat ns  /trial  /ref'
  do icase = 1, 3
    write (output_unit, '(2x,a12,2(6x,2f8.1,f8.2,f6.2,3x))') names(icase), &
      (t_ref(icase, itan), t_case(icase, itan), t_case(icase, itan)/t_trial, &
       t_case(icase, itan)/t_ref(icase, itan), itan = 1, 2)
  end do
  write (output_unit, '(a)') '  targets /trial: elastic 2.5 / 2, cone 4 / 3, apex 5 / 4; /ref 1.3'
  write (output_unit, '(a)') '  the reference behind the contract''s input checks (layout, PROPS,'// &
    ' DTIME, finiteness; bench_reference_checked): DDSDDE ns, /ref | explicit ns, /ref'
  do icase = 1, 3
    write (output_unit, '(2x,a12,2(f12.1,f7.2,3x))') names(icase), &
      (t_checked(icase, itan), t_checked(icase, itan)/t_ref(icase, itan), itan = 1, 2)
  end do
  write (output_unit, '(a)') '  (ref: the minimal closed-form return of bench_reference.f90, no'// &
    ' checks, no conversions)'
  ! The mixed block's UMAT equivalent: the same mix of explicit calls.
  t_mixed = (15*0.5_dp*(t_case(1, 2) + t_case(2, 2)) + t_case(3, 2))/16
  write (output_unit, '(a)') '  VUMAT: ns per point, and /UMAT explicit call of the same '// &
    'points, by points per block'
  write (output_unit, '(4x,a12,4(i9,a7))') 'block', (nblocks(i), '  /UMAT', i = 1, 4)
  do icase = 1, 4
    write (output_unit, '(4x,a12,4(f9.1,f7.2))') vnames(icase), (t_vumat(icase, i), &
      t_vumat(icase, i)/merge(t_mixed, t_case(min(icase, 3), 2), icase == 4), i = 1, 4)
  end do
  write (output_unit, '(a)') '    (mixed: elastic and cone points in turn, every 16th an apex '// &
    'point.) Where a point goes: elastic and cone points are one vectorised pass; the apex '// &
    'points of a chunk of 64 are gathered into a list and take the apex return in a second '// &
    'vectorised pass (Duvaut-Lions relaxes both in a scalar pass); a block of 1 to 3 points '// &
    'goes point by point (point_update) and pays the per-block PROPS and finiteness checks alone'
  write (output_unit, '(a)') '  VUMAT per point against the reference behind the checks '// &
    '(explicit): blocks of 1 and 16, target <= 1.3'
  do icase = 1, 3
    write (output_unit, '(4x,a12,2(i6,a,f7.2))') vnames(icase), (nblocks(i), ': ', &
      t_vumat(icase, i)/t_checked(icase, 2), i = 1, 2)
  end do
  write (output_unit, '(a)') '  the entry points'' own share (elastic; umat with DDSDDE, vumat'// &
    ' on a block of 1): ns of the entry, of the adapter it forwards to, share'
  write (output_unit, '(4x,a,2f8.1,f7.1,a)') 'umat  / umat_update   ', t_entry(1, 1), &
    t_entry(1, 2), 100*(t_entry(1, 1) - t_entry(1, 2))/t_entry(1, 1), ' %'
  write (output_unit, '(4x,a,2f8.1,f7.1,a)') 'vumat / vumat_update  ', t_entry(2, 1), &
    t_entry(2, 2), 100*(t_entry(2, 1) - t_entry(2, 2))/t_entry(2, 1), ' %'
  write (output_unit, '(4x,a,f7.1,a,f7.2,a)') 'a floating-point environment save and restore'// &
    ' costs', t_env(1) - t_env(2), ' ns here (', (t_env(1) - t_env(2))/t_entry(1, 1), &
    ' x the umat call): an entry that paid it would show that share'
  write (output_unit, '(a)') '  extended flow rule (beta_p = beta), cone case:'// &
    ' DDSDDE ns  /regular  explicit ns  /regular'
  do i = 1, 3
    write (output_unit, '(4x,a34,2(f10.1,f9.2,3x))') efr_names(i), &
      (t_efr(i, itan), t_efr(i, itan)/t_efr(1, itan), itan = 1, 2)
  end do
  write (output_unit, '(a)') '  target: an EFR call <= 3x the regular cone call. Where an EFR'// &
    ' call goes: a scalar Newton on t = dlambda/||M|| (2 evaluations for P_v, 3 for P_d),'// &
    ' the Jacobian factored once and the tangent as outer products (DDSDDE), the Mandel'// &
    ' conversions of point_update'
  write (output_unit, '(a)') '  where a cone call with DDSDDE goes:'
  write (output_unit, '(a,f7.1,a,f5.1,a)') '    PROPS validation (fill_dp_params)  ', t_check, &
    ' ns ', 100*t_check/t_case(2, 1), ' %'
  write (output_unit, '(a,f7.1,a,f5.1,a)') '    closed-form return and tangent     ', t_kernel, &
    ' ns ', 100*t_kernel/t_case(2, 1), ' %'
  write (output_unit, '(a,f7.1,a,f5.1,a)') '    the rest (layout and finiteness    ', &
    t_case(2, 1) - t_check - t_kernel, ' ns ', 100*(t_case(2, 1) - t_check - t_kernel)/ &
    t_case(2, 1), ' %'
  write (output_unit, '(a)') '     checks, Abaqus packing, energies, the call of 37 arguments)'
  if (sink == 1.2345_dp) write (output_unit, '(a)') 'checksum hit'

contains

  !> The case-study props with beta_p = beta: 1 regular flow rule, 2 EFR
  !> P_v = 0.5 (the dissertation's case: the first Newton step is exact),
  !> 3 EFR P_d = 0.5 (the deviator turns: a scalar Newton iteration).
  function efr_props(k) result(pr)
    integer, intent(in) :: k
    real(dp) :: pr(14)
    pr = props
    pr(4) = props(3)
    if (k == 2) pr(9) = 0.5_dp
    if (k == 3) pr(10) = 0.5_dp
  end function efr_props

  !> The reference must answer as the UMAT does (else it bounds nothing).
  subroutine check_reference()
    real(dp) :: s_u(6), sv_u(12), s_r(6), sv_r(12), dd_u(6, 6), dd_r(6, 6)
    integer :: ic
    do ic = 1, 3
      s_u = base_stress(:, ic); sv_u = 0.0_dp
      call one_umat(props, s_u, sv_u, dd_u, strains(:, ic))
      s_r = base_stress(:, ic); sv_r = 0.0_dp
      call bench_reference(s_r, sv_r, dd_r, strains(:, ic), props(1:5), .true.)
      if (maxval(abs(s_u - s_r)) > 1.0e-12_dp*maxval(abs(s_u)) .or. &
          maxval(abs(dd_u - dd_r)) > 1.0e-12_dp*maxval(abs(dd_u)) + tiny(1.0_dp) .or. &
          abs(sv_u(1) - sv_r(1)) > 1.0e-12_dp*abs(sv_u(1))) &
        error stop 'bench_umat: the reference does not answer as the UMAT'
    end do
  end subroutine check_reference

  subroutine one_umat(pr, stress, statev, ddsdde, de)
    real(dp), intent(in) :: pr(14), de(6)
    real(dp), intent(inout) :: stress(6), statev(12), ddsdde(6, 6)
    real(dp) :: sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt, stran(6), time(2)
    real(dp) :: predef(1), coords(3), drot(3, 3), f(3, 3), pnewdt
    character(len=80) :: cmname
    sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; stran = 0
    time = 0; predef = 0; coords = 0; drot = 0; f = 0; cmname = 'BENCH'; pnewdt = 1
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, de, &
              time, 1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, pr, 14, &
              coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, 1)
  end subroutine one_umat

  !> ns per call of umat for one case, resetting stress and state each call;
  !> with `direct`, of umat_update, the adapter procedure umat forwards to.
  function time_umat(pr, s0, de, status, explicit, n, direct) result(ns)
    real(dp), intent(in) :: pr(14), s0(6), de(6)
    integer, intent(in) :: status, n
    logical, intent(in) :: explicit
    logical, intent(in), optional :: direct
    real(dp) :: ns
    type(error_t), allocatable :: err
    real(dp) :: p(14), stress(6), statev(12), ddsdde(6, 6), sse, spd, scd, rpl, ddsddt(6)
    real(dp) :: drplde(6), drpldt, stran(6), time(2), predef(1), coords(3), drot(3, 3), f(3, 3)
    real(dp) :: pnewdt
    character(len=80) :: cmname
    real(dp) :: t0, t1
    integer :: i
    p = pr
    p(14) = merge(1.0_dp, 0.0_dp, explicit)
    sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; stran = 0
    time = 0; predef = 0; coords = 0; drot = 0; f = 0; cmname = 'BENCH'; ddsdde = 0
    stress = s0; statev = 0; pnewdt = 1
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, de, &
              time, 1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, p, 14, &
              coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, 1)
    if (nint(statev(12)) /= status) error stop 'bench_umat: a case is not in its regime'
    call cpu_time(t0)
    if (is_on(direct)) then
      do i = 1, n
        stress = s0; statev = 0.0_dp
        call umat_update(stress, statev, ddsdde, sse, spd, de, stran, 1.0e-3_dp, 3, 3, 6, 12, p, &
                         14, pnewdt, err)
        sink = sink + stress(1)
      end do
    else
      do i = 1, n
        stress = s0; statev = 0.0_dp
        call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
                  de, time, 1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, 12, p, &
                  14, coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, 1)
        sink = sink + stress(1)
      end do
    end if
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/n
  end function time_umat

  !> ns per point of the external vumat on blocks of nb points (VUMAT order
  !> 11, 22, 33, 12, 23, 31, tensor shears), old arrays read and new arrays
  !> written as by Abaqus/Explicit. Case 1-3: nb copies of the elastic, cone
  !> or apex point; 4 (mixed): elastic and cone points in turn, every
  !> sixteenth an apex point. With `direct`, of vumat_update, the adapter
  !> procedure vumat forwards to.
  function time_vumat(nb, icase, direct) result(ns)
    integer, intent(in) :: nb, icase
    logical, intent(in), optional :: direct
    real(dp) :: ns
    type(error_t), allocatable :: err
    integer :: point
    real(dp), allocatable :: coord(:, :), clen(:), rho(:), dstr(:, :), spin(:, :), temp(:)
    real(dp), allocatable :: stretch(:, :), fgrad(:, :), field(:, :), s_old(:, :), sv_old(:, :)
    real(dp), allocatable :: e_old(:), s_new(:, :), sv_new(:, :), e_new(:), e2_new(:)
    real(dp) :: t0, t1
    character(len=80) :: cmname
    integer :: i, k, n, kc
    allocate (coord(nb, 3), clen(nb), rho(nb), dstr(nb, 6), spin(nb, 3), temp(nb), &
              stretch(nb, 6), fgrad(nb, 9), field(nb, 1), s_old(nb, 6), sv_old(nb, 12), &
              e_old(nb), s_new(nb, 6), sv_new(nb, 12), e_new(nb), e2_new(nb))
    coord = 0; clen = 1; rho = 2500; spin = 0; temp = 0; stretch = 0; fgrad = 0; field = 0
    sv_old = 0; e_old = 0; s_new = 0; sv_new = 0; cmname = 'BENCH'
    do k = 1, nb
      kc = icase
      if (icase == 4) kc = merge(3, 1 + mod(k, 2), mod(k, 16) == 0)
      s_old(k, :) = base_stress([1, 2, 3, 4, 6, 5], kc)
      dstr(k, :) = [strains(1:3, kc), 0.5_dp*strains([4, 6, 5], kc)]
    end do
    n = max(1, ncalls/nb)
    call cpu_time(t0)
    if (is_on(direct)) then
      do i = 1, n
        call vumat_update(nb, 3, 3, 12, 14, 1.0_dp, 1.0_dp, 1.0e-3_dp, props, rho, dstr, s_old, &
                          sv_old, e_old, e_old, s_new, sv_new, e_new, e2_new, err, point)
        sink = sink + s_new(1, 1)
      end do
    else
      do i = 1, n
        call vumat(nb, 3, 3, 12, 0, 14, 0, 1.0_dp, 1.0_dp, 1.0e-3_dp, cmname, coord, clen, &
                   props, rho, dstr, spin, temp, stretch, fgrad, field, s_old, sv_old, e_old, &
                   e_old, temp, stretch, fgrad, field, s_new, sv_new, e_new, e2_new)
        sink = sink + s_new(1, 1)
      end do
    end if
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/(real(n, dp)*nb)
  end function time_vumat

  !> True when the optional `flag` is present and true.
  pure logical function is_on(flag)
    logical, intent(in), optional :: flag
    is_on = .false.
    if (present(flag)) is_on = flag
  end function is_on

  !> ns per call of a procedure that only adds 1, with (`saved`) or without
  !> the floating-point environment's save and restore (bench_fp_env.f90).
  function time_env(saved) result(ns)
    logical, intent(in) :: saved
    real(dp) :: ns, x, t0, t1
    integer :: i
    x = 0.0_dp
    call cpu_time(t0)
    if (saved) then
      do i = 1, ncalls
        call bench_fp_env_saved(x)
      end do
    else
      do i = 1, ncalls
        call bench_fp_env_plain(x)
      end do
    end if
    call cpu_time(t1)
    sink = sink + x
    ns = (t1 - t0)*1.0e9_dp/ncalls
  end function time_env

  !> ns per call of the minimal reference, with the same resets; with
  !> `checked`, of the reference behind the contract's input checks.
  function time_reference(s0, de, tangent, checked) result(ns)
    real(dp), intent(in) :: s0(6), de(6)
    logical, intent(in) :: tangent
    logical, intent(in), optional :: checked
    real(dp) :: ns, stress(6), statev(12), ddsdde(6, 6), p(14), stran(6)
    real(dp) :: t0, t1
    integer :: i, n
    ddsdde = 0.0_dp
    n = ncalls
    p = props
    p(14) = merge(0.0_dp, 1.0_dp, tangent)
    stran = 0.0_dp
    call cpu_time(t0)
    if (is_on(checked)) then
      do i = 1, n
        stress = s0; statev = 0.0_dp
        call bench_reference_checked(stress, statev, ddsdde, stran, de, 1.0e-3_dp, p, 14)
        sink = sink + stress(1)
      end do
    else
      do i = 1, n
        stress = s0; statev = 0.0_dp
        call bench_reference(stress, statev, ddsdde, de, props(1:5), tangent)
        sink = sink + stress(1)
      end do
    end if
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/n
  end function time_reference

  !> ns per elastic trial stress, with the same resets.
  function time_trial(s0, de) result(ns)
    real(dp), intent(in) :: s0(6), de(6)
    real(dp) :: ns, stress(6), statev(12), c(6, 6)
    real(dp) :: t0, t1
    integer :: i, n
    c = 0.0_dp
    c(1:3, 1:3) = 4.0e9_dp - 1.0e9_dp
    do i = 1, 3
      c(i, i) = 4.0e9_dp + 2.0e9_dp
      c(i + 3, i + 3) = 1.5e9_dp
    end do
    n = ncalls
    call cpu_time(t0)
    do i = 1, n
      stress = s0; statev = 0.0_dp
      call bench_elastic_trial(stress, statev, c, de, 12)
      sink = sink + stress(1)
    end do
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/n
  end function time_trial

  !> ns per validation of the 13 parameters (the PROPS share of a call).
  function time_check() result(ns)
    real(dp) :: ns, v(13)
    type(dp_params_t) :: p
    real(dp) :: t0, t1
    integer :: i, fault, n
    v = props(1:13)
    n = ncalls
    call cpu_time(t0)
    do i = 1, n
      v(13) = sink*1.0e-300_dp
      call fill_dp_params(p, v, fault)
      sink = sink + p%a_m + fault
    end do
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/n
  end function time_check

  !> ns per closed-form cone return with tangent (the model's share).
  function time_kernel(s0, de) result(ns)
    real(dp), intent(in) :: s0(6), de(6)
    real(dp) :: ns, sig(6), eps_p(6), z, zeta, dlambda, f, t(6, 6), det(6)
    type(dp_params_t) :: p
    real(dp) :: t0, t1
    integer :: i, status, fault, n
    call fill_dp_params(p, props(1:13), fault)
    det = de
    det(4:6) = 0.5_dp*de(4:6)
    n = ncalls
    call cpu_time(t0)
    do i = 1, n
      sig = s0; eps_p = 0.0_dp; z = 0.0_dp; zeta = 0.0_dp
      call point_closed_form(p, sig, eps_p, z, zeta, 0.0_dp, det, 1.0e-3_dp, dlambda, f, &
                             status, 6, t)
      sink = sink + sig(1) + t(1, 1)
    end do
    call cpu_time(t1)
    ns = (t1 - t0)*1.0e9_dp/n
  end function time_kernel

end program bench_umat
