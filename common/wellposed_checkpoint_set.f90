!> The set a checkpoint holds in memory: named 1-D arrays (real(dp) or
!> integer; a text as its character codes) in the order they were put,
!> each held once (put copies the caller's array, put_moved takes it over).
!> Files of it: wellposed_checkpoint.
module wellposed_checkpoint_set
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  implicit none
  private
  public :: checkpoint_t, entry_t, add_entry

  type :: entry_t
    character(len=:), allocatable :: name
    real(dp), allocatable :: r(:)
    integer, allocatable :: i(:)
  end type entry_t

  !> Named arrays in the order they were put.
  type :: checkpoint_t
    type(entry_t), allocatable :: entries(:)
    integer :: n = 0
  contains
    procedure, private :: put_r1, put_i1, put_r0, put_i0
    !> put(name, values): a real(dp) or integer array or scalar.
    generic :: put => put_r1, put_i1, put_r0, put_i0
    procedure, private :: get_r1, get_i1, get_r0, get_i0
    !> get(name, values, err): the array (allocated to its length) or scalar.
    generic :: get => get_r1, get_i1, get_r0, get_i0
    procedure :: has => ckpt_has
    procedure :: put_moved => ckpt_put_moved
    !> put_text(name, text): a text as [0, its character codes].
    procedure :: put_text => ckpt_put_text
    !> get_text(name, text, err): the text put by put_text.
    procedure :: get_text => ckpt_get_text
  end type checkpoint_t

contains

  !> e into the set (replacing an entry of its name), its arrays moved, not
  !> copied: a checkpoint holds each array once (particle records are most
  !> of a run's memory at that moment).
  subroutine add_entry(self, e)
    class(checkpoint_t), intent(inout) :: self
    type(entry_t), intent(inout) :: e
    type(entry_t), allocatable :: grown(:)
    integer :: k
    if (.not. allocated(self%entries)) allocate (self%entries(16))
    do k = 1, self%n
      if (self%entries(k)%name == e%name) then
        call move_entry(e, self%entries(k))
        return
      end if
    end do
    if (self%n == size(self%entries)) then
      allocate (grown(2*self%n))
      do k = 1, self%n
        call move_entry(self%entries(k), grown(k))
      end do
      call move_alloc(grown, self%entries)
    end if
    self%n = self%n + 1
    call move_entry(e, self%entries(self%n))
  end subroutine add_entry

  !> to takes from's name and arrays (from's arrays deallocated).
  subroutine move_entry(from, to)
    type(entry_t), intent(inout) :: from, to
    call move_alloc(from%name, to%name)
    if (allocated(to%r)) deallocate (to%r)
    if (allocated(to%i)) deallocate (to%i)
    if (allocated(from%r)) call move_alloc(from%r, to%r)
    if (allocated(from%i)) call move_alloc(from%i, to%i)
  end subroutine move_entry

  subroutine put_r1(self, name, values)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    type(entry_t) :: e
    e%name = name
    e%r = values
    call add_entry(self, e)
  end subroutine put_r1

  !> put_moved(name, values): the array taken over without a copy (values
  !> is deallocated on return).
  subroutine ckpt_put_moved(self, name, values)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), allocatable, intent(inout) :: values(:)
    type(entry_t) :: e
    e%name = name
    call move_alloc(values, e%r)
    call add_entry(self, e)
  end subroutine ckpt_put_moved

  subroutine put_i1(self, name, values)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: values(:)
    type(entry_t) :: e
    e%name = name
    e%i = values
    call add_entry(self, e)
  end subroutine put_i1

  subroutine put_r0(self, name, value)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value
    call put_r1(self, name, [value])
  end subroutine put_r0

  subroutine put_i0(self, name, value)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    call put_i1(self, name, [value])
  end subroutine put_i0

  subroutine ckpt_put_text(self, name, text)
    class(checkpoint_t), intent(inout) :: self
    character(len=*), intent(in) :: name, text
    integer :: k
    call put_i1(self, name, [0, (iachar(text(k:k)), k=1, len(text))])
  end subroutine ckpt_put_text

  subroutine ckpt_get_text(self, name, text, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: c(:)
    integer :: k
    call get_i1(self, name, c, err)
    if (allocated(err)) return
    if (size(c) >= 1) then
      if (c(1) == 0 .and. all(c(2:) >= 0 .and. c(2:) <= 255)) then
        allocate (character(len=size(c) - 1) :: text)
        do k = 2, size(c)
          text(k - 1:k - 1) = achar(c(k))
        end do
        return
      end if
    end if
    call new_error(err, status_invalid, name, 'checkpoint entry "'//name//'" is not a text')
  end subroutine ckpt_get_text

  integer function find(self, name) result(k)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    do k = 1, self%n
      if (self%entries(k)%name == name) return
    end do
    k = 0
  end function find

  logical function ckpt_has(self, name)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    ckpt_has = find(self, name) > 0
  end function ckpt_has

  subroutine missing(name, kind, err)
    character(len=*), intent(in) :: name, kind
    type(error_t), allocatable, intent(out) :: err
    call new_error(err, status_invalid, name, 'the checkpoint holds no '//kind//' array "'// &
      name//'" (written by another version of the program?)')
  end subroutine missing

  subroutine get_r1(self, name, values, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    real(dp), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    k = find(self, name)
    if (k > 0) then
      if (allocated(self%entries(k)%r)) then
        values = self%entries(k)%r
        return
      end if
    end if
    call missing(name, 'real', err)
  end subroutine get_r1

  subroutine get_i1(self, name, values, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    integer, allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    k = find(self, name)
    if (k > 0) then
      if (allocated(self%entries(k)%i)) then
        values = self%entries(k)%i
        return
      end if
    end if
    call missing(name, 'integer', err)
  end subroutine get_i1

  subroutine get_r0(self, name, value, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: value
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: v(:)
    call get_r1(self, name, v, err)
    if (allocated(err)) return
    if (size(v) /= 1) then
      call new_error(err, status_invalid, name, 'checkpoint entry "'//name//'" is not a scalar')
      return
    end if
    value = v(1)
  end subroutine get_r0

  subroutine get_i0(self, name, value, err)
    class(checkpoint_t), intent(in) :: self
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: v(:)
    call get_i1(self, name, v, err)
    if (allocated(err)) return
    if (size(v) /= 1) then
      call new_error(err, status_invalid, name, 'checkpoint entry "'//name//'" is not a scalar')
      return
    end if
    value = v(1)
  end subroutine get_i0

end module wellposed_checkpoint_set
