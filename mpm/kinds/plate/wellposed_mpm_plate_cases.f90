!> The cases of a plate deck (&study: meshes, sizes): each case's name and
!> configuration, what a finished case leaves for the files written at the
!> end (and its form in a checkpoint), and a case's measures and tables: the
!> width of a localized band (FWHM of the plastic strain along a line), the
!> distance between two stress-strain curves, the curve and iteration CSVs.
module wellposed_mpm_plate_cases
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_checked_io, only: out_file_t
  use wellposed_mpm_plate_build, only: plate_config_t
  use wellposed_mpm_plate_deck, only: plate_study_t
  use wellposed_mpm_materials, only: scale_regions
  use wellposed_mpm_band, only: half_crossings
  implicit none
  private
  public :: case_out_t, case_tag, case_config, put_case_out, get_case_out, band_width, &
            curve_difference, write_csv_curve, write_csv_iterations

  !> What a finished case leaves for the files written at the end.
  type :: case_out_t
    character(len=:), allocatable :: tag
    real(dp), allocatable :: curve(:, :)     !< (time, strain, stress, sample)
    integer, allocatable :: its(:), nplast(:)
    real(dp), allocatable :: bounds(:, :)    !< (n_alpha, eq. 4.43 bound, error, step)
    !> dt, final time, sharp bound, wall time, peak (strain, stress), band FWHM
    !> along the line, band FWHM normal to the band (0: none measured)
    real(dp) :: scal(8) = 0.0_dp
    integer :: nsnap = 0, nparticles = 0, nsteps = 0
  end type case_out_t

  !> The checkpoint names of case_out_t%scal(1:8).
  character(len=16), parameter :: scal_names(8) = [character(len=16) :: 'dt', 't_final', &
    'bound_sharp', 'wall_time', 'peak_strain', 'peak_stress', 'band_fwhm', 'band_fwhm_normal']

contains

  !> Case k's name: its label, else h<dx>[_s<scale>].
  function case_tag(study, k) result(t)
    type(plate_study_t), intent(in) :: study
    integer, intent(in) :: k
    character(len=:), allocatable :: t
    t = trim(study%label(k))
    if (len(t) > 0) return
    t = 'h'//trim(short(study%dx(k)))
    if (study%scale(k) /= 1.0_dp) t = t//'_s'//trim(short(study%scale(k)))
  end function case_tag

  !> Case k's configuration: the deck's (cfg0) at the case's dx, the plate,
  !> weak zone and top velocity scaled by its scale (fig. 4.6).
  function case_config(cfg0, study, k) result(c)
    type(plate_config_t), intent(in) :: cfg0
    type(plate_study_t), intent(in) :: study
    integer, intent(in) :: k
    type(plate_config_t) :: c
    real(dp) :: f
    c = cfg0
    f = study%scale(k)
    c%dx = study%dx(k)
    c%width = cfg0%width*f
    c%height = cfg0%height*f
    call scale_regions(c%materials, f)
    c%top_velocity = cfg0%top_velocity*f
  end function case_config

  !> A finished case into checkpoint ck under the prefix pre, each value by
  !> name (arrays with a leading dummy entry, so that an empty one is still
  !> a dataset).
  subroutine put_case_out(ck, pre, o)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: pre
    type(case_out_t), intent(in) :: o
    integer :: k
    call ck%put_text(pre//'tag', o%tag)
    call ck%put(pre//'curve', [0.0_dp, reshape(o%curve, [size(o%curve)])])
    call ck%put(pre//'its', [0, o%its])
    call ck%put(pre//'nplast', [0, o%nplast])
    call ck%put(pre//'bounds', [0.0_dp, reshape(o%bounds, [size(o%bounds)])])
    do k = 1, size(o%scal)
      call ck%put(pre//trim(scal_names(k)), o%scal(k))
    end do
    call ck%put(pre//'nsnap', o%nsnap)
    call ck%put(pre//'nparticles', o%nparticles)
    call ck%put(pre//'nsteps', o%nsteps)
  end subroutine put_case_out

  !> The finished case that put_case_out stored under pre.
  subroutine get_case_out(ck, pre, o, err)
    type(checkpoint_t), intent(in) :: ck
    character(len=*), intent(in) :: pre
    type(case_out_t), intent(inout) :: o
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: iv(:)
    real(dp), allocatable :: a(:)
    integer :: k
    call ck%get_text(pre//'tag', o%tag, err); if (allocated(err)) return
    call ck%get(pre//'nsnap', o%nsnap, err); if (allocated(err)) return
    call ck%get(pre//'nparticles', o%nparticles, err); if (allocated(err)) return
    call ck%get(pre//'nsteps', o%nsteps, err); if (allocated(err)) return
    do k = 1, size(o%scal)
      call ck%get(pre//trim(scal_names(k)), o%scal(k), err); if (allocated(err)) return
    end do
    call ck%get(pre//'its', iv, err); if (allocated(err)) return
    o%its = iv(2:)
    call ck%get(pre//'nplast', iv, err); if (allocated(err)) return
    o%nplast = iv(2:)
    call ck%get(pre//'curve', a, err); if (allocated(err)) return
    o%curve = reshape(a(2:), [3, (size(a) - 1)/3])
    call ck%get(pre//'bounds', a, err); if (allocated(err)) return
    o%bounds = reshape(a(2:), [3, (size(a) - 1)/3])
  end subroutine get_case_out

  !> FWHM of ||eps^p|| along a line: axis 1, the horizontal line y = yl (m);
  !> axis 2, the vertical line x = yl. From the particles within
  !> half_spacing (half a particle spacing) of it, sorted along it; the
  !> half maximum crossings are interpolated linearly. Where a crossing lies
  !> beyond the body the body's edge counts.
  subroutine band_width(xy, ep, axis, yl, half_spacing, w, xpk, vpk)
    real(dp), intent(in) :: xy(:, :), ep(:)
    integer, intent(in) :: axis
    real(dp), intent(in) :: yl, half_spacing
    real(dp), intent(out) :: w, xpk, vpk
    real(dp), allocatable :: xs(:), vs(:)
    real(dp) :: half, xl, xr, tx, tv
    integer :: p, m, j, k, ipk, across
    allocate (xs(0), vs(0))
    across = 3 - axis
    do p = 1, size(ep)
      if (abs(xy(across, p) - yl) <= half_spacing) then
        xs = [xs, xy(axis, p)]
        vs = [vs, ep(p)]
      end if
    end do
    m = size(xs)
    w = 0.0_dp; xpk = 0.0_dp; vpk = 0.0_dp
    if (m < 3) return
    do j = 2, m
      tx = xs(j); tv = vs(j)
      k = j - 1
      do while (k >= 1)
        if (xs(k) <= tx) exit
        xs(k + 1) = xs(k); vs(k + 1) = vs(k)
        k = k - 1
      end do
      xs(k + 1) = tx; vs(k + 1) = tv
    end do
    ipk = maxloc(vs, dim=1)
    vpk = vs(ipk)
    xpk = xs(ipk)
    if (vpk <= 0.0_dp) return
    half = 0.5_dp*vpk
    xl = xs(1)
    xr = xs(m)
    call half_crossings(xs, vs, ipk, half, xl, xr)
    w = xr - xl
  end subroutine band_width

  !> Max |stress_b(e) - stress_a(e)| (Pa) over the common strain range,
  !> curve b interpolated linearly at a's strains.
  pure real(dp) function curve_difference(ca, cb) result(d)
    real(dp), intent(in) :: ca(:, :), cb(:, :)   !< (time, strain, stress) per sample
    integer :: j, k, na, nb
    real(dp) :: e, sb, emax
    d = 0.0_dp
    na = min(size(ca, 2), 20000)
    nb = min(size(cb, 2), 20000)
    emax = min(ca(2, na), cb(2, nb))
    k = 1
    do j = 1, na
      e = ca(2, j)
      if (e > emax) exit
      do while (k < nb - 1 .and. cb(2, k + 1) < e)
        k = k + 1
      end do
      if (cb(2, k + 1) == cb(2, k)) cycle
      sb = cb(3, k) + (e - cb(2, k))*(cb(3, k + 1) - cb(3, k))/(cb(2, k + 1) - cb(2, k))
      d = max(d, abs(sb - ca(3, j)))
    end do
  end function curve_difference

  subroutine write_csv_curve(path, c, err)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: c(:, :)
    type(error_t), allocatable, intent(out) :: err
    type(out_file_t) :: out
    integer :: j
    character(len=80) :: row
    call out%open(path, err)
    if (allocated(err)) return
    call out%put('time_s,apparent_strain,applied_stress_Pa')
    do j = 1, size(c, 2)
      write (row, '(es16.8,2(",",es16.8))') c(:, j)
      call out%put(trim(row))
    end do
    call out%close(err)
  end subroutine write_csv_curve

  !> One line per step with plastic particles: iterations, and the bounds
  !> of eq. 4.43 (the dissertation's with N_alpha, and the sharp one) of that step.
  subroutine write_csv_iterations(path, it, np, dt, b, sharp, err)
    character(len=*), intent(in) :: path
    integer, intent(in) :: it(:), np(:)
    real(dp), intent(in) :: dt, b(:, :), sharp
    type(error_t), allocatable, intent(out) :: err
    type(out_file_t) :: out
    integer :: j
    character(len=160) :: row
    call out%open(path, err)
    if (allocated(err)) return
    call out%put('step,time_s,plastic_particles,iterations,n_alpha,'// &
                 'lipschitz_eq4_43_printed,lipschitz_eq4_43_sharp,final_error')
    do j = 1, size(it)
      if (np(j) == 0) cycle
      write (row, '(i0,",",es14.6,",",i0,",",i0,4(",",es12.4))') j, j*dt, np(j), it(j), &
        b(1, j), b(2, j), sharp, b(3, j)
      call out%put(trim(row))
    end do
    call out%close(err)
  end subroutine write_csv_iterations

  !> x in at most 6 decimals without trailing zeros (0.03125, 2, 0.5).
  pure function short(x) result(text)
    real(dp), intent(in) :: x
    character(len=16) :: text
    write (text, '(f0.6)') x
    do while (len_trim(text) > 1 .and. text(len_trim(text):len_trim(text)) == '0')
      text(len_trim(text):len_trim(text)) = ' '
    end do
    if (text(len_trim(text):len_trim(text)) == '.') text(len_trim(text):len_trim(text)) = ' '
    if (text(1:1) == '.') text = '0'//text(1:len(text) - 1)
  end function short

end module wellposed_mpm_plate_cases
