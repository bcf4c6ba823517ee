!> Stations of a plate case (&stations of wellposed_mpm_plate_deck): the
!> histories of sigma_xx, sigma_yy, sigma_xy, v_x and v_y of the particle
!> nearest each point (scaled with the case), sampled every &output
!> sample_dt on rank 0 through a station proxy, as the bar's stations are
!> (wellposed_mpm_stations, wellposed_mpm_parallel_io), so that they hold
!> the serial values on any number of ranks. They go to run.h5
!> (cases/<tag>/stations/), summary.txt and the checkpoints.
module wellposed_mpm_plate_stations
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_text, only: int_text
  use wellposed_mpi, only: comm_t
  use wellposed_summary, only: summary_t
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_stations, only: stations_t, place_point_stations, sample_stations, nfields, &
                                    field_sxx, field_syy, field_sxy, field_v, field_vy, &
                                    change_extreme
  use wellposed_mpm_parallel_io, only: station_proxy_t, gather_reference_positions, &
                                       start_proxied_stations, fill_station_proxy, &
                                       put_stations, get_stations
  use wellposed_mpm_plate_deck, only: plate_study_t
  implicit none
  private
  public :: plate_stations_t, new_plate_stations, restore_plate_stations, plate_station_keys

  !> A plate's station keys after station_<s> (summarise_plate_stations).
  character(len=10), parameter :: plate_station_keys(6) = [character(len=10) :: '_x', '_y', &
    '_sigma_yy', '_sigma_xx', '_v_x_final', '_v_y_final']

  type :: plate_stations_t
    logical :: on = .false.             !< the deck gives &stations
    logical :: root = .false.           !< this rank holds the histories
    type(stations_t) :: st
    type(station_proxy_t) :: proxy
  contains
    procedure :: sample => sample_plate_stations
    procedure :: summarise => summarise_plate_stations
    procedure :: write_h5 => write_plate_stations
    procedure :: put => put_plate_stations
    procedure :: get => get_plate_stations
  end type plate_stations_t

contains

  !> The stations of case `ic` of `study` on scene `sc` at t = 0
  !> (collective; none when the deck gives no &stations).
  subroutine new_plate_stations(self, study, ic, sc, t_end, comm)
    type(plate_stations_t), intent(out) :: self
    type(plate_study_t), intent(in) :: study
    integer, intent(in) :: ic
    type(mpm_scene_t), intent(in) :: sc
    real(dp), intent(in) :: t_end
    type(comm_t), intent(in) :: comm
    real(dp), allocatable :: x0(:, :)
    integer :: n
    n = study%nstations
    if (n == 0) return
    self%on = .true.
    self%root = comm%rank == 0
    call gather_reference_positions(comm, sc%parts, 0, x0)
    if (self%root) then
      call place_point_stations(self%st, study%station_x(1:n)*study%scale(ic), &
                                study%station_y(1:n)*study%scale(ic), x0)
    else
      allocate (self%st%x(0), self%st%y(0), self%st%time(0), self%st%hist(nfields, 0, 0))
    end if
    call start_proxied_stations(self%st, comm, sc%ntotal, sc%parts, study%sample_dt, t_end, &
                                self%proxy)
  end subroutine new_plate_stations

  !> The stations of finished case `ic` (run to t_end) from checkpoint `ck`
  !> under `prefix` (collective: rank 0 reads the histories).
  subroutine restore_plate_stations(self, study, t_end, comm, ck, prefix, err)
    type(plate_stations_t), intent(out) :: self
    type(plate_study_t), intent(in) :: study
    real(dp), intent(in) :: t_end
    type(comm_t), intent(in) :: comm
    type(checkpoint_t), intent(in) :: ck
    character(len=*), intent(in) :: prefix
    type(error_t), allocatable, intent(out) :: err
    integer :: n, nmax
    n = study%nstations
    if (n == 0) return
    self%on = .true.
    self%root = comm%rank == 0
    if (.not. self%root) then
      allocate (self%st%x(0), self%st%y(0), self%st%time(0), self%st%hist(nfields, 0, 0))
      return
    end if
    nmax = int(t_end/study%sample_dt) + 2
    self%st%n = n
    allocate (self%st%x(n), self%st%y(n), self%st%pa(n), self%st%pb(n), self%st%wb(n), &
              self%st%time(nmax), self%st%hist(nfields, n, nmax), self%st%prev(nfields, n))
    call self%get(ck, prefix, err)
  end subroutine restore_plate_stations

  !> The samples due by the scene's time (collective).
  subroutine sample_plate_stations(self, sc, comm)
    class(plate_stations_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(in) :: comm
    if (.not. self%on) return
    call fill_station_proxy(self%proxy, comm, sc%parts)
    if (self%root) call sample_stations(self%st, self%proxy%parts, sc%t)
  end subroutine sample_plate_stations

  !> Per station (rank 0), keys prefix//'<s>'//keys(i): the particle's
  !> reference position (x + x_shift, y), the signed extremes of sigma_yy and
  !> sigma_xx about their values at t = 0 with their times, and the final
  !> velocity (v_x, v_y). A plate's keys: plate_station_keys; a kind on the
  !> same section names them its own way (the cylinder: r, z).
  subroutine summarise_plate_stations(self, sm, prefix, keys, x_shift)
    class(plate_stations_t), intent(in) :: self
    type(summary_t), intent(inout) :: sm
    character(len=*), intent(in) :: prefix, keys(6)
    real(dp), intent(in) :: x_shift
    character(len=:), allocatable :: k
    integer :: s, ns
    if (.not. self%on) return
    ns = self%st%ns
    do s = 1, self%st%n
      k = prefix//int_text(s)
      call sm%add(k//trim(keys(1)), self%st%x(s) + x_shift, &
                  'm, reference position of the particle read')
      call sm%add(k//trim(keys(2)), self%st%y(s), 'm')
      call extreme(trim(keys(3)), field_syy)
      call extreme(trim(keys(4)), field_sxx)
      call sm%add(k//trim(keys(5)), self%st%hist(field_v, s, ns), 'm/s')
      call sm%add(k//trim(keys(6)), self%st%hist(field_vy, s, ns), 'm/s')
    end do
  contains
    subroutine extreme(name, field)
      character(len=*), intent(in) :: name
      integer, intent(in) :: field
      real(dp) :: d
      integer :: j
      call change_extreme(self%st, field, s, d, j)
      call sm%add(k//name//'_extreme', d, 'Pa, signed extreme of the change from t = 0 '// &
                  '(tension +)')
      call sm%add(k//'_t'//name//'_extreme', self%st%time(j), 's')
    end subroutine extreme
  end subroutine summarise_plate_stations

  !> The histories under `prefix` of run.h5 (collective; rank 0's values).
  subroutine write_plate_stations(self, h5, prefix)
    class(plate_stations_t), intent(in) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    character(len=*), intent(in) :: prefix
    integer :: ns
    if (.not. self%on) return
    ns = self%st%ns
    call h5%write(prefix//'time', self%st%time(1:ns))
    call h5%write(prefix//'x', self%st%x)
    call h5%write(prefix//'y', self%st%y)
    call h5%write(prefix//'sigma_xx', self%st%hist(field_sxx, :, 1:ns))
    call h5%write(prefix//'sigma_yy', self%st%hist(field_syy, :, 1:ns))
    call h5%write(prefix//'sigma_xy', self%st%hist(field_sxy, :, 1:ns))
    call h5%write(prefix//'velocity_x', self%st%hist(field_v, :, 1:ns))
    call h5%write(prefix//'velocity_y', self%st%hist(field_vy, :, 1:ns))
  end subroutine write_plate_stations

  !> The histories so far into a checkpoint (rank 0).
  subroutine put_plate_stations(self, ck, prefix)
    class(plate_stations_t), intent(in) :: self
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: prefix
    if (.not. (self%on .and. self%root)) return
    call put_stations(ck, prefix, self%st)
    call ck%put(prefix//'y', self%st%y)
  end subroutine put_plate_stations

  !> The histories back from a checkpoint (rank 0).
  subroutine get_plate_stations(self, ck, prefix, err)
    class(plate_stations_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    character(len=*), intent(in) :: prefix
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: y(:)
    if (.not. (self%on .and. self%root)) return
    call get_stations(ck, prefix, self%st, err); if (allocated(err)) return
    call ck%get(prefix//'y', y, err); if (allocated(err)) return
    self%st%y = y
  end subroutine get_plate_stations

end module wellposed_mpm_plate_stations
