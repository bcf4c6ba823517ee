!> Kinds used throughout wellposed. Every real is real(dp); hosts may rename
!> on import (`use wellposed_kinds, only: wk => dp`).
module wellposed_kinds
  use, intrinsic :: iso_fortran_env, only: real64, int32
  implicit none
  private
  public :: dp, ik

  !> Double precision: the UMAT contract passes every real as real64.
  integer, parameter :: dp = real64
  !> Default integer kind of the Abaqus interface.
  integer, parameter :: ik = int32
end module wellposed_kinds
