!> Linked into a driver built with a user's VUMAT: only the Abaqus contract
!> holds (no wellposed PROPS or STATEV slots are assumed).
logical function wellposed_vumat_is_ours()
  implicit none
  wellposed_vumat_is_ours = .false.
end function wellposed_vumat_is_ours
