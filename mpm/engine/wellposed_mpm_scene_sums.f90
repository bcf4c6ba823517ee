!> Sums over a scene's particles that every kind reports: kinetic energy,
!> momentum, the plastic strain of each particle (fig. 4.2, 4.4) and the
!> plastic count of the last step; the sums over ranks go through the
!> scene's exchange (collective where said).
module wellposed_mpm_scene_sums
  use wellposed_kinds, only: dp
  use wellposed_mpm_scene, only: mpm_scene_t
  implicit none
  private
  public :: kinetic_energy, total_momentum, plastic_strain, plastic_count

contains

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
  !> This rank's share of the plastic particles of the last step: their sum
  !> over the ranks is the scene's count (Algorithm 1 counts them over
  !> every rank, and rank 0 reports them).
  integer function plastic_count(self) result(count_mine)
    type(mpm_scene_t), intent(in) :: self
    count_mine = self%nl%last%n_plastic
    if (self%exchange%rank() /= 0) count_mine = 0
  end function plastic_count

end module wellposed_mpm_scene_sums
