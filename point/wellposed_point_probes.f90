!> Probes of a saved state of the single element, all through UMAT calls from
!> copies of the state: the directional stiffness ratio R(theta) (eq. 2.5,
!> section 2.4, fig. 2.4), the acoustic tensor n.T.n (eq. 1.7) with loss of
!> ellipticity and flutter, elastic and plastic uniaxial-strain wave speeds,
!> and Gudehus strain-response envelopes (fig. 3.2). The yield normal is found
!> by bisection on probe responses, not asked of the material.
!> Conventions and method: docs/research/theory.md. Abaqus order, tension positive.
module wellposed_point_probes
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_lapack, only: sym_eigen, general_eigenvalues
  use wellposed_point_material, only: material_t, point_state_t, umat_increment, ntens
  use wellposed_point_path, only: leg_t, solver_t, run_leg
  use wellposed_deck, only: value_text
  implicit none
  private
  public :: elastic_stiffness, lode_frame_t, find_lode_frame, rtheta_probe, acoustic_t, &
            acoustic_probe, wave_speeds, gudehus_probe, lode2, from_lode2, pi

  real(dp), parameter :: pi = 3.14159265358979323846_dp
  real(dp), parameter :: sqrt2 = sqrt(2.0_dp), sqrt3 = sqrt(3.0_dp)

  !> The axisymmetric Lode plane of a state and its loading geometry.
  type :: lode_frame_t
    real(dp) :: e_z(ntens), e_r(ntens)  !< unit tensors I/sqrt(3) and S_hat
    real(dp) :: c2(2, 2)                !< elastic stiffness in the plane
    real(dp) :: n2(2)                   !< unit yield normal N in the plane (z, r)
    real(dp) :: t2(2)                   !< theta = 0 direction (tangent, negative trace)
    real(dp) :: boundary_deg(2)         !< loading/unloading boundary angles from E_z (degrees)
  end type lode_frame_t

  !> Acoustic tensor results over a grid of unit normals.
  type :: acoustic_t
    real(dp), allocatable :: polar_deg(:), azimuth_deg(:)  !< grid (from axis 1)
    real(dp), allocatable :: min_eig(:, :)    !< smallest eigenvalue of sym(A)
    real(dp), allocatable :: max_imag(:, :)   !< largest |imaginary part| of eig(A)
    real(dp) :: min_eig_global = 0.0_dp       !< over the grid
    real(dp) :: n_crit(3) = 0.0_dp            !< normal of min_eig_global
    real(dp) :: elastic_min_eig = 0.0_dp      !< same measure for C (scale)
    logical :: loss_of_ellipticity = .false.  !< min_eig_global <= 0
    logical :: flutter = .false.              !< complex eigenvalues somewhere
  end type acoustic_t

contains

  !> DDSDDE of a small strain increment from the stress-free virgin state.
  subroutine elastic_stiffness(mat, eps, c, err)
    type(material_t), intent(in) :: mat
    real(dp), intent(in) :: eps
    real(dp), intent(out) :: c(ntens, ntens)
    type(error_t), allocatable, intent(out) :: err
    type(point_state_t) :: s0, s1
    real(dp) :: pnewdt
    allocate (s0%statev(mat%nstatv))
    s0%statev = 0.0_dp
    call umat_increment(mat, s0, [eps, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], 1.0_dp, s1, &
                        c, pnewdt, err)
    if (allocated(err)) then
      err%message = 'material "'//mat%label//'": '//err%message
      return
    end if
    if (pnewdt <= 0.0_dp .or. .not. all(ieee_is_finite(c))) then
      call new_error(err, status_invalid, 'props', 'material "'//mat%label//'": no '// &
        'elastic stiffness from the UMAT at the virgin state (PNEWDT = '//value_text(pnewdt)//')')
    end if
  end subroutine elastic_stiffness

  !> Response dsig/eps of the probe increment eps*d from `s` (DTIME = 1:
  !> a rate-dependent material is probed over unit time).
  subroutine probe(mat, s, d, eps, dsig, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s
    real(dp), intent(in) :: d(ntens), eps
    real(dp), intent(out) :: dsig(ntens)
    type(error_t), allocatable, intent(out) :: err
    type(point_state_t) :: s1
    real(dp) :: dd(ntens, ntens), pnewdt
    call umat_increment(mat, s, eps*d, 1.0_dp, s1, dd, pnewdt, err)
    if (allocated(err)) then
      err%message = 'material "'//mat%label//'": '//err%message
      return
    end if
    if (pnewdt < 1.0_dp) then
      call new_error(err, status_invalid, 'probe_strain', 'material "'//mat%label// &
        '": the UMAT refused a probe increment of size probe_strain = '//value_text(eps)// &
        ' (PNEWDT = '//value_text(pnewdt)//')')
      return
    end if
    dsig = (s1%stress - s%stress)/eps
  end subroutine probe

  !> Axisymmetric Lode components (compression positive, chapter 3:
  !> sigma_z = -tr/sqrt(3), sigma_r = -sqrt(2/3) (sigma_A - sigma_L)), axis 1
  !> axial, lateral the mean of 22 and 33.
  pure function lode2(v) result(w)
    real(dp), intent(in) :: v(ntens)
    real(dp) :: w(2)
    w(1) = -(v(1) + v(2) + v(3))/sqrt3
    w(2) = -sqrt(2.0_dp/3.0_dp)*(v(1) - 0.5_dp*(v(2) + v(3)))
  end function lode2

  !> The axisymmetric tensor (Abaqus order) of compression-positive Lode
  !> components w (inverse of lode2 on axisymmetric tensors).
  pure function from_lode2(w) result(v)
    real(dp), intent(in) :: w(2)
    real(dp) :: v(ntens), z, r
    z = -w(1)
    r = -w(2)
    v = 0.0_dp
    v(1) = (z + sqrt2*r)/sqrt3
    v(2) = (z - r/sqrt2)/sqrt3
    v(3) = v(2)
  end function from_lode2

  !> Locate the loading/unloading boundary of the Lode plane of `s` and
  !> build the theta frame (see the module description).
  subroutine find_lode_frame(mat, s, c, eps, frame, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s
    real(dp), intent(in) :: c(ntens, ntens), eps
    type(lode_frame_t), intent(out) :: frame
    type(error_t), allocatable, intent(out) :: err
    integer, parameter :: nscan = 720
    real(dp) :: dev(ntens), ang(nscan), a, b, m, cut(2), mid, qs(2), ns(2), inv(2, 2), det
    logical :: pl(nscan), pa, pm
    integer :: i, k, ncut, it
    frame%e_z = [1.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]/sqrt3
    dev = s%stress
    dev(1:3) = dev(1:3) - sum(s%stress(1:3))/3.0_dp
    if (norm_t(dev) > 0.0_dp) then
      frame%e_r = dev/norm_t(dev)
    else
      frame%e_r = [2.0_dp, -1.0_dp, -1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]/sqrt(6.0_dp)
    end if
    frame%c2(1, 1) = dot_product(frame%e_z, matmul(c, frame%e_z))
    frame%c2(1, 2) = dot_product(frame%e_z, matmul(c, frame%e_r))
    frame%c2(2, 1) = dot_product(frame%e_r, matmul(c, frame%e_z))
    frame%c2(2, 2) = dot_product(frame%e_r, matmul(c, frame%e_r))
    do i = 1, nscan
      ang(i) = 2.0_dp*pi*(i - 1)/nscan
      pl(i) = plastic(ang(i))
      if (allocated(err)) return
    end do
    ncut = 0
    do i = 1, nscan
      k = modulo(i, nscan) + 1
      if (pl(i) .neqv. pl(k)) then
        ncut = ncut + 1
        if (ncut > 2) exit
        a = ang(i)
        b = ang(i) + 2.0_dp*pi/nscan
        pa = pl(i)
        do it = 1, 50
          m = 0.5_dp*(a + b)
          pm = plastic(m)
          if (pm .eqv. pa) then
            a = m
          else
            b = m
          end if
        end do
        cut(ncut) = 0.5_dp*(a + b)
      end if
    end do
    if (ncut /= 2) then
      call new_error(err, status_invalid, 'at_leg', 'material "'//mat%label//'": the '// &
        'probed state is not on the yield surface with one loading half-plane (found '// &
        trim(adjustl(itoa(ncut)))//' loading/unloading boundaries in the Lode plane): '// &
        'probe a state reached by a plastic leg')
      return
    end if
    frame%boundary_deg = cut*180.0_dp/pi
    ! the middle of the plastic arc
    mid = 0.5_dp*(cut(1) + cut(2))
    if (.not. plastic(mid)) mid = mid + pi
    ! C:N in strain space: normal to the boundary, towards the plastic side
    qs = [-sin(cut(1)), cos(cut(1))]
    if (dot_product(qs, [cos(mid), sin(mid)]) < 0.0_dp) qs = -qs
    det = frame%c2(1, 1)*frame%c2(2, 2) - frame%c2(1, 2)*frame%c2(2, 1)
    inv = reshape([frame%c2(2, 2), -frame%c2(2, 1), -frame%c2(1, 2), frame%c2(1, 1)], [2, 2])/det
    ns = matmul(inv, qs)
    frame%n2 = ns/norm2(ns)
    frame%t2 = [frame%n2(2), -frame%n2(1)]
    if (frame%t2(1) > 0.0_dp) frame%t2 = -frame%t2

  contains

    logical function plastic(phi)
      real(dp), intent(in) :: phi
      real(dp) :: d(ntens), dsig(ntens), ce(ntens)
      d = cos(phi)*frame%e_z + sin(phi)*frame%e_r
      call probe(mat, s, d, eps, dsig, err)
      ce = matmul(c, d)
      plastic = norm_t(dsig - ce) > 1.0e-7_dp*norm_t(ce)
    end function plastic

  end subroutine find_lode_frame

  !> R(theta) (eq. 2.5) at the angles `theta` (radians) of the frame.
  subroutine rtheta_probe(mat, s, c, eps, frame, theta, r, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s
    real(dp), intent(in) :: c(ntens, ntens), eps
    type(lode_frame_t), intent(in) :: frame
    real(dp), intent(in) :: theta(:)
    real(dp), intent(out) :: r(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: d2(2), d(ntens), dsig(ntens)
    integer :: i
    do i = 1, size(theta)
      d2 = cos(theta(i))*frame%t2 + sin(theta(i))*frame%n2
      d = d2(1)*frame%e_z + d2(2)*frame%e_r
      call probe(mat, s, d, eps, dsig, err)
      if (allocated(err)) return
      r(i) = dot_product(d, dsig)/dot_product(d, matmul(c, d))
    end do
  end subroutine rtheta_probe

  !> Acoustic tensor A_ik = n_j T_ijkl n_l of the Abaqus-order tangent `t`
  !> (engineering shears: T_ijkl = t(v(ij), v(kl))) over a grid of unit
  !> normals n = (cos a, sin a cos b, sin a sin b), a in [0, 180], b in [0, 180).
  subroutine acoustic_probe(t, c, n_polar, n_azimuth, res, err)
    real(dp), intent(in) :: t(ntens, ntens), c(ntens, ntens)
    integer, intent(in) :: n_polar, n_azimuth
    type(acoustic_t), intent(out) :: res
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: n(3), a(3, 3), w(3), v(3, 3), wr(3), wi(3), scale
    integer :: i, j
    allocate (res%polar_deg(n_polar), res%azimuth_deg(n_azimuth))
    allocate (res%min_eig(n_polar, n_azimuth), res%max_imag(n_polar, n_azimuth))
    res%min_eig_global = huge(1.0_dp)
    res%elastic_min_eig = huge(1.0_dp)
    do i = 1, n_polar
      res%polar_deg(i) = 180.0_dp*(i - 1)/max(n_polar - 1, 1)
      do j = 1, n_azimuth
        res%azimuth_deg(j) = 180.0_dp*(j - 1)/n_azimuth
        n = unit_normal(res%polar_deg(i), res%azimuth_deg(j))
        a = acoustic(c, n)
        call sym_eigen(a, w, v, err)
        if (allocated(err)) return
        res%elastic_min_eig = min(res%elastic_min_eig, w(1))
        a = acoustic(t, n)
        call sym_eigen(0.5_dp*(a + transpose(a)), w, v, err)
        if (allocated(err)) return
        call general_eigenvalues(a, wr, wi, err)
        if (allocated(err)) return
        res%min_eig(i, j) = w(1)
        res%max_imag(i, j) = maxval(abs(wi))
        if (w(1) < res%min_eig_global) then
          res%min_eig_global = w(1)
          res%n_crit = n
        end if
      end do
    end do
    scale = max(res%elastic_min_eig, tiny(1.0_dp))
    res%loss_of_ellipticity = res%min_eig_global <= 0.0_dp
    res%flutter = any(res%max_imag > 1.0e-10_dp*scale)
  end subroutine acoustic_probe

  pure function unit_normal(polar_deg, azimuth_deg) result(n)
    real(dp), intent(in) :: polar_deg, azimuth_deg
    real(dp) :: n(3), a, b
    a = polar_deg*pi/180.0_dp
    b = azimuth_deg*pi/180.0_dp
    n = [cos(a), sin(a)*cos(b), sin(a)*sin(b)]
  end function unit_normal

  pure function acoustic(t, n) result(a)
    real(dp), intent(in) :: t(ntens, ntens), n(3)
    real(dp) :: a(3, 3)
    integer, parameter :: v(3, 3) = reshape([1, 4, 5, 4, 2, 6, 5, 6, 3], [3, 3])
    integer :: i, j, k, l
    a = 0.0_dp
    do i = 1, 3
      do k = 1, 3
        do j = 1, 3
          do l = 1, 3
            a(i, k) = a(i, k) + n(j)*t(v(i, j), v(k, l))*n(l)
          end do
        end do
      end do
    end do
  end function acoustic

  !> Uniaxial-strain wave speeds along axis 1 from `s`: the elastic speed
  !> from C_1111 and the plastic one from the probe response
  !> dsig_11/deps_11 of a strain increment `sign_`*eps*e_1 (sign_ = +1:
  !> extension, as the dissertation's tensile pulse).
  subroutine wave_speeds(mat, s, c, eps, sign_, c_e, c_p, mod_p, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s
    real(dp), intent(in) :: c(ntens, ntens), eps, sign_
    real(dp), intent(out) :: c_e, c_p, mod_p
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: d(ntens), dsig(ntens)
    d = 0.0_dp
    d(1) = sign(1.0_dp, sign_)
    call probe(mat, s, d, eps, dsig, err)
    if (allocated(err)) return
    mod_p = dsig(1)*d(1)
    c_e = sqrt(c(1, 1)/mat%density)
    c_p = sqrt(max(mod_p, 0.0_dp)/mat%density)
  end subroutine wave_speeds

  !> Gudehus envelope from `s`: for n directions phi (degrees from the
  !> hydrostatic compression axis, eq. 3.5) apply the stress increment
  !> (size*cos phi, size*sin phi) in compression-positive Lode components
  !> under full stress control, record the total strain increment, unload
  !> to the start stress and record the residual (plastic) strain.
  subroutine gudehus_probe(mat, s, solver, size_, n_sub, phi_deg, dsig2, deps2, depsp2, err)
    type(material_t), intent(in) :: mat
    type(point_state_t), intent(in) :: s
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: size_, phi_deg(:)
    integer, intent(in) :: n_sub
    real(dp), intent(out) :: dsig2(:, :), deps2(:, :), depsp2(:, :)
    type(error_t), allocatable, intent(out) :: err
    type(point_state_t) :: sp
    type(leg_t) :: leg
    type(solver_t) :: quiet
    integer :: i
    real(dp) :: phi
    quiet = solver
    quiet%verbose = .false.
    leg%stress_control = .true.
    leg%n_inc = n_sub
    leg%duration = 1.0_dp
    do i = 1, size(phi_deg)
      phi = phi_deg(i)*pi/180.0_dp
      dsig2(i, :) = size_*[cos(phi), sin(phi)]
      sp = s
      leg%target = s%stress + from_lode2(dsig2(i, :))
      call run_leg(mat, sp, leg, i, quiet, err)
      if (allocated(err)) then
        err%message = 'Gudehus probe at phi = '//value_text(phi_deg(i))//' deg: '//err%message
        return
      end if
      deps2(i, :) = lode2(sp%strain - s%strain)
      leg%target = s%stress
      call run_leg(mat, sp, leg, i, quiet, err)
      if (allocated(err)) then
        err%message = 'Gudehus unloading at phi = '//value_text(phi_deg(i))//' deg: '//err%message
        return
      end if
      depsp2(i, :) = lode2(sp%strain - s%strain)
    end do
  end subroutine gudehus_probe

  pure real(dp) function norm_t(v)
    real(dp), intent(in) :: v(ntens)
    ! tensor norm of a stress-like Abaqus-order vector (each shear twice)
    norm_t = sqrt(sum(v(1:3)**2) + 2.0_dp*sum(v(4:6)**2))
  end function norm_t

  pure function itoa(i) result(text)
    integer, intent(in) :: i
    character(len=12) :: text
    write (text, '(i0)') i
  end function itoa

end module wellposed_point_probes
