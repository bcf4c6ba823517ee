!> The Abaqus/Standard utility routines legacy UMATs call, as external
!> subroutines with Abaqus' names and arguments (Abaqus User Subroutines
!> Reference, "Utility routines"; docs/guide/hosting.md): XIT, XPLB_EXIT, STDB_ABQERR,
!> SINV, SPRINC, SPRIND, ROTSIG, GETOUTDIR, GETJOBNAME. LSTR = 1: stress; 2: strain
!> with engineering shears.

!> XIT: end the run at once with a clear message (no output is finished).
subroutine xit()
  use wellposed_abaqus_job, only: abaqus_abort
  implicit none
  call abaqus_abort('the UMAT called XIT (Abaqus: terminate the analysis)')
end subroutine xit

!> XPLB_EXIT: Abaqus/Explicit's XIT, for a VUMAT.
subroutine xplb_exit()
  use wellposed_abaqus_job, only: abaqus_abort
  implicit none
  call abaqus_abort('the VUMAT called XPLB_EXIT (Abaqus/Explicit: terminate the analysis)')
end subroutine xplb_exit

!> STDB_ABQERR: a note, warning or error of the UMAT on standard error.
!> LOP = 1 note, -1 warning, -2 error (the host stops the run after the
!> call), -3 error and end now; %I, %R, %S take the next INTV, REALV, CHARV.
subroutine stdb_abqerr(lop, string, intv, realv, charv)
  use, intrinsic :: iso_fortran_env, only: error_unit
  use wellposed_kinds, only: dp
  use wellposed_text, only: int_text, real_text
  use wellposed_abaqus_job, only: abaqus_raise, abaqus_abort
  implicit none
  integer, intent(in) :: lop, intv(*)
  character(len=*), intent(in) :: string
  real(dp), intent(in) :: realv(*)
  character(len=8), intent(in) :: charv(*)
  character(len=:), allocatable :: text, head
  integer :: k, ni, nr, nc
  text = ''
  ni = 0; nr = 0; nc = 0
  k = 1
  do while (k <= len_trim(string))
    if (string(k:k) == '%' .and. k < len_trim(string)) then
      select case (string(k + 1:k + 1))
      case ('I', 'i')
        ni = ni + 1; text = text//int_text(intv(ni)); k = k + 2; cycle
      case ('R', 'r')
        nr = nr + 1; text = text//real_text(realv(nr)); k = k + 2; cycle
      case ('S', 's')
        nc = nc + 1; text = text//trim(charv(nc)); k = k + 2; cycle
      end select
    end if
    text = text//string(k:k)
    k = k + 1
  end do
  select case (lop)
  case (1)
    head = '***NOTE (UMAT): '
  case (-1)
    head = '***WARNING (UMAT): '
  case default
    head = '***ERROR (UMAT): '
  end select
  write (error_unit, '(a)') head//text
  if (lop == -2) call abaqus_raise(text)
  if (lop <= -3) call abaqus_abort('the UMAT ended the run (STDB_ABQERR with LOP = -3)')
end subroutine stdb_abqerr

!> SINV: SINV1 = (S11 + S22 + S33)/3, SINV2 = sqrt(3/2 dev(S):dev(S)).
subroutine sinv(stress, sinv1, sinv2, ndi, nshr)
  use wellposed_kinds, only: dp
  use wellposed_abaqus_tensors, only: abaqus_sinv
  implicit none
  integer, intent(in) :: ndi, nshr
  real(dp), intent(in) :: stress(ndi + nshr)
  real(dp), intent(out) :: sinv1, sinv2
  call abaqus_sinv(stress, ndi, nshr, sinv1, sinv2)
end subroutine sinv

!> SPRINC: principal values PS (ascending) of a stress (LSTR = 1) or strain.
subroutine sprinc(s, ps, lstr, ndi, nshr)
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_abaqus_tensors, only: abaqus_sprind
  use wellposed_abaqus_job, only: abaqus_abort
  implicit none
  integer, intent(in) :: lstr, ndi, nshr
  real(dp), intent(in) :: s(ndi + nshr)
  real(dp), intent(out) :: ps(3)
  type(error_t), allocatable :: err
  call abaqus_sprind(s, lstr, ndi, nshr, ps, err=err)
  if (allocated(err)) call abaqus_abort('SPRINC: '//err%message)
end subroutine sprinc

!> SPRIND: principal values PS (ascending) and directions, AN(K, 1:3) the
!> unit vector of PS(K).
subroutine sprind(s, ps, an, lstr, ndi, nshr)
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_abaqus_tensors, only: abaqus_sprind
  use wellposed_abaqus_job, only: abaqus_abort
  implicit none
  integer, intent(in) :: lstr, ndi, nshr
  real(dp), intent(in) :: s(ndi + nshr)
  real(dp), intent(out) :: ps(3), an(3, 3)
  type(error_t), allocatable :: err
  call abaqus_sprind(s, lstr, ndi, nshr, ps, an, err)
  if (allocated(err)) call abaqus_abort('SPRIND: '//err%message)
end subroutine sprind

!> ROTSIG: SPRIME = R S R^T in Abaqus vector form (LSTR = 2: strain).
subroutine rotsig(s, r, sprime, lstr, ndi, nshr)
  use wellposed_kinds, only: dp
  use wellposed_abaqus_tensors, only: abaqus_rotsig
  implicit none
  integer, intent(in) :: lstr, ndi, nshr
  real(dp), intent(in) :: s(ndi + nshr), r(3, 3)
  real(dp), intent(out) :: sprime(ndi + nshr)
  sprime = abaqus_rotsig(s, r, lstr, ndi, nshr)
end subroutine rotsig

!> GETOUTDIR: the run's output folder and its length.
subroutine getoutdir(outdir, lenoutdir)
  use wellposed_abaqus_job, only: abaqus_outdir, abaqus_put
  implicit none
  character(len=*), intent(out) :: outdir
  integer, intent(out) :: lenoutdir
  call abaqus_put(abaqus_outdir(), outdir, lenoutdir)
end subroutine getoutdir

!> GETJOBNAME: the run's name and its length.
subroutine getjobname(jobname, lenjobname)
  use wellposed_abaqus_job, only: abaqus_jobname, abaqus_put
  implicit none
  character(len=*), intent(out) :: jobname
  integer, intent(out) :: lenjobname
  call abaqus_put(abaqus_jobname(), jobname, lenjobname)
end subroutine getjobname
