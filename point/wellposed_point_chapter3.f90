!> The virtual experiment of chapter 3 (sections 3.4-3.5) on any UMAT: cyclic
!> stress probing of one specimen (table 3.1), interpolation of repeated
!> stimulus-response pairs to a common state (fig. 3.3), the best-fit tangent
!> compliance L = R S^+, and the flow direction M and yield normal N by the
!> polar decomposition of A = C - T (eq. 3.19-3.25), as table 3.2.
!> Legs, drift increments and sign conventions: docs/research/theory.md.
module wellposed_point_chapter3
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_lapack, only: pseudo_inverse, sym_eigen
  use wellposed_point_material, only: material_t, point_state_t, ntens
  use wellposed_point_path, only: leg_t, solver_t, run_leg
  use wellposed_point_probes, only: lode2, from_lode2, pi
  use wellposed_fs, only: int_text
  use wellposed_deck, only: value_text
  implicit none
  private
  public :: ch3_config_t, ch3_result_t, run_chapter3, polar_directions

  !> Settings of the virtual experiment (deck group &chapter3).
  type :: ch3_config_t
    real(dp) :: magnitude = 0.0_dp        !< stress increment size Sigma (eq. 3.5)
    real(dp) :: phi(4) = [90.0_dp, 180.0_dp, 35.0_dp, 125.0_dp]  !< table 3.1 (degrees)
    integer :: n_cycles = 3               !< cycles applied
    integer :: analysis_cycle = 2         !< cycle whose mid-point is the common state
    real(dp) :: drift_axial = 0.0_dp      !< axial stress drift before each leg
    integer :: n_sub = 10                 !< increments per leg
  end type ch3_config_t

  !> Results; columns 1-4 are legs A-D, 5-8 their reverses.
  type :: ch3_result_t
    real(dp), allocatable :: seq_position(:), seq_deps(:, :), seq_depsp(:, :)
    integer, allocatable :: seq_dir(:), seq_cycle(:)
    real(dp) :: s(2, 8) = 0.0_dp       !< stimuli: stress increments
    real(dp) :: r(2, 8) = 0.0_dp       !< interpolated total strain responses
    real(dp) :: rp(2, 8) = 0.0_dp      !< interpolated plastic strain responses
    real(dp) :: l(2, 2) = 0.0_dp       !< best-fit plastic compliance (legs A-D)
    real(dp) :: l_el(2, 2) = 0.0_dp    !< best-fit elastic compliance (reverses)
    real(dp) :: residual = 0.0_dp      !< ||R - L S||_F / ||R||_F, legs A-D
    real(dp) :: residual_el = 0.0_dp   !< same for the reverses
    real(dp) :: m(2) = 0.0_dp, n(2) = 0.0_dp  !< unit M and N
    real(dp) :: theta_m = 0.0_dp, theta_n = 0.0_dp  !< degrees from the compression axis
    real(dp) :: rank_ratio = 0.0_dp    !< small/large eigenvalue of U^2 = A^T A (0: classical)
  end type ch3_result_t

contains

  !> Run the cyclic probing from `s` (changed: the specimen is loaded).
  subroutine run_chapter3(mat, s, cfg, solver, res, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(inout) :: s
    type(ch3_config_t), intent(in) :: cfg
    type(solver_t), intent(in) :: solver
    type(ch3_result_t), intent(out) :: res
    type(error_t), allocatable, intent(out) :: err
    type(leg_t) :: leg
    type(solver_t) :: quiet
    type(point_state_t) :: s_before
    integer :: c, k, iocc, nocc, ca, c1
    real(dp) :: phi, dsig(2), p, w
    quiet = solver
    quiet%verbose = .false.
    nocc = 8*cfg%n_cycles
    allocate (res%seq_position(nocc), res%seq_deps(nocc, 2), res%seq_depsp(nocc, 2), &
              res%seq_dir(nocc), res%seq_cycle(nocc))
    ! normal stresses controlled; shear strains held (zero shear stress by
    ! symmetry for an isotropic specimen, and three unknowns fewer)
    leg%stress_control = [.true., .true., .true., .false., .false., .false.]
    leg%n_inc = cfg%n_sub
    leg%duration = 1.0_dp
    do k = 1, 8
      phi = cfg%phi(modulo(k - 1, 4) + 1)
      if (k > 4) phi = phi + 180.0_dp
      res%s(:, k) = cfg%magnitude*[cos(phi*pi/180.0_dp), sin(phi*pi/180.0_dp)]
    end do
    iocc = 0
    do c = 1, cfg%n_cycles
      do k = 1, 8
        iocc = iocc + 1
        ! drift along the monotonic path
        leg%target(1:3) = s%stress(1:3)
        leg%target(4:6) = s%strain(4:6)
        leg%target(1) = s%stress(1) + cfg%drift_axial
        call run_leg(mat, s, leg, iocc, quiet, err)
        if (allocated(err)) then
          err%message = 'chapter3 cycle '//int_text(c)//', drift before leg '// &
            leg_name(k)//': '//err%message
          return
        end if
        s_before = s
        dsig = res%s(:, k)
        leg%target(1:3) = s%stress(1:3) + from_lode2_3(dsig)
        call run_leg(mat, s, leg, iocc, quiet, err)
        if (allocated(err)) then
          err%message = 'chapter3 cycle '//int_text(c)//', leg '//leg_name(k)//': '// &
            err%message
          return
        end if
        res%seq_deps(iocc, :) = lode2(s%strain - s_before%strain)
        leg%target(1:3) = s_before%stress(1:3)
        call run_leg(mat, s, leg, iocc, quiet, err)
        if (allocated(err)) then
          err%message = 'chapter3 cycle '//int_text(c)//', reversal of leg '// &
            leg_name(k)//': '//err%message
          return
        end if
        res%seq_depsp(iocc, :) = lode2(s%strain - s_before%strain)
        res%seq_position(iocc) = real(iocc, dp)
        res%seq_dir(iocc) = k
        res%seq_cycle(iocc) = c
      end do
      if (solver%verbose) write (*, '(a)') '  ['//mat%label//'] chapter 3: cycle '// &
        int_text(c)//' of '//int_text(cfg%n_cycles)//' done'
    end do
    ! interpolate to the common state: the middle of the analysis cycle
    ca = cfg%analysis_cycle
    p = 8.0_dp*(ca - 1) + 4.5_dp
    do k = 1, 8
      c1 = ca
      if (k > 4) c1 = ca - 1
      w = (p - (8.0_dp*(c1 - 1) + k))/8.0_dp
      res%r(:, k) = (1.0_dp - w)*res%seq_deps(8*(c1 - 1) + k, :) + w*res%seq_deps(8*c1 + k, :)
      res%rp(:, k) = (1.0_dp - w)*res%seq_depsp(8*(c1 - 1) + k, :) + w*res%seq_depsp(8*c1 + k, :)
    end do
    call fit(res%s(:, 1:4), res%r(:, 1:4), res%l, res%residual, err)
    if (allocated(err)) return
    call fit(res%s(:, 5:8), res%r(:, 5:8), res%l_el, res%residual_el, err)
    if (allocated(err)) return
    call polar_directions(res%l, res%l_el, sum(res%rp(:, 1:4), dim=2), res%m, res%n, &
                          res%rank_ratio, err)
    if (allocated(err)) return
    res%theta_m = angle_deg(res%m)
    res%theta_n = angle_deg(res%n)
  end subroutine run_chapter3

  !> L = R S^+ and the relative residual ||R - L S||_F / ||R||_F.
  subroutine fit(s, r, l, residual, err)
    real(dp), intent(in) :: s(:, :), r(:, :)
    real(dp), intent(out) :: l(2, 2), residual
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: splus(size(s, 2), 2)
    call pseudo_inverse(s, splus, err)
    if (allocated(err)) return
    l = matmul(r, splus)
    residual = norm2(r - matmul(l, s))/max(norm2(r), tiny(1.0_dp))
  end subroutine fit

  !> Eq. 3.19-3.25: with T = L^-1 and C = L_el^-1, A = C - T; the
  !> eigenvector of the largest eigenvalue of A^T A is Q's direction, of
  !> A A^T P's; M = C^-1 P, N = C^-1 Q (unit). M is oriented along the mean
  !> plastic strain `plastic_sum`, N so that P.A.Q > 0 (mu > 0).
  subroutine polar_directions(l, l_el, plastic_sum, m, n, rank_ratio, err)
    real(dp), intent(in) :: l(2, 2), l_el(2, 2), plastic_sum(2)
    real(dp), intent(out) :: m(2), n(2), rank_ratio
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: t(2, 2), c(2, 2), a(2, 2), w(2), v(2, 2), p(2), q(2)
    if (.not. abs(det2(l)) > 0.0_dp .or. .not. abs(det2(l_el)) > 0.0_dp) then
      call new_error(err, status_invalid, 'chapter3', 'singular best-fit compliance: '// &
        'the stimuli do not span the Lode plane')
      return
    end if
    t = inv2(l)
    c = inv2(l_el)
    a = c - t
    call sym_eigen(matmul(transpose(a), a), w, v, err)
    if (allocated(err)) return
    q = v(:, 2)
    rank_ratio = abs(w(1))/max(abs(w(2)), tiny(1.0_dp))
    call sym_eigen(matmul(a, transpose(a)), w, v, err)
    if (allocated(err)) return
    p = v(:, 2)
    m = matmul(l_el, p)
    if (dot_product(m, plastic_sum) < 0.0_dp) then
      m = -m
      p = -p
    end if
    if (dot_product(p, matmul(a, q)) < 0.0_dp) q = -q
    n = matmul(l_el, q)
    m = m/norm2(m)
    n = n/norm2(n)
  end subroutine polar_directions

  pure function from_lode2_3(w) result(v3)
    real(dp), intent(in) :: w(2)
    real(dp) :: v3(3), v(ntens)
    v = from_lode2(w)
    v3 = v(1:3)
  end function from_lode2_3

  pure real(dp) function det2(a)
    real(dp), intent(in) :: a(2, 2)
    det2 = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
  end function det2

  pure function inv2(a) result(b)
    real(dp), intent(in) :: a(2, 2)
    real(dp) :: b(2, 2)
    b = reshape([a(2, 2), -a(2, 1), -a(1, 2), a(1, 1)], [2, 2])/det2(a)
  end function inv2

  pure real(dp) function angle_deg(v)
    real(dp), intent(in) :: v(2)
    angle_deg = modulo(atan2(v(2), v(1))*180.0_dp/pi, 360.0_dp)
  end function angle_deg

  pure function leg_name(k) result(name)
    integer, intent(in) :: k
    character(len=:), allocatable :: name
    character(len=*), parameter :: letters = 'ABCD'
    name = letters(modulo(k - 1, 4) + 1:modulo(k - 1, 4) + 1)
    if (k > 4) name = name//"'"
  end function leg_name

end module wellposed_point_chapter3
