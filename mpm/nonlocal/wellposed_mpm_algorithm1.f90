!> The dissertation's nonlocal Algorithm 1 for the MPM (eq. 4.46-4.50), one
!> code for 1D and 2D grids; the material is reached through the host
!> (wellposed_mpm_nonlocal_host), one UMAT call per particle and average:
!> the fixed-point map of eq. 4.39. Sweeps gauss_seidel (the dissertation's,
!> pipelined across ranks in the serial order), jacobi (relaxed by
!> 2/(2 +- b), b of eq. 4.43) and coloured; 'anderson' accelerates the map.
!> Across ranks: docs/guide/parallel.md, "Algorithm 1 across ranks".
module wellposed_mpm_algorithm1
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_anderson, only: anderson_t, new_anderson, anderson_step, anderson_push, &
                               anderson_normal_solve
  use wellposed_mpm_nonlocal_settings, only: nl_anderson, nl_sweep_auto, &
                                             nl_gauss_seidel, nl_jacobi, nl_coloured
  use wellposed_mpm_nonlocal_grid, only: nonlocal_t, nonlocal_step_stats_t, nonlocal_project, &
                                         plastic_stats, support_mass, cached_average, warn_bounds, &
                                         field_extents, field_reaches, extend_extents, &
                                         iteration_error, sweep_verdict, sweep_converged, sweep_stop
  use wellposed_mpm_nonlocal_ranks, only: nonlocal_ranks_t
  use wellposed_mpm_sweep_order, only: key_order, find_sorted, sweep_layer, sweep_colour
  use wellposed_mpm_nonlocal_host, only: nonlocal_host_t
  implicit none
  private
  public :: nonlocal_host_t, nonlocal_ranks_t, nonlocal_solve

contains

  !> One time step of Algorithm 1: (1) every particle once with <dlambda> = 0
  !> (eq. 4.41), the plastic set where dlambda > 0 (h_zeta = 0: the local
  !> update); (2) sweeps over the plastic set, the field corrected by
  !> (m_p/m_i) phi_ip (dlambda^{k+1} - dlambda^k) (eq. 4.49-4.50), to the
  !> tolerances; (3) elastic particles with a nonzero average called once
  !> more, and step 2 again if one yields. `x` (ndim, n) positions (m),
  !> `mass` (kg), `node`/`phi` this step's shape weights (nsup, n). A stall,
  !> divergence or host error is an error value; `log_unit` takes the
  !> warnings of eq. 4.43 and 4.45's bounds. Over ranks: `ranks` and `key`
  !> (sweep_key, unique), collective, errors and self%last alike on all.
  subroutine nonlocal_solve(self, host, x, mass, node, phi, err, log_unit, ranks, key)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    real(dp), intent(in) :: x(:, :), mass(:), phi(:, :)
    integer, intent(in) :: node(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: log_unit
    class(nonlocal_ranks_t), intent(inout), optional :: ranks
    integer(int64), intent(in), optional :: key(:)
    integer :: n, p, q, round, sweep
    integer(int64) :: c0, c1
    real(dp) :: avg, dnew
    logical :: changed, par, simul
    integer, allocatable :: act(:), order(:)

    n = size(mass)
    par = present(ranks)
    ! the sweep: 'auto' is Gauss-Seidel in one process, Jacobi across ranks
    sweep = self%set%sweep
    if (sweep == nl_sweep_auto) then
      sweep = nl_gauss_seidel
      if (par) then
        if (ranks%nranks() > 1) sweep = nl_jacobi
      end if
    end if
    self%sweep = sweep
    simul = sweep /= nl_gauss_seidel
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
    call plastic_stats(self)
    if (par) then
      call ranks%sum_int(self%last%n_plastic)
      call ranks%max_real(self%last%max_dlambda)
    end if
    if (.not. self%active .or. self%last%n_plastic == 0) return
    ! the local particles in the serial order (a local model never needs it)
    if (present(key) .and. .not. simul) then
      call key_order(key(1:n), order)
    else
      order = [(p, p=1, n)]
    end if
    call project(self%dl)

    ! The bounds, before iterating.
    do p = 1, n
      if (.not. self%plastic(p)) cycle
      self%last%n_alpha = max(self%last%n_alpha, support_mass(self, x(:, p))/mass(p))
    end do
    if (par) call ranks%max_real(self%last%n_alpha)
    if (self%bound_43 >= 0.0_dp) self%last%bound_printed = self%last%n_alpha*self%bound_43
    if (present(log_unit)) call warn_bounds(self, log_unit)

    do round = 1, self%set%max_rounds
      self%last%rounds = round
      act = pack(order, self%plastic(order))
      call iterate(act, err)
      if (allocated(err)) return
      ! Step 3: plastic diffusion to the elastic particles.
      changed = .false.
      if (par .and. .not. simul) call ranks%nodes_from_lower(self%field)
      call field_extents(self)
      if (simul) then
        call diffuse_simultaneous(err)
      else
        do q = 1, n
          p = order(q)
          if (.not. diffuses_to(p, avg)) cycle
          call host%update(p, avg, dnew, err)
          if (allocated(err)) exit
          self%last%umat_calls = self%last%umat_calls + 1
          if (dnew > 0.0_dp) call reclassify(p, dnew)
        end do
      end if
      if (simul) then
        call refresh()
      else if (par) then
        call ranks%nodes_to_higher(self%field)
        call ranks%nodes_from_highest(self%field)
      end if
      if (par) changed = ranks%any_true(changed)
      if (stopped(err)) return
      if (.not. changed) exit
      if (round == self%set%max_rounds) then
        call new_error(err, status_cutback, 'max_rounds', 'the nonlocal plastic set kept '// &
          'growing by plastic diffusion (step 3 of Algorithm 1) after '// &
          int_text(self%set%max_rounds)//' rounds; raise &nonlocal max_rounds')
        return
      end if
    end do
    call plastic_stats(self)
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
      integer :: k, kbest, q, nact, verdict
      integer(int64) :: s0, s1, s2, s3
      type(anderson_t) :: acc

      nact = size(act)
      if (par) call ranks%sum_int(nact)
      allocate (pos(size(act)), perm(0), xn(0))
      if (simul) then
        call iterate_simultaneous(act, nact, err)
        return
      end if
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
        call system_clock(s1)
        self%ticks_exchange = self%ticks_exchange + (s1 - s0)
        call sweep_pass(act, err, .false.)
        if (par) then
          call system_clock(s2)
          call ranks%nodes_to_higher(self%field)
          call ranks%nodes_from_highest(self%field)
          call system_clock(s3)
          self%ticks_exchange = self%ticks_exchange + (s3 - s2)
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
          call system_clock(s0)
          call ranks%max_real(e)
          call ranks%max_real(gmax)
          call system_clock(s1)
          self%ticks_exchange = self%ticks_exchange + (s1 - s0)
        end if
        call sweep_verdict(self, k, e, gmax, best, kbest, limit, verdict)
        if (verdict == sweep_converged) return
        if (verdict == sweep_stop) exit
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
      call iteration_error(self, k > self%set%max_iterations, e, best, kbest, limit, nact, err)
    end subroutine iterate

    !> Step 2 with the simultaneous sweeps (module comment) on this rank's
    !> plastic particles act(:) (nact over all ranks), plain or with
    !> Anderson: each rank keeps its entries, the Gram system is summed.
    subroutine iterate_simultaneous(act, nact, err)
      integer, intent(in) :: act(:), nact
      type(error_t), allocatable, intent(out) :: err
      real(dp) :: xk(size(act)), gx(size(act)), xn(size(act)), e, e_prev, best, limit, gmax, w
      real(dp) :: gram(self%set%anderson_depth*(self%set%anderson_depth + 1))
      integer :: k, kbest, m, c, ncol, q, verdict
      logical :: defer
      integer, allocatable :: colour(:)
      real(dp) :: gamma(self%set%anderson_depth)
      real(dp), allocatable :: ata(:, :), atb(:)
      integer(int64) :: s0, s1
      type(anderson_t) :: acc

      allocate (colour(size(act)))
      colour = 0
      ncol = 1
      if (self%sweep == nl_coloured) then
        ! blocks of cell layers as wide as the Gaussian's reach plus one
        ncol = 2
        if (present(key)) then
          colour = sweep_colour(sweep_layer(key(act)), ceiling(self%radius/self%dx) + 1)
        else
          colour = sweep_colour(floor((x(self%ndim, act) - self%origin(self%ndim))/self%dx), &
                                ceiling(self%radius/self%dx) + 1)
        end if
      end if
      ! The sweep's Jacobian is -h_zeta/(a + h_eta) times the averaging (eq.
      ! 4.39, 4.47), eigenvalues in [-b, 0] for h_zeta > 0, [0, b] for h_zeta
      ! < 0 (b = bound_43): relaxing by w = 2/(2 + b), resp. 2/(2 - b) when b
      ! < 1, centres them on 0, the smallest factor (docs/guide/parallel.md).
      w = 1.0_dp
      if (self%bound_43 > 0.0_dp) then
        if (self%h_zeta > 0.0_dp) then
          w = 2.0_dp/(2.0_dp + self%bound_43)
        else if (self%h_zeta < 0.0_dp .and. self%bound_43 < 1.0_dp) then
          w = 2.0_dp/(2.0_dp - self%bound_43)
        end if
      end if
      ! at most as many differences as unknowns: more make the least-squares
      ! problem singular, and the step wild
      if (self%set%scheme == nl_anderson) call new_anderson(acc, size(act), &
        min(self%set%anderson_depth, nact), w*self%set%anderson_mixing)
      ! one colour and a step past the sweep's answer: the field is corrected
      ! once, from x^k to x^{k+1}, not to the sweep's answer and on
      defer = ncol == 1 .and. (self%set%scheme == nl_anderson .or. w /= 1.0_dp)
      best = huge(1.0_dp)
      e_prev = huge(1.0_dp)
      kbest = 0
      do k = 1, self%set%max_iterations
        xk = self%dl(act)
        ! one sweep, eq. 4.47, 4.39 (through the UMAT), 4.49-4.50 on `own`,
        ! each colour from the field the previous one left
        call system_clock(s0)
        do c = 0, ncol - 1
          call refresh()
          call sweep_pass(pack(act, colour == c), err, defer)
          if (stopped(err)) return
        end do
        call system_clock(s1)
        self%ticks_sweeps = self%ticks_sweeps + (s1 - s0)
        self%calls_sweeps = self%calls_sweeps + size(act)
        self%last%umat_calls = self%last%umat_calls + size(act)
        self%last%iterations = self%last%iterations + 1
        gx = self%dl(act)
        e = 0.0_dp
        gmax = 0.0_dp
        if (size(act) > 0) then
          e = maxval(abs(gx - xk))
          gmax = maxval(abs(gx))
        end if
        if (par) then
          call system_clock(s0)
          call ranks%max_real(e)
          call ranks%max_real(gmax)
          call system_clock(s1)
          self%ticks_exchange = self%ticks_exchange + (s1 - s0)
        end if
        call sweep_verdict(self, k, e, gmax, best, kbest, limit, verdict)
        if (verdict == sweep_converged) then
          if (defer) then
            do q = 1, size(act)
              call correct_field(act(q), gx(q) - xk(q))
            end do
          end if
          call refresh()
          return
        end if
        if (verdict == sweep_stop) exit
        if (self%set%scheme == nl_anderson) then
          ! anderson_step with the Gram system dR^T [dR r] summed over the ranks;
          ! a residual that grew (the clamp dlambda >= 0 changed the map) starts
          ! the history afresh from the relaxed step
          if (e > e_prev) call new_anderson(acc, size(act), min(self%set%anderson_depth, nact), &
                                            w*self%set%anderson_mixing)
          e_prev = e
          call anderson_push(acc, xk, gx - xk)
          xn = xk + acc%mixing*(gx - xk)
          m = acc%count
          if (m > 0) then
            gram(1:m*m) = reshape(matmul(transpose(acc%dr(:, 1:m)), acc%dr(:, 1:m)), [m*m])
            gram(m*m + 1:m*m + m) = matmul(gx - xk, acc%dr(:, 1:m))
            if (par) call ranks%sum_reals(gram(1:m*m + m))
            ata = reshape(gram(1:m*m), [m, m])
            atb = gram(m*m + 1:m*m + m)
            call anderson_normal_solve(ata, atb, gamma(1:m))
            xn = xn - matmul(acc%dx(:, 1:m) + acc%mixing*acc%dr(:, 1:m), gamma(1:m))
          end if
        else if (w /= 1.0_dp) then
          xn = xk + w*(gx - xk)
        else
          cycle
        end if
        do q = 1, size(act)
          call correct_field(act(q), xn(q) - merge(xk(q), gx(q), defer))
        end do
        self%dl(act) = xn
      end do
      call iteration_error(self, k > self%set%max_iterations, e, best, kbest, limit, nact, err)
    end subroutine iterate_simultaneous

    !> One pass over `list` in its order: average, UMAT, correction (eq. 4.47,
    !> 4.39, 4.49-4.50). Gauss-Seidel corrects the field it reads as it goes;
    !> the simultaneous sweeps read the field as the pass began and correct
    !> this rank's part `own`: their UMAT calls go to the host as one list;
    !> with `defer` the correction is left to the caller.
    subroutine sweep_pass(list, err, defer)
      integer, intent(in) :: list(:)
      type(error_t), allocatable, intent(out) :: err
      logical, intent(in) :: defer
      integer :: q, pp
      real(dp) :: avg, dn
      real(dp), allocatable :: avgs(:), dns(:)
      if (simul) then
        allocate (avgs(size(list)), dns(size(list)))
        do q = 1, size(list)
          call cached_average(self, list(q), x(:, list(q)), avgs(q))
        end do
        call host%update_list(list, avgs, dns, err)
        if (allocated(err)) return
        if (defer) then
          self%dl(list) = dns
          return
        end if
        do q = 1, size(list)
          pp = list(q)
          call correct_field(pp, dns(q) - self%dl(pp))
          self%dl(pp) = dns(q)
        end do
        return
      end if
      do q = 1, size(list)
        pp = list(q)
        call cached_average(self, pp, x(:, pp), avg)
        call host%update(pp, avg, dn, err)
        if (allocated(err)) return
        call correct_field(pp, dn - self%dl(pp))
        self%dl(pp) = dn
      end do
    end subroutine sweep_pass

    !> Step 3 with the simultaneous sweeps: the averages read the field as
    !> the pass began (corrections go to `own`), so the elastic particles
    !> with a nonzero average go to the host as one list.
    subroutine diffuse_simultaneous(err)
      type(error_t), allocatable, intent(out) :: err
      integer :: q, p, m
      integer, allocatable :: list(:)
      real(dp), allocatable :: avgs(:), dns(:)
      allocate (list(n), avgs(n), dns(n))
      m = 0
      do q = 1, n
        p = order(q)
        if (.not. diffuses_to(p, avgs(m + 1))) cycle
        m = m + 1
        list(m) = p
      end do
      call host%update_list(list(1:m), avgs(1:m), dns(1:m), err)
      if (allocated(err)) return
      self%last%umat_calls = self%last%umat_calls + m
      do q = 1, m
        if (dns(q) > 0.0_dp) call reclassify(list(q), dns(q))
      end do
    end subroutine diffuse_simultaneous

    !> Whether step 3 calls particle p: elastic, with a nonzero average
    !> `avg` (zero when its support holds no nonzero field node; with a zero
    !> average the step-1 call already had this input).
    logical function diffuses_to(p, avg)
      integer, intent(in) :: p
      real(dp), intent(out) :: avg
      avg = 0.0_dp
      diffuses_to = .false.
      if (self%plastic(p)) return
      if (.not. field_reaches(self, x(:, p))) return
      call cached_average(self, p, x(:, p), avg)
      diffuses_to = avg /= 0.0_dp
    end function diffuses_to

    !> Step 3's elastic particle p yields (dlambda = dnew > 0): it joins the
    !> plastic set and its contribution enters the field.
    subroutine reclassify(p, dnew)
      integer, intent(in) :: p
      real(dp), intent(in) :: dnew
      changed = .true.
      self%plastic(p) = .true.
      self%last%n_reclassified = self%last%n_reclassified + 1
      call correct_field(p, dnew - self%dl(p))
      call extend_extents(self, node(:, p))
      self%dl(p) = dnew
    end subroutine reclassify

    !> The field of the simultaneous sweeps: every rank's `own` added at the
    !> nodes they share (collective).
    subroutine refresh()
      integer(int64) :: t0, t1
      self%field = self%own
      if (.not. par) return
      call system_clock(t0)
      call ranks%nodes_sum(self%field)
      call system_clock(t1)
      self%ticks_exchange = self%ticks_exchange + (t1 - t0)
    end subroutine refresh

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
      if (simul) then
        ! each rank its own part, then the parts added at shared nodes
        call nonlocal_project(self, mass, node, phi, values)
        self%own = self%field
        if (par) then
          call ranks%nodes_sum(self%node_mass)
          call ranks%nodes_sum(self%field)
        end if
        return
      end if
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

    !> eq. 4.49-4.50: move particle p's contribution on its nodes by `delta`
    !> (in the simultaneous sweeps on this rank's part of the field).
    subroutine correct_field(p, delta)
      integer, intent(in) :: p
      real(dp), intent(in) :: delta
      integer :: k, i
      if (delta == 0.0_dp) return
      if (simul) then
        do k = 1, size(node, 1)
          i = node(k, p)
          self%own(i) = self%own(i) + mass(p)*phi(k, p)*delta
        end do
        return
      end if
      do k = 1, size(node, 1)
        i = node(k, p)
        self%field(i) = self%field(i) + mass(p)*phi(k, p)*delta
      end do
    end subroutine correct_field

  end subroutine nonlocal_solve

end module wellposed_mpm_algorithm1
