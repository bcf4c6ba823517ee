!> The implicit quasi-static MPM step (docs/research/implicit.md): Newton on
!> the step's grid displacement increment du, R(du) = f_int + f_ext(t + dt)
!> = 0 on the free nodes (eq. 4.5 without inertia), each iteration's stress
!> from the UMAT over the increment du gives (eq. 4.11 with v = du/dt), the
!> tangent from its DDSDDE (the consistent tangent; nonsymmetric for a
!> nonassociative model). One rank, the
!> bar (ndim = 1), local models through the UMAT; the same scene, weights,
!> kind and bookkeeping as the explicit step (wellposed_mpm_step).
module wellposed_mpm_implicit_step
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text, real_text
  use wellposed_mpm_shape_weights, only: shape_weights
  use wellposed_mpm_transfer, only: p2g, velocity_gradients
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t, size_workspace
  use wellposed_mpm_particle_umat, only: umat_particle
  use wellposed_umat_host, only: umat_is_ours
  use wellposed_mpm_linear_solver, only: linear_solver_t, solver_direct
  use wellposed_step_kinematics, only: step_kinematics
  implicit none
  private
  public :: implicit_settings_t, newton_report_t, advance_implicit, implicit_refusal, &
            max_newton

  integer, parameter :: max_newton = 50

  !> What the Newton iteration is told: its iteration limit and the
  !> tolerance on the residual relative to the internal force's scale.
  type :: implicit_settings_t
    integer :: max_iterations = 20
    real(dp) :: rtol = 1.0e-10_dp
    integer :: method = solver_direct     !< the linear solver (wellposed_mpm_linear_solver)
  end type implicit_settings_t

  !> One step's Newton history: relative residual after each evaluation
  !> (residual(1): at du = 0), the linear solver's iterations summed.
  type :: newton_report_t
    integer :: iterations = 0             !< linear solves of the step
    integer :: linear_iterations = 0
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
    if (sc%ndim /= 1) then
      why = 'the implicit scheme runs the bar (1D) only so far'
    else if (sc%exchange%nranks() /= 1) then
      why = 'the implicit scheme runs on one rank only so far'
    else if (sc%nl%active) then
      why = 'the implicit scheme has no nonlocal (Algorithm 1) iteration yet'
    else if (sc%visc_a1 > 0.0_dp .or. sc%visc_a2 > 0.0_dp) then
      why = 'a quasi-static step has no bulk viscosity (&viscosity a1 = a2 = 0)'
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

  !> One quasi-static step of length sc%dt (see the module comment), the
  !> load at t + dt; on return the particles hold the converged state, their
  !> positions moved by the interpolated du and v = du/dt. An error leaves
  !> the scene at its start of step (status_cutback: Newton did not
  !> converge, or the UMAT asked for a smaller step).
  subroutine advance_implicit(sc, solver, opt, rep, err)
    type(mpm_scene_t), intent(inout) :: sc
    type(linear_solver_t), intent(inout) :: solver
    type(implicit_settings_t), intent(in) :: opt
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    class(scene_kind_t), allocatable :: kind
    character(len=:), allocatable :: why
    why = implicit_refusal(sc)
    if (len(why) > 0) then
      call new_error(err, status_invalid, 'time%scheme', why); return
    end if
    call move_alloc(sc%kind, kind)
    call newton_step(sc, kind, solver, opt, rep, err)
    call move_alloc(kind, sc%kind)
  end subroutine advance_implicit

  !> advance_implicit's step, the scene's kind in `kind`.
  subroutine newton_step(sc, kind, solver, opt, rep, err)
    type(mpm_scene_t), intent(inout) :: sc
    class(scene_kind_t), intent(inout) :: kind
    type(linear_solver_t), intent(inout) :: solver
    type(implicit_settings_t), intent(in) :: opt
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: x0(:, :), f0(:, :, :), v0(:), s0(:, :), sv0(:, :), e0(:, :)
    real(dp), allocatable :: du(:), r(:), delta(:), dtan(:)
    integer, allocatable :: dof(:)
    real(dp) :: given(1), t0, scale, rel
    integer :: n, nfree, it, last, p
    call size_workspace(sc)
    associate (g => sc%grid, pt => sc%parts)
      n = pt%n
      call shape_weights(sc%shape, pt, sc%origin, sc%dx, sc%nx, sc%nnz)
      call sc%exchange%check_support(pt, g, err)
      if (allocated(err)) return
      ! the grid's mass (the nodes in use) and the load at the step's end
      call p2g(g, pt, n, nnz=sc%nnz)
      t0 = sc%t
      sc%t = t0 + sc%dt
      given = 0.0_dp
      call kind%conditions(sc, given)
      sc%t = t0
      call number_dofs(sc, dof, nfree)
      if (nfree == 0) then
        call new_error(err, status_invalid, 'time%scheme', 'the implicit step has no free '// &
                       'node: every node in use is fixed'); return
      end if
      x0 = pt%x(:, 1:n); f0 = pt%defgrad(:, :, 1:n); v0 = pt%vol(1:n)
      s0 = pt%stress(:, 1:n); sv0 = pt%statev(:, 1:n); e0 = pt%stran(:, 1:n)
      allocate (du(g%glo:g%ghi), source=0.0_dp)
      allocate (r(nfree), delta(nfree), dtan(n))
      call solver%setup(nfree, 2*pt%nsup - 1, opt%method, err)
      if (allocated(err)) return
      do it = 0, opt%max_iterations
        ! --- the state at du from the start's: F, V, the UMAT's stress and
        ! tangent (V_n, the kinematics' vol_n, is the start's v0)
        call restore()
        g%velocity(1, :) = du/sc%dt
        call velocity_gradients(g, pt, n, sc%lgrad, sc%nnz)
        last = kind%kinematics(sc)
        if (last <= n) then
          call fail('particle '//int_text(pt%gid(last))//' was turned inside out'); return
        end if
        do p = 1, n
          call stress_tangent(sc, p, dtan(p), err)
          if (allocated(err)) then
            call restore(); return
          end if
        end do
        ! --- the residual on the free nodes and its scale
        call residual(sc, dof, v0, r, scale)
        rel = maxval(abs(r))/max(scale, tiny(1.0_dp))
        rep%residual(it) = rel
        if (rel <= opt%rtol) then
          rep%converged = .true.
          exit
        end if
        if (it == opt%max_iterations) exit
        ! --- the tangent A = -dR/du and the Newton correction A delta = R
        call assemble(sc, solver, dof, dtan, v0)
        call solver%solve(r, delta, err, last)
        if (allocated(err)) then
          call restore(); return
        end if
        rep%iterations = rep%iterations + 1
        rep%linear_iterations = rep%linear_iterations + last
        call add_correction(dof, delta, du)
      end do
      if (.not. rep%converged) then
        call fail('Newton did not converge in '//int_text(opt%max_iterations)// &
                  ' iterations (relative residual '//real_text(rel)//')'); return
      end if
      ! --- the converged step: positions and velocities from du
      do p = 1, n
        pt%x(1, p) = x0(1, p) + sum(pt%phi(1:sc%nnz(p), p)*du(pt%node(1:sc%nnz(p), p)))
        pt%v(1, p) = (pt%x(1, p) - x0(1, p))/sc%dt
      end do
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
      call restore()
      call new_error(err, status_cutback, 'time', 'implicit step '//int_text(sc%nstep + 1)// &
                     ', t = '//real_text(sc%t + sc%dt)//' s: '//what)
    end subroutine fail
  end subroutine newton_step

  !> Free degrees of freedom: nodes in use (mass above the floor), neither
  !> fixed nor given, numbered 1 .. nfree in node order (0: not free).
  subroutine number_dofs(sc, dof, nfree)
    type(mpm_scene_t), intent(in) :: sc
    integer, allocatable, intent(out) :: dof(:)
    integer, intent(out) :: nfree
    integer :: i
    associate (g => sc%grid)
      allocate (dof(g%glo:g%ghi), source=0)
      nfree = 0
      do i = g%glo, g%ghi
        if (.not. g%mass(i) > sc%mass_floor) cycle
        if (g%fixed(1, i) .or. g%given(1, i)) cycle
        nfree = nfree + 1
        dof(i) = nfree
      end do
    end associate
  end subroutine number_dofs

  !> Particle p's stress over its increment through the UMAT with the
  !> tangent asked for (our PROPS(14), the explicit host's slot, set to 0):
  !> dtan = DDSDDE(1, 1), d sigma_11 / d eps_11 of the uniaxial increment.
  subroutine stress_tangent(sc, p, dtan, err)
    type(mpm_scene_t), intent(inout) :: sc
    integer, intent(in) :: p
    real(dp), intent(out) :: dtan
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: props(size(sc%mats%props, 1)), dl
    integer :: k, np, nsub, nt
    k = sc%mat(p)
    np = sc%mats%nprops(k)
    nt = sc%ntens
    props(1:np) = sc%mats%props(1:np, k)
    if (sc%mats%ours(k) .and. np >= 14) props(14) = 0.0_dp
    sc%host%ours = sc%mats%contract(k)
    sc%host%kinematics_given = .true.
    associate (pt => sc%parts)
      if (allocated(sc%f_n)) call step_kinematics(sc%f_n(:, :, p), pt%defgrad(1:1, 1:1, p), &
        sc%host%dfgrd0, sc%host%dfgrd1, sc%host%drot)
      call umat_particle(sc%host, props(1:np), sc%t, sc%dt, sc%nstep + 1, pt%gid(p), &
                         pt%x(:, p), pt%stress(1:nt, p), pt%statev(:, p), pt%stran(1:nt, p), &
                         sc%de(:, p), 0.0_dp, dl, nsub, err)
    end associate
    if (allocated(err)) return
    if (nsub > sc%max_substeps_step) sc%max_substeps_step = nsub
    dtan = sc%host%ddsdde(1)
  end subroutine stress_tangent

  !> R = f_int + f_ext on the free nodes, f_int = -sum_p G_ip sigma_p V_p
  !> (eq. 4.5) in the step's end configuration: G_ip V_p there is G_ip V_n,p
  !> of the start (weights at x^n, vn); scale: the largest node sum of
  !> |G_ip sigma_p V_n,p| and |f_ext|.
  subroutine residual(sc, dof, vn, r, scale)
    type(mpm_scene_t), intent(in) :: sc
    integer, intent(in) :: dof(sc%grid%glo:)
    real(dp), intent(in) :: vn(:)
    real(dp), intent(out) :: r(:), scale
    real(dp) :: mag(sc%grid%glo:sc%grid%ghi), f
    integer :: p, a, i
    associate (g => sc%grid, pt => sc%parts)
      r = 0.0_dp
      mag = abs(g%fext(1, :))
      do p = 1, pt%n
        do a = 1, sc%nnz(p)
          i = pt%node(a, p)
          f = pt%grad(1, a, p)*pt%stress(1, p)*vn(p)
          mag(i) = mag(i) + abs(f)
          if (dof(i) > 0) r(dof(i)) = r(dof(i)) - f
        end do
      end do
      do i = g%glo, g%ghi
        if (dof(i) > 0) r(dof(i)) = r(dof(i)) + g%fext(1, i)
      end do
      scale = maxval(mag)
    end associate
  end subroutine residual

  !> A = -dR/du = sum_p G_ia G_ib D_p V_n,p, D_p the UMAT's tangent.
  subroutine assemble(sc, solver, dof, dtan, vn)
    type(mpm_scene_t), intent(in) :: sc
    type(linear_solver_t), intent(inout) :: solver
    integer, intent(in) :: dof(sc%grid%glo:)
    real(dp), intent(in) :: dtan(:), vn(:)
    real(dp) :: k
    integer :: p, a, b, ia, ib
    call solver%zero()
    associate (pt => sc%parts)
      do p = 1, pt%n
        k = dtan(p)*vn(p)
        do a = 1, sc%nnz(p)
          ia = dof(pt%node(a, p))
          if (ia == 0) cycle
          do b = 1, sc%nnz(p)
            ib = dof(pt%node(b, p))
            if (ib == 0) cycle
            call solver%add(ia, ib, pt%grad(1, a, p)*pt%grad(1, b, p)*k)
          end do
        end do
      end do
    end associate
  end subroutine assemble

  !> du += delta on the free nodes.
  pure subroutine add_correction(dof, delta, du)
    integer, intent(in) :: dof(:)
    real(dp), intent(in) :: delta(:)
    real(dp), intent(inout) :: du(:)
    integer :: i
    do i = 1, size(dof)
      if (dof(i) > 0) du(i) = du(i) + delta(dof(i))
    end do
  end subroutine add_correction

end module wellposed_mpm_implicit_step
