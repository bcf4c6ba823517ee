!> The dissertation's nonlocal Algorithm 1 for the MPM (eq. 4.46-4.50),
!> the same code for 1D and 2D grids, talking to the material through the
!> UMAT's nonlocal slots only (docs/umat.md): the host
!> keeps each particle's start-of-step STRESS and STATEV, and for a given
!> average <dlambda> it restores them, writes STATEV(3) = <dlambda>, calls
!> the UMAT with this step's strain increment and reports STATEV(2). That
!> one call is the fixed-point map of eq. 4.39 for one particle.
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
!> The nodal field and the averages: wellposed_mpm_nonlocal_grid; the
!> sweep order: wellposed_mpm_sweep_order.
module wellposed_mpm_algorithm1
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_anderson, only: anderson_t, new_anderson, anderson_step
  use wellposed_mpm_nonlocal_settings, only: nl_anderson, nl_scheme_names
  use wellposed_mpm_nonlocal_grid, only: nonlocal_t, nonlocal_step_stats_t, nonlocal_project, &
                                         nonlocal_average, cached_average
  use wellposed_mpm_sweep_order, only: key_order, find_sorted
  implicit none
  private
  public :: nonlocal_host_t, nonlocal_ranks_t, nonlocal_solve

  !> The host's side: one UMAT call for particle p from its start-of-step
  !> copies with STATEV(3) = avg; dlambda = STATEV(2) afterwards; the
  !> result becomes p's end-of-step state (overwritten by the next call).
  !> `update_local`: step 1 (every particle with avg = 0; dl(p) out), by
  !> default `update` per particle; a host may do it a block at a time.
  type, abstract :: nonlocal_host_t
  contains
    procedure(host_update), deferred :: update
    procedure :: update_local
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

contains

  !> Step 1 of Algorithm 1: every particle once with <dlambda> = 0, in
  !> order, up to the first error.
  subroutine update_local(self, dl, err)
    class(nonlocal_host_t), intent(inout) :: self
    real(dp), intent(out) :: dl(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: p
    do p = 1, size(dl)
      call self%update(p, 0.0_dp, dl(p), err)
      if (allocated(err)) return
    end do
  end subroutine update_local

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
    call host%update_local(self%dl, err)
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

end module wellposed_mpm_algorithm1
