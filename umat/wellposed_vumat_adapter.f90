!> The Abaqus/Explicit VUMAT contract on typed arguments: a block of nblock
!> points, PROPS, layout and DTIME checked once per block (the UMAT's checks
!> and messages), every point's inputs checked for finiteness, then the
!> UMAT's point update. Arrays (nblock, ndir + nshr), components 11, 22, 33,
!> 12, 23, 31 (or 11, 22, 33, 12), tensor shears; STATEV as the UMAT's.
!> Energies per unit mass by the trapezoidal rule:
!> (sigma_old + sigma_new) : d eps/(2 rho). Contract: docs/guide/umat.md.
module wellposed_vumat_adapter
  use wellposed_kinds, only: dp
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_finite, only: all_finite, is_finite, nonfinite_bits, range_bits, range_carry
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_tensor, only: ntens6
  use wellposed_dp_params, only: dp_params_t
  use wellposed_dp_point, only: point_update, has_closed_form
  use wellposed_dp_closed_form, only: closed_form_block, block_chunk, deferred_points
  use wellposed_hardening, only: hardening_t
  use wellposed_generalized_dl, only: gdl_update
  use wellposed_umat_adapter, only: check_props, explain, fault_non_finite, state_carry, &
                                   range_error
  use wellposed_umat_layout, only: sv_z, sv_dlambda, sv_avg_dlambda, sv_zeta, sv_eps_p, sv_f, &
                                   sv_status, nstatv_min, sv_over, sv_over_z, &
                                   nstatv_gdl
  implicit none
  private
  public :: vumat_update, vumat_props

  !> Model component i (11, 22, 33, 12, 13, 23) is VUMAT component comp(i):
  !> the model is isotropic, the order only keeps its arithmetic the UMAT's.
  integer, parameter :: comp(ntens6) = [1, 2, 3, 4, 6, 5]
  !> Blocks of fewer points go point by point (point_update, the same
  !> arithmetic): below four points the chunk's copies and the vectorised
  !> pass cost more than they save.
  integer, parameter :: min_chunk_block = 4

contains

  !> One VUMAT call on a block. Arguments as the Abaqus VUMAT's (the ones a
  !> Drucker-Prager model reads). On failure `err` is allocated (status -1
  !> invalid input, -2 non-finite input or no convergence), `point` names
  !> the point of the block at fault (0: the block's PROPS, layout or DT),
  !> STATENEW(point, 12) holds the status when it can, and the New arrays are
  !> otherwise untouched when the inputs were at fault (a return that fails
  !> to converge may leave earlier points of the block updated). `checked`:
  !> the block's PROPS, layout and DT as vumat_props accepted them (a host
  !> calling with the same ones many times checks them once).
  subroutine vumat_update(nblock, ndir, nshr, nstatev, nprops, step_time, total_time, dt, &
                          props, density, strain_inc, stress_old, state_old, ener_intern_old, &
                          ener_inelas_old, stress_new, state_new, ener_intern_new, &
                          ener_inelas_new, err, point, checked)
    integer, intent(in) :: nblock, ndir, nshr, nstatev, nprops
    real(dp), intent(in) :: step_time, total_time, dt, props(nprops), density(nblock)
    real(dp), intent(in) :: strain_inc(nblock, ndir + nshr), stress_old(nblock, ndir + nshr)
    real(dp), intent(in) :: state_old(nblock, nstatev), ener_intern_old(nblock)
    real(dp), intent(in) :: ener_inelas_old(nblock)
    real(dp), intent(inout) :: stress_new(nblock, ndir + nshr), state_new(nblock, nstatev)
    real(dp), intent(inout) :: ener_intern_new(nblock), ener_inelas_new(nblock)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out) :: point
    type(dp_params_t), intent(in), optional :: checked
    type(dp_params_t) :: p
    logical :: packaging

    point = 0
    if (present(checked)) then
      call check_points(checked, nblock, ndir, ndir + nshr, nstatev, &
                        merge(nstatv_gdl, nstatv_min, checked%gdl), density, strain_inc, &
                        stress_old, state_old, ener_intern_old, ener_inelas_old, err, point)
    else
      call vumat_props(ndir, nshr, nstatev, nprops, props, dt, p, err)
      if (allocated(err)) return
      call check_points(p, nblock, ndir, ndir + nshr, nstatev, merge(nstatv_gdl, nstatv_min, &
                        p%gdl), density, strain_inc, stress_old, state_old, ener_intern_old, &
                        ener_inelas_old, err, point)
    end if
    if (allocated(err)) then
      state_new(point, sv_status) = real(err%status, dp)
      return
    end if

    ! Abaqus/Explicit's packaging call (stepTime = totalTime = 0) asks for
    ! the elastic response to fictitious strains: a strength no stress
    ! reaches, no nonlocal or viscous part, the state kept.
    packaging = step_time == 0.0_dp .and. total_time == 0.0_dp
    if (packaging .or. .not. present(checked)) then
      if (present(checked)) p = checked
      if (packaging) then
        p%hard = hardening_t(0.25_dp*huge(1.0_dp), 0.0_dp, 0.0_dp, 0.0_dp)
        p%h_zeta = 0.0_dp
        p%efr = .false.
        p%gdl = .false.
      end if
      call update_points(p, packaging, nblock, ndir + nshr, nstatev, dt, density, strain_inc, &
                         stress_old, state_old, ener_intern_old, ener_inelas_old, stress_new, &
                         state_new, ener_intern_new, ener_inelas_new, err, point)
    else
      call update_points(checked, .false., nblock, ndir + nshr, nstatev, dt, density, &
                         strain_inc, stress_old, state_old, ener_intern_old, ener_inelas_old, &
                         stress_new, state_new, ener_intern_new, ener_inelas_new, err, point)
    end if
  end subroutine vumat_update

  !> The points of a checked block through the model (vumat_update's
  !> arguments; `p` as the call sees it): chunks of the closed form
  !> (update_chunk) for blocks of min_chunk_block points or more, else
  !> point by point (update_point). On error `point` names the point.
  subroutine update_points(p, packaging, nblock, ntens, nstatev, dt, density, strain_inc, &
                           stress_old, state_old, ener_intern_old, ener_inelas_old, stress_new, &
                           state_new, ener_intern_new, ener_inelas_new, err, point)
    type(dp_params_t), intent(in) :: p
    logical, intent(in) :: packaging
    integer, intent(in) :: nblock, ntens, nstatev
    real(dp), intent(in) :: dt, density(nblock), strain_inc(nblock, ntens)
    real(dp), intent(in) :: stress_old(nblock, ntens), state_old(nblock, nstatev)
    real(dp), intent(in) :: ener_intern_old(nblock), ener_inelas_old(nblock)
    real(dp), intent(inout) :: stress_new(nblock, ntens), state_new(nblock, nstatev)
    real(dp), intent(inout) :: ener_intern_new(nblock), ener_inelas_new(nblock)
    type(error_t), allocatable, intent(inout) :: err
    integer, intent(inout) :: point
    integer :: k, k0
    if (has_closed_form(p) .and. .not. p%gdl .and. nblock >= min_chunk_block) then
      do k0 = 1, nblock, block_chunk
        call update_chunk(p, packaging, k0, min(block_chunk, nblock - k0 + 1), nblock, ntens, &
                          nstatev, dt, density, strain_inc, stress_old, state_old, &
                          ener_intern_old, ener_inelas_old, stress_new, state_new, &
                          ener_intern_new, ener_inelas_new, err, point)
        if (allocated(err)) return
      end do
      return
    end if
    do k = 1, nblock
      call update_point(p, packaging, k, nblock, ntens, nstatev, dt, density(k), strain_inc, &
                        stress_old, state_old, ener_intern_old(k), ener_inelas_old(k), &
                        stress_new, state_new, ener_intern_new(k), ener_inelas_new(k), err)
      if (allocated(err)) then
        point = k
        state_new(k, sv_status) = real(err%status, dp)
        return
      end if
    end do
  end subroutine update_points

  !> Point k of the block through point_update (gdl_update for the
  !> generalized form): its inputs in the model's order (tensor shears
  !> already; the missing shears of plane strain are 0), its results, the
  !> STATEV slots past the contract's copied, and the energies.
  subroutine update_point(p, packaging, k, nblock, ntens, nstatev, dt, density, strain_inc, &
                          stress_old, state_old, ener_intern_old, ener_inelas_old, stress_new, &
                          state_new, ener_intern_new, ener_inelas_new, err)
    type(dp_params_t), intent(in) :: p
    logical, intent(in) :: packaging
    integer, intent(in) :: k, nblock, ntens, nstatev
    real(dp), intent(in) :: dt, density, strain_inc(nblock, ntens), stress_old(nblock, ntens)
    real(dp), intent(in) :: state_old(nblock, nstatev), ener_intern_old, ener_inelas_old
    real(dp), intent(inout) :: stress_new(nblock, ntens), state_new(nblock, nstatev)
    real(dp), intent(inout) :: ener_intern_new, ener_inelas_new
    type(error_t), allocatable, intent(inout) :: err
    real(dp) :: sig(ntens6), de(ntens6), eps_p(ntens6), sig0(ntens6), eps_p0(ntens6)
    real(dp) :: over(ntens6), z, zeta, z_over, dlambda, f
    integer :: i, j, status
    ! comp is its own inverse: VUMAT column j holds model component comp(j).
    sig0 = 0.0_dp
    de = 0.0_dp
    do j = 1, ntens
      sig0(comp(j)) = stress_old(k, j)
      de(comp(j)) = strain_inc(k, j)
    end do
    do j = 1, ntens6
      eps_p0(comp(j)) = state_old(k, sv_eps_p - 1 + j)
    end do
    sig = sig0
    eps_p = eps_p0
    z = state_old(k, sv_z)
    zeta = state_old(k, sv_zeta)
    if (p%gdl) then
      do i = 1, ntens6
        over(i) = state_old(k, sv_over - 1 + comp(i))
      end do
      z_over = state_old(k, sv_over_z)
      call gdl_update(p, sig, eps_p, z, zeta, over, z_over, state_old(k, sv_avg_dlambda), de, &
                      dt, dlambda, f, status, ntens, err=err)
    else
      call point_update(p, sig, eps_p, z, zeta, state_old(k, sv_avg_dlambda), de, dt, &
                        dlambda, f, status, ntens, err=err)
    end if
    if (allocated(err)) return
    if (packaging) f = state_old(k, sv_f)
    do j = 1, ntens
      stress_new(k, j) = sig(comp(j))
    end do
    do j = 1, ntens6
      state_new(k, sv_eps_p - 1 + j) = eps_p(comp(j))
    end do
    state_new(k, sv_z) = z
    state_new(k, sv_dlambda) = dlambda
    state_new(k, sv_avg_dlambda) = state_old(k, sv_avg_dlambda)
    state_new(k, sv_zeta) = zeta
    state_new(k, sv_f) = f
    state_new(k, sv_status) = real(status, dp)
    do i = nstatv_min + 1, nstatev
      state_new(k, i) = state_old(k, i)
    end do
    if (p%gdl) then
      do i = 1, ntens6
        state_new(k, sv_over - 1 + comp(i)) = over(i)
      end do
      state_new(k, sv_over_z) = z_over
    end if
    sig0 = sig0 + sig
    ener_intern_new = ener_intern_old + 0.5_dp*contract(sig0, de)/density
    eps_p = eps_p - eps_p0
    ener_inelas_new = ener_inelas_old + 0.5_dp*contract(sig0, eps_p)/density
  end subroutine update_point

  !> Points k0 .. k0 + n - 1 (n <= block_chunk) of a closed-form block: into
  !> the chunk arrays in the model's order, one vectorised pass
  !> (closed_form_block), the rare deferred points through point_update,
  !> the results into the New arrays with the energies (as update_point).
  subroutine update_chunk(p, packaging, k0, n, nblock, ntens, nstatev, dt, density, strain_inc, &
                          stress_old, state_old, ener_intern_old, ener_inelas_old, stress_new, &
                          state_new, ener_intern_new, ener_inelas_new, err, point)
    type(dp_params_t), intent(in) :: p
    logical, intent(in) :: packaging
    integer, intent(in) :: k0, n, nblock, ntens, nstatev
    real(dp), intent(in) :: dt, density(nblock), strain_inc(nblock, ntens)
    real(dp), intent(in) :: stress_old(nblock, ntens), state_old(nblock, nstatev)
    real(dp), intent(in) :: ener_intern_old(nblock), ener_inelas_old(nblock)
    real(dp), intent(inout) :: stress_new(nblock, ntens), state_new(nblock, nstatev)
    real(dp), intent(inout) :: ener_intern_new(nblock), ener_inelas_new(nblock)
    type(error_t), allocatable, intent(inout) :: err
    integer, intent(inout) :: point
    integer, parameter :: chunk = block_chunk
    ! One chunk in the block kernel's layout (its arrays stay in L1 cache).
    real(dp) :: c_sig0(chunk, ntens6), c_ep0(chunk, ntens6), c_de(chunk, ntens6)
    real(dp) :: c_sig(chunk, ntens6), c_ep(chunk, ntens6), c_z0(chunk), c_zeta0(chunk)
    real(dp) :: c_avg(chunk), c_z(chunk), c_zeta(chunk), c_dl(chunk), c_f(chunk)
    real(dp) :: c_st(chunk), c_trial(chunk, ntens6)
    real(dp) :: sig(ntens6), de(ntens6), eps_p(ntens6), ss(ntens6), z, zeta, dlambda, f
    integer :: defer(chunk), ndefer, i, j, kk, status
    do i = 1, ntens6
      if (comp(i) <= ntens) then
        c_sig0(1:n, i) = stress_old(k0:k0 + n - 1, comp(i))
        c_de(1:n, i) = strain_inc(k0:k0 + n - 1, comp(i))
      else
        c_sig0(1:n, i) = 0.0_dp
        c_de(1:n, i) = 0.0_dp
      end if
      c_ep0(1:n, i) = state_old(k0:k0 + n - 1, sv_eps_p - 1 + comp(i))
    end do
    c_z0(1:n) = state_old(k0:k0 + n - 1, sv_z)
    c_zeta0(1:n) = state_old(k0:k0 + n - 1, sv_zeta)
    c_avg(1:n) = state_old(k0:k0 + n - 1, sv_avg_dlambda)
    call closed_form_block(p, n, c_sig0, c_ep0, c_z0, c_zeta0, c_avg, c_de, dt, c_sig, c_ep, &
                           c_z, c_zeta, c_dl, c_f, c_st, c_trial)
    call deferred_points(n, c_st, defer, ndefer)
    do j = 1, ndefer
      i = defer(j)
      sig = c_sig0(i, :)
      eps_p = c_ep0(i, :)
      z = c_z0(i)
      zeta = c_zeta0(i)
      de = c_de(i, :)  ! a contiguous copy: no array temporary in the call
      call point_update(p, sig, eps_p, z, zeta, c_avg(i), de, dt, dlambda, f, status, ntens, &
                        err=err)
      if (allocated(err)) then
        point = k0 - 1 + i
        state_new(point, sv_status) = real(err%status, dp)
        return
      end if
      c_sig(i, :) = sig
      c_ep(i, :) = eps_p
      c_z(i) = z
      c_zeta(i) = zeta
      c_dl(i) = dlambda
      c_f(i) = f
      c_st(i) = real(status, dp)
    end do
    if (packaging) c_f(1:n) = state_old(k0:k0 + n - 1, sv_f)
    do i = 1, ntens6
      if (comp(i) <= ntens) stress_new(k0:k0 + n - 1, comp(i)) = c_sig(1:n, i)
      state_new(k0:k0 + n - 1, sv_eps_p - 1 + comp(i)) = c_ep(1:n, i)
    end do
    state_new(k0:k0 + n - 1, sv_z) = c_z(1:n)
    state_new(k0:k0 + n - 1, sv_dlambda) = c_dl(1:n)
    state_new(k0:k0 + n - 1, sv_avg_dlambda) = c_avg(1:n)
    state_new(k0:k0 + n - 1, sv_zeta) = c_zeta(1:n)
    state_new(k0:k0 + n - 1, sv_f) = c_f(1:n)
    state_new(k0:k0 + n - 1, sv_status) = c_st(1:n)
    do i = nstatv_min + 1, nstatev
      state_new(k0:k0 + n - 1, i) = state_old(k0:k0 + n - 1, i)
    end do
    do i = 1, n
      kk = k0 - 1 + i
      ! Rows copied to contiguous vectors: no array temporaries (no heap).
      ss = c_sig0(i, :) + c_sig(i, :)
      de = c_de(i, :)
      ener_intern_new(kk) = ener_intern_old(kk) + 0.5_dp*contract(ss, de)/density(kk)
      de = c_ep(i, :) - c_ep0(i, :)
      ener_inelas_new(kk) = ener_inelas_old(kk) + 0.5_dp*contract(ss, de)/density(kk)
    end do
  end subroutine update_chunk

  !> The checks of a VUMAT call that concern the whole block: layout,
  !> NSTATEV, PROPS and DT, as the UMAT checks them; `p` their parameters,
  !> else `err` (status -1).
  pure subroutine vumat_props(ndir, nshr, nstatev, nprops, props, dt, p, err)
    integer, intent(in) :: ndir, nshr, nstatev, nprops
    real(dp), intent(in) :: props(nprops), dt
    type(dp_params_t), intent(inout) :: p
    type(error_t), allocatable, intent(out) :: err
    integer :: fault
    logical :: want_tangent
    call check_props(ndir, nshr, ndir + nshr, nstatev, nprops, props, dt, p, want_tangent, fault)
    if (fault /= 0) call explain(fault, ndir, nshr, ndir + nshr, nstatev, nprops, props, dt, err)
  end subroutine vumat_props

  !> range_bits of wellposed_finite (negative when x's exponent field
  !> exceeds `limit`), here so that the checks' loops inline it: a call per
  !> value costs more than the test.
  elemental integer(int64) function exceeds(x, limit)
    real(dp), intent(in) :: x
    integer(int64), intent(in) :: limit
    exceeds = limit - iand(transfer(x, 0_int64), int(z'7FF0000000000000', int64))
  end function exceeds

  !> a : b of two symmetric tensors in tensor components.
  pure function contract(a, b) result(c)
    real(dp), intent(in) :: a(ntens6), b(ntens6)
    real(dp) :: c
    c = a(1)*b(1) + a(2)*b(2) + a(3)*b(3) + 2.0_dp*(a(4)*b(4) + a(5)*b(5) + a(6)*b(6))
  end function contract

  !> Every point's inputs: finite stress, strain increment, STATEV slots
  !> 1-nsv (the ones the model reads) and energies, stresses and strains
  !> within the material's limits as the UMAT checks them (engineering
  !> shears: twice the VUMAT's) (else status -2), density finite and > 0
  !> (else -1). `point` is the first point at fault.
  pure subroutine check_points(p, nblock, ndir, ntens, nstatev, nsv, density, strain_inc, &
                               stress_old, state_old, ener_intern_old, ener_inelas_old, err, point)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: nblock, ndir, ntens, nstatev, nsv
    real(dp), intent(in) :: density(nblock), strain_inc(nblock, ntens)
    real(dp), intent(in) :: stress_old(nblock, ntens), state_old(nblock, nstatev)
    real(dp), intent(in) :: ener_intern_old(nblock), ener_inelas_old(nblock)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out) :: point
    character(len=*), parameter :: name = 'non-finite stressOld, strainInc, stateOld or energy '
    ! One binade: the limit of an engineering shear (2 eps) on eps itself.
    integer(int64), parameter :: binade = int(z'0010000000000000', int64)
    ! The limit of a slot that need only be finite: the exponent of huge
    ! (range_bits < 0 only for an all-ones exponent, Inf or NaN).
    integer(int64), parameter :: finite_only = int(z'7FE0000000000000', int64)
    ! What each STATEV slot is (umat_layout): 1 a strain, 2 a stress, 3 a
    ! value that need only be finite, 4 a shear strain (tensor: limit / 2).
    integer, parameter :: slot_kind(nstatv_gdl) = [1, 3, 1, 2, 1, 1, 1, 4, 4, 4, 3, 3, &
                                                   2, 2, 2, 2, 2, 2, 1]
    integer(int64) :: carry, lim(4)
    real(dp) :: sig(ntens6), de(ntens6), sv(nstatv_gdl)  ! fixed size: no heap
    integer :: j, k
    ! Every value tested into one carry: the usual all-valid block costs one
    ! pass and one branch. Plain loops, not finite_carry per column: its
    ! vector prologue per column costs more than it saves on small blocks;
    ! a block of a few points goes point by point.
    lim = [p%strain_limit, p%stress_limit, finite_only, p%strain_limit - binade]
    carry = 0
    if (nblock < min_chunk_block) then
      do k = 1, nblock
        carry = ior(carry, ior(nonfinite_bits(density(k)), ior(nonfinite_bits( &
                ener_intern_old(k)), nonfinite_bits(ener_inelas_old(k)))))
        do j = 1, ntens
          carry = ior(carry, ior(exceeds(strain_inc(k, j), lim(merge(4, 1, j > ndir))), &
                                 exceeds(stress_old(k, j), p%stress_limit)))
        end do
        ! the usual NSTATV as a constant: the loop unrolled
        if (nsv == nstatv_min) then
          do j = 1, nstatv_min
            carry = ior(carry, exceeds(state_old(k, j), lim(slot_kind(j))))
          end do
        else
          do j = 1, nsv
            carry = ior(carry, exceeds(state_old(k, j), lim(slot_kind(j))))
          end do
        end if
        carry = ior(carry, transfer(state_old(k, sv_z) + 0.0_dp, carry))  ! z >= 0; -0.0 is 0
      end do
    else
      do k = 1, nblock
        carry = ior(carry, ior(nonfinite_bits(density(k)), ior(nonfinite_bits( &
                ener_intern_old(k)), nonfinite_bits(ener_inelas_old(k)))))
      end do
      do j = 1, ntens
        do k = 1, nblock
          carry = ior(carry, ior(exceeds(strain_inc(k, j), lim(merge(4, 1, j > ndir))), &
                                 exceeds(stress_old(k, j), p%stress_limit)))
        end do
      end do
      do j = 1, nsv
        do k = 1, nblock
          carry = ior(carry, exceeds(state_old(k, j), lim(slot_kind(j))))
        end do
      end do
      do k = 1, nblock
        carry = ior(carry, transfer(state_old(k, sv_z) + 0.0_dp, carry))  ! z >= 0; -0.0 is 0
      end do
    end if
    point = 0
    if (carry >= 0) then
      if (all(density > 0.0_dp)) return
    end if
    do point = 1, nblock
      if (.not. (all_finite(strain_inc(point, :)) .and. all_finite(stress_old(point, :)) .and. &
                 all_finite(state_old(point, 1:nsv)) .and. &
                 is_finite(ener_intern_old(point)) .and. is_finite(ener_inelas_old(point)))) then
        call new_error(err, status_cutback, '', name//'on input (point '//int_text(point)// &
          ' of the block)')
        return
      end if
      ! The UMAT's layout (engineering shears) for its range test and message.
      sig = 0.0_dp
      de = 0.0_dp
      do j = 1, ntens6
        if (comp(j) > ntens) cycle
        sig(j) = stress_old(point, comp(j))
        de(j) = merge(2.0_dp, 1.0_dp, j > 3)*strain_inc(point, comp(j))
      end do
      sv(1:nsv) = state_old(point, 1:nsv)
      sv(sv_eps_p + 3:sv_eps_p + 5) = 2.0_dp*sv(sv_eps_p + 3:sv_eps_p + 5)
      if (ior(state_carry(p, sv(1:nsv)), ior(range_carry(sig, p%stress_limit), &
                                      range_carry(de, p%strain_limit))) < 0) then
        call new_error(err, status_cutback, '', 'out of range')
        call range_error(p, sig, de, sv(1:nsv), err)
        err%message = err%message//' (point '//int_text(point)//' of the block; VUMAT order)'
        return
      else if (.not. is_finite(density(point))) then
        exit
      else if (.not. density(point) > 0.0_dp) then
        exit
      end if
    end do
    call new_error(err, status_invalid, 'density', 'density = '//real_text(density(point))// &
      ' (point '//int_text(point)//' of the block) is out of range: valid is > 0')

  end subroutine check_points

end module wellposed_vumat_adapter
