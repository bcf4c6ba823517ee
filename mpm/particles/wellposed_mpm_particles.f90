!> Material points of the MPM (section 4.3): mass, volume, position,
!> velocity, deformation gradient, stress and the UMAT's STATEV, as a
!> structure of arrays with the particle index last. `gid` survives a
!> hand-off between ranks; `n` may be below the capacity, so particles
!> arrive and leave without reallocating. The connectivity (node, phi,
!> grad) is rebuilt each step from x; a particle travels as one record of
!> reals holding every other field.
module wellposed_mpm_particles
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  implicit none
  private
  public :: particles_t, new_particles, particle_bytes, copy_particle, particle_record_length, &
            pack_particle, unpack_particle, ensure_capacity, first_outside

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
  subroutine new_particles(self, capacity, ndim, nsup, nstatv)
    type(particles_t), intent(out) :: self
    integer, intent(in) :: capacity, ndim, nsup, nstatv
    integer :: st
    self%n = 0
    self%ndim = ndim
    self%nsup = nsup
    self%nstatv = nstatv
    allocate (self%gid(capacity), self%x0(ndim, capacity), self%x(ndim, capacity), &
              self%v(ndim, capacity), self%lp(ndim, capacity), self%mass(capacity), &
              self%vol0(capacity), self%vol(capacity), self%defgrad(3, 3, capacity), &
              self%stress(6, capacity), self%stran(6, capacity), &
              self%statev(nstatv, capacity), self%node(nsup, capacity), &
              self%phi(nsup, capacity), self%grad(ndim, nsup, capacity), stat=st)
    if (st /= 0) call out_of_memory('particle storage', int(capacity, int64), st)
  end subroutine new_particles

  !> Bytes of storage per particle for this layout.
  pure integer function particle_bytes(ndim, nsup, nstatv)
    integer, intent(in) :: ndim, nsup, nstatv
    particle_bytes = 4 + 8*(4*ndim + 3 + 9 + 6 + 6 + nstatv) + nsup*(4 + 8 + 8*ndim)
  end function particle_bytes

  !> Move particle q's data to slot m (connectivity included).
  pure subroutine copy_particle(parts, q, m)
    type(particles_t), intent(inout) :: parts
    integer, intent(in) :: q, m
    parts%gid(m) = parts%gid(q)
    parts%x0(:, m) = parts%x0(:, q)
    parts%x(:, m) = parts%x(:, q)
    parts%v(:, m) = parts%v(:, q)
    parts%lp(:, m) = parts%lp(:, q)
    parts%mass(m) = parts%mass(q)
    parts%vol0(m) = parts%vol0(q)
    parts%vol(m) = parts%vol(q)
    parts%defgrad(:, :, m) = parts%defgrad(:, :, q)
    parts%stress(:, m) = parts%stress(:, q)
    parts%stran(:, m) = parts%stran(:, q)
    parts%statev(:, m) = parts%statev(:, q)
    parts%node(:, m) = parts%node(:, q)
    parts%phi(:, m) = parts%phi(:, q)
    parts%grad(:, :, m) = parts%grad(:, :, q)
  end subroutine copy_particle

  !> Reals per particle in a hand-off record.
  pure integer function particle_record_length(parts) result(n)
    type(particles_t), intent(in) :: parts
    n = 1 + 4*parts%ndim + 3 + 9 + 6 + 6 + parts%nstatv
  end function particle_record_length

  !> Particle p as one record of reals (the global id is exact as a real
  !> below 2**53). The connectivity is not sent: it is rebuilt from x.
  pure subroutine pack_particle(parts, p, rec)
    type(particles_t), intent(in) :: parts
    integer, intent(in) :: p
    real(dp), intent(out) :: rec(:)
    integer :: k, d
    d = parts%ndim
    rec(1) = real(parts%gid(p), dp)
    k = 1
    rec(k + 1:k + d) = parts%x0(:, p); k = k + d
    rec(k + 1:k + d) = parts%x(:, p); k = k + d
    rec(k + 1:k + d) = parts%v(:, p); k = k + d
    rec(k + 1:k + d) = parts%lp(:, p); k = k + d
    rec(k + 1) = parts%mass(p)
    rec(k + 2) = parts%vol0(p)
    rec(k + 3) = parts%vol(p); k = k + 3
    rec(k + 1:k + 9) = reshape(parts%defgrad(:, :, p), [9]); k = k + 9
    rec(k + 1:k + 6) = parts%stress(:, p); k = k + 6
    rec(k + 1:k + 6) = parts%stran(:, p); k = k + 6
    rec(k + 1:k + parts%nstatv) = parts%statev(:, p)
  end subroutine pack_particle

  !> The inverse of pack_particle into slot p (connectivity zeroed).
  pure subroutine unpack_particle(parts, p, rec)
    type(particles_t), intent(inout) :: parts
    integer, intent(in) :: p
    real(dp), intent(in) :: rec(:)
    integer :: k, d
    d = parts%ndim
    parts%gid(p) = nint(rec(1))
    k = 1
    parts%x0(:, p) = rec(k + 1:k + d); k = k + d
    parts%x(:, p) = rec(k + 1:k + d); k = k + d
    parts%v(:, p) = rec(k + 1:k + d); k = k + d
    parts%lp(:, p) = rec(k + 1:k + d); k = k + d
    parts%mass(p) = rec(k + 1)
    parts%vol0(p) = rec(k + 2)
    parts%vol(p) = rec(k + 3); k = k + 3
    parts%defgrad(:, :, p) = reshape(rec(k + 1:k + 9), [3, 3]); k = k + 9
    parts%stress(:, p) = rec(k + 1:k + 6); k = k + 6
    parts%stran(:, p) = rec(k + 1:k + 6); k = k + 6
    parts%statev(:, p) = rec(k + 1:k + parts%nstatv)
    parts%node(:, p) = 0
    parts%phi(:, p) = 0.0_dp
    parts%grad(:, :, p) = 0.0_dp
  end subroutine unpack_particle

  !> Room for at least `needed` particles, keeping the first n (grows by
  !> half again at least, so repeated arrivals reallocate rarely). A set
  !> never allocated is allocated with its ndim, nsup and nstatv.
  subroutine ensure_capacity(parts, needed)
    type(particles_t), intent(inout) :: parts
    integer, intent(in) :: needed
    integer :: cap, n, ndim, nsup, nstatv
    if (.not. allocated(parts%gid)) then
      ndim = parts%ndim                  ! copies: new_particles resets parts on entry
      nsup = parts%nsup
      nstatv = parts%nstatv
      call new_particles(parts, max(needed, 1), ndim, nsup, nstatv)
      return
    end if
    if (size(parts%gid) >= needed) return
    cap = max(needed, size(parts%gid) + size(parts%gid)/2 + 16)
    n = parts%n
    call grow_i1(parts%gid)
    call grow_r2(parts%x0)
    call grow_r2(parts%x)
    call grow_r2(parts%v)
    call grow_r2(parts%lp)
    call grow_r1(parts%mass)
    call grow_r1(parts%vol0)
    call grow_r1(parts%vol)
    call grow_r3(parts%defgrad)
    call grow_r2(parts%stress)
    call grow_r2(parts%stran)
    call grow_r2(parts%statev)
    call grow_i2(parts%node)
    call grow_r2(parts%phi)
    call grow_r3(parts%grad)
  contains
    subroutine grow_i1(a)
      integer, allocatable, intent(inout) :: a(:)
      integer, allocatable :: b(:)
      integer :: st
      allocate (b(cap), stat=st)
      if (st /= 0) call out_of_memory('particle storage', int(cap, int64), st)
      b(1:n) = a(1:n)
      call move_alloc(b, a)
    end subroutine grow_i1
    subroutine grow_i2(a)
      integer, allocatable, intent(inout) :: a(:, :)
      integer, allocatable :: b(:, :)
      integer :: st
      allocate (b(size(a, 1), cap), stat=st)
      if (st /= 0) call out_of_memory('particle storage', int(cap, int64), st)
      b(:, 1:n) = a(:, 1:n)
      call move_alloc(b, a)
    end subroutine grow_i2
    subroutine grow_r1(a)
      real(dp), allocatable, intent(inout) :: a(:)
      real(dp), allocatable :: b(:)
      integer :: st
      allocate (b(cap), stat=st)
      if (st /= 0) call out_of_memory('particle storage', int(cap, int64), st)
      b(1:n) = a(1:n)
      call move_alloc(b, a)
    end subroutine grow_r1
    subroutine grow_r2(a)
      real(dp), allocatable, intent(inout) :: a(:, :)
      real(dp), allocatable :: b(:, :)
      integer :: st
      allocate (b(size(a, 1), cap), stat=st)
      if (st /= 0) call out_of_memory('particle storage', int(cap, int64), st)
      b(:, 1:n) = a(:, 1:n)
      call move_alloc(b, a)
    end subroutine grow_r2
    subroutine grow_r3(a)
      real(dp), allocatable, intent(inout) :: a(:, :, :)
      real(dp), allocatable :: b(:, :, :)
      integer :: st
      allocate (b(size(a, 1), size(a, 2), cap), stat=st)
      if (st /= 0) call out_of_memory('particle storage', int(cap, int64), st)
      b(:, :, 1:n) = a(:, :, 1:n)
      call move_alloc(b, a)
    end subroutine grow_r3
  end subroutine ensure_capacity

  !> The first of particles 1 .. n whose support nodes (node(:, p)) leave
  !> [lo, hi], 0 when none does: the support check of every step, one pass
  !> over the nodes (their extremes) and a second only to name the particle.
  pure integer function first_outside(node, n, lo, hi) result(p_out)
    integer, intent(in), contiguous :: node(:, :)
    integer, intent(in) :: n, lo, hi
    integer :: p, nmin, nmax
    call extremes(node, size(node, 1)*n, nmin, nmax)
    p_out = 0
    if (nmin >= lo .and. nmax <= hi) return
    do p = 1, n
      if (any(node(:, p) < lo) .or. any(node(:, p) > hi)) then
        p_out = p
        return
      end if
    end do
  end function first_outside

  !> The smallest and largest of flat(1:m) (the node columns as one run, so
  !> the loop vectorises).
  pure subroutine extremes(flat, m, nmin, nmax)
    integer, intent(in) :: m
    integer, intent(in) :: flat(m)
    integer, intent(out) :: nmin, nmax
    integer :: k
    nmin = huge(1)
    nmax = -huge(1)
    do k = 1, m
      nmin = min(nmin, flat(k))
      nmax = max(nmax, flat(k))
    end do
  end subroutine extremes

end module wellposed_mpm_particles
