!> Errors as values (fpm style): a routine that can fail takes
!> `type(error_t), allocatable, intent(out) :: err` and leaves it unallocated
!> on success. Nothing in src/ stops or prints; the edge (umat/, drivers)
!> decides what to do with an error.
module wellposed_error
  implicit none
  private
  public :: error_t, new_error, status_invalid, status_cutback

  !> Status of invalid input: no cut-back can cure it (UMAT status -1).
  integer, parameter :: status_invalid = -1
  !> Status of a failure a smaller increment may cure (UMAT status -2).
  integer, parameter :: status_cutback = -2

  !> One error: its status, the input it concerns (a parameter's symbol,
  !> empty when no single input is to blame) and a sentence for a person.
  type :: error_t
    integer :: status = status_invalid
    character(len=:), allocatable :: key
    character(len=:), allocatable :: message
  end type error_t

contains

  !> Allocate `err` with a status, the offending key and a message.
  pure subroutine new_error(err, status, key, message)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in) :: status
    character(len=*), intent(in) :: key
    character(len=*), intent(in) :: message
    allocate (err)
    err%status = status
    err%key = key
    err%message = message
  end subroutine new_error

end module wellposed_error
