!> The material's side of Algorithm 1 (wellposed_mpm_algorithm1): one UMAT
!> call for particle p from its start-of-step copies with STATEV(3) = avg;
!> dlambda = STATEV(2) afterwards. A host implements `update`, and may
!> override `update_local` (step 1, every particle with avg = 0) and
!> `update_list` (a list of independent calls) to do them a block at a
!> time; by default both call `update` per particle, in order.
module wellposed_mpm_nonlocal_host
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  implicit none
  private
  public :: nonlocal_host_t

  type, abstract :: nonlocal_host_t
  contains
    procedure(host_update), deferred :: update
    procedure :: update_local
    procedure :: update_list
  end type nonlocal_host_t

  abstract interface
    subroutine host_update(self, p, avg, dlambda, err)
      import :: nonlocal_host_t, dp, error_t
      class(nonlocal_host_t), intent(inout) :: self
      integer, intent(in) :: p
      real(dp), intent(in) :: avg
      real(dp), intent(out) :: dlambda
      type(error_t), allocatable, intent(out) :: err
    end subroutine host_update
  end interface

contains

  !> Step 1 of Algorithm 1: every particle once with <dlambda> = 0, in
  !> order, up to the first error.
  subroutine update_local(self, dl, err)
    class(nonlocal_host_t), intent(inout) :: self
    real(dp), intent(out) :: dl(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: p
    do p = 1, size(dl)
      call self%update(p, 0.0_dp, dl(p), err)
      if (allocated(err)) return
    end do
  end subroutine update_local

  !> Particles list(q) with <dlambda> = avg(q): dl(q) their dlambda, in
  !> order, up to the first error (the entries past it are not set).
  subroutine update_list(self, list, avg, dl, err)
    class(nonlocal_host_t), intent(inout) :: self
    integer, intent(in) :: list(:)
    real(dp), intent(in) :: avg(:)
    real(dp), intent(out) :: dl(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: q
    do q = 1, size(list)
      call self%update(list(q), avg(q), dl(q), err)
      if (allocated(err)) return
    end do
  end subroutine update_list

end module wellposed_mpm_nonlocal_host
