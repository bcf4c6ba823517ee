!> The width and angle of a localized band from particle values (a plate's
!> ||eps^p||, fig. 4.2 and 4.4 of the dissertation), measured normal to the
!> band: the centre line is fitted through horizontal slices, then the FWHM
!> of the plastic strain is read off the profile across that line.
!> docs/research/bands.md ("The band normal to itself") states the method and its limits:
!> one band per slice (an X of two bands crossing a slice is followed along
!> the branch holding the slice's peak), bands steeper than about 15 degrees
!> from the horizontal, a straight centre line.
module wellposed_mpm_band
  use wellposed_kinds, only: dp
  implicit none
  private
  public :: band_fit_t, fit_band, in_grown_box, line_meets_box, half_crossings

  !> A measured band.
  type :: band_fit_t
    logical :: found = .false.
    character(len=120) :: why = ''   !< why no band was measured (found = .false.)
    real(dp) :: fwhm = 0.0_dp        !< m, full width at half maximum normal to the line
    real(dp) :: angle_deg = 0.0_dp   !< the line's angle from the +x axis, in (0, 180)
    real(dp) :: x0 = 0.0_dp          !< the centre line x = x0 + slope*y (m)
    real(dp) :: slope = 0.0_dp
    real(dp) :: peak = 0.0_dp        !< the profile's peak value
    real(dp) :: rms = 0.0_dp         !< rms distance (m) of the slice centres from the line
    integer :: slices = 0            !< slices in the fit
  end type band_fit_t

contains

  !> Fit the band of the field `ep` carried by particles at `xy` (2, n),
  !> particle spacing `spacing` (m), through the slices of [ylo, yhi].
  !> 1. Slices of height ~spacing; a slice counts when its peak is at least
  !>    half the window's peak. Its centre is the ep-weighted mean position of
  !>    the contiguous run (in x) of particles at or above half the slice peak
  !>    around that peak; a run that reaches the body's edge in the slice is
  !>    left out (its centre would be biased inward).
  !> 2. x = x0 + slope*y by least squares, each slice weighted by its peak.
  !> 3. The particles of the window whose position along the line lies
  !>    within the fitted slices' span, binned by signed normal distance (bins
  !>    of spacing/4): the FWHM of the bins' mean ep around the largest bin
  !>    within max(spacing, 2 rms) of the line, half-maximum crossings
  !>    interpolated linearly between neighbouring non-empty bins.
  pure subroutine fit_band(xy, ep, spacing, ylo, yhi, fit)
    real(dp), intent(in) :: xy(:, :), ep(:), spacing, ylo, yhi
    type(band_fit_t), intent(out) :: fit
    integer :: nslice, s, ns
    real(dp) :: emax, hs, xc, yc, wsum, nrm, smin, smax
    real(dp), allocatable :: cx(:), cy(:), cw(:), sc(:)
    logical :: ok
    emax = 0.0_dp
    if (size(ep) > 0) emax = maxval(ep, mask=xy(2, :) >= ylo .and. xy(2, :) <= yhi)
    if (.not. (emax > 0.0_dp)) then
      fit%why = 'no plastic strain between the fit window''s y bounds'
      return
    end if
    nslice = max(1, nint((yhi - ylo)/spacing))
    hs = (yhi - ylo)/nslice
    allocate (cx(nslice), cy(nslice), cw(nslice))
    ns = 0
    do s = 1, nslice
      call slice_centre(xy, ep, ylo + (s - 1)*hs, ylo + s*hs, 0.5_dp*emax, xc, yc, wsum, ok)
      if (.not. ok) cycle
      ns = ns + 1
      cx(ns) = xc; cy(ns) = yc; cw(ns) = wsum
    end do
    fit%slices = ns
    if (ns < 3) then
      fit%why = 'fewer than 3 slices hold a band away from the body''s edges'
      return
    end if
    call fit_centre_line(cx(1:ns), cy(1:ns), cw(1:ns), fit)
    if (len_trim(fit%why) > 0) return
    nrm = sqrt(1.0_dp + fit%slope**2)
    ! the span of the fitted centres along the line
    sc = along(cx(1:ns), cy(1:ns), fit%x0, fit%slope, nrm)
    smin = minval(sc)
    smax = maxval(sc)
    call normal_fwhm(xy, ep, spacing, [ylo, yhi], [smin, smax], nrm, fit)
  end subroutine fit_band

  !> Step 2: x = x0 + slope*y through the slice centres (cx, cy) by least
  !> squares weighted by cw; the line's angle and the centres' rms distance.
  pure subroutine fit_centre_line(cx, cy, cw, fit)
    real(dp), intent(in) :: cx(:), cy(:), cw(:)
    type(band_fit_t), intent(inout) :: fit
    real(dp), parameter :: pi = acos(-1.0_dp)
    real(dp) :: wsum, ybar, xbar, syy, sxy, nrm
    integer :: ns
    ns = size(cx)
    wsum = sum(cw)
    ybar = sum(cw*cy)/wsum
    xbar = sum(cw*cx)/wsum
    syy = sum(cw*(cy - ybar)**2)
    sxy = sum(cw*(cy - ybar)*(cx - xbar))
    if (.not. (syy > 0.0_dp)) then
      fit%why = 'the slice centres lie at one height'
      return
    end if
    fit%slope = sxy/syy
    fit%x0 = xbar - fit%slope*ybar
    fit%angle_deg = atan2(1.0_dp, fit%slope)*180.0_dp/pi
    nrm = sqrt(1.0_dp + fit%slope**2)
    fit%rms = sqrt(sum((cx - fit%x0 - fit%slope*cy)**2)/ns)/nrm
  end subroutine fit_centre_line

  !> Position along the line x = x0 + slope*y (m) of points (x, y); nrm is
  !> sqrt(1 + slope^2).
  elemental real(dp) function along(x, y, x0, slope, nrm)
    real(dp), intent(in) :: x, y, x0, slope, nrm
    along = ((x - x0)*slope + y)/nrm
  end function along

  !> Step 1: the centre (xc, yc) and weight (its peak) of the band in the
  !> slice y0 <= y < y1; ok = .false. when the slice's peak is below `floor`
  !> or its half-maximum run reaches the body's edge.
  pure subroutine slice_centre(xy, ep, y0, y1, floor, xc, yc, w, ok)
    real(dp), intent(in) :: xy(:, :), ep(:), y0, y1, floor
    real(dp), intent(out) :: xc, yc, w
    logical, intent(out) :: ok
    integer, allocatable :: idx(:)
    integer :: m, j, k, ipk, il, ir, p
    real(dp) :: half
    xc = 0.0_dp; yc = 0.0_dp; w = 0.0_dp; ok = .false.
    idx = pack([(p, p=1, size(ep))], xy(2, :) >= y0 .and. xy(2, :) < y1)
    m = size(idx)
    if (m < 3) return
    ! sort the slice's particles by x (insertion sort: a slice is one or two rows)
    do j = 2, m
      p = idx(j)
      k = j - 1
      do while (k >= 1)
        if (xy(1, idx(k)) <= xy(1, p)) exit
        idx(k + 1) = idx(k)
        k = k - 1
      end do
      idx(k + 1) = p
    end do
    ipk = maxloc(ep(idx), dim=1)
    w = ep(idx(ipk))
    if (w < floor) return
    half = 0.5_dp*w
    il = ipk
    do while (il > 1)
      if (ep(idx(il - 1)) < half) exit
      il = il - 1
    end do
    ir = ipk
    do while (ir < m)
      if (ep(idx(ir + 1)) < half) exit
      ir = ir + 1
    end do
    if (il == 1 .or. ir == m) return
    xc = sum(ep(idx(il:ir))*xy(1, idx(il:ir)))/sum(ep(idx(il:ir)))
    yc = sum(ep(idx(il:ir))*xy(2, idx(il:ir)))/sum(ep(idx(il:ir)))
    ok = .true.
  end subroutine slice_centre

  !> Step 3: the FWHM of the binned profile across the line bf, over the
  !> particles with y in yb = [ylo, yhi] and a position along the line in
  !> span = [smin, smax].
  pure subroutine normal_fwhm(xy, ep, spacing, yb, span, nrm, bf)
    real(dp), intent(in) :: xy(:, :), ep(:), spacing, yb(2), span(2), nrm
    type(band_fit_t), intent(inout) :: bf
    real(dp), allocatable :: d(:), bsum(:), dsum(:), pd(:), pv(:)
    integer, allocatable :: bcnt(:), kb(:)
    logical, allocatable :: use(:)
    real(dp) :: bw, half, dl, dr, s_p
    integer :: p, kmin, kmax, ipk, j
    bw = 0.25_dp*spacing
    allocate (use(size(ep)), d(size(ep)))
    do p = 1, size(ep)
      s_p = along(xy(1, p), xy(2, p), bf%x0, bf%slope, nrm)
      use(p) = s_p >= span(1) .and. s_p <= span(2) .and. xy(2, p) >= yb(1) .and. &
               xy(2, p) <= yb(2)
      d(p) = (xy(1, p) - bf%x0 - bf%slope*xy(2, p))/nrm
    end do
    kb = nint(pack(d, use)/bw)
    kmin = minval(kb); kmax = maxval(kb)
    allocate (bsum(kmin:kmax), dsum(kmin:kmax), bcnt(kmin:kmax))
    bsum = 0.0_dp; dsum = 0.0_dp; bcnt = 0
    j = 0
    do p = 1, size(ep)
      if (.not. use(p)) cycle
      j = j + 1
      bsum(kb(j)) = bsum(kb(j)) + ep(p)
      dsum(kb(j)) = dsum(kb(j)) + d(p)
      bcnt(kb(j)) = bcnt(kb(j)) + 1
    end do
    pv = pack(bsum, bcnt > 0)/pack(real(bcnt, dp), bcnt > 0)
    pd = pack(dsum, bcnt > 0)/pack(real(bcnt, dp), bcnt > 0)
    ! the band's own peak: the largest bin near the line (another plastic
    ! zone further off, e.g. a loaded corner, is not the band)
    ipk = maxloc(pv, dim=1, mask=abs(pd) <= max(spacing, 2.0_dp*bf%rms))
    if (ipk == 0) then
      bf%why = 'no particle lies near the fitted centre line'
      return
    end if
    bf%peak = pv(ipk)
    half = 0.5_dp*bf%peak
    dl = -huge(1.0_dp); dr = -huge(1.0_dp)
    call half_crossings(pd, pv, ipk, half, dl, dr)
    if (dl == -huge(1.0_dp) .or. dr == -huge(1.0_dp)) then
      bf%why = 'the profile across the band does not fall to half its peak in the body'
      return
    end if
    bf%fwhm = dr - dl
    bf%found = .true.
  end subroutine normal_fwhm

  !> The crossings of `half` by the profile v(x) (x sorted) on either side of
  !> its peak at index ipk, interpolated linearly between neighbours; xl, xr
  !> are left as given where the profile does not fall below half.
  pure subroutine half_crossings(x, v, ipk, half, xl, xr)
    real(dp), intent(in) :: x(:), v(:), half
    integer, intent(in) :: ipk
    real(dp), intent(inout) :: xl, xr
    integer :: j
    do j = ipk, 2, -1
      if (v(j - 1) < half) then
        xl = x(j - 1) + (half - v(j - 1))*(x(j) - x(j - 1))/(v(j) - v(j - 1))
        exit
      end if
    end do
    do j = ipk, size(v) - 1
      if (v(j + 1) < half) then
        xr = x(j) + (v(j) - half)*(x(j + 1) - x(j))/(v(j) - v(j + 1))
        exit
      end if
    end do
  end subroutine half_crossings

  !> Whether point x (2) lies in the box lo..hi grown by `grow` on every side.
  pure logical function in_grown_box(x, lo, hi, grow)
    real(dp), intent(in) :: x(2), lo(2), hi(2), grow
    in_grown_box = all(x >= lo - grow) .and. all(x <= hi + grow)
  end function in_grown_box

  !> Whether the line x = x0 + slope y passes through the box [lo, hi] grown
  !> by `grow` on every side and clipped to the body [0, body(1)] x [0, body(2)]
  !> (a band's centre line through a weak zone: docs/research/bands.md).
  pure logical function line_meets_box(x0, slope, lo, hi, grow, body) result(meets)
    real(dp), intent(in) :: x0, slope, lo(2), hi(2), grow, body(2)
    real(dp) :: a(2), b(2), xa, xb
    a = max(lo - grow, 0.0_dp)
    b = min(hi + grow, body)
    meets = .false.
    if (any(a > b)) return
    xa = x0 + slope*a(2)
    xb = x0 + slope*b(2)
    meets = max(xa, xb) >= a(1) .and. min(xa, xb) <= b(1)
  end function line_meets_box

end module wellposed_mpm_band
