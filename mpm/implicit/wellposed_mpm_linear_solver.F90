!> The linear systems of the MPM's implicit scheme, K x = b with K sparse,
!> n x n and possibly nonsymmetric (a nonassociative model's tangent), over
!> PETSc: an AIJ matrix filled entry by entry (1-based, global indices), on
!> PETSC_COMM_SELF, or over the ranks of an MPI communicator, each holding a
!> block of rows; then LU through MUMPS, or GMRES(50) with ILU(0) (block
!> Jacobi over ranks). PETSc starts once per process without the program's
!> command line; a build without PETSc compiles ..._none.f90 instead.
module wellposed_mpm_linear_solver
#include <petsc/finclude/petscksp.h>
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_ptr, c_null_ptr, c_null_char
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_all, &
    ieee_get_halting_mode, ieee_set_halting_mode, ieee_get_flag, ieee_set_flag
  use petscksp
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text
  implicit none
  private
  public :: linear_solver_t, linear_solver_finalize, linear_solver_available
  public :: solver_direct, solver_gmres, solver_names

  !> LU factorisation through MUMPS (PCLU, MATSOLVERMUMPS), one application.
  integer, parameter :: solver_direct = 1
  !> GMRES restarted every 50 iterations, preconditioned by ILU(0).
  integer, parameter :: solver_gmres = 2
  !> The methods' names, for messages and decks.
  character(len=*), parameter :: solver_names(2) = [character(len=6) :: 'direct', 'gmres']
  !> .true.: this build has PETSc (this file); .false. in the _none build.
  logical, parameter :: linear_solver_available = .true.

  !> The options prefix of our KSPs and factors in PETSc's database.
  character(len=*), parameter :: prefix = 'wellposed_'

  !> Whether this module started PETSc (and so linear_solver_finalize may
  !> end it): process-wide by nature, as PETSc's own state is.
  logical :: petsc_started_here = .false.

  !> One system: its matrix, right-hand side and solution vectors and the
  !> KSP; distributed, this rank's rows first .. last and the scatter of x
  !> to every rank (`whole`). `stage` says how far setup got (0: nothing to
  !> free), `fault` the first failed `add`, reported by the next solve.
  type :: linear_solver_t
    private
    integer :: n = 0, method = 0, stage = 0, first = 1, last = 0
    logical :: dirty = .false., distributed = .false.
    character(len=:), allocatable :: fault
    Mat :: a
    Vec :: b, x, whole
    VecScatter :: to_all
    KSP :: ksp
  contains
    procedure :: setup, zero, add, add_block, solve, destroy
  end type linear_solver_t

  interface
    !> PETSc's C start without argc/argv: the driver keeps its command line.
    function petsc_initialize_no_arguments() result(ierr) &
        bind(C, name='PetscInitializeNoArguments')
      import :: c_int
      integer(c_int) :: ierr
    end function petsc_initialize_no_arguments
    !> Hands the C start's communicators and constants to PETSc's Fortran side.
    function petsc_initialize_fortran() result(ierr) bind(C, name='PetscInitializeFortran')
      import :: c_int
      integer(c_int) :: ierr
    end function petsc_initialize_fortran
    !> An option into PETSc's database (allowed before PetscInitialize).
    function petsc_options_set_value(options, name, value) result(ierr) &
        bind(C, name='PetscOptionsSetValue')
      import :: c_int, c_char, c_ptr
      type(c_ptr), value :: options
      character(kind=c_char), intent(in) :: name(*)
      type(c_ptr), value :: value
      integer(c_int) :: ierr
    end function petsc_options_set_value
  end interface

contains

  !> Create the n x n matrix (max_row_nonzeros entries a row preallocated),
  !> its vectors and the KSP of `method` (solver_direct, solver_gmres; rtol
  !> the relative residual reduction of GMRES, default 1e-10). With `comm`
  !> (an MPI communicator's Fortran handle) and `rows` (this rank's rows
  !> [first, last], 1-based; the ranks' blocks in rank order cover 1 .. n)
  !> the system is shared over the ranks of comm, and setup, zero and solve
  !> are collective; add and add_block take any row. Starts PETSc on first
  !> use: collective over MPI_COMM_WORLD when the driver runs MPI on several
  !> ranks (PetscInitialize is), so all of them set up first then. A solver
  !> already set up is destroyed first, so the caller may set up again
  !> whenever n or the sparsity changes.
  subroutine setup(self, n, max_row_nonzeros, method, err, rtol, comm, rows)
    class(linear_solver_t), intent(inout) :: self
    integer, intent(in) :: n, max_row_nonzeros, method
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: rtol
    integer, intent(in), optional :: comm, rows(2)
    real(dp) :: tol
    PetscErrorCode :: ierr
    PetscBool :: given
    PetscInt :: lo, hi
    MPI_Comm :: pcomm
    PC :: pc
    integer :: nloc, m
    call self%destroy()
    tol = 1.0e-10_dp
    if (present(rtol)) tol = rtol
    if (method /= solver_direct .and. method /= solver_gmres) then
      call new_error(err, status_invalid, 'method', 'linear solver: method '// &
                     int_text(method)//' is none of 1 (direct) and 2 (gmres)'); return
    else if (n < 1) then
      call new_error(err, status_invalid, 'n', 'linear solver: a system of n = '// &
                     int_text(n)//' unknowns (need n >= 1)'); return
    else if (max_row_nonzeros < 1) then
      call new_error(err, status_invalid, 'max_row_nonzeros', 'linear solver: '// &
                     int_text(max_row_nonzeros)//' entries a row (need >= 1)'); return
    else if (.not. (tol > 0.0_dp .and. tol < 1.0_dp)) then
      call new_error(err, status_invalid, 'rtol', 'linear solver: rtol must lie in (0, 1)')
      return
    else if (present(comm) .neqv. present(rows)) then
      call new_error(err, status_invalid, 'rows', 'linear solver: a shared system needs '// &
                     'both the communicator and this rank''s rows'); return
    end if
    self%first = 1
    self%last = n
    self%distributed = present(comm)
    pcomm = PETSC_COMM_SELF
    if (self%distributed) then
      if (rows(1) < 1 .or. rows(2) > n .or. rows(2) < rows(1) - 1) then
        call new_error(err, status_invalid, 'rows', 'linear solver: rows '// &
          int_text(rows(1))//' .. '//int_text(rows(2))//' of a system of '//int_text(n)// &
          ' (need 1 <= first <= last + 1 <= n + 1)'); return
      end if
      self%first = rows(1)
      self%last = rows(2)
      pcomm = comm
    end if
    call start_petsc(err)
    if (allocated(err)) return
    self%n = n
    self%method = method
    nloc = self%last - self%first + 1
    m = min(max_row_nonzeros, n)
    if (self%distributed) then
      ! preallocation: the diagonal block holds at most nloc columns
      call MatCreateAIJ(pcomm, to_petsc(nloc), to_petsc(nloc), to_petsc(n), to_petsc(n), &
                        to_petsc(min(m, nloc)), PETSC_NULL_INTEGER, to_petsc(min(m, n - nloc)), &
                        PETSC_NULL_INTEGER, self%a, ierr)
    else
      call MatCreateSeqAIJ(pcomm, to_petsc(n), to_petsc(n), to_petsc(m), PETSC_NULL_INTEGER, &
                           self%a, ierr)
    end if
    if (failed(ierr, 'MatCreateAIJ', self, err)) return
    self%stage = 1
    call MatGetOwnershipRange(self%a, lo, hi, ierr)
    if (failed(ierr, 'MatGetOwnershipRange', self, err)) return
    if (lo /= self%first - 1 .or. hi /= self%last) then
      call new_error(err, status_invalid, 'rows', 'linear solver: PETSc gave this rank rows '// &
        int_text(int(lo) + 1)//' .. '//int_text(int(hi))//', not '//int_text(self%first)// &
        ' .. '//int_text(self%last)//' (the ranks'' rows must follow in rank order)'); return
    end if
    ! Particles crossing cells change the pattern between assemblies: an
    ! entry new to it is stored (PETSc would otherwise refuse it).
    call MatSetOption(self%a, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE, ierr)
    if (failed(ierr, 'MatSetOption', self, err)) return
    call MatCreateVecs(self%a, self%x, self%b, ierr)
    if (failed(ierr, 'MatCreateVecs', self, err)) return
    self%stage = 3
    call KSPCreate(pcomm, self%ksp, ierr)
    if (failed(ierr, 'KSPCreate', self, err)) return
    self%stage = 4
    if (self%distributed) then
      ! every rank takes the whole solution (its patch's unknowns among them)
      call VecScatterCreateToAll(self%x, self%to_all, self%whole, ierr)
      if (failed(ierr, 'VecScatterCreateToAll', self, err)) return
      self%stage = 5
    end if
    call KSPGetPC(self%ksp, pc, ierr)
    if (failed(ierr, 'KSPGetPC', self, err)) return
    if (method == solver_direct) then
      call KSPSetType(self%ksp, KSPPREONLY, ierr)
      if (failed(ierr, 'KSPSetType', self, err)) return
      call PCSetType(pc, PCLU, ierr)
      if (failed(ierr, 'PCSetType', self, err)) return
      call PCFactorSetMatSolverType(pc, MATSOLVERMUMPS, ierr)
      if (failed(ierr, 'PCFactorSetMatSolverType', self, err)) return
      ! MUMPS's null pivot detection (ICNTL(24) = 1): a matrix singular only
      ! in rounding (a free rigid-body mode) would else give an answer of
      ! 1e16; the count of null pivots (INFOG(28)) is checked after solve.
      ! Through the options, since PETSc recreates the factor when the
      ! pattern changes; PETSC_OPTIONS may set it otherwise.
      call PetscOptionsHasName(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, &
                               '-'//prefix//'mat_mumps_icntl_24', given, ierr)
      if (failed(ierr, 'PetscOptionsHasName', self, err)) return
      if (.not. given) call PetscOptionsSetValue(PETSC_NULL_OPTIONS, &
                                                 '-'//prefix//'mat_mumps_icntl_24', '1', ierr)
      if (failed(ierr, 'PetscOptionsSetValue', self, err)) return
    else
      call KSPSetType(self%ksp, KSPGMRES, ierr)
      if (failed(ierr, 'KSPSetType', self, err)) return
      call KSPGMRESSetRestart(self%ksp, to_petsc(50), ierr)
      if (failed(ierr, 'KSPGMRESSetRestart', self, err)) return
      if (self%distributed) then
        ! ILU(0) of each rank's diagonal block (PETSc's ILU is sequential)
        call PCSetType(pc, PCBJACOBI, ierr)
        if (failed(ierr, 'PCSetType', self, err)) return
      else
        call PCSetType(pc, PCILU, ierr)
        if (failed(ierr, 'PCSetType', self, err)) return
        call PCFactorSetLevels(pc, to_petsc(0), ierr)
        if (failed(ierr, 'PCFactorSetLevels', self, err)) return
      end if
      call KSPSetTolerances(self%ksp, tol, PETSC_DEFAULT_REAL, PETSC_DEFAULT_REAL, &
                            PETSC_DEFAULT_INTEGER, ierr)
      if (failed(ierr, 'KSPSetTolerances', self, err)) return
    end if
    ! PETSC_OPTIONS='-wellposed_ksp_monitor ...' reaches this KSP, and only it
    call KSPSetOptionsPrefix(self%ksp, prefix, ierr)
    if (failed(ierr, 'KSPSetOptionsPrefix', self, err)) return
    call KSPSetFromOptions(self%ksp, ierr)
    if (failed(ierr, 'KSPSetFromOptions', self, err)) return
  end subroutine setup

  !> Set every stored entry to zero and keep the pattern (the next step's
  !> matrix reuses the storage). Entries added since the last solve are
  !> assembled first, as PETSc requires.
  subroutine zero(self)
    class(linear_solver_t), intent(inout) :: self
    PetscErrorCode :: ierr
    if (self%stage < 1) return
    if (self%dirty) then
      call assemble(self, ierr)
      if (ierr /= 0) call note_fault(self, 'MatAssemblyBegin/End', ierr)
    end if
    call MatZeroEntries(self%a, ierr)
    if (ierr /= 0) call note_fault(self, 'MatZeroEntries', ierr)
  end subroutine zero

  !> K(i, j) += v (1-based). A bad index or a PETSc failure is kept and
  !> returned by the next solve, so assembly loops need no error argument.
  subroutine add(self, i, j, v)
    class(linear_solver_t), intent(inout) :: self
    integer, intent(in) :: i, j
    real(dp), intent(in) :: v
    PetscInt :: row(1), col(1)
    PetscScalar :: val(1)
    PetscErrorCode :: ierr
    if (self%stage < 1) then
      call note(self, 'add before setup'); return
    else if (i < 1 .or. i > self%n .or. j < 1 .or. j > self%n) then
      call note(self, 'entry ('//int_text(i)//', '//int_text(j)//') outside the '// &
                int_text(self%n)//' x '//int_text(self%n)//' matrix'); return
    end if
    row(1) = to_petsc(i - 1)
    col(1) = to_petsc(j - 1)
    val(1) = v
    call MatSetValues(self%a, to_petsc(1), row, to_petsc(1), col, val, ADD_VALUES, ierr)
    if (ierr /= 0) then
      call note_fault(self, 'MatSetValues', ierr); return
    end if
    self%dirty = .true.
  end subroutine add

  !> K(idx(a), idx(b)) += block(a, b) for every idx > 0 (0: a row and
  !> column left out, as a fixed node's), in one call: an element's block.
  subroutine add_block(self, idx, block)
    class(linear_solver_t), intent(inout) :: self
    integer, intent(in) :: idx(:)
    real(dp), intent(in) :: block(:, :)
    PetscInt :: rows(size(idx))
    PetscErrorCode :: ierr
    integer :: a
    if (self%stage < 1) then
      call note(self, 'add before setup'); return
    end if
    do a = 1, size(idx)
      if (idx(a) > self%n .or. idx(a) < 0) then
        call note(self, 'index '//int_text(idx(a))//' outside the '//int_text(self%n)// &
                  ' x '//int_text(self%n)//' matrix'); return
      end if
      ! PETSc skips negative indices: 0 becomes -1
      rows(a) = to_petsc(idx(a) - 1)
    end do
    ! PETSc reads the values row by row: the transpose's columns
    call MatSetValues(self%a, to_petsc(size(idx)), rows, to_petsc(size(idx)), rows, &
                      transpose(block), ADD_VALUES, ierr)
    if (ierr /= 0) then
      call note_fault(self, 'MatSetValues', ierr); return
    end if
    self%dirty = .true.
  end subroutine add_block

  !> Assemble K and solve K x = b with the method of setup; the operator is
  !> handed to the KSP on every call since its entries change between calls
  !> (the factorisation or ILU is redone). `iterations`: the KSP's (1 for
  !> direct). A divergence (KSPGetConvergedReason < 0: a singular matrix,
  !> GMRES out of iterations, ...) is status_cutback, a PETSc error or a
  !> misuse status_invalid, each naming method and reason; x is NaN then.
  subroutine solve(self, b, x, err, iterations)
    class(linear_solver_t), intent(inout) :: self
    real(dp), intent(in) :: b(:)
    real(dp), intent(out) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: iterations
    PetscScalar, pointer :: p(:)
    PetscErrorCode :: ierr
    KSPConvergedReason :: reason
    PetscInt :: its
    integer :: nnull
    logical :: halting(size(ieee_all)), flags(size(ieee_all))
    x = ieee_value(x, ieee_quiet_nan)
    if (present(iterations)) iterations = 0
    if (self%stage < 4) then
      call new_error(err, status_invalid, 'setup', 'linear solver: solve before setup')
      return
    else if (allocated(self%fault)) then
      call new_error(err, status_invalid, 'add', 'linear solver ('//name(self)// &
                     '): '//self%fault); return
    else if (size(b) /= self%n .or. size(x) /= self%n) then
      call new_error(err, status_invalid, 'b', 'linear solver: b and x of '// &
                     int_text(size(b))//' and '//int_text(size(x))//' entries for '// &
                     int_text(self%n)//' unknowns'); return
    end if
    if (self%method == solver_gmres) then
      call diagonal_entries(self, ierr)
      if (failed(ierr, 'MatSetValues', self, err)) return
    end if
    call assemble(self, ierr)
    if (failed(ierr, 'MatAssemblyBegin/End', self, err)) return
    call VecGetArrayF90(self%b, p, ierr)
    if (failed(ierr, 'VecGetArrayF90', self, err)) return
    p = b(self%first:self%last)
    call VecRestoreArrayF90(self%b, p, ierr)
    if (failed(ierr, 'VecRestoreArrayF90', self, err)) return
    call KSPSetOperators(self%ksp, self%a, self%a, ierr)
    if (failed(ierr, 'KSPSetOperators', self, err)) return
    ! PETSc's ILU, MUMPS and BLAS may raise IEEE exceptions on the way (a
    ! zero pivot is divided by, then tested): no trap of a Debug driver
    ! (-ffpe-trap) may fire inside them, and its flags stay as they were.
    call ieee_get_flag(ieee_all, flags)
    call ieee_get_halting_mode(ieee_all, halting)
    call ieee_set_halting_mode(ieee_all, .false.)
    call KSPSolve(self%ksp, self%b, self%x, ierr)
    call ieee_set_flag(ieee_all, flags)
    call ieee_set_halting_mode(ieee_all, halting)
    if (failed(ierr, 'KSPSolve', self, err)) return
    call KSPGetConvergedReason(self%ksp, reason, ierr)
    if (failed(ierr, 'KSPGetConvergedReason', self, err)) return
    call KSPGetIterationNumber(self%ksp, its, ierr)
    if (failed(ierr, 'KSPGetIterationNumber', self, err)) return
    if (present(iterations)) iterations = int(its)
    if (reason < 0) then
      call new_error(err, status_cutback, 'solve', 'linear solver ('//name(self)// &
                     '): '//diverged(self, reason, int(its))); return
    end if
    call null_pivots(self, nnull, ierr)
    if (failed(ierr, 'MatMumpsGetInfog', self, err)) return
    if (nnull > 0) then
      call new_error(err, status_cutback, 'solve', 'linear solver ('//name(self)// &
                     '): the matrix is singular (MUMPS found '//int_text(nnull)// &
                     ' null pivot(s): a node or mode nothing holds)'); return
    end if
    if (self%distributed) then
      call VecScatterBegin(self%to_all, self%x, self%whole, INSERT_VALUES, SCATTER_FORWARD, ierr)
      if (ierr == 0) call VecScatterEnd(self%to_all, self%x, self%whole, INSERT_VALUES, &
                                        SCATTER_FORWARD, ierr)
      if (failed(ierr, 'VecScatterBegin/End', self, err)) return
      call VecGetArrayReadF90(self%whole, p, ierr)
      if (failed(ierr, 'VecGetArrayReadF90', self, err)) return
      x = p
      call VecRestoreArrayReadF90(self%whole, p, ierr)
      if (failed(ierr, 'VecRestoreArrayReadF90', self, err)) return
      return
    end if
    call VecGetArrayReadF90(self%x, p, ierr)
    if (failed(ierr, 'VecGetArrayReadF90', self, err)) return
    x = p
    call VecRestoreArrayReadF90(self%x, p, ierr)
    if (failed(ierr, 'VecRestoreArrayReadF90', self, err)) return
  end subroutine solve

  !> Free the KSP, vectors and matrix. Safe before setup, twice, and after
  !> linear_solver_finalize (PETSc has then freed everything itself).
  subroutine destroy(self)
    class(linear_solver_t), intent(inout) :: self
    PetscErrorCode :: ierr
    PetscBool :: finished
    if (self%stage > 0) then
      call PetscFinalized(finished, ierr)
      if (.not. finished) then
        if (self%stage >= 5) call VecScatterDestroy(self%to_all, ierr)
        if (self%stage >= 5) call VecDestroy(self%whole, ierr)
        if (self%stage >= 4) call KSPDestroy(self%ksp, ierr)
        if (self%stage >= 3) call VecDestroy(self%x, ierr)
        if (self%stage >= 2) call VecDestroy(self%b, ierr)
        call MatDestroy(self%a, ierr)
      end if
    end if
    self%stage = 0
    self%n = 0
    self%method = 0
    self%dirty = .false.
    self%distributed = .false.
    if (allocated(self%fault)) deallocate (self%fault)
  end subroutine destroy

  !> End PETSc if this module started it (and with it MPI, when PETSc
  !> started that too); a driver that began MPI itself finalises it after
  !> this. Call once, after destroying every solver: PETSc cannot restart.
  subroutine linear_solver_finalize()
    PetscErrorCode :: ierr
    PetscBool :: started
    if (.not. petsc_started_here) return
    call PetscInitialized(started, ierr)
    if (started) call PetscFinalize(ierr)
    petsc_started_here = .false.
  end subroutine linear_solver_finalize

  !> PetscInitialize once per process, on the MPI the driver began if any
  !> (PETSc then leaves MPI_Finalize to it), else PETSc begins MPI itself.
  !> Without argc/argv, and without PETSc's signal handlers, so the driver's
  !> options and crash reports stay its own; PETSC_OPTIONS still applies.
  subroutine start_petsc(err)
    type(error_t), allocatable, intent(out) :: err
    PetscBool :: started, finished
    PetscErrorCode :: ierr
    call PetscInitialized(started, ierr)
    if (started) return
    call PetscFinalized(finished, ierr)
    if (finished) then
      call new_error(err, status_invalid, 'setup', 'linear solver: PETSc was finalised '// &
                     'in this process (linear_solver_finalize) and cannot start again')
      return
    end if
    ierr = petsc_options_set_value(c_null_ptr, '-no_signal_handler'//c_null_char, c_null_ptr)
    if (ierr == 0) ierr = petsc_initialize_no_arguments()
    if (ierr == 0) ierr = petsc_initialize_fortran()
    if (ierr /= 0) then
      call new_error(err, status_invalid, 'setup', 'linear solver: PetscInitialize '// &
                     'failed with PETSc error code '//int_text(int(ierr)))
      return
    end if
    petsc_started_here = .true.
  end subroutine start_petsc

  !> MUMPS's count of null pivots in the last factorisation (INFOG(28);
  !> 0 for GMRES, whose ILU reports a zero pivot as a divergence).
  subroutine null_pivots(self, nnull, ierr)
    type(linear_solver_t), intent(in) :: self
    integer, intent(out) :: nnull
    PetscErrorCode, intent(out) :: ierr
    PetscInt :: infog
    Mat :: factor
    PC :: pc
    nnull = 0
    ierr = 0
    if (self%method /= solver_direct) return
    call KSPGetPC(self%ksp, pc, ierr)
    if (ierr == 0) call PCFactorGetMatrix(pc, factor, ierr)
    if (ierr == 0) call MatMumpsGetInfog(factor, to_petsc(28), infog, ierr)
    if (ierr == 0) nnull = int(infog)
  end subroutine null_pivots

  !> Add 0 to every diagonal entry of this rank's rows: PETSc's ILU refuses
  !> a row without one (a node nothing stiffens) as an error; stored, it is
  !> a zero pivot, a divergence the solve reports as a singular matrix.
  subroutine diagonal_entries(self, ierr)
    type(linear_solver_t), intent(inout) :: self
    PetscErrorCode, intent(out) :: ierr
    PetscInt :: k(1)
    PetscScalar, parameter :: nothing(1) = 0.0_dp
    integer :: i
    ierr = 0
    do i = self%first, self%last
      k(1) = to_petsc(i - 1)
      call MatSetValues(self%a, to_petsc(1), k, to_petsc(1), k, nothing, ADD_VALUES, ierr)
      if (ierr /= 0) return
    end do
  end subroutine diagonal_entries

  !> MatAssemblyBegin/End of the final assembly, after the entries' adds.
  subroutine assemble(self, ierr)
    type(linear_solver_t), intent(inout) :: self
    PetscErrorCode, intent(out) :: ierr
    call MatAssemblyBegin(self%a, MAT_FINAL_ASSEMBLY, ierr)
    if (ierr == 0) call MatAssemblyEnd(self%a, MAT_FINAL_ASSEMBLY, ierr)
    if (ierr == 0) self%dirty = .false.
  end subroutine assemble

  !> True, with err naming the routine and code, when PETSc returned ierr /= 0.
  logical function failed(ierr, routine, self, err)
    PetscErrorCode, intent(in) :: ierr
    character(len=*), intent(in) :: routine
    type(linear_solver_t), intent(in) :: self
    type(error_t), allocatable, intent(out) :: err
    failed = ierr /= 0
    if (failed) call new_error(err, status_invalid, 'petsc', 'linear solver ('// &
      name(self)//'): PETSc''s '//routine//' failed with error code '//int_text(int(ierr))// &
      ' (PETSc wrote its details on standard error)')
  end function failed

  !> Keep the first fault of `add` or `zero` for the next solve.
  subroutine note(self, what)
    type(linear_solver_t), intent(inout) :: self
    character(len=*), intent(in) :: what
    if (.not. allocated(self%fault)) self%fault = what
  end subroutine note

  !> note() for a PETSc routine's error code.
  subroutine note_fault(self, routine, ierr)
    type(linear_solver_t), intent(inout) :: self
    character(len=*), intent(in) :: routine
    PetscErrorCode, intent(in) :: ierr
    call note(self, 'PETSc''s '//routine//' failed with error code '//int_text(int(ierr))// &
              ' (PETSc wrote its details on standard error)')
  end subroutine note_fault

  !> Why the KSP diverged, in words (KSPConvergedReason < 0), with the
  !> preconditioner's own reason when it failed (a zero pivot: singular K).
  function diverged(self, reason, its) result(why)
    type(linear_solver_t), intent(in) :: self
    KSPConvergedReason, intent(in) :: reason
    integer, intent(in) :: its
    character(len=:), allocatable :: why
    PCFailedReason :: pcreason
    PetscErrorCode :: ierr
    PC :: pc
    select case (reason)
    case (KSP_DIVERGED_ITS)
      why = 'KSP_DIVERGED_ITS (no convergence within the iteration limit)'
    case (KSP_DIVERGED_DTOL)
      why = 'KSP_DIVERGED_DTOL (the residual grew)'
    case (KSP_DIVERGED_BREAKDOWN)
      why = 'KSP_DIVERGED_BREAKDOWN (the Krylov method broke down)'
    case (KSP_DIVERGED_NANORINF)
      why = 'KSP_DIVERGED_NANORINF (a NaN or Inf in the residual: is K or b finite?)'
    case (KSP_DIVERGED_NULL)
      why = 'KSP_DIVERGED_NULL'
    case (KSP_DIVERGED_PC_FAILED)
      why = 'KSP_DIVERGED_PC_FAILED (the preconditioner failed'
      call KSPGetPC(self%ksp, pc, ierr)
      if (ierr == 0) call PCGetFailedReason(pc, pcreason, ierr)
      if (ierr /= 0) then
        why = why//')'
      else if (pcreason == PC_FACTOR_NUMERIC_ZEROPIVOT .or. &
               pcreason == PC_FACTOR_STRUCT_ZEROPIVOT) then
        why = why//': a zero pivot in the factorisation, the matrix is singular)'
      else if (pcreason == PC_FACTOR_OUTMEMORY) then
        why = why//': out of memory in the factorisation)'
      else
        why = why//', PCFailedReason '//int_text(int(pcreason))//')'
      end if
    case default
      why = 'KSPConvergedReason '//int_text(int(reason))
    end select
    if (reason /= KSP_DIVERGED_PC_FAILED) why = why//' after '//int_text(its)//' iterations'
  end function diverged

  !> The method's name for messages.
  function name(self) result(text)
    type(linear_solver_t), intent(in) :: self
    character(len=:), allocatable :: text
    if (self%method == solver_direct .or. self%method == solver_gmres) then
      text = trim(solver_names(self%method))
    else
      text = 'not set up'
    end if
  end function name

  !> An integer in PETSc's index kind (PetscInt).
  elemental function to_petsc(i) result(k)
    integer, intent(in) :: i
    PetscInt :: k
    k = int(i, kind(k))
  end function to_petsc

end module wellposed_mpm_linear_solver
