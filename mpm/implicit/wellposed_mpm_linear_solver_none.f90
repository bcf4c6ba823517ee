!> wellposed_mpm_linear_solver for a build without PETSc: the same public
!> interface as wellposed_mpm_linear_solver.F90, so the implicit scheme and
!> its tests compile; setup refuses with the message that says how to get
!> PETSc, and the other procedures do nothing.
module wellposed_mpm_linear_solver
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  implicit none
  private
  public :: linear_solver_t, linear_solver_finalize, linear_solver_available
  public :: solver_direct, solver_gmres, solver_names

  !> LU factorisation through MUMPS (with PETSc).
  integer, parameter :: solver_direct = 1
  !> GMRES(50) with ILU(0) (with PETSc).
  integer, parameter :: solver_gmres = 2
  !> The methods' names, for messages and decks.
  character(len=*), parameter :: solver_names(2) = [character(len=6) :: 'direct', 'gmres']
  !> .false.: this build has no PETSc, every setup fails.
  logical, parameter :: linear_solver_available = .false.

  !> Why setup fails in this build.
  character(len=*), parameter :: no_petsc = 'the implicit scheme needs PETSc, and this '// &
    'build has none: install Debian''s petsc-dev and reconfigure (bash scripts/test.sh '// &
    'does both)'

  !> A solver that is never set up.
  type :: linear_solver_t
    private
    integer :: n = 0
  contains
    procedure :: setup, zero, add, add_block, solve, destroy
  end type linear_solver_t

contains

  !> Always fails: this build has no PETSc (see no_petsc).
  subroutine setup(self, n, max_row_nonzeros, method, err, rtol, comm, rows)
    class(linear_solver_t), intent(inout) :: self
    integer, intent(in) :: n, max_row_nonzeros, method
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: rtol
    integer, intent(in), optional :: comm, rows(2)
    self%n = 0
    call new_error(err, status_invalid, 'petsc', no_petsc)
  end subroutine setup

  !> Nothing to zero without a matrix.
  subroutine zero(self)
    class(linear_solver_t), intent(inout) :: self
    self%n = 0
  end subroutine zero

  !> Nothing to add to without a matrix.
  subroutine add(self, i, j, v)
    class(linear_solver_t), intent(inout) :: self
    integer, intent(in) :: i, j
    real(dp), intent(in) :: v
    self%n = 0
  end subroutine add

  !> Nothing to add to without a matrix.
  subroutine add_block(self, idx, block)
    class(linear_solver_t), intent(inout) :: self
    integer, intent(in) :: idx(:)
    real(dp), intent(in) :: block(:, :)
    self%n = 0
  end subroutine add_block

  !> Fails as setup does; x is zero.
  subroutine solve(self, b, x, err, iterations)
    class(linear_solver_t), intent(inout) :: self
    real(dp), intent(in) :: b(:)
    real(dp), intent(out) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: iterations
    x = 0.0_dp
    if (present(iterations)) iterations = 0
    self%n = 0
    call new_error(err, status_invalid, 'petsc', no_petsc)
  end subroutine solve

  !> Nothing to free.
  subroutine destroy(self)
    class(linear_solver_t), intent(inout) :: self
    self%n = 0
  end subroutine destroy

  !> Nothing to finalise.
  subroutine linear_solver_finalize()
  end subroutine linear_solver_finalize

end module wellposed_mpm_linear_solver
