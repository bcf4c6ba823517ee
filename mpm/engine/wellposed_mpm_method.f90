!> The choices of the MPM method every scene kind shares (section 4.3): the
!> 1D shape families, the update variant and the mass matrix of a bar's
!> grid acceleration. Their own module, so that shape/, grid/ and the
!> engine read them without importing a kind's configuration.
module wellposed_mpm_method
  implicit none
  private
  public :: shape_linear, shape_gimp, shape_names, scheme_usl, scheme_musl, scheme_implicit, &
            scheme_names, &
            mass_lumped, mass_consistent, mass_blended, mass_names

  !> Shape function families (eq. 4.6-4.8): standard MPM (Dirac chi_p)
  !> and uGIMP (undeforming particle domain). CPDI comes with 2D.
  integer, parameter :: shape_linear = 1, shape_gimp = 2
  character(len=6), parameter :: shape_names(2) = [character(len=6) :: 'linear', 'gimp']
  !> Update variants: USL (eq. 4.10-4.13 as written: strain rate from the
  !> grid velocity after the update) and MUSL (the same, with the grid velocity
  !> rebuilt from the updated particle velocities before the strain rate),
  !> and the implicit quasi-static step (mpm/implicit/, Newton on the grid).
  integer, parameter :: scheme_usl = 1, scheme_musl = 2, scheme_implicit = 3
  character(len=8), parameter :: scheme_names(3) = [character(len=8) :: 'usl', 'musl', &
                                                    'implicit']
  !> The mass matrix of a bar's grid acceleration (wellposed_mpm_mass_matrix):
  !> 'lumped' (eq. 4.9), 'consistent' (the particles' M_P: the rebuilt grid
  !> velocity follows the lumped-mass finite-element update) or 'blended'
  !> (it follows the average of the lumped and consistent masses).
  integer, parameter :: mass_lumped = 1, mass_consistent = 2, mass_blended = 3
  character(len=10), parameter :: mass_names(3) = [character(len=10) :: 'lumped', &
                                                   'consistent', 'blended']

end module wellposed_mpm_method
