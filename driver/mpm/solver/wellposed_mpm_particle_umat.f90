!> The stress update of one material point through the UMAT host, for
!> ndim = 1 and 2: the strain increment embedded in the UMAT's NTENS (6 for
!> the bar's uniaxial strain, 4 for plane strain, engineering shear) and
!> the call with the particle's identity, under the host's rules
!> (docs/guide/mpm.md, "Hosting a UMAT in the MPM"). Our own material also goes a
!> block at a time through the VUMAT's kernel (umat_block, bitwise the
!> UMAT's answer); what it defers, non-finite values and refused PROPS are
!> left to the per-particle call.
module wellposed_mpm_particle_umat
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_finite, only: nonfinite_bits
  use wellposed_error, only: error_t
  use wellposed_umat_host, only: umat_host_t, host_update
  use wellposed_umat_adapter, only: check_props
  use wellposed_umat_layout, only: sv_z, sv_dlambda, sv_avg_dlambda, sv_zeta, sv_eps_p, sv_f, &
                                   sv_status
  use wellposed_dp_params, only: dp_params_t
  use wellposed_dp_point, only: has_closed_form, point_update
  use wellposed_dp_block, only: closed_form_block, block_trial, block_return, elastic_answer, &
                               block_chunk
  implicit none
  private
  public :: strain_increment, umat_particle, umat_block, umat_point, point_params

contains

  !> The plane-strain increment of a step dt from the velocity gradient lg
  !> (2 x 2, lg(a, b) = d v_a / d x_b; eq. 4.11) in the UMAT's order: 11,
  !> 22, 33 = 0, 12 engineering (NTENS = 4). A bar's uniaxial increment is
  !> bar_kinematics' (wellposed_mpm_bar).
  pure subroutine strain_increment(lg, dt, de)
    real(dp), intent(in) :: lg(2, 2), dt
    real(dp), intent(out) :: de(4)
    ! element by element: no array constructor (a temporary) per particle
    de(1) = dt*lg(1, 1)
    de(2) = dt*lg(2, 2)
    de(3) = dt*0.0_dp
    de(4) = dt*(lg(1, 2) + lg(2, 1))
  end subroutine strain_increment

  !> One particle through the UMAT: s, sv, e (STRESS, STATEV, STRAN, in
  !> place) over the increment de, in the step from time t of length dt
  !> (KINC = kinc), NOEL = gid, COORDS = x. Algorithm 1's slots only for a
  !> UMAT that has them (the host knows): STATEV(3) = avg in, dlambda =
  !> STATEV(2) out (else 0). nsub: the host's cut-back split.
  subroutine umat_particle(host, props, t, dt, kinc, gid, x, s, sv, e, de, avg, dlambda, &
                           nsub, err)
    type(umat_host_t), intent(inout) :: host
    ! contiguous, as the host's: the particle's columns pass without a copy
    real(dp), intent(in), contiguous :: props(:), x(:), de(:)
    real(dp), intent(in) :: t, dt, avg
    integer, intent(in) :: kinc, gid
    real(dp), intent(inout), contiguous :: s(:), sv(:), e(:)
    real(dp), intent(out) :: dlambda
    integer, intent(out) :: nsub
    type(error_t), allocatable, intent(out) :: err
    if (host%ours) sv(3) = avg
    host%time = t
    host%dtime = dt
    host%kinc = kinc
    host%noel = gid
    host%coords = 0.0_dp
    host%coords(1:size(x)) = x
    call host_update(host, props, s, sv, e, de, nsub, err)
    dlambda = 0.0_dp
    if (allocated(err)) return
    if (host%ours) dlambda = sv(2)
  end subroutine umat_particle

  !> PROPS of one material checked as the UMAT checks them on every call
  !> (NTENS = ntens, NSTATV = nstatv, the step dt): ok and their parameters
  !> par for umat_point, which then skips the check (the generalized
  !> Duvaut-Lions model keeps its UMAT call).
  subroutine point_params(props, ntens, nstatv, dt, par, ok)
    real(dp), intent(in), contiguous :: props(:)
    integer, intent(in) :: ntens, nstatv
    real(dp), intent(in) :: dt
    type(dp_params_t), intent(inout) :: par
    logical, intent(out) :: ok
    logical :: want_tangent
    integer :: fault
    ok = .false.
    if (ntens /= 6 .and. ntens /= 4) return
    call check_props(3, ntens - 3, ntens, nstatv, size(props), props, dt, par, want_tangent, &
                     fault)
    ok = fault == 0 .and. .not. par%gdl
  end subroutine point_params

  !> One particle of our material through the model's point update: the
  !> UMAT's arithmetic and conversions without its call, for PROPS checked
  !> once (par, from check_props). s, sv, e (STRESS, STATEV, STRAN) in
  !> place over the increment de with STATEV(3) = avg. done when the UMAT
  !> would answer in one call (inputs and outputs finite, no error such as
  !> a cut-back request): the result is then bitwise that call's, dlambda =
  !> STATEV(2). Else nothing is touched and the host's call decides.
  subroutine umat_point(par, nt, dt, avg, s, sv, e, de, dlambda, done)
    type(dp_params_t), intent(in) :: par
    integer, intent(in) :: nt
    real(dp), intent(in) :: dt, avg
    real(dp), intent(inout), contiguous :: s(:), sv(:), e(:)
    real(dp), intent(in), contiguous :: de(:)
    real(dp), intent(out) :: dlambda
    logical, intent(out) :: done
    real(dp) :: sig(6), d6(6), ep(6), z, zeta, f, dl
    integer(int64) :: b
    integer :: status, j
    type(error_t), allocatable :: err
    done = .false.
    dlambda = 0.0_dp
    if (par%gdl .or. (nt /= 6 .and. nt /= 4) .or. size(sv) < sv_status) return
    ! what the UMAT and the host check: STATEV(3) is avg here
    b = ior(ior(nonfinite_bits(avg), nonfinite_run(nt, s)), &
            ior(nonfinite_run(nt, de), nonfinite_run(nt, e)))
    do j = 1, size(sv)
      if (j /= sv_avg_dlambda) b = ior(b, nonfinite_bits(sv(j)))
    end do
    if (b < 0) return
    sig = 0.0_dp
    d6 = 0.0_dp
    sig(1:nt) = s(1:nt)
    d6(1:nt) = de(1:nt)
    d6(4:6) = 0.5_dp*d6(4:6)
    ep(1:3) = sv(sv_eps_p:sv_eps_p + 2)
    ep(4:6) = 0.5_dp*sv(sv_eps_p + 3:sv_eps_p + 5)
    z = sv(sv_z)
    zeta = sv(sv_zeta)
    call point_update(par, sig, ep, z, zeta, avg, d6, dt, dl, f, status, nt, err=err)
    if (allocated(err)) return
    ep(4:6) = 2.0_dp*ep(4:6)
    b = ior(ior(nonfinite_run(nt, sig), nonfinite_run(6, ep)), &
            ior(ior(nonfinite_bits(z), nonfinite_bits(dl)), &
                ior(nonfinite_bits(zeta), nonfinite_bits(f))))
    if (b < 0) return
    s(1:nt) = sig(1:nt)
    sv(sv_avg_dlambda) = avg
    sv(sv_z) = z
    sv(sv_dlambda) = dl
    sv(sv_zeta) = zeta
    sv(sv_eps_p:sv_eps_p + 5) = ep
    sv(sv_f) = f
    sv(sv_status) = real(status, dp)
    e(1:nt) = e(1:nt) + de(1:nt)
    dlambda = dl
    done = .true.
  end subroutine umat_point

  !> Particles idx(:) of one material of ours through the block kernel, in
  !> place, with STATEV(3) = <dlambda> = avg(p) (0 when absent: the local
  !> update of Algorithm 1's step 1): stress, statev, stran (the particle
  !> arrays, NTENS x n, NSTATV x n) hold the start of the step and, for
  !> every particle so updated, its end, with dlambda; done(p) is set for
  !> those. A particle left (deferred, not finite) is not touched. The
  !> UMAT's conversions: engineering shears halved in the strains and
  !> doubled in the plastic strain (STATEV 8-10), as the UMAT does them
  !> (exact but for subnormal numbers, which round the same way). Nothing
  !> is done when PROPS are refused or the model has no closed form.
  subroutine umat_block(props, ntens, nstatv, dt, idx, de, stress, statev, stran, dlambda, &
                        done, avg, ndone)
    real(dp), intent(in), contiguous :: props(:)
    real(dp), intent(in) :: dt
    integer, intent(in) :: ntens, nstatv, idx(:)
    real(dp), intent(in), contiguous :: de(:, :)
    real(dp), intent(inout), contiguous :: stress(:, :), statev(:, :), stran(:, :)
    real(dp), intent(inout) :: dlambda(:)
    logical, intent(inout) :: done(:)
    real(dp), intent(in), optional :: avg(:)
    integer, intent(inout), optional :: ndone   !< increased by the particles updated
    integer, parameter :: chunk = block_chunk
    real(dp) :: c_sig0(chunk, 6), c_ep0(chunk, 6), c_de(chunk, 6), c_sig(chunk, 6)
    real(dp) :: c_ep(chunk, 6), c_z0(chunk), c_zeta0(chunk), c_avg(chunk), c_z(chunk)
    real(dp) :: c_zeta(chunk), c_dl(chunk), c_f(chunk), c_st(chunk), c_trial(chunk, 6), c_q(chunk)
    integer(int64) :: bad(chunk), b
    logical :: want_tangent, keep, run, plastic
    type(dp_params_t) :: par
    integer :: fault, k0, n, i, j, q, q0, q1, nt
    nt = ntens
    if (nt /= 6 .and. nt /= 4) return
    call check_props(3, nt - 3, nt, nstatv, size(props), props, dt, par, want_tangent, fault)
    if (fault /= 0) return
    if (.not. has_closed_form(par) .or. par%gdl) return
    c_avg = 0.0_dp
    ! plane strain: the shears 13, 23 are zero in every point
    do j = nt + 1, 6
      c_sig0(:, j) = 0.0_dp
      c_de(:, j) = 0.0_dp
    end do
    do k0 = 1, size(idx), chunk
      n = min(chunk, size(idx) - k0 + 1)
      if (present(avg)) then
        do i = 1, n
          c_avg(i) = avg(idx(k0 - 1 + i))
        end do
      end if
      ! bad(i) < 0 when an input the UMAT or the host checks is not finite:
      ! the average (the UMAT reads it from STATEV(3)), STRESS, DSTRAN, STRAN
      ! and every STATEV slot (the UMAT reads 1-12, the host checks all after).
      ! Consecutive particles (a local update) are tested as one run of
      ! memory per array, which vectorises; a run that fails, or a list, is
      ! tested point by point.
      b = -1_int64
      if (idx(k0 - 1 + n) - idx(k0) == n - 1) then
        q0 = idx(k0)
        q1 = q0 + n - 1
        b = ior(ior(nonfinite_run(size(stress, 1)*n, stress(:, q0:q1)), &
                    nonfinite_run(size(de, 1)*n, de(:, q0:q1))), &
                ior(ior(nonfinite_run(size(stran, 1)*n, stran(:, q0:q1)), &
                        nonfinite_run(size(statev, 1)*n, statev(:, q0:q1))), &
                    nonfinite_run(n, c_avg)))
        do i = 2, n
          if (idx(k0 - 1 + i) /= q0 + i - 1) b = -1_int64
        end do
      end if
      run = b >= 0
      if (run) then
        bad(1:n) = 0
      else
        do i = 1, n
          q = idx(k0 - 1 + i)
          b = nonfinite_bits(c_avg(i))
          do j = 1, nt
            b = ior(b, ior(nonfinite_bits(stress(j, q)), &
                           ior(nonfinite_bits(de(j, q)), nonfinite_bits(stran(j, q)))))
          end do
          do j = 1, nstatv
            b = ior(b, nonfinite_bits(statev(j, q)))
          end do
          bad(i) = b
        end do
      end if
      ! Gather in the model's order with tensor shears; a point with a bad
      ! input enters the kernel as zeros (selected, not computed on) and is
      ! left to the per-particle call. A finite run is copied column by
      ! column and goes through the kernel's two phases: a chunk with no
      ! plastic point is written back as soon as its trial is known, its
      ! plastic strain and z left as they are (their values unchanged).
      if (run) then
        if (nt == 6) then   ! NTENS a constant in each call: the loops unroll
          call gather_run(n, 6, size(stress, 1), size(de, 1), size(statev, 1), &
                          stress(:, q0:q1), de(:, q0:q1), statev(:, q0:q1), c_sig0, c_de, &
                          c_z0, c_zeta0)
        else
          call gather_run(n, 4, size(stress, 1), size(de, 1), size(statev, 1), &
                          stress(:, q0:q1), de(:, q0:q1), statev(:, q0:q1), c_sig0, c_de, &
                          c_z0, c_zeta0)
        end if
        call block_trial(par, n, c_sig0, c_z0, c_zeta0, c_avg, c_de, c_trial, c_q, c_f, c_zeta, &
                         plastic)
        if (.not. plastic) then
          b = 0
          do j = 1, 6
            do i = 1, n
              b = ior(b, nonfinite_bits(c_trial(i, j)))
            end do
          end do
          do i = 1, n
            b = ior(b, ior(nonfinite_bits(c_f(i)), nonfinite_bits(c_zeta(i))))
          end do
          if (b >= 0) then
            call scatter_elastic(n, nt, size(stress, 1), size(de, 1), size(stran, 1), &
                                 size(statev, 1), c_trial, c_avg, c_zeta, c_f, de(:, q0:q1), &
                                 stress(:, q0:q1), stran(:, q0:q1), statev(:, q0:q1))
            dlambda(q0:q1) = 0.0_dp
            done(q0:q1) = .true.
            if (present(ndone)) ndone = ndone + n
            cycle
          end if
        end if
        call gather_ep_run(n, size(statev, 1), statev(:, q0:q1), c_ep0)
        if (plastic) then
          call block_return(par, n, c_ep0, c_z0, c_trial, c_q, dt, c_sig, c_ep, c_z, c_zeta, &
                            c_dl, c_f, c_st)
        else
          call elastic_answer(n, c_trial, c_ep0, c_z0, c_sig, c_ep, c_z, c_dl, c_st)
        end if
      else
        do i = 1, n
          q = idx(k0 - 1 + i)
          keep = bad(i) >= 0
          do j = 1, 3
            c_sig0(i, j) = merge(stress(j, q), 0.0_dp, keep)
            c_de(i, j) = merge(de(j, q), 0.0_dp, keep)
            c_ep0(i, j) = merge(statev(sv_eps_p - 1 + j, q), 0.0_dp, keep)
            c_ep0(i, j + 3) = 0.5_dp*merge(statev(sv_eps_p + 2 + j, q), 0.0_dp, keep)
          end do
          do j = 4, nt
            c_sig0(i, j) = merge(stress(j, q), 0.0_dp, keep)
            c_de(i, j) = 0.5_dp*merge(de(j, q), 0.0_dp, keep)
          end do
          c_z0(i) = merge(statev(sv_z, q), 0.0_dp, keep)
          c_zeta0(i) = merge(statev(sv_zeta, q), 0.0_dp, keep)
          c_avg(i) = merge(c_avg(i), 0.0_dp, keep)
        end do
        call closed_form_block(par, n, c_sig0, c_ep0, c_z0, c_zeta0, c_avg, c_de, dt, c_sig, &
                               c_ep, c_z, c_zeta, c_dl, c_f, c_st, c_trial)
      end if
      ! The outputs the host checks (STRESS and STATEV finite), a column at
      ! a time; a deferred point (status < 0) or a bad input counts as bad.
      ! A finite run ORs them all into b first (no per-point store).
      if (run) then
        b = 0
        do i = 1, n
          b = ior(b, scalar_bits(c_st(i), c_z(i), c_dl(i), c_zeta(i), c_f(i)))
        end do
        do j = 1, 6
          do i = 1, n
            b = ior(b, ior(nonfinite_bits(c_sig(i, j)), nonfinite_bits(c_ep(i, j))))
          end do
        end do
        if (b >= 0) then
          if (nt == 6) then
            call scatter_run(n, 6, size(stress, 1), size(de, 1), size(stran, 1), &
                             size(statev, 1), c_sig, c_ep, c_z, c_dl, c_avg, c_zeta, c_f, c_st, &
                             de(:, q0:q1), stress(:, q0:q1), stran(:, q0:q1), statev(:, q0:q1))
          else
            call scatter_run(n, 4, size(stress, 1), size(de, 1), size(stran, 1), &
                             size(statev, 1), c_sig, c_ep, c_z, c_dl, c_avg, c_zeta, c_f, c_st, &
                             de(:, q0:q1), stress(:, q0:q1), stran(:, q0:q1), statev(:, q0:q1))
          end if
          dlambda(q0:q1) = c_dl(1:n)
          done(q0:q1) = .true.
          if (present(ndone)) ndone = ndone + n
          cycle
        end if
      end if
      do i = 1, n
        bad(i) = ior(bad(i), scalar_bits(c_st(i), c_z(i), c_dl(i), c_zeta(i), c_f(i)))
      end do
      do j = 1, 6
        do i = 1, n
          bad(i) = ior(bad(i), ior(nonfinite_bits(c_sig(i, j)), nonfinite_bits(c_ep(i, j))))
        end do
      end do
      do i = 1, n
        if (bad(i) < 0) cycle
        q = idx(k0 - 1 + i)
        do j = 1, nt
          stress(j, q) = c_sig(i, j)
          stran(j, q) = stran(j, q) + de(j, q)
        end do
        call store_statev(i, c_z, c_dl, c_avg, c_zeta, c_f, c_st, c_ep, statev(:, q))
        dlambda(q) = c_dl(i)
        done(q) = .true.
        if (present(ndone)) ndone = ndone + 1
      end do
    end do
  end subroutine umat_block

  !> umat_block's gather of a run of n particles whose inputs are all
  !> finite: the chunk's columns of what the trial needs, tensor shears.
  pure subroutine gather_run(n, nt, ns, nd, nv, s, d, sv, c_sig0, c_de, c_z0, c_zeta0)
    integer, value :: nt
    integer, intent(in) :: n, ns, nd, nv
    real(dp), intent(in) :: s(ns, n), d(nd, n), sv(nv, n)
    real(dp), intent(inout) :: c_sig0(block_chunk, 6), c_de(block_chunk, 6)
    real(dp), intent(out) :: c_z0(block_chunk), c_zeta0(block_chunk)
    integer :: i, j
    do j = 1, 3
      do i = 1, n
        c_sig0(i, j) = s(j, i)
        c_de(i, j) = d(j, i)
      end do
    end do
    do j = 4, nt
      do i = 1, n
        c_sig0(i, j) = s(j, i)
        c_de(i, j) = 0.5_dp*d(j, i)
      end do
    end do
    do i = 1, n
      c_z0(i) = sv(sv_z, i)
      c_zeta0(i) = sv(sv_zeta, i)
    end do
  end subroutine gather_run

  !> The plastic strain of a run (a chunk with a plastic point), tensor
  !> shears.
  pure subroutine gather_ep_run(n, nv, sv, c_ep0)
    integer, intent(in) :: n, nv
    real(dp), intent(in) :: sv(nv, n)
    real(dp), intent(out) :: c_ep0(block_chunk, 6)
    integer :: i, j
    do j = 1, 3
      do i = 1, n
        c_ep0(i, j) = sv(sv_eps_p - 1 + j, i)
        c_ep0(i, j + 3) = 0.5_dp*sv(sv_eps_p + 2 + j, i)
      end do
    end do
  end subroutine gather_ep_run

  !> umat_block's write-back of an elastic run: the trial stress, the
  !> strain, and the STATEV slots scatter_run writes with other values than
  !> they hold (dlambda, <dlambda>, zeta, f, status, and the plastic
  !> strain's shears through the UMAT's halving and doubling).
  pure subroutine scatter_elastic(n, nt, ns, nd, ne, nv, c_trial, c_avg, c_zeta, c_f, d, s, e, &
                                  sv)
    integer, intent(in) :: n, nt, ns, nd, ne, nv
    real(dp), intent(in) :: c_trial(block_chunk, 6), d(nd, n)
    real(dp), intent(in), dimension(block_chunk) :: c_avg, c_zeta, c_f
    real(dp), intent(inout) :: s(ns, n), e(ne, n), sv(nv, n)
    integer :: i, j
    call put_stress_strain(n, nt, ns, nd, ne, c_trial, d, s, e)
    do i = 1, n
      sv(sv_dlambda, i) = 0.0_dp
      sv(sv_avg_dlambda, i) = c_avg(i)
      sv(sv_zeta, i) = c_zeta(i)
      do j = 1, 3
        sv(sv_eps_p + 2 + j, i) = 2.0_dp*(0.5_dp*sv(sv_eps_p + 2 + j, i))
      end do
      sv(sv_f, i) = c_f(i)
      sv(sv_status, i) = 0.0_dp
    end do
  end subroutine scatter_elastic

  !> umat_block's scatter of a run of n particles every output of which is
  !> finite: stress, strain, the STATEV slots (engineering plastic shears).
  pure subroutine scatter_run(n, nt, ns, nd, ne, nv, c_sig, c_ep, c_z, c_dl, c_avg, c_zeta, &
                              c_f, c_st, d, s, e, sv)
    integer, value :: nt
    integer, intent(in) :: n, ns, nd, ne, nv
    real(dp), intent(in), dimension(block_chunk, 6) :: c_sig, c_ep
    real(dp), intent(in), dimension(block_chunk) :: c_z, c_dl, c_avg, c_zeta, c_f, c_st
    real(dp), intent(in) :: d(nd, n)
    real(dp), intent(inout) :: s(ns, n), e(ne, n), sv(nv, n)
    integer :: i
    call put_stress_strain(n, nt, ns, nd, ne, c_sig, d, s, e)
    do i = 1, n
      call store_statev(i, c_z, c_dl, c_avg, c_zeta, c_f, c_st, c_ep, sv(:, i))
    end do
  end subroutine scatter_run

  !> The STATEV slots of chunk point i (the plastic strain's shears
  !> engineering again).
  pure subroutine store_statev(i, c_z, c_dl, c_avg, c_zeta, c_f, c_st, c_ep, sv)
    integer, intent(in) :: i
    real(dp), intent(in), dimension(block_chunk) :: c_z, c_dl, c_avg, c_zeta, c_f, c_st
    real(dp), intent(in) :: c_ep(block_chunk, 6)
    real(dp), intent(inout) :: sv(*)
    integer :: j
    sv(sv_z) = c_z(i)
    sv(sv_dlambda) = c_dl(i)
    sv(sv_avg_dlambda) = c_avg(i)
    sv(sv_zeta) = c_zeta(i)
    do j = 1, 3
      sv(sv_eps_p - 1 + j) = c_ep(i, j)
      sv(sv_eps_p + 2 + j) = 2.0_dp*c_ep(i, j + 3)
    end do
    sv(sv_f) = c_f(i)
    sv(sv_status) = c_st(i)
  end subroutine store_statev

  !> A run's stress from the chunk's columns and its strain + d.
  pure subroutine put_stress_strain(n, nt, ns, nd, ne, c_sig, d, s, e)
    integer, intent(in) :: n, nt, ns, nd, ne
    real(dp), intent(in) :: c_sig(block_chunk, 6), d(nd, n)
    real(dp), intent(inout) :: s(ns, n), e(ne, n)
    integer :: i, j
    do j = 1, nt
      do i = 1, n
        s(j, i) = c_sig(i, j)
      end do
    end do
    if (ne == nt .and. nd == nt) then
      call add_run(nt*n, d, e)     ! one run of memory: it vectorises
    else
      do i = 1, n
        do j = 1, nt
          e(j, i) = e(j, i) + d(j, i)
        end do
      end do
    end if
  end subroutine put_stress_strain

  !> Negative when a point's scalar outputs are not finite or its status
  !> is negative (deferred).
  elemental integer(int64) function scalar_bits(st, z, dl, zeta, f) result(b)
    real(dp), intent(in) :: st, z, dl, zeta, f
    b = ior(ior(transfer(st, 0_int64), ior(nonfinite_bits(z), nonfinite_bits(dl))), &
            ior(nonfinite_bits(zeta), nonfinite_bits(f)))
  end function scalar_bits

  !> e(1:m) = e(1:m) + d(1:m).
  pure subroutine add_run(m, d, e)
    integer, intent(in) :: m
    real(dp), intent(in) :: d(m)
    real(dp), intent(inout) :: e(m)
    e = e + d
  end subroutine add_run

  !> Negative when one of x(1:m) is NaN or Inf (nonfinite_bits OR-ed over a
  !> run of memory: no branch, so the loop vectorises).
  pure integer(int64) function nonfinite_run(m, x) result(b)
    integer, intent(in) :: m
    real(dp), intent(in) :: x(m)
    integer :: k
    b = 0
    do k = 1, m
      b = ior(b, nonfinite_bits(x(k)))
    end do
  end function nonfinite_run

end module wellposed_mpm_particle_umat
