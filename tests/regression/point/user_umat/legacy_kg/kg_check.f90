! The third file of the legacy test UMAT (umat_kg.f), free form with
! default REAL: right only when built with -fdefault-real-8 (the user-UMAT
! flags), since the UMAT passes REAL*8 moduli.
subroutine kgchk(bulk, shear, ok)
  implicit none
  real, intent(in) :: bulk, shear
  logical, intent(out) :: ok
  ok = bulk > 0.0 .and. shear > 0.0 .and. precision(bulk) >= 15
end subroutine kgchk
