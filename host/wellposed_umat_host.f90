!> The one caller of a UMAT in the drivers (docs/guide/umat.md, docs/guide/hosting.md):
!> every driver reaches a material only through here, so ours and a user's
!> Abaqus UMAT are driven alike. `umat_host_t` bundles a point's arguments
!> (set up once, reused over particles); `host_call` makes one call and
!> gives its verdict; `host_update` adds the cut-back rule (halvings from
!> the saved state); `host_probe` asks the stress change of an increment.
!> Abaqus components (11, 22, 33, 12[, 13, 23]), engineering shears.
module wellposed_umat_host
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid, status_cutback
  use wellposed_finite, only: all_finite, is_finite
  use wellposed_text, only: int_text, real_text
  use wellposed_umat_interface, only: umat
  use wellposed_abaqus_job, only: abaqus_take_error
  use wellposed_step_kinematics, only: split_kinematics, small_strain_kinematics
  implicit none
  private
  public :: umat_host_t, new_umat_host, host_call, host_error, host_update, host_probe, &
            host_tangent, umat_is_ours, vumat_is_ours
  public :: verdict_ok, verdict_cutback, verdict_refused, verdict_nonfinite, max_halvings

  integer, parameter :: verdict_ok = 0         !< accepted increment
  integer, parameter :: verdict_cutback = 1    !< 0 <= PNEWDT < 1: a smaller increment may pass
  integer, parameter :: verdict_refused = 2    !< PNEWDT < 0: invalid input, the run stops
  integer, parameter :: verdict_nonfinite = 3  !< NaN/Inf in STRESS or STATEV: the run stops

  !> Deepest split of `host_update`: 2**6 = 64 sub-increments.
  integer, parameter :: max_halvings = 6

  !> The bundled UMAT arguments of one point. Inputs the driver sets; the
  !> UMAT's outputs besides STRESS and STATEV stay here after a call.
  type :: umat_host_t
    integer :: ntens = 6, ndi = 3, nshr = 3    !< 6: (3, 3) 3D; 4: (3, 1) plane strain
    integer :: nstatv = 0                      !< STATEV length the UMAT sees
    character(len=80) :: cmname = 'WELLPOSED'  !< material name
    character(len=16) :: what = 'point'        !< a point's name in messages (particle, ...)
    logical :: ours = .true.                   !< the UMAT follows wellposed's named slots
    real(dp) :: time(2) = 0.0_dp               !< step time, total time at the increment's start
    real(dp) :: dtime = 0.0_dp                 !< time increment (s)
    integer :: kstep = 1, kinc = 1             !< step and increment numbers
    integer :: noel = 1, npt = 1               !< element (particle) and integration point
    integer :: layer = 1, kspt = 1             !< shell layer and section point (1: none)
    real(dp) :: coords(3) = 0.0_dp             !< position of the point
    real(dp) :: celent = 1.0_dp                !< characteristic length (cell size)
    real(dp) :: drot(3, 3) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, &
                                      0.0_dp, 0.0_dp, 1.0_dp], [3, 3])  !< increment rotation
    real(dp) :: dfgrd0(3, 3) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, &
                                        0.0_dp, 0.0_dp, 1.0_dp], [3, 3])  !< F at the start
    real(dp) :: dfgrd1(3, 3) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, &
                                        0.0_dp, 0.0_dp, 1.0_dp], [3, 3])  !< F at the end
    !> The driver sets DFGRD0, DFGRD1 and DROT (the MPM: the particle's F);
    !> else each call passes the small-strain F = I + eps of STRAN and of
    !> STRAN + DSTRAN and DROT = I (a point, a probe of the moduli)
    logical :: kinematics_given = .false.
    real(dp) :: temp = 0.0_dp, dtemp = 0.0_dp  !< no temperature field
    real(dp) :: predef(1) = 0.0_dp, dpred(1) = 0.0_dp  !< no predefined fields
    ! written by the UMAT
    real(dp) :: ddsdde(36) = 0.0_dp            !< DDSDDE(NTENS, NTENS), column-major
    real(dp) :: sse = 0.0_dp, spd = 0.0_dp, scd = 0.0_dp  !< energies after the call
    real(dp) :: rpl = 0.0_dp, ddsddt(6) = 0.0_dp, drplde(6) = 0.0_dp, drpldt = 0.0_dp
    real(dp) :: pnewdt = 1.0_dp                !< the UMAT's time-step factor
    character(len=:), allocatable :: message   !< an STDB_ABQERR error of the last call
    real(dp), allocatable :: statev_save(:)    !< start-of-increment STATEV (cut-back)
    !> A UMAT to call instead of the linked `umat` (tests, hosts of several).
    procedure(umat), pointer, nopass :: fn => null()
  end type umat_host_t

  interface
    !> True when the linked `umat` is wellposed's (host/umat_origin.f90;
    !> a user-UMAT build links its own answer, false).
    logical function wellposed_umat_is_ours()
    end function wellposed_umat_is_ours
    !> The same for the linked `vumat` (host/vumat_origin.f90).
    logical function wellposed_vumat_is_ours()
    end function wellposed_vumat_is_ours
  end interface

contains

  !> True when the linked `umat` is wellposed's own.
  logical function umat_is_ours()
    umat_is_ours = wellposed_umat_is_ours()
  end function umat_is_ours

  !> True when the linked `vumat` is wellposed's own.
  logical function vumat_is_ours()
    vumat_is_ours = wellposed_vumat_is_ours()
  end function vumat_is_ours

  !> Set up a host for NTENS = 6 (NDI = 3, NSHR = 3) or 4 (NDI = 3,
  !> NSHR = 1) and NSTATV >= 0; `what` names a point in messages.
  subroutine new_umat_host(self, ntens, nstatv, err, cmname, what)
    type(umat_host_t), intent(out) :: self
    integer, intent(in) :: ntens, nstatv
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: cmname, what
    if (ntens /= 6 .and. ntens /= 4) then
      call new_error(err, status_invalid, 'ntens', 'NTENS = '//int_text(ntens)// &
        ' is not supported: 6 (3D) or 4 (plane strain)')
      return
    end if
    if (nstatv < 0) then
      call new_error(err, status_invalid, 'nstatv', 'NSTATV = '//int_text(nstatv)// &
        ' must be >= 0')
      return
    end if
    self%ntens = ntens
    self%nshr = ntens - 3
    self%nstatv = nstatv
    if (present(cmname)) self%cmname = cmname
    if (present(what)) self%what = what
    self%ours = umat_is_ours()
    allocate (self%statev_save(nstatv))
  end subroutine new_umat_host

  !> One UMAT call on STRESS, STATEV (updated in place) from STRAN with the
  !> increment DSTRAN over self%dtime, and the verdict on what came back.
  !> `energy` (SSE, SPD, SCD of this point) is passed in and updated when
  !> present; else zeros are passed. STRAN is not advanced here.
  subroutine host_call(self, props, stress, statev, stran, dstran, verdict, energy)
    type(umat_host_t), intent(inout) :: self
    real(dp), intent(in), contiguous :: props(:), stran(:), dstran(:)
    real(dp), intent(inout), contiguous :: stress(:), statev(:)
    integer, intent(out) :: verdict
    real(dp), intent(inout), optional :: energy(3)
    procedure(umat), pointer :: fn
    if (present(energy)) then
      self%sse = energy(1); self%spd = energy(2); self%scd = energy(3)
    else
      self%sse = 0.0_dp; self%spd = 0.0_dp; self%scd = 0.0_dp
    end if
    self%pnewdt = 1.0_dp
    if (.not. self%kinematics_given) call small_strain_kinematics(stran, dstran, self%dfgrd0, &
                                                                  self%dfgrd1, self%drot)
    fn => umat
    if (associated(self%fn)) fn => self%fn
    call fn(stress, statev, self%ddsdde, self%sse, self%spd, self%scd, self%rpl, self%ddsddt, &
            self%drplde, self%drpldt, stran, dstran, self%time, self%dtime, self%temp, &
            self%dtemp, self%predef, self%dpred, self%cmname, self%ndi, self%nshr, self%ntens, &
            self%nstatv, props, size(props), self%coords, self%drot, self%pnewdt, self%celent, &
            self%dfgrd0, self%dfgrd1, self%noel, self%npt, self%layer, self%kspt, self%kstep, &
            self%kinc)
    if (present(energy)) energy = [self%sse, self%spd, self%scd]
    call abaqus_take_error(self%message)
    if (allocated(self%message) .or. .not. is_finite(self%pnewdt) .or. &
        self%pnewdt < 0.0_dp) then
      verdict = verdict_refused
    else if (self%pnewdt < 1.0_dp) then
      verdict = verdict_cutback
    else if (.not. (all_finite(stress(1:self%ntens)) .and. &
                    all_finite(statev(1:self%nstatv)))) then
      verdict = verdict_nonfinite
    else
      verdict = verdict_ok
    end if
  end subroutine host_call

  !> DDSDDE of the last call as an NTENS x NTENS matrix.
  pure function host_tangent(self) result(c)
    type(umat_host_t), intent(in) :: self
    real(dp) :: c(self%ntens, self%ntens)
    c = reshape(self%ddsdde(1:self%ntens**2), [self%ntens, self%ntens])
  end function host_tangent

  !> The error value of a verdict other than `verdict_ok`, naming the point
  !> (self%what, self%noel) and the time; `context` is added when given
  !> (e.g. what the driver was doing).
  subroutine host_error(self, verdict, err, context)
    type(umat_host_t), intent(in) :: self
    integer, intent(in) :: verdict
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: context
    character(len=:), allocatable :: who, tail
    who = trim(self%what)//' '//int_text(self%noel)//' at time '// &
      real_text(self%time(2) + self%dtime)
    tail = ''
    if (present(context)) tail = ' ('//context//')'
    select case (verdict)
    case (verdict_refused)
      if (allocated(self%message)) then
        call new_error(err, status_invalid, 'umat', 'the UMAT stopped the run at '//who// &
          ': '//self%message//tail)
      else
        call new_error(err, status_invalid, 'umat', 'the UMAT refused the input of '//who// &
          ' (PNEWDT = '//real_text(self%pnewdt)//': invalid input; its own message is on '// &
          'standard error above)'//tail)
      end if
    case (verdict_cutback)
      call new_error(err, status_cutback, 'umat', 'the UMAT asked to cut back the '// &
        'increment of '//who//' (PNEWDT = '//real_text(self%pnewdt)//')'//tail)
    case (verdict_nonfinite)
      call new_error(err, status_invalid, 'umat', 'the UMAT returned a non-finite '// &
        'STRESS or STATEV for '//who//tail)
    case default
      call new_error(err, status_invalid, 'umat', 'unknown UMAT verdict '// &
        int_text(verdict)//' for '//who//tail)
    end select
  end subroutine host_error

  !> Advance one point by DSTRAN over self%dtime from self%time: STRESS,
  !> STATEV, STRAN (advanced by DSTRAN) in place. A cut-back request splits
  !> the increment into 2, 4, ... 2**max_halvings equal parts from the saved
  !> start state (each part its share of DFGRD0 -> DFGRD1 and that part's
  !> DROT); when the UMAT follows our slots (self%ours), each part gets
  !> the share 1/n of the nonlocal average STATEV(3) and STATEV(2) returns the
  !> sum of the parts' dlambda (Algorithm 1 sees one increment). On an error
  !> the state is left as it came in. `nsub` is the number of parts used.
  subroutine host_update(self, props, stress, statev, stran, dstran, nsub, err, energy)
    type(umat_host_t), intent(inout) :: self
    real(dp), intent(in), contiguous :: props(:), dstran(:)
    real(dp), intent(inout), contiguous :: stress(:), statev(:), stran(:)
    integer, intent(out) :: nsub
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(inout), optional :: energy(3)
    real(dp) :: s0(6), e0(6), en0(3), time0(2), dtime0, dl, avg, f0(3, 3), f1(3, 3), rot(3, 3)
    integer :: verdict, level, k, n
    n = self%ntens
    s0(1:n) = stress(1:n)
    self%statev_save = statev(1:self%nstatv)
    en0 = 0.0_dp
    if (present(energy)) en0 = energy
    nsub = 1
    call host_call(self, props, stress, statev, stran, dstran, verdict, energy)
    if (verdict == verdict_ok) then
      stran(1:n) = stran(1:n) + dstran(1:n)
      return
    end if
    if (verdict /= verdict_cutback) then
      call restore()
      call host_error(self, verdict, err)
      return
    end if
    e0(1:n) = stran(1:n)
    time0 = self%time
    dtime0 = self%dtime
    f0 = self%dfgrd0
    f1 = self%dfgrd1
    rot = self%drot
    avg = 0.0_dp
    if (self%ours .and. self%nstatv >= 3) avg = self%statev_save(3)
    levels: do level = 1, max_halvings
      nsub = 2**level
      call restore()
      stran(1:n) = e0(1:n)
      self%dtime = dtime0/nsub
      dl = 0.0_dp
      do k = 1, nsub
        self%time = time0 + dtime0*real(k - 1, dp)/nsub
        call split_kinematics(f0, f1, k, nsub, self%dfgrd0, self%dfgrd1, self%drot)
        if (self%ours .and. self%nstatv >= 3) statev(3) = avg/nsub
        call host_call(self, props, stress, statev, stran, dstran/nsub, verdict, energy)
        if (verdict == verdict_cutback) cycle levels
        if (verdict /= verdict_ok) then
          call restore()
          stran(1:n) = e0(1:n)
          call finish()
          call host_error(self, verdict, err, 'sub-increment '//int_text(k)//' of '// &
            int_text(nsub))
          return
        end if
        if (self%ours .and. self%nstatv >= 3) dl = dl + statev(2)
        stran(1:n) = stran(1:n) + dstran(1:n)/nsub
      end do
      if (self%ours .and. self%nstatv >= 3) then
        statev(2) = dl
        statev(3) = avg
      end if
      call finish()
      return
    end do levels
    call restore()
    stran(1:n) = e0(1:n)
    call finish()
    call new_error(err, status_cutback, 'umat', 'the UMAT asked to cut back the increment '// &
      'of '//trim(self%what)//' '//int_text(self%noel)//' at time '// &
      real_text(time0(2) + dtime0)//' and still did with '//int_text(2**max_halvings)// &
      ' sub-increments; a smaller time step may help')

  contains

    subroutine restore()
      stress(1:n) = s0(1:n)
      statev(1:self%nstatv) = self%statev_save
      if (present(energy)) energy = en0
    end subroutine restore

    subroutine finish()
      self%time = time0
      self%dtime = dtime0
      self%dfgrd0 = f0
      self%dfgrd1 = f1
      self%drot = rot
    end subroutine finish

  end subroutine host_update

  !> The stress change `dsig` (NTENS) of the increment DSTRAN over
  !> self%dtime from STRESS, STATEV (not changed), through `host_update`
  !> with STRAN = 0; `stress_end`, `statev_end` return the end state.
  !> DDSDDE of the (last) call is in self%ddsdde.
  subroutine host_probe(self, props, stress, statev, dstran, dsig, err, stress_end, statev_end)
    type(umat_host_t), intent(inout) :: self
    real(dp), intent(in), contiguous :: props(:), stress(:), statev(:), dstran(:)
    real(dp), intent(out) :: dsig(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(out), optional :: stress_end(:), statev_end(:)
    real(dp) :: s(self%ntens), sv(self%nstatv), e(self%ntens)
    integer :: nsub
    s = stress(1:self%ntens)
    sv = statev(1:self%nstatv)
    e = 0.0_dp
    call host_update(self, props, s, sv, e, dstran, nsub, err)
    dsig = 0.0_dp
    if (allocated(err)) return
    dsig(1:self%ntens) = s - stress(1:self%ntens)
    if (present(stress_end)) stress_end(1:self%ntens) = s
    if (present(statev_end)) statev_end(1:self%nstatv) = sv
  end subroutine host_probe

end module wellposed_umat_host
