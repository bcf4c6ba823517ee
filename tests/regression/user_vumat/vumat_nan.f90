!> A quiet NaN for vumat_hooke.f's misbehaving mode (0/0 would trap in a
!> Debug build, -ffpe-trap=invalid).
real(kind(1.0d0)) function qnan()
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  implicit none
  qnan = ieee_value(qnan, ieee_quiet_nan)
end function qnan
