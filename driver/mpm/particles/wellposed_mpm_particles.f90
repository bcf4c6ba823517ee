!> Material points of the MPM (section 4.3): each carries mass,
!> volume, position, velocity, deformation gradient, stress and the UMAT's
!> STATEV. Structure of arrays with the particle index last, so the core
!> loops stream through memory; `gid` is a global identity that survives a
!> hand-off between ranks, and `n` may be below the allocated
!> capacity so particles can arrive and leave without reallocating.
!> The connectivity (node, phi, grad) is recomputed each step from x.
module wellposed_mpm_particles
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: particles_t, new_particles, particle_bytes

  type :: particles_t
    integer :: n = 0                 !< particles in use
    integer :: ndim = 1
    integer :: nsup = 2              !< nodes per particle (shape support)
    integer :: nstatv = 12
    integer, allocatable :: gid(:)           !< global particle number (1-based)
    real(dp), allocatable :: x0(:, :)        !< reference position (m)
    real(dp), allocatable :: x(:, :)         !< current position (m)
    real(dp), allocatable :: v(:, :)         !< velocity (m/s)
    real(dp), allocatable :: lp(:, :)        !< GIMP half-width of the domain (m)
    real(dp), allocatable :: mass(:)         !< kg (per m^2 of section in 1D)
    real(dp), allocatable :: vol0(:)         !< reference volume (m^3 per m^2)
    real(dp), allocatable :: vol(:)          !< current volume = det F * vol0
    real(dp), allocatable :: defgrad(:, :, :) !< F (3, 3, p)
    real(dp), allocatable :: stress(:, :)    !< Cauchy stress (6, p), Abaqus order, Pa
    real(dp), allocatable :: stran(:, :)     !< total strain (6, p), engineering shears
    real(dp), allocatable :: statev(:, :)    !< UMAT state (nstatv, p)
    integer, allocatable :: node(:, :)       !< support nodes (nsup, p), global numbers
    real(dp), allocatable :: phi(:, :)       !< weights phi_ip (nsup, p), eq. 4.6
    real(dp), allocatable :: grad(:, :, :)   !< gradient weights G_ip (ndim, nsup, p), eq. 4.7
  end type particles_t

contains

  !> Room for `capacity` particles, none in use yet.
  pure subroutine new_particles(self, capacity, ndim, nsup, nstatv)
    type(particles_t), intent(out) :: self
    integer, intent(in) :: capacity, ndim, nsup, nstatv
    self%n = 0
    self%ndim = ndim
    self%nsup = nsup
    self%nstatv = nstatv
    allocate (self%gid(capacity), self%x0(ndim, capacity), self%x(ndim, capacity), &
              self%v(ndim, capacity), self%lp(ndim, capacity), self%mass(capacity), &
              self%vol0(capacity), self%vol(capacity), self%defgrad(3, 3, capacity), &
              self%stress(6, capacity), self%stran(6, capacity), &
              self%statev(nstatv, capacity), self%node(nsup, capacity), &
              self%phi(nsup, capacity), self%grad(ndim, nsup, capacity))
  end subroutine new_particles

  !> Bytes of storage per particle for this layout.
  pure integer function particle_bytes(ndim, nsup, nstatv)
    integer, intent(in) :: ndim, nsup, nstatv
    particle_bytes = 4 + 8*(4*ndim + 3 + 9 + 6 + 6 + nstatv) + nsup*(4 + 8 + 8*ndim)
  end function particle_bytes

end module wellposed_mpm_particles
