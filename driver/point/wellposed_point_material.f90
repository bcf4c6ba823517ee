!> The single-element driver's view of a material: a PROPS array, an
!> STATEV length and the external `umat` (Abaqus signature,
!> docs/umat.md). The driver reaches materials only through here, so a
!> user's own UMAT linked instead of ours is driven the same way.
!> Vectors are in Abaqus order (11, 22, 33, 12, 13, 23) with engineering
!> shear strains; NDI = 3, NSHR = 3, NTENS = 6; tension positive.
module wellposed_point_material
  use wellposed_kinds, only: dp
  use wellposed_umat_interface, only: umat
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
  end type point_state_t

contains

  !> One UMAT call from `s0` with the strain increment `dstran` over
  !> `dtime`: returns the end state `s1`, DDSDDE and PNEWDT (1 unless the
  !> UMAT asks for a cut-back). `s0` is not changed (probes rely on it).
  subroutine umat_increment(mat, s0, dstran, dtime, s1, ddsdde, pnewdt, noel)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s0
    real(dp), intent(in) :: dstran(ntens), dtime
    type(point_state_t), intent(out) :: s1
    real(dp), intent(out) :: ddsdde(ntens, ntens), pnewdt
    integer, intent(in), optional :: noel
    real(dp) :: sse, spd, scd, rpl, ddsddt(ntens), drplde(ntens), drpldt
    real(dp) :: time(2), predef(1), dpred(1), coords(3), drot(3, 3), f(3, 3)
    character(len=80) :: cmname
    integer :: el
    s1 = s0
    sse = 0.0_dp; spd = 0.0_dp; scd = 0.0_dp; rpl = 0.0_dp; drpldt = 0.0_dp
    ddsddt = 0.0_dp; drplde = 0.0_dp
    time = s0%time
    predef = 0.0_dp; dpred = 0.0_dp; coords = 0.0_dp
    drot = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [3, 3])
    f = drot
    ddsdde = 0.0_dp
    pnewdt = 1.0_dp
    cmname = mat%label
    el = 1
    if (present(noel)) el = noel
    call umat(s1%stress, s1%statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
              s0%strain, dstran, time, dtime, 0.0_dp, 0.0_dp, predef, dpred, cmname, &
              3, 3, ntens, mat%nstatv, mat%props, size(mat%props), coords, drot, pnewdt, &
              1.0_dp, f, f, el, 1, 1, 1, 1, 1)
    s1%strain = s0%strain + dstran
    s1%time = s0%time + dtime
  end subroutine umat_increment

end module wellposed_point_material
