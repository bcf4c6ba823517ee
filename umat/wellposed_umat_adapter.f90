!> The UMAT contract implemented on typed arguments: validation, unpacking
!> of PROPS/STATEV, the call of the point update (wellposed_dp_point, in
!> tensor components: the Abaqus<->model conversion is a factor 1/2 on the
!> engineering shears), packing back, and the contract's error behaviour
!> (docs/guide/umat.md). The external `umat` (umat.f90) only forwards here and
!> prints the message of an invalid input; hosts and tests that want the
!> message as a value call umat_update directly.
module wellposed_umat_adapter
  use wellposed_kinds, only: dp
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_finite, only: is_finite, all_finite, finite_carry, range_carry, range_bits
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_tensor, only: ntens6
  use wellposed_dp_params, only: dp_params_t, new_dp_params, fill_dp_params, set_dl_form, &
                                 n_params
  use wellposed_dp_point, only: point_update, voigt_stiffness, elastic_energy
  use wellposed_generalized_dl, only: gdl_update
  use wellposed_return_mapping, only: state_elastic
  use wellposed_text, only: int_text, real_text
  use wellposed_umat_layout
  implicit none
  private
  public :: umat_update, umat_update_checked, cutback_factor, failure_pnewdt, check_props, explain, fault_non_finite, &
            state_carry, range_error

  !> PNEWDT requested on status -2 (a smaller increment may succeed).
  real(dp), parameter :: cutback_factor = 0.5_dp

  !> What the checks of umat_update find, in the order they check.
  integer, parameter :: fault_layout = 1, fault_nstatv = 2, fault_nprops = 3, &
                        fault_extra_prop = 4, fault_params = 5, fault_explicit = 6, &
                        fault_dtime = 7, fault_non_finite = 8, fault_dl_form = 9, &
                        fault_nstatv_gdl = 10
  !> @var fault_non_finite
  !> The fault of a non-finite input (the VUMAT names it per point too).

contains

  !> One UMAT increment. Arguments as in the Abaqus UMAT. On failure `err`
  !> is allocated (status -1 invalid input, -2 cut back), STATEV(12) holds the
  !> status when NSTATV >= 12, PNEWDT < 1, STRESS and the other STATEV slots
  !> are untouched and DDSDDE is the elastic stiffness where K and G are valid.
  !> Every check runs on every call; text is built only for a failure.
  subroutine umat_update(stress, statev, ddsdde, sse, spd, dstran, stran, dtime, ndi, nshr, &
                         ntens, nstatv, props, nprops, pnewdt, err)
    integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(inout) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
    real(dp), intent(inout) :: sse, spd, pnewdt
    real(dp), intent(in) :: dstran(ntens), stran(ntens), dtime, props(nprops)
    type(error_t), allocatable, intent(out) :: err
    type(dp_params_t) :: p
    real(dp) :: sig(ntens6), sig_n(ntens6), de(ntens6), dep(ntens6)
    integer :: fault, status
    logical :: want_tangent

    call check_props(ndi, nshr, ntens, nstatv, nprops, props, dtime, p, want_tangent, fault)
    if (fault == 0) call point_inputs(p, ntens, stress, dstran, stran, statev, sig, de, fault)
    if (fault /= 0) then
      call explain(fault, ndi, nshr, ntens, nstatv, nprops, props, dtime, err)
      if (fault == fault_non_finite) call range_error(p, sig, de, statev, err)
      call fail(); return
    end if
    sig_n = sig
    call point_increment(p, want_tangent, ntens, sig, de, statev, dtime, ddsdde, dep, status, err)
    if (allocated(err)) then
      call fail(); return
    end if
    if (ntens == ntens6) then
      stress(1:6) = sig
    else
      stress(1:4) = sig(1:4)
    end if
    ! Elastic energy density and plastic dissipation (trapezoidal rule;
    ! an elastic increment leaves eps_p, so SPD, as it is, except where a
    ! generalized Duvaut-Lions overstress relaxes).
    sse = elastic_energy(p%el%bulk, p%el%shear, sig)
    if (status /= state_elastic .or. p%gdl) then
      sig_n = sig_n + sig
      spd = spd + 0.5_dp*(sig_n(1)*dep(1) + sig_n(2)*dep(2) + sig_n(3)*dep(3) + &
                          2.0_dp*(sig_n(4)*dep(4) + sig_n(5)*dep(5) + sig_n(6)*dep(6)))
    end if

  contains

    !> The contract's failure: status slot, PNEWDT, elastic DDSDDE.
    subroutine fail()
      if (nstatv >= nstatv_min) statev(sv_status) = real(err%status, dp)
      pnewdt = failure_pnewdt(err%status, pnewdt)
      ! Nested so that no ordered comparison meets a NaN (a trap under
      ! -ffpe-trap=invalid): Fortran's .and. need not short-circuit.
      if (nprops >= prop_shear .and. ntens >= 4 .and. ntens <= 6) then
        if (all_finite(props(prop_bulk:prop_shear))) then
          if (props(prop_bulk) > 0.0_dp .and. props(prop_shear) > 0.0_dp) then
            call voigt_stiffness(props(prop_bulk), props(prop_shear), ntens, ddsdde)
          end if
        end if
      end if
    end subroutine fail

  end subroutine umat_update

  !> umat_update's increment for a host that checked the PROPS, layout and
  !> DTIME once (`p` as check_props or vumat_props gave it for them): the
  !> same checks of STRESS, STRAN, DSTRAN and STATEV and the same STRESS and
  !> STATEV, bit for bit, without DDSDDE, SSE or SPD. Not ok (every argument
  !> untouched) where umat_update would fail: the host calls it for the rules.
  pure subroutine umat_update_checked(p, ntens, stress, statev, dstran, stran, dtime, ok)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: ntens
    real(dp), intent(inout) :: stress(ntens), statev(:)
    real(dp), intent(in) :: dstran(ntens), stran(ntens), dtime
    logical, intent(out) :: ok
    type(error_t), allocatable :: err
    real(dp) :: sig(ntens6), de(ntens6), dep(ntens6), none(ntens6, ntens6)
    integer :: fault, status
    call point_inputs(p, ntens, stress, dstran, stran, statev, sig, de, fault)
    ok = fault == 0
    if (.not. ok) return
    call point_increment(p, .false., ntens, sig, de, statev, dtime, none, dep, status, err)
    ok = .not. allocated(err)
    if (ok) stress = sig(1:ntens)
  end subroutine umat_update_checked

  !> One point's inputs into the model's order (sig, de: NTENS 6 or 4 of
  !> Abaqus order 11, 22, 33, 12, 13, 23, the rest 0; engineering shears
  !> kept), every value checked OR-ed into one carry (one branch for all):
  !> finite, and (exponent tests, the same cost) stresses and strains within
  !> the material's limits (dp_params_t); fault_non_finite where one is not.
  pure subroutine point_inputs(p, ntens, stress, dstran, stran, statev, sig, de, fault)
    type(dp_params_t), intent(in) :: p
    integer, intent(in) :: ntens
    real(dp), intent(in) :: stress(ntens), dstran(ntens), stran(ntens), statev(:)
    real(dp), intent(out) :: sig(ntens6), de(ntens6)
    integer, intent(out) :: fault
    integer(int64) :: carry
    ! NTENS is 6 or 4 here: literal bounds let the compiler unroll the copies.
    if (ntens == ntens6) then
      sig = stress(1:6)
      de = dstran(1:6)
      carry = finite_carry(stran(1:6))
    else
      sig(1:4) = stress(1:4)
      sig(5:6) = 0.0_dp
      de(1:4) = dstran(1:4)
      de(5:6) = 0.0_dp
      carry = finite_carry(stran(1:4))
    end if
    carry = ior(ior(carry, state_carry(p, statev)), &
                ior(range_carry(sig, p%stress_limit), range_carry(de, p%strain_limit)))
    fault = 0
    if (carry < 0) fault = fault_non_finite
  end subroutine point_inputs

  !> The model's increment of a checked point (point_inputs' sig and de):
  !> sig advanced, STATEV written (on success only), dep the plastic strain
  !> increment (tensor shears), DDSDDE when want_tangent (else not read).
  pure subroutine point_increment(p, want_tangent, ntens, sig, de, statev, dtime, ddsdde, dep, &
                                  status, err)
    type(dp_params_t), intent(in) :: p
    logical, intent(in) :: want_tangent
    integer, intent(in) :: ntens
    real(dp), intent(inout) :: sig(ntens6), de(ntens6), statev(:), ddsdde(ntens, ntens)
    real(dp), intent(in) :: dtime
    real(dp), intent(out) :: dep(ntens6)
    integer, intent(out) :: status
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: eps_p(ntens6), eps_p_n(ntens6), z, zeta, dlambda, f, over(ntens6), z_over

    ! Engineering shears in the strains; the model takes tensor shears.
    de(4:6) = 0.5_dp*de(4:6)
    eps_p(1:3) = statev(sv_eps_p:sv_eps_p + 2)
    eps_p(4:6) = 0.5_dp*statev(sv_eps_p + 3:sv_eps_p + 5)
    z = statev(sv_z)
    zeta = statev(sv_zeta)
    eps_p_n = eps_p
    if (p%gdl) then
      over = statev(sv_over:sv_over + 5)
      z_over = statev(sv_over_z)
      if (want_tangent) then
        call gdl_update(p, sig, eps_p, z, zeta, over, z_over, statev(sv_avg_dlambda), de, &
                        dtime, dlambda, f, status, ntens, ddsdde, err)
      else
        call gdl_update(p, sig, eps_p, z, zeta, over, z_over, statev(sv_avg_dlambda), de, &
                        dtime, dlambda, f, status, ntens, err=err)
      end if
    else if (want_tangent) then
      call point_update(p, sig, eps_p, z, zeta, statev(sv_avg_dlambda), de, dtime, dlambda, f, &
                        status, ntens, ddsdde, err)
    else
      call point_update(p, sig, eps_p, z, zeta, statev(sv_avg_dlambda), de, dtime, dlambda, f, &
                        status, ntens, err=err)
    end if
    if (allocated(err)) return
    statev(sv_z) = z
    statev(sv_dlambda) = dlambda
    statev(sv_zeta) = zeta
    statev(sv_eps_p:sv_eps_p + 2) = eps_p(1:3)
    statev(sv_eps_p + 3:sv_eps_p + 5) = 2.0_dp*eps_p(4:6)
    statev(sv_f) = f
    statev(sv_status) = real(status, dp)
    if (p%gdl) then
      statev(sv_over:sv_over + 5) = over
      statev(sv_over_z) = z_over
    end if
    dep = eps_p - eps_p_n
  end subroutine point_increment

  !> PNEWDT out of a failed call (docs/guide/umat.md, "Status codes"), from the
  !> status and PNEWDT on entry. A host whose "no request" is >= 1 (Abaqus's
  !> large value, our drivers' 1) gets -1 for invalid input (stop) and
  !> min(PNEWDT, 1/2) for a cut-back. A host whose "no request" is <= 0
  !> (CalculiX passes -1) acts only on a positive PNEWDT: it gets 1/2, or
  !> the smaller request already pending, for either status, so that it
  !> cuts back until it stops with its own message.
  elemental function failure_pnewdt(status, pnewdt_in) result(pnewdt)
    integer, intent(in) :: status
    real(dp), intent(in) :: pnewdt_in
    real(dp) :: pnewdt
    if (status == status_invalid .and. pnewdt_in >= 1.0_dp) then
      pnewdt = -1.0_dp
    else if (pnewdt_in > 0.0_dp) then
      pnewdt = min(pnewdt_in, cutback_factor)
    else
      pnewdt = cutback_factor
    end if
  end function failure_pnewdt

  !> The range carry of the STATEV slots the model reads (1-12, 1-19 with
  !> PROPS(15) = 1): strains (1, 3, 5-10, 19) and stresses (4, 13-18)
  !> within the material's limits, the outputs 2, 11, 12 finite.
  pure function state_carry(p, statev) result(carry)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: statev(:)
    integer(int64) :: carry
    carry = ior(ior(ior(range_carry(statev(sv_z:sv_z), p%strain_limit), &
                        range_carry(statev(sv_avg_dlambda:sv_avg_dlambda), p%strain_limit)), &
                    ior(range_carry(statev(sv_zeta:sv_zeta), p%stress_limit), &
                        finite_carry(statev(sv_dlambda:sv_dlambda)))), &
                ior(range_carry(statev(sv_eps_p:sv_eps_p + 5), p%strain_limit), &
                    finite_carry(statev(sv_f:sv_status))))
    ! z >= 0: the sign bit makes the carry negative (eq. 2.6 grows as exp(-z));
    ! + 0 turns a host's -0.0 into +0.0, which is z = 0.
    carry = ior(carry, transfer(statev(sv_z) + 0.0_dp, carry))
    if (p%gdl) carry = ior(carry, ior(range_carry(statev(sv_over:sv_over + 5), p%stress_limit), &
                                      range_carry(statev(sv_over_z:sv_over_z), p%strain_limit)))
  end function state_carry

  !> Where the state carry failed on finite values: the message names the
  !> first STRESS, DSTRAN or STATEV entry beyond the material's limits
  !> (status -2: a smaller increment may pass; `err` kept for non-finite).
  pure subroutine range_error(p, sig, de, statev, err)
    type(dp_params_t), intent(in) :: p
    real(dp), intent(in) :: sig(ntens6), de(ntens6), statev(:)
    type(error_t), allocatable, intent(inout) :: err
    integer :: i
    integer(int64) :: limit
    integer, parameter :: stress_slots(7) = [sv_zeta, sv_over, sv_over + 1, sv_over + 2, &
                                             sv_over + 3, sv_over + 4, sv_over + 5]
    if (.not. (all_finite(sig) .and. all_finite(de) .and. &
               all_finite(statev(1:merge(nstatv_gdl, nstatv_min, p%gdl))))) return
    i = findloc(range_bits(sig, p%stress_limit) < 0, .true., 1)
    if (i > 0) then
      call limit_error('STRESS', i, sig(i), p%stress_limit, err)
      return
    end if
    i = findloc(range_bits(de, p%strain_limit) < 0, .true., 1)
    if (i > 0) then
      call limit_error('DSTRAN', i, de(i), p%strain_limit, err)
      return
    end if
    if (transfer(statev(sv_z) + 0.0_dp, 0_int64) < 0) then
      call new_error(err, status_cutback, '', 'STATEV('//int_text(sv_z)//') z = '// &
        real_text(statev(sv_z))//' is out of range: the cumulative plastic strain is >= 0')
      return
    end if
    do i = 1, merge(nstatv_gdl, nstatv_min, p%gdl)
      if (any(i == [sv_dlambda, sv_f, sv_status])) cycle
      limit = merge(p%stress_limit, p%strain_limit, any(i == stress_slots))
      if (range_bits(statev(i), limit) >= 0) cycle
      call limit_error('STATEV', i, statev(i), limit, err)
      return
    end do

  end subroutine range_error

  !> The message of an entry beyond its limit (exponent_bits `limit`).
  pure subroutine limit_error(name, i, value, limit, err)
    character(len=*), intent(in) :: name
    integer, intent(in) :: i
    real(dp), intent(in) :: value
    integer(int64), intent(in) :: limit
    type(error_t), allocatable, intent(inout) :: err
    character(len=*), parameter :: why = ' (stresses below 2^448 min(1, K, G), strains '// &
      'below that over the largest modulus: the model squares them)'
    call new_error(err, status_cutback, '', name//'('//int_text(i)//') = '// &
      real_text(value)//' is out of range: |value| < '// &
      real_text(2.0_dp*transfer(limit, 1.0_dp))//why)
  end subroutine limit_error

  !> The checks of the UMAT's inputs that concern a whole block of points:
  !> layout, PROPS (fill_dp_params) and DTIME. `fault` is 0 when all hold
  !> (`p` then holds the validated parameters and `want_tangent` says
  !> whether DDSDDE is wanted), else the first check that fails (a fault_*
  !> code): comparisons only, no text. `p` is intent(inout) so that it is
  !> not default-initialised on every call (fill_dp_params assigns it all).
  pure subroutine check_props(ndi, nshr, ntens, nstatv, nprops, props, dtime, p, want_tangent, &
                              fault)
    integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(in) :: props(nprops), dtime
    type(dp_params_t), intent(inout) :: p
    logical, intent(out) :: want_tangent
    integer, intent(out) :: fault
    real(dp) :: pr(n_params), explicit, dl_form
    integer :: param_fault
    logical :: valid

    want_tangent = .false.
    fault = layout_fault(ndi, nshr, ntens, nstatv, nprops, props)
    if (fault /= 0) return
    ! PROPS read in place; a short PROPS padded with the zeros of the
    ! features it leaves off (the copy only then).
    if (nprops >= n_params) then
      call fill_dp_params(p, props(1:n_params), param_fault)
    else
      pr = 0.0_dp
      pr(1:nprops) = props
      call fill_dp_params(p, pr, param_fault)
    end if
    explicit = 0.0_dp
    if (nprops >= prop_explicit) explicit = props(prop_explicit)
    dl_form = 0.0_dp
    if (nprops >= prop_dl_form) dl_form = props(prop_dl_form)
    fault = fault_params
    if (param_fault /= 0) return
    fault = fault_explicit
    want_tangent = explicit == 0.0_dp
    if (.not. want_tangent .and. explicit /= 1.0_dp) return
    fault = fault_dl_form
    call set_dl_form(p, dl_form, valid)
    if (.not. valid) return
    fault = fault_nstatv_gdl
    if (p%gdl .and. nstatv < nstatv_gdl) return
    fault = fault_dtime
    if (.not. is_finite(dtime)) return
    if (dtime < 0.0_dp) return
    fault = 0
  end subroutine check_props

  !> 0 when the dimensions and array sizes are ones the contract supports
  !> and PROPS past the known slots are 0, else the fault_* code.
  pure function layout_fault(ndi, nshr, ntens, nstatv, nprops, props) result(fault)
    integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(in) :: props(nprops)
    integer :: fault
    integer :: i
    fault = fault_layout
    if (.not. ((ntens == 6 .and. ndi == 3 .and. nshr == 3) .or. &
               (ntens == 4 .and. ndi == 3 .and. nshr == 1))) return
    fault = fault_nstatv
    if (nstatv < nstatv_min) return
    fault = fault_nprops
    if (nprops < nprops_min) return
    fault = fault_extra_prop
    do i = nprops_known + 1, nprops
      if (props(i) /= 0.0_dp) return
    end do
    fault = 0
  end function layout_fault

  !> The error of a fault found by umat_update's checks: status and message naming
  !> the entry, its value and the valid range.
  pure subroutine explain(fault, ndi, nshr, ntens, nstatv, nprops, props, dtime, err)
    integer, intent(in) :: fault, ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(in) :: props(nprops), dtime
    type(error_t), allocatable, intent(out) :: err
    type(dp_params_t) :: p
    real(dp) :: pr(nprops_known)
    integer :: i

    pr = 0.0_dp
    pr(1:min(nprops, nprops_known)) = props(1:min(nprops, nprops_known))
    select case (fault)
    case (fault_layout)
      call new_error(err, status_invalid, '', 'NTENS = '//int_text(ntens)//' (NDI = '// &
        int_text(ndi)//', NSHR = '//int_text(nshr)//') is not supported: valid are NTENS = 6 '// &
        '(NDI = 3, NSHR = 3) and NTENS = 4 (plane strain or axisymmetric, NDI = 3, NSHR = 1); '// &
        'plane stress is not')
    case (fault_nstatv)
      call new_error(err, status_invalid, '', 'NSTATV = '//int_text(nstatv)// &
        ' is too small: the contract needs NSTATV >= '//int_text(nstatv_min))
    case (fault_nprops)
      call new_error(err, status_invalid, '', 'NPROPS = '//int_text(nprops)// &
        ' is too small: K, G, beta, beta_p and k0 (PROPS 1-5) are required')
    case (fault_extra_prop)
      do i = nprops_known + 1, nprops
        if (props(i) /= 0.0_dp) exit
      end do
      call new_error(err, status_invalid, '', 'PROPS('//int_text(i)//') = '// &
        real_text(props(i))//' is not a wellposed slot: valid are PROPS 1-'// &
        int_text(nprops_known)//'; extra entries must be 0')
    case (fault_params)
      call new_dp_params(p, pr(prop_bulk), pr(prop_shear), pr(prop_beta), pr(prop_beta_p), &
                         pr(prop_k0), pr(prop_h), pr(prop_k_lim), pr(prop_z_ref), pr(prop_p_v), &
                         pr(prop_p_d), pr(prop_tau), pr(prop_h_zeta), pr(prop_length), err)
      err%message = slot_text(err%key)//err%message
    case (fault_explicit)
      call new_error(err, status_invalid, 'explicit', slot_text('explicit')//'explicit = '// &
        real_text(pr(prop_explicit))//' is out of range: valid is 0 (compute DDSDDE) or 1 '// &
        '(explicit host: no tangent)')
    case (fault_dl_form)
      call new_error(err, status_invalid, 'dl_form', slot_text('dl_form')//'dl_form = '// &
        real_text(pr(prop_dl_form))//' is out of range: valid is 0 (Duvaut-Lions toward the '// &
        'return of the current trial) or 1 (generalized Duvaut-Lions: a tracked quasi-static '// &
        'state, NSTATV >= '//int_text(nstatv_gdl)//')')
    case (fault_nstatv_gdl)
      call new_error(err, status_invalid, '', 'NSTATV = '//int_text(nstatv)//' is too small '// &
        'for PROPS('//int_text(prop_dl_form)//') dl_form = 1: the generalized Duvaut-Lions '// &
        'form needs NSTATV >= '//int_text(nstatv_gdl)//' (slots '//int_text(sv_over)//'-'// &
        int_text(sv_over_z)//': overstress and z - z_qs)')
    case (fault_dtime)
      call new_error(err, status_invalid, '', 'DTIME = '//real_text(dtime)// &
        ' is out of range: valid is a finite time increment >= 0')
    case default
      call new_error(err, status_cutback, 'non_finite', 'non-finite STRESS, STRAN, DSTRAN '// &
        'or STATEV on input')
    end select
  end subroutine explain

  !> "PROPS(n) " for a parameter symbol, empty when it has no slot.
  pure function slot_text(key) result(text)
    character(len=*), intent(in) :: key
    character(len=:), allocatable :: text
    integer :: slot
    slot = prop_slot(key)
    text = ''
    if (slot > 0) text = 'PROPS('//int_text(slot)//') '
  end function slot_text

end module wellposed_umat_adapter
