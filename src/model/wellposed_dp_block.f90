!> The closed form of wellposed_dp_point (eq. 4.36-4.39, 2.10) for a block
!> of points, as an explicit host calls it: arrays (n, 6), components
!> [11, 22, 33, 12, 13, 23]. Trial, cone and apex returns for every point of
!> a chunk, selected by masks, so the loops have no call or branch and
!> vectorise (-fno-trapping-math). Points none of these answer (a zero
!> deviator, the apex under Duvaut-Lions) are deferred to point_update.
!> The results are bitwise point_closed_form's.
module wellposed_dp_block
  use wellposed_kinds, only: dp
  use wellposed_tensor, only: sqrt2
  use wellposed_dp_params, only: dp_params_t
  implicit none
  private
  public :: closed_form_block, block_trial, block_return, elastic_answer, block_chunk, &
            deferred_points

  !> Points per call of closed_form_block (the leading dimension of its
  !> arrays, a constant so that the compiler sees the columns apart).
  integer, parameter :: block_chunk = 64

  real(dp), parameter :: third = 1.0_dp/3.0_dp, rsqrt2 = 1.0_dp/sqrt2

contains

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

  !> The first phase of closed_form_block: the trial (eq. 1.5), its q, the
  !> yield function f_trial and zeta_trial for points 1 to n; `plastic`
  !> when a point is outside the yield surface (a NaN f counts as elastic,
  !> as in block_return). With none, the elastic answer is the trial, f
  !> f_trial, zeta zeta_trial, eps_p and z unchanged, dlambda and status 0.
  pure subroutine block_trial(p, n, sig0, z0, zeta0, avg_dlambda, de, trial, q_trial, f_trial, &
                              zeta_trial, plastic)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: sig0(block_chunk, 6), z0(block_chunk), zeta0(block_chunk)
    real(dp), intent(in) :: avg_dlambda(block_chunk), de(block_chunk, 6)
    real(dp), intent(inout) :: trial(block_chunk, 6), q_trial(block_chunk)
    real(dp), intent(inout) :: f_trial(block_chunk), zeta_trial(block_chunk)
    logical, intent(out) :: plastic
    real(dp) :: bulk, shear, tr_de, st(6), s(6), i1_tr, q, k_n, pl
    integer :: i, j
    bulk = p%el%bulk
    shear = p%el%shear
    do i = 1, n
      zeta_trial(i) = zeta0(i) + p%h_zeta*avg_dlambda(i)
      tr_de = de(i, 1) + de(i, 2) + de(i, 3)
      do j = 1, 3
        st(j) = sig0(i, j) + 2.0_dp*shear*(de(i, j) - tr_de/3.0_dp) + bulk*tr_de
      end do
      do j = 4, 6
        st(j) = sig0(i, j) + 2.0_dp*shear*de(i, j)
      end do
      i1_tr = st(1) + st(2) + st(3)
      s(1:3) = st(1:3) - i1_tr/3.0_dp
      s(4:6) = st(4:6)
      q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
      k_n = p%hard%k0 + p%hard%h*z0(i) + zeta_trial(i)
      f_trial(i) = q/sqrt2 + p%beta*i1_tr - k_n
      q_trial(i) = q
      do j = 1, 6
        trial(i, j) = st(j)
      end do
    end do
    pl = 0.0_dp
    do i = 1, n
      pl = merge(1.0_dp, pl, f_trial(i) > 0.0_dp)
    end do
    plastic = pl /= 0.0_dp
  end subroutine block_trial

  !> The second phase of closed_form_block, for a chunk with a plastic
  !> point: from block_trial's trial, q_trial, f (its f_trial) and zeta
  !> (its zeta_trial), every point's answer (the elastic ones selected).
  pure subroutine block_return(p, n, eps_p0, z0, trial, q_trial, dtime, sig, eps_p, z, zeta, &
                               dlambda, f, status)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: eps_p0(block_chunk, 6), z0(block_chunk), trial(block_chunk, 6)
    real(dp), intent(in) :: q_trial(block_chunk), dtime
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: zeta(block_chunk), dlambda(block_chunk), f(block_chunk)
    real(dp), intent(inout) :: status(block_chunk)
    real(dp) :: bulk, shear, rn, rate, w, zeta_new, st(6), s(6), i1_tr, q, f_tr
    real(dp) :: qs, x_max, x, xc, shrink, i1, sn(6), dep(6), r, fc, bad, pl
    real(dp) :: f_trial(block_chunk), zeta_trial(block_chunk)
    integer :: i, j
    real(dp) :: apex_on

    bulk = p%el%bulk
    shear = p%el%shear
    rn = 1.0_dp/p%n_m
    rate = p%a_m + p%hard%h
    ! 1 when the cone has an apex (beta > 0), else 0: a factor, not a branch.
    apex_on = merge(1.0_dp, 0.0_dp, p%beta > 0.0_dp)
    ! local copies: loads of a dummy in the plastic branch only would block
    ! vectorising (see zeta_new below)
    f_trial(1:n) = f(1:n)
    zeta_trial(1:n) = zeta(1:n)
    do i = 1, n
      ! the first loop's trial, deviator, q and f: the same operations.
      ! zeta_new from a local array: a dummy's load that GCC sinks into the
      ! plastic branch (only fc reads it) might trap, and blocks vectorising.
      st = trial(i, :)
      i1_tr = st(1) + st(2) + st(3)
      s(1:3) = st(1:3) - i1_tr/3.0_dp
      s(4:6) = st(4:6)
      q = q_trial(i)
      f_tr = f_trial(i)
      zeta_new = zeta_trial(i)

      ! Cone (eq. 4.36), evaluated on every point with divisors kept >=
      ! tiny and x clipped to [0, x_max], so that no lane divides by zero or
      ! overflows. A plastic point is deferred when q or x_max < tiny (the
      ! guards would change them), x > x_max (no admissible cone stress) or
      ! the apex is reached (f_tr - (a + h) x_max > 0, beta > 0; apex_return
      ! then takes most of these): each condition is the sign of a
      ! difference, so no logical is stored. The apex term is selected, not
      ! scaled by apex_on and shifted by 1: the shift rounds a difference
      ! below 1e-16 to 0 and sent such a point to the cone, not the apex.
      qs = max(q, tiny(1.0_dp))
      x_max = qs*p%n_m/(sqrt2*shear)
      x = f_tr/rate
      bad = max(tiny(1.0_dp) - q, tiny(1.0_dp) - x_max, x - x_max, &
                merge(f_tr - rate*x_max, -1.0_dp, apex_on > 0.0_dp))
      xc = min(max(x, 0.0_dp), x_max)
      shrink = 1.0_dp - xc/max(x_max, tiny(1.0_dp))
      i1 = i1_tr - 9.0_dp*bulk*p%beta_p*xc*rn
      sn = shrink*s
      sn(1:3) = sn(1:3) + i1/3.0_dp
      ! d eps^p = x M_hat, M_hat = (S_hat/sqrt(2) + beta_p I)/n_m (eq. 4.35).
      dep = (rsqrt2*xc*rn/qs)*s
      dep(1:3) = dep(1:3) + xc*p%beta_p*rn
      fc = rsqrt2*shrink*q + p%beta*i1 - (p%hard%k0 + p%hard%h*(z0(i) + xc)) - zeta_new

      do j = 1, 6
        sig(i, j) = merge(sn(j), st(j), f_tr > 0.0_dp)
        r = eps_p0(i, j) + dep(j)
        eps_p(i, j) = merge(r, eps_p0(i, j), f_tr > 0.0_dp)
      end do
      r = z0(i) + xc
      z(i) = merge(r, z0(i), f_tr > 0.0_dp)
      dlambda(i) = merge(xc, 0.0_dp, f_tr > 0.0_dp)
      f(i) = merge(fc, f_tr, f_tr > 0.0_dp)
      ! 0 elastic, 1 cone, -1 deferred, as arithmetic on two 0/1 masks.
      pl = merge(1.0_dp, 0.0_dp, f_tr > 0.0_dp)
      status(i) = pl - 2.0_dp*pl*merge(1.0_dp, 0.0_dp, bad > 0.0_dp)
    end do
    ! The apex: a second branch-free pass, only for a chunk with a deferred
    ! point, on a cone with an apex and without Duvaut-Lions.
    if (apex_on > 0.0_dp .and. p%tau == 0.0_dp) then
      if (any(status(1:n) < 0.0_dp)) call apex_return(p, n, eps_p0, z0, trial, q_trial, &
                                                      f_trial, zeta_trial, sig, eps_p, z, &
                                                      dlambda, f, status)
    end if
    if (p%tau > 0.0_dp) then
      ! Duvaut-Lions (eq. 2.10, backward Euler): relax the cone points toward
      ! the trial, in a second, scalar pass so that the rate-independent pass
      ! stays one branch-free loop. The trial's deviator and the plastic
      ! strain increment are formed again by the same operations (bitwise
      ! the first pass's).
      w = p%tau/(p%tau + dtime)
      do i = 1, n
        if (status(i) /= 1.0_dp) cycle
        st = trial(i, :)
        i1_tr = st(1) + st(2) + st(3)
        s(1:3) = st(1:3) - i1_tr/3.0_dp
        s(4:6) = st(4:6)
        q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
        xc = dlambda(i)
        dep = (rsqrt2*xc*rn/q)*s
        dep(1:3) = dep(1:3) + xc*p%beta_p*rn
        sn = sig(i, :)
        sn = sn + w*(st - sn)
        dep = (1.0_dp - w)*dep
        xc = (1.0_dp - w)*xc
        i1 = sn(1) + sn(2) + sn(3)
        s(1:3) = sn(1:3) - i1/3.0_dp
        s(4:6) = sn(4:6)
        q = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_dp*(s(4)**2 + s(5)**2 + s(6)**2))
        sig(i, :) = sn
        eps_p(i, :) = eps_p0(i, :) + dep
        z(i) = z0(i) + xc
        dlambda(i) = xc
        f(i) = q/sqrt2 + p%beta*i1 - (p%hard%k0 + p%hard%h*(z0(i) + xc)) - zeta(i)
      end do
    end if
  end subroutine block_return

  !> The apex return of point_closed_form for the points block_return
  !> deferred (status -1) whose trial lies beyond the cone's reach (beta > 0,
  !> f_tr > (a + h) x_max): sigma = s_ap I, s_ap = k(z + d)/(3 beta), d eps^p
  !> = C^-1 : (sigma_trial - sigma_apex), d = ||d eps^p|| the root of a
  !> quadratic. The deferred points are gathered into a compact list (the
  !> cost follows their number, not the chunk's), computed there branch-free
  !> with divisors kept away from zero, and a point takes the answer (status
  !> 2) only where point_closed_form finds one (disc >= 0, 0 <= d <= huge);
  !> any other stays deferred. The same operations in the same order:
  !> bitwise point_closed_form's.
  pure subroutine apex_return(p, n, eps_p0, z0, trial, q_trial, f_trial, zeta_trial, sig, &
                              eps_p, z, dlambda, f, status)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: n
    real(dp), intent(in) :: eps_p0(block_chunk, 6), z0(block_chunk), trial(block_chunk, 6)
    real(dp), intent(in) :: q_trial(block_chunk), f_trial(block_chunk), zeta_trial(block_chunk)
    real(dp), intent(inout) :: sig(block_chunk, 6), eps_p(block_chunk, 6), z(block_chunk)
    real(dp), intent(inout) :: dlambda(block_chunk), f(block_chunk), status(block_chunk)
    real(dp) :: bulk, shear, rate, c1, a2, st(6), s(6), i1_tr, q, x_max, k_n, c0, b2, c2, disc
    real(dp) :: sd, num, den, x, s_ap, dz
    ! The compact list: inputs and answers in local arrays only, so that
    ! no load can trap and no store is conditional (either would stop GCC
    ! vectorising the loop).
    real(dp) :: tr(block_chunk, 6), ep0(block_chunk, 6), ft(block_chunk), zt(block_chunk)
    real(dp) :: zc(block_chunk), qt(block_chunk), dep(block_chunk, 6), a_ap(block_chunk)
    real(dp) :: a_dz(block_chunk), a_f(block_chunk), take(block_chunk)
    integer :: i, j, k, m, idx(block_chunk)
    call deferred_points(n, status, idx, m)
    do k = 1, m
      i = idx(k)
      tr(k, :) = trial(i, :)
      ep0(k, :) = eps_p0(i, :)
      ft(k) = f_trial(i)
      zt(k) = zeta_trial(i)
      zc(k) = z0(i)
      qt(k) = q_trial(i)
    end do
    bulk = p%el%bulk
    shear = p%el%shear
    rate = p%a_m + p%hard%h
    c1 = p%hard%h/(9.0_dp*bulk*p%beta)
    a2 = 1.0_dp - 3.0_dp*c1**2
    do k = 1, m
      st = tr(k, :)
      i1_tr = st(1) + st(2) + st(3)
      s(1:3) = st(1:3) - i1_tr/3.0_dp
      s(4:6) = st(4:6)
      q = qt(k)
      x_max = q*p%n_m/(sqrt2*shear)
      k_n = p%hard%k0 + p%hard%h*zc(k) + zt(k)
      c0 = (i1_tr - k_n/p%beta)/(9.0_dp*bulk)
      b2 = 3.0_dp*c0*c1
      c2 = (q/(2.0_dp*shear))**2 + 3.0_dp*c0**2
      disc = b2**2 + a2*c2
      sd = sqrt(max(disc, 0.0_dp))
      num = merge(c2, sd - b2, b2 >= 0.0_dp)
      den = merge(b2 + sd, a2, b2 >= 0.0_dp)
      ! 1 where the answer is the apex's, a product of 0/1 masks (a logical
      ! .and. would put branches in the loop).
      take(k) = merge(1.0_dp, 0.0_dp, disc >= 0.0_dp)* &
                merge(1.0_dp, 0.0_dp, ft(k) - rate*x_max > 0.0_dp)* &
                merge(1.0_dp, 0.0_dp, abs(den) >= tiny(1.0_dp))
      x = num/merge(den, 1.0_dp, take(k) > 0.0_dp)
      take(k) = take(k)*merge(1.0_dp, 0.0_dp, x >= 0.0_dp)*merge(1.0_dp, 0.0_dp, x <= huge(x))
      x = merge(x, 0.0_dp, take(k) > 0.0_dp)
      s_ap = (k_n + p%hard%h*x)/(3.0_dp*p%beta)
      do j = 1, 6
        dep(k, j) = s(j)/(2.0_dp*shear)
      end do
      do j = 1, 3
        dep(k, j) = dep(k, j) + (i1_tr - 3.0_dp*s_ap)/(9.0_dp*bulk)
      end do
      dz = sqrt(dep(k, 1)**2 + dep(k, 2)**2 + dep(k, 3)**2 + &
                2.0_dp*(dep(k, 4)**2 + dep(k, 5)**2 + dep(k, 6)**2))
      a_ap(k) = s_ap
      a_dz(k) = dz
      a_f(k) = 3.0_dp*p%beta*s_ap - (p%hard%k0 + p%hard%h*(zc(k) + dz)) - zt(k)
    end do
    do k = 1, m
      if (take(k) == 0.0_dp) cycle
      i = idx(k)
      sig(i, 1:3) = a_ap(k)
      sig(i, 4:6) = 0.0_dp
      eps_p(i, :) = ep0(k, :) + dep(k, :)
      z(i) = zc(k) + a_dz(k)
      dlambda(i) = a_dz(k)
      f(i) = a_f(k)
      status(i) = 2.0_dp
    end do
  end subroutine apex_return

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

end module wellposed_dp_block
