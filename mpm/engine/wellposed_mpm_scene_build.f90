!> What a scene kind's build calls, in this order: start_scene (the kind,
!> the numbers the step reads, the UMAT host), setup_ranks (the exchange,
!> the grid patch and Algorithm 1 on it), scene_particles (room),
!> assign_materials and init_particles (the particles at rest).
module wellposed_mpm_scene_build
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_grid, only: new_grid
  use wellposed_mpm_particles, only: new_particles
  use wellposed_mpm_exchange, only: mpm_exchange_t, mpm_serial_t
  use wellposed_mpm_materials, only: material_of, check_covered
  use wellposed_umat_host, only: new_umat_host
  use wellposed_mpm_nonlocal, only: nonlocal_settings_t, new_nonlocal, nonlocal_ghost_nodes
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t, size_workspace
  implicit none
  private
  public :: start_scene, setup_ranks, scene_particles, assign_materials, init_particles

contains

  !> A scene of `kind` (its NTENS) in `ndim` dimensions: the numbers the
  !> step reads (cell size `dx`, shape family, USL/MUSL, density, viscosity
  !> A1 and A2) and the UMAT host of materials with nstatv STATEV.
  subroutine start_scene(self, kind, ndim, dx, shape, scheme, density, visc, nstatv, err)
    type(mpm_scene_t), intent(inout) :: self
    class(scene_kind_t), intent(in) :: kind
    integer, intent(in) :: ndim, shape, scheme, nstatv
    real(dp), intent(in) :: dx, density, visc(2)
    type(error_t), allocatable, intent(out) :: err
    allocate (self%kind, source=kind)
    self%ndim = ndim
    self%ntens = kind%ntens
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

end module wellposed_mpm_scene_build
