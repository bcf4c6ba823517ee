!> The closed-form Drucker-Prager update (linear hardening; eq. 4.36-4.39,
!> apex return, Duvaut-Lions eq. 2.10) written once, as branch-free kernels
!> per point (tensor components 11, 22, 33, 12, 13, 23): cf_trial, cf_cone,
!> cf_apex, cf_relax, divisors kept >= `floor`. point_closed_form (the
!> UMAT's path) calls them on one point, closed_form_block (the VUMAT's) on
!> chunks, vectorised. One file, so they inline into both: bitwise the same
!> (docs/guide/performance.md, "The VUMAT").
module wellposed_dp_closed_form
  use wellposed_kinds, only: dp
  use wellposed_error, only: status_cutback
  use wellposed_tensor, only: ntens6, sqrt2
  use wellposed_dp_params, only: dp_params_t
  use wellposed_return_mapping, only: state_elastic, state_plastic, state_apex
  use wellposed_dp_tangent, only: voigt_stiffness, closed_form_tangent, blend_voigt_stiffness
  implicit none
  private
  public :: cf_trial, cf_deviator, cf_cone, cf_apex, cf_relax, point_closed_form
  public :: closed_form_block, block_trial, block_return, elastic_answer, block_chunk, &
            deferred_points

  !> Points per call of closed_form_block (the leading dimension of its
  !> arrays, a constant so that the compiler sees the columns apart).
  integer, parameter :: block_chunk = 64

  real(dp), parameter :: rsqrt2 = 1.0_dp/sqrt2

contains

  !> The deviator s and trace i1 of a stress st (tensor components).
  pure subroutine cf_deviator(st, s, i1)
    real(dp), intent(in) :: st(6)
    real(dp), intent(out) :: s(6), i1
    i1 = st(1) + st(2) + st(3)
    s(1:3) = st(1:3) - i1/3.0_dp
    s(4:6) = st(4:6)
  end subroutine cf_deviator

  !> The elastic trial st = sig0 + C : de (eq. 1.5), its deviator s, trace
  !> i1, q = ||s||, zeta = zeta0 + h_zeta avg (eq. 4.24) and f_tr.
  pure subroutine cf_trial(p, sig0, de, z0, zeta0, avg, st, s, i1, q, zeta, f_tr)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig0(6), de(6), z0, zeta0, avg
    real(dp), intent(out) :: st(6), s(6), i1, q, zeta, f_tr
    real(dp) :: tr_de
    zeta = zeta0 + p%h_zeta*avg
    tr_de = de(1) + de(2) + de(3)
    st(1:3) = sig0(1:3) + 2.0_dp*p%el%shear*(de(1:3) - tr_de/3.0_dp) + p%el%bulk*tr_de
    st(4:6) = sig0(4:6) + 2.0_dp*p%el%shear*de(4:6)
    call cf_deviator(st, s, i1)
    q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
    f_tr = q/sqrt2 + p%beta*i1 - (p%hard%k0 + p%hard%h*z0 + zeta)
  end subroutine cf_trial

  !> The cone return (eq. 4.36) of a plastic trial (deviator s, trace i1,
  !> q, f_tr, zeta; z0): stress sn, d eps^p = x M_hat (eq. 4.35), x = dz
  !> and f at the end. q and x_max are kept >= floor and x within [0,
  !> x_max], so no divisor vanishes; `bad` > 0 where that changed them (q
  !> or x_max < floor), where x > x_max (no admissible cone stress) or where
  !> the apex is reached (beta > 0, f_tr > (a + h) x_max): the answer is
  !> then not the cone's. With floor 0 and none of these, the unguarded
  !> return; where bad <= 0 the guards changed nothing.
  pure subroutine cf_cone(p, s, i1_tr, q, f_tr, zeta, z0, floor, sn, dep, x, f, bad)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: s(6), i1_tr, q, f_tr, zeta, z0, floor
    real(dp), intent(out) :: sn(6), dep(6), x, f, bad
    real(dp) :: qs, x_max, rate, rn, shrink, i1
    rate = p%a_m + p%hard%h
    rn = 1.0_dp/p%n_m
    qs = max(q, floor)
    x_max = qs*p%n_m/(sqrt2*p%el%shear)
    x = f_tr/rate
    ! Each condition the sign of a difference: no logical stored. The apex
    ! term is selected, not scaled (a shift by 1 rounds a difference below
    ! 1e-16 to 0 and sent such a point to the cone, not the apex).
    bad = max(floor - q, floor - x_max, x - x_max, &
              merge(f_tr - rate*x_max, -1.0_dp, p%beta > 0.0_dp))
    x = min(max(x, 0.0_dp), x_max)
    shrink = 1.0_dp - x/max(x_max, floor)
    i1 = i1_tr - 9.0_dp*p%el%bulk*p%beta_p*x*rn
    sn = shrink*s
    sn(1:3) = sn(1:3) + i1/3.0_dp
    ! M_hat = (S_hat/sqrt(2) + beta_p I)/n_m (eq. 4.35).
    dep = (rsqrt2*x*rn/qs)*s
    dep(1:3) = dep(1:3) + x*p%beta_p*rn
    f = rsqrt2*shrink*q + p%beta*i1 - (p%hard%k0 + p%hard%h*(z0 + x)) - zeta
  end subroutine cf_cone

  !> The apex return (beta > 0) of a trial (deviator s, trace i1_tr, q,
  !> f_tr, zeta; z0): sigma = s_ap I, s_ap = k(z0 + d)/(3 beta), d eps^p =
  !> C^-1 : (sigma_trial - sigma_apex), d = ||d eps^p|| the root of d^2 =
  !> ||S||^2/(2G)^2 + 3 (c0 - c1 d)^2 (k linear). take = 1 where that is the
  !> answer (the trial beyond the cone's reach, a real root 0 <= d <= huge,
  !> its divisor >= floor), else 0 (sn, dep, d, f then not to be used).
  pure subroutine cf_apex(p, s, i1_tr, q, f_tr, zeta, z0, floor, s_ap, dep, d, f, take)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: s(6), i1_tr, q, f_tr, zeta, z0, floor
    real(dp), intent(out) :: s_ap, dep(6), d, f, take
    real(dp) :: bulk, shear, c0, c1, a2, b2, c2, disc, sd, num, den, x_max, k_n
    bulk = p%el%bulk
    shear = p%el%shear
    c1 = p%hard%h/(9.0_dp*bulk*p%beta)
    a2 = 1.0_dp - 3.0_dp*c1**2
    x_max = q*p%n_m/(sqrt2*shear)
    k_n = p%hard%k0 + p%hard%h*z0 + zeta
    c0 = (i1_tr - k_n/p%beta)/(9.0_dp*bulk)
    b2 = 3.0_dp*c0*c1
    c2 = (q/(2.0_dp*shear))**2 + 3.0_dp*c0**2
    disc = b2**2 + a2*c2
    sd = sqrt(max(disc, 0.0_dp))
    num = merge(c2, sd - b2, b2 >= 0.0_dp)
    den = merge(b2 + sd, a2, b2 >= 0.0_dp)
    ! a product of 0/1 masks (a logical .and. would put branches in a loop)
    take = merge(1.0_dp, 0.0_dp, disc >= 0.0_dp)* &
           merge(1.0_dp, 0.0_dp, f_tr - (p%a_m + p%hard%h)*x_max > 0.0_dp)* &
           merge(1.0_dp, 0.0_dp, abs(den) >= floor)
    d = num/merge(den, 1.0_dp, take > 0.0_dp)
    take = take*merge(1.0_dp, 0.0_dp, d >= 0.0_dp)*merge(1.0_dp, 0.0_dp, d <= huge(d))
    d = merge(d, 0.0_dp, take > 0.0_dp)
    s_ap = (k_n + p%hard%h*d)/(3.0_dp*p%beta)
    dep = s/(2.0_dp*shear)
    dep(1:3) = dep(1:3) + (i1_tr - 3.0_dp*s_ap)/(9.0_dp*bulk)
    d = sqrt(dep(1)**2 + dep(2)**2 + dep(3)**2 + 2.0_dp*(dep(4)**2 + dep(5)**2 + dep(6)**2))
    f = 3.0_dp*p%beta*s_ap - (p%hard%k0 + p%hard%h*(z0 + d)) - zeta
  end subroutine cf_apex

  !> Duvaut-Lions (eq. 2.10, backward Euler, w = tau/(tau + dt)): the
  !> rate-independent answer sn, dep, dz relaxed toward the trial st, and f
  !> at the relaxed stress (z0, zeta as for the return).
  pure subroutine cf_relax(p, w, st, z0, zeta, sn, dep, dz, f)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: w, st(6), z0, zeta
    real(dp), intent(inout) :: sn(6), dep(6), dz
    real(dp), intent(out) :: f
    real(dp) :: s(6), i1, q
    sn = sn + w*(st - sn)
    dep = (1.0_dp - w)*dep
    dz = (1.0_dp - w)*dz
    call cf_deviator(sn, s, i1)
    q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
    f = q/sqrt2 + p%beta*i1 - (p%hard%k0 + p%hard%h*(z0 + dz)) - zeta
  end subroutine cf_relax

  !> The closed-form increment (regular flow rule, linear hardening, eq.
  !> 4.36-4.39; apex return; Duvaut-Lions eq. 2.10 by backward Euler), in
  !> tensor components: the kernels on one point. `status` is 0 elastic, 1
  !> cone, 2 apex, or status_cutback where no closed-form answer exists (a
  !> cylinder softened below any admissible stress, or an apex equation
  !> without a root): the arguments are then untouched. `tangent(n, n)` (n = 4 or 6), when present, receives the
  !> leading n x n block of d sigma/d eps (Voigt).
  pure subroutine point_closed_form(p, sig, eps_p, z, zeta, avg_dlambda, de, dtime, dlambda, &
                                    f, status, n, tangent)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(inout) :: sig(ntens6), eps_p(ntens6), z, zeta
    real(dp), intent(in) :: avg_dlambda, de(ntens6), dtime
    real(dp), intent(out) :: dlambda, f
    integer, intent(out) :: status
    integer, intent(in) :: n
    real(dp), intent(inout), optional :: tangent(n, n)
    real(dp) :: zeta_new, sig_tr(ntens6), s(ntens6), i1_tr, q, f_tr, x, sig_new(ntens6)
    real(dp) :: dep(ntens6), dz, bad, s_ap, take

    call cf_trial(p, sig, de, z, zeta, avg_dlambda, sig_tr, s, i1_tr, q, zeta_new, f_tr)
    if (.not. f_tr > 0.0_dp) then
      sig = sig_tr
      zeta = zeta_new
      dlambda = 0.0_dp
      f = f_tr
      status = state_elastic
      if (present(tangent)) call voigt_stiffness(p%el%bulk, p%el%shear, n, tangent)
      return
    end if

    ! The kernels' guards are not needed on one point: the branch is taken
    ! first (floor 0: the unguarded arithmetic).
    status = reach(p, q, f_tr)
    if (status == state_plastic) then
      call cf_cone(p, s, i1_tr, q, f_tr, zeta_new, z, 0.0_dp, sig_new, dep, x, f, bad)
    else if (status == state_apex) then
      call cf_apex(p, s, i1_tr, q, f_tr, zeta_new, z, 0.0_dp, s_ap, dep, dz, f, take)
      if (take == 0.0_dp) status = status_cutback
      sig_new(1:3) = s_ap
      sig_new(4:6) = 0.0_dp
    end if
    if (status == status_cutback) return
    if (status == state_plastic) dz = x
    if (present(tangent)) call closed_form_tangent(p, status, s, q, x, dep, dz, n, tangent)
    if (p%tau > 0.0_dp) then
      call cf_relax(p, p%tau/(p%tau + dtime), sig_tr, z, zeta_new, sig_new, dep, dz, f)
      if (present(tangent)) call blend_voigt_stiffness(p%el%bulk, p%el%shear, n, &
                                                       p%tau/(p%tau + dtime), tangent)
    end if
    sig = sig_new
    eps_p = eps_p + dep
    z = z + dz
    zeta = zeta_new
    dlambda = dz
  end subroutine point_closed_form

  !> Where a plastic trial (q, f_tr as cf_cone's) returns: state_apex when
  !> beta > 0 and the trial lies beyond the cone's reach (or on the axis),
  !> status_cutback when no cone stress is admissible (x > x_max), else
  !> state_plastic (the cone).
  pure function reach(p, q, f_tr) result(status)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: q, f_tr
    integer :: status
    real(dp) :: x_max
    x_max = 0.0_dp
    if (q > 0.0_dp) x_max = q*p%n_m/(sqrt2*p%el%shear)
    status = state_plastic
    if (p%beta > 0.0_dp) then
      if (q == 0.0_dp .or. f_tr - (p%a_m + p%hard%h)*x_max > 0.0_dp) status = state_apex
    end if
    if (status == state_plastic .and. f_tr/(p%a_m + p%hard%h) > x_max) status = status_cutback
  end function reach

  !> Advance points 1 to n <= block_chunk: inputs sig0, eps_p0, z0, zeta0
  !> (start of increment), avg_dlambda (the host's `<dlambda>`), de; outputs
  !> sig, eps_p, z, zeta, dlambda, f and status (0 elastic, 1 cone, 2 apex,
  !> or -1: deferred, the outputs not to be used), and the elastic trial stress.
  !> Status is real, as the STATEV slot it goes to, so that every quantity
  !> of the loop is a double. `p` must serve the closed form
  !> (has_closed_form). block_trial, then the elastic answer or
  !> block_return; a host may call the two itself (an elastic chunk then
  !> needs no eps_p0).
  pure subroutine closed_form_block(p, n, sig0, eps_p0, z0, zeta0, avg_dlambda, de, dtime, &
                                    sig, eps_p, z, zeta, dlambda, f, status, trial)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: sig0(block_chunk, 6), eps_p0(block_chunk, 6), z0(block_chunk)
    real(dp), intent(in) :: zeta0(block_chunk), avg_dlambda(block_chunk), de(block_chunk, 6)
    real(dp), intent(in) :: dtime
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: zeta(block_chunk), dlambda(block_chunk), f(block_chunk)
    real(dp), intent(inout) :: status(block_chunk), trial(block_chunk, 6)
    real(dp) :: q_trial(block_chunk)
    logical :: plastic
    call block_trial(p, n, sig0, z0, zeta0, avg_dlambda, de, trial, q_trial, f, zeta, plastic)
    if (plastic) then
      call block_return(p, n, eps_p0, z0, trial, q_trial, dtime, sig, eps_p, z, zeta, dlambda, &
                        f, status)
    else
      call elastic_answer(n, trial, eps_p0, z0, sig, eps_p, z, dlambda, status)
    end if
  end subroutine closed_form_block

  !> The answer of a chunk block_trial found elastic: the trial, eps_p and
  !> z unchanged, dlambda and status 0 (f and zeta are block_trial's).
  pure subroutine elastic_answer(n, trial, eps_p0, z0, sig, eps_p, z, dlambda, status)
    integer, intent(in) :: n
    real(dp), intent(in) :: trial(block_chunk, 6), eps_p0(block_chunk, 6), z0(block_chunk)
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: dlambda(block_chunk), status(block_chunk)
    integer :: i, j
    do j = 1, 6
      do i = 1, n
        sig(i, j) = trial(i, j)
        eps_p(i, j) = eps_p0(i, j)
      end do
    end do
    do i = 1, n
      z(i) = z0(i)
      dlambda(i) = 0.0_dp
      status(i) = 0.0_dp
    end do
  end subroutine elastic_answer

  !> The first phase of closed_form_block: cf_trial on points 1 to n (the
  !> trial, its q, f_trial, zeta_trial); `plastic` when a point is outside
  !> the yield surface (a NaN f counts as elastic, as in block_return).
  !> With none, the elastic answer is the trial, f f_trial, zeta
  !> zeta_trial, eps_p and z unchanged, dlambda and status 0.
  pure subroutine block_trial(p, n, sig0, z0, zeta0, avg_dlambda, de, trial, q_trial, f_trial, &
                              zeta_trial, plastic)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: sig0(block_chunk, 6), z0(block_chunk), zeta0(block_chunk)
    real(dp), intent(in) :: avg_dlambda(block_chunk), de(block_chunk, 6)
    real(dp), intent(inout) :: trial(block_chunk, 6), q_trial(block_chunk)
    real(dp), intent(inout) :: f_trial(block_chunk), zeta_trial(block_chunk)
    logical, intent(out) :: plastic
    real(dp) :: s0(6), d(6), st(6), s(6), i1, q, zt, ft, pl
    integer :: i
    do i = 1, n
      ! rows copied to local vectors: the kernel's arguments are contiguous
      s0 = sig0(i, :)
      d = de(i, :)
      call cf_trial(p, s0, d, z0(i), zeta0(i), avg_dlambda(i), st, s, i1, q, zt, ft)
      zeta_trial(i) = zt
      f_trial(i) = ft
      q_trial(i) = q
      trial(i, :) = st
    end do
    pl = 0.0_dp
    do i = 1, n
      pl = merge(1.0_dp, pl, f_trial(i) > 0.0_dp)
    end do
    plastic = pl /= 0.0_dp
  end subroutine block_trial

  !> The second phase of closed_form_block, for a chunk with a plastic
  !> point: from block_trial's trial, q_trial, f (its f_trial) and zeta
  !> (its zeta_trial), every point's answer (the elastic ones selected):
  !> cf_cone on every point, cf_apex on the compacted list of those the
  !> cone defers (beta > 0), cf_relax under Duvaut-Lions.
  pure subroutine block_return(p, n, eps_p0, z0, trial, q_trial, dtime, sig, eps_p, z, zeta, &
                               dlambda, f, status)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: eps_p0(block_chunk, 6), z0(block_chunk), trial(block_chunk, 6)
    real(dp), intent(in) :: q_trial(block_chunk), dtime
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: zeta(block_chunk), dlambda(block_chunk), f(block_chunk)
    real(dp), intent(inout) :: status(block_chunk)
    real(dp) :: st(6), s(6), i1_tr, f_tr, zeta_new, x, sn(6), dep(6), r, fc, bad, pl
    real(dp) :: f_trial(block_chunk), zeta_trial(block_chunk)
    integer :: i, j
    ! Local copies: a dummy's load in the plastic branch only (GCC sinks it
    ! there) might trap, and blocks vectorising.
    f_trial(1:n) = f(1:n)
    zeta_trial(1:n) = zeta(1:n)
    do i = 1, n
      st = trial(i, :)
      call cf_deviator(st, s, i1_tr)
      f_tr = f_trial(i)
      zeta_new = zeta_trial(i)
      call cf_cone(p, s, i1_tr, q_trial(i), f_tr, zeta_new, z0(i), tiny(1.0_dp), sn, dep, x, &
                   fc, bad)
      do j = 1, 6
        sig(i, j) = merge(sn(j), st(j), f_tr > 0.0_dp)
        r = eps_p0(i, j) + dep(j)
        eps_p(i, j) = merge(r, eps_p0(i, j), f_tr > 0.0_dp)
      end do
      r = z0(i) + x
      z(i) = merge(r, z0(i), f_tr > 0.0_dp)
      dlambda(i) = merge(x, 0.0_dp, f_tr > 0.0_dp)
      f(i) = merge(fc, f_tr, f_tr > 0.0_dp)
      ! 0 elastic, 1 cone, -1 deferred, as arithmetic on two 0/1 masks.
      pl = merge(1.0_dp, 0.0_dp, f_tr > 0.0_dp)
      status(i) = pl - 2.0_dp*pl*merge(1.0_dp, 0.0_dp, bad > 0.0_dp)
    end do
    if (p%beta > 0.0_dp) then
      if (any(status(1:n) < 0.0_dp)) call apex_pass(p, n, eps_p0, z0, trial, q_trial, f_trial, &
                                                    zeta_trial, sig, eps_p, z, dlambda, f, &
                                                    status)
    end if
    if (p%tau > 0.0_dp) call relax_pass(p, n, eps_p0, z0, trial, q_trial, f_trial, zeta_trial, &
                                        dtime, sig, eps_p, z, dlambda, f, status)
  end subroutine block_return

  !> cf_apex for the points block_return deferred (status -1), gathered
  !> into a compact list (the cost follows their number, not the chunk's)
  !> and computed there branch-free; a point takes the answer (status 2)
  !> where cf_apex finds one, any other stays deferred.
  pure subroutine apex_pass(p, n, eps_p0, z0, trial, q_trial, f_trial, zeta_trial, sig, &
                            eps_p, z, dlambda, f, status)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: eps_p0(block_chunk, 6), z0(block_chunk), trial(block_chunk, 6)
    real(dp), intent(in) :: q_trial(block_chunk), f_trial(block_chunk), zeta_trial(block_chunk)
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: dlambda(block_chunk), f(block_chunk), status(block_chunk)
    real(dp) :: st(6), s(6), i1_tr, d(6)
    ! The compact list: inputs and answers in local arrays only, so that
    ! no load can trap and no store is conditional (either would stop GCC
    ! vectorising the loop).
    real(dp) :: tr(block_chunk, 6), ft(block_chunk), zt(block_chunk), zc(block_chunk)
    real(dp) :: qt(block_chunk), dep(block_chunk, 6), a_ap(block_chunk), a_dz(block_chunk)
    real(dp) :: a_f(block_chunk), take(block_chunk)
    integer :: i, k, m, idx(block_chunk)
    call deferred_points(n, status, idx, m)
    do k = 1, m
      i = idx(k)
      tr(k, :) = trial(i, :)
      ft(k) = f_trial(i)
      zt(k) = zeta_trial(i)
      zc(k) = z0(i)
      qt(k) = q_trial(i)
    end do
    do k = 1, m
      st = tr(k, :)
      call cf_deviator(st, s, i1_tr)
      call cf_apex(p, s, i1_tr, qt(k), ft(k), zt(k), zc(k), tiny(1.0_dp), a_ap(k), d, a_dz(k), &
                   a_f(k), take(k))
      dep(k, :) = d
    end do
    do k = 1, m
      if (take(k) == 0.0_dp) cycle
      i = idx(k)
      sig(i, 1:3) = a_ap(k)
      sig(i, 4:6) = 0.0_dp
      eps_p(i, :) = eps_p0(i, :) + dep(k, :)
      z(i) = zc(k) + a_dz(k)
      dlambda(i) = a_dz(k)
      f(i) = a_f(k)
      status(i) = 2.0_dp
    end do
  end subroutine apex_pass

  !> Duvaut-Lions (tau > 0): the cone and apex points (status 1, 2) relaxed
  !> toward the trial by cf_relax, in a second, scalar pass so that the
  !> rate-independent pass stays one branch-free loop; each point's return
  !> formed again by the same kernel (bitwise the first pass's).
  pure subroutine relax_pass(p, n, eps_p0, z0, trial, q_trial, f_trial, zeta_trial, dtime, &
                             sig, eps_p, z, dlambda, f, status)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: eps_p0(block_chunk, 6), z0(block_chunk), trial(block_chunk, 6)
    real(dp), intent(in) :: q_trial(block_chunk), f_trial(block_chunk), zeta_trial(block_chunk)
    real(dp), intent(in) :: dtime
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: dlambda(block_chunk), f(block_chunk), status(block_chunk)
    real(dp) :: w, st(6), s(6), i1_tr, sn(6), dep(6), dz, fr, bad, s_ap
    integer :: i
    w = p%tau/(p%tau + dtime)
    do i = 1, n
      if (.not. (status(i) == 1.0_dp .or. status(i) == 2.0_dp)) cycle
      st = trial(i, :)
      call cf_deviator(st, s, i1_tr)
      if (status(i) == 1.0_dp) then
        call cf_cone(p, s, i1_tr, q_trial(i), f_trial(i), zeta_trial(i), z0(i), tiny(1.0_dp), &
                     sn, dep, dz, fr, bad)
      else
        call cf_apex(p, s, i1_tr, q_trial(i), f_trial(i), zeta_trial(i), z0(i), tiny(1.0_dp), &
                     s_ap, dep, dz, fr, bad)
        sn(1:3) = s_ap
        sn(4:6) = 0.0_dp
      end if
      call cf_relax(p, w, st, z0(i), zeta_trial(i), sn, dep, dz, fr)
      sig(i, :) = sn
      eps_p(i, :) = eps_p0(i, :) + dep
      z(i) = z0(i) + dz
      dlambda(i) = dz
      f(i) = fr
    end do
  end subroutine relax_pass

  !> The points of 1 to n the kernel deferred (status < 0): idx(1:m).
  pure subroutine deferred_points(n, status, idx, m)
    integer, intent(in) :: n
    real(dp), intent(in) :: status(block_chunk)
    integer, intent(out) :: idx(block_chunk), m
    integer :: i
    m = 0
    do i = 1, n
      if (status(i) < 0.0_dp) then
        m = m + 1
        idx(m) = i
      end if
    end do
  end subroutine deferred_points

end module wellposed_dp_closed_form
