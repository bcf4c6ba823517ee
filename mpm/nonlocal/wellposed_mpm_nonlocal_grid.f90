!> The grid-based nonlocal average of section 4.5 for the MPM, 1D and 2D:
!>   dlambda_i   = sum_p phi_ip m_p dlambda_p / m_i             (eq. 4.46)
!>   <dlambda>_p = sum_i alpha(x_p - x_i) m_i dlambda_i / M_p   (eq. 4.47)
!>   M_p         = sum_i alpha(x_p - x_i) m_i                   (eq. 4.48)
!> alpha the Gaussian of eq. 4.27, cut below weight_cutoff. Massless nodes
!> drop out of both sums, so a uniform field averages to itself; the
!> Gaussian factorises on the uniform grid, so nothing is stored between
!> sweeps. Also the state Algorithm 1 keeps between steps.
module wellposed_mpm_nonlocal_grid
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: real_text, int_text
  use wellposed_nonlocal, only: nonlocal_weight, weight_support
  use wellposed_mpm_nonlocal_settings, only: nonlocal_settings_t, nl_fixed_point, nl_anderson, &
                                             nl_sweep_names, nl_scheme_names
  implicit none
  private
  public :: nonlocal_t, nonlocal_step_stats_t, new_nonlocal, nonlocal_ghost_nodes, plastic_stats, &
            field_extents, extend_extents, field_reaches, nonlocal_project, &
            nonlocal_average, support_mass, cached_average, warn_bounds, iteration_error, &
            sweep_verdict, sweep_go, sweep_converged, sweep_stop

  !> sweep_verdict's answers.
  integer, parameter :: sweep_go = 0, sweep_converged = 1, sweep_stop = 2

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
        call bad('scheme', 'must be fixed_point or anderson'); return
      end if
      if (s%sweep < 1 .or. s%sweep > size(nl_sweep_names)) then
        call bad('sweep', 'must be auto, gauss_seidel, jacobi or coloured'); return
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

  !> <dlambda> at position xp (m) from the nodal field, eq. 4.47-4.48.
  !> Zero where no node with mass lies in the support.
  pure subroutine nonlocal_average(self, xp, avg)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    real(dp), intent(out) :: avg
    integer, parameter :: rmax = 256
    real(dp) :: ax(-rmax:rmax), ay(-rmax:rmax), num, den, rowm, rowf
    integer :: lo(2), hi(2), i, j, g
    call box(self, xp, lo, hi)
    num = 0.0_dp
    den = 0.0_dp
    do i = lo(1), hi(1)
      ax(i - lo(1)) = nonlocal_weight(xp(1) - (self%origin(1) + self%dx*i), self%length)
    end do
    if (self%ndim == 1) then
      do i = max(lo(1), self%glo), min(hi(1), self%ghi)
        num = num + ax(i - lo(1))*self%field(i)
        den = den + ax(i - lo(1))*self%node_mass(i)
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
        end do
        num = num + ay(j - lo(2))*rowf
        den = den + ay(j - lo(2))*rowm
      end do
    end if
    avg = 0.0_dp
    if (den > 0.0_dp) avg = num/den
  end subroutine nonlocal_average

  !> The node mass within the support radius of xp (kg): the dissertation's
  !> N_alpha times the particle mass (eq. 4.43). Comparisons and sums only.
  pure real(dp) function support_mass(self, xp) result(smass)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    integer :: lo(2), hi(2), i, j, g
    real(dp) :: r2
    call box(self, xp, lo, hi)
    smass = 0.0_dp
    if (self%ndim == 1) then
      do i = max(lo(1), self%glo), min(hi(1), self%ghi)
        if (abs(xp(1) - (self%origin(1) + self%dx*i)) <= self%radius) &
          smass = smass + self%node_mass(i)
      end do
      return
    end if
    do j = lo(2), hi(2)
      do i = lo(1), hi(1)
        g = i + self%nnode(1)*j
        if (g < self%glo .or. g > self%ghi) cycle
        r2 = (xp(1) - (self%origin(1) + self%dx*i))**2 + &
             (xp(2) - (self%origin(2) + self%dx*j))**2
        if (r2 <= self%radius**2) smass = smass + self%node_mass(g)
      end do
    end do
  end function support_mass

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

  !> The row extents of the nonzero `field` nodes of the patch.
  subroutine field_extents(self)
    type(nonlocal_t), intent(inout) :: self
    integer :: g
    self%row_lo = huge(1)
    self%row_hi = -1
    do g = self%glo, self%ghi
      if (self%field(g) /= 0.0_dp) call extend_extents(self, [g])
    end do
  end subroutine field_extents

  !> The nodes g(:) may now hold a nonzero field.
  pure subroutine extend_extents(self, g)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: g(:)
    integer :: i, j, k
    do k = 1, size(g)
      i = g(k)
      j = 0
      if (self%ndim == 2) then
        i = mod(g(k), self%nnode(1))
        j = g(k)/self%nnode(1)
      end if
      self%row_lo(j) = min(self%row_lo(j), i)
      self%row_hi(j) = max(self%row_hi(j), i)
    end do
  end subroutine extend_extents

  !> Whether the Gaussian's support of a particle at xp covers a node of
  !> nonzero field: if not, its average is exactly 0 (eq. 4.47).
  pure logical function field_reaches(self, xp) result(reaches)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    integer :: lo(2), hi(2), j
    call box(self, xp, lo, hi)
    reaches = .true.
    do j = lo(2), hi(2)
      if (self%row_lo(j) <= hi(1) .and. self%row_hi(j) >= lo(1)) return
    end do
    reaches = .false.
  end function field_reaches

  !> The contraction bounds' warning and note (once per run each) to `unit`.
  subroutine warn_bounds(self, unit)
    type(nonlocal_t), intent(inout) :: self
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

  !> After sweep k of step 2 (error e, largest |dlambda| gmax): the error is
  !> recorded and `verdict` is sweep_converged when e <= limit (tolerance +
  !> rel_tolerance gmax), sweep_stop when e is not finite or no new smallest
  !> error came for stall_iterations sweeps (then iteration_error), else
  !> sweep_go. The one test of every sweep scheme.
  subroutine sweep_verdict(self, k, e, gmax, best, kbest, limit, verdict)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: k
    real(dp), intent(in) :: e, gmax
    real(dp), intent(inout) :: best
    integer, intent(inout) :: kbest
    real(dp), intent(out) :: limit
    integer, intent(out) :: verdict
    self%last%error = e
    limit = self%set%tolerance + self%set%rel_tolerance*gmax
    verdict = sweep_stop
    if (.not. ieee_is_finite(e)) return
    verdict = sweep_converged
    if (e <= limit) return
    verdict = sweep_go
    if (e < best) then
      best = e
      kbest = k
    else if (k - kbest >= self%set%stall_iterations) then
      verdict = sweep_stop
    end if
  end subroutine sweep_verdict

  !> The error value of a step-2 iteration that did not converge
  !> (`exhausted`: in max_iterations sweeps) or diverged.
  subroutine iteration_error(self, exhausted, e, best, kbest, limit, nact, err)
    type(nonlocal_t), intent(in) :: self
    logical, intent(in) :: exhausted
    real(dp), intent(in) :: e, best, limit
    integer, intent(in) :: kbest, nact
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: why, hint
    if (exhausted) then
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
      trim(nl_scheme_names(self%set%scheme))//' iteration ('//trim(nl_sweep_names(self%sweep))// &
      ' sweeps) '//why// &
      ' (max |dlambda^{k+1} - dlambda^k| = '//real_text(e)//', smallest '// &
      real_text(best)//' at sweep '//int_text(kbest)//', tolerance '// &
      real_text(limit)//'; '//int_text(nact)//' plastic particles); '// &
      'contraction factor |h_zeta/(a + h_eta)| of eq. 4.43 = '//real_text(self%bound_43)//hint)
  end subroutine iteration_error

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

  !> The step's count of plastic particles and largest dlambda (at least
  !> 0), in one pass: count and maxval were a pass each, and maxval's NaN
  !> rule a branch per particle (dlambda is finite here: the host checks).
  pure subroutine plastic_stats(self)
    type(nonlocal_t), intent(inout) :: self
    integer :: p, m
    real(dp) :: top
    m = 0
    top = 0.0_dp
    do p = 1, size(self%dl)
      m = m + merge(1, 0, self%plastic(p))
      top = max(top, self%dl(p))
    end do
    self%last%n_plastic = m
    self%last%max_dlambda = top
  end subroutine plastic_stats

end module wellposed_mpm_nonlocal_grid
