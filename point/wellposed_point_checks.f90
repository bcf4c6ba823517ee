!> The point deck against its materials, before any increment: each
!> material holds the initial state (a zero increment through the UMAT
!> contract alone comes back accepted), and a leg stress-controlled on
!> every component has a target a rate-independent, non-hardening material
!> can carry (inside its yield surface, eq. 2.3: f = sqrt(J2) + beta I1 - k).
!> Messages name the deck, the material and the leg (docs/guide/decks.md).
module wellposed_point_checks
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_deck, only: unheld_stress_note
  use wellposed_umat_host, only: umat_host_t, new_umat_host, host_call, host_error, &
                                 verdict_ok, verdict_cutback, umat_is_ours
  use wellposed_umat_layout, only: prop_h, prop_tau
  use wellposed_point_material, only: material_t, ntens
  use wellposed_point_path, only: leg_t
  implicit none
  private
  public :: check_point_materials

  !> STATEV(11) of the UMAT contract: the yield function f after the call.
  integer, parameter :: slot_f = 11
  !> f relative to |target| taken as on the surface (round-off).
  real(dp), parameter :: surface_tol = 1.0e-9_dp

contains

  !> Error when a material of deck `path` cannot hold the initial state
  !> (stress0, statev0) or cannot reach a fully stress-controlled leg target.
  subroutine check_point_materials(path, materials, stress0, statev0, legs, err)
    character(len=*), intent(in) :: path
    type(material_t), intent(in) :: materials(:)
    real(dp), intent(in) :: stress0(ntens), statev0(:)
    type(leg_t), intent(in) :: legs(:)
    type(error_t), allocatable, intent(out) :: err
    type(umat_host_t) :: h
    real(dp) :: s(ntens), zero(ntens)
    real(dp), allocatable :: sv(:)
    integer :: m, verdict
    character(len=:), allocatable :: who
    zero = 0.0_dp
    do m = 1, size(materials)
      who = path//': &material "'//materials(m)%label//'": '
      call new_umat_host(h, ntens, materials(m)%nstatv, err, what='element')
      if (allocated(err)) return
      h%dtime = 0.0_dp
      s = stress0
      sv = statev0(1:materials(m)%nstatv)
      call host_call(h, materials(m)%props, s, sv, zero, zero, verdict)
      if (verdict == verdict_cutback) then
        call new_error(err, status_invalid, 'stress', who//'the UMAT asks for a smaller step '// &
          'on a zero increment from the initial state (&initial)'//unheld_stress_note(stress0))
        return
      else if (verdict /= verdict_ok) then
        call host_error(h, verdict, err, 'a zero increment from the initial state')
        err%message = who//'the UMAT rejected its input: '//err%message
        return
      end if
      if (umat_is_ours()) call check_targets(materials(m), who)
      if (allocated(err)) return
    end do

  contains

    !> A target outside the yield surface of a material without hardening
    !> (h <= 0) nor rate dependence (tau <= 0) lies beyond what it can carry.
    subroutine check_targets(mat, who)
      type(material_t), intent(in) :: mat
      character(len=*), intent(in) :: who
      real(dp) :: props(max(size(mat%props), prop_tau, prop_h)), f
      integer :: il
      if (mat%nstatv < slot_f) return
      props = 0.0_dp                       ! PROPS not given are 0 (docs/umat.md)
      props(1:size(mat%props)) = mat%props
      if (props(prop_h) > 0.0_dp .or. props(prop_tau) > 0.0_dp) return
      ! tau > 0 with DTIME = 0: the update is the elastic trial and STATEV(11)
      ! the yield function of the stress passed in (eq. 2.10)
      props(prop_tau) = 1.0_dp
      do il = 1, size(legs)
        if (.not. all(legs(il)%stress_control)) cycle
        s = legs(il)%target
        sv = statev0(1:mat%nstatv)
        call host_call(h, props, s, sv, zero, zero, verdict)
        if (verdict /= verdict_ok) cycle
        f = sv(slot_f)
        if (f <= surface_tol*max(norm2(legs(il)%target), 1.0_dp)) cycle
        call new_error(err, status_invalid, 'target', who//'&leg (number '//int_text(il)// &
          '): the stress target lies outside the yield surface by f = sqrt(J2) + beta I1 - k '// &
          '= '//real_text(f)//' Pa (eq. 2.3), and the material neither hardens (h <= 0) nor '// &
          'relaxes (tau <= 0): no stress-controlled path reaches it; control a strain '// &
          'component there')
        return
      end do
    end subroutine check_targets

  end subroutine check_point_materials

end module wellposed_point_checks
