!> Which `umat` a driver is linked with: this default answers "wellposed's"
!> (its named PROPS and STATEV slots hold); a build with a user's UMAT links
!> host/user/umat_origin_user.f90 instead, which answers "a user's"
!> (only the Abaqus contract holds). Kept alone in its file so that the
!> linker drops it when the user's answer is present.
logical function wellposed_umat_is_ours()
  implicit none
  wellposed_umat_is_ours = .true.
end function wellposed_umat_is_ours
