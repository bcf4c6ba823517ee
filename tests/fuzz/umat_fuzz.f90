!> Fuzz of the UMAT and VUMAT contract (docs/guide/umat.md): groups of points of
!> one random material (fuzz_inputs) run chains of increments through
!> umat_update point by point and vumat_update as one block, with faults
!> injected into one input now and then. Checked on every call: a success
!> status comes with finite STRESS, STATEV, DDSDDE, SSE and SPD; a refusal
!> leaves STRESS and STATEV bit for bit; a NaN or Inf input is refused; an
!> elastic step leaves z and eps^p bit for bit; the VUMAT agrees bitwise.
!> Usage: umat_fuzz [calls [seed]]; exit status 1 on any violation.
program umat_fuzz
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use, intrinsic :: ieee_exceptions, only: ieee_set_halting_mode, ieee_set_flag, ieee_all
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text
  use wellposed_umat_adapter, only: umat_update
  use wellposed_vumat_adapter, only: vumat_update
  use fuzz_inputs, only: material_t, fault_t, new_material, new_state, new_increment, &
                         new_fault, chance, pick, nfault_targets, target_names
  implicit none

  integer, parameter :: maxblock = 9, maxsv = 21
  !> VUMAT component of UMAT component i (UMAT 11, 22, 33, 12, 13, 23).
  integer, parameter :: vcomp(6) = [1, 2, 3, 4, 6, 5]
  integer, parameter :: max_examples = 3
  ! Counters: calls and outcomes, then the violations.
  integer(int64) :: budget = 200000, ncalls = 0, nseq = 0, nblocks = 0, nvpoints = 0
  integer(int64) :: nrefused(-2:-1) = 0, nsuccess(0:2) = 0, nfaults(nfault_targets) = 0
  integer(int64) :: bad_finite(3) = 0, bad_vfinite = 0, bad_changed = 0, bad_nan = 0
  integer(int64) :: bad_elastic = 0, bad_energy = 0, bad_agree = 0, bad_vrefusal = 0
  integer(int64) :: bad_status = 0, bad_bound = 0, n_status_differ = 0, n_bits_differ = 0
  integer :: seed = 20261201, nexamples(8) = 0, ios, nargs, nb, nsteps, step, k, nt, nsv
  character(len=32) :: arg
  type(material_t) :: m
  type(fault_t) :: fault
  real(dp) :: props(15), dtime
  real(dp), dimension(6, maxblock) :: stress, s_in, s_out, de, last, stran
  real(dp), dimension(maxsv, maxblock) :: statev, sv_in, sv_out
  real(dp), dimension(maxblock) :: spd, cut
  integer :: status(maxblock)
  logical :: ext_state(maxblock), ext_inc(maxblock), gdl

  call ieee_set_halting_mode(ieee_all, .false.)
  nargs = command_argument_count()
  if (nargs >= 1) then
    call get_command_argument(1, arg)
    read (arg, *, iostat=ios) budget
    if (ios /= 0 .or. budget < 1) call usage()
  end if
  if (nargs >= 2) then
    call get_command_argument(2, arg)
    read (arg, *, iostat=ios) seed
    if (ios /= 0) call usage()
  end if
  call seed_generator(seed)

  do while (ncalls < budget)
    call new_material(m)
    nt = m%ntens
    nsv = m%nstatv
    nb = pick(1, maxblock)
    nsteps = pick(1, 30)
    nseq = nseq + nb
    do k = 1, nb
      call new_state(m, stress(1:nt, k), statev(1:nsv, k), ext_state(k))
      last(:, k) = 0.0_dp
      last(1, k) = 1.0_dp
      spd(k) = 0.0_dp
      cut(k) = 1.0_dp
    end do
    do step = 1, nsteps
      props = m%props
      dtime = m%dtime
      fault%target = 0
      if (chance(0.1_dp)) call new_fault(m, nb, fault)
      if (fault%target > 0) nfaults(fault%target) = nfaults(fault%target) + 1
      if (fault%target == 5) props(fault%slot) = fault%value
      if (fault%target == 6) dtime = fault%value
      gdl = props(15) == 1.0_dp
      do k = 1, nb
        call new_increment(m, last(:, k), de(1:nt, k), ext_inc(k))
        de(1:nt, k) = cut(k)*de(1:nt, k)
        s_in(1:nt, k) = stress(1:nt, k)
        sv_in(1:nsv, k) = statev(1:nsv, k)
        stran(1:nt, k) = 0.0_dp
        if (fault%point == k) then
          select case (fault%target)
          case (1); s_in(fault%slot, k) = fault%value
          case (2); de(fault%slot, k) = fault%value
          case (3); sv_in(fault%slot, k) = fault%value
          case (4); stran(fault%slot, k) = fault%value
          end select
        end if
        call umat_point(k)
      end do
      if (fault%target /= 4) call vumat_block()
      do k = 1, nb
        if (status(k) >= 0) then
          stress(1:nt, k) = s_out(1:nt, k)
          statev(1:nsv, k) = sv_out(1:nsv, k)
          cut(k) = 1.0_dp
        else if (status(k) == -2) then
          cut(k) = max(0.25_dp*cut(k), 1.0e-6_dp)
        end if
      end do
    end do
  end do

  call report()
  ! The flags the faults raised, cleared: the program's end restores the
  ! trapping of a Debug build, which would otherwise fire on them.
  call ieee_set_flag(ieee_all, .false.)
  if (bad_finite(1) + bad_finite(2) + bad_finite(3) + bad_vfinite + bad_changed + bad_nan + &
      bad_elastic + bad_energy + bad_agree + bad_vrefusal + bad_status + bad_bound > 0) &
    error stop 1

contains

  subroutine usage()
    write (output_unit, '(a)') 'usage: umat_fuzz [calls [seed]] (default 200000 calls, '// &
      'seed 20261201)'
    stop 1
  end subroutine usage

  !> The generator's seed from one integer.
  subroutine seed_generator(s)
    integer, intent(in) :: s
    integer :: n, i
    integer, allocatable :: put(:)
    call random_seed(size=n)
    allocate (put(n))
    do i = 1, n
      put(i) = s + 7919*i
    end do
    call random_seed(put=put)
  end subroutine seed_generator

  !> Bitwise equality (NaN equal to the same NaN).
  elemental logical function same(a, b)
    real(dp), intent(in) :: a, b
    same = transfer(a, 0_int64) == transfer(b, 0_int64)
  end function same

  !> One UMAT call for point k of the group, and its checks.
  subroutine umat_point(k)
    integer, intent(in) :: k
    real(dp) :: s(nt), sv(nsv), dd(nt, nt), sse, pnewdt, spd_in
    type(error_t), allocatable :: err
    integer :: nread, cls
    logical :: faulted, nan_in, ok
    s = s_in(1:nt, k)
    sv = sv_in(1:nsv, k)
    dd = 0.0_dp
    sse = 0.0_dp
    spd_in = spd(k)
    pnewdt = 1.0_dp
    call umat_update(s, sv, dd, sse, spd(k), de(1:nt, k), stran(1:nt, k), dtime, 3, nt - 3, &
                     nt, nsv, props, 15, pnewdt, err)
    ncalls = ncalls + 1
    nread = merge(19, 12, gdl)
    faulted = fault%target >= 5 .or. (fault%target > 0 .and. fault%point == k)
    nan_in = faulted .and. fault%nonfinite
    if (nan_in .and. fault%target == 3) nan_in = fault%slot <= nread
    s_out(1:nt, k) = s
    sv_out(1:nsv, k) = sv
    if (allocated(err)) then
      status(k) = err%status
      nrefused(err%status) = nrefused(err%status) + 1
      ok = all(same(s, s_in(1:nt, k))) .and. all(same(sv(1:11), sv_in(1:11, k))) .and. &
           all(same(sv(13:nsv), sv_in(13:nsv, k))) .and. same(spd(k), spd_in)
      if (.not. ok) bad_changed = bad_changed + 1
      if (sv(12) /= real(err%status, dp)) bad_status = bad_status + 1
      if (pnewdt /= merge(-1.0_dp, 0.5_dp, err%status == -1)) bad_status = bad_status + 1
      spd(k) = spd_in
      return
    end if
    status(k) = nint(sv(12))
    if (status(k) < 0 .or. status(k) > 2 .or. pnewdt /= 1.0_dp) then
      bad_status = bad_status + 1
      status(k) = max(0, min(2, status(k)))
    end if
    nsuccess(status(k)) = nsuccess(status(k)) + 1
    if (nan_in) bad_nan = bad_nan + 1
    ok = all(ieee_is_finite(s)) .and. all(ieee_is_finite(sv(1:nread))) .and. &
         all(ieee_is_finite(dd)) .and. ieee_is_finite(sse) .and. ieee_is_finite(spd(k))
    if (.not. ok) then
      cls = 1
      if (m%extreme .or. ext_state(k) .or. ext_inc(k)) cls = 2
      if (faulted) cls = 3
      bad_finite(cls) = bad_finite(cls) + 1
      call example('non-finite UMAT answer with status '//int_text(status(k)), k, cls)
    end if
    if (ok .and. .not. (m%extreme .or. ext_state(k) .or. ext_inc(k) .or. faulted)) then
      if (.not. bounded(s, k)) then
        bad_bound = bad_bound + 1
        call example('answer far beyond the trial stress and the strength', k, 7)
      end if
    end if
    ! A state reached from extreme or faulty inputs stays extreme.
    ext_state(k) = ext_state(k) .or. ext_inc(k) .or. faulted
    if (status(k) == 0 .and. .not. gdl) then
      if (.not. (same(sv(1), sv_in(1, k)) .and. all(same(sv(5:10), sv_in(5:10, k))))) then
        bad_elastic = bad_elastic + 1
        call example('elastic step changed z or eps^p', k, 3)
      end if
    end if
  end subroutine umat_point

  !> False when the answer of point k is far beyond any stress the return
  !> can reach from the trial: the trial's size, the strength, and the
  !> largest shift of I1 along a nonassociative or extended direction.
  logical function bounded(s, k)
    real(dp), intent(in) :: s(:)
    integer, intent(in) :: k
    real(dp) :: scale, factor
    scale = maxval(abs(s_in(1:nt, k))) + (3.0_dp*props(1) + 4.0_dp*props(2))* &
            maxval(abs(de(1:nt, k))) + props(5) + abs(props(6))*sv_in(1, k) + &
            abs(sv_in(4, k)) + abs(props(12)*sv_in(3, k)) + abs(props(7)) + &
            abs(props(6))*sv_out(1, k)
    if (gdl) scale = scale + maxval(abs(sv_in(13:18, k))) - abs(props(6))*sv_in(19, k)
    ! the apex I1 = k/beta of a strength softened below zero
    if (props(3) > 0.0_dp) scale = scale + scale/props(3)
    factor = 100.0_dp*(1.0_dp + props(1)/props(2))*(1.0_dp + abs(props(4)) + abs(props(9)) + &
             abs(props(10)))
    bounded = maxval(abs(s)) <= factor*scale
  end function bounded

  !> The group as one VUMAT block, against the UMAT's answers.
  subroutine vumat_block()
    real(dp) :: so(nb, nt), sn(nb, nt), dv(nb, nt), sto(nb, nsv), stn(nb, nsv), rho(nb)
    real(dp) :: ei0(nb), en0(nb), ei(nb), en(nb), expect(nsv)
    type(error_t), allocatable :: err
    integer :: kk, i, point
    logical :: refused
    do kk = 1, nb
      do i = 1, nt
        so(kk, vcomp(i)) = s_in(i, kk)
        dv(kk, vcomp(i)) = merge(0.5_dp, 1.0_dp, i >= 4)*de(i, kk)
      end do
      sto(kk, :) = to_vumat(sv_in(1:nsv, kk))
    end do
    sn = so
    stn = sto
    rho = 1.0_dp
    ei0 = 0.0_dp
    en0 = 0.0_dp
    ei = 0.0_dp
    en = 0.0_dp
    call vumat_update(nb, 3, nt - 3, nsv, 15, 1.0_dp, 1.0_dp, dtime, props, rho, dv, so, sto, &
                      ei0, en0, sn, stn, ei, en, err, point)
    nblocks = nblocks + 1
    nvpoints = nvpoints + nb
    refused = any(status(1:nb) < 0)
    if (allocated(err) .neqv. refused) then
      bad_vrefusal = bad_vrefusal + 1
      call example('VUMAT and UMAT differ on refusing', max(point, 1), 4)
    end if
    if (allocated(err) .or. refused) return
    do kk = 1, nb
      if (.not. (all(ieee_is_finite(sn(kk, :))) .and. all(ieee_is_finite(stn(kk, 1:12))) .and. &
                 ieee_is_finite(ei(kk)) .and. ieee_is_finite(en(kk)))) bad_vfinite = bad_vfinite + 1
      expect = to_vumat(sv_out(1:nsv, kk))
      do i = 1, nt
        if (.not. same(sn(kk, vcomp(i)), s_out(i, kk))) expect(1) = -huge(1.0_dp)
      end do
      ! The status alone may differ where a cone return ends exactly at the
      ! apex (the same stress and state): counted, not a violation.
      if (.not. same(stn(kk, 12), expect(12))) n_status_differ = n_status_differ + 1
      expect(12) = stn(kk, 12)
      if (.not. all(same(stn(kk, :), expect))) then
        n_bits_differ = n_bits_differ + 1
        ! Beyond rounding (1e-13 of each quantity): a violation.
        if (all(abs(stn(kk, :) - expect) <= 1.0e-13_dp*abs(expect))) cycle
        bad_agree = bad_agree + 1
        if (bad_agree <= 2) write (output_unit, '(a,6es25.17)') '  VUMAT stress ', sn(kk, :)
        if (bad_agree <= 2) write (output_unit, '(a,12es25.17)') '  VUMAT state ', stn(kk, 1:12)
        call example('VUMAT differs from the UMAT', kk, 5)
      end if
      if (status(kk) == 0 .and. .not. gdl .and. en(kk) /= 0.0_dp) then
        bad_energy = bad_energy + 1
        call example('VUMAT inelastic energy on an elastic step', kk, 8)
      end if
    end do
  end subroutine vumat_block

  !> STATEV in the VUMAT's layout: eps^p (and the overstress) in its order,
  !> tensor shears.
  pure function to_vumat(sv) result(v)
    real(dp), intent(in) :: sv(:)
    real(dp) :: v(size(sv))
    integer :: i
    v = sv
    do i = 1, 6
      v(4 + vcomp(i)) = merge(0.5_dp, 1.0_dp, i >= 4)*sv(4 + i)
      if (gdl .and. size(sv) >= 18) v(12 + vcomp(i)) = sv(12 + i)
    end do
  end function to_vumat

  !> One example of a violation of kind `kind` (a few of each): the
  !> material, the point's inputs, its answer.
  subroutine example(what, k, kind)
    character(len=*), intent(in) :: what
    integer, intent(in) :: k, kind
    if (nexamples(kind) >= max_examples) return
    nexamples(kind) = nexamples(kind) + 1
    write (output_unit, '(a)') 'umat_fuzz: '//what
    write (output_unit, '(a,i0,a,i0,a,es10.3,a,i0,a,i0)') '  NTENS ', nt, ', NSTATV ', nsv, &
      ', DTIME ', dtime, ', fault target ', fault%target, ' slot ', fault%slot
    write (output_unit, '(a,15es10.2)') '  PROPS ', props
    write (output_unit, '(a,6es11.3)') '  STRESS in ', s_in(1:nt, k)
    write (output_unit, '(a,6es11.3)') '  DSTRAN ', de(1:nt, k)
    write (output_unit, '(a,12es10.2)') '  STATEV in ', sv_in(1:12, k)
    if (nsv >= 19) write (output_unit, '(a,7es10.2)') '  STATEV 13-19 in ', sv_in(13:19, k)
    write (output_unit, '(a,6es11.3)') '  STRESS out ', s_out(1:nt, k)
    write (output_unit, '(a,12es10.2)') '  STATEV out ', sv_out(1:12, k)
  end subroutine example

  subroutine report()
    integer :: i
    write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') 'umat_fuzz: seed ', seed, ', ', ncalls, &
      ' UMAT calls in ', nseq, ' sequences; ', nvpoints, ' VUMAT points'
    write (output_unit, '(a,i0,a,i0,a)') '  VUMAT blocks ', nblocks, ', faults injected ', &
      sum(nfaults), ' (by target:'
    write (output_unit, '(6(2x,a,1x,i0))') (trim(target_names(i)), nfaults(i), i = 1, nfault_targets)
    write (output_unit, '(a,3(1x,i0),a,2(1x,i0))') '  answered (status 0, 1, 2):', nsuccess, &
      '; refused (status -1, -2):', nrefused(-1), nrefused(-2)
    write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') '  non-finite answer with a success status: ', &
      bad_finite(1), ' from ordinary inputs, ', bad_finite(2), ' from extreme magnitudes, ', &
      bad_finite(3), ' with an injected fault; VUMAT ', bad_vfinite, ' points'
    write (output_unit, '(a,i0,a,i0,a,i0)') '  refusals that changed STRESS/STATEV: ', &
      bad_changed, '; non-finite inputs answered: ', bad_nan, '; wrong status/PNEWDT: ', &
      bad_status
    write (output_unit, '(a,i0)') '  finite answers far beyond the trial and the strength: ', &
      bad_bound
    write (output_unit, '(a,i0,a,i0)') '  elastic steps that changed z or eps^p: ', bad_elastic, &
      '; VUMAT inelastic energy on an elastic step: ', bad_energy
    write (output_unit, '(a,i0,a,i0)') '  VUMAT points not bitwise the UMAT''s: ', n_bits_differ, &
      '; beyond 1e-13: ', bad_agree
    write (output_unit, '(a,i0,a,i0)') '  VUMAT points that differ from the UMAT: ', bad_agree, &
      '; blocks refused by one and not the other: ', bad_vrefusal
    write (output_unit, '(a,i0)') '  points where only the status differs (cone ending at the '// &
      'apex): ', n_status_differ
  end subroutine report

end program umat_fuzz
