!> The UMAT contract implemented on typed arguments: validation, unpacking
!> of PROPS/STATEV into wellposed's types, the call, packing back, and the
!> contract's error behaviour. The external `umat` (umat.f90) only forwards
!> here and prints the message of an invalid input; hosts and tests that
!> want the message as a value call umat_update directly.
module wellposed_umat_adapter
  use wellposed_kinds, only: dp
  use wellposed_finite, only: is_finite, all_finite
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_tensor, only: ntens6
  use wellposed_elasticity, only: elastic_t, stiffness, apply_compliance
  use wellposed_dp_params, only: dp_params_t, new_dp_params
  use wellposed_text, only: int_text, real_text
  use wellposed_dp_model, only: dp_state_t, dp_output_t, dp_update
  use wellposed_abaqus, only: stress_to_mandel, stress_from_mandel, strain_to_mandel, &
                              strain_from_mandel, tangent_from_mandel
  use wellposed_umat_layout
  implicit none
  private
  public :: umat_update, cutback_factor

  !> PNEWDT requested on status -2 (a smaller increment may succeed).
  real(dp), parameter :: cutback_factor = 0.5_dp

contains

  !> One UMAT increment. Arguments as in the Abaqus UMAT. On failure `err`
  !> is allocated (status -1 invalid input, -2 cut back), STATEV(12) holds the
  !> status when NSTATV >= 12, PNEWDT < 1, STRESS and the other STATEV slots
  !> are untouched and DDSDDE is the elastic stiffness where K and G are valid.
  subroutine umat_update(stress, statev, ddsdde, sse, spd, dstran, stran, dtime, ndi, nshr, &
                         ntens, nstatv, props, nprops, pnewdt, err)
    integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(inout) :: stress(ntens), statev(nstatv), ddsdde(ntens, ntens)
    real(dp), intent(inout) :: sse, spd, pnewdt
    real(dp), intent(in) :: dstran(ntens), stran(ntens), dtime, props(nprops)
    type(error_t), allocatable, intent(out) :: err
    type(dp_params_t) :: p
    type(dp_state_t) :: state
    type(dp_output_t) :: out
    real(dp) :: pr(nprops_known), sig(ntens6), sig_n(ntens6), tangent(ntens6, ntens6)
    real(dp) :: deps(ntens6), eps_p_n(ntens6)
    logical :: want_tangent

    call check_layout(ndi, nshr, ntens, nstatv, nprops, props, err)
    if (allocated(err)) then
      call fail(); return
    end if
    pr = 0.0_dp
    pr(1:min(nprops, nprops_known)) = props(1:min(nprops, nprops_known))
    call new_dp_params(p, pr(prop_bulk), pr(prop_shear), pr(prop_beta), pr(prop_beta_p), &
                       pr(prop_k0), pr(prop_h), pr(prop_k_lim), pr(prop_z_ref), pr(prop_p_v), &
                       pr(prop_p_d), pr(prop_tau), pr(prop_h_zeta), pr(prop_length), err)
    if (allocated(err)) then
      err%message = slot_text(err%key)//err%message
      call fail(); return
    end if
    if (pr(prop_explicit) /= 0.0_dp .and. pr(prop_explicit) /= 1.0_dp) then
      call new_error(err, status_invalid, 'explicit', slot_text('explicit')//'explicit = '// &
        real_text(pr(prop_explicit))//' is out of range: valid is 0 (compute DDSDDE) or 1 '// &
        '(explicit host: no tangent)')
      call fail(); return
    end if
    if (.not. is_finite(dtime)) then
      call bad_dtime(); return
    else if (dtime < 0.0_dp) then
      call bad_dtime(); return
    end if
    if (.not. (all_finite(stress) .and. all_finite(dstran) .and. all_finite(stran) .and. &
               all_finite(statev(1:nstatv_min)))) then
      call new_error(err, status_cutback, '', 'non-finite STRESS, STRAN, DSTRAN or STATEV '// &
        'on input')
      call fail(); return
    end if

    state%z = statev(sv_z)
    state%zeta = statev(sv_zeta)
    eps_p_n = strain_to_mandel(statev(sv_eps_p:sv_eps_p + 5), ntens6)
    state%eps_p = eps_p_n
    sig_n = stress_to_mandel(stress, ntens)
    sig = sig_n
    deps = strain_to_mandel(dstran, ntens)
    want_tangent = pr(prop_explicit) == 0.0_dp
    if (want_tangent) then
      call dp_update(p, sig, state, deps, dtime, statev(sv_avg_dlambda), out, tangent, err)
    else
      call dp_update(p, sig, state, deps, dtime, statev(sv_avg_dlambda), out, err=err)
    end if
    if (allocated(err)) then
      call fail(); return
    end if

    call stress_from_mandel(sig, ntens, stress)
    if (want_tangent) call tangent_from_mandel(tangent, ntens, ddsdde)
    statev(sv_z) = state%z
    statev(sv_dlambda) = out%dlambda
    statev(sv_zeta) = state%zeta
    statev(sv_eps_p:sv_eps_p + 5) = strain_from_mandel(state%eps_p)
    statev(sv_f) = out%f
    statev(sv_status) = real(out%status, dp)
    ! Elastic energy density and plastic dissipation (trapezoidal rule).
    sse = 0.5_dp*dot_product(sig, apply_compliance(p%el, sig))
    spd = spd + 0.5_dp*dot_product(sig_n + sig, state%eps_p - eps_p_n)

  contains

    !> The contract's failure: status slot, PNEWDT, elastic DDSDDE.
    subroutine fail()
      if (nstatv >= nstatv_min) statev(sv_status) = real(err%status, dp)
      if (err%status == status_invalid) then
        pnewdt = -1.0_dp
      else
        pnewdt = min(pnewdt, cutback_factor)
      end if
      ! Nested so that no ordered comparison meets a NaN (a trap under
      ! -ffpe-trap=invalid): Fortran's .and. need not short-circuit.
      if (nprops >= prop_shear .and. ntens >= 4 .and. ntens <= 6) then
        if (all_finite(props(prop_bulk:prop_shear))) then
          if (props(prop_bulk) > 0.0_dp .and. props(prop_shear) > 0.0_dp) then
            call tangent_from_mandel(stiffness(elastic_t(props(prop_bulk), &
                                                         props(prop_shear))), ntens, ddsdde)
          end if
        end if
      end if
    end subroutine fail

    subroutine bad_dtime()
      call new_error(err, status_invalid, '', 'DTIME = '//real_text(dtime)// &
        ' is out of range: valid is a finite time increment >= 0')
      call fail()
    end subroutine bad_dtime

  end subroutine umat_update

  !> Dimensions and array sizes the contract supports.
  pure subroutine check_layout(ndi, nshr, ntens, nstatv, nprops, props, err)
    integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(in) :: props(nprops)
    type(error_t), allocatable, intent(out) :: err
    integer :: i
    if (.not. ((ntens == 6 .and. ndi == 3 .and. nshr == 3) .or. &
               (ntens == 4 .and. ndi == 3 .and. nshr == 1))) then
      call new_error(err, status_invalid, '', 'NTENS = '//int_text(ntens)//' (NDI = '// &
        int_text(ndi)//', NSHR = '//int_text(nshr)//') is not supported: valid are NTENS = 6 '// &
        '(NDI = 3, NSHR = 3) and NTENS = 4 (plane strain or axisymmetric, NDI = 3, NSHR = 1); '// &
        'plane stress is not')
      return
    end if
    if (nstatv < nstatv_min) then
      call new_error(err, status_invalid, '', 'NSTATV = '//int_text(nstatv)// &
        ' is too small: the contract needs NSTATV >= '//int_text(nstatv_min))
      return
    end if
    if (nprops < nprops_min) then
      call new_error(err, status_invalid, '', 'NPROPS = '//int_text(nprops)// &
        ' is too small: K, G, beta, beta_p and k0 (PROPS 1-5) are required')
      return
    end if
    do i = nprops_known + 1, nprops
      if (props(i) /= 0.0_dp) then
        call new_error(err, status_invalid, '', 'PROPS('//int_text(i)//') = '// &
          real_text(props(i))//' is not a wellposed slot: valid are PROPS 1-'// &
          int_text(nprops_known)//'; extra entries must be 0')
        return
      end if
    end do
  end subroutine check_layout

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
