!> No heap allocation on the success path of the UMAT and the VUMAT: every
!> model of the contract (elastic, cone and apex increments, NTENS 6 and 4,
!> with and without DDSDDE) and a VUMAT block, counted by the interposed
!> malloc of wellposed_malloc_counter after one warm-up round. The test
!> first shows the counter sees an allocation inside the library (the error
!> value of an invalid call), so it can fail. Exit 0 and
!> one line on success; a message and exit 1 otherwise.
program umat_heap_main
  use, intrinsic :: iso_c_binding, only: c_long_long
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_umat_interface, only: umat
  use wellposed_umat_adapter, only: umat_update
  use wellposed_vumat_adapter, only: vumat_update
  use wellposed_malloc_counter, only: heap_allocations
  implicit none
  integer, parameter :: nmodels = 9, nblock = 16
  integer(c_long_long) :: n0, n1
  real(dp) :: stress(6), statev(12), ddsdde(6, 6), sse, spd, pnewdt
  type(error_t), allocatable :: err
  integer :: ncalls, iround

  ! The counter sees the error value an invalid call builds in the library.
  stress = 0.0_dp; statev = 0.0_dp; sse = 0.0_dp; spd = 0.0_dp; pnewdt = 1.0_dp
  n0 = heap_allocations()
  call umat_update(stress, statev, ddsdde, sse, spd, [1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, &
                   0.0_dp, 0.0_dp], [(0.0_dp, iround = 1, 6)], 1.0e-3_dp, 3, 3, 6, 12, &
                   [-1.0_dp, 1.5e9_dp, 0.3_dp, 0.0_dp, 5.0e6_dp], 5, pnewdt, err)
  n1 = heap_allocations()
  if (.not. allocated(err) .or. n1 == n0) &
    error stop 'umat_heap: the counter misses the library''s allocations'

  ncalls = 0
  do iround = 1, 2
    if (iround == 2) n0 = heap_allocations()
    call every_case(ncalls)
  end do
  n1 = heap_allocations()
  if (n1 /= n0) then
    write (*, '(a,i0,a,i0,a)') 'umat_heap: ', n1 - n0, ' heap allocations in ', ncalls/2, &
      ' successful UMAT and VUMAT calls (expected none)'
    error stop 1
  end if
  write (*, '(a,i0,a)') 'umat_heap: no heap allocation in ', ncalls/2, &
    ' successful UMAT and VUMAT calls'

contains

  !> The models of the contract (as test_vumat's): 1 elastic, 2
  !> nonassociative, 3 hardening, 4 softening, 5 exponential eq. 2.6, 6 EFR
  !> P_v, 7 EFR P_d, 8 Duvaut-Lions, 9 nonlocal slots.
  function model_props(m, explicit) result(pr)
    integer, intent(in) :: m
    logical, intent(in) :: explicit
    real(dp) :: pr(14)
    pr = 0.0_dp
    pr(1:5) = [4.0e9_dp, 1.5e9_dp, 0.315_dp, 0.0_dp, 5.066e6_dp]
    select case (m)
    case (1); pr(5) = 1.0e12_dp
    case (2); pr(4) = 0.1_dp
    case (3); pr(6) = 2.0e8_dp
    case (4); pr(6) = -2.0e8_dp
    case (5); pr(7) = 10.0e6_dp; pr(8) = 1.0e-3_dp
    case (6); pr(4) = 0.315_dp; pr(9) = 0.5_dp
    case (7); pr(4) = 0.315_dp; pr(10) = 0.5_dp
    case (8); pr(11) = 2.0e-3_dp
    case (9); pr(6) = 1.0e8_dp; pr(12) = 3.0e8_dp; pr(13) = 0.05_dp
    end select
    if (explicit) pr(14) = 1.0_dp
  end function model_props

  !> One successful call of every model, regime, NTENS and tangent choice,
  !> and one VUMAT block per model; `n` counts the calls.
  subroutine every_case(n)
    integer, intent(inout) :: n
    real(dp) :: s0(6, 3), de(6, 3), pr(14)
    integer :: m, ic, nt, ie
    s0(:, 1) = [-100.0e6_dp, -30.0e6_dp, -30.0e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    de(:, 1) = [1.0e-6_dp, 0.0_dp, 0.0_dp, 1.0e-7_dp, 0.0_dp, 0.0_dp]
    s0(:, 2) = [-100.0e6_dp, -17.55e6_dp, -17.55e6_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    de(:, 2) = [1.0e-4_dp, -2.0e-5_dp, 3.0e-5_dp, 4.0e-5_dp, -1.0e-5_dp, 2.0e-5_dp]
    s0(:, 3) = 0.0_dp
    de(:, 3) = [3.0e-3_dp, 2.0e-3_dp, 2.5e-3_dp, 1.0e-4_dp, -2.0e-4_dp, 3.0e-4_dp]
    do m = 1, nmodels
      do ie = 0, 1
        pr = model_props(m, ie == 1)
        do nt = 4, 6, 2
          do ic = 1, 3
            call one_umat(pr, s0(:, ic), de(:, ic), nt)
            n = n + 1
          end do
        end do
      end do
      call one_vumat(model_props(m, .false.), s0, de)
      n = n + 1
    end do
  end subroutine every_case

  !> One call through the external umat. Fixed-size local arrays (gfortran
  !> puts automatic arrays of a run-time size on the heap): the leading
  !> elements serve NTENS = 4 by sequence association.
  subroutine one_umat(pr, s0, de, nt)
    real(dp), intent(in) :: pr(14)
    integer, intent(in) :: nt
    real(dp), intent(in) :: s0(6), de(6)
    real(dp) :: s(6), sv(12), dd(36), sse, spd, scd, rpl, ddsddt(6), drplde(6)
    real(dp) :: drpldt, stran(6), time(2), predef(1), coords(3), drot(3, 3), f(3, 3), pnewdt
    character(len=80) :: cmname
    sse = 0; spd = 0; scd = 0; rpl = 0; ddsddt = 0; drplde = 0; drpldt = 0; stran = 0
    time = 0; predef = 0; coords = 0; drot = 0; f = 0; cmname = 'HEAP'; pnewdt = 1; dd = 0
    s = s0; sv = 0.0_dp
    call umat(s, sv, dd, sse, spd, scd, rpl, ddsddt, drplde, drpldt, stran, de, time, &
              1.0e-3_dp, 0.0_dp, 0.0_dp, predef, predef, cmname, 3, nt - 3, nt, 12, pr, 14, &
              coords, drot, pnewdt, 1.0_dp, f, f, 1, 1, 1, 1, 1, 1)
    if (sv(12) < 0.0_dp .or. pnewdt < 1.0_dp) error stop 'umat_heap: a case did not succeed'
  end subroutine one_umat

  !> A block of nblock points cycling through the three regimes (NTENS 6,
  !> VUMAT order 11, 22, 33, 12, 23, 31 and tensor shears).
  subroutine one_vumat(pr, s0, de)
    real(dp), intent(in) :: pr(14), s0(6, 3), de(6, 3)
    real(dp) :: s_old(nblock, 6), s_new(nblock, 6), d(nblock, 6), sv_old(nblock, 12)
    real(dp) :: sv_new(nblock, 12), rho(nblock), e_old(nblock), e_new(nblock), e2_new(nblock)
    type(error_t), allocatable :: verr
    integer :: k, point
    do k = 1, nblock
      s_old(k, :) = s0([1, 2, 3, 4, 6, 5], mod(k, 3) + 1)
      d(k, :) = de([1, 2, 3, 4, 6, 5], mod(k, 3) + 1)
      d(k, 4:6) = 0.5_dp*d(k, 4:6)
    end do
    sv_old = 0.0_dp; sv_new = 0.0_dp; s_new = 0.0_dp; rho = 2500.0_dp; e_old = 0.0_dp
    call vumat_update(nblock, 3, 3, 12, 14, 1.0_dp, 1.0_dp, 1.0e-3_dp, pr, rho, d, s_old, &
                      sv_old, e_old, e_old, s_new, sv_new, e_new, e2_new, verr, point)
    if (allocated(verr)) error stop 'umat_heap: a VUMAT block did not succeed'
  end subroutine one_vumat

end program umat_heap_main
