!> The state of the dissertation's nonlocal Algorithm 1 for the MPM
!> (section 4.5) that lives from step to step: the &nonlocal settings with
!> the deck's L and bounds, the grid's geometry, the nodal field of eq.
!> 4.46, each particle's dlambda and plastic flag, the per-step cache of
!> the averages' weights, the last step's measures and the run's totals.
!> `new_nonlocal` validates the settings once. The averages on this state:
!> wellposed_mpm_nonlocal_grid; the iteration: wellposed_mpm_algorithm1.
module wellposed_mpm_nonlocal_state
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: real_text, int_text
  use wellposed_nonlocal, only: weight_support
  use wellposed_mpm_nonlocal_settings, only: nonlocal_settings_t, nl_fixed_point, nl_anderson, &
                                             nl_sweep_names
  implicit none
  private
  public :: nonlocal_t, nonlocal_step_stats_t, new_nonlocal, nonlocal_ghost_nodes

  !> Measures of the last solve (one time step).
  type :: nonlocal_step_stats_t
    integer :: iterations = 0        !< sweeps of step 2, all rounds
    integer :: rounds = 0            !< step-2 rounds (1 + reclassifications that re-ran it)
    integer :: n_plastic = 0         !< plastic particles at the end
    integer :: n_reclassified = 0    !< elastic -> plastic in step 3 (plastic diffusion)
    integer :: umat_calls = 0
    real(dp) :: error = 0.0_dp       !< last max |dlambda^{k+1} - dlambda^k|
    real(dp) :: max_dlambda = 0.0_dp
    real(dp) :: n_alpha = 0.0_dp     !< largest particle count in a plastic particle's support
    real(dp) :: bound_printed = 0.0_dp  !< eq. 4.43 (scheme 1) with that N_alpha
  end type nonlocal_step_stats_t

  !> Nonlocal solver state: settings (with the deck's L and bounds), grid
  !> geometry, the nodal field, and run totals.
  type :: nonlocal_t
    type(nonlocal_settings_t) :: set
    logical :: active = .false.       !< Algorithm 1 iterates (settings%active)
    real(dp) :: h_zeta = 0.0_dp       !< Pa (the deck's, for the bounds)
    real(dp) :: length = 0.0_dp       !< L (m)
    real(dp) :: radius = 0.0_dp       !< support radius of the cut Gaussian (m)
    real(dp) :: bound_43 = 0.0_dp     !< |h_zeta/(a + h_eta)|: eq. 4.43 with N_alpha = 1
    real(dp) :: bound_45 = 0.0_dp     !< |(h_eta + h_zeta)/a|: eq. 4.45 with N_alpha = 1
    ! grid: node g at origin + dx*(g mod n1, g / n1) (2D), origin + dx*g (1D)
    integer :: ndim = 1
    real(dp) :: origin(2) = 0.0_dp
    real(dp) :: dx = 1.0_dp
    integer :: nnode(2) = 1
    integer :: glo = 0, ghi = -1
    real(dp), allocatable :: node_mass(:)   !< m_i = sum_p phi_ip m_p (glo:ghi)
    !> m_i dlambda_i (glo:ghi), eq. 4.46 times the node mass: the sums of
    !> eq. 4.47 need only this product, and eq. 4.49-4.50 update it without
    !> a division
    real(dp), allocatable :: field(:)
    !> this rank's own part of `field` (its particles' sum) in the
    !> simultaneous sweeps, which add the parts of the ranks after each pass
    real(dp), allocatable :: own(:)
    integer :: sweep = 0                    !< the step-2 sweep of the last solve
    ! per-step cache of each particle's separable weights (eq. 4.27) and M_p
    integer :: nbmax = 0
    real(dp), allocatable :: wx(:, :), wy(:, :), den(:)
    integer, allocatable :: blo(:, :), bhi(:, :)
    logical, allocatable :: cached(:)
    !> per node row (0 .. nnode(2)-1; one row in 1D): the first and last
    !> node column where `field` may be nonzero (row_lo > row_hi: none), so
    !> step 3 skips the particles whose support sees only zeros
    integer, allocatable :: row_lo(:), row_hi(:)
    real(dp), allocatable :: dl(:)          !< dlambda_p of the current iterate
    logical, allocatable :: plastic(:)
    type(nonlocal_step_stats_t) :: last
    ! run totals over the steps that iterated
    integer :: steps_iterated = 0
    integer :: iterations_total = 0
    integer :: iterations_max = 0
    logical :: warned_sharp = .false., warned_printed = .false.
    !> Cost accounting (system_clock ticks and UMAT calls): step 1, the local
    !> pass; and the sweeps with their averages, UMAT calls and corrections.
    integer(int64) :: ticks_local = 0, ticks_sweeps = 0
    !> of ticks_sweeps: the exchanges between ranks (node sums or the
    !> pipeline, with the waiting for the other ranks) and the reductions
    integer(int64) :: ticks_exchange = 0
    integer(int64) :: calls_local = 0, calls_sweeps = 0
  end type nonlocal_t

contains

  !> Node layers beyond a particle's cell that Algorithm 1 reads around it
  !> (0 when h_zeta = 0): the cut Gaussian's radius in cells, rounded up,
  !> plus one because the averages are taken at the end-of-step positions,
  !> up to a cell (CFL < 1) away from the cell that holds the particle when
  !> the step begins. A patch needs at least this many ghost layers.
  pure integer function nonlocal_ghost_nodes(self) result(layers)
    type(nonlocal_t), intent(in) :: self
    layers = 0
    if (self%active) layers = ceiling(self%radius/self%dx) + 1
  end function nonlocal_ghost_nodes

  !> Validate the settings (the deck's &nonlocal group with L, h_zeta and
  !> the bounds resolved against the materials: wellposed_mpm_nonlocal_deck)
  !> and lay out the nodal field on the patch [glo, ghi] of a grid with
  !> `nnode(1:ndim)` nodes per direction, node 0 at `origin` (m), cell size
  !> `dx` (m). Errors name the deck key.
  subroutine new_nonlocal(self, settings, ndim, origin, dx, nnode, glo, ghi, err)
    type(nonlocal_t), intent(out) :: self
    type(nonlocal_settings_t), intent(in) :: settings
    real(dp), intent(in) :: origin(:), dx
    integer, intent(in) :: ndim, nnode(:), glo, ghi
    type(error_t), allocatable, intent(out) :: err

    associate (s => settings)
      if (s%scheme /= nl_fixed_point .and. s%scheme /= nl_anderson) then
        call bad(err, 'scheme', 'must be fixed_point or anderson'); return
      end if
      if (s%sweep < 1 .or. s%sweep > size(nl_sweep_names)) then
        call bad(err, 'sweep', 'must be auto, gauss_seidel, jacobi or coloured'); return
      end if
      if (.not. (s%tolerance >= 0.0_dp .and. s%rel_tolerance >= 0.0_dp .and. &
                 s%tolerance + s%rel_tolerance > 0.0_dp .and. ieee_is_finite(s%tolerance) &
                 .and. ieee_is_finite(s%rel_tolerance))) then
        call bad(err, 'tolerance', 'tolerance and rel_tolerance must be finite, >= 0 and not '// &
          'both 0 (tolerance = '//real_text(s%tolerance)//', rel_tolerance = '// &
          real_text(s%rel_tolerance)//')'); return
      end if
      if (s%max_iterations < 1 .or. s%max_iterations > 100000) then
        call bad(err, 'max_iterations', 'must be 1 ... 100000 (is '// &
          int_text(s%max_iterations)//')'); return
      end if
      if (s%stall_iterations < 2) then
        call bad(err, 'stall_iterations', 'must be >= 2 (is '//int_text(s%stall_iterations)//')')
        return
      end if
      if (s%max_rounds < 1) then
        call bad(err, 'max_rounds', 'must be >= 1 (is '//int_text(s%max_rounds)//')'); return
      end if
      if (s%anderson_depth < 1 .or. s%anderson_depth > 50) then
        call bad(err, 'anderson_depth', 'must be 1 ... 50 (is '//int_text(s%anderson_depth)//')')
        return
      end if
      if (.not. (s%anderson_mixing > 0.0_dp .and. s%anderson_mixing <= 1.0_dp)) then
        call bad(err, 'anderson_mixing', 'must lie in (0, 1] (is '// &
          real_text(s%anderson_mixing)//')'); return
      end if
      if (.not. (s%weight_cutoff > 0.0_dp .and. s%weight_cutoff < 0.5_dp)) then
        call bad(err, 'weight_cutoff', 'must lie in (0, 0.5): the Gaussian is cut where it '// &
          'falls below it (is '//real_text(s%weight_cutoff)//')'); return
      end if
    end associate
    if (ndim < 1 .or. ndim > 2 .or. size(nnode) < ndim .or. size(origin) < ndim) then
      call bad(err, 'ndim', 'the nonlocal average serves 1D and 2D grids'); return
    end if
    if (.not. (dx > 0.0_dp)) then
      call bad(err, 'dx', 'the cell size must be > 0'); return
    end if

    self%set = settings
    self%ndim = ndim
    self%origin(1:ndim) = origin(1:ndim)
    self%dx = dx
    self%nnode(1:ndim) = nnode(1:ndim)
    self%glo = glo
    self%ghi = ghi
    allocate (self%node_mass(glo:ghi), self%field(glo:ghi), self%own(glo:ghi))
    self%node_mass = 0.0_dp
    self%field = 0.0_dp
    self%own = 0.0_dp
    allocate (self%row_lo(0:self%nnode(2) - 1), self%row_hi(0:self%nnode(2) - 1))
    self%row_lo = huge(1)
    self%row_hi = -1

    self%h_zeta = settings%h_zeta
    self%length = settings%length
    self%active = settings%active
    self%bound_43 = settings%bound_43
    self%bound_45 = settings%bound_45
    if (.not. self%active) return
    if (.not. (self%length > 0.0_dp .and. ieee_is_finite(self%length))) then
      call new_error(err, status_invalid, 'L', 'Algorithm 1 needs a nonlocal length L > 0 m '// &
        '(&nonlocal L, or L of our &material); L = '//real_text(self%length))
      return
    end if
    self%radius = weight_support(self%length, settings%weight_cutoff)
    if (self%radius < 0.5_dp*dx) then
      call new_error(err, status_invalid, 'L', 'L = '//real_text(self%length)// &
        ' m is too short for the grid: the Gaussian (cut at '// &
        real_text(settings%weight_cutoff)//') reaches '//real_text(self%radius)// &
        ' m, less than half a cell (dx = '//real_text(dx)//' m), so no node would carry '// &
        'the average')
      return
    end if
  end subroutine new_nonlocal

  !> The error of a bad &nonlocal `key`: `what` says why.
  subroutine bad(err, key, what)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in) :: key, what
    call new_error(err, status_invalid, key, '&nonlocal '//key//' '//what)
  end subroutine bad

end module wellposed_mpm_nonlocal_state
