!> The materials of an MPM scene by region: each material's PROPS, NSTATV,
!> interface (the VUMAT on blocks, or the UMAT per particle), whether that
!> routine is ours (PROPS slots of docs/guide/umat.md), whether it follows
!> the nonlocal contract (STATEV 2 out, 3 in), and its region: a box (x, and
!> y in 2D) or "rest" (every particle no box holds). A particle takes the
!> material of the first box, in deck order, holding its initial centre
!> (bounds included), else the rest's; boxes may touch but not overlap
!> (docs/guide/decks.md, docs/guide/mpm.md).
module wellposed_mpm_materials
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  implicit none
  private
  public :: mpm_materials_t, max_materials, max_material_props, min_nstatv, least_nstatv, &
            nstatv_why
  public :: add_material, material_of, check_regions, check_covered, single_material, &
            scale_regions, materials_nstatv, occurrence, first_material

  integer, parameter :: max_materials = 8        !< &material groups per deck
  integer, parameter :: max_material_props = 40  !< PROPS per material
  !> NSTATV our model needs (docs/guide/umat.md), and a UMAT following the
  !> nonlocal contract (STATEV 2/3); a user's UMAT needs 1 or more and the
  !> outputs reading our slots are left out where it has fewer
  integer, parameter :: min_nstatv = 12

  !> The materials of one scene (n = 0: not given; see single_material).
  type :: mpm_materials_t
    character(len=:), allocatable :: deck          !< the deck, for messages
    integer :: n = 0
    integer :: ndim = 1                            !< region dimensions (1 bar, 2 plate)
    integer :: nprops(max_materials) = 0
    real(dp) :: props(max_material_props, max_materials) = 0.0_dp
    integer :: nstatv(max_materials) = 0
    logical :: vumat(max_materials) = .false.      !< called through the VUMAT, on blocks
    logical :: ours(max_materials) = .false.       !< the linked UMAT (VUMAT) is wellposed's
    logical :: contract(max_materials) = .false.   !< STATEV 2/3 of Algorithm 1
    logical :: rest(max_materials) = .false.       !< region "rest"
    real(dp) :: lo(2, max_materials) = 0.0_dp      !< box lower corner (m)
    real(dp) :: hi(2, max_materials) = 0.0_dp      !< box upper corner (m)
  end type mpm_materials_t

contains

  !> "&material" or "&material (occurrence k)" of the deck, for messages.
  pure function occurrence(self, k) result(s)
    type(mpm_materials_t), intent(in) :: self
    integer, intent(in) :: k
    character(len=:), allocatable :: s
    s = '&material'
    if (self%n > 1) s = s//' (occurrence '//int_text(k)//')'
    if (allocated(self%deck)) s = self%deck//': '//s
  end function occurrence

  !> Append a material: PROPS, NSTATV, ours, contract, and its region (a box
  !> lo(1:ndim) .. hi(1:ndim), or the rest when lo and hi are absent);
  !> through the VUMAT when `vumat` is true (else the UMAT). Errors name the
  !> occurrence and the key.
  subroutine add_material(self, props, nstatv, ours, contract, err, lo, hi, vumat)
    type(mpm_materials_t), intent(inout) :: self
    real(dp), intent(in) :: props(:)
    integer, intent(in) :: nstatv
    logical, intent(in) :: ours, contract
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: lo(:), hi(:)
    logical, intent(in), optional :: vumat
    integer :: k
    if (self%n >= max_materials) then
      call new_error(err, status_invalid, 'material', occurrence(self, self%n + 1)// &
        ': at most '//int_text(max_materials)//' &material groups'); return
    end if
    self%n = self%n + 1
    k = self%n
    if (size(props) < 1 .or. size(props) > max_material_props) then
      call new_error(err, status_invalid, 'props', occurrence(self, k)//': props: '// &
        int_text(size(props))//' entries; give 1 ... '//int_text(max_material_props)); return
    end if
    if (nstatv < least_nstatv(ours, contract)) then
      call new_error(err, status_invalid, 'nstatv', occurrence(self, k)//': nstatv = '// &
        int_text(nstatv)//' is below '//int_text(least_nstatv(ours, contract))// &
        nstatv_why(ours .or. contract)); return
    end if
    self%nprops(k) = size(props)
    self%props(:, k) = 0.0_dp
    self%props(1:size(props), k) = props
    self%nstatv(k) = nstatv
    self%ours(k) = ours
    self%vumat(k) = .false.
    if (present(vumat)) self%vumat(k) = vumat
    self%contract(k) = ours .or. contract
    self%rest(k) = .not. (present(lo) .and. present(hi))
    if (self%rest(k)) return
    self%lo(:, k) = 0.0_dp
    self%hi(:, k) = 0.0_dp
    self%lo(1:self%ndim, k) = lo(1:self%ndim)
    self%hi(1:self%ndim, k) = hi(1:self%ndim)
    if (.not. all(self%lo(1:self%ndim, k) < self%hi(1:self%ndim, k))) then
      call new_error(err, status_invalid, 'x', occurrence(self, k)//': the box '// &
        box_text(self, k)//' must have lower < upper bounds, each finite'); return
    end if
  end subroutine add_material

  !> The set's checks once every material is in: one "rest" at most, and no
  !> two boxes overlapping (sharing more than a face).
  subroutine check_regions(self, err)
    type(mpm_materials_t), intent(in) :: self
    type(error_t), allocatable, intent(out) :: err
    integer :: k, j
    do k = 1, self%n
      do j = 1, k - 1
        if (self%rest(k) .and. self%rest(j)) then
          call new_error(err, status_invalid, 'region', occurrence(self, k)// &
            ': region: a second "rest" (occurrence '//int_text(j)//' is one); give '// &
            'every material but one a box'); return
        end if
        if (self%rest(k) .or. self%rest(j)) cycle
        if (all(max(self%lo(1:self%ndim, k), self%lo(1:self%ndim, j)) < &
                min(self%hi(1:self%ndim, k), self%hi(1:self%ndim, j)))) then
          call new_error(err, status_invalid, 'x', occurrence(self, k)//': the box '// &
            box_text(self, k)//' overlaps the box '//box_text(self, j)//' of occurrence '// &
            int_text(j)); return
        end if
      end do
    end do
  end subroutine check_regions

  !> Material of a particle whose initial centre is x(1:ndim): the first
  !> box holding it, else the rest, else 0 (not covered).
  pure integer function material_of(self, x) result(k)
    type(mpm_materials_t), intent(in) :: self
    real(dp), intent(in) :: x(:)
    integer :: r
    r = 0
    do k = 1, self%n
      if (self%rest(k)) then
        if (r == 0) r = k
        cycle
      end if
      if (all(x(1:self%ndim) >= self%lo(1:self%ndim, k) .and. &
              x(1:self%ndim) <= self%hi(1:self%ndim, k))) return
    end do
    k = r
  end function material_of

  !> Error naming the first particle centre (columns of x) no region holds
  !> (the scene's runner adds the deck).
  subroutine check_covered(self, x, err)
    type(mpm_materials_t), intent(in) :: self
    real(dp), intent(in) :: x(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer :: p, d
    character(len=:), allocatable :: at
    do p = 1, size(x, 2)
      if (material_of(self, x(:, p)) /= 0) cycle
      at = real_text(x(1, p))
      do d = 2, self%ndim
        at = at//', '//real_text(x(d, p))
      end do
      call new_error(err, status_invalid, 'region', '&material: region: the particle at ('// &
        at//') m lies in no &material box and no group has region = ''rest'''); return
    end do
  end subroutine check_covered

  !> A set of one material filling the scene, from a config's PROPS when
  !> `given` holds none (configs built in code; ours through the VUMAT);
  !> else `given`.
  function single_material(given, props, nstatv, ndim, ours) result(m)
    type(mpm_materials_t), intent(in) :: given
    real(dp), intent(in) :: props(:)
    integer, intent(in) :: nstatv, ndim
    logical, intent(in) :: ours
    type(mpm_materials_t) :: m
    type(error_t), allocatable :: err
    m = given
    if (m%n > 0) return
    m%ndim = ndim
    call add_material(m, props, max(nstatv, least_nstatv(ours, .false.)), ours, .false., err, &
                      vumat=ours)
  end function single_material

  !> Least NSTATV of a material: our model's (min_nstatv) where the UMAT is
  !> ours or follows the nonlocal contract (STATEV 2/3), else 1.
  pure integer function least_nstatv(ours, contract) result(n)
    logical, intent(in) :: ours, contract
    n = merge(min_nstatv, 1, ours .or. contract)
  end function least_nstatv

  !> Why a material's NSTATV is too short (ours_or_contract: as above).
  pure function nstatv_why(ours_or_contract) result(s)
    logical, intent(in) :: ours_or_contract
    character(len=:), allocatable :: s
    if (ours_or_contract) then
      s = ', what our model needs (docs/guide/umat.md) and the nonlocal contract''s STATEV 2/3 read'
    else
      s = ' (a UMAT''s STATEV has at least one entry)'
    end if
  end function nstatv_why

  !> Every box scaled by f about the origin (a plate scaled for fig. 4.6).
  pure subroutine scale_regions(self, f)
    type(mpm_materials_t), intent(inout) :: self
    real(dp), intent(in) :: f
    self%lo = self%lo*f
    self%hi = self%hi*f
  end subroutine scale_regions

  !> NSTATV of the scene: the largest of the materials' (one STATEV length
  !> for every particle; each UMAT is passed that length).
  pure integer function materials_nstatv(self) result(n)
    type(mpm_materials_t), intent(in) :: self
    n = maxval(self%nstatv(1:max(self%n, 1)))
  end function materials_nstatv

  !> A config's one-material fields from the set: the first material's
  !> PROPS (zero past NPROPS) and the scene's NSTATV (the largest).
  pure subroutine first_material(self, props, nprops, nstatv)
    type(mpm_materials_t), intent(in) :: self
    real(dp), intent(out) :: props(:)
    integer, intent(out) :: nprops, nstatv
    props = 0.0_dp
    nprops = self%nprops(1)
    props(1:nprops) = self%props(1:nprops, 1)
    nstatv = materials_nstatv(self)
  end subroutine first_material

  pure function box_text(self, k) result(s)
    type(mpm_materials_t), intent(in) :: self
    integer, intent(in) :: k
    character(len=:), allocatable :: s
    s = 'x = '//real_text(self%lo(1, k))//', '//real_text(self%hi(1, k))
    if (self%ndim == 2) s = s//'; y = '//real_text(self%lo(2, k))//', '// &
                            real_text(self%hi(2, k))
  end function box_text

end module wellposed_mpm_materials
