!> The plastic work of a bar run, a component of the run loop: at every
!> station sample and at the end D = W_int - (E - E0), the internal work
!> (viscous pressure excluded) less the change of the stored elastic energy
!> E = sum_p V0_p sigma : C^-1 : sigma / 2 (eq. 1.5; our model's K, G in
!> PROPS(1:2); a user's UMAT: not reported). The second law asks D never to
!> fall; the EFR's does (docs/research/waves.md, "The plastic work of the
!> waves").
module wellposed_mpm_bar_dissipation
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpi, only: comm_t, broadcast
  use wellposed_umat_host, only: umat_is_ours
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_mpm_bar_outputs, only: bar_energy_t
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  use wellposed_mpm_output, only: mpm_output_t
  implicit none
  private
  public :: bar_dissipation_t, elastic_energy

  !> A fall of D counts when it exceeds this share of max |W_int| between
  !> two samples (an elastic bar's D, whose drift is the energy balance's
  !> error, never falls by as much: docs/research/waves.md).
  real(dp), parameter :: fall_share = 1.0e-4_dp

  !> D at every sample of the energy balance (rank 0's rows), at the end.
  !> Sampled after `energy` in the run loop's list.
  type, extends(mpm_output_t) :: bar_dissipation_t
    type(bar_energy_t), pointer :: energy => null()
    real(dp), allocatable :: d(:)         !< D at the energy balance's samples
    integer :: n = 0
    logical :: known = .false.            !< our UMAT: K and G known
    real(dp) :: e0 = 0.0_dp               !< E at the start (every rank: the total)
    real(dp) :: d_end = 0.0_dp, w_end = 0.0_dp
  contains
    procedure :: setup => dissipation_setup
    procedure :: sample => dissipation_sample
    procedure :: finish => dissipation_finish
    procedure :: summarise => dissipation_summarise
    procedure :: write_h5 => dissipation_write_h5
    procedure :: put => dissipation_put
    procedure :: get => dissipation_get
  end type bar_dissipation_t

contains

  !> This rank's stored elastic energy sum_p V0_p e(sigma_p) (J/m^2 in 1D),
  !> with the reference volume: with the current one, the prestress's energy
  !> times the volume change would count as elastic work (first order in
  !> the strain), where W_int has none.
  real(dp) function elastic_energy(sc) result(w)
    type(mpm_scene_t), intent(in) :: sc
    real(dp) :: a(size(sc%mats%props, 2)), b(size(sc%mats%props, 2)), tr, ss
    integer :: p, m, nt
    ! e = (s : s/(2 G) + (tr sigma)^2/(9 K))/2 = a s : s + b (tr sigma)^2,
    ! s : s = sigma : sigma - (tr sigma)^2/3, Voigt shears counted twice
    do m = 1, size(a)
      a(m) = 0.0_dp
      b(m) = 0.0_dp
      if (sc%mats%props(2, m) > 0.0_dp) a(m) = 0.25_dp/sc%mats%props(2, m)
      if (sc%mats%props(1, m) > 0.0_dp) b(m) = 1.0_dp/(18.0_dp*sc%mats%props(1, m))
    end do
    w = 0.0_dp
    nt = size(sc%parts%stress, 1)
    if (nt /= 6) error stop 'elastic_energy: the bar''s stress has 6 components'
    associate (st => sc%parts%stress)
      do p = 1, sc%parts%n
        m = sc%mat(p)
        tr = st(1, p) + st(2, p) + st(3, p)
        ss = st(1, p)**2 + st(2, p)**2 + st(3, p)**2 - tr*tr/3.0_dp + &
             2.0_dp*(st(4, p)**2 + st(5, p)**2 + st(6, p)**2)
        w = w + sc%parts%vol0(p)*(a(m)*ss + b(m)*tr*tr)
      end do
    end associate
  end function elastic_energy


  !> D read at every sample of `energy` of scene `sc` (collective).
  subroutine dissipation_setup(self, energy, sc)
    class(bar_dissipation_t), intent(inout) :: self
    type(bar_energy_t), target, intent(in) :: energy
    type(mpm_scene_t), intent(in) :: sc
    self%name = 'dissipation'
    self%energy => energy
    self%known = umat_is_ours()
    allocate (self%d(size(energy%rows, 2)))
    self%n = 1
    self%d(1) = 0.0_dp
    if (self%known) self%e0 = elastic_change(sc, 0.0_dp)
  end subroutine dissipation_setup

  !> E - e0 summed over the ranks (collective through the scene's exchange).
  real(dp) function elastic_change(sc, e0) result(e)
    type(mpm_scene_t), intent(in) :: sc
    real(dp), intent(in) :: e0
    real(dp) :: a(1)
    a(1) = elastic_energy(sc)
    call sc%exchange%sum_reals(a)
    e = a(1) - e0
  end function elastic_change

  subroutine dissipation_sample(self, sc, comm, err)
    class(bar_dissipation_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    logical :: due
    real(dp) :: e
    if (.not. self%known) return
    due = .false.
    if (comm%rank == 0) due = self%energy%n > self%n
    call broadcast(comm, due, 0)
    if (.not. due) return
    e = elastic_change(sc, self%e0)
    if (comm%rank /= 0) return
    self%n = self%energy%n
    self%d(self%n) = self%energy%rows(3, self%n) - e
  end subroutine dissipation_sample

  subroutine dissipation_finish(self, sc, comm, err)
    class(bar_dissipation_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    if (.not. self%known) return
    self%w_end = self%energy%sums(1)
    self%d_end = self%w_end - elastic_change(sc, self%e0)
  end subroutine dissipation_finish

  subroutine dissipation_summarise(self, sm)
    class(bar_dissipation_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    character(len=*), parameter :: why = 'a user''s UMAT: its elastic stiffness is not known'
    real(dp) :: wmax, tol
    integer :: k, falls
    if (.not. self%known) then
      call sm%not_applicable('plastic_work', why)
      return
    end if
    wmax = max(maxval(abs(self%energy%rows(3, 1:self%n))), abs(self%w_end), tiny(1.0_dp))
    tol = fall_share*wmax
    falls = 0
    do k = 2, self%n
      if (self%d(k) < self%d(k - 1) - tol) falls = falls + 1
    end do
    call sm%add('plastic_work', self%d_end, 'J/m^2, W_int - (E - E0) at the end, E = sum V0 '// &
                'sigma : C^-1 : sigma / 2; the second law asks it never to fall')
    if (self%w_end /= 0.0_dp) then
      call sm%add('plastic_work_to_internal_work', self%d_end/self%w_end)
    else
      call sm%not_applicable('plastic_work_to_internal_work', 'no internal work')
    end if
    call sm%add('plastic_work_least', minval(self%d(1:self%n)), &
                'J/m^2, the least over the samples (from 0 at the start)')
    call sm%add('plastic_work_falls', falls, 'sample intervals over which it fell by more '// &
                'than 1e-4 of max |W_int|')
  end subroutine dissipation_summarise

  subroutine dissipation_write_h5(self, h5)
    class(bar_dissipation_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    if (.not. self%known) return
    call h5%write('energy/plastic_work', self%d(1:self%n))
  end subroutine dissipation_write_h5

  subroutine dissipation_put(self, ck, comm)
    class(bar_dissipation_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    if (.not. self%known .or. comm%rank /= 0) return
    call ck%put(self%name//'/plastic_work', self%d(1:self%n))
    call ck%put(self%name//'/elastic_energy0', self%e0)
  end subroutine dissipation_put

  !> Every rank holds the whole checkpoint: all take E0 (the run's start),
  !> rank 0 its D per sample.
  subroutine dissipation_get(self, ck, comm, err)
    class(bar_dissipation_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: d(:)
    if (.not. self%known) return
    call ck%get(self%name//'/elastic_energy0', self%e0, err); if (allocated(err)) return
    if (comm%rank /= 0) return
    call ck%get(self%name//'/plastic_work', d, err); if (allocated(err)) return
    ! one D per sample of the energy balance, restored before this component
    if (size(d) /= self%energy%n .or. size(d) > size(self%d)) then
      call new_error(err, status_invalid, 'checkpoint', 'its plastic work rows do not '// &
                     'fit this deck'); return
    end if
    self%n = size(d)
    self%d(1:self%n) = d
  end subroutine dissipation_get

end module wellposed_mpm_bar_dissipation
