!> The state of a running MPM scene (bar or plate) in a checkpoint and back
!> (--restart), on any number of ranks: time, step, time step, every rank's
!> partial sums and the kind's scalars (scene_kind_t), Algorithm 1's totals
!> and every particle (a Newmark run's with its acceleration), bit for bit. Entries `mpm/<field>`, one per value (the
!> layout's sizes, t, dt, nstep, ...) beside the particle records and the
!> kind's own arrays; another layout, cell size or time step is refused.
!> Called by wellposed_mpm_checkpoints; design: docs/guide/parallel.md.
module wellposed_mpm_restart
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_mpm_particles, only: particle_record_length, pack_particle, unpack_particle, &
                                     ensure_capacity
  use wellposed_mpm_scene, only: mpm_scene_t, size_workspace, max_substeps
  implicit none
  private
  public :: save_scene, restore_scene

  !> Version of the entries below; a restart refuses any other.
  !> 3: one layout for bars and plates; 4: every value an entry of its own,
  !> the kind's partial sums and scalars (mpm/partials, mpm/kind_scalars) its own
  integer, parameter :: layout_version = 4
  !> The real entries of a scene, as restore_scene reads them into sc(1:3).
  character(len=2), parameter :: real_names(3) = [character(len=2) :: 't', 'dt', 'dx']

contains

  !> Put the state of `scene` into `ckpt` (collective; `ckpt` is filled on
  !> rank 0 only, the others get nothing to write).
  subroutine save_scene(scene, ckpt)
    type(mpm_scene_t), intent(inout) :: scene
    type(checkpoint_t), intent(inout) :: ckpt
    real(dp), allocatable :: rec(:), recs(:), partials(:)
    integer, allocatable :: counts(:), pcounts(:)
    integer :: plen, reclen, p, nsub, moved, na, k
    plen = particle_record_length(scene%parts)
    na = accel_rows(scene)
    reclen = plen + 2 + na
    allocate (rec(reclen*scene%parts%n))
    do p = 1, scene%parts%n
      k = (p - 1)*reclen
      call pack_particle(scene%parts, p, rec(k + 1:k + plen))
      rec(k + plen + 1) = scene%q(p)
      rec(k + plen + 2) = real(scene%mat(p), dp)
      if (na > 0) rec(k + plen + 3:k + plen + 2 + na) = scene%accel(:, p)
    end do
    if (scene%exchange%nranks() == 1) then
      counts = [size(rec)]   ! one rank: the records are the checkpoint's, not copied
      call move_alloc(rec, recs)
    else
      call scene%exchange%gather_root(rec, recs, counts)
      deallocate (rec)
    end if
    call scene%exchange%gather_root(scene%kind%partial_sums(), partials, pcounts)
    nsub = max_substeps(scene)
    moved = scene%moved
    call scene%exchange%sum_int(moved)
    if (scene%exchange%rank() /= 0) return
    call ckpt%put('mpm/layout_version', layout_version)
    call ckpt%put('mpm/ndim', scene%parts%ndim)
    call ckpt%put('mpm/nsup', scene%parts%nsup)
    call ckpt%put('mpm/nstatv', scene%parts%nstatv)
    call ckpt%put('mpm/ntotal', scene%ntotal)
    call ckpt%put('mpm/nranks', size(counts))
    call ckpt%put('mpm/record_length', reclen)
    call ckpt%put('mpm/accel_rows', na)
    call ckpt%put('mpm/counts', counts/reclen)
    call ckpt%put_moved('mpm/particles', recs)
    call ckpt%put('mpm/partials', partials)
    call ckpt%put('mpm/t', scene%t)
    call ckpt%put('mpm/dt', scene%dt)
    call ckpt%put('mpm/dx', scene%dx)
    call ckpt%put('mpm/kind_scalars', scene%kind%scalars())
    call ckpt%put('mpm/nstep', scene%nstep)
    call ckpt%put('mpm/max_substeps', nsub)
    call ckpt%put('mpm/moved', moved)
    call ckpt%put('mpm/nl_steps_iterated', scene%nl%steps_iterated)
    call ckpt%put('mpm/nl_iterations_total', scene%nl%iterations_total)
    call ckpt%put('mpm/nl_iterations_max', scene%nl%iterations_max)
    call ckpt%put('mpm/nl_warned_sharp', merge(1, 0, scene%nl%warned_sharp))
    call ckpt%put('mpm/nl_warned_printed', merge(1, 0, scene%nl%warned_printed))
  end subroutine save_scene

  !> Continue `scene`, freshly built by new_scene from the deck of the run
  !> that wrote `ckpt` (every rank holds the whole checkpoint; collective
  !> only in its error values' agreement). Saved on as many ranks as now:
  !> every rank takes back its particles in their order and its partial
  !> sums, and the run continues bit for bit. Saved on another number: every
  !> rank takes the particles of its cell layers in global-id order and rank
  !> 0 the summed partials (the continuation then differs by the order of
  !> additions only).
  subroutine restore_scene(scene, ckpt, err)
    type(mpm_scene_t), intent(inout) :: scene
    type(checkpoint_t), intent(in) :: ckpt
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: counts(:), order(:)
    real(dp), allocatable :: recs(:), partials(:), kind_sc(:)
    integer :: layout(7), steps(3), nl(5)
    real(dp) :: sc(3)
    integer :: plen, reclen, nsaved, p, m, k, rank, nranks, npart, na, j
    call get_ints(ckpt, [character(len=24) :: 'layout_version', 'ndim', 'nsup', 'nstatv', &
                  'ntotal', 'nranks', 'record_length'], layout, err)
    if (allocated(err)) return
    rank = scene%exchange%rank()
    nranks = scene%exchange%nranks()
    plen = particle_record_length(scene%parts)
    if (layout(1) /= layout_version) then
      call refuse(err, 'MPM checkpoint layout '//int_text(layout(1))//', this program reads '// &
                  int_text(layout_version)); return
    end if
    reclen = layout(7)
    nsaved = layout(6)
    ! the accelerations of a Newmark run (none in a checkpoint before them)
    na = 0
    if (ckpt%has('mpm/accel_rows')) then
      call ckpt%get('mpm/accel_rows', na, err); if (allocated(err)) return
    end if
    if (na /= accel_rows(scene)) then
      call refuse(err, 'its particles carry '//int_text(na)//' acceleration components, '// &
        'this run '//int_text(accel_rows(scene))//': a checkpoint of a Newmark run '// &
        'continues a Newmark run only, and one of another scheme none'); return
    end if
    do k = 1, 3
      call ckpt%get('mpm/'//trim(real_names(k)), sc(k), err); if (allocated(err)) return
    end do
    npart = size(scene%kind%partial_sums())
    call ckpt%get('mpm/kind_scalars', kind_sc, err); if (allocated(err)) return
    if (size(kind_sc) /= size(scene%kind%scalars())) then
      call refuse(err, 'its kind_scalars entry is garbled'); return
    end if
    call check_scene_matches(scene, layout, sc, plen + na, err); if (allocated(err)) return
    call ckpt%get('mpm/counts', counts, err); if (allocated(err)) return
    call ckpt%get('mpm/particles', recs, err); if (allocated(err)) return
    call ckpt%get('mpm/partials', partials, err); if (allocated(err)) return
    call get_ints(ckpt, [character(len=24) :: 'nstep', 'max_substeps', 'moved'], steps, err)
    if (allocated(err)) return
    call get_ints(ckpt, [character(len=24) :: 'nl_steps_iterated', 'nl_iterations_total', &
                  'nl_iterations_max', 'nl_warned_sharp', 'nl_warned_printed'], nl, err)
    if (allocated(err)) return
    if (size(counts) /= nsaved .or. sum(counts) /= scene%ntotal .or. &
        size(recs) /= reclen*scene%ntotal .or. size(partials) /= npart*nsaved) then
      call refuse(err, 'its particle entries do not match its layout'); return
    end if
    call records_of_rank(scene, counts, recs, reclen, order, err); if (allocated(err)) return
    m = size(order)
    scene%parts%n = 0
    call ensure_capacity(scene%parts, m)
    call size_workspace(scene)
    if (na > 0) then
      deallocate (scene%accel)
      allocate (scene%accel(na, size(scene%parts%gid)), source=0.0_dp)
    end if
    do k = 1, m
      p = order(k)
      j = (p - 1)*reclen
      call unpack_particle(scene%parts, k, recs(j + 1:j + plen))
      scene%q(k) = recs(j + plen + 1)
      scene%mat(k) = nint(recs(j + plen + 2))
      if (na > 0) scene%accel(:, k) = recs(j + plen + 3:j + plen + 2 + na)
    end do
    scene%parts%n = m
    scene%t = sc(1)
    call scene%kind%set_scalars(kind_sc)
    scene%nstep = steps(1)
    scene%max_substeps = steps(2)
    scene%moved = 0
    if (rank == 0) scene%moved = steps(3)
    if (nsaved == nranks) then
      call scene%kind%set_partial_sums(partials(npart*rank + 1:npart*(rank + 1)))
    else if (rank == 0) then
      call scene%kind%set_partial_sums([(sum(partials(k::npart)), k=1, npart)])
    else
      call scene%kind%set_partial_sums([(0.0_dp, k=1, npart)])
    end if
    scene%nl%steps_iterated = nl(1)
    scene%nl%iterations_total = nl(2)
    scene%nl%iterations_max = nl(3)
    scene%nl%warned_sharp = nl(4) == 1
    scene%nl%warned_printed = nl(5) == 1
  end subroutine restore_scene

  !> The checkpoint's dx, dt (sc(3), sc(2)) and particle layout (layout:
  !> version, ndim, nsup, nstatv, ntotal, nranks, record length: plen + 2)
  !> against the scene the deck built: another deck or other overrides are
  !> refused.
  subroutine check_scene_matches(scene, layout, sc, plen, err)
    type(mpm_scene_t), intent(in) :: scene
    integer, intent(in) :: layout(7), plen
    real(dp), intent(in) :: sc(3)
    type(error_t), allocatable, intent(out) :: err
    if (sc(3) /= scene%dx .or. sc(2) /= scene%dt) then
      call new_error(err, status_invalid, 'checkpoint', 'the checkpoint was written with '// &
        'dx = '//real_text(sc(3))//' m and dt = '//real_text(sc(2))//' s; this deck gives '// &
        real_text(scene%dx)//' m and '//real_text(scene%dt)//' s: restart with the deck '// &
        '(and overrides) of the interrupted run')
      return
    end if
    if (layout(2) /= scene%parts%ndim .or. layout(3) /= scene%parts%nsup .or. &
        layout(4) /= scene%parts%nstatv .or. layout(5) /= scene%ntotal .or. &
        layout(7) /= plen + 2) then
      call refuse(err, 'it holds '//int_text(layout(5))//' particles with ndim, nsup, '// &
                  'nstatv = '//int_text(layout(2))//', '//int_text(layout(3))//', '// &
                  int_text(layout(4))//'; this deck gives '//int_text(scene%ntotal)//', '// &
                  int_text(scene%parts%ndim)//', '//int_text(scene%parts%nsup)//', '// &
                  int_text(scene%parts%nstatv)//' (another deck?)')
    end if
  end subroutine check_scene_matches

  !> Acceleration components a particle record carries: ndim in a Newmark
  !> run (scene%accel allocated), else 0.
  pure integer function accel_rows(scene) result(na)
    type(mpm_scene_t), intent(in) :: scene
    na = 0
    if (allocated(scene%accel)) na = size(scene%accel, 1)
  end function accel_rows

  !> Which saved records (1-based, `order`) this rank takes: saved on as
  !> many ranks as now, its own in their order; else those of its cell
  !> layers in global-id order (the ids must be 1 .. ntotal, each once).
  subroutine records_of_rank(scene, counts, recs, reclen, order, err)
    type(mpm_scene_t), intent(in) :: scene
    integer, intent(in) :: counts(:), reclen
    real(dp), intent(in) :: recs(:)
    integer, allocatable, intent(out) :: order(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: rank, first, p, g, k, m, d
    rank = scene%exchange%rank()
    d = scene%ndim
    if (size(counts) == scene%exchange%nranks()) then
      first = sum(counts(1:rank))
      order = [(first + p, p=1, counts(rank + 1))]
      return
    end if
    allocate (order(scene%ntotal))
    order = 0
    do p = 1, scene%ntotal
      g = nint(recs((p - 1)*reclen + 1))
      if (g < 1 .or. g > scene%ntotal) then
        call refuse(err, 'its particle ids are not 1 .. '//int_text(scene%ntotal)); return
      end if
      order(g) = p
    end do
    m = 0
    do k = 1, scene%ntotal
      p = order(k)
      if (p == 0) then
        call refuse(err, 'its particle ids are not 1 .. '//int_text(scene%ntotal)); return
      end if
      ! the record: gid, x0(d), x(d), ...
      if (scene%exchange%owner(recs((p - 1)*reclen + 1 + d + d)) /= rank) cycle
      m = m + 1
      order(m) = p
    end do
    order = order(1:m)
  end subroutine records_of_rank

  !> The integer entries mpm/<names(k)> of ckpt into v(k).
  subroutine get_ints(ckpt, names, v, err)
    type(checkpoint_t), intent(in) :: ckpt
    character(len=*), intent(in) :: names(:)
    integer, intent(out) :: v(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: j
    v = 0
    do j = 1, size(names)
      call ckpt%get('mpm/'//trim(names(j)), v(j), err)
      if (allocated(err)) return
    end do
  end subroutine get_ints

  !> The refusal of a checkpoint that cannot continue the scene, and why.
  subroutine refuse(err, why)
    type(error_t), allocatable, intent(inout) :: err
    character(len=*), intent(in) :: why
    call new_error(err, status_invalid, 'checkpoint', 'the checkpoint cannot continue this '// &
                   'scene: '//why)
  end subroutine refuse

end module wellposed_mpm_restart
