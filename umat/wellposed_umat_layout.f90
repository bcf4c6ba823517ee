!> The named PROPS and STATEV slots of the UMAT contract
!> (docs/guide/umat.md). The only place that knows the numbers.
module wellposed_umat_layout
  implicit none
  private
  public :: prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_k0, prop_h, prop_k_lim, &
            prop_z_ref, prop_p_v, prop_p_d, prop_tau, prop_h_zeta, prop_length, &
            prop_explicit, prop_dl_form, nprops_known, nprops_min, prop_names, prop_slot
  public :: sv_z, sv_dlambda, sv_avg_dlambda, sv_zeta, sv_eps_p, sv_f, sv_status, nstatv_min
  public :: sv_over, sv_over_z, nstatv_gdl

  integer, parameter :: prop_bulk = 1      !< K, bulk modulus (> 0)
  integer, parameter :: prop_shear = 2     !< G, shear modulus (> 0)
  integer, parameter :: prop_beta = 3      !< beta, friction slope (>= 0)
  integer, parameter :: prop_beta_p = 4    !< beta_p, dilatation slope (beta_p = beta: associative)
  integer, parameter :: prop_k0 = 5        !< k0, initial yield strength (> 0)
  integer, parameter :: prop_h = 6         !< h = h_eta, linear hardening modulus
  integer, parameter :: prop_k_lim = 7     !< k_lim, exponential limit (eq. 2.6; 0: off)
  integer, parameter :: prop_z_ref = 8     !< z_ref, exponential reference strain
  integer, parameter :: prop_p_v = 9       !< P_v, EFR volumetric parameter (eq. 2.7)
  integer, parameter :: prop_p_d = 10      !< P_d, EFR deviatoric parameter (eq. 2.7)
  integer, parameter :: prop_tau = 11      !< tau, Duvaut-Lions relaxation time (eq. 2.10)
  integer, parameter :: prop_h_zeta = 12   !< h_zeta, nonlocal hardening modulus (eq. 4.24)
  integer, parameter :: prop_length = 13   !< L, nonlocal length scale (eq. 2.15)
  !> Appended slot: 1 for a host that never reads DDSDDE (explicit
  !> dynamics); the tangent is then not computed and DDSDDE not written.
  integer, parameter :: prop_explicit = 14
  !> Appended slot: 1 selects the generalized Duvaut-Lions form (a tracked
  !> quasi-static state, needs NSTATV >= nstatv_gdl); 0 the default form.
  integer, parameter :: prop_dl_form = 15
  !> PROPS slots the UMAT reads; any further nonzero slot is refused.
  integer, parameter :: nprops_known = 15
  !> K, G, beta, beta_p and k0 have no valid zero default.
  integer, parameter :: nprops_min = 5
  !> The symbol of every PROPS slot, for messages.
  character(len=8), parameter :: prop_names(nprops_known) = [character(len=8) :: 'K', 'G', &
    'beta', 'beta_p', 'k0', 'h', 'k_lim', 'z_ref', 'P_v', 'P_d', 'tau', 'h_zeta', 'L', 'explicit', &
    'dl_form']

  integer, parameter :: sv_z = 1            !< cumulative equivalent plastic strain
  integer, parameter :: sv_dlambda = 2      !< dlambda of this increment (output)
  integer, parameter :: sv_avg_dlambda = 3  !< `<dlambda>` from a nonlocal host (input)
  integer, parameter :: sv_zeta = 4         !< nonlocal strength zeta
  integer, parameter :: sv_eps_p = 5        !< first of six plastic strain slots (5-10)
  integer, parameter :: sv_f = 11           !< yield function at the end
  integer, parameter :: sv_status = 12      !< status code
  !> The STATEV slots every model needs (1-12).
  integer, parameter :: nstatv_min = 12
  !> With PROPS(15) = 1: the overstress sigma - sigma_qs (eq. 2.8, six
  !> slots 13-18, order 11, 22, 33, 12, 13, 23) and z - z_qs (slot 19).
  integer, parameter :: sv_over = 13
  !> The slot of z - z_qs.
  integer, parameter :: sv_over_z = 19
  !> NSTATV the generalized Duvaut-Lions form needs.
  integer, parameter :: nstatv_gdl = 19

contains

  !> The PROPS slot of a parameter symbol, 0 when it is none.
  pure function prop_slot(name) result(slot)
    character(len=*), intent(in) :: name
    integer :: slot
    do slot = 1, nprops_known
      if (trim(prop_names(slot)) == name) return
    end do
    slot = 0
  end function prop_slot

end module wellposed_umat_layout
