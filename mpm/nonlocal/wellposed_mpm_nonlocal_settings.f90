!> The deck's choices for the dissertation's nonlocal Algorithm 1 (the
!> &nonlocal group, docs/guide/decks.md): the iteration scheme and its
!> tolerances, limits and weight cut-off (wellposed_mpm_algorithm1), and
!> what Algorithm 1 knows of the materials, all from the deck
!> (wellposed_mpm_nonlocal_deck): whether it runs, L, h_zeta and the
!> contraction bounds of eq. 4.43 and 4.45.
module wellposed_mpm_nonlocal_settings
  use wellposed_kinds, only: dp
  use wellposed_umat_layout, only: prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_h, &
                                   prop_h_zeta
  implicit none
  private
  public :: nonlocal_settings_t, nl_fixed_point, nl_anderson, nl_scheme_names, nl_scheme_id, &
            ours_bounds
  public :: nl_sweep_auto, nl_gauss_seidel, nl_jacobi, nl_coloured, nl_sweep_names, nl_sweep_id

  !> Iteration schemes: the dissertation's Gauss-Seidel fixed point of eq. 4.39,
  !> and Anderson acceleration of the same sweep.
  integer, parameter :: nl_fixed_point = 1, nl_anderson = 2
  character(len=11), parameter :: nl_scheme_names(2) = [character(len=11) :: 'fixed_point', &
                                                        'anderson']

  !> Sweeps of step 2 (docs/guide/parallel.md): the dissertation's Gauss-Seidel in
  !> the serial order (pipelined across ranks); Jacobi, every plastic
  !> particle from the field of the previous sweep; coloured, two colours of
  !> blocks of cell layers (by global layer), each colour from the field the
  !> other left. 'auto': Gauss-Seidel on one rank, Jacobi on more.
  integer, parameter :: nl_sweep_auto = 1, nl_gauss_seidel = 2, nl_jacobi = 3, nl_coloured = 4
  character(len=12), parameter :: nl_sweep_names(4) = [character(len=12) :: 'auto', &
                                                       'gauss_seidel', 'jacobi', 'coloured']

  !> What a deck chooses (&nonlocal group). Tolerances are on dlambda, a
  !> strain increment (dimensionless).
  type :: nonlocal_settings_t
    integer :: scheme = nl_fixed_point
    integer :: sweep = nl_sweep_auto
    real(dp) :: tolerance = 1.0e-14_dp      !< absolute on max |dlambda^{k+1} - dlambda^k|
    real(dp) :: rel_tolerance = 1.0e-8_dp   !< times max_p dlambda_p, added to tolerance
    integer :: max_iterations = 200         !< sweeps per step-2 round
    integer :: stall_iterations = 10        !< sweeps without a new smallest error: diverging
    integer :: max_rounds = 50              !< step 2 -> step 3 -> step 2 rounds per step
    integer :: anderson_depth = 16          !< m, differences kept
    real(dp) :: anderson_mixing = 1.0_dp    !< beta in (0, 1]
    real(dp) :: weight_cutoff = 1.0e-6_dp   !< alpha below this is dropped (eq. 4.27)
    !> Algorithm 1 iterates: a material of ours with h_zeta /= 0, or one that
    !> declares the nonlocal contract (STATEV 2 out, STATEV 3 in)
    logical :: active = .false.
    real(dp) :: length = 0.0_dp             !< L (m) of the Gaussian, eq. 2.15, 4.27
    real(dp) :: h_zeta = 0.0_dp             !< nonlocal hardening modulus (Pa), eq. 4.24
    !> |h_zeta/(a + h_eta)| (eq. 4.43) and |(h_eta + h_zeta)/a| (eq. 4.45) with
    !> N_alpha = 1; < 0 where not known
    real(dp) :: bound_43 = -1.0_dp
    real(dp) :: bound_45 = -1.0_dp
  end type nonlocal_settings_t

contains

  !> The deck's scheme word as a scheme id, 0 when it is none.
  pure integer function nl_scheme_id(word) result(id)
    character(len=*), intent(in) :: word
    do id = 1, size(nl_scheme_names)
      if (trim(word) == trim(nl_scheme_names(id))) return
    end do
    id = 0
  end function nl_scheme_id

  !> The deck's sweep word as a sweep id, 0 when it is none.
  pure integer function nl_sweep_id(word) result(id)
    character(len=*), intent(in) :: word
    do id = 1, size(nl_sweep_names)
      if (trim(word) == trim(nl_sweep_names(id))) return
    end do
    id = 0
  end function nl_sweep_id

  !> The contraction factors of our model from its named keys (PROPS of
  !> docs/guide/umat.md), with N_alpha = 1: eq. 4.43 |h_zeta/(a + h_eta)| and
  !> eq. 4.45 |(h_eta + h_zeta)/a|, a = (G + 9 K beta beta_p)/sqrt(1/2 +
  !> 3 beta_p^2) (eq. 4.36). Both < 0 (not known) where a or a + h_eta is 0.
  pure subroutine ours_bounds(props, bound_43, bound_45)
    real(dp), intent(in) :: props(:)
    real(dp), intent(out) :: bound_43, bound_45
    real(dp) :: a, n_m
    bound_43 = -1.0_dp
    bound_45 = -1.0_dp
    n_m = sqrt(0.5_dp + 3.0_dp*props(prop_beta_p)**2)
    a = (props(prop_shear) + 9.0_dp*props(prop_bulk)*props(prop_beta)*props(prop_beta_p))/n_m
    if (.not. a > 0.0_dp .or. a + props(prop_h) == 0.0_dp) return
    bound_43 = abs(props(prop_h_zeta)/(a + props(prop_h)))
    bound_45 = abs((props(prop_h) + props(prop_h_zeta))/a)
  end subroutine ours_bounds

end module wellposed_mpm_nonlocal_settings
