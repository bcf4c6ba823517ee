!> The implicit MPM step (docs/research/implicit.md): Newton on the step's
!> grid displacement increment du, R(du) = f_int + f_ext(t + dt) = 0 on the
!> free nodes (eq. 4.5 without inertia; dynamic: minus the trapezoidal rule's
!> m a, wellposed_mpm_newmark), the stress from the UMAT over du (eq. 4.11
!> with v = du/dt), the tangent from its DDSDDE (consistent, nonsymmetric
!> for a nonassociative model; wellposed_mpm_implicit_forces). The bar, the
!> plate and the cylinder, on any ranks (wellposed_mpm_implicit_dofs); a
!> nonlocal model runs Algorithm 1 in every iteration (Anderson-accelerated).
module wellposed_mpm_implicit_step
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_shape_weights, only: shape_weights
  use wellposed_mpm_transfer, only: p2g, velocity_gradients
  use wellposed_mpm_implicit_forces, only: residual, assemble, assemble_hoop, row_nonzeros
  use wellposed_mpm_implicit_dofs, only: number_dofs, gather_free, complete_residual, &
                                        zero_mean_motion
  use wellposed_mpm_implicit_contact, only: contact_platen, contact_residual, contact_tangent
  use wellposed_mpm_grid, only: cell_layer
  use wellposed_mpm_nonlocal, only: nonlocal_solve, nonlocal_average, sweep_key
  use wellposed_anderson, only: anderson_t, new_anderson, anderson_step
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t, size_workspace, keep_start, &
                                 restore_start
  use wellposed_mpm_bar_kind, only: bar_kind_t
  use wellposed_mpm_plate_kind, only: plate_kind_t
  use wellposed_mpm_method, only: no_viscosity
  use wellposed_mpm_particle_umat, only: umat_particle
  use wellposed_umat_host, only: umat_is_ours
  use wellposed_mpm_linear_solver, only: linear_solver_t, solver_direct
  use wellposed_mpm_newmark, only: newmark_t, newmark_start, newmark_inertia, &
                                   newmark_tangent, newmark_particles
  use wellposed_step_kinematics, only: step_kinematics
  implicit none
  private
  public :: implicit_settings_t, newton_report_t, advance_implicit, implicit_refusal, &
            dynamic_refusal, max_newton

  integer, parameter :: max_newton = 50

  !> What the Newton iteration is told: its iteration limit and the
  !> tolerance on the residual relative to the internal force's scale.
  type :: implicit_settings_t
    integer :: max_iterations = 20
    real(dp) :: rtol = 1.0e-10_dp
    !> with Algorithm 1 the tangent leaves out the averages' coupling, so the
    !> corrections converge linearly: Anderson acceleration of depth m on
    !> the free dofs' map du -> du + A^-1 R (0: the plain corrections)
    integer :: anderson_depth = 5
    integer :: method = solver_direct     !< the linear solver (wellposed_mpm_linear_solver)
  end type implicit_settings_t

  !> One step's Newton history: relative residual after each evaluation
  !> (residual(0): the predictor's), the linear solver's iterations and
  !> Algorithm 1's sweeps (a nonlocal model) summed over the step.
  type :: newton_report_t
    integer :: iterations = 0             !< linear solves of the step
    integer :: linear_iterations = 0
    integer :: sweeps = 0
    real(dp) :: residual(0:max_newton) = 0.0_dp
    logical :: converged = .false.
  end type newton_report_t

contains

  !> Why scene sc cannot take the implicit step (empty: it can).
  function implicit_refusal(sc) result(why)
    type(mpm_scene_t), intent(in) :: sc
    character(len=:), allocatable :: why
    integer :: k
    logical :: ours
    why = ''
    select type (k => sc%kind)
    type is (bar_kind_t)
    class is (plate_kind_t)
      ! the plate and the axisymmetric cylinder (whose kind extends it)
    class default
      why = 'the implicit scheme runs the bar, the plate and the cylinder only so far'
    end select
    if (len(why) > 0) then
      return
    else if (sc%visc_a1 > 0.0_dp .or. sc%visc_a2 > 0.0_dp) then
      why = no_viscosity
    end if
    if (len(why) > 0) return
    ! our VUMAT's material is our UMAT's (same PROPS): the UMAT gives DDSDDE
    ours = umat_is_ours()
    do k = 1, sc%mats%n
      if (sc%mats%vumat(k) .and. .not. (sc%mats%ours(k) .and. ours)) &
        why = 'material '//int_text(k)//' goes through a user''s VUMAT, which has no '// &
              'tangent (DDSDDE): the implicit scheme needs a UMAT'
    end do
  end function implicit_refusal

  !> Why scene sc cannot take the dynamic (Newmark) step beyond
  !> implicit_refusal's reasons (empty: it can).
  function dynamic_refusal(sc) result(why)
    type(mpm_scene_t), intent(in) :: sc
    character(len=:), allocatable :: why
    real(dp) :: plane(2)
    why = ''
    if (contact_platen(sc, sc%kind, plane)) why = 'the Newmark step has no contact platen '// &
      'yet (its penalty would ring undamped): &boundary platen = ''grid'' or ''surface'', '// &
      'or scheme = ''implicit'''
  end function dynamic_refusal

  !> One step of length sc%dt (see the module comment), the load at t + dt:
  !> quasi-static, or with `accel` (the particles' accelerations, ndim x n)
  !> the trapezoidal rule's dynamic step. On return the particles hold the
  !> converged state, their positions moved by the interpolated du and v =
  !> du/dt (dynamic: the trapezoidal update, accel the end's). An error
  !> leaves the scene and accel at the step's start (status_cutback: Newton
  !> did not converge, or the UMAT asked for a smaller step). Collective
  !> over the scene's ranks (the particles already on their ranks: hand_off
  !> of wellposed_mpm_step), an error on one rank an error on every rank.
  subroutine advance_implicit(sc, solver, opt, rep, err, accel)
    type(mpm_scene_t), intent(inout) :: sc
    type(linear_solver_t), intent(inout) :: solver
    type(implicit_settings_t), intent(in) :: opt
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(inout), optional :: accel(:, :)
    class(scene_kind_t), allocatable :: kind
    character(len=:), allocatable :: why
    why = ''
    if (present(accel)) why = dynamic_refusal(sc)
    if (len(why) == 0) why = implicit_refusal(sc)
    if (len(why) > 0) then
      call new_error(err, status_invalid, 'time%scheme', why); return
    end if
    if (present(accel)) then
      if (size(accel, 1) /= sc%ndim .or. size(accel, 2) < sc%parts%n) then
        call new_error(err, status_invalid, 'time%scheme', 'the dynamic implicit step '// &
                       'holds accelerations of '//int_text(size(accel, 2))//' particles, '// &
                       'the scene has '//int_text(sc%parts%n)); return
      end if
    end if
    call move_alloc(sc%kind, kind)
    call newton_step(sc, kind, solver, opt, rep, err, accel)
    call move_alloc(kind, sc%kind)
  end subroutine advance_implicit

  !> advance_implicit's step, the scene's kind in `kind`.
  subroutine newton_step(sc, kind, solver, opt, rep, err, accel)
    type(mpm_scene_t), intent(inout) :: sc
    class(scene_kind_t), intent(inout) :: kind
    type(linear_solver_t), intent(inout) :: solver
    type(implicit_settings_t), intent(in) :: opt
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(inout), optional :: accel(:, :)
    type(newmark_t) :: nm
    real(dp), allocatable :: x0(:, :), f0(:, :, :), v0(:), s0(:, :), sv0(:, :), e0(:, :)
    real(dp), allocatable :: du(:, :), r(:), delta(:), dtan(:, :), avg(:), xf(:), xn(:)
    type(anderson_t) :: acc
    logical :: accelerate
    integer, allocatable :: dof(:, :)
    integer(int64), allocatable :: skey(:)
    ! the optional terms of the residual: unallocated, they are absent there
    real(dp), allocatable :: radius(:), stretch(:), inertia(:, :), mag(:, :)
    real(dp) :: given(sc%ndim), scale, rel
    integer :: n, nd, nfree, it, last, p, a, rows(2)
    real(dp) :: plane(2)
    logical :: axi, contact, pinned(sc%ndim)
    call size_workspace(sc)
    nd = sc%ndim
    associate (g => sc%grid, pt => sc%parts)
      n = pt%n
      call shape_weights(sc%shape, pt, sc%origin, sc%dx, sc%nx, sc%nnz)
      call sc%exchange%check_support(pt, g, err)
      call sc%exchange%sync_error(err)
      if (allocated(err)) return
      ! the grid's mass (the nodes in use), the step's conditions and loads
      call p2g(g, pt, n, nnz=sc%nnz)
      contact = contact_platen(sc, kind, plane)
      call push(.false.)
      call kind%forces(sc)
      call push(.true.)
      call sc%exchange%sum_grid(g, .false.)
      call step_loads(sc, kind, given)
      ! an axisymmetric kind: the hoop terms, from each particle's radius
      ! (any rank's particles tell: every rank numbers the dofs alike)
      axi = .false.
      if (n > 0) axi = kind%radius(pt%x(:, 1)) > 0.0_dp
      axi = sc%exchange%any_true(axi)
      ! quasi-static: a rigid translation nothing holds is pinned (the hoop
      ! terms hold the cylinder's radial one)
      pinned = .false.
      if (present(accel) .or. axi) then
        call number_dofs(sc, dof, nfree, rows)
      else
        call number_dofs(sc, dof, nfree, rows, pinned)
      end if
      if (nfree == 0) then
        call new_error(err, status_invalid, 'time%scheme', 'the implicit step has no free '// &
                       'node: every node in use is fixed'); return
      end if
      x0 = pt%x(:, 1:n); f0 = pt%defgrad(:, :, 1:n); v0 = pt%vol(1:n)
      s0 = pt%stress(:, 1:n); sv0 = pt%statev(:, 1:n); e0 = pt%stran(:, 1:n)
      ! du to start: the given motion on its nodes, elsewhere the particles'
      ! velocity of the last step mapped to the grid (p2g's momentum), so
      ! Newton starts on the last step's loading path (its plastic set);
      ! dynamic: dt v + dt^2 a / 4, the start's acceleration kept
      allocate (du(nd, g%glo:g%ghi), source=0.0_dp)
      if (present(accel)) call newmark_start(sc, accel, given, nm, du)
      do a = g%glo, g%ghi
        if (g%mass(a) > sc%mass_floor .and. .not. present(accel)) &
          du(:, a) = sc%dt*g%momentum(1:nd, a)/g%mass(a)
        where (g%fixed(1:nd, a)) du(:, a) = 0.0_dp
        where (g%given(1:nd, a)) du(:, a) = given*sc%dt
      end do
      allocate (r(nfree), delta(nfree), dtan(sc%ntens**2, n), avg(n), xf(nfree), xn(nfree), &
                mag(nd, g%glo:g%ghi), source=0.0_dp)
      ! Algorithm 1's sweep order: the explicit step's keys (the start's cell layer, the id)
      allocate (skey(n))
      do p = 1, n
        skey(p) = sweep_key(cell_layer(x0(nd, p), sc%origin(nd), sc%dx, sc%nlayers), pt%gid(p))
      end do
      if (axi) allocate (radius(n), stretch(n))
      accelerate = sc%nl%active .and. opt%anderson_depth > 0
      if (accelerate) call new_anderson(acc, nfree, opt%anderson_depth, 1.0_dp)
      if (sc%exchange%nranks() > 1) then
        call solver%setup(nfree, row_nonzeros(nd, pt%nsup), opt%method, err, &
                          comm=sc%exchange%mpi_handle(), rows=rows)
      else
        call solver%setup(nfree, row_nonzeros(nd, pt%nsup), opt%method, err)
      end if
      if (allocated(err)) return
      do it = 0, opt%max_iterations
        ! --- the state at du from the start's: F, V, the UMAT's stress and
        ! tangent (V_n, the kinematics' vol_n, is the start's v0)
        call restore()
        g%velocity(1:nd, :) = du/sc%dt
        call velocity_gradients(g, pt, n, sc%lgrad, sc%nnz)
        ! the hoop strain is the radius's: the iterate's positions first
        if (axi) call move_particles(sc, x0, du)
        last = kind%kinematics(sc)
        if (last <= n) call fail('particle '//int_text(pt%gid(last))//' was turned inside out')
        if (stopped()) return
        if (axi) then
          do p = 1, n
            radius(p) = kind%radius(pt%x(:, p))
            stretch(p) = pt%defgrad(3, 3, p)/f0(3, 3, p)
          end do
        end if
        if (sc%nl%active) then
          call nonlocal_fixed_point(sc, x0, du, skey, avg, rep%sweeps, err)
          if (stopped()) return
        end if
        do p = 1, n
          call stress_tangent(sc, p, avg(p), dtan(:, p), err)
          if (allocated(err)) exit
        end do
        if (stopped()) return
        ! --- the residual on the free nodes and its scale
        if (present(accel)) inertia = newmark_inertia(sc, nm, du)
        call residual(sc, dof, v0, r, mag, inertia, radius, stretch)
        if (contact) call contact_residual(sc, plane, x0, f0, du, dof, r, mag)
        call complete_residual(sc, r, mag, scale)
        rel = maxval(abs(r))/max(scale, tiny(1.0_dp))
        rep%residual(it) = rel
        if (rel <= opt%rtol) then
          rep%converged = .true.
          exit
        end if
        if (it == opt%max_iterations) exit
        ! --- the tangent A = -dR/du and the Newton correction A delta = R
        call assemble(sc, solver, dof, dtan, s0, v0)
        if (axi) call assemble_hoop(sc, solver, dof, dtan, radius)
        if (contact) call contact_tangent(sc, plane, x0, f0, du, dof, solver)
        if (present(accel)) call newmark_tangent(sc, solver, dof)
        call solver%solve(r, delta, err, last)
        if (stopped()) return
        rep%iterations = rep%iterations + 1
        rep%linear_iterations = rep%linear_iterations + last
        if (accelerate) then
          ! Anderson on x -> x + delta, x the free dofs of du
          call gather_free(sc, dof, du, xf)
          call anderson_step(acc, xf, xf + delta, xn)
          delta = xn - xf
        end if
        do a = g%glo, g%ghi
          where (dof(:, a) > 0) du(:, a) = du(:, a) + delta(max(dof(:, a), 1))
        end do
      end do
      if (.not. rep%converged) then
        call fail('Newton did not converge in '//int_text(opt%max_iterations)// &
                  ' iterations (relative residual '//real_text(rel)//')')
        if (stopped()) return
      end if
      ! --- the converged step: positions and velocities from du
      call zero_mean_motion(sc, pinned, du)
      call move_particles(sc, x0, du)
      if (.not. present(accel)) then
        do p = 1, n
          pt%v(1:nd, p) = (pt%x(1:nd, p) - x0(1:nd, p))/sc%dt
        end do
      end if
      if (present(accel)) call newmark_particles(sc, nm, du, accel)
      call kind%bookkeeping(sc)
    end associate
    sc%t = sc%t + sc%dt
    sc%nstep = sc%nstep + 1
  contains
    subroutine restore()
      associate (pt => sc%parts)
        pt%defgrad(:, :, 1:n) = f0; pt%vol(1:n) = v0; pt%x(:, 1:n) = x0
        pt%stress(:, 1:n) = s0; pt%statev(:, 1:n) = sv0; pt%stran(:, 1:n) = e0
      end associate
    end subroutine restore
    subroutine fail(what)
      character(len=*), intent(in) :: what
      call new_error(err, status_cutback, 'time', 'implicit step '//int_text(sc%nstep + 1)// &
                     ', t = '//real_text(sc%t + sc%dt)//' s: '//what)
    end subroutine fail
    !> The contact platen's explicit push in kind%forces on or off.
    subroutine push(on)
      logical, intent(in) :: on
      select type (kind)
      class is (plate_kind_t)
        kind%push = on
      end select
    end subroutine push
    !> An error on any rank, made every rank's (the lowest rank's message):
    !> the particles back at the step's start. Collective.
    logical function stopped()
      call sc%exchange%sync_error(err)
      stopped = allocated(err)
      if (stopped) call restore()
    end function stopped
  end subroutine newton_step

  !> The kind's conditions of the step (the node flags and given velocity,
  !> as the explicit step has them: the plate's platen over the step) and
  !> its loads at the step's end t + dt on g%fext (the bar's surface
  !> traction: the quasi-static balance is the end's).
  subroutine step_loads(sc, kind, given)
    type(mpm_scene_t), intent(inout) :: sc
    class(scene_kind_t), intent(inout) :: kind
    real(dp), intent(out) :: given(:)
    real(dp) :: t0, fext(size(sc%grid%fext, 1), sc%grid%glo:sc%grid%ghi), end_given(size(given))
    t0 = sc%t
    fext = sc%grid%fext
    given = 0.0_dp
    call kind%conditions(sc, given)
    sc%grid%fext = fext
    sc%t = t0 + sc%dt
    end_given = 0.0_dp
    call kind%conditions(sc, end_given)
    sc%t = t0
  end subroutine step_loads

  !> The particles at the step's grid displacement du from x0: x0 + sum phi du.
  subroutine move_particles(sc, x0, du)
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: x0(:, :), du(:, sc%grid%glo:)
    integer :: p, a
    associate (pt => sc%parts)
      do p = 1, pt%n
        do a = 1, sc%ndim
          pt%x(a, p) = x0(a, p) + sum(pt%phi(1:sc%nnz(p), p)*du(a, pt%node(1:sc%nnz(p), p)))
        end do
      end do
    end associate
  end subroutine move_particles

  !> Algorithm 1 at the iterate du (the dissertation's global fixed point
  !> inside each Newton iteration): the sweeps of the explicit step from the
  !> kinematics' start (the rotated stress), the averages at the end-of-step
  !> positions x0 + sum phi du; avg(p), each particle's converged average
  !> (0 for the elastic ones), for stress_tangent, which then redoes the
  !> particle's update with it. `sweeps` counts Algorithm 1's sweeps.
  subroutine nonlocal_fixed_point(sc, x0, du, skey, avg, sweeps, err)
    type(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: x0(:, :), du(:, sc%grid%glo:)
    integer(int64), intent(in) :: skey(:)
    real(dp), intent(out) :: avg(:)
    integer, intent(inout) :: sweeps
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: start(:)
    integer :: p, n
    logical :: warm
    n = sc%parts%n
    associate (pt => sc%parts)
      do p = 1, n
        call keep_start(sc, p)
      end do
      call move_particles(sc, x0, du)
      sc%max_substeps_step = 1
      ! Algorithm 1 starts from the last solve's dlambda (the last iterate's,
      ! or at a step's first iterate the last step's): fewer sweeps
      warm = allocated(sc%nl%dl)
      if (warm) warm = size(sc%nl%dl) == n
      if (warm) then
        start = sc%nl%dl
        call nonlocal_solve(sc%nl, sc, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, ranks=sc%exchange, key=skey, dl_start=start)
      else
        call nonlocal_solve(sc%nl, sc, pt%x(:, 1:n), pt%mass(1:n), pt%node(:, 1:n), &
                            pt%phi(:, 1:n), err, ranks=sc%exchange, key=skey)
      end if
      if (allocated(err)) return
      sweeps = sweeps + sc%nl%last%iterations
      do p = 1, n
        avg(p) = 0.0_dp
        if (sc%nl%plastic(p)) call nonlocal_average(sc%nl, pt%x(:, p), avg(p))
        call restore_start(sc, p)
      end do
    end associate
  end subroutine nonlocal_fixed_point

  !> Particle p's stress over its increment through the UMAT with the
  !> tangent asked for (our PROPS(14), the explicit host's slot, set to 0),
  !> the nonlocal average avg in our slot STATEV(3) (0: a local model):
  !> dtan = DDSDDE (column-major, NTENS x NTENS), at fixed avg.
  subroutine stress_tangent(sc, p, avg, dtan, err)
    type(mpm_scene_t), intent(inout) :: sc
    integer, intent(in) :: p
    real(dp), intent(in) :: avg
    real(dp), intent(out) :: dtan(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: props(size(sc%mats%props, 1)), dl
    integer :: k, np, nsub, nt, nd
    k = sc%mat(p)
    np = sc%mats%nprops(k)
    nt = sc%ntens
    nd = sc%ndim
    props(1:np) = sc%mats%props(1:np, k)
    if (sc%mats%ours(k) .and. np >= 14) props(14) = 0.0_dp
    sc%host%ours = sc%mats%contract(k)
    sc%host%kinematics_given = .true.
    associate (pt => sc%parts)
      if (allocated(sc%f_n)) call step_kinematics(sc%f_n(:, :, p), pt%defgrad(1:nd, 1:nd, p), &
        sc%host%dfgrd0, sc%host%dfgrd1, sc%host%drot)
      call umat_particle(sc%host, props(1:np), sc%t, sc%dt, sc%nstep + 1, pt%gid(p), &
                         pt%x(:, p), pt%stress(1:nt, p), pt%statev(:, p), pt%stran(1:nt, p), &
                         sc%de(:, p), avg, dl, nsub, err)
    end associate
    if (allocated(err)) return
    if (nsub > 1) then
      ! PNEWDT < 1: the host split the increment, so DDSDDE is one part's;
      ! the step is cut back instead (the stepper's step control)
      call new_error(err, status_cutback, 'umat', 'the UMAT asked to cut back the '// &
                     'increment of particle '//int_text(sc%parts%gid(p))//' (PNEWDT < 1)')
      return
    end if
    dtan = sc%host%ddsdde(1:nt*nt)
  end subroutine stress_tangent

end module wellposed_mpm_implicit_step
