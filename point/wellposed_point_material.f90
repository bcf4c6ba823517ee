!> The single-element driver's view of a material: PROPS and an STATEV
!> length (docs/guide/umat.md), reached only through the UMAT host, so a user's
!> own UMAT is driven alike. The element is a unit cube (CELENT = 1, COORDS
!> = 0) strained homogeneously without rotation (DROT = I, F = I + eps);
!> KSTEP is the leg, KINC the increment, TIME(1) the leg's time, TIME(2) the
!> total. Abaqus order (11, 22, 33, 12, 13, 23), engineering shears, NTENS 6.
module wellposed_point_material
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_error, &
                                 host_tangent, verdict_ok, verdict_cutback
  implicit none
  private
  public :: material_t, point_state_t, umat_increment, ntens

  !> Number of stress and strain components handed to the UMAT.
  integer, parameter :: ntens = 6

  !> One material of a deck.
  type :: material_t
    character(len=:), allocatable :: label  !< name used in outputs
    real(dp), allocatable :: props(:)       !< PROPS(1:NPROPS), units of the deck
    integer :: nstatv = 12                  !< STATEV length
    real(dp) :: density = 0.0_dp            !< mass density for wave speeds (0: none)
  end type material_t

  !> The state of the element: what a host keeps between increments.
  type :: point_state_t
    real(dp) :: stress(ntens) = 0.0_dp   !< STRESS (Abaqus order)
    real(dp) :: strain(ntens) = 0.0_dp   !< total STRAN (engineering shears)
    real(dp), allocatable :: statev(:)   !< STATEV(1:NSTATV)
    real(dp) :: time = 0.0_dp            !< total time at the state
    real(dp) :: energy(3) = 0.0_dp       !< SSE, SPD, SCD of the UMAT
    integer :: kstep = 1                 !< leg (Abaqus step) of the state
    integer :: kinc = 0                  !< increments done in that leg
    real(dp) :: step_start = 0.0_dp      !< total time at which the leg began
  end type point_state_t

contains

  !> One UMAT call from `s0` with the strain increment `dstran` over
  !> `dtime`: returns the end state `s1`, DDSDDE and PNEWDT. `err` is
  !> allocated when the run must stop (the UMAT refused its input, or
  !> returned a non-finite STRESS or STATEV); otherwise PNEWDT < 1 asks for
  !> a smaller increment. `s0` is not changed (probes rely on it).
  subroutine umat_increment(mat, s0, dstran, dtime, s1, ddsdde, pnewdt, err, noel)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s0
    real(dp), intent(in) :: dstran(ntens), dtime
    type(point_state_t), intent(out) :: s1
    real(dp), intent(out) :: ddsdde(ntens, ntens), pnewdt
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: noel
    type(umat_host_t) :: h
    integer :: verdict
    call new_umat_host(h, ntens, mat%nstatv, err, cmname=mat%label, what='element')
    if (allocated(err)) return
    if (present(noel)) h%noel = noel
    h%kstep = s0%kstep
    h%kinc = s0%kinc + 1
    h%time = [s0%time - s0%step_start, s0%time]
    h%dtime = dtime
    s1 = s0
    call host_call(h, mat%props, s1%stress, s1%statev, s0%strain, dstran, verdict, s1%energy)
    ddsdde = host_tangent(h)
    pnewdt = h%pnewdt
    if (verdict /= verdict_ok .and. verdict /= verdict_cutback) then
      call host_error(h, verdict, err)
      pnewdt = -1.0_dp
      return
    end if
    s1%strain = s0%strain + dstran
    s1%time = s0%time + dtime
    s1%kinc = s0%kinc + 1
  end subroutine umat_increment

end module wellposed_point_material
