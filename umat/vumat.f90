!> The Abaqus/Explicit VUMAT entry point (docs/guide/umat.md, "The VUMAT"): an
!> external subroutine with the documented argument list, callable without
!> any module, forwarding to wellposed_vumat_adapter. Abaqus/Explicit
!> cannot cut an increment back, so any error is fatal: one line on
!> standard error names the point, the entry, its value and the valid
!> range, then error stop. Hosts wanting errors as values call vumat_update.
subroutine vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, stepTime, totalTime, &
                 dt, cmname, coordMp, charLength, props, density, strainInc, relSpinInc, &
                 tempOld, stretchOld, defgradOld, fieldOld, stressOld, stateOld, &
                 enerInternOld, enerInelasOld, tempNew, stretchNew, defgradNew, fieldNew, &
                 stressNew, stateNew, enerInternNew, enerInelasNew)
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_vumat_adapter, only: vumat_update
  use wellposed_text, only: int_text
  implicit none
  integer, intent(in) :: nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal
  real(dp), intent(in) :: stepTime, totalTime, dt
  character(len=80), intent(in) :: cmname
  real(dp), intent(in) :: coordMp(nblock, *), charLength(nblock), props(nprops), density(nblock)
  real(dp), intent(in) :: strainInc(nblock, ndir + nshr), relSpinInc(nblock, nshr)
  real(dp), intent(in) :: tempOld(nblock), stretchOld(nblock, ndir + nshr)
  real(dp), intent(in) :: defgradOld(nblock, ndir + nshr + nshr), fieldOld(nblock, nfieldv)
  real(dp), intent(in) :: stressOld(nblock, ndir + nshr), stateOld(nblock, nstatev)
  real(dp), intent(in) :: enerInternOld(nblock), enerInelasOld(nblock), tempNew(nblock)
  real(dp), intent(in) :: stretchNew(nblock, ndir + nshr)
  real(dp), intent(in) :: defgradNew(nblock, ndir + nshr + nshr), fieldNew(nblock, nfieldv)
  real(dp), intent(inout) :: stressNew(nblock, ndir + nshr), stateNew(nblock, nstatev)
  real(dp), intent(inout) :: enerInternNew(nblock), enerInelasNew(nblock)
  type(error_t), allocatable :: err
  integer :: point

  call vumat_update(nblock, ndir, nshr, nstatev, nprops, stepTime, totalTime, dt, props, &
                    density, strainInc, stressOld, stateOld, enerInternOld, enerInelasOld, &
                    stressNew, stateNew, enerInternNew, enerInelasNew, err, point)
  if (allocated(err)) then
    if (point > 0) then
      write (error_unit, '(a)') 'wellposed VUMAT error (material '//trim(cmname)//', point '// &
        int_text(point)//' of the block): '//err%message
    else
      write (error_unit, '(a)') 'wellposed VUMAT error (material '//trim(cmname)//'): '// &
        err%message
    end if
    error stop 1
  end if

end subroutine vumat
