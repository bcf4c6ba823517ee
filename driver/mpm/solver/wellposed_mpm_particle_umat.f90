!> The stress update of one material point through the UMAT host, written
!> once for ndim = 1 and 2: the step's strain increment in the UMAT's NTENS
!> (the dimension's kernel: uniaxial strain into 6 components, plane strain
!> into 4, engineering shear) and the call with the particle's identity
!> (docs/mpm.md, "Hosting a UMAT in the MPM"). The host's rules apply:
!> PNEWDT < 0 or a non-finite result is an error naming the particle, a
!> cut-back splits the increment.
module wellposed_mpm_particle_umat
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_host, only: umat_host_t, host_update
  implicit none
  private
  public :: strain_increment, umat_particle

contains

  !> The strain increment of a step dt from the velocity gradient lg
  !> (ndim x ndim, lg(a, b) = d v_a / d x_b; eq. 4.11) in the UMAT's order:
  !> ndim 1, uniaxial strain (11, 0, 0, 0, 0, 0); ndim 2, plane strain
  !> (11, 22, 33 = 0, 12 engineering). de: NTENS = 6 (ndim 1) or 4.
  pure subroutine strain_increment(lg, dt, de)
    real(dp), intent(in) :: lg(:, :), dt
    real(dp), intent(out) :: de(:)
    if (size(lg, 1) == 1) then
      de = [lg(1, 1)*dt, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    else
      de = dt*[lg(1, 1), lg(2, 2), 0.0_dp, lg(1, 2) + lg(2, 1)]
    end if
  end subroutine strain_increment

  !> One particle through the UMAT: s, sv, e (STRESS, STATEV, STRAN, in
  !> place) over the increment de, in the step from time t of length dt
  !> (KINC = kinc), NOEL = gid, COORDS = x. Algorithm 1's slots only for a
  !> UMAT that has them (the host knows): STATEV(3) = avg in, dlambda =
  !> STATEV(2) out (else 0). nsub: the host's cut-back split.
  subroutine umat_particle(host, props, t, dt, kinc, gid, x, s, sv, e, de, avg, dlambda, &
                           nsub, err)
    type(umat_host_t), intent(inout) :: host
    real(dp), intent(in) :: props(:), t, dt, x(:), de(:), avg
    integer, intent(in) :: kinc, gid
    real(dp), intent(inout) :: s(:), sv(:), e(:)
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
