!> The plate scene kind's build in 2D plane strain (chapter 4, fig. 4.1):
!> a body [0, width] x [0, height] on a uniform grid, GIMP, CPDI or linear
!> weights, nodes past a boundary sharing its condition, the particles of
!> this rank's strip of cell rows, the materials and the time step (the
!> kind's probe). The kind itself (boundaries, platen, kinematics,
!> measures): wellposed_mpm_plate_kind. Deck keys: docs/guide/decks.md.
module wellposed_mpm_plate_build
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_materials, only: single_material
  use wellposed_mpm_exchange, only: mpm_exchange_t
  use wellposed_mpm_shape_2d, only: support_size_2d, shape2d_reach
  use wellposed_mpm_plate_config, only: plate_config_t, check_plate_config, bc_roller, &
                                        bc_plate_fixed, bc_plate_free, bc_velocity, &
                                        plate_bc_names, platen_names
  use wellposed_mpm_scene, only: mpm_scene_t, scene_kind_t, probe_kind
  use wellposed_mpm_scene_build, only: start_scene, setup_ranks, scene_particles, &
                                       assign_materials, init_particles
  use wellposed_mpm_plate_kind, only: plate_kind_t, platen_nodes, platen_velocity, &
                                      apparent_strain
  implicit none
  private
  public :: plate_config_t, new_plate_scene, platen_velocity, apparent_strain, bc_roller, &
            bc_plate_fixed, bc_plate_free, bc_velocity, plate_bc_names, platen_names

contains

  !> Build grid, particles, materials and the time step; errors name keys.
  !> With `exchange` (collective then) this rank keeps its strip of cell
  !> rows, the nodes they touch with their ghost rows, and the particles in
  !> them (global ids as in the serial scene).
  subroutine new_plate_scene(self, cfg, err, exchange)
    type(mpm_scene_t), intent(out) :: self
    type(plate_config_t), intent(in) :: cfg
    type(error_t), allocatable, intent(out) :: err
    class(mpm_exchange_t), intent(in), optional :: exchange
    integer :: ncx, ncy, np, p, a, b, g, nlocal, cap, rank
    real(dp) :: lp, xy(2)
    type(plate_kind_t) :: plate
    class(scene_kind_t), allocatable :: kind

    call check_plate_config(cfg, err)
    if (allocated(err)) return
    plate%cfg = cfg
    plate%ntens = 4   ! plane strain: 11, 22, 33, 12
    call start_scene(self, plate, 2, cfg%dx, cfg%shape, cfg%scheme, cfg%density, &
                     [cfg%visc_a1, cfg%visc_a2], cfg%nstatv, err)
    if (allocated(err)) return
    ncx = nint(cfg%width/cfg%dx)
    ncy = nint(cfg%height/cfg%dx)
    self%nx = ncx + 2*cfg%pad_cells + 1
    self%ny = ncy + 2*cfg%pad_cells + 1
    self%nlayers = self%ny - 1
    self%origin = -cfg%pad_cells*cfg%dx
    call setup_ranks(self, cfg%nonlocal, self%nx*self%ny, &
                     shape2d_reach(cfg%shape), err, exchange)
    if (allocated(err)) return
    ! the kind out of the scene for the call (no alias of it through self)
    call move_alloc(self%kind, kind)
    select type (kind)
    type is (plate_kind_t)
      call platen_nodes(kind, self)
    end select
    call move_alloc(kind, self%kind)

    np = ncx*ncy*cfg%ppc**2
    self%ntotal = np
    lp = 0.5_dp*cfg%dx/cfg%ppc
    ! this rank's particles: those whose cell row it owns (all on one rank)
    rank = self%exchange%rank()
    nlocal = 0
    do b = 1, ncy*cfg%ppc
      if (self%exchange%owner((b - 0.5_dp)*2.0_dp*lp) == rank) nlocal = nlocal + ncx*cfg%ppc
    end do
    cap = np
    if (self%exchange%nranks() > 1) cap = min(np, nlocal + nlocal/4 + 64)
    call scene_particles(self, cap, support_size_2d(cfg%shape), cfg%nstatv)
    self%mats = single_material(cfg%materials, cfg%props(1:cfg%nprops), cfg%nstatv, 2, &
                                self%host%ours)
    p = 0
    g = 0
    do b = 1, ncy*cfg%ppc
      do a = 1, ncx*cfg%ppc
        g = g + 1
        xy = [(a - 0.5_dp)*2.0_dp*lp, (b - 0.5_dp)*2.0_dp*lp]
        if (self%exchange%owner(xy(2)) /= rank) cycle
        p = p + 1
        self%parts%gid(p) = g
        self%parts%x0(:, p) = xy
      end do
    end do
    self%parts%n = nlocal
    call assign_materials(self, err)
    if (allocated(err)) return
    call init_particles(self, nlocal, lp, (2.0_dp*lp)**2)
    do p = 1, nlocal
      self%parts%v(:, p) = matmul(cfg%velocity_gradient0, self%parts%x0(:, p))
    end do
    self%parts%stress(:, 1:nlocal) = 0.0_dp

    ! the stiffest material's moduli (the time step)
    call probe_kind(self, err)

  end subroutine new_plate_scene

end module wellposed_mpm_plate_build
