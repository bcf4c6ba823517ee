!> The choices of the MPM method every scene kind shares (section 4.3): the
!> 1D shape families, the update variant and the mass matrix of a bar's
!> grid acceleration. Their own module, so that shape/, grid/ and the
!> engine read them without importing a kind's configuration.
module wellposed_mpm_method
  implicit none
  private
  public :: shape_linear, shape_gimp, shape_names, scheme_usl, scheme_musl, scheme_implicit, &
            scheme_newmark, scheme_names, implicit_scheme, no_viscosity, &
            mass_lumped, mass_consistent, mass_blended, mass_names

  !> Shape function families (eq. 4.6-4.8): standard MPM (Dirac chi_p)
  !> and uGIMP (undeforming particle domain). CPDI comes with 2D.
  integer, parameter :: shape_linear = 1, shape_gimp = 2
  character(len=6), parameter :: shape_names(2) = [character(len=6) :: 'linear', 'gimp']
  !> Update variants: USL (eq. 4.10-4.13 as written: strain rate from the
  !> grid velocity after the update) and MUSL (the same, with the grid velocity
  !> rebuilt from the updated particle velocities before the strain rate),
  !> and the implicit steps (mpm/implicit/, Newton on the grid): quasi-static
  !> and the trapezoidal rule's dynamic one (Newmark beta = 1/4, gamma = 1/2).
  integer, parameter :: scheme_usl = 1, scheme_musl = 2, scheme_implicit = 3, &
                        scheme_newmark = 4
  character(len=8), parameter :: scheme_names(4) = [character(len=8) :: 'usl', 'musl', &
                                                    'implicit', 'newmark']
  !> Why an implicit scheme refuses bulk viscosity (the deck's check and the
  !> step's): its tangent has no rate term.
  character(len=*), parameter :: no_viscosity = 'the implicit schemes have no bulk '// &
    'viscosity (its rate term is not in the tangent): set &viscosity a1 = 0, a2 = 0'
  !> The mass matrix of a bar's grid acceleration (wellposed_mpm_mass_matrix):
  !> 'lumped' (eq. 4.9), 'consistent' (the particles' M_P: the rebuilt grid
  !> velocity follows the lumped-mass finite-element update) or 'blended'
  !> (it follows the average of the lumped and consistent masses).
  integer, parameter :: mass_lumped = 1, mass_consistent = 2, mass_blended = 3
  character(len=10), parameter :: mass_names(3) = [character(len=10) :: 'lumped', &
                                                   'consistent', 'blended']

contains

  !> True for the schemes that step by Newton on the grid (mpm/implicit/).
  elemental logical function implicit_scheme(id)
    integer, intent(in) :: id
    implicit_scheme = id == scheme_implicit .or. id == scheme_newmark
  end function implicit_scheme

end module wellposed_mpm_method
