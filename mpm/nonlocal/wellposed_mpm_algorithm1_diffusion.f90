!> Step 3 of Algorithm 1 (wellposed_mpm_algorithm1), plastic diffusion:
!> the elastic particles with a nonzero average are called once more; one
!> that yields joins the plastic set and its contribution enters the field
!> (eq. 4.49-4.50), and step 2 runs again.
module wellposed_mpm_algorithm1_diffusion
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_mpm_nonlocal_state, only: nonlocal_t
  use wellposed_mpm_nonlocal_grid, only: cached_average, field_extents, field_reaches, &
                                         extend_extents
  use wellposed_mpm_nonlocal_host, only: nonlocal_host_t
  use wellposed_mpm_algorithm1_work, only: algorithm1_work_t, refresh, stopped
  use wellposed_mpm_algorithm1_sweep, only: correct_field
  implicit none
  private
  public :: plastic_diffusion

contains

  !> Step 3 over this rank's particles in the serial order (collective):
  !> w%changed tells every rank whether any particle became plastic. The
  !> Gauss-Seidel sweep reads and passes on the field as its step 2 does.
  subroutine plastic_diffusion(self, host, w, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(inout) :: w
    type(error_t), allocatable, intent(out) :: err
    w%changed = .false.
    if (w%par .and. .not. w%simul) call w%ranks%nodes_from_lower(self%field)
    call field_extents(self)
    if (w%simul) then
      call diffuse_simultaneous(self, host, w, err)
      call refresh(self, w)
    else
      call diffuse_in_order(self, host, w, err)
      if (w%par) then
        call w%ranks%nodes_to_higher(self%field)
        call w%ranks%nodes_from_highest(self%field)
      end if
    end if
    if (w%par) w%changed = w%ranks%any_true(w%changed)
    if (stopped(w, err)) return
  end subroutine plastic_diffusion

  !> Step 3 with the Gauss-Seidel sweep: one particle after the other, each
  !> reading the field the ones before it left.
  subroutine diffuse_in_order(self, host, w, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(inout) :: w
    type(error_t), allocatable, intent(out) :: err
    integer :: q, p
    real(dp) :: avg, dnew
    do q = 1, w%n
      p = w%order(q)
      if (.not. diffuses_to(self, w, p, avg)) cycle
      call host%update(p, avg, dnew, err)
      if (allocated(err)) return
      self%last%umat_calls = self%last%umat_calls + 1
      if (dnew > 0.0_dp) call reclassify(self, w, p, dnew)
    end do
  end subroutine diffuse_in_order

  !> Step 3 with the simultaneous sweeps: the averages read the field as
  !> the pass began (corrections go to `own`), so the elastic particles
  !> with a nonzero average go to the host as one list.
  subroutine diffuse_simultaneous(self, host, w, err)
    type(nonlocal_t), intent(inout) :: self
    class(nonlocal_host_t), intent(inout) :: host
    type(algorithm1_work_t), intent(inout) :: w
    type(error_t), allocatable, intent(out) :: err
    integer :: q, p, m
    integer, allocatable :: list(:)
    real(dp), allocatable :: avgs(:), dns(:)
    allocate (list(w%n), avgs(w%n), dns(w%n))
    m = 0
    do q = 1, w%n
      p = w%order(q)
      if (.not. diffuses_to(self, w, p, avgs(m + 1))) cycle
      m = m + 1
      list(m) = p
    end do
    call host%update_list(list(1:m), avgs(1:m), dns(1:m), err)
    if (allocated(err)) return
    self%last%umat_calls = self%last%umat_calls + m
    do q = 1, m
      if (dns(q) > 0.0_dp) call reclassify(self, w, list(q), dns(q))
    end do
  end subroutine diffuse_simultaneous

  !> Whether step 3 calls particle p: elastic, with a nonzero average
  !> `avg` (zero when its support holds no nonzero field node; with a zero
  !> average the step-1 call already had this input).
  logical function diffuses_to(self, w, p, avg)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(in) :: w
    integer, intent(in) :: p
    real(dp), intent(out) :: avg
    avg = 0.0_dp
    diffuses_to = .false.
    if (self%plastic(p)) return
    if (.not. field_reaches(self, w%x(:, p))) return
    call cached_average(self, p, w%x(:, p), avg)
    diffuses_to = avg /= 0.0_dp
  end function diffuses_to

  !> Step 3's elastic particle p yields (dlambda = dnew > 0): it joins the
  !> plastic set and its contribution enters the field.
  subroutine reclassify(self, w, p, dnew)
    type(nonlocal_t), intent(inout) :: self
    type(algorithm1_work_t), intent(inout) :: w
    integer, intent(in) :: p
    real(dp), intent(in) :: dnew
    w%changed = .true.
    self%plastic(p) = .true.
    self%last%n_reclassified = self%last%n_reclassified + 1
    call correct_field(self, w, p, dnew - self%dl(p))
    call extend_extents(self, w%node(:, p))
    self%dl(p) = dnew
  end subroutine reclassify

end module wellposed_mpm_algorithm1_diffusion
