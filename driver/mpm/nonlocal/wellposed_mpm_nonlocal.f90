!> The dissertation's nonlocal algorithm for the MPM (Algorithm 1, eq. 4.46-4.50),
!> the same code for 1D and 2D grids, talking to the material through the
!> UMAT's nonlocal slots only (docs/umat.md): the host
!> keeps each particle's start-of-step STRESS and STATEV, and for a given
!> average <dlambda> it restores them, writes STATEV(3) = <dlambda>, calls
!> the UMAT with this step's strain increment and reports STATEV(2). That
!> one call is the fixed-point map of eq. 4.39 for one particle.
!>
!> Grid-based nonlocal integral (eq. 4.46-4.48):
!>   dlambda_i  = sum_p phi_ip m_p dlambda_p / m_i            (eq. 4.46)
!>   <dlambda>_p = sum_i alpha(x_p - x_i) m_i dlambda_i / M_p  (eq. 4.47)
!>   M_p        = sum_i alpha(x_p - x_i) m_i                  (eq. 4.48)
!> with alpha the Gaussian of eq. 4.27, cut where alpha < weight_cutoff.
!> Nodes without mass (outside the body) drop out of both sums, so a uniform
!> field averages to itself exactly, also next to a free boundary. On the
!> uniform grid the Gaussian factorises, alpha = alpha_x(i) alpha_y(j), so a
!> particle's weights cost 2 (2R+1) exponentials, not (2R+1)^2, and nothing
!> is stored between sweeps: no neighbour lists, as the dissertation intends.
!>
!> Steps per time step (Algorithm 1):
!>  1. every particle once with <dlambda> = 0 (the local estimate, eq. 4.41
!>     without the average); the plastic set is where dlambda > 0; project.
!>     With h_zeta = 0 the algorithm stops here: no iteration, and the calls
!>     are exactly a local host's (STATEV(3) = 0), so the answer is the local
!>     one bit for bit.
!>  2. sweeps over the plastic set: average, UMAT, and the nodal field
!>     corrected at once by (m_p/m_i) phi_ip (dlambda^{k+1} - dlambda^k)
!>     (eq. 4.49-4.50): Gauss-Seidel. Converged when
!>     max_p |dlambda^{k+1} - dlambda^k| <= tolerance + rel_tolerance *
!>     max_p dlambda. Scheme 'anderson' (beyond the dissertation, section 5.2's open
!>     problem) treats one Gauss-Seidel sweep as the map G of a fixed point
!>     x = G(x) on the plastic particles' dlambda and accelerates it
!>     (wellposed_anderson: Anderson type II, depth m), which converges where
!>     the plain sweep's contraction factor exceeds 1.
!>  3. plastic diffusion: every elastic particle with a non-zero average is
!>     called once with it (its zeta takes h_zeta <dlambda>); one that now
!>     yields (dlambda > 0) joins the plastic set and step 2 runs again.
!>
!> Convergence bounds (eq. 4.43, 4.45): the dissertation's bound is N_alpha times
!> |h_zeta/(a + h_eta)|. Since the weights of eq. 4.47 are normalised (they
!> sum to 1 over the nodes, and the projection of eq. 4.46 too), the sup-norm
!> of the sweep's Jacobian is at most |h_zeta/(a + h_eta)| itself: that
!> "sharp" factor bounds a Jacobi sweep, the dissertation's N_alpha bound is reported
!> beside it. Measured (tests/unit/mpm/test_mpm_nonlocal.pf): with a sharp
!> factor of 5.9 (h_eta = -30 GPa, h_zeta = +40 GPa) a Jacobi sweep diverges
!> at once, while the dissertation's Gauss-Seidel sweep creeps for ~150 sweeps and
!> then stalls (Gauss-Seidel converges on symmetric positive definite
!> systems whatever their diagonal dominance, and the clamp dlambda >= 0
!> spoils it); Anderson on the Gauss-Seidel sweep (depth 16) converges in
!> ~40, and in 6 instead of 7 on the dissertation's plate values. A sweep that stops
!> reducing the error for `stall_iterations` sweeps, or exceeds
!> `max_iterations`, is an error value: the host stops.
!>
!> Across ranks: the nodal mass and field are patch arrays
!> [glo, ghi] whose ghost layers cover the Gaussian's support around every
!> particle of the patch (nonlocal_ghost_nodes). A decomposed run passes
!> `ranks` (a nonlocal_ranks_t: its neighbour exchanges and reductions) and
!> `key` (each local particle's place in the sweep order) to
!> nonlocal_solve, which then keeps the dissertation's Gauss-Seidel sweep in the
!> serial order across ranks by pipelining every pass that updates the
!> nodal field as it goes (projection, sweep, plastic diffusion): rank r
!> takes the values of the nodes it shares with rank r-1 as r-1 left them,
!> does its particles in key order, hands its shared nodes on to r+1, and
!> at the end every node takes the values of the highest rank holding it
!> (which has seen every update). Each node then sees the same updates in
!> the same order as in one process, so a pass gives the serial answer bit
!> for bit from the same particle data, and iteration counts are the
!> serial ones. Anderson works on the whole plastic set in key order, the
!> same on every rank. The price: the sweeps of the ranks run one after
!> the other (the UMAT calls of step 1, most of a step's work, stay
!> parallel). Without `ranks` nothing of this runs: one process.
!>
!> The sweep order (`sweep_key`): by the cell layer along the decomposition
!> axis that decides the particle's owner (from its start-of-step position,
!> where the hosts hand particles off), then by global id. The pipeline
!> needs every key of rank r below every key of rank r+1; the global id
!> alone is not, once a particle crosses to the rank below while a
!> neighbour with a lower id stays above (the 2D plate under compression).
!> The layer does not depend on the rank count, so the serial program
!> passes the same keys and sweeps in the same order as every N. Within a
!> layer the ids keep the storage order of a fresh scene; in 1D the ids
!> follow x and particles keep their order, so there the order is the id
!> order.
module wellposed_mpm_nonlocal
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_nonlocal, only: nonlocal_weight, weight_support, gaussian_k, &
                                lipschitz_local_implicit, lipschitz_local_explicit
  use wellposed_anderson, only: anderson_t, new_anderson, anderson_step
  use wellposed_dp_params, only: dp_params_t, new_dp_params
  use wellposed_umat_host, only: umat_is_ours
  use wellposed_umat_layout, only: prop_bulk, prop_shear, prop_beta, prop_beta_p, prop_k0, &
                                   prop_h, prop_k_lim, prop_z_ref, prop_p_v, prop_p_d, &
                                   prop_tau, prop_h_zeta, prop_length, nprops_known
  implicit none
  private
  public :: nonlocal_settings_t, nonlocal_t, nonlocal_host_t, nonlocal_step_stats_t
  public :: new_nonlocal, nonlocal_solve, nonlocal_project, nonlocal_average
  public :: nl_fixed_point, nl_anderson, nl_scheme_names, nl_scheme_id
  public :: nonlocal_ranks_t, nonlocal_ghost_nodes, sweep_key

  !> Iteration schemes: the dissertation's Gauss-Seidel fixed point of eq. 4.39,
  !> and Anderson acceleration of the same sweep.
  integer, parameter :: nl_fixed_point = 1, nl_anderson = 2
  character(len=11), parameter :: nl_scheme_names(2) = [character(len=11) :: 'fixed_point', &
                                                        'anderson']

  !> What a deck chooses (&nonlocal group). Tolerances are on dlambda, a
  !> strain increment (dimensionless).
  type :: nonlocal_settings_t
    integer :: scheme = nl_fixed_point
    real(dp) :: tolerance = 1.0e-14_dp      !< absolute on max |dlambda^{k+1} - dlambda^k|
    real(dp) :: rel_tolerance = 1.0e-8_dp   !< times max_p dlambda_p, added to tolerance
    integer :: max_iterations = 200         !< sweeps per step-2 round
    integer :: stall_iterations = 10        !< sweeps without a new smallest error: diverging
    integer :: max_rounds = 50              !< step 2 -> step 3 -> step 2 rounds per step
    integer :: anderson_depth = 16          !< m, differences kept
    real(dp) :: anderson_mixing = 1.0_dp    !< beta in (0, 1]
    real(dp) :: weight_cutoff = 1.0e-6_dp   !< alpha below this is dropped (eq. 4.27)
  end type nonlocal_settings_t

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

  !> The host's side: one UMAT call for particle p from its start-of-step
  !> copies with STATEV(3) = avg; dlambda = STATEV(2) afterwards; the
  !> result becomes p's end-of-step state (overwritten by the next call).
  type, abstract :: nonlocal_host_t
  contains
    procedure(host_update), deferred :: update
  end type nonlocal_host_t

  abstract interface
    subroutine host_update(self, p, avg, dlambda, err)
      import :: nonlocal_host_t, dp, error_t
      class(nonlocal_host_t), intent(inout) :: self
      integer, intent(in) :: p
      real(dp), intent(in) :: avg
      real(dp), intent(out) :: dlambda
      type(error_t), allocatable, intent(out) :: err
    end subroutine host_update
  end interface

  !> What Algorithm 1 needs from a run spread over ranks. Node
  !> arrays are a patch's nodal values, values(1) at its first node; the
  !> pipeline calls are collective in rank order (see the module comment).
  type, abstract :: nonlocal_ranks_t
  contains
    !> values of the nodes shared with the next lower rank, as that rank left them
    procedure(ranks_nodes), deferred :: nodes_from_lower
    !> this rank's values of the nodes shared with the next higher rank, to it
    procedure(ranks_nodes), deferred :: nodes_to_higher
    !> every node the value of the highest rank holding it
    procedure(ranks_nodes), deferred :: nodes_from_highest
    !> maximum over the ranks, in place
    procedure(ranks_max), deferred :: max_real
    !> sum over the ranks, in place
    procedure(ranks_sum_int), deferred :: sum_int
    !> true on every rank when true on any
    procedure(ranks_any), deferred :: any_true
    !> every rank's `mine` concatenated in rank order, on every rank
    procedure(ranks_gather), deferred :: gather_all
  end type nonlocal_ranks_t

  abstract interface
    subroutine ranks_nodes(self, values)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(inout) :: self
      real(dp), intent(inout) :: values(:)
    end subroutine ranks_nodes
    subroutine ranks_max(self, x)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(inout) :: self
      real(dp), intent(inout) :: x
    end subroutine ranks_max
    subroutine ranks_sum_int(self, i)
      import :: nonlocal_ranks_t
      class(nonlocal_ranks_t), intent(inout) :: self
      integer, intent(inout) :: i
    end subroutine ranks_sum_int
    logical function ranks_any(self, flag)
      import :: nonlocal_ranks_t
      class(nonlocal_ranks_t), intent(inout) :: self
      logical, intent(in) :: flag
    end function ranks_any
    subroutine ranks_gather(self, mine, all)
      import :: nonlocal_ranks_t, dp
      class(nonlocal_ranks_t), intent(inout) :: self
      real(dp), intent(in) :: mine(:)
      real(dp), allocatable, intent(out) :: all(:)
    end subroutine ranks_gather
  end interface

  !> Nonlocal solver state: settings, material constants for the bounds,
  !> grid geometry, the nodal field, and run totals.
  type :: nonlocal_t
    type(nonlocal_settings_t) :: set
    logical :: active = .false.       !< h_zeta /= 0
    real(dp) :: h_zeta = 0.0_dp       !< Pa
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
    ! per-step cache of each particle's separable weights (eq. 4.27) and M_p
    integer :: nbmax = 0
    real(dp), allocatable :: wx(:, :), wy(:, :), den(:)
    integer, allocatable :: blo(:, :), bhi(:, :)
    logical, allocatable :: cached(:)
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
    integer(int64) :: calls_local = 0, calls_sweeps = 0
  end type nonlocal_t

contains

  !> The deck's scheme word as a scheme id, 0 when it is none.
  pure integer function nl_scheme_id(word) result(id)
    character(len=*), intent(in) :: word
    do id = 1, size(nl_scheme_names)
      if (trim(word) == trim(nl_scheme_names(id))) return
    end do
    id = 0
  end function nl_scheme_id

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

  !> Validate the settings, read h_zeta and L from PROPS (wellposed's
  !> layout, PROPS 12-13) and lay out the nodal field on the patch [glo, ghi]
  !> of a grid with `nnode(1:ndim)` nodes per direction, node 0 at `origin`
  !> (m), cell size `dx` (m). Errors name the deck key.
  subroutine new_nonlocal(self, settings, props, ndim, origin, dx, nnode, glo, ghi, err)
    type(nonlocal_t), intent(out) :: self
    type(nonlocal_settings_t), intent(in) :: settings
    real(dp), intent(in) :: props(:), origin(:), dx
    integer, intent(in) :: ndim, nnode(:), glo, ghi
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: pr(nprops_known)
    type(dp_params_t) :: mat
    type(error_t), allocatable :: perr

    associate (s => settings)
      if (s%scheme /= nl_fixed_point .and. s%scheme /= nl_anderson) then
        call bad('scheme', 'must be fixed_point or anderson'); return
      end if
      if (.not. (s%tolerance >= 0.0_dp .and. s%rel_tolerance >= 0.0_dp .and. &
                 s%tolerance + s%rel_tolerance > 0.0_dp .and. ieee_is_finite(s%tolerance) &
                 .and. ieee_is_finite(s%rel_tolerance))) then
        call bad('tolerance', 'tolerance and rel_tolerance must be finite, >= 0 and not '// &
          'both 0 (tolerance = '//real_text(s%tolerance)//', rel_tolerance = '// &
          real_text(s%rel_tolerance)//')'); return
      end if
      if (s%max_iterations < 1 .or. s%max_iterations > 100000) then
        call bad('max_iterations', 'must be 1 ... 100000 (is '// &
          int_text(s%max_iterations)//')'); return
      end if
      if (s%stall_iterations < 2) then
        call bad('stall_iterations', 'must be >= 2 (is '//int_text(s%stall_iterations)//')')
        return
      end if
      if (s%max_rounds < 1) then
        call bad('max_rounds', 'must be >= 1 (is '//int_text(s%max_rounds)//')'); return
      end if
      if (s%anderson_depth < 1 .or. s%anderson_depth > 50) then
        call bad('anderson_depth', 'must be 1 ... 50 (is '//int_text(s%anderson_depth)//')')
        return
      end if
      if (.not. (s%anderson_mixing > 0.0_dp .and. s%anderson_mixing <= 1.0_dp)) then
        call bad('anderson_mixing', 'must lie in (0, 1] (is '// &
          real_text(s%anderson_mixing)//')'); return
      end if
      if (.not. (s%weight_cutoff > 0.0_dp .and. s%weight_cutoff < 0.5_dp)) then
        call bad('weight_cutoff', 'must lie in (0, 0.5): the Gaussian is cut where it '// &
          'falls below it (is '//real_text(s%weight_cutoff)//')'); return
      end if
    end associate
    if (ndim < 1 .or. ndim > 2 .or. size(nnode) < ndim .or. size(origin) < ndim) then
      call bad('ndim', 'the nonlocal average serves 1D and 2D grids'); return
    end if
    if (.not. (dx > 0.0_dp)) then
      call bad('dx', 'the cell size must be > 0'); return
    end if

    self%set = settings
    self%ndim = ndim
    self%origin(1:ndim) = origin(1:ndim)
    self%dx = dx
    self%nnode(1:ndim) = nnode(1:ndim)
    self%glo = glo
    self%ghi = ghi
    allocate (self%node_mass(glo:ghi), self%field(glo:ghi))
    self%node_mass = 0.0_dp
    self%field = 0.0_dp

    pr = 0.0_dp
    ! PROPS(12), PROPS(13) are wellposed's nonlocal slots: a user's own UMAT
    ! has other PROPS and runs local
    if (umat_is_ours()) pr(1:min(size(props), nprops_known)) = &
      props(1:min(size(props), nprops_known))
    self%h_zeta = pr(prop_h_zeta)
    self%length = pr(prop_length)
    self%active = self%h_zeta /= 0.0_dp
    if (.not. self%active) return
    if (.not. (self%length > 0.0_dp .and. ieee_is_finite(self%length))) then
      call new_error(err, status_invalid, 'L', 'h_zeta = '//real_text(self%h_zeta)// &
        ' needs a nonlocal length L > 0 m (PROPS(13)); L = '//real_text(self%length))
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
    call new_dp_params(mat, pr(prop_bulk), pr(prop_shear), pr(prop_beta), pr(prop_beta_p), &
                       pr(prop_k0), pr(prop_h), pr(prop_k_lim), pr(prop_z_ref), pr(prop_p_v), &
                       pr(prop_p_d), pr(prop_tau), pr(prop_h_zeta), pr(prop_length), perr)
    if (allocated(perr)) then
      ! Not wellposed's parameter layout (a user's UMAT): no bound to report.
      self%bound_43 = -1.0_dp
      self%bound_45 = -1.0_dp
    else
      self%bound_43 = lipschitz_local_implicit(mat, 1.0_dp)
      self%bound_45 = lipschitz_local_explicit(mat, 1.0_dp)
    end if

  contains

    subroutine bad(key, what)
      character(len=*), intent(in) :: key, what
      call new_error(err, status_invalid, key, '&nonlocal '//key//' '//what)
    end subroutine bad

  end subroutine new_nonlocal

  !> Node mass and the nodal field of eq. 4.46 from particle values:
  !> m_i = sum_p phi_ip m_p and field_i = m_i dlambda_i = sum_p phi_ip m_p
  !> values_p. node(k, p) are global node numbers inside [glo, ghi].
  pure subroutine nonlocal_project(self, mass, node, phi, values)
    type(nonlocal_t), intent(inout) :: self
    real(dp), intent(in) :: mass(:), phi(:, :), values(:)
    integer, intent(in) :: node(:, :)
    integer :: p, k, i
    real(dp) :: w
    self%node_mass = 0.0_dp
    self%field = 0.0_dp
    do p = 1, size(mass)
      do k = 1, size(node, 1)
        i = node(k, p)
        w = phi(k, p)*mass(p)
        self%node_mass(i) = self%node_mass(i) + w
        self%field(i) = self%field(i) + w*values(p)
      end do
    end do
  end subroutine nonlocal_project

  !> <dlambda> at position xp (m) from the nodal field, eq. 4.47-4.48; also
  !> the mass in the support (kg, optional: the dissertation's N_alpha times the
  !> particle mass). Zero where no node with mass lies in the support.
  pure subroutine nonlocal_average(self, xp, avg, support_mass)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    real(dp), intent(out) :: avg
    real(dp), intent(out), optional :: support_mass
    integer, parameter :: rmax = 256
    real(dp) :: ax(-rmax:rmax), ay(-rmax:rmax), num, den, rowm, rowf, smass, r2
    integer :: lo(2), hi(2), i, j, g
    call box(self, xp, lo, hi)
    num = 0.0_dp
    den = 0.0_dp
    smass = 0.0_dp
    do i = lo(1), hi(1)
      ax(i - lo(1)) = nonlocal_weight(xp(1) - (self%origin(1) + self%dx*i), self%length)
    end do
    if (self%ndim == 1) then
      do i = lo(1), hi(1)
        if (i < self%glo .or. i > self%ghi) cycle
        num = num + ax(i - lo(1))*self%field(i)
        den = den + ax(i - lo(1))*self%node_mass(i)
        if (present(support_mass)) then
          if (abs(xp(1) - (self%origin(1) + self%dx*i)) <= self%radius) &
            smass = smass + self%node_mass(i)
        end if
      end do
    else
      do j = lo(2), hi(2)
        ay(j - lo(2)) = nonlocal_weight(xp(2) - (self%origin(2) + self%dx*j), self%length)
      end do
      do j = lo(2), hi(2)
        rowm = 0.0_dp
        rowf = 0.0_dp
        do i = lo(1), hi(1)
          g = i + self%nnode(1)*j
          if (g < self%glo .or. g > self%ghi) cycle
          rowm = rowm + ax(i - lo(1))*self%node_mass(g)
          rowf = rowf + ax(i - lo(1))*self%field(g)
          if (present(support_mass)) then
            r2 = (xp(1) - (self%origin(1) + self%dx*i))**2 + &
                 (xp(2) - (self%origin(2) + self%dx*j))**2
            if (r2 <= self%radius**2) smass = smass + self%node_mass(g)
          end if
        end do
        num = num + ay(j - lo(2))*rowf
        den = den + ay(j - lo(2))*rowm
      end do
    end if
    avg = 0.0_dp
    if (den > 0.0_dp) avg = num/den
    if (present(support_mass)) support_mass = smass
  end subroutine nonlocal_average

  !> <dlambda> of particle p at xp within a solve: its separable weights and
  !> M_p (eq. 4.48) are computed at the first call of the step and kept, so a
  !> sweep costs (2R+1)^ndim multiply-adds per particle and no exponential.
  subroutine cached_average(self, p, xp, avg)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: xp(:)
    real(dp), intent(out) :: avg
    integer :: lo(2), hi(2), i, j, g, nb
    real(dp) :: num, row, den
    if (.not. self%cached(p)) then
      call box(self, xp, lo, hi)
      hi = min(hi, lo + self%nbmax - 1)
      self%blo(:, p) = lo
      self%bhi(:, p) = hi
      do i = lo(1), hi(1)
        self%wx(i - lo(1) + 1, p) = nonlocal_weight(xp(1) - (self%origin(1) + self%dx*i), &
                                                    self%length)
      end do
      den = 0.0_dp
      if (self%ndim == 1) then
        do i = max(lo(1), self%glo), min(hi(1), self%ghi)
          den = den + self%wx(i - lo(1) + 1, p)*self%node_mass(i)
        end do
      else
        do j = lo(2), hi(2)
          self%wy(j - lo(2) + 1, p) = nonlocal_weight(xp(2) - (self%origin(2) + self%dx*j), &
                                                      self%length)
          row = 0.0_dp
          do i = lo(1), hi(1)
            g = i + self%nnode(1)*j
            if (g < self%glo .or. g > self%ghi) cycle
            row = row + self%wx(i - lo(1) + 1, p)*self%node_mass(g)
          end do
          den = den + self%wy(j - lo(2) + 1, p)*row
        end do
      end if
      self%den(p) = den
      self%cached(p) = .true.
    end if
    avg = 0.0_dp
    if (.not. self%den(p) > 0.0_dp) return
    lo = self%blo(:, p)
    hi = self%bhi(:, p)
    num = 0.0_dp
    if (self%ndim == 1) then
      do i = max(lo(1), self%glo), min(hi(1), self%ghi)
        num = num + self%wx(i - lo(1) + 1, p)*self%field(i)
      end do
    else
      nb = hi(1) - lo(1) + 1
      do j = lo(2), hi(2)
        g = lo(1) + self%nnode(1)*j
        if (g < self%glo .or. g + nb - 1 > self%ghi) then
          row = 0.0_dp
          do i = lo(1), hi(1)
            g = i + self%nnode(1)*j
            if (g >= self%glo .and. g <= self%ghi) &
              row = row + self%wx(i - lo(1) + 1, p)*self%field(g)
          end do
        else
          row = dot_product(self%wx(1:nb, p), self%field(g:g + nb - 1))
        end if
        num = num + self%wy(j - lo(2) + 1, p)*row
      end do
    end if
    avg = num/self%den(p)
  end subroutine cached_average

  !> Node index box [lo, hi] per direction covering the cut Gaussian at xp.
  pure subroutine box(self, xp, lo, hi)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    integer, intent(out) :: lo(2), hi(2)
    integer :: d
    lo = 0
    hi = 0
    do d = 1, self%ndim
      lo(d) = max(0, ceiling((xp(d) - self%radius - self%origin(d))/self%dx))
      hi(d) = min(self%nnode(d) - 1, floor((xp(d) + self%radius - self%origin(d))/self%dx))
      ! at most 2*256 + 1 nodes per direction (the radius is L*sqrt(-ln cutoff)/k)
      hi(d) = min(hi(d), lo(d) + 512)
    end do
  end subroutine box

  !> One time step of Algorithm 1 (see the module comment). `x` (ndim, n)
  !> are the particle positions (m), `mass` (kg), `node`/`phi` the shape
  !> weights of this step (nsup, n). On return every particle's end-of-step
  !> state is the host's last update of it. Diverging or non-converging
  !> iterations, and host errors, return an error value. When `log_unit` is
  !> given, warnings about the contraction bounds are written there before
  !> iterating (once per run each). A run spread over ranks gives `ranks`
  !> and `key` (n): the particles' places in the serial order (sweep_key,
  !> unique); the solve is then collective, and its error values and the
  !> step's measures (self%last, but umat_calls: this rank's) are the same
  !> on every rank.
  subroutine nonlocal_solve(self, host, x, mass, node, phi, err, log_unit, ranks, key)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    real(dp), intent(in) :: x(:, :), mass(:), phi(:, :)
    integer, intent(in) :: node(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: log_unit
    class(nonlocal_ranks_t), intent(inout), optional :: ranks
    integer(int64), intent(in), optional :: key(:)
    integer :: n, p, q, round
    integer(int64) :: c0, c1
    real(dp) :: avg, dnew, smass
    logical :: changed, par
    integer, allocatable :: act(:), order(:)

    n = size(mass)
    par = present(ranks)
    self%last = nonlocal_step_stats_t()
    if (allocated(self%dl)) then
      if (size(self%dl) /= n) deallocate (self%dl, self%plastic)
    end if
    if (.not. allocated(self%dl)) allocate (self%dl(n), self%plastic(n))
    if (self%active) then
      self%nbmax = 2*ceiling(self%radius/self%dx) + 3
      if (allocated(self%cached)) then
        if (size(self%cached) /= n) deallocate (self%wx, self%wy, self%den, self%blo, &
                                                self%bhi, self%cached)
      end if
      if (.not. allocated(self%cached)) allocate (self%wx(self%nbmax, n), &
        self%wy(self%nbmax, n), self%den(n), self%blo(2, n), self%bhi(2, n), self%cached(n))
      self%cached = .false.
    end if
    ! Step 1: the local estimate, <dlambda> = 0.
    call system_clock(c0)
    do p = 1, n
      call host%update(p, 0.0_dp, self%dl(p), err)
      if (allocated(err)) exit
    end do
    if (stopped(err)) return
    call system_clock(c1)
    self%ticks_local = self%ticks_local + (c1 - c0)
    self%calls_local = self%calls_local + n
    self%last%umat_calls = n
    self%plastic = self%dl > 0.0_dp
    self%last%n_plastic = count(self%plastic)
    self%last%max_dlambda = max(0.0_dp, maxval(self%dl))
    if (par) then
      call ranks%sum_int(self%last%n_plastic)
      call ranks%max_real(self%last%max_dlambda)
    end if
    if (.not. self%active .or. self%last%n_plastic == 0) return
    ! the local particles in the serial order (a local model never needs it)
    if (present(key)) then
      call key_order(key(1:n), order)
    else
      order = [(p, p=1, n)]
    end if
    call project(self%dl)

    ! The bounds, before iterating.
    do p = 1, n
      if (.not. self%plastic(p)) cycle
      call nonlocal_average(self, x(:, p), avg, smass)
      self%last%n_alpha = max(self%last%n_alpha, smass/mass(p))
    end do
    if (par) call ranks%max_real(self%last%n_alpha)
    if (self%bound_43 >= 0.0_dp) self%last%bound_printed = self%last%n_alpha*self%bound_43
    if (present(log_unit)) call warn_bounds(log_unit)

    do round = 1, self%set%max_rounds
      self%last%rounds = round
      act = pack(order, self%plastic(order))
      call iterate(act, err)
      if (allocated(err)) return
      ! Step 3: plastic diffusion to the elastic particles.
      changed = .false.
      if (par) call ranks%nodes_from_lower(self%field)
      do q = 1, n
        p = order(q)
        if (self%plastic(p)) cycle
        call cached_average(self, p, x(:, p), avg)
        if (avg == 0.0_dp) cycle   ! the step-1 call already had this input
        call host%update(p, avg, dnew, err)
        if (allocated(err)) exit
        self%last%umat_calls = self%last%umat_calls + 1
        if (dnew > 0.0_dp) then
          changed = .true.
          self%plastic(p) = .true.
          self%last%n_reclassified = self%last%n_reclassified + 1
          call correct_field(p, dnew - self%dl(p))
          self%dl(p) = dnew
        end if
      end do
      if (par) then
        call ranks%nodes_to_higher(self%field)
        call ranks%nodes_from_highest(self%field)
        changed = ranks%any_true(changed)
      end if
      if (stopped(err)) return
      if (.not. changed) exit
      if (round == self%set%max_rounds) then
        call new_error(err, status_cutback, 'max_rounds', 'the nonlocal plastic set kept '// &
          'growing by plastic diffusion (step 3 of Algorithm 1) after '// &
          int_text(self%set%max_rounds)//' rounds; raise &nonlocal max_rounds')
        return
      end if
    end do
    self%last%n_plastic = count(self%plastic)
    self%last%max_dlambda = max(0.0_dp, maxval(self%dl))
    if (par) then
      call ranks%sum_int(self%last%n_plastic)
      call ranks%sum_int(self%last%n_reclassified)
      call ranks%max_real(self%last%max_dlambda)
    end if
    self%steps_iterated = self%steps_iterated + 1
    self%iterations_total = self%iterations_total + self%last%iterations
    self%iterations_max = max(self%iterations_max, self%last%iterations)

  contains

    !> Step 2 on the particles act(:) (this rank's, in the serial order):
    !> plain Gauss-Seidel or Anderson.
    subroutine iterate(act, err)
      integer, intent(in) :: act(:)
      type(error_t), allocatable, intent(out) :: err
      real(dp) :: xk(size(act)), gx(size(act)), e, best, limit, gmax
      real(dp), allocatable :: xn(:), xall(:), gall(:), kall(:)
      integer, allocatable :: perm(:), pos(:)
      integer :: k, kbest, q, pp, nact
      integer(int64) :: s0, s1
      type(anderson_t) :: acc
      character(len=:), allocatable :: why, hint

      nact = size(act)
      if (par) call ranks%sum_int(nact)
      allocate (pos(size(act)), perm(0), xn(0))
      if (self%set%scheme == nl_anderson) then
        ! Anderson acts on the whole plastic set in the serial order: with
        ! ranks, every rank runs it on the gathered vectors (bitwise alike)
        ! and keeps its own entries (pos)
        if (par) then
          call ranks%gather_all(real(key_of(act), dp), kall)
          call key_order(nint(kall, int64), perm)
          kall = kall(perm)
          do q = 1, size(act)
            pos(q) = find_sorted(kall, real(key_of([act(q)]), dp))
          end do
        else
          pos = [(q, q=1, size(act))]
        end if
        call new_anderson(acc, nact, self%set%anderson_depth, self%set%anderson_mixing)
        deallocate (xn)
        allocate (xn(nact))
      end if
      best = huge(1.0_dp)
      kbest = 0
      do k = 1, self%set%max_iterations
        xk = self%dl(act)
        ! one Gauss-Seidel sweep, eq. 4.47, 4.39 (through the UMAT), 4.49-4.50
        call system_clock(s0)
        if (par) call ranks%nodes_from_lower(self%field)
        do q = 1, size(act)
          pp = act(q)
          call cached_average(self, pp, x(:, pp), avg)
          call host%update(pp, avg, dnew, err)
          if (allocated(err)) exit
          call correct_field(pp, dnew - self%dl(pp))
          self%dl(pp) = dnew
        end do
        if (par) then
          call ranks%nodes_to_higher(self%field)
          call ranks%nodes_from_highest(self%field)
        end if
        if (stopped(err)) return
        call system_clock(s1)
        self%ticks_sweeps = self%ticks_sweeps + (s1 - s0)
        self%calls_sweeps = self%calls_sweeps + size(act)
        self%last%umat_calls = self%last%umat_calls + size(act)
        self%last%iterations = self%last%iterations + 1
        gx = self%dl(act)
        e = maxval(abs(gx - xk))
        gmax = maxval(abs(gx))
        if (par) then
          call ranks%max_real(e)
          call ranks%max_real(gmax)
        end if
        self%last%error = e
        limit = self%set%tolerance + self%set%rel_tolerance*gmax
        if (.not. ieee_is_finite(e)) exit
        if (e <= limit) return
        if (e < best) then
          best = e
          kbest = k
        else if (k - kbest >= self%set%stall_iterations) then
          exit
        end if
        if (self%set%scheme == nl_anderson) then
          if (par) then
            call ranks%gather_all(xk, xall)
            call ranks%gather_all(gx, gall)
            call anderson_step(acc, xall(perm), gall(perm), xn)
            self%dl(act) = xn(pos)
          else
            call anderson_step(acc, xk, gx, xn)
            self%dl(act) = xn
          end if
          call project(self%dl)
        end if
      end do
      if (k > self%set%max_iterations) then
        why = 'did not converge in '//int_text(self%set%max_iterations)//' sweeps'
      else if (.not. ieee_is_finite(e)) then
        why = 'diverges: the error is no longer finite'
      else
        why = 'diverges: no smaller error in '//int_text(self%set%stall_iterations)//' sweeps'
      end if
      if (self%bound_43 > 1.0_dp) then
        hint = ' > 1: the plain fixed point cannot be relied on; set &nonlocal scheme = '// &
               '''anderson'''
      else
        hint = ' <= 1'
      end if
      call new_error(err, status_cutback, 'scheme', 'the nonlocal '// &
        trim(nl_scheme_names(self%set%scheme))//' iteration '//why// &
        ' (max |dlambda^{k+1} - dlambda^k| = '//real_text(e)//', smallest '// &
        real_text(best)//' at sweep '//int_text(kbest)//', tolerance '// &
        real_text(limit)//'; '//int_text(nact)//' plastic particles); '// &
        'contraction factor |h_zeta/(a + h_eta)| of eq. 4.43 = '//real_text(self%bound_43)//hint)
    end subroutine iterate

    !> The serial-order keys of local particles (their indices without `key`).
    function key_of(idx) result(k)
      integer, intent(in) :: idx(:)
      integer(int64) :: k(size(idx))
      if (present(key)) then
        k = key(idx)
      else
        k = int(idx, int64)
      end if
    end function key_of

    !> Node mass and field from particle `values` (eq. 4.46) in the key
    !> order: with ranks, pipelined (the module comment); without a key,
    !> nonlocal_project (storage order).
    subroutine project(values)
      real(dp), intent(in) :: values(:)
      integer :: k, i, qq, pq
      real(dp) :: w
      if (.not. par .and. .not. present(key)) then
        call nonlocal_project(self, mass, node, phi, values)
        return
      end if
      self%node_mass = 0.0_dp
      self%field = 0.0_dp
      if (par) then
        call ranks%nodes_from_lower(self%node_mass)
        call ranks%nodes_from_lower(self%field)
      end if
      do qq = 1, n
        pq = order(qq)
        do k = 1, size(node, 1)
          i = node(k, pq)
          w = phi(k, pq)*mass(pq)
          self%node_mass(i) = self%node_mass(i) + w
          self%field(i) = self%field(i) + w*values(pq)
        end do
      end do
      if (.not. par) return
      call ranks%nodes_to_higher(self%node_mass)
      call ranks%nodes_to_higher(self%field)
      call ranks%nodes_from_highest(self%node_mass)
      call ranks%nodes_from_highest(self%field)
    end subroutine project

    !> An error on this rank or, with ranks, on any (collective then): every
    !> rank stops with an error value.
    logical function stopped(e)
      type(error_t), allocatable, intent(inout) :: e
      stopped = allocated(e)
      if (.not. par) return
      stopped = ranks%any_true(stopped)
      if (stopped .and. .not. allocated(e)) call new_error(e, status_invalid, 'ranks', &
        'Algorithm 1 stopped on another rank (its message is above)')
    end function stopped

    !> eq. 4.49-4.50: move particle p's contribution on its nodes by `delta`.
    subroutine correct_field(p, delta)
      integer, intent(in) :: p
      real(dp), intent(in) :: delta
      integer :: k, i
      if (delta == 0.0_dp) return
      do k = 1, size(node, 1)
        i = node(k, p)
        self%field(i) = self%field(i) + mass(p)*phi(k, p)*delta
      end do
    end subroutine correct_field

    subroutine warn_bounds(unit)
      integer, intent(in) :: unit
      if (self%bound_43 > 1.0_dp .and. .not. self%warned_sharp) then
        write (unit, '(a)') 'warning: nonlocal contraction factor |h_zeta/(a + h_eta)| '// &
          '(eq. 4.43 with normalised weights) = '//real_text(self%bound_43)//' > 1: the '// &
          'dissertation''s fixed point (scheme fixed_point) is not a contraction and may diverge'
        self%warned_sharp = .true.
      end if
      if (self%last%bound_printed > 1.0_dp .and. .not. self%warned_printed) then
        write (unit, '(a)') 'note: the dissertation''s Lipschitz bound of eq. 4.43, N_alpha |h_zeta/'// &
          '(a + h_eta)| with N_alpha = '//real_text(self%last%n_alpha)//', is '// &
          real_text(self%last%bound_printed)//' > 1 (eq. 4.45: '// &
          real_text(self%last%n_alpha*self%bound_45)//'); it counts every particle in the '// &
          'support at full weight, so convergence is not guaranteed by it; the sharp '// &
          'factor above decides'
        self%warned_printed = .true.
      end if
    end subroutine warn_bounds

  end subroutine nonlocal_solve

  !> The sweep key of a particle in cell layer `layer` (0 .. ncells-1 along
  !> the decomposition axis, the layer that decides its owner) with global
  !> id `gid` (1 .. 2**31-1): layer first, then id. Below 2**53 while
  !> layer < 2**22, so exact also as a real (Anderson gathers keys so).
  elemental integer(int64) function sweep_key(layer, gid) result(k)
    integer, intent(in) :: layer, gid
    k = int(layer, int64)*2_int64**31 + int(gid, int64)
  end function sweep_key

  !> order(1:n): the indices of key(1:n) in ascending key order (stable
  !> merge sort; the identity, at the cost of one pass, when already sorted).
  pure subroutine key_order(key, order)
    integer(int64), intent(in) :: key(:)
    integer, allocatable, intent(out) :: order(:)
    integer, allocatable :: tmp(:)
    integer :: n, width, lo, mid, hi, i, j, k, p
    n = size(key)
    order = [(p, p=1, n)]
    if (n < 2) return
    if (all(key(2:) >= key(:n - 1))) return
    allocate (tmp(n))
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width, n + 1)
        hi = min(lo + 2*width, n + 1)
        i = lo
        j = mid
        do k = lo, hi - 1
          if (i < mid .and. (j >= hi .or. key(order(min(i, n))) <= key(order(min(j, n))))) then
            tmp(k) = order(i)
            i = i + 1
          else
            tmp(k) = order(j)
            j = j + 1
          end if
        end do
      end do
      order = tmp
      width = 2*width
    end do
  end subroutine key_order

  !> Index of `x` in the ascending `sorted` (x must occur).
  pure integer function find_sorted(sorted, x) result(pos)
    real(dp), intent(in) :: sorted(:), x(1)
    integer :: lo, hi, mid
    lo = 1
    hi = size(sorted)
    do while (lo < hi)
      mid = (lo + hi)/2
      if (sorted(mid) < x(1)) then
        lo = mid + 1
      else
        hi = mid
      end if
    end do
    pos = lo
  end function find_sorted

end module wellposed_mpm_nonlocal
