!> Random inputs of the UMAT/VUMAT fuzz (tests/fuzz/umat_fuzz.f90): a
!> material over every PROPS slot (all models, user units from 1e-9 to 1e9,
!> moduli ratios 1e-3 to 1e3, occasionally extreme magnitudes), start
!> states (stress, every STATEV slot, strengths softened to k <= 0),
!> increments from 1e-12 to 1e3 times the yield strain in chains of
!> directions, and faults (NaN, +-Inf, huge, out of range) injected into
!> one input. random_number with a fixed seed: the same cases every run.
module fuzz_inputs
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, &
                                            ieee_negative_inf, ieee_is_finite
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: material_t, fault_t, new_material, new_state, new_increment, new_fault, &
            uniform, chance, pick, fault_value, nfault_targets, target_names

  !> A group's material: PROPS(1:15), NTENS, NSTATV, DTIME; `extreme` when
  !> a magnitude was drawn far outside any unit system's range.
  type :: material_t
    real(dp) :: props(15) = 0.0_dp
    integer :: ntens = 6, nstatv = 12
    real(dp) :: dtime = 1.0e-3_dp
    logical :: extreme = .false.
  end type material_t

  !> An injected fault: what (1 STRESS, 2 DSTRAN, 3 STATEV, 4 STRAN, 5 PROPS,
  !> 6 DTIME), which slot, the value, and `nonfinite` for NaN or +-Inf.
  type :: fault_t
    integer :: target = 0, slot = 0, point = 0
    real(dp) :: value = 0.0_dp
    logical :: nonfinite = .false.
  end type fault_t

  integer, parameter :: nfault_targets = 6
  character(len=6), parameter :: target_names(nfault_targets) = [character(len=6) :: &
    'STRESS', 'DSTRAN', 'STATEV', 'STRAN', 'PROPS', 'DTIME']

contains

  !> A uniform number in [a, b).
  real(dp) function uniform(a, b)
    real(dp), intent(in) :: a, b
    real(dp) :: r
    call random_number(r)
    uniform = a + (b - a)*r
  end function uniform

  !> True with probability p.
  logical function chance(p)
    real(dp), intent(in) :: p
    chance = uniform(0.0_dp, 1.0_dp) < p
  end function chance

  !> An integer in [lo, hi].
  integer function pick(lo, hi)
    integer, intent(in) :: lo, hi
    pick = min(hi, lo + int(uniform(0.0_dp, 1.0_dp)*(hi - lo + 1)))
  end function pick

  !> 10^u, u uniform in [a, b).
  real(dp) function decade(a, b)
    real(dp), intent(in) :: a, b
    decade = 10.0_dp**uniform(a, b)
  end function decade

  !> A material of any model: cone or cylinder, associative or not, linear
  !> hardening or softening (up to the bound), exponential eq. 2.6, EFR,
  !> Duvaut-Lions (both forms), overlocal, explicit; a few invalid ones.
  subroutine new_material(m)
    type(material_t), intent(out) :: m
    real(dp) :: unit, bulk, shear, beta, beta_p, a, n_m
    associate (pr => m%props)
    unit = 10.0_dp**pick(-9, 9)
    bulk = unit*decade(8.0_dp, 11.0_dp)
    shear = bulk*decade(-3.0_dp, 3.0_dp)
    beta = 0.0_dp
    if (chance(0.6_dp)) beta = uniform(0.0_dp, 0.6_dp)
    beta_p = 0.0_dp
    if (chance(0.35_dp)) beta_p = beta
    if (chance(0.3_dp)) beta_p = uniform(-0.1_dp, 0.6_dp)
    pr(1:5) = [bulk, shear, beta, beta_p, shear*decade(-5.0_dp, -1.0_dp)]
    n_m = sqrt(0.5_dp + 3.0_dp*beta_p**2)
    a = (shear + 9.0_dp*bulk*beta*beta_p)/n_m
    if (beta > 0.0_dp) a = min(a, 9.0_dp*bulk*beta/sqrt(3.0_dp))
    if (chance(0.3_dp)) pr(6) = shear*decade(-3.0_dp, 0.0_dp)
    if (chance(0.3_dp)) pr(6) = -a*uniform(0.0_dp, 1.0_dp)
    if (chance(0.05_dp)) pr(6) = -a*(1.0_dp - 1.0e-6_dp)
    if (chance(0.2_dp)) then
      pr(7) = pr(5)*decade(-1.0_dp, 1.0_dp)
      pr(8) = decade(-5.0_dp, -1.0_dp)
      if (pr(7) < pr(5)) pr(6) = max(pr(6), -0.5_dp*a + (pr(5) - pr(7))/pr(8))
    end if
    if (chance(0.3_dp)) then
      pr(9) = uniform(-1.0_dp, 1.0_dp)
      if (chance(0.4_dp)) pr(10) = uniform(-0.5_dp, 0.5_dp)
      if (chance(0.2_dp)) pr(9) = 0.0_dp
    end if
    m%dtime = decade(-6.0_dp, 0.0_dp)
    if (chance(0.1_dp)) m%dtime = 0.0_dp
    if (chance(0.25_dp)) pr(11) = m%dtime*decade(-3.0_dp, 3.0_dp)
    if (chance(0.15_dp)) then
      pr(12) = a*uniform(-0.9_dp, 1.0_dp)
      pr(13) = 1.0_dp
    end if
    if (chance(0.5_dp)) pr(14) = 1.0_dp
    m%ntens = merge(4, 6, chance(0.4_dp))
    m%nstatv = merge(12, 20, chance(0.5_dp))
    if (pr(11) > 0.0_dp .and. chance(0.4_dp)) then
      pr(15) = 1.0_dp
      m%nstatv = merge(19, 21, chance(0.5_dp))
    end if
    end associate
    if (chance(0.08_dp)) call extreme_material(m)
  end subroutine new_material

  !> One magnitude far out: a modulus, strength or parameter huge or tiny.
  subroutine extreme_material(m)
    type(material_t), intent(inout) :: m
    integer, parameter :: slots(11) = [1, 2, 3, 4, 5, 6, 7, 9, 10, 11, 12]
    integer :: slot
    m%extreme = .true.
    slot = slots(pick(1, 11))
    if (chance(0.5_dp)) then
      m%props(slot) = sign(decade(100.0_dp, 200.0_dp), m%props(slot))
    else
      m%props(slot) = sign(decade(-300.0_dp, -100.0_dp), m%props(slot))
    end if
    if (m%props(slot) == 0.0_dp .or. chance(0.3_dp)) m%props(slot) = decade(140.0_dp, 160.0_dp)
  end subroutine extreme_material

  !> A start state: zero, general, hydrostatic or pure shear stress
  !> around the strength; z, zeta, eps^p, <dlambda>, slot 11/12 leftovers and
  !> the generalized Duvaut-Lions slots; strengths softened to k <= 0.
  subroutine new_state(m, stress, statev, extreme)
    type(material_t), intent(in) :: m
    real(dp), intent(out) :: stress(:), statev(:)
    logical, intent(out) :: extreme
    real(dp) :: k0, h, scale
    integer :: i
    k0 = m%props(5)
    h = m%props(6)
    extreme = .false.
    scale = k0*decade(-2.0_dp, 2.0_dp)
    stress = 0.0_dp
    select case (pick(1, 5))
    case (1)
    case (2)
      do i = 1, m%ntens
        stress(i) = scale*uniform(-1.0_dp, 1.0_dp)
      end do
    case (3)
      stress(1:3) = scale*uniform(-1.0_dp, 1.0_dp)
    case (4)
      stress(4) = k0*uniform(0.5_dp, 1.5_dp)
    case default
      stress(1:3) = -scale*[1.0_dp, 0.2_dp, 0.2_dp]
    end select
    statev = 0.0_dp
    if (chance(0.5_dp)) statev(1) = decade(-6.0_dp, 0.0_dp)
    if (h < 0.0_dp .and. chance(0.3_dp)) statev(1) = k0/(-h)*uniform(0.5_dp, 3.0_dp)
    if (chance(0.2_dp)) statev(4) = k0*uniform(-3.0_dp, 1.0_dp)
    if (m%props(12) /= 0.0_dp .and. chance(0.7_dp)) statev(3) = decade(-8.0_dp, -2.0_dp)
    do i = 5, 5 + m%ntens - 1
      if (chance(0.5_dp)) statev(i) = 1.0e-3_dp*uniform(-1.0_dp, 1.0_dp)
    end do
    if (chance(0.3_dp)) statev(11) = k0*uniform(-1.0_dp, 1.0_dp)
    if (chance(0.3_dp)) statev(12) = real(pick(-2, 2), dp)
    if (m%props(15) == 1.0_dp .and. chance(0.6_dp)) then
      do i = 13, 13 + m%ntens - 1
        statev(i) = k0*uniform(-0.5_dp, 0.5_dp)
      end do
      if (m%ntens == 4) statev(17:18) = 0.0_dp
      statev(19) = -decade(-6.0_dp, 1.0_dp)
    end if
    do i = 20, size(statev)
      statev(i) = uniform(-1.0_dp, 1.0_dp)
    end do
    if (chance(0.03_dp)) then
      extreme = .true.
      stress(1:m%ntens) = stress(1:m%ntens) + decade(140.0_dp, 200.0_dp)*uniform(-1.0_dp, 1.0_dp)
    end if
  end subroutine new_state

  !> The next increment of a chain (engineering shears, NTENS components):
  !> zero, hydrostatic, pure shear, uniaxial or random, repeated or
  !> reversed from `last`, 1e-12 to 1e3 times the yield strain k0/G.
  subroutine new_increment(m, last, de, extreme)
    type(material_t), intent(in) :: m
    real(dp), intent(inout) :: last(:)
    real(dp), intent(out) :: de(:)
    logical, intent(out) :: extreme
    real(dp) :: amp, d(6)
    integer :: i
    extreme = .false.
    amp = abs(m%props(5)/m%props(2))*decade(-12.0_dp, 3.0_dp)
    d = 0.0_dp
    select case (pick(1, 8))
    case (1)
    case (2)
      d(1:3) = sign(1.0_dp, uniform(-1.0_dp, 1.0_dp))
    case (3)
      d(4) = 1.0_dp
    case (4)
      d(1) = sign(1.0_dp, uniform(-1.0_dp, 1.0_dp))
    case (5, 6)
      d = last
    case (7)
      d = -last
    case default
      do i = 1, m%ntens
        d(i) = uniform(-1.0_dp, 1.0_dp)
      end do
    end select
    if (m%ntens == 4) d(5:6) = 0.0_dp
    last = d
    if (chance(0.02_dp)) then
      extreme = .true.
      amp = decade(100.0_dp, 200.0_dp)
    end if
    de = amp*d(1:size(de))
  end subroutine new_increment

  !> A fault for a group of npoints points of material m: target, slot,
  !> point and value (NaN, +-Inf, huge, beyond sqrt(huge), negative, 0).
  subroutine new_fault(m, npoints, fault)
    type(material_t), intent(in) :: m
    integer, intent(in) :: npoints
    type(fault_t), intent(out) :: fault
    fault%target = pick(1, nfault_targets)
    fault%point = pick(1, npoints)
    select case (fault%target)
    case (1, 2, 4)
      fault%slot = pick(1, m%ntens)
    case (3)
      fault%slot = pick(1, m%nstatv)
    case (5)
      fault%slot = pick(1, 15)
    case default
      fault%slot = 1
    end select
    fault%value = fault_value(pick(1, 7))
    fault%nonfinite = .not. ieee_is_finite(fault%value)
  end subroutine new_fault

  !> Fault value of class c: NaN, +Inf, -Inf, +-1e300, +-1e160, -1, 0.
  function fault_value(c) result(v)
    integer, intent(in) :: c
    real(dp) :: v
    select case (c)
    case (1); v = ieee_value(v, ieee_quiet_nan)
    case (2); v = ieee_value(v, ieee_positive_inf)
    case (3); v = ieee_value(v, ieee_negative_inf)
    case (4); v = sign(1.0e300_dp, uniform(-1.0_dp, 1.0_dp))
    case (5); v = sign(1.0e160_dp, uniform(-1.0_dp, 1.0_dp))
    case (6); v = -1.0_dp
    case default; v = 0.0_dp
    end select
  end function fault_value

end module fuzz_inputs
