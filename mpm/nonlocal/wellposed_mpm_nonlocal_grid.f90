!> The grid-based nonlocal average of section 4.5 for the MPM, 1D and 2D:
!>   dlambda_i   = sum_p phi_ip m_p dlambda_p / m_i             (eq. 4.46)
!>   <dlambda>_p = sum_i alpha(x_p - x_i) m_i dlambda_i / M_p   (eq. 4.47)
!>   M_p         = sum_i alpha(x_p - x_i) m_i                   (eq. 4.48)
!> alpha the Gaussian of eq. 4.27, cut below weight_cutoff. Massless nodes
!> drop out of both sums, so a uniform field averages to itself; the
!> Gaussian factorises on the uniform grid. State: wellposed_mpm_nonlocal_state.
module wellposed_mpm_nonlocal_grid
  use wellposed_kinds, only: dp
  use wellposed_nonlocal, only: nonlocal_weight
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  implicit none
  private
  public :: nonlocal_project, add_projection, nonlocal_average, row_prefix, &
            disk_mass, cached_average, &
            field_extents, extend_extents, field_reaches

contains

  !> Node mass and the nodal field of eq. 4.46 from particle values:
  !> m_i = sum_p phi_ip m_p and field_i = m_i dlambda_i = sum_p phi_ip m_p
  !> values_p. node(k, p) are global node numbers inside [glo, ghi]; the
  !> particles in storage order, or in `order` when given.
  pure subroutine nonlocal_project(self, mass, node, phi, values, order)
    type(nonlocal_t), intent(inout) :: self
    real(dp), intent(in) :: mass(:), phi(:, :), values(:)
    integer, intent(in) :: node(:, :)
    integer, intent(in), optional :: order(:)
    self%node_mass = 0.0_dp
    self%field = 0.0_dp
    call add_projection(self, mass, node, phi, values, order)
  end subroutine nonlocal_project

  !> nonlocal_project's sums added to the node mass and field they find
  !> (the pipeline across ranks starts from the lower rank's).
  pure subroutine add_projection(self, mass, node, phi, values, order)
    type(nonlocal_t), intent(inout) :: self
    real(dp), intent(in) :: mass(:), phi(:, :), values(:)
    integer, intent(in) :: node(:, :)
    integer, intent(in), optional :: order(:)
    integer :: q, p, k, i
    real(dp) :: w
    do q = 1, size(mass)
      p = q
      if (present(order)) p = order(q)
      do k = 1, size(node, 1)
        i = node(k, p)
        w = phi(k, p)*mass(p)
        self%node_mass(i) = self%node_mass(i) + w
        self%field(i) = self%field(i) + w*values(p)
      end do
    end do
  end subroutine add_projection

  !> <dlambda> at position xp (m) from the nodal field, eq. 4.47-4.48.
  !> Zero where no node with mass lies in the support.
  pure subroutine nonlocal_average(self, xp, avg)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    real(dp), intent(out) :: avg
    integer, parameter :: rmax = 256
    real(dp) :: ax(-rmax:rmax), ay(-rmax:rmax), num, den, rowm, rowf
    integer :: lo(2), hi(2), i, j, g
    call box(self, xp, lo, hi)
    num = 0.0_dp
    den = 0.0_dp
    do i = lo(1), hi(1)
      ax(i - lo(1)) = nonlocal_weight(xp(1) - (self%origin(1) + self%dx*i), self%length)
    end do
    if (self%ndim == 1) then
      do i = max(lo(1), self%glo), min(hi(1), self%ghi)
        num = num + ax(i - lo(1))*self%field(i)
        den = den + ax(i - lo(1))*self%node_mass(i)
      end do
    else
      do j = lo(2), hi(2)
        ay(j - lo(2)) = nonlocal_weight(xp(2) - (self%origin(2) + self%dx*j), self%length)
      end do
      do j = lo(2), hi(2)
        rowm = 0.0_dp
        rowf = 0.0_dp
        do i = lo(1), hi(1)
          g = i + self%nnode(1)*j
          if (g < self%glo .or. g > self%ghi) cycle
          rowm = rowm + ax(i - lo(1))*self%node_mass(g)
          rowf = rowf + ax(i - lo(1))*self%field(g)
        end do
        num = num + ay(j - lo(2))*rowf
        den = den + ay(j - lo(2))*rowm
      end do
    end if
    avg = 0.0_dp
    if (den > 0.0_dp) avg = num/den
  end subroutine nonlocal_average

  !> prefix(g): the node masses of g's grid row on this patch up to g.
  pure subroutine row_prefix(self, prefix)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(out) :: prefix(self%glo:)
    integer :: g
    prefix(self%glo) = self%node_mass(self%glo)
    do g = self%glo + 1, self%ghi
      prefix(g) = self%node_mass(g)
      if (self%ndim == 1 .or. mod(g, self%nnode(1)) /= 0) prefix(g) = prefix(g) + prefix(g - 1)
    end do
  end subroutine row_prefix

  !> The node mass within the support radius of xp (kg): the dissertation's
  !> N_alpha times the particle mass (eq. 4.43), from row_prefix's sums: per
  !> row the run of nodes within the radius (found by the distance test
  !> itself), a difference of prefixes: 2R+1 rows a point, not (2R+1)^2 nodes.
  pure real(dp) function disk_mass(self, prefix, xp) result(smass)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: prefix(self%glo:), xp(:)
    integer :: lo(2), hi(2), j, a, b, ga, gb, row0
    real(dp) :: dy2, c, h
    call box(self, xp, lo, hi)
    smass = 0.0_dp
    do j = lo(2), hi(2)
      dy2 = 0.0_dp
      if (self%ndim == 2) dy2 = (xp(2) - (self%origin(2) + self%dx*j))**2
      if (dy2 > self%radius**2) cycle
      c = (xp(1) - self%origin(1))/self%dx
      h = sqrt(self%radius**2 - dy2)/self%dx
      a = max(lo(1), min(hi(1) + 1, ceiling(c - h)))
      b = min(hi(1), max(lo(1) - 1, floor(c + h)))
      do while (a <= b .and. .not. inside(a))
        a = a + 1
      end do
      do while (a > lo(1) .and. inside(a - 1))
        a = a - 1
      end do
      do while (b >= a .and. .not. inside(b))
        b = b - 1
      end do
      do while (b < hi(1) .and. inside(b + 1))
        b = b + 1
      end do
      row0 = 0
      if (self%ndim == 2) row0 = self%nnode(1)*j
      ga = max(a + row0, self%glo)
      gb = min(b + row0, self%ghi)
      if (ga > gb) cycle
      smass = smass + (prefix(gb) - prefix(ga)) + self%node_mass(ga)
    end do

  contains

    !> node i of row j within the radius of xp (the distance test)
    pure logical function inside(i)
      integer, intent(in) :: i
      if (self%ndim == 1) then
        inside = abs(xp(1) - (self%origin(1) + self%dx*i)) <= self%radius
      else
        inside = (xp(1) - (self%origin(1) + self%dx*i))**2 + dy2 <= self%radius**2
      end if
    end function inside
  end function disk_mass

  !> <dlambda> of particle p at xp within a solve: its separable weights and
  !> M_p (eq. 4.48) are computed at the first call of the step and kept, so a
  !> sweep costs (2R+1)^ndim multiply-adds per particle and no exponential.
  subroutine cached_average(self, p, xp, avg)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: p
    real(dp), intent(in) :: xp(:)
    real(dp), intent(out) :: avg
    integer :: lo(2), hi(2), i, j
    if (.not. self%cached(p)) then
      call box(self, xp, lo, hi)
      hi = min(hi, lo + self%nbmax - 1)
      self%blo(:, p) = lo
      self%bhi(:, p) = hi
      do i = lo(1), hi(1)
        self%wx(i - lo(1) + 1, p) = nonlocal_weight(xp(1) - (self%origin(1) + self%dx*i), &
                                                    self%length)
      end do
      if (self%ndim == 2) then
        do j = lo(2), hi(2)
          self%wy(j - lo(2) + 1, p) = nonlocal_weight(xp(2) - (self%origin(2) + self%dx*j), &
                                                      self%length)
        end do
      end if
      self%den(p) = weighted_sum(self, self%node_mass, p)
      self%cached(p) = .true.
    end if
    avg = 0.0_dp
    if (.not. self%den(p) > 0.0_dp) return
    avg = weighted_sum(self, self%field, p)/self%den(p)
  end subroutine cached_average

  !> sum_i alpha(x_p - x_i) v_i over particle p's cached box (the sums of
  !> eq. 4.47-4.48), nodes outside this rank's patch [glo, ghi] left out.
  pure real(dp) function weighted_sum(self, v, p) result(total)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: v(self%glo:)
    integer, intent(in) :: p
    integer :: lo(2), hi(2), i, j, g, nb, nx
    real(dp) :: row
    lo = self%blo(:, p)
    hi = self%bhi(:, p)
    total = 0.0_dp
    if (self%ndim == 1) then
      do i = max(lo(1), self%glo), min(hi(1), self%ghi)
        total = total + self%wx(i - lo(1) + 1, p)*v(i)
      end do
      return
    end if
    nb = hi(1) - lo(1) + 1
    nx = self%nnode(1)
    g = lo(1) + nx*lo(2)
    if (g >= self%glo .and. lo(1) + nx*hi(2) + nb - 1 <= self%ghi) then
      ! the whole box on this rank's patch: plain loops
      total = box_sum(v(g:), nx, nb, hi(2) - lo(2) + 1, self%wx(:, p), self%wy(:, p))
      return
    end if
    do j = lo(2), hi(2)
      row = 0.0_dp
      do i = lo(1), hi(1)
        g = i + nx*j
        if (g >= self%glo .and. g <= self%ghi) row = row + self%wx(i - lo(1) + 1, p)*v(g)
      end do
      total = total + self%wy(j - lo(2) + 1, p)*row
    end do
  end function weighted_sum

  !> sum_i wx(i) sum_j wy(j) f(i, j) over nb x ny nodes of rows nx apart
  !> (cached_average's box): the rows are added into one column sum, a loop
  !> without a carried dependence that the compiler vectorises, then one dot
  !> product (a sum along each row would wait on every addition).
  pure function box_sum(f, nx, nb, ny, wx, wy) result(num)
    integer, intent(in) :: nx, nb, ny
    real(dp), intent(in) :: f(nx, *), wx(nb), wy(ny)
    real(dp) :: num, col(nb)
    integer :: i, j
    col = 0.0_dp
    do j = 1, ny
      do i = 1, nb
        col(i) = col(i) + wy(j)*f(i, j)
      end do
    end do
    num = 0.0_dp
    do i = 1, nb
      num = num + wx(i)*col(i)
    end do
  end function box_sum

  !> The row extents of the nonzero `field` nodes of the patch.
  subroutine field_extents(self)
    type(nonlocal_t), intent(inout) :: self
    integer :: g
    self%row_lo = huge(1)
    self%row_hi = -1
    do g = self%glo, self%ghi
      if (self%field(g) /= 0.0_dp) call extend_extents(self, [g])
    end do
  end subroutine field_extents

  !> The nodes g(:) may now hold a nonzero field.
  pure subroutine extend_extents(self, g)
    type(nonlocal_t), intent(inout) :: self
    integer, intent(in) :: g(:)
    integer :: i, j, k
    do k = 1, size(g)
      i = g(k)
      j = 0
      if (self%ndim == 2) then
        i = mod(g(k), self%nnode(1))
        j = g(k)/self%nnode(1)
      end if
      self%row_lo(j) = min(self%row_lo(j), i)
      self%row_hi(j) = max(self%row_hi(j), i)
    end do
  end subroutine extend_extents

  !> Whether the Gaussian's support of a particle at xp covers a node of
  !> nonzero field: if not, its average is exactly 0 (eq. 4.47).
  pure logical function field_reaches(self, xp) result(reaches)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    integer :: lo(2), hi(2), j
    call box(self, xp, lo, hi)
    reaches = .true.
    do j = lo(2), hi(2)
      if (self%row_lo(j) <= hi(1) .and. self%row_hi(j) >= lo(1)) return
    end do
    reaches = .false.
  end function field_reaches

  !> Node index box [lo, hi] per direction covering the cut Gaussian at xp.
  pure subroutine box(self, xp, lo, hi)
    type(nonlocal_t), intent(in) :: self
    real(dp), intent(in) :: xp(:)
    integer, intent(out) :: lo(2), hi(2)
    integer :: d
    lo = 0
    hi = 0
    do d = 1, self%ndim
      lo(d) = max(0, ceiling((xp(d) - self%radius - self%origin(d))/self%dx))
      hi(d) = min(self%nnode(d) - 1, floor((xp(d) + self%radius - self%origin(d))/self%dx))
      ! at most 2*256 + 1 nodes per direction (the radius is L*sqrt(-ln cutoff)/k)
      hi(d) = min(hi(d), lo(d) + 512)
    end do
  end subroutine box

end module wellposed_mpm_nonlocal_grid
