!> A counting malloc for tests: defining `malloc`, `calloc` and `realloc`
!> in the test program interposes them for the whole process (glibc looks
!> them up in the executable first), so every heap allocation, from
!> wellposed's code, a compiler temporary or the Fortran runtime, goes
!> through here; each is counted and handed to glibc's own allocator
!> (__libc_malloc and friends, which glibc's free releases). Linux/glibc
!> only; the count is a test's oracle, so this is test support, not src/.
module wellposed_malloc_counter
  use, intrinsic :: iso_c_binding, only: c_ptr, c_size_t, c_long_long
  implicit none
  private
  public :: heap_allocations

  !> Allocations since the program started.
  integer(c_long_long), save :: count = 0

  interface
    function libc_malloc(n) bind(C, name='__libc_malloc') result(ptr)
      import :: c_ptr, c_size_t
      integer(c_size_t), value :: n
      type(c_ptr) :: ptr
    end function libc_malloc
    function libc_calloc(m, n) bind(C, name='__libc_calloc') result(ptr)
      import :: c_ptr, c_size_t
      integer(c_size_t), value :: m, n
      type(c_ptr) :: ptr
    end function libc_calloc
    function libc_realloc(old, n) bind(C, name='__libc_realloc') result(ptr)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: old
      integer(c_size_t), value :: n
      type(c_ptr) :: ptr
    end function libc_realloc
  end interface

contains

  !> Heap allocations (malloc, calloc, realloc calls) so far.
  function heap_allocations() result(n)
    integer(c_long_long) :: n
    n = count
  end function heap_allocations

  function counted_malloc(n) bind(C, name='malloc') result(ptr)
    integer(c_size_t), value :: n
    type(c_ptr) :: ptr
    count = count + 1
    ptr = libc_malloc(n)
  end function counted_malloc

  function counted_calloc(m, n) bind(C, name='calloc') result(ptr)
    integer(c_size_t), value :: m, n
    type(c_ptr) :: ptr
    count = count + 1
    ptr = libc_calloc(m, n)
  end function counted_calloc

  function counted_realloc(old, n) bind(C, name='realloc') result(ptr)
    type(c_ptr), value :: old
    integer(c_size_t), value :: n
    type(c_ptr) :: ptr
    count = count + 1
    ptr = libc_realloc(old, n)
  end function counted_realloc

end module wellposed_malloc_counter
