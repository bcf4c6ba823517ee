!> Three kinds of host drive our UMAT through one element of 8 points in
!> uniaxial strain: abaqus (PNEWDT large on entry, cut back while < 1),
!> calculix (PNEWDT = -1 on entry, cut back only when > 0, as its
!> checkconvergence.c) and ours (wellposed_umat_host's host_update), each
!> at most 5 cut-backs. A valid material must finish with the same stress in
!> all three; invalid PROPS (k0 = 0), NSTATV = 0 and a NaN initial STATEV
!> must finish in none. Prints a table; exits 1 when a host finishes a bad
!> case (docs/guide/umat.md, "Status codes, errors and PNEWDT").
program host_semantics
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_update
  use wellposed_umat_interface, only: umat
  implicit none
  integer, parameter :: npt = 8, ninc = 10, max_cutbacks = 5
  character(len=8), parameter :: hosts(3) = [character(len=8) :: 'abaqus', 'calculix', 'ours']
  character(len=8), parameter :: cases(4) = [character(len=8) :: 'VALID', 'K0', 'NOSTATV', &
                                             'NAN']
  real(dp) :: props(5), final(6, 3)
  integer :: ih, ic, nstatv
  logical :: finished, failed

  failed = .false.
  write (*, '(a10,a10,a10,a16)') 'host', 'case', 'outcome', 'stress(1)'
  do ic = 1, size(cases)
    do ih = 1, size(hosts)
      props = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
      if (cases(ic) == 'K0') props(5) = 0.0_dp
      nstatv = merge(0, 12, cases(ic) == 'NOSTATV')
      call run(hosts(ih), cases(ic), props, nstatv, finished, final(:, ih))
      write (*, '(a10,a10,a10,es16.7)') trim(hosts(ih)), trim(cases(ic)), &
        merge('finished', 'stopped ', finished), final(1, ih)
      if (finished .neqv. cases(ic) == 'VALID') failed = .true.
    end do
    if (cases(ic) == 'VALID') then
      if (any(final(:, 1) /= final(:, 3)) .or. any(final(:, 2) /= final(:, 3))) then
        write (*, '(a)') 'the hosts disagree on the valid case'
        failed = .true.
      end if
    end if
  end do
  if (failed) error stop 1

contains

  !> Run one host on one case: `finished` when every increment was accepted;
  !> `stress` is point 1's stress at the end (or where the host stopped).
  subroutine run(host, label, props, nstatv, finished, stress)
    character(len=*), intent(in) :: host, label
    real(dp), intent(in), contiguous :: props(:)
    integer, intent(in) :: nstatv
    logical, intent(out) :: finished
    real(dp), intent(out) :: stress(6)
    real(dp) :: sig(6, npt), eps(6, npt), s0(6, npt)
    real(dp) :: sv(nstatv, npt), sv0(nstatv, npt)
    real(dp) :: dstran(6), pnewdt, pmin, step, t, dt
    type(umat_host_t) :: h
    type(error_t), allocatable :: err
    integer :: inc, p, cuts, nsub
    logical :: accepted

    sig = 0.0_dp; sv = 0.0_dp; eps = 0.0_dp
    if (label == 'NAN') sv(1, 1) = ieee_value(1.0_dp, ieee_quiet_nan)
    finished = .false.
    step = -1.0e-2_dp
    if (host == 'ours') then
      call new_umat_host(h, 6, nstatv, err, cmname=label, what='point')
      if (allocated(err)) error stop 'host_semantics: new_umat_host failed'
      h%dtime = 1.0_dp/ninc
      do inc = 1, ninc
        dstran = [step/ninc, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
        do p = 1, npt
          h%noel = 1; h%npt = p
          call host_update(h, props, sig(:, p), sv(:, p), eps(:, p), dstran, nsub, err)
          if (allocated(err)) then
            stress = sig(:, 1)
            return
          end if
        end do
      end do
    else
      t = 0.0_dp
      dt = 1.0_dp/ninc
      inc = 0
      do while (t < 1.0_dp - 1.0e-12_dp)
        cuts = 0
        s0 = sig; sv0 = sv
        attempt: do
          dstran = [step*dt, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
          accepted = .true.
          pnewdt = -1.0_dp
          pmin = 1.0e36_dp
          do p = 1, npt
            if (host == 'abaqus') pnewdt = 1.0e36_dp
            call call_umat(label, props, nstatv, sig(:, p), sv(:, p), eps(:, p), dstran, &
                           dt, pnewdt, p, inc + 1)
            pmin = min(pmin, pnewdt)
          end do
          if (host == 'abaqus' .and. pmin < 1.0_dp) accepted = .false.
          if (host == 'calculix' .and. pnewdt > 0.0_dp) accepted = .false.
          if (accepted) exit attempt
          sig = s0; sv = sv0
          cuts = cuts + 1
          if (cuts > max_cutbacks) then
            stress = sig(:, 1)
            return
          end if
          if (host == 'abaqus') then
            dt = dt*max(pmin, 0.25_dp)
          else
            dt = dt*pnewdt
          end if
        end do attempt
        do p = 1, npt
          eps(:, p) = eps(:, p) + dstran
        end do
        t = t + dt
        inc = inc + 1
        dt = min(1.0_dp/ninc, 1.0_dp - t)
      end do
    end if
    finished = .true.
    stress = sig(:, 1)
  end subroutine run

  !> One call of the external umat at point `p`.
  subroutine call_umat(label, props, nstatv, stress, statev, stran, dstran, dtime, pnewdt, p, &
                       kinc)
    character(len=*), intent(in) :: label
    real(dp), intent(in) :: props(:), stran(6), dstran(6), dtime
    integer, intent(in) :: nstatv, p, kinc
    real(dp), intent(inout) :: stress(6), statev(nstatv), pnewdt
    real(dp) :: ddsdde(6, 6), sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt, time(2)
    real(dp) :: predef(1), coords(3), drot(3, 3), f(3, 3)
    character(len=80) :: cmname
    sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; predef = 0
    coords = 0; drot = 0; f = 0; time = 0
    cmname = label
    call umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, &
              dstran, time, dtime, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, 3, 6, nstatv, &
              props, size(props), coords, drot, pnewdt, 1.0_dp, f, f, 1, p, 1, 1, 1, kinc)
  end subroutine call_umat

end program host_semantics
