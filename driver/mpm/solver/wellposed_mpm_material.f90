!> The stress update of one material point through the UMAT contract only
!> (shared design: UMAT_CONTRACT.md), as any host would call a user's UMAT:
!> explicit interface from wellposed_umat_interface, NTENS = 6 (NDI = 3,
!> NSHR = 3), the deck's PROPS, NSTATV >= 12. PNEWDT is the only status the
!> host relies on, so a user's UMAT without wellposed's status slot works:
!>  - PNEWDT < 0 (contract status -1, invalid input): fatal, an error value;
!>  - 0 <= PNEWDT < 1 (status -2, cut back): the increment is split into 2,
!>    4, ... 2**max_halvings equal sub-increments from the saved start state;
!>    if the smallest still fails, an error value.
module wellposed_mpm_material
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_text, only: int_text
  use wellposed_umat_interface, only: umat
  implicit none
  private
  public :: umat_point, max_halvings

  !> Deepest cut-back: 2**6 = 64 sub-increments.
  integer, parameter :: max_halvings = 6

contains

  !> Advance one point by the strain increment dstran (engineering shears)
  !> over dtime (s) ending at time t_end (s). stress (Pa), statev, stran are
  !> updated in place; on error they are left as they came in and `err`
  !> says which particle failed and why. `celent` is the grid cell size (m),
  !> `coords` the position (m), `noel` the particle's global number.
  subroutine umat_point(props, nprops, stress, statev, stran, dstran, dtime, t_end, &
                        coords, celent, noel, nsub_used, err)
    integer, intent(in) :: nprops, noel
    real(dp), intent(in) :: props(nprops), dstran(6), dtime, t_end, coords(3), celent
    real(dp), intent(inout) :: stress(6), statev(:), stran(6)
    integer, intent(out) :: nsub_used
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: s0(6), sv0(size(statev)), e0(6), pnewdt
    integer :: level, nsub, k
    logical :: ok

    pnewdt = 1.0_dp
    call one_call(stress, statev, stran, dstran, dtime, t_end, pnewdt)
    nsub_used = 1
    if (pnewdt >= 1.0_dp) then
      stran = stran + dstran
      if (.not. all(ieee_is_finite(stress))) call nonfinite()
      return
    end if
    if (pnewdt < 0.0_dp) then
      call fatal(pnewdt); return
    end if
    ! Cut back: retry from the saved start state with more sub-increments.
    s0 = stress; sv0 = statev; e0 = stran
    do level = 1, max_halvings
      nsub = 2**level
      stress = s0; statev = sv0; stran = e0
      ok = .true.
      do k = 1, nsub
        pnewdt = 1.0_dp
        call one_call(stress, statev, stran, dstran/nsub, dtime/nsub, &
                      t_end - dtime*real(nsub - k, dp)/nsub, pnewdt)
        if (pnewdt < 0.0_dp) then
          stress = s0; statev = sv0; stran = e0
          call fatal(pnewdt); return
        end if
        if (pnewdt < 1.0_dp) then
          ok = .false.; exit
        end if
        stran = stran + dstran/nsub
      end do
      if (ok) then
        nsub_used = nsub
        if (.not. all(ieee_is_finite(stress))) call nonfinite()
        return
      end if
    end do
    stress = s0; statev = sv0; stran = e0
    call new_error(err, status_cutback, '', 'the UMAT asked to cut back (PNEWDT < 1) '// &
      'the increment of particle '//int_text(noel)//' and still did with '// &
      int_text(2**max_halvings)//' sub-increments; a smaller CFL fraction may help')

  contains

    subroutine one_call(s, sv, e, de, dt, t, pnew)
      real(dp), intent(inout) :: s(6), sv(:), pnew
      real(dp), intent(in) :: e(6), de(6), dt, t
      real(dp) :: ddsdde(6, 6), sse, spd, scd, rpl, ddsddt(6), drplde(6), drpldt
      real(dp) :: time(2), predef(1), dpred(1), drot(3, 3), f0(3, 3), f1(3, 3)
      character(len=80) :: cmname
      sse = 0.0_dp; spd = 0.0_dp; scd = 0.0_dp; rpl = 0.0_dp; drpldt = 0.0_dp
      ddsddt = 0.0_dp; drplde = 0.0_dp; predef = 0.0_dp; dpred = 0.0_dp
      drot = 0.0_dp; drot(1, 1) = 1.0_dp; drot(2, 2) = 1.0_dp; drot(3, 3) = 1.0_dp
      f0 = drot; f1 = drot
      time = [t - dt, t - dt]
      cmname = 'WELLPOSED'
      call umat(s, sv, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, e, de, time, dt, &
                0.0_dp, 0.0_dp, predef, dpred, cmname, 3, 3, 6, size(sv), props, nprops, &
                coords, drot, pnew, celent, f0, f1, noel, 1, 1, 1, 1, 1)
    end subroutine one_call

    subroutine fatal(pnew)
      real(dp), intent(in) :: pnew
      character(len=32) :: buf
      write (buf, '(g0.4)') pnew
      call new_error(err, status_invalid, '', 'the UMAT refused the input of particle '// &
        int_text(noel)//' (PNEWDT = '//trim(buf)//', contract status -1: invalid input; '// &
        'its own message is on standard error above)')
    end subroutine fatal

    subroutine nonfinite()
      call new_error(err, status_cutback, '', 'the UMAT returned a non-finite stress '// &
        'for particle '//int_text(noel))
    end subroutine nonfinite

  end subroutine umat_point

end module wellposed_mpm_material
