!> The &material group of the MPM decks (wellposed-mpm, wellposed-mpm2d)
!> into UMAT PROPS, once for both readers.
module wellposed_mpm_material_deck
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_deck, only: check_finite, is_set
  use wellposed_umat_layout, only: prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_k0, &
                                   prop_h, prop_k_lim, prop_z_ref, prop_p_v, prop_p_d, &
                                   prop_tau, prop_h_zeta, prop_length, prop_explicit
  implicit none
  private
  public :: material_props

contains

  !> PROPS of an MPM deck's &material group into `out` (zeroed past
  !> `nprops`). `props`, when any entry is set, is a user's full list
  !> (every entry up to the last set, each finite) and is passed as given.
  !> Otherwise `named` holds the model's named keys in PROPS order
  !> (K, G, beta, beta_p, k0, h, k_lim, z_ref, P_v, P_d, tau, h_zeta, L:
  !> slots 1-13), each checked finite under its own key, and the appended
  !> slot 14 is set: our MPM hosts are explicit and never read DDSDDE.
  subroutine material_props(path, props, named, out, nprops, err)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: props(:), named(13)
    real(dp), intent(out) :: out(:)
    integer, intent(out) :: nprops
    type(error_t), allocatable, intent(out) :: err
    character(len=6), parameter :: keys(13) = [character(len=6) :: 'K', 'G', 'beta', &
      'beta_p', 'k0', 'h', 'k_lim', 'z_ref', 'P_v', 'P_d', 'tau', 'h_zeta', 'L']
    integer :: i
    out = 0.0_dp
    nprops = 0
    if (any(is_set(props))) then
      nprops = findloc(is_set(props), .true., back=.true., dim=1)
      if (.not. all(is_set(props(1:nprops)))) then
        call new_error(err, status_invalid, 'props', path//': &material: props has gaps; '// &
          'give every entry up to the last'); return
      end if
      call check_finite(path, 'material', 'props', props(1:nprops), err)
      if (allocated(err)) return
      out(1:nprops) = props(1:nprops)
      return
    end if
    do i = 1, size(named)
      call check_finite(path, 'material', trim(keys(i)), named(i), err)
      if (allocated(err)) return
    end do
    out([prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_k0, prop_h, prop_k_lim, &
         prop_z_ref, prop_p_v, prop_p_d, prop_tau, prop_h_zeta, prop_length]) = named
    out(prop_explicit) = 1.0_dp
    nprops = prop_explicit
  end subroutine material_props

end module wellposed_mpm_material_deck
