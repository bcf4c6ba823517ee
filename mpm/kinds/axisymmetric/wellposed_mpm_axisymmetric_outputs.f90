!> The axisymmetric kind's outputs of the run loop (wellposed_mpm_output):
!> particle snapshots in r-z (r, z, sigma_rr, sigma_zz, sigma_tt, sigma_rz,
!> ||eps^p||), the specimen's curve with the onset of yield, and the
!> progress line (the closed forms: wellposed_mpm_axisymmetric_closed_forms).
!> Keys: docs/guide/axisymmetric.md.
module wellposed_mpm_axisymmetric_outputs
  use, intrinsic :: iso_fortran_env, only: output_unit
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_mpi, only: comm_t, allreduce_max
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_scene_sums, only: plastic_strain
  use wellposed_mpm_output, only: mpm_output_t
  use wellposed_mpm_run_loop, only: snapshot_due
  use wellposed_mpm_snapshot_output, only: snapshot_output_t, progress_output_t
  use wellposed_mpm_axisymmetric_kind, only: axi_kind_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_stations, only: field_sxx, field_syy, field_sxy, field_v, field_vy
  use wellposed_mpm_plate_stations, only: plate_stations_t
  implicit none
  private
  public :: axi_snapshots_t, axi_progress_t, axi_curve_t, axi_stations_t, axi_field_names, &
            axi_field_widths

  character(len=14), parameter :: axi_field_names(6) = [character(len=14) :: 'rz', &
    'sigma_rr', 'sigma_zz', 'sigma_tt', 'sigma_rz', 'plastic_strain']
  integer, parameter :: axi_field_widths(6) = [2, 1, 1, 1, 1, 1]

  !> Snapshots at t = 0, every interval and at the end.
  type, extends(snapshot_output_t) :: axi_snapshots_t
    real(dp) :: r_inner = 0.0_dp
  contains
    procedure :: rows => axi_rows
    procedure :: start => axi_snapshots_start
    procedure :: sample => axi_snapshots_sample
    procedure :: finish => axi_snapshots_finish
  end type axi_snapshots_t

  !> A line every 10 s of wall time (rank 0, &output progress).
  type, extends(progress_output_t) :: axi_progress_t
    logical :: on = .false.
    integer :: nsteps_est = 0
  contains
    procedure :: sample => axi_progress_sample
  end type axi_progress_t


  !> The specimen's curve every sample_dt (every step when 0): time, axial
  !> strain (-u_top/height, of the body under the platen's lowest node row
  !> once the platen is below the top), axial and lateral stress (compression +: minus
  !> the volume averages of sigma_zz and sigma_rr over the body under the
  !> platen's lowest node row; the averages are the platen's force and the
  !> lateral pressure per area in equilibrium), the largest ||eps^p||; and
  !> the onset: the first sample where ||eps^p|| passes `onset_strain`,
  !> with the axial strain then and where (r, z; the mean of ties).
  type, extends(mpm_output_t) :: axi_curve_t
    real(dp) :: sample_dt = 0.0_dp, next = 0.0_dp, onset_strain = 1.0e-3_dp
    integer :: n = 0
    real(dp), allocatable :: rows(:, :)     !< (5, n)
    real(dp) :: onset(4) = -1.0_dp          !< t, axial strain, r, z (t < 0: none yet)
    real(dp) :: peak_at(3) = 0.0_dp         !< at the end: the largest ||eps^p||, its r, z
    real(dp) :: r_inner = 0.0_dp
  contains
    procedure :: start => curve_start
    procedure :: sample => curve_sample
    procedure :: finish => curve_finish
    procedure :: summarise => curve_summarise
    procedure :: put => curve_put
    procedure :: get => curve_get
  end type axi_curve_t

  !> &stations: the histories of the particle nearest each point (the
  !> plate's station machinery on the section, x = r - r_inner), sampled
  !> every sample_dt on rank 0, into run.h5 (stations/), the summary and
  !> the checkpoints; named in r and z.
  type, extends(mpm_output_t) :: axi_stations_t
    type(plate_stations_t) :: pst
    real(dp) :: r_inner = 0.0_dp
  contains
    procedure :: sample => stations_sample
    procedure :: summarise => stations_summarise
    procedure :: write_h5 => stations_write_h5
    procedure :: put => stations_put
    procedure :: get => stations_get
  end type axi_stations_t

contains

  subroutine stations_sample(self, sc, comm, err)
    class(axi_stations_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%pst%sample(sc, comm)
  end subroutine stations_sample

  !> Per station (rank 0): the particle's reference (r, z), the signed
  !> extremes of sigma_zz and sigma_rr about t = 0 with their times, and
  !> the final velocity.
  subroutine stations_summarise(self, sm)
    class(axi_stations_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    call self%pst%summarise(sm, 'station_', [character(len=10) :: '_r', '_z', '_sigma_zz', &
                            '_sigma_rr', '_v_r_final', '_v_z_final'], self%r_inner)
  end subroutine stations_summarise

  !> The histories under stations/ of run.h5 (collective; rank 0's values).
  subroutine stations_write_h5(self, h5)
    class(axi_stations_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    integer :: ns
    if (.not. self%pst%on) return
    associate (st => self%pst%st)
      ns = st%ns
      call h5%write('stations/time', st%time(1:ns))
      call h5%write('stations/r', st%x + self%r_inner)
      call h5%write('stations/z', st%y)
      call h5%write('stations/sigma_rr', st%hist(field_sxx, :, 1:ns))
      call h5%write('stations/sigma_zz', st%hist(field_syy, :, 1:ns))
      call h5%write('stations/sigma_rz', st%hist(field_sxy, :, 1:ns))
      call h5%write('stations/velocity_r', st%hist(field_v, :, 1:ns))
      call h5%write('stations/velocity_z', st%hist(field_vy, :, 1:ns))
    end associate
  end subroutine stations_write_h5

  subroutine stations_put(self, ck, comm)
    class(axi_stations_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    call self%pst%put(ck, self%name//'/')
  end subroutine stations_put

  subroutine stations_get(self, ck, comm, err)
    class(axi_stations_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    call self%pst%get(ck, self%name//'/', err)
  end subroutine stations_get

  subroutine curve_start(self, sc, comm, err)
    class(axi_curve_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    self%n = 0
    self%next = 0.0_dp
    call curve_sample(self, sc, comm, err)
  end subroutine curve_start

  !> A row when due (collective: the averages are summed over the ranks).
  subroutine curve_sample(self, sc, comm, err)
    class(axi_curve_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: a(3), yg, strain, epmax, at(3)
    real(dp), allocatable :: grown(:, :)
    integer :: p
    if (sc%t < self%next - 1.0e-12_dp) return
    self%next = self%next + self%sample_dt
    a = 0.0_dp
    strain = 0.0_dp
    select type (kind => sc%kind)
    class is (axi_kind_t)
      ! the body under the platen's lowest node row; the layer above it
      ! moves with the platen (the plate's apparent strain)
      yg = sc%origin(2) + sc%dx*kind%platen_row
      strain = -kind%top_disp/kind%cfg%height
      if (yg < kind%cfg%height + kind%top_disp) strain = -kind%top_disp/(yg - kind%top_disp)
      associate (pt => sc%parts)
        do p = 1, pt%n
          if (pt%x(2, p) < yg) a = a + pt%vol(p)*[1.0_dp, pt%stress(2, p), pt%stress(1, p)]
        end do
      end associate
    end select
    call sc%exchange%sum_reals(a)
    call largest_plastic(self, sc, comm, epmax, at)
    if (self%onset(1) < 0.0_dp .and. epmax >= self%onset_strain) &
      self%onset = [sc%t, strain, at(1:2)]
    if (.not. allocated(self%rows)) allocate (self%rows(5, 256))
    if (self%n == size(self%rows, 2)) then
      allocate (grown(5, 2*self%n))
      grown(:, 1:self%n) = self%rows
      call move_alloc(grown, self%rows)
    end if
    self%n = self%n + 1
    self%rows(:, self%n) = [sc%t, strain, -a(2:3)/max(a(1), tiny(1.0_dp)), epmax]
  end subroutine curve_sample

  !> The largest ||eps^p|| of the scene, epmax, and where, at(1:2) = (r, z)
  !> (the mean of ties; collective).
  subroutine largest_plastic(self, sc, comm, epmax, at)
    class(axi_curve_t), intent(in) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    real(dp), intent(out) :: epmax, at(3)
    real(dp), allocatable :: ep(:)
    integer :: p
    ep = plastic_strain(sc)
    epmax = maxval([0.0_dp, ep])
    if (comm%size > 1) call allreduce_max(comm, epmax)
    at = 0.0_dp
    do p = 1, sc%parts%n
      if (ep(p) == epmax) at = at + [sc%parts%x(1, p) + self%r_inner, sc%parts%x(2, p), 1.0_dp]
    end do
    call sc%exchange%sum_reals(at)
    at(1:2) = at(1:2)/max(at(3), 1.0_dp)
  end subroutine largest_plastic

  !> Where the largest plastic strain is at the end.
  subroutine curve_finish(self, sc, comm, err)
    class(axi_curve_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: epmax, at(3)
    call largest_plastic(self, sc, comm, epmax, at)
    self%peak_at = [epmax, at(1:2)]
  end subroutine curve_finish

  subroutine curve_summarise(self, sm)
    class(axi_curve_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    integer :: j
    associate (c => self%rows(:, 1:self%n))
      j = maxloc(c(3, :) - c(4, :), dim=1)
      call sm%add('peak_deviator', (c(3, j) - c(4, j))*1.0e-6_dp, 'MPa, axial - lateral '// &
                  'stress (compression +)')
      call sm%add('strain_at_peak', c(2, j), 'axial strain -u_top/height')
      call sm%add('final_axial_stress', c(3, self%n)*1.0e-6_dp, 'MPa')
      call sm%add('final_lateral_stress', c(4, self%n)*1.0e-6_dp, 'MPa')
      call sm%add('final_strain', c(2, self%n))
    end associate
    call sm%add('final_peak_plastic_r', self%peak_at(2), 'm, where ||eps^p|| is largest at the end')
    call sm%add('final_peak_plastic_z', self%peak_at(3), 'm')
    if (self%onset(1) < 0.0_dp) then
      call sm%not_applicable('onset_time', 'no particle reached ||eps^p|| = '// &
                             real_text(self%onset_strain))
      call sm%not_applicable('onset_strain', 'no onset')
      call sm%not_applicable('onset_r', 'no onset')
      call sm%not_applicable('onset_z', 'no onset')
      return
    end if
    call sm%add('onset_time', self%onset(1), 's, the first sample with ||eps^p|| >= '// &
                real_text(self%onset_strain))
    call sm%add('onset_strain', self%onset(2), 'axial strain then')
    call sm%add('onset_r', self%onset(3), 'm, where')
    call sm%add('onset_z', self%onset(4), 'm')
  end subroutine curve_summarise

  !> The rows by column, each with a leading 0 (an entry even when empty).
  subroutine curve_put(self, ck, comm)
    class(axi_curve_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    integer :: k
    if (comm%rank /= 0) return
    do k = 1, 5
      call ck%put(self%name//'/column_'//int_text(k), [0.0_dp, self%rows(k, 1:self%n)])
    end do
    call ck%put(self%name//'/next', self%next)
    call ck%put(self%name//'/onset', self%onset)
  end subroutine curve_put

  subroutine curve_get(self, ck, comm, err)
    class(axi_curve_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: col(:)
    integer :: k
    do k = 1, 5
      call ck%get(self%name//'/column_'//int_text(k), col, err)
      if (allocated(err)) return
      if (k == 1) then
        self%n = size(col) - 1
        if (allocated(self%rows)) deallocate (self%rows)
        allocate (self%rows(5, max(256, self%n)))
      end if
      if (size(col) /= self%n + 1) then
        call new_error(err, status_invalid, 'checkpoint', self%name//': its columns differ '// &
                       'in length'); return
      end if
      self%rows(k, 1:self%n) = col(2:self%n + 1)
    end do
    call ck%get(self%name//'/next', self%next, err)
    if (allocated(err)) return
    call ck%get(self%name//'/onset', col, err)
    if (allocated(err)) return
    if (size(col) /= 4) then
      call new_error(err, status_invalid, 'checkpoint', self%name//'/onset: garbled'); return
    end if
    self%onset = col
  end subroutine curve_get

  !> Rows of this rank's particles: r, z, the stresses, ||eps^p||.
  subroutine axi_rows(self, sc, group, rows)
    class(axi_snapshots_t), intent(in) :: self
    type(mpm_scene_t), intent(in) :: sc
    character(len=:), allocatable, intent(out) :: group
    real(dp), allocatable, intent(out) :: rows(:, :)
    integer :: n
    n = sc%parts%n
    allocate (rows(7, n))
    rows(1, :) = sc%parts%x(1, 1:n) + self%r_inner
    rows(2, :) = sc%parts%x(2, 1:n)
    rows(3, :) = sc%parts%stress(1, 1:n)
    rows(4, :) = sc%parts%stress(2, 1:n)
    rows(5, :) = sc%parts%stress(3, 1:n)
    rows(6, :) = sc%parts%stress(4, 1:n)
    rows(7, :) = plastic_strain(sc)
    group = 'snapshots/snap_'//int_text(self%taken)//'/'
  end subroutine axi_rows

  subroutine axi_snapshots_start(self, sc, comm, err)
    class(axi_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    self%taken = 0
    self%next = self%interval
    call self%take(sc, comm, err)
  end subroutine axi_snapshots_start

  subroutine axi_snapshots_sample(self, sc, comm, err)
    class(axi_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. snapshot_due(self%interval, sc%t, self%next, 1.0e-12_dp)) return
    self%next = self%next + self%interval
    call self%take(sc, comm, err)
  end subroutine axi_snapshots_sample

  !> The last state, unless a scheduled snapshot just took it.
  subroutine axi_snapshots_finish(self, sc, comm, err)
    class(axi_snapshots_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (self%last_due(sc)) call self%take(sc, comm, err)
  end subroutine axi_snapshots_finish

  subroutine axi_progress_sample(self, sc, comm, err)
    class(axi_progress_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. self%on) return
    if (.not. self%clock%progress_due()) return
    write (output_unit, '(a)') '    step '//int_text(sc%nstep)//'/'//int_text(self%nsteps_est)// &
      ', t = '//real_text(sc%t)//' s, ~'//int_text(nint(self%clock%elapsed()* &
      (self%nsteps_est - sc%nstep)/max(sc%nstep, 1)))//' s left'
    flush (output_unit)
  end subroutine axi_progress_sample

end module wellposed_mpm_axisymmetric_outputs
