!> Particles of one material through the linked VUMAT, a block at a time
!> (docs/guide/mpm.md, "Hosting a UMAT in the MPM"): the particles' STRESS,
!> STATEV and increments (UMAT order, engineering shears) gathered into the
!> VUMAT's arrays (order 11, 22, 33, 12, 23, 31, tensor shears), one call,
!> the answers scattered back. Ours goes through its typed entry
!> vumat_update (the external `vumat` forwards to it and stops on error), its
!> STATEV converted to the UMAT's layout; a user's VUMAT gets its STATEV as is.
module wellposed_mpm_vumat_call
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_finite, only: all_finite
  use wellposed_text, only: int_text, real_text
  use wellposed_vumat_adapter, only: vumat_update, vumat_props
  use wellposed_dp_params, only: dp_params_t
  use wellposed_vumat_interface, only: vumat
  use wellposed_abaqus_job, only: abaqus_take_error
  use wellposed_umat_layout, only: sv_dlambda, sv_avg_dlambda, sv_eps_p, sv_over, nstatv_gdl
  use wellposed_umat_host, only: umat_host_t, host_update, vumat_is_ours
  use wellposed_umat_adapter, only: umat_update_checked
  implicit none
  private
  public :: vumat_work_t, vumat_particles, vumat_point, vumat_block, material_update

  !> Points per VUMAT call (Abaqus/Explicit's blocks are of this order).
  integer, parameter :: vumat_block = 128
  !> UMAT component j (11, 22, 33, 12, 13, 23) is VUMAT component vcol(j).
  integer, parameter :: vcol(6) = [1, 2, 3, 4, 6, 5]

  !> One block's VUMAT arrays, each a run of memory holding an (n, columns)
  !> array for the block's n points (passed whole: no copy in the call).
  type :: vumat_work_t
    integer :: ntens = 0, nstatv = 0
    real(dp), allocatable :: de(:), s_old(:), s_new(:), sv_old(:), sv_new(:)
    real(dp), allocatable :: dens(:), en_old(:), en_new(:), en_new2(:)
    !> what a user's VUMAT is also passed: positions, lengths, spins,
    !> temperatures (zero), stretches and F (the identity); ours reads none
    real(dp), allocatable :: zeros(:), ones(:), stretch(:), defgrad(:), field(:)
  end type vumat_work_t

  !> What a call of the VUMAT is told about its material and step.
  type, public :: vumat_material_t
    real(dp), allocatable :: props(:)
    logical :: ours = .true.       !< the linked VUMAT is wellposed's (our STATEV layout)
    logical :: contract = .true.   !< STATEV 3 in, STATEV 2 out (Algorithm 1)
    character(len=80) :: cmname = 'WELLPOSED'
    real(dp) :: density = 0.0_dp
    real(dp) :: celent = 1.0_dp    !< charLength (the cell size)
    !> ours: the block checks of PROPS, layout and DT, made once for dt = par_dt
    type(dp_params_t) :: par
    real(dp) :: par_dt = -1.0_dp
    logical :: par_ok = .false.
  end type vumat_material_t

contains

  !> Particles idx(1:m) of material `mat` over the step from t of length dt
  !> (the VUMAT is told the time at the increment's end, so no step is its
  !> packaging call): stress, statev, stran (rows 1:nt, NSTATV x n) in place
  !> from the increments de (NTENS nt), with STATEV(3) = avg(q) (0 when
  !> absent) under the contract; done(q) for each answered, dl(q) its STATEV(2) (else 0).
  !> Ours: a block it refuses, or answers with a non-finite value, is left
  !> untouched (done false) for the UMAT's per-particle call and its rules.
  !> A user's: a message raised in the call or a non-finite answer is `err`,
  !> naming the particle by gid.
  subroutine vumat_particles(w, mat, nt, t, dt, idx, gid, de, stress, statev, stran, dl, done, &
                             err, avg)
    type(vumat_work_t), intent(inout) :: w
    type(vumat_material_t), intent(inout) :: mat
    integer, intent(in) :: nt
    real(dp), intent(in) :: t, dt
    integer, intent(in) :: idx(:), gid(:)
    real(dp), intent(in) :: de(:, :)
    real(dp), intent(inout) :: stress(:, :), statev(:, :), stran(:, :)
    real(dp), intent(out) :: dl(:)
    logical, intent(out) :: done(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: avg(:)
    integer :: nv, k0, n, i, p, bad
    logical :: ok
    nv = size(statev, 1)
    call size_work(w, nt, nv)
    dl(1:size(idx)) = 0.0_dp
    done(1:size(idx)) = .false.
    do k0 = 1, size(idx), vumat_block
      n = min(vumat_block, size(idx) - k0 + 1)
      do i = 1, n
        p = idx(k0 - 1 + i)
        call point_in(n, i, nt, nv, mat%ours, stress(:, p), de(:, p), statev(:, p), w%s_old, &
                      w%de, w%sv_old)
        if (mat%contract) then
          w%sv_old(i + (sv_avg_dlambda - 1)*n) = 0.0_dp
          if (present(avg)) w%sv_old(i + (sv_avg_dlambda - 1)*n) = avg(k0 - 1 + i)
        end if
      end do
      ! ours writes every New entry of a block it answers (a refused block
      ! is dropped); a user's VUMAT may leave some as they came
      if (.not. mat%ours) then
        w%s_new(1:n*nt) = w%s_old(1:n*nt)
        w%sv_new(1:n*nv) = w%sv_old(1:n*nv)
      end if
      call call_vumat(w, mat, n, t, dt, ok, bad, err)
      ! STRAN, which the VUMAT does not read, finite as the UMAT wants it
      do i = 1, n
        if (.not. ok) exit
        if (all_finite(stran(1:nt, idx(k0 - 1 + i)))) cycle
        ok = .false.
        bad = i
      end do
      if (.not. ok) then
        if (mat%ours) cycle
        if (.not. allocated(err)) call new_error(err, status_invalid, 'vumat', 'the VUMAT '// &
          'returned a non-finite stressNew or stateNew for particle '// &
          int_text(gid(idx(k0 - 1 + bad)))//' at time '//real_text(t + dt))
        if (bad == 0) err%message = err%message//' (the block of particle '// &
          int_text(gid(idx(k0)))//' on)'
        return
      end if
      do i = 1, n
        p = idx(k0 - 1 + i)
        call point_out(n, i, nt, nv, mat%ours, w%s_new, w%sv_new, stress(:, p), statev(:, p))
        stran(1:nt, p) = stran(1:nt, p) + de(1:nt, p)
        if (mat%contract) dl(k0 - 1 + i) = statev(sv_dlambda, p)
        done(k0 - 1 + i) = .true.
      end do
    end do
  end subroutine vumat_particles

  !> One particle of our VUMAT's material again from its start of step with
  !> STATEV(3) = avg (Algorithm 1's sweeps): the UMAT's increment on the
  !> particle's own arrays with the block checks the VUMAT made for this dt
  !> (umat_update_checked: the VUMAT's answer for a block of one, bit for
  !> bit, without the copies into its layout and back). Not done (the arrays
  !> to be restored) where the VUMAT path must decide: checks not made for
  !> this dt, a point it refuses, a non-finite answer.
  subroutine vumat_point(mat, nt, dt, s, sv, e, d, avg, dl, done)
    type(vumat_material_t), intent(in) :: mat
    integer, intent(in) :: nt
    real(dp), intent(in) :: dt, d(nt), avg
    real(dp), intent(inout) :: s(nt), sv(:), e(nt)
    real(dp), intent(out) :: dl
    logical, intent(out) :: done
    dl = 0.0_dp
    done = .false.
    if (.not. (mat%ours .and. mat%contract .and. mat%par_ok .and. mat%par_dt == dt)) return
    sv(sv_avg_dlambda) = avg
    call umat_update_checked(mat%par, nt, s, sv, d, e, dt, done)
    if (.not. done) return
    done = all_finite(s) .and. all_finite(sv)
    if (.not. done) return
    e = e + d
    dl = sv(sv_dlambda)
  end subroutine vumat_point

  !> One point of a material as host_update advances it (its arguments;
  !> the step host%time, host%dtime), through the linked VUMAT when `vumat`
  !> (a block of one: density 1, our slots where the VUMAT is ours), else,
  !> or when our VUMAT refuses it, through host_update: a probe of the
  !> material by the interface its particles are called through.
  subroutine material_update(host, props, vumat, stress, statev, stran, dstran, nsub, err)
    type(umat_host_t), intent(inout) :: host
    real(dp), intent(in), contiguous :: props(:), dstran(:)
    logical, intent(in) :: vumat
    real(dp), intent(inout), contiguous :: stress(:), statev(:), stran(:)
    integer, intent(out) :: nsub
    type(error_t), allocatable, intent(out) :: err
    type(vumat_work_t) :: w
    type(vumat_material_t) :: mat
    real(dp) :: s(6, 1), sv(size(statev), 1), e(6, 1), d(6, 1), dl(1)
    logical :: done(1)
    integer :: nt
    nt = host%ntens
    nsub = 1
    if (vumat) then
      mat = vumat_material_t(props, vumat_is_ours(), vumat_is_ours(), host%cmname, 1.0_dp, &
                             host%celent)
      s(1:nt, 1) = stress(1:nt)
      sv(:, 1) = statev
      e(1:nt, 1) = stran(1:nt)
      d(1:nt, 1) = dstran(1:nt)
      call vumat_particles(w, mat, nt, host%time(2), host%dtime, [1], [host%noel], d, s, sv, e, &
                           dl, done, err)
      if (allocated(err)) return
      if (done(1)) then
        stress(1:nt) = s(1:nt, 1)
        statev = sv(:, 1)
        stran(1:nt) = e(1:nt, 1)
        return
      end if
    end if
    call host_update(host, props, stress, statev, stran, dstran, nsub, err)
  end subroutine material_update

  !> One call on the block's n points; ok when it answered with finite
  !> values (else bad: the point at fault, 0 when unknown; a user's message
  !> raised in the call is err).
  subroutine call_vumat(w, mat, n, t, dt, ok, bad, err)
    type(vumat_work_t), intent(inout) :: w
    type(vumat_material_t), intent(inout) :: mat
    integer, intent(in) :: n
    real(dp), intent(in) :: t, dt
    logical, intent(out) :: ok
    integer, intent(out) :: bad
    type(error_t), allocatable, intent(inout) :: err
    type(error_t), allocatable :: e
    character(len=:), allocatable :: message
    integer :: nt, nv, nr, ii
    nt = w%ntens
    nv = w%nstatv
    nr = nt - 3
    bad = 0
    w%dens(1:n) = mat%density
    w%en_old(1:n) = 0.0_dp
    if (mat%ours) then
      ! the block checks once a step (they depend on PROPS, layout and DT only)
      if (.not. mat%par_dt == dt) then
        call vumat_props(3, nr, nv, size(mat%props), mat%props, dt, mat%par, e)
        mat%par_ok = .not. allocated(e)
        mat%par_dt = dt
      end if
      ok = mat%par_ok
      if (.not. ok) return
      call vumat_update(n, 3, nr, nv, size(mat%props), t + dt, t + dt, dt, mat%props, w%dens, &
                        w%de, w%s_old, w%sv_old, w%en_old, w%en_old, w%s_new, w%sv_new, &
                        w%en_new, w%en_new2, e, bad, mat%par)
      ok = .not. allocated(e)
      if (.not. ok) return
    else
      w%ones(1:n) = mat%celent
      call identity(w%stretch, n, nt)
      call identity(w%defgrad, n, nt + nr)
      call vumat(n, 3, nr, nv, 1, size(mat%props), 0, t + dt, t + dt, dt, mat%cmname, w%zeros, &
                 w%ones, mat%props, w%dens, w%de, w%zeros, w%zeros, w%stretch, w%defgrad, &
                 w%field, w%s_old, w%sv_old, w%en_old, w%en_old, w%zeros, w%stretch, &
                 w%defgrad, w%field, w%s_new, w%sv_new, w%en_new, w%en_new2)
      call abaqus_take_error(message)
      if (allocated(message)) then
        ok = .false.
        call new_error(err, status_invalid, 'vumat', 'the VUMAT stopped the run: '//message)
        return
      end if
    end if
    ok = all_finite(w%s_new(1:n*nt)) .and. all_finite(w%sv_new(1:n*nv))
    if (ok) return
    do ii = 1, n
      if (.not. (all_finite(w%s_new(ii:n*nt:n)) .and. all_finite(w%sv_new(ii:n*nv:n)))) exit
    end do
    bad = ii
  end subroutine call_vumat

  !> x(1:n*m) an (n, m) array whose first three columns are 1, the rest 0.
  pure subroutine identity(x, n, m)
    real(dp), intent(inout) :: x(:)
    integer, intent(in) :: n, m
    x(1:3*n) = 1.0_dp
    x(3*n + 1:m*n) = 0.0_dp
  end subroutine identity

  !> The block arrays for NTENS nt and NSTATV nv (kept when they fit).
  subroutine size_work(w, nt, nv)
    type(vumat_work_t), intent(inout) :: w
    integer, intent(in) :: nt, nv
    integer :: nb
    if (w%ntens == nt .and. w%nstatv == nv) return
    if (allocated(w%de)) deallocate (w%de, w%s_old, w%s_new, w%sv_old, w%sv_new, w%dens, &
                                     w%en_old, w%en_new, w%en_new2, w%zeros, w%ones, &
                                     w%stretch, w%defgrad, w%field)
    nb = vumat_block
    allocate (w%de(nb*nt), w%s_old(nb*nt), w%s_new(nb*nt), w%sv_old(nb*nv), w%sv_new(nb*nv), &
              w%dens(nb), w%en_old(nb), w%en_new(nb), w%en_new2(nb), w%zeros(3*nb), &
              w%ones(nb), w%stretch(nb*nt), w%defgrad(nb*9), w%field(nb))
    w%ntens = nt
    w%nstatv = nv
    w%zeros = 0.0_dp
    w%field = 0.0_dp
  end subroutine size_work

  !> A particle's STRESS s, increment d and STATEV sv (NTENS nt, NSTATV nv)
  !> into row i of the block's (n, columns) arrays s_old, de, sv_old: VUMAT
  !> order, tensor shears in the increment; the STATEV as is for a user's
  !> VUMAT, for ours the plastic strain (5-10) in the VUMAT's order with
  !> tensor shears (halved, as our UMAT halves them) and the overstress
  !> (13-18) in its order. Explicit-shape arrays: plain indexing.
  pure subroutine point_in(n, i, nt, nv, ours, s, d, sv, s_old, de, sv_old)
    integer, intent(in) :: n, i, nt, nv
    logical, intent(in) :: ours
    real(dp), intent(in) :: s(:), d(:), sv(:)
    real(dp), intent(inout) :: s_old(n, nt), de(n, nt), sv_old(n, nv)
    integer :: j
    do j = 1, nt
      s_old(i, vcol(j)) = s(j)
      de(i, vcol(j)) = merge(0.5_dp, 1.0_dp, j > 3)*d(j)
    end do
    do j = 1, nv
      sv_old(i, j) = sv(j)
    end do
    if (.not. ours) return
    do j = 1, 6
      sv_old(i, sv_eps_p - 1 + vcol(j)) = merge(0.5_dp, 1.0_dp, j > 3)*sv(sv_eps_p - 1 + j)
    end do
    if (nv < nstatv_gdl) return
    do j = 1, 6
      sv_old(i, sv_over - 1 + vcol(j)) = sv(sv_over - 1 + j)
    end do
  end subroutine point_in

  !> Row i's answer (of the block's s_new, sv_new) into a particle's STRESS
  !> and STATEV (the inverse of point_in; engineering shears doubled, as our
  !> UMAT doubles them).
  pure subroutine point_out(n, i, nt, nv, ours, s_new, sv_new, s, sv)
    integer, intent(in) :: n, i, nt, nv
    logical, intent(in) :: ours
    real(dp), intent(in) :: s_new(n, nt), sv_new(n, nv)
    real(dp), intent(inout) :: s(:), sv(:)
    integer :: j
    do j = 1, nt
      s(j) = s_new(i, vcol(j))
    end do
    do j = 1, nv
      sv(j) = sv_new(i, j)
    end do
    if (.not. ours) return
    do j = 1, 6
      sv(sv_eps_p - 1 + j) = merge(2.0_dp, 1.0_dp, j > 3)*sv_new(i, sv_eps_p - 1 + vcol(j))
    end do
    if (nv < nstatv_gdl) return
    do j = 1, 6
      sv(sv_over - 1 + j) = sv_new(i, sv_over - 1 + vcol(j))
    end do
  end subroutine point_out

end module wellposed_mpm_vumat_call
