!> The stress update of one material point through the UMAT host, for
!> ndim = 1 and 2: the strain increment embedded in the UMAT's NTENS (6 for
!> the bar's uniaxial strain, 4 for plane strain, engineering shear) and
!> the call with the particle's identity, under the host's rules
!> (docs/guide/mpm.md, "Hosting a UMAT in the MPM"). Materials a deck gives
!> to the VUMAT go a block at a time through wellposed_mpm_vumat_call.
module wellposed_mpm_particle_umat
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_host, only: umat_host_t, host_update
  implicit none
  private
  public :: strain_increment, umat_particle

contains

  !> The plane-strain increment of a step dt from the velocity gradient lg
  !> (2 x 2, lg(a, b) = d v_a / d x_b; eq. 4.11) in the UMAT's order: 11,
  !> 22, 33 = 0, 12 engineering (NTENS = 4). A bar's uniaxial increment is
  !> bar_kinematics' (wellposed_mpm_bar_build).
  pure subroutine strain_increment(lg, dt, de)
    real(dp), intent(in) :: lg(2, 2), dt
    real(dp), intent(out) :: de(4)
    ! element by element: no array constructor (a temporary) per particle
    de(1) = dt*lg(1, 1)
    de(2) = dt*lg(2, 2)
    de(3) = dt*0.0_dp
    de(4) = dt*(lg(1, 2) + lg(2, 1))
  end subroutine strain_increment

  !> One particle through the UMAT: s, sv, e (STRESS, STATEV, STRAN, in
  !> place) over the increment de, in the step from time t of length dt
  !> (KINC = kinc), NOEL = gid, COORDS = x. Algorithm 1's slots only for a
  !> UMAT that has them (the host knows): STATEV(3) = avg in, dlambda =
  !> STATEV(2) out (else 0). nsub: the host's cut-back split.
  subroutine umat_particle(host, props, t, dt, kinc, gid, x, s, sv, e, de, avg, dlambda, &
                           nsub, err)
    type(umat_host_t), intent(inout) :: host
    ! contiguous, as the host's: the particle's columns pass without a copy
    real(dp), intent(in), contiguous :: props(:), x(:), de(:)
    real(dp), intent(in) :: t, dt, avg
    integer, intent(in) :: kinc, gid
    real(dp), intent(inout), contiguous :: s(:), sv(:), e(:)
    real(dp), intent(out) :: dlambda
    integer, intent(out) :: nsub
    type(error_t), allocatable, intent(out) :: err
    if (host%ours) sv(3) = avg
    host%time = t
    host%dtime = dt
    host%kinc = kinc
    host%noel = gid
    host%coords = 0.0_dp
    host%coords(1:size(x)) = x
    call host_update(host, props, s, sv, e, de, nsub, err)
    dlambda = 0.0_dp
    if (allocated(err)) return
    if (host%ours) dlambda = sv(2)
  end subroutine umat_particle

end module wellposed_mpm_particle_umat
