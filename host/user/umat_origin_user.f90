!> Linked into a driver built with a user's UMAT: only the Abaqus contract
!> holds (no wellposed PROPS or STATEV slots are assumed).
logical function wellposed_umat_is_ours()
  implicit none
  wellposed_umat_is_ours = .false.
end function wellposed_umat_is_ours
