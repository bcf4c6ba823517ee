!> Which `vumat` a driver is linked with: this default answers "wellposed's"
!> (its named PROPS and STATEV slots hold); a build with a user's VUMAT links
!> host/user/vumat_origin_user.f90 instead, which answers "a user's"
!> (only the Abaqus contract holds). Alone in its file, as umat_origin.f90.
logical function wellposed_vumat_is_ours()
  implicit none
  wellposed_vumat_is_ours = .true.
end function wellposed_vumat_is_ours
