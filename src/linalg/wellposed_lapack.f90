!> The one adapter to LAPACK for wellposed: explicit interfaces to DSYEV,
!> DGEEV, DGESVD and DPBSV, and small wrappers with errors as values:
!> symmetric eigenpairs, eigenvalues of a general matrix (real and
!> imaginary parts), the Moore-Penrose pseudo-inverse by the SVD (the
!> best-fit map L = R S^+ of section 3.5), and a banded symmetric positive
!> definite solve (the MPM's mass matrix of a bar). Work arrays are queried
!> from LAPACK and allocated per call (no saved state).
module wellposed_lapack
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  implicit none
  private
  public :: sym_eigen, general_eigenvalues, pseudo_inverse, spd_band_solve

  interface
    subroutine dsyev(jobz, uplo, n, a, lda, w, work, lwork, info)
      import :: dp
      character, intent(in) :: jobz, uplo
      integer, intent(in) :: n, lda, lwork
      real(dp), intent(inout) :: a(lda, *)
      real(dp), intent(out) :: w(*), work(*)
      integer, intent(out) :: info
    end subroutine dsyev
    subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, info)
      import :: dp
      character, intent(in) :: jobvl, jobvr
      integer, intent(in) :: n, lda, ldvl, ldvr, lwork
      real(dp), intent(inout) :: a(lda, *)
      real(dp), intent(out) :: wr(*), wi(*), vl(ldvl, *), vr(ldvr, *), work(*)
      integer, intent(out) :: info
    end subroutine dgeev
    subroutine dgesvd(jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt, work, lwork, info)
      import :: dp
      character, intent(in) :: jobu, jobvt
      integer, intent(in) :: m, n, lda, ldu, ldvt, lwork
      real(dp), intent(inout) :: a(lda, *)
      real(dp), intent(out) :: s(*), u(ldu, *), vt(ldvt, *), work(*)
      integer, intent(out) :: info
    end subroutine dgesvd
    subroutine dpbsv(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
      import :: dp
      character(len=1), intent(in) :: uplo
      integer, intent(in) :: n, kd, nrhs, ldab, ldb
      real(dp), intent(inout) :: ab(ldab, *), b(ldb, *)
      integer, intent(out) :: info
    end subroutine dpbsv
  end interface

contains

  !> Eigenvalues `w` (ascending) and orthonormal eigenvectors (columns of
  !> `v`) of the symmetric matrix `a` (only its upper triangle is read).
  subroutine sym_eigen(a, w, v, err)
    real(dp), intent(in) :: a(:, :)
    real(dp), intent(out) :: w(:), v(:, :)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: work(:)
    real(dp) :: query(1)
    integer :: n, info
    n = size(a, 1)
    v = a
    call dsyev('V', 'U', n, v, n, w, query, -1, info)
    allocate (work(max(1, int(query(1)))))
    call dsyev('V', 'U', n, v, n, w, work, size(work), info)
    if (info /= 0) call new_error(err, status_invalid, 'dsyev', &
      'LAPACK DSYEV failed (info /= 0): symmetric eigenproblem not solved')
  end subroutine sym_eigen

  !> Eigenvalues wr + i wi of the general square matrix `a` (DGEEV).
  subroutine general_eigenvalues(a, wr, wi, err)
    real(dp), intent(in) :: a(:, :)
    real(dp), intent(out) :: wr(:), wi(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: work(:), b(:, :)
    real(dp) :: query(1), vl(1, 1), vr(1, 1)
    integer :: n, info
    n = size(a, 1)
    allocate (b, source=a)  ! (not b = a: LTO then warns of b's descriptor)
    call dgeev('N', 'N', n, b, n, wr, wi, vl, 1, vr, 1, query, -1, info)
    allocate (work(max(1, int(query(1)))))
    call dgeev('N', 'N', n, b, n, wr, wi, vl, 1, vr, 1, work, size(work), info)
    if (info /= 0) call new_error(err, status_invalid, 'dgeev', &
      'LAPACK DGEEV failed (info /= 0): eigenvalues not found')
  end subroutine general_eigenvalues

  !> Moore-Penrose pseudo-inverse of the m x n matrix `a` (n x m result)
  !> by the SVD; singular values below rcond * (largest) count as zero.
  !> `sv` returns the singular values when present.
  subroutine pseudo_inverse(a, ainv, err, rcond, sv)
    real(dp), intent(in) :: a(:, :)
    real(dp), intent(out) :: ainv(:, :)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: rcond
    real(dp), intent(out), optional :: sv(:)
    real(dp), allocatable :: b(:, :), s(:), u(:, :), vt(:, :), work(:)
    real(dp) :: query(1), cut
    integer :: m, n, k, i, info
    m = size(a, 1)
    n = size(a, 2)
    k = min(m, n)
    allocate (b, source=a)
    allocate (s(k), u(m, k), vt(k, n))
    call dgesvd('S', 'S', m, n, b, m, s, u, m, vt, k, query, -1, info)
    allocate (work(max(1, int(query(1)))))
    call dgesvd('S', 'S', m, n, b, m, s, u, m, vt, k, work, size(work), info)
    if (info /= 0) then
      call new_error(err, status_invalid, 'dgesvd', 'LAPACK DGESVD failed (info /= 0)')
      return
    end if
    cut = epsilon(1.0_dp)*max(m, n)
    if (present(rcond)) cut = rcond
    cut = cut*maxval(s)
    ainv = 0.0_dp
    do i = 1, k
      if (s(i) > cut) ainv = ainv + spread(vt(i, :), 2, m)*spread(u(:, i), 1, n)/s(i)
    end do
    if (present(sv)) sv(1:k) = s
  end subroutine pseudo_inverse

  !> Solve A x = b for a symmetric positive definite band matrix A held in
  !> `ab` (kd + 1, n) as its lower band, ab(1 + i - j, j) = A(i, j) (DPBSV);
  !> `b` becomes x and `ab` its Cholesky factor. `ok` is false when A is not
  !> positive definite (b is then not a solution).
  subroutine spd_band_solve(ab, b, ok)
    real(dp), intent(inout) :: ab(:, :), b(:)
    logical, intent(out) :: ok
    integer :: info
    call dpbsv('L', size(ab, 2), size(ab, 1) - 1, 1, ab, size(ab, 1), b, size(b), info)
    ok = info == 0
  end subroutine spd_band_solve

end module wellposed_lapack
