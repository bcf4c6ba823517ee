!> Explicit interface of the external `vumat` (the Abaqus/Explicit
!> signature), for Fortran hosts that want argument checking:
!> `use wellposed_vumat_interface`. Fixed-form hosts call `vumat` without it.
module wellposed_vumat_interface
  implicit none
  private
  public :: vumat

  interface
    subroutine vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, stepTime, &
                     totalTime, dt, cmname, coordMp, charLength, props, density, strainInc, &
                     relSpinInc, tempOld, stretchOld, defgradOld, fieldOld, stressOld, &
                     stateOld, enerInternOld, enerInelasOld, tempNew, stretchNew, defgradNew, &
                     fieldNew, stressNew, stateNew, enerInternNew, enerInelasNew)
      use wellposed_kinds, only: dp
      implicit none
      integer, intent(in) :: nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal
      real(dp), intent(in) :: stepTime, totalTime, dt
      character(len=80), intent(in) :: cmname
      real(dp), intent(in) :: coordMp(nblock, *), charLength(nblock), props(nprops)
      real(dp), intent(in) :: density(nblock)
      real(dp), intent(in) :: strainInc(nblock, ndir + nshr), relSpinInc(nblock, nshr)
      real(dp), intent(in) :: tempOld(nblock), stretchOld(nblock, ndir + nshr)
      real(dp), intent(in) :: defgradOld(nblock, ndir + nshr + nshr), fieldOld(nblock, nfieldv)
      real(dp), intent(in) :: stressOld(nblock, ndir + nshr), stateOld(nblock, nstatev)
      real(dp), intent(in) :: enerInternOld(nblock), enerInelasOld(nblock), tempNew(nblock)
      real(dp), intent(in) :: stretchNew(nblock, ndir + nshr)
      real(dp), intent(in) :: defgradNew(nblock, ndir + nshr + nshr), fieldNew(nblock, nfieldv)
      real(dp), intent(inout) :: stressNew(nblock, ndir + nshr), stateNew(nblock, nstatev)
      real(dp), intent(inout) :: enerInternNew(nblock), enerInelasNew(nblock)
    end subroutine vumat
  end interface

end module wellposed_vumat_interface
