!> Where a plate's band starts and how wide it is at an equal post-peak
!> stage (docs/research/bands.md, "Where bands start", "The band normal to itself"),
!> watched step by step: the onset (the first particle past &output
!> band_onset_strain, and whether it is in the weak zone); the stage (the
!> apparent stress band_drop below its peak), where the band is fitted
!> normal to itself in the middle 60 % of the height; and the platen's
!> layer stress after the last step (docs/research/bands.md, "The platen").
!> Collective: every rank calls `step` each step with the same curve.
module wellposed_mpm_plate_band_watch
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: real_text
  use wellposed_mpi, only: comm_t, allreduce_max, allreduce_sum
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_mpm_solver, only: mpm_scene_t, plastic_strain
  use wellposed_mpm_plate_kind, only: platen_base, plate_config
  use wellposed_mpm_plate_config, only: plate_config_t
  use wellposed_mpm_decomposition, only: gather_by_gid
  use wellposed_mpm_band, only: band_fit_t, fit_band, in_grown_box, line_meets_box
  implicit none
  private
  public :: band_watch_t, new_band_watch

  !> The fit window: this fraction of the height off the bottom and the top
  !> (the weak corner and the platen's boundary layer lie outside it).
  real(dp), parameter :: window_margin = 0.2_dp

  type :: band_watch_t
    real(dp) :: drop = 0.05_dp, threshold = 1.0e-3_dp
    logical :: has_weak = .false.
    real(dp) :: weak_lo(2) = 0.0_dp, weak_hi(2) = 0.0_dp, grow = 0.0_dp
    real(dp) :: body(2) = 0.0_dp     !< the plate's width and height (m)
    logical :: onset = .false.
    real(dp) :: onset_t = 0.0_dp, onset_x(2) = 0.0_dp, onset_ep = 0.0_dp
    real(dp) :: peak = -huge(1.0_dp)
    logical :: staged = .false.
    logical :: just_staged = .false. !< the stage was reached in the last step (snapshot it)
    real(dp) :: stage(3) = 0.0_dp     !< the stage's (time, apparent strain, stress)
    type(band_fit_t) :: fit
    real(dp) :: top_ratio = 0.0_dp   !< top row's mean sigma_yy / mid-height row's, now
  contains
    procedure :: step => watch_step
    procedure :: summarise => watch_summarise
    procedure :: put => watch_put
    procedure :: get => watch_get
  end type band_watch_t

contains

  !> A watch for the case of scene sc: drop and threshold from &output.
  function new_band_watch(sc, drop, threshold) result(w)
    type(mpm_scene_t), intent(in) :: sc
    real(dp), intent(in) :: drop, threshold
    type(band_watch_t) :: w
    integer :: k, nbox
    type(plate_config_t) :: plate
    plate = plate_config(sc)
    w%drop = drop
    w%threshold = threshold
    w%grow = sc%dx
    w%body = [plate%width, plate%height]
    nbox = 0
    do k = 1, sc%mats%n
      if (sc%mats%rest(k)) cycle
      nbox = nbox + 1
      w%weak_lo = sc%mats%lo(:, k)
      w%weak_hi = sc%mats%hi(:, k)
    end do
    w%has_weak = nbox == 1
  end function new_band_watch

  !> After each step: the onset, then the stage on the curve so far (time,
  !> strain, stress per sample); at the stage the band is measured.
  subroutine watch_step(self, sc, comm, curve)
    class(band_watch_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(in) :: comm
    real(dp), intent(in) :: curve(:, :)
    real(dp), allocatable :: ep(:)
    real(dp) :: emax, x, y
    integer :: p, nc
    call top_row_ratio(self, sc, comm)
    self%just_staged = .false.
    if (self%staged) return
    nc = size(curve, 2)
    if (nc > 0) self%peak = max(self%peak, curve(3, nc))
    if (.not. self%onset) then
      ep = plastic_strain(sc)
      emax = -1.0_dp; x = -huge(1.0_dp); y = -huge(1.0_dp)
      if (size(ep) > 0) then
        p = maxloc(ep, dim=1)
        emax = ep(p)
      end if
      if (comm%size > 1) call allreduce_max(comm, emax)
      if (emax <= self%threshold) return
      if (size(ep) > 0) then
        p = maxloc(ep, dim=1)
        if (ep(p) == emax) then
          x = sc%parts%x(1, p); y = sc%parts%x(2, p)
        end if
      end if
      if (comm%size > 1) call allreduce_max(comm, x)
      if (comm%size > 1) call allreduce_max(comm, y)
      self%onset = .true.
      self%onset_t = sc%t
      self%onset_x = [x, y]
      self%onset_ep = emax
    end if
    if (nc < 1) return
    if (curve(3, nc) > (1.0_dp - self%drop)*self%peak) return
    self%staged = .true.
    self%just_staged = .true.
    self%stage = curve(:, nc)
    call measure(self, sc, comm)
  end subroutine watch_step

  !> The mean sigma_yy of the particles in the cell row under the platen's
  !> lowest node row, or its plane with platen = 'contact' (by their
  !> centres now), over that of the particle row(s) within lp of mid-height
  !> (by their initial centres), now.
  subroutine top_row_ratio(self, sc, comm)
    type(band_watch_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(in) :: comm
    real(dp) :: a(4), lp, yg, y
    integer :: p
    type(plate_config_t) :: plate
    plate = plate_config(sc)
    lp = 0.5_dp*sc%dx/plate%ppc
    yg = platen_base(sc)
    a = 0.0_dp
    do p = 1, sc%parts%n
      y = sc%parts%x(2, p)
      if (y < yg .and. y > yg - sc%dx) a(1:2) = a(1:2) + [sc%parts%stress(2, p), 1.0_dp]
      y = sc%parts%x0(2, p)
      if (abs(y - 0.5_dp*plate%height) < 1.0001_dp*lp) &
        a(3:4) = a(3:4) + [sc%parts%stress(2, p), 1.0_dp]
    end do
    if (comm%size > 1) call allreduce_sum(comm, a)
    self%top_ratio = 0.0_dp
    if (a(2) > 0.0_dp .and. a(4) > 0.0_dp .and. a(3) /= 0.0_dp) &
      self%top_ratio = (a(1)/a(2))/(a(3)/a(4))
  end subroutine top_row_ratio

  !> The band now (rank 0 gathers the particles and fits).
  subroutine measure(self, sc, comm)
    type(band_watch_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(in) :: comm
    real(dp), allocatable :: f(:, :), all(:, :)
    integer :: n
    type(plate_config_t) :: plate
    plate = plate_config(sc)
    n = sc%parts%n
    allocate (f(3, n))
    f(1:2, :) = sc%parts%x(:, 1:n)
    f(3, :) = plastic_strain(sc)
    call gather_by_gid(comm, sc%parts%gid(1:n), f, 0, all)
    if (comm%rank /= 0) return
    call fit_band(all(1:2, :), all(3, :), sc%dx/plate%ppc, &
                  window_margin*plate%height, (1.0_dp - window_margin)*plate%height, self%fit)
  end subroutine measure

  !> The case's summary lines under `tag.` (rank 0).
  !> `no_slot`: why the band measures are not applicable (no plastic strain
  !> slot in the STATEV), instead of the watch's own reasons.
  subroutine watch_summarise(self, sm, tag, no_slot)
    class(band_watch_t), intent(in) :: self
    type(summary_t), intent(inout) :: sm
    character(len=*), intent(in) :: tag
    character(len=*), intent(in), optional :: no_slot
    character(len=:), allocatable :: why
    call sm%add(tag//'.band_onset_strain', self%threshold, &
                '||eps^p|| whose first crossing (one particle) marks where the band starts')
    if (self%onset) then
      call sm%add(tag//'.band_onset_time', self%onset_t, 's')
      call sm%add(tag//'.band_onset_x', self%onset_x(1), 'm, the first particle past the threshold')
      call sm%add(tag//'.band_onset_y', self%onset_x(2), 'm')
      if (self%has_weak) then
        call sm%add(tag//'.band_starts_at_weak_zone', &
                    in_grown_box(self%onset_x, self%weak_lo, self%weak_hi, self%grow), &
                    'the onset within one cell of the weak zone ['// &
                    real_text(self%weak_lo(1))//', '//real_text(self%weak_hi(1))//'] x ['// &
                    real_text(self%weak_lo(2))//', '//real_text(self%weak_hi(2))//'] m')
      else
        call sm%not_applicable(tag//'.band_starts_at_weak_zone', &
                               'the deck has no single box-region material (weak zone)')
      end if
    else
      why = 'no particle exceeded the onset threshold'
      if (present(no_slot)) why = no_slot
      call sm%not_applicable(tag//'.band_onset_time', why)
      call sm%not_applicable(tag//'.band_starts_at_weak_zone', why)
    end if
    if (self%top_ratio /= 0.0_dp) then
      call sm%add(tag//'.platen_cell_stress_ratio', self%top_ratio, 'mean sigma_yy in the '// &
                  'cell row under the platen''s nodes over the mid-height row(s), at the end')
    else
      call sm%not_applicable(tag//'.platen_cell_stress_ratio', &
                             'no particle under a platen, or no stress at mid-height')
    end if
    call sm%add(tag//'.band_drop', self%drop, 'the stage: apparent stress this fraction '// &
                'below its peak, first sample after the onset')
    if (.not. self%staged) then
      why = 'the apparent stress never dropped by band_drop after the onset'
      if (present(no_slot)) why = no_slot
      call sm%not_applicable(tag//'.band_stage_time', why)
      call sm%not_applicable(tag//'.band_fwhm_normal', why)
      call sm%not_applicable(tag//'.band_angle_deg', why)
      call sm%not_applicable(tag//'.band_through_weak_zone', why)
      return
    end if
    call sm%add(tag//'.band_stage_time', self%stage(1), 's')
    call sm%add(tag//'.band_stage_strain', self%stage(2), 'apparent axial strain')
    call sm%add(tag//'.band_stage_stress', self%stage(3)*1.0e-6_dp, 'MPa')
    if (.not. self%fit%found) then
      call sm%not_applicable(tag//'.band_fwhm_normal', trim(self%fit%why))
      call sm%not_applicable(tag//'.band_angle_deg', trim(self%fit%why))
      call sm%not_applicable(tag//'.band_through_weak_zone', trim(self%fit%why))
      return
    end if
    call sm%add(tag//'.band_fwhm_normal', self%fit%fwhm, 'm, FWHM of ||eps^p|| normal to '// &
                'the fitted centre line, at the stage')
    call sm%add(tag//'.band_angle_deg', self%fit%angle_deg, 'the centre line from the +x axis')
    call sm%add(tag//'.band_line_x0', self%fit%x0, 'm: the centre line x = x0 + slope y')
    call sm%add(tag//'.band_line_slope', self%fit%slope)
    call sm%add(tag//'.band_line_rms', self%fit%rms, 'm, slice centres off the line')
    call sm%add(tag//'.band_fit_slices', self%fit%slices)
    call sm%add(tag//'.band_normal_peak', self%fit%peak, 'peak of the profile across the band')
    if (self%has_weak) then
      call sm%add(tag//'.band_through_weak_zone', line_meets_box(self%fit%x0, self%fit%slope, &
                  self%weak_lo, self%weak_hi, self%grow, self%body), 'the centre line at the '// &
                  'stage, across the plate, within one cell of the weak zone')
    else
      call sm%not_applicable(tag//'.band_through_weak_zone', &
                             'the deck has no single box-region material (weak zone)')
    end if
  end subroutine watch_summarise

  !> The watch into a checkpoint (under `pre`), each value by name.
  subroutine watch_put(self, ck, pre)
    class(band_watch_t), intent(in) :: self
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: pre
    call ck%put(pre//'onset', merge(1, 0, self%onset))
    call ck%put(pre//'onset_t', self%onset_t)
    call ck%put(pre//'onset_x', self%onset_x)
    call ck%put(pre//'onset_ep', self%onset_ep)
    call ck%put(pre//'peak', self%peak)
    call ck%put(pre//'staged', merge(1, 0, self%staged))
    call ck%put(pre//'stage', self%stage)
    call ck%put(pre//'top_ratio', self%top_ratio)
    call ck%put(pre//'fit/found', merge(1, 0, self%fit%found))
    call ck%put(pre//'fit/slices', self%fit%slices)
    call ck%put(pre//'fit/fwhm', self%fit%fwhm)
    call ck%put(pre//'fit/angle_deg', self%fit%angle_deg)
    call ck%put(pre//'fit/x0', self%fit%x0)
    call ck%put(pre//'fit/slope', self%fit%slope)
    call ck%put(pre//'fit/peak', self%fit%peak)
    call ck%put(pre//'fit/rms', self%fit%rms)
    call ck%put_text(pre//'fit/why', self%fit%why)
  end subroutine watch_put

  !> The watch that watch_put stored under `pre`.
  subroutine watch_get(self, ck, pre, err)
    class(band_watch_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    character(len=*), intent(in) :: pre
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: a(:)
    character(len=:), allocatable :: why
    call get_flag('onset', self%onset); if (allocated(err)) return
    call ck%get(pre//'onset_t', self%onset_t, err); if (allocated(err)) return
    call ck%get(pre//'onset_x', a, err); if (allocated(err)) return
    self%onset_x = a
    call ck%get(pre//'onset_ep', self%onset_ep, err); if (allocated(err)) return
    call ck%get(pre//'peak', self%peak, err); if (allocated(err)) return
    call get_flag('staged', self%staged); if (allocated(err)) return
    call ck%get(pre//'stage', a, err); if (allocated(err)) return
    self%stage = a
    call ck%get(pre//'top_ratio', self%top_ratio, err); if (allocated(err)) return
    call get_flag('fit/found', self%fit%found); if (allocated(err)) return
    call ck%get(pre//'fit/slices', self%fit%slices, err); if (allocated(err)) return
    call ck%get(pre//'fit/fwhm', self%fit%fwhm, err); if (allocated(err)) return
    call ck%get(pre//'fit/angle_deg', self%fit%angle_deg, err); if (allocated(err)) return
    call ck%get(pre//'fit/x0', self%fit%x0, err); if (allocated(err)) return
    call ck%get(pre//'fit/slope', self%fit%slope, err); if (allocated(err)) return
    call ck%get(pre//'fit/peak', self%fit%peak, err); if (allocated(err)) return
    call ck%get(pre//'fit/rms', self%fit%rms, err); if (allocated(err)) return
    call ck%get_text(pre//'fit/why', why, err); if (allocated(err)) return
    self%fit%why = why
  contains
    subroutine get_flag(name, flag)
      character(len=*), intent(in) :: name
      logical, intent(out) :: flag
      integer :: v
      v = 0
      call ck%get(pre//name, v, err)
      flag = v == 1
    end subroutine get_flag
  end subroutine watch_get

end module wellposed_mpm_plate_band_watch
