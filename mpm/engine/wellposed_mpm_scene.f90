!> The state of a running MPM scene in ndim dimensions, whatever its kind:
!> grid, particles, time, the UMAT host, Algorithm 1's solver, the exchange
!> with other ranks and the kind (scene_kind_t: the bar of chapter 2, the
!> plate of chapter 4, each in mpm/kinds/) with its loads, boundary
!> conditions, kinematics, bookkeeping and moduli probe; advanced by
!> wellposed_mpm_step. Also Algorithm 1's host side. SI units, tension +.
module wellposed_mpm_scene
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_out_of_memory, only: out_of_memory
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_particles, only: particles_t
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_materials, only: mpm_materials_t
  use wellposed_umat_host, only: umat_host_t, umat_is_ours
  use wellposed_step_kinematics, only: step_kinematics
  use wellposed_mpm_particle_umat, only: umat_particle
  use wellposed_mpm_vumat_call, only: vumat_work_t, vumat_material_t, vumat_particles, vumat_point
  use wellposed_mpm_nonlocal, only: nonlocal_t, nonlocal_host_t
  implicit none
  private
  public :: mpm_scene_t, scene_kind_t, probe_kind, size_workspace, max_substeps, timer_transfer, &
            timer_grid, timer_umat, ntimers, keep_start, restore_start

  integer, parameter :: timer_transfer = 1, timer_grid = 2, timer_umat = 3, ntimers = 3

  !> What a scene kind adds to the step (its dimension's own physics): the
  !> loads and boundary conditions on the grid, the kinematics (how lgrad
  !> becomes the UMAT's strain increment: NTENS and its layout), the per-step
  !> bookkeeping and the moduli probe. Each procedure gets the scene `sc`
  !> that holds the kind; it changes the kind only through `self`.
  type, abstract :: scene_kind_t
    integer :: ntens = 6                  !< NTENS of the kind's UMAT calls
  contains
    procedure(kind_probe), deferred :: probe
    procedure :: forces => kind_no_forces
    procedure(kind_conditions), deferred :: conditions
    procedure :: grid_solved => kind_grid_solved
    procedure(kind_kinematics), deferred :: kinematics
    procedure(kind_bookkeeping), deferred :: bookkeeping
    procedure :: partial_sums => kind_no_sums
    procedure :: set_partial_sums => kind_set_no_sums
    procedure :: scalars => kind_no_sums
    procedure :: set_scalars => kind_set_no_sums
    procedure :: radius => kind_no_radius
  end type scene_kind_t

  !> One running scene of `ndim` dimensions; its kind in `kind`, the
  !> numbers the step reads from the kind's configuration copied beside.
  type, extends(nonlocal_host_t) :: mpm_scene_t
    integer :: ndim = 1
    integer :: ntens = 6                  !< NTENS of the UMAT calls (the kind's)
    class(scene_kind_t), allocatable :: kind
    ! what the step reads, from the kind's configuration
    real(dp) :: dx = 0.0_dp               !< cell size (m)
    integer :: shape = 0, scheme = 0      !< shape family and USL/MUSL
    real(dp) :: density = 0.0_dp          !< kg/m^3
    real(dp) :: visc_a1 = 0.0_dp, visc_a2 = 0.0_dp  !< artificial viscosity (0: off)
    real(dp) :: c_visc = 0.0_dp           !< sound speed of the viscosity (m/s)
    ! grid: node g = i + nx*j at origin + dx*(i, j); strips along axis ndim
    integer :: nx = 1, ny = 1, nlayers = 0  !< nodes per row, rows (2D); cell layers along ndim
    real(dp) :: origin(2) = 0.0_dp
    type(grid_t) :: grid
    type(particles_t) :: parts
    integer :: ntotal = 0                 !< particles of the whole scene
    real(dp) :: t = 0.0_dp                !< time (s)
    real(dp) :: dt = 0.0_dp               !< time step (s)
    integer :: nstep = 0
    real(dp) :: mass_floor = 0.0_dp       !< grid nodes at or below it count as empty (kg)
    ! the kind's probe: the fastest wave's modulus and speed, the time step's
    real(dp) :: modulus_elastic = 0.0_dp, modulus_dt = 0.0_dp, c_max = 0.0_dp
    integer :: moved = 0                  !< particles this rank handed to others, so far
    integer :: max_substeps = 1           !< largest UMAT cut-back split used (this rank)
    integer :: max_substeps_step = 1      !< the same within the current step
    integer :: nl_log_unit = 6            !< where the nonlocal bound warnings go
    integer(int64) :: ticks(ntimers) = 0_int64
    !> the other ranks (a serial stand-in when the scene was built without)
    class(mpm_exchange_t), allocatable :: exchange
    type(mpm_materials_t) :: mats         !< the materials by region (initial position)
    ! per particle, beside particles_t (they travel with it: hand-off, checkpoint)
    integer, allocatable :: mat(:)        !< material of each particle
    real(dp), allocatable :: q(:)         !< artificial viscous pressure (Pa)
    !> the implicit dynamic (Newmark) step's accelerations (ndim, capacity;
    !> unallocated in any other run)
    real(dp), allocatable :: accel(:, :)
    ! workspace: start-of-step copies (s0, sv0, e0 when Algorithm 1
    ! iterates; the bar's s0(1, :) always), increments, volume at the start,
    ! velocity gradients (ndim x ndim each, eq. 4.11)
    real(dp), allocatable :: s0(:, :), sv0(:, :), e0(:, :), de(:, :), vol_n(:)
    real(dp), allocatable :: lgrad(:, :, :)
    !> F at the step's start (ndim x ndim), kept for a user's UMAT only:
    !> its DFGRD0 and DROT (wellposed's own reads neither)
    real(dp), allocatable :: f_n(:, :, :)
    ! the material calls (update, update_local, update_list): particles of
    ! one VUMAT material, their places in the update, averages, answers
    integer, allocatable :: block_idx(:), block_pos(:)
    real(dp), allocatable :: block_avg(:), block_dl(:)
    logical, allocatable :: block_done(:)
    logical, allocatable :: done(:)       !< answered by the VUMAT (by place in the update)
    integer, allocatable :: nnz(:)        !< support nodes in use of each particle, this step
    type(vumat_work_t) :: vw              !< the VUMAT's block arrays
    type(vumat_material_t), allocatable :: vmat(:)  !< what each material's VUMAT call is told
    type(nonlocal_t) :: nl                !< Algorithm 1 (the dissertation's chapter 4)
    type(umat_host_t) :: host             !< the UMAT host, one per scene
  contains
    procedure :: update => scene_update
    procedure :: update_local => scene_update_local
    procedure :: update_list => scene_update_list
  end type mpm_scene_t

  abstract interface
    !> The moduli of the scene's materials at their initial state, through
    !> the UMAT: modulus_elastic, modulus_dt, c_max, c_visc and dt.
    subroutine kind_probe(self, sc, err)
      import :: scene_kind_t, mpm_scene_t, error_t
      class(scene_kind_t), intent(inout) :: self
      class(mpm_scene_t), intent(inout) :: sc
      type(error_t), allocatable, intent(out) :: err
    end subroutine kind_probe
    !> After the ghost sum, before the grid update (eq. 4.9-4.10): the
    !> kind's loads on the summed grid and its boundary conditions;
    !> `given` (ndim, zero on entry) the velocity of the given components.
    subroutine kind_conditions(self, sc, given)
      import :: scene_kind_t, mpm_scene_t, dp
      class(scene_kind_t), intent(inout) :: self
      class(mpm_scene_t), intent(inout) :: sc
      real(dp), intent(inout) :: given(:)
    end subroutine kind_conditions
    !> The strain increment de (NTENS), F, volume (vol_n: the start's) and
    !> the UMAT's start of every particle from sc%lgrad (eq. 4.11). Returns
    !> the first particle turned inside out (det F <= 0), or n + 1.
    integer function kind_kinematics(self, sc) result(last)
      import :: scene_kind_t, mpm_scene_t
      class(scene_kind_t), intent(inout) :: self
      class(mpm_scene_t), intent(inout) :: sc
    end function kind_kinematics
    !> The kind's sums of the step, after the stress update and before the
    !> time advances.
    subroutine kind_bookkeeping(self, sc)
      import :: scene_kind_t, mpm_scene_t
      class(scene_kind_t), intent(inout) :: self
      class(mpm_scene_t), intent(inout) :: sc
    end subroutine kind_bookkeeping
  end interface

contains

  !> The kind's moduli probe (kind_probe) on the scene: the kind leaves the
  !> scene for the call, as in the step, so it is changed through one name.
  subroutine probe_kind(self, err)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    class(scene_kind_t), allocatable :: kind
    call move_alloc(self%kind, kind)
    call kind%probe(self, err)
    call move_alloc(kind, self%kind)
  end subroutine probe_kind

  !> Per-particle arrays beside particles_t for as many particles as the
  !> set can hold (a rank's count changes as particles cross; a restart
  !> refills it); the material and viscous pressure in use are kept.
  subroutine size_workspace(self)
    type(mpm_scene_t), intent(inout) :: self
    integer :: cap, n, ns, st
    integer, allocatable :: mat(:)
    real(dp), allocatable :: q(:), accel(:, :)
    cap = size(self%parts%gid)
    ns = self%parts%nstatv
    if (allocated(self%q)) then
      if (size(self%q) >= cap) return
      n = min(self%parts%n, size(self%q))
      mat = self%mat(1:n)
      q = self%q(1:n)
      if (allocated(self%accel)) then
        accel = self%accel(:, 1:n)
        deallocate (self%accel)
        allocate (self%accel(self%ndim, cap), source=0.0_dp)
        self%accel(:, 1:n) = accel
      end if
      deallocate (self%mat, self%q, self%s0, self%sv0, self%e0, self%de, self%vol_n, &
                  self%lgrad, self%block_idx, self%block_pos, self%block_done, self%done, &
                  self%nnz, self%block_avg, self%block_dl)
    else
      n = 0
      allocate (mat(0), q(0))
    end if
    allocate (self%mat(cap), self%q(cap), self%s0(self%ntens, cap), self%sv0(ns, cap), &
              self%e0(self%ntens, cap), self%de(self%ntens, cap), self%vol_n(cap), &
              self%lgrad(self%ndim, self%ndim, cap), self%block_idx(cap), self%block_pos(cap), &
              self%block_done(cap), self%done(cap), self%nnz(cap), self%block_avg(cap), &
              self%block_dl(cap), stat=st)
    if (st /= 0) call out_of_memory('particle workspace', int(cap, int64), st)
    if (allocated(self%f_n)) deallocate (self%f_n)
    if (.not. umat_is_ours()) allocate (self%f_n(self%ndim, self%ndim, cap))
    self%mat(1:n) = mat
    self%q(1:n) = q
  end subroutine size_workspace

  !> The host side of Algorithm 1: particle p from its start of step (the
  !> copies s0, sv0, e0 when Algorithm 1 iterates; else the particle's own
  !> state: a local model updates each particle once) with STATEV(3) = avg:
  !> through the VUMAT (a block of one; ours in a sweep: vumat_point) when
  !> its material is a VUMAT's, else
  !> (or when our VUMAT refuses it) through the UMAT host (host: its
  !> cut-back splitting, PNEWDT and non-finite rules); dlambda = STATEV(2).
  subroutine scene_update(self, p, avg, dlambda, err)
    class(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: avg
    real(dp), intent(out) :: dlambda
    type(error_t), allocatable, intent(out) :: err
    integer :: nsub, k, nt
    logical :: done
    nt = self%ntens
    call restore_start(self, p)
    k = self%mat(p)
    if (self%mats%vumat(k)) then
      ! a sweep's call (the start of step restored): the checked point path
      if (self%nl%active .and. allocated(self%vmat)) then
        call vumat_point(self%vmat(k), nt, self%dt, self%parts%stress(1:nt, p), &
                         self%parts%statev(:, p), self%parts%stran(1:nt, p), self%de(1:nt, p), &
                         avg, dlambda, done)
        if (done) return
        call restore_start(self, p)
      end if
      self%block_idx(1) = p
      self%block_avg(1) = avg
      call vumat_of(self, k, 1, .true., err)
      dlambda = self%block_dl(1)
      if (allocated(err) .or. self%block_done(1)) return
    end if
    associate (pt => self%parts)
      self%host%ours = self%mats%contract(k)
      self%host%kinematics_given = .true.
      if (allocated(self%f_n)) call step_kinematics(self%f_n(:, :, p), pt%defgrad(1:self%ndim, &
        1:self%ndim, p), self%host%dfgrd0, self%host%dfgrd1, self%host%drot)
      call umat_particle(self%host, self%mats%props(1:self%mats%nprops(k), k), self%t, &
                         self%dt, self%nstep + 1, pt%gid(p), pt%x(:, p), pt%stress(1:nt, p), &
                         pt%statev(:, p), pt%stran(1:nt, p), self%de(:, p), avg, dlambda, &
                         nsub, err)
      if (allocated(err)) return
      if (nsub > self%max_substeps_step) self%max_substeps_step = nsub
    end associate
  end subroutine scene_update

  !> Step 1 of Algorithm 1 (every particle with <dlambda> = 0): the
  !> particles of each VUMAT material a block at a time (update_blocks);
  !> every other particle, and any our VUMAT refuses, through scene_update
  !> one by one, in order, up to the first error.
  subroutine scene_update_local(self, dl, err)
    class(mpm_scene_t), intent(inout) :: self
    real(dp), intent(out) :: dl(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: n, p
    n = size(dl)
    call update_blocks(self, n, dl, err)
    if (allocated(err)) return
    do p = 1, n
      if (self%done(p)) cycle
      call self%update(p, 0.0_dp, dl(p), err)
      if (allocated(err)) return
    end do
  end subroutine scene_update_local

  !> Particles list(q) with <dlambda> = avg(q), each from its start of step
  !> (Algorithm 1's simultaneous sweeps and their step 3: the calls do not
  !> depend on each other), the same way as scene_update_local: bitwise the
  !> answers of scene_update one by one.
  subroutine scene_update_list(self, list, avg, dl, err)
    class(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: list(:)
    real(dp), intent(in) :: avg(:)
    real(dp), intent(out) :: dl(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: q
    ! the VUMAT updates in place: its particles back at their start here
    ! (scene_update restores the others)
    do q = 1, size(list)
      if (self%mats%vumat(self%mat(list(q)))) call restore_start(self, list(q))
    end do
    call update_blocks(self, size(list), dl, err, list, avg)
    if (allocated(err)) return
    do q = 1, size(list)
      if (self%done(q)) cycle
      call self%update(list(q), avg(q), dl(q), err)
      if (allocated(err)) return
    end do
  end subroutine scene_update_list

  !> The start of particle p's stress update: Algorithm 1's sweeps restart
  !> from copies; a local model updates in place.
  subroutine keep_start(self, p)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    integer :: nt
    if (.not. self%nl%active) return
    nt = self%ntens
    self%s0(:, p) = self%parts%stress(1:nt, p)
    self%sv0(:, p) = self%parts%statev(:, p)
    self%e0(:, p) = self%parts%stran(1:nt, p)
  end subroutine keep_start

  !> Particle p back at its start of step when Algorithm 1 iterates (the
  !> copies s0, sv0, e0); a local model updates each particle once, in place.
  subroutine restore_start(self, p)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    integer :: nt
    if (.not. self%nl%active) return
    nt = self%ntens
    self%parts%stress(1:nt, p) = self%s0(:, p)
    self%parts%statev(:, p) = self%sv0(:, p)
    self%parts%stran(1:nt, p) = self%e0(:, p)
  end subroutine restore_start

  !> The particles list(1:n) (1 .. n without a list) of each VUMAT material
  !> through the VUMAT, a block at a time, with <dlambda> avg(q) (0 if
  !> absent): done(q) is set for those it answered, dl(q) is their dlambda.
  subroutine update_blocks(self, n, dl, err, list, avg)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: n
    real(dp), intent(inout) :: dl(:)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: list(:)
    real(dp), intent(in), optional :: avg(:)
    integer :: k, m, q, p, j
    self%done(1:n) = .false.
    do k = 1, self%mats%n
      if (.not. self%mats%vumat(k)) cycle
      m = 0
      do q = 1, n
        p = q
        if (present(list)) p = list(q)
        if (self%mat(p) /= k) cycle
        m = m + 1
        self%block_idx(m) = p
        self%block_pos(m) = q
        if (present(avg)) self%block_avg(m) = avg(q)
      end do
      if (m == 0) cycle
      call vumat_of(self, k, m, present(avg), err)
      if (allocated(err)) return
      do j = 1, m
        if (.not. self%block_done(j)) cycle
        self%done(self%block_pos(j)) = .true.
        dl(self%block_pos(j)) = self%block_dl(j)
      end do
    end do
  end subroutine update_blocks

  !> Particles block_idx(1:m) of material k through the VUMAT, with the
  !> averages block_avg(1:m) when with_avg (else 0): block_done, block_dl.
  subroutine vumat_of(self, k, m, with_avg, err)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: k, m
    logical, intent(in) :: with_avg
    type(error_t), allocatable, intent(out) :: err
    integer :: j
    if (.not. allocated(self%vmat)) then
      allocate (self%vmat(self%mats%n))
      do j = 1, self%mats%n
        self%vmat(j) = vumat_material_t(self%mats%props(1:self%mats%nprops(j), j), &
                                        self%mats%ours(j), self%mats%contract(j), &
                                        self%host%cmname, self%density, self%dx)
      end do
    end if
    associate (pt => self%parts, w => self%vw, mat => self%vmat(k), nt => self%ntens)
      if (with_avg) then
        call vumat_particles(w, mat, nt, self%t, self%dt, self%block_idx(1:m), pt%gid, &
                             self%de, pt%stress, pt%statev, pt%stran, self%block_dl, &
                             self%block_done, err, self%block_avg(1:m))
      else
        call vumat_particles(w, mat, nt, self%t, self%dt, self%block_idx(1:m), pt%gid, &
                             self%de, pt%stress, pt%statev, pt%stran, self%block_dl, &
                             self%block_done, err)
      end if
    end associate
  end subroutine vumat_of

  !> The largest UMAT cut-back split used so far on any rank (collective).
  integer function max_substeps(self) result(nsub)
    type(mpm_scene_t), intent(inout) :: self
    real(dp) :: x
    x = real(self%max_substeps, dp)
    call self%exchange%max_real(x)
    nsub = nint(x)
  end function max_substeps

  !> A kind that puts no force on the grid before the ghost sum.
  subroutine kind_no_forces(self, sc)
    class(scene_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
  end subroutine kind_no_forces

  !> Particle p's radius about the kind's axis of revolution at its position
  !> x (0: the kind has none; the implicit step's hoop terms then vanish).
  pure real(dp) function kind_no_radius(self, x) result(r)
    class(scene_kind_t), intent(in) :: self
    real(dp), intent(in) :: x(:)
    r = 0.0_dp
  end function kind_no_radius

  !> After the grid update, before G2P: a kind's change to the grid's
  !> answer (none by default); `reaction` (ndim) the fixed nodes' force.
  subroutine kind_grid_solved(self, sc, reaction, err)
    class(scene_kind_t), intent(inout) :: self
    class(mpm_scene_t), intent(inout) :: sc
    real(dp), intent(in) :: reaction(:)
    type(error_t), allocatable, intent(out) :: err
  end subroutine kind_grid_solved

  !> The kind's bookkeeping a checkpoint keeps: `partial_sums`, this rank's
  !> shares of sums over the ranks; `scalars`, values alike on every rank
  !> (none by default).
  function kind_no_sums(self) result(v)
    class(scene_kind_t), intent(in) :: self
    real(dp), allocatable :: v(:)
    allocate (v(0))
  end function kind_no_sums

  !> The kind's bookkeeping back from a checkpoint (as kind_no_sums).
  subroutine kind_set_no_sums(self, v)
    class(scene_kind_t), intent(inout) :: self
    real(dp), intent(in) :: v(:)
  end subroutine kind_set_no_sums

end module wellposed_mpm_scene
