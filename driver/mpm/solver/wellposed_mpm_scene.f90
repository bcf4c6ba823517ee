!> The state of a running MPM scene, one type for the 1D bar (uniaxial
!> strain, chapter 2) and the 2D plate (plane strain, chapter 4): grid,
!> particles, time, the UMAT host, Algorithm 1's solver and the exchange
!> with other ranks; built by wellposed_mpm_bar and wellposed_mpm_plane_strain,
!> advanced by wellposed_mpm_solver. Also Algorithm 1's host side and the
!> sums over ranks a driver reports. NTENS 6 in 1D, 4 in 2D (engineering
!> shear); SI units, tension positive.
module wellposed_mpm_scene
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_config, only: mpm_config_t
  use wellposed_mpm_plate_config, only: ps_config_t, platen_contact
  use wellposed_mpm_grid, only: grid_t, new_grid
  use wellposed_mpm_particles, only: particles_t, new_particles
  use wellposed_mpm_exchange, only: mpm_exchange_t, mpm_serial_t
  use wellposed_mpm_materials, only: mpm_materials_t, material_of, check_covered
  use wellposed_umat_host, only: umat_host_t, new_umat_host, umat_is_ours
  use wellposed_step_kinematics, only: step_kinematics
  use wellposed_mpm_particle_umat, only: umat_particle
  use wellposed_mpm_vumat_call, only: vumat_work_t, vumat_material_t, vumat_particles
  use wellposed_mpm_nonlocal, only: nonlocal_t, nonlocal_host_t, nonlocal_settings_t, &
                                    new_nonlocal, nonlocal_ghost_nodes
  implicit none
  private
  public :: mpm_scene_t, start_scene, init_particles, size_workspace, setup_ranks, &
            kinetic_energy, total_momentum, applied_stress, platen_base, plastic_strain, &
            max_substeps, plastic_count, scene_particles, &
            assign_materials, timer_transfer, timer_grid, timer_umat, ntimers

  integer, parameter :: timer_transfer = 1, timer_grid = 2, timer_umat = 3, ntimers = 3

  !> One running scene. Its kind's configuration is `bar` (ndim = 1) or
  !> `plate` (ndim = 2); the numbers the step reads are copied beside.
  type, extends(nonlocal_host_t) :: mpm_scene_t
    integer :: ndim = 1
    integer :: ntens = 6                  !< NTENS of the UMAT calls
    type(mpm_config_t) :: bar             !< the bar's configuration (ndim = 1)
    type(ps_config_t) :: plate            !< the plate's configuration (ndim = 2)
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
    ! probed moduli (Pa): bar: axial unloading / loading; plate: M and K
    real(dp) :: modulus_elastic = 0.0_dp, modulus_plastic = 0.0_dp, modulus_dt = 0.0_dp
    real(dp) :: bulk = 0.0_dp, c_max = 0.0_dp
    ! bookkeeping of the bar (per unit cross-section: J/m^2, kg m/s / m^2)
    integer :: node_surface = 0, node_far = 0  !< global nodes at x = 0 and x = length
    real(dp) :: work_internal = 0.0_dp    !< int sigma : d eps dV (stored + dissipated)
    real(dp) :: work_external = 0.0_dp    !< work of the surface traction
    real(dp) :: impulse = 0.0_dp          !< time integral of surface force + reaction
    real(dp) :: kinetic0 = 0.0_dp, momentum0 = 0.0_dp
    ! bookkeeping of the plate
    real(dp) :: top_disp = 0.0_dp         !< vertical displacement of the top (m)
    integer :: platen_row = -huge(1)      !< the plate's lowest platen node row (none yet)
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

contains

  !> The numbers the step reads (cell size `dx`, shape family, USL/MUSL,
  !> density, viscosity A1 and A2) and the UMAT host of a scene in `ndim`
  !> dimensions (NTENS 6 in 1D, 4 in 2D) of materials with nstatv STATEV.
  subroutine start_scene(self, ndim, dx, shape, scheme, density, visc, nstatv, err)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: ndim, shape, scheme, nstatv
    real(dp), intent(in) :: dx, density, visc(2)
    type(error_t), allocatable, intent(out) :: err
    self%ndim = ndim
    self%ntens = merge(6, 4, ndim == 1)
    self%dx = dx
    self%shape = shape
    self%scheme = scheme
    self%density = density
    self%visc_a1 = visc(1)
    self%visc_a2 = visc(2)
    call new_umat_host(self%host, self%ntens, nstatv, err, what='particle')
    if (allocated(err)) return
    self%host%celent = dx
  end subroutine start_scene

  !> The particles 1 .. n of this rank at rest in their initial state: at
  !> x0, undeformed, half-widths lp (GIMP, CPDI; never changed), volume
  !> vol0, mass density * vol0, no strain, STATEV zero (the stress and
  !> velocity are the scene kind's).
  subroutine init_particles(self, n, lp, vol0)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: n
    real(dp), intent(in) :: lp, vol0
    integer :: k
    associate (pt => self%parts)
      pt%x(:, 1:n) = pt%x0(:, 1:n)
      pt%lp(:, 1:n) = lp
      pt%vol0(1:n) = vol0
      pt%vol(1:n) = pt%vol0(1:n)
      pt%mass(1:n) = self%density*pt%vol0(1:n)
      pt%defgrad(:, :, 1:n) = 0.0_dp
      do k = 1, 3
        pt%defgrad(k, k, 1:n) = 1.0_dp
      end do
      pt%stran(:, 1:n) = 0.0_dp
      pt%statev(:, 1:n) = 0.0_dp
    end associate
    ! every particle has this mass: one floor for every step and rank
    self%mass_floor = 1.0e-9_dp*(self%density*vol0)
  end subroutine init_particles

  !> The exchange of `self` (given or serial) over `nlayers` cell layers
  !> along the last axis, the grid of `nnodes` nodes cut to this rank's
  !> patch, and Algorithm 1 on that patch (collective). Ghost layers: the
  !> shape's `reach` or the nonlocal Gaussian's support, the wider.
  subroutine setup_ranks(self, settings, nnodes, reach, err, exchange)
    type(mpm_scene_t), intent(inout) :: self
    type(nonlocal_settings_t), intent(in) :: settings
    integer, intent(in) :: nnodes, reach
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    integer :: d, nnode(2), layer_nodes
    d = self%ndim
    ! node layers: one node in 1D, a row of nx nodes in 2D
    nnode = [self%nx, self%ny]
    layer_nodes = self%nx
    if (d == 1) then
      nnode(1) = nnodes
      layer_nodes = 1
    end if
    call new_nonlocal(self%nl, settings, d, self%origin(1:d), self%dx, nnode(1:d), 0, &
                      nnodes - 1, err)
    if (allocated(err)) then
      err%message = '&nonlocal / &material: '//err%message
      return
    end if
    if (present(exchange)) then
      allocate (self%exchange, source=exchange)
    else
      allocate (mpm_serial_t :: self%exchange)
    end if
    call self%exchange%setup(self%nlayers, layer_nodes, max(reach, nonlocal_ghost_nodes(self%nl)), &
                             d, self%origin(d), self%dx, err)
    if (allocated(err)) return
    call new_grid(self%grid, d, self%origin(1), self%dx, nnodes, 0, nnodes - 1)
    call self%exchange%restrict_grid(self%grid)
    if (self%grid%glo /= 0 .or. self%grid%ghi /= nnodes - 1) &
      call new_nonlocal(self%nl, settings, d, self%origin(1:d), self%dx, nnode(1:d), &
                        self%grid%glo, self%grid%ghi, err)
  end subroutine setup_ranks

  !> Room for `cap` particles of this rank (all `ntotal` on one rank),
  !> with nsup support nodes and nstatv state variables.
  subroutine scene_particles(self, cap, nsup, nstatv)
    type(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: cap, nsup, nstatv
    call new_particles(self%parts, cap, self%ndim, nsup, nstatv)
    call size_workspace(self)
    self%q = 0.0_dp
    self%mat = 0
  end subroutine scene_particles

  !> The material of every particle of this rank from its initial
  !> position; a particle no region holds is an error on every rank
  !> (collective).
  subroutine assign_materials(self, err)
    type(mpm_scene_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    integer :: p
    do p = 1, self%parts%n
      self%mat(p) = material_of(self%mats, self%parts%x0(:, p))
      if (self%mat(p) == 0) then
        call check_covered(self%mats, self%parts%x0(:, p:p), err)
        exit
      end if
    end do
    call self%exchange%sync_error(err)
  end subroutine assign_materials

  !> Per-particle arrays beside particles_t for as many particles as the
  !> set can hold (a rank's count changes as particles cross; a restart
  !> refills it); the material and viscous pressure in use are kept.
  subroutine size_workspace(self)
    type(mpm_scene_t), intent(inout) :: self
    integer :: cap, n, ns
    integer, allocatable :: mat(:)
    real(dp), allocatable :: q(:)
    cap = size(self%parts%gid)
    ns = self%parts%nstatv
    if (allocated(self%q)) then
      if (size(self%q) >= cap) return
      n = min(self%parts%n, size(self%q))
      mat = self%mat(1:n)
      q = self%q(1:n)
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
              self%block_dl(cap))
    if (allocated(self%f_n)) deallocate (self%f_n)
    if (.not. umat_is_ours()) allocate (self%f_n(self%ndim, self%ndim, cap))
    self%mat(1:n) = mat
    self%q(1:n) = q
  end subroutine size_workspace

  !> The host side of Algorithm 1: particle p from its start of step (the
  !> copies s0, sv0, e0 when Algorithm 1 iterates; else the particle's own
  !> state: a local model updates each particle once) with STATEV(3) = avg:
  !> through the VUMAT (a block of one) when its material is a VUMAT's, else
  !> (or when our VUMAT refuses it) through the UMAT host (driver/host: its
  !> cut-back splitting, PNEWDT and non-finite rules); dlambda = STATEV(2).
  subroutine scene_update(self, p, avg, dlambda, err)
    class(mpm_scene_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: avg
    real(dp), intent(out) :: dlambda
    type(error_t), allocatable, intent(out) :: err
    integer :: nsub, k, nt
    nt = self%ntens
    call restore_start(self, p)
    k = self%mat(p)
    if (self%mats%vumat(k)) then
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

  !> Kinetic energy of the particles on all ranks (J per m^2 of section in
  !> 1D, per m of thickness in 2D; collective).
  real(dp) function kinetic_energy(self)
    type(mpm_scene_t), intent(in) :: self
    integer :: n
    real(dp) :: e(1)
    n = self%parts%n
    if (self%ndim == 1) then
      e(1) = 0.5_dp*sum(self%parts%mass(1:n)*self%parts%v(1, 1:n)**2)
    else
      e(1) = 0.5_dp*sum(self%parts%mass(1:n)*(self%parts%v(1, 1:n)**2 + &
                                               self%parts%v(2, 1:n)**2))
    end if
    call self%exchange%sum_reals(e)
    kinetic_energy = e(1)
  end function kinetic_energy

  !> x-momentum of the particles on all ranks (collective).
  real(dp) function total_momentum(self)
    type(mpm_scene_t), intent(in) :: self
    integer :: n
    real(dp) :: m(1)
    n = self%parts%n
    m(1) = sum(self%parts%mass(1:n)*self%parts%v(1, 1:n))
    call self%exchange%sum_reals(m)
    total_momentum = m(1)
  end function total_momentum

  !> The plate's applied axial stress (Pa, compression positive): the top
  !> force per unit initial width, from the volume average of sigma_yy (in
  !> equilibrium without body force, int sigma_yy dV = F_top * H, H the
  !> current height) over the body under the platen's lowest node row y_g
  !> (the layer above it moves with the platen): -sum_p sigma_yy V_p /
  !> (width * min(y_g, height + top_disp)), particles with y_p < y_g.
  !> Robust to the boundary layer under a laterally fixed top and to the
  !> mesh. Collective.
  real(dp) function applied_stress(self) result(s)
    type(mpm_scene_t), intent(in) :: self
    integer :: n
    real(dp) :: a(1), yg
    n = self%parts%n
    yg = platen_base(self)
    a(1) = sum(self%parts%stress(2, 1:n)*self%parts%vol(1:n), mask=self%parts%x(2, 1:n) < yg)
    call self%exchange%sum_reals(a)
    s = -a(1)/(self%plate%width*min(yg, self%plate%height + self%top_disp))
  end function applied_stress

  !> The height y_g under which the plate's body is measured (applied_stress,
  !> the top cell row's stress ratio): the platen's lowest node row, or the
  !> platen's plane with platen = 'contact' (no node row; docs/research/bands.md).
  pure real(dp) function platen_base(self) result(yg)
    type(mpm_scene_t), intent(in) :: self
    if (self%plate%platen == platen_contact) then
      yg = self%plate%height + self%top_disp
    else
      yg = self%origin(2) + self%dx*self%platen_row
    end if
  end function platen_base

  !> Magnitude of the plastic strain tensor ||eps^p|| of each particle
  !> (STATEV 5-10, engineering shears halved), as in fig. 4.2 and 4.4;
  !> zero where NSTATV < 10 (a user's UMAT: its outputs are left out).
  pure function plastic_strain(self) result(ep)
    type(mpm_scene_t), intent(in) :: self
    real(dp) :: ep(self%parts%n)
    integer :: p
    ep = 0.0_dp
    if (self%parts%nstatv < 10) return
    do p = 1, self%parts%n
      associate (e => self%parts%statev(5:10, p))
        ep(p) = sqrt(e(1)**2 + e(2)**2 + e(3)**2 + 0.5_dp*(e(4)**2 + e(5)**2 + e(6)**2))
      end associate
    end do
  end function plastic_strain

  !> The largest UMAT cut-back split used so far on any rank (collective).
  integer function max_substeps(self) result(nsub)
    type(mpm_scene_t), intent(inout) :: self
    real(dp) :: x
    x = real(self%max_substeps, dp)
    call self%exchange%max_real(x)
    nsub = nint(x)
  end function max_substeps

  !> This rank's share of the plastic particles of the last step: their sum
  !> over the ranks is the scene's count (Algorithm 1 counts them over
  !> every rank, and rank 0 reports them).
  integer function plastic_count(self) result(count_mine)
    type(mpm_scene_t), intent(in) :: self
    count_mine = self%nl%last%n_plastic
    if (self%exchange%rank() /= 0) count_mine = 0
  end function plastic_count

end module wellposed_mpm_scene
