!> The state of a running MPM scene in a checkpoint (wellposed_checkpoint)
!> and back (--restart). What the next step reads is saved bit
!> for bit: time, step count, time step, the bookkeeping sums and every
!> particle field but the connectivity (rebuilt from x at the start of a
!> step) and Algorithm 1's run totals; the grid is not, because every step
!> rebuilds it from the particles. A scene restored into a fresh `new_scene` of the same deck
!> therefore continues exactly as the uninterrupted run would.
!>
!> Entries are named `mpm/<field>`; particle fields are flattened in
!> Fortran order over the particles in use, in their local order, with the
!> leading extents (ndim, nstatv, 3x3) saved beside them, so a checkpoint
!> of a different layout is refused instead of misread.
module wellposed_mpm_restart
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_mpm_particles, only: particles_t, ensure_capacity, particle_record_length, &
                                     pack_particle, unpack_particle
  use wellposed_mpm_solver, only: mpm_scene_t
  use wellposed_mpm_decomposition, only: decomposition_t, owner_of_position
  use wellposed_mpi, only: comm_t, gatherv_real, allreduce_max
  implicit none
  private
  public :: save_scene, restore_scene, put_particles, get_particles, save_scene_ranks, &
            restore_scene_ranks

  !> Version of the entries below; a restart refuses any other.
  integer, parameter :: layout_version = 2   !< 2: with the nonlocal totals

contains

  !> Put the particles in use (all fields but the connectivity) under
  !> `prefix` (e.g. 'mpm/').
  subroutine put_particles(ckpt, prefix, parts)
    type(checkpoint_t), intent(inout) :: ckpt
    character(len=*), intent(in) :: prefix
    type(particles_t), intent(in) :: parts
    integer :: n
    n = parts%n
    call ckpt%put(prefix//'layout', [parts%n, parts%ndim, parts%nsup, parts%nstatv])
    call ckpt%put(prefix//'gid', parts%gid(1:n))
    call ckpt%put(prefix//'x0', reshape(parts%x0(:, 1:n), [parts%ndim*n]))
    call ckpt%put(prefix//'x', reshape(parts%x(:, 1:n), [parts%ndim*n]))
    call ckpt%put(prefix//'v', reshape(parts%v(:, 1:n), [parts%ndim*n]))
    call ckpt%put(prefix//'lp', reshape(parts%lp(:, 1:n), [parts%ndim*n]))
    call ckpt%put(prefix//'mass', parts%mass(1:n))
    call ckpt%put(prefix//'vol0', parts%vol0(1:n))
    call ckpt%put(prefix//'vol', parts%vol(1:n))
    call ckpt%put(prefix//'defgrad', reshape(parts%defgrad(:, :, 1:n), [9*n]))
    call ckpt%put(prefix//'stress', reshape(parts%stress(:, 1:n), [6*n]))
    call ckpt%put(prefix//'stran', reshape(parts%stran(:, 1:n), [6*n]))
    call ckpt%put(prefix//'statev', reshape(parts%statev(:, 1:n), [parts%nstatv*n]))
  end subroutine put_particles

  !> Overwrite `parts` (allocated with the same ndim, nsup and nstatv) with
  !> the particles saved under `prefix`; capacity grows when needed.
  subroutine get_particles(ckpt, prefix, parts, err)
    type(checkpoint_t), intent(in) :: ckpt
    character(len=*), intent(in) :: prefix
    type(particles_t), intent(inout) :: parts
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: layout(:), ids(:)
    real(dp), allocatable :: a(:)
    integer :: n, d, ns
    call ckpt%get(prefix//'layout', layout, err)
    if (allocated(err)) return
    if (size(layout) /= 4) then
      call new_error(err, status_invalid, 'checkpoint', 'particle layout entry is garbled')
      return
    end if
    n = layout(1)
    d = layout(2)
    ns = layout(4)
    if (d /= parts%ndim .or. layout(3) /= parts%nsup .or. ns /= parts%nstatv) then
      call new_error(err, status_invalid, 'checkpoint', 'the checkpoint''s particles have '// &
        'ndim, nsup, nstatv = '//int_text(d)//', '//int_text(layout(3))//', '// &
        int_text(ns)//'; this scene has '//int_text(parts%ndim)//', '// &
        int_text(parts%nsup)//', '//int_text(parts%nstatv)//' (another deck?)')
      return
    end if
    parts%n = 0
    call ensure_capacity(parts, n)
    parts%n = n
    call ckpt%get(prefix//'gid', ids, err); if (allocated(err)) return
    if (.not. fits(size(ids), n)) return
    parts%gid(1:n) = ids
    call ckpt%get(prefix//'x0', a, err); if (allocated(err)) return
    if (.not. fits(size(a), d*n)) return
    parts%x0(:, 1:n) = reshape(a, [d, n])
    call ckpt%get(prefix//'x', a, err); if (allocated(err)) return
    if (.not. fits(size(a), d*n)) return
    parts%x(:, 1:n) = reshape(a, [d, n])
    call ckpt%get(prefix//'v', a, err); if (allocated(err)) return
    if (.not. fits(size(a), d*n)) return
    parts%v(:, 1:n) = reshape(a, [d, n])
    call ckpt%get(prefix//'lp', a, err); if (allocated(err)) return
    if (.not. fits(size(a), d*n)) return
    parts%lp(:, 1:n) = reshape(a, [d, n])
    call ckpt%get(prefix//'mass', a, err); if (allocated(err)) return
    if (.not. fits(size(a), n)) return
    parts%mass(1:n) = a
    call ckpt%get(prefix//'vol0', a, err); if (allocated(err)) return
    if (.not. fits(size(a), n)) return
    parts%vol0(1:n) = a
    call ckpt%get(prefix//'vol', a, err); if (allocated(err)) return
    if (.not. fits(size(a), n)) return
    parts%vol(1:n) = a
    call ckpt%get(prefix//'defgrad', a, err); if (allocated(err)) return
    if (.not. fits(size(a), 9*n)) return
    parts%defgrad(:, :, 1:n) = reshape(a, [3, 3, n])
    call ckpt%get(prefix//'stress', a, err); if (allocated(err)) return
    if (.not. fits(size(a), 6*n)) return
    parts%stress(:, 1:n) = reshape(a, [6, n])
    call ckpt%get(prefix//'stran', a, err); if (allocated(err)) return
    if (.not. fits(size(a), 6*n)) return
    parts%stran(:, 1:n) = reshape(a, [6, n])
    call ckpt%get(prefix//'statev', a, err); if (allocated(err)) return
    if (.not. fits(size(a), ns*n)) return
    parts%statev(:, 1:n) = reshape(a, [ns, n])
    parts%node(:, 1:n) = 0
    parts%phi(:, 1:n) = 0.0_dp
    parts%grad(:, :, 1:n) = 0.0_dp
  contains
    logical function fits(got, want)
      integer, intent(in) :: got, want
      fits = got == want
      if (.not. fits) call new_error(err, status_invalid, 'checkpoint', 'a particle field '// &
        'of the checkpoint has '//int_text(got)//' values, expected '//int_text(want))
    end function fits
  end subroutine get_particles

  !> Put the state of `scene` into `ckpt` (see the module comment).
  subroutine save_scene(scene, ckpt)
    type(mpm_scene_t), intent(in) :: scene
    type(checkpoint_t), intent(inout) :: ckpt
    call ckpt%put('mpm/layout_version', layout_version)
    call ckpt%put('mpm/nstep', scene%nstep)
    call ckpt%put('mpm/max_substeps', scene%max_substeps)
    call ckpt%put('mpm/scalars', [scene%t, scene%dt, scene%work_internal, &
                                  scene%work_external, scene%impulse, scene%kinetic0, &
                                  scene%momentum0, scene%cfg%dx, scene%modulus_dt])
    call ckpt%put('mpm/nonlocal_totals', [scene%nl%steps_iterated, scene%nl%iterations_total, &
                                          scene%nl%iterations_max])
    call put_particles(ckpt, 'mpm/', scene%parts)
  end subroutine save_scene

  !> Continue `scene`, freshly built by new_scene from the deck of the run
  !> that wrote `ckpt`, from the saved state. A checkpoint of another
  !> layout, cell size or time step is refused with the reason. (The step
  !> sizes its per-particle workspace to the restored particles itself.)
  subroutine restore_scene(scene, ckpt, err)
    type(mpm_scene_t), intent(inout) :: scene
    type(checkpoint_t), intent(in) :: ckpt
    type(error_t), allocatable, intent(out) :: err
    integer :: version
    real(dp), allocatable :: s(:)
    integer, allocatable :: totals(:)
    call ckpt%get('mpm/layout_version', version, err)
    if (allocated(err)) return
    if (version /= layout_version) then
      call new_error(err, status_invalid, 'checkpoint', 'MPM checkpoint layout '// &
        int_text(version)//', this program reads '//int_text(layout_version))
      return
    end if
    call ckpt%get('mpm/scalars', s, err)
    if (allocated(err)) return
    if (size(s) /= 9) then
      call new_error(err, status_invalid, 'checkpoint', 'MPM scalars entry is garbled')
      return
    end if
    if (s(8) /= scene%cfg%dx .or. s(2) /= scene%dt) then
      call new_error(err, status_invalid, 'checkpoint', 'the checkpoint was written with '// &
        'dx = '//real_text(s(8))//' m and dt = '//real_text(s(2))//' s; this deck gives '// &
        real_text(scene%cfg%dx)//' m and '//real_text(scene%dt)//' s: restart with the '// &
        'deck (and overrides) of the interrupted run')
      return
    end if
    call get_particles(ckpt, 'mpm/', scene%parts, err)
    if (allocated(err)) return
    call ckpt%get('mpm/nstep', scene%nstep, err)
    if (allocated(err)) return
    call ckpt%get('mpm/max_substeps', scene%max_substeps, err)
    if (allocated(err)) return
    scene%t = s(1)
    scene%work_internal = s(3)
    scene%work_external = s(4)
    scene%impulse = s(5)
    scene%kinetic0 = s(6)
    scene%momentum0 = s(7)
    ! Algorithm 1's run totals (the summary's iteration counts)
    call ckpt%get('mpm/nonlocal_totals', totals, err)
    if (allocated(err)) return
    if (size(totals) /= 3) then
      call new_error(err, status_invalid, 'checkpoint', 'the nonlocal totals are garbled')
      return
    end if
    scene%nl%steps_iterated = totals(1)
    scene%nl%iterations_total = totals(2)
    scene%nl%iterations_max = totals(3)
  end subroutine restore_scene

  !> save_scene for a scene spread over the ranks of `comm` (collective):
  !> rank 0 receives every rank's particles, concatenated in rank order
  !> with the rank that held each (`mpm/rank`), and every rank's partial
  !> sums (internal and external work, impulse: `mpm/partials`, 3 per
  !> rank); `ckpt` is filled on rank 0 only (others get nothing to write).
  subroutine save_scene_ranks(scene, comm, ckpt)
    type(mpm_scene_t), intent(in) :: scene
    type(comm_t), intent(in) :: comm
    type(checkpoint_t), intent(inout) :: ckpt
    type(particles_t) :: all
    real(dp), allocatable :: rec(:), recs(:), partials(:)
    integer, allocatable :: counts(:), owner(:)
    integer :: reclen, p, n, q, k, substeps
    reclen = particle_record_length(scene%parts)
    allocate (rec(reclen*scene%parts%n))
    do p = 1, scene%parts%n
      call pack_particle(scene%parts, p, rec((p - 1)*reclen + 1:p*reclen))
    end do
    call gatherv_real(comm, rec, recs, 0, counts)
    call gatherv_real(comm, [scene%work_internal, scene%work_external, scene%impulse], &
                      partials, 0)
    substeps = scene%max_substeps
    call allreduce_max(comm, substeps)
    if (comm%rank /= 0) return
    n = size(recs)/reclen
    all%ndim = scene%parts%ndim
    all%nsup = scene%parts%nsup
    all%nstatv = scene%parts%nstatv
    call ensure_capacity(all, n)
    allocate (owner(n))
    k = 0
    do q = 0, comm%size - 1
      owner(k + 1:k + counts(q)/reclen) = q
      k = k + counts(q)/reclen
    end do
    do p = 1, n
      call unpack_particle(all, p, recs((p - 1)*reclen + 1:p*reclen))
    end do
    all%n = n
    call save_scene(scene, ckpt)
    call put_particles(ckpt, 'mpm/', all)
    call ckpt%put('mpm/max_substeps', substeps)
    call ckpt%put('mpm/rank', owner)
    call ckpt%put('mpm/partials', partials)
  end subroutine save_scene_ranks

  !> restore_scene for a scene spread over the ranks of `comm` by `dec`
  !> (every rank holds the whole checkpoint). Written on as many ranks as
  !> now: every rank takes back exactly its particles in their order and
  !> its partial sums, so the run continues bit for bit. Written on another
  !> number of ranks: every rank takes the particles of its cells in
  !> global-id order, and rank 0 the summed partials (the continuation then
  !> differs from the uninterrupted run by the order of additions only).
  subroutine restore_scene_ranks(scene, dec, comm, ckpt, err)
    type(mpm_scene_t), intent(inout) :: scene
    type(decomposition_t), intent(in) :: dec
    type(comm_t), intent(in) :: comm
    type(checkpoint_t), intent(in) :: ckpt
    type(error_t), allocatable, intent(out) :: err
    type(particles_t) :: all
    integer, allocatable :: owner(:), order(:)
    real(dp), allocatable :: partials(:), rec(:)
    integer :: nsaved, p, m, reclen
    call restore_scene(scene, ckpt, err)      ! scalars; particles redone below
    if (allocated(err)) return
    call ckpt%get('mpm/rank', owner, err)
    if (allocated(err)) return
    call ckpt%get('mpm/partials', partials, err)
    if (allocated(err)) return
    all%ndim = scene%parts%ndim
    all%nsup = scene%parts%nsup
    all%nstatv = scene%parts%nstatv
    call ensure_capacity(all, 1)
    call get_particles(ckpt, 'mpm/', all, err)
    if (allocated(err)) return
    nsaved = size(partials)/3
    if (size(owner) /= all%n .or. nsaved*3 /= size(partials) .or. nsaved < 1) then
      call new_error(err, status_invalid, 'checkpoint', 'the rank entries of the MPM '// &
        'checkpoint do not match its particles')
      return
    end if
    ! the order to take particles in: as saved, or by global id
    allocate (order(all%n))
    if (nsaved == comm%size) then
      order = [(p, p=1, all%n)]
    else
      order = 0
      do p = 1, all%n
        if (all%gid(p) < 1 .or. all%gid(p) > all%n) then
          call new_error(err, status_invalid, 'checkpoint', 'particle ids of the MPM '// &
            'checkpoint are not 1 .. '//int_text(all%n))
          return
        end if
        order(all%gid(p)) = p
      end do
    end if
    reclen = particle_record_length(all)
    allocate (rec(reclen))
    scene%parts%n = 0
    m = 0
    do p = 1, all%n
      if (nsaved == comm%size) then
        if (owner(order(p)) /= comm%rank) cycle
      else
        if (owner_of_position(dec, all%x(dec%axis, order(p))) /= comm%rank) cycle
      end if
      m = m + 1
      call ensure_capacity(scene%parts, m)
      call pack_particle(all, order(p), rec)
      call unpack_particle(scene%parts, m, rec)
    end do
    scene%parts%n = m
    if (nsaved == comm%size) then
      scene%work_internal = partials(3*comm%rank + 1)
      scene%work_external = partials(3*comm%rank + 2)
      scene%impulse = partials(3*comm%rank + 3)
    else if (comm%rank == 0) then
      scene%work_internal = sum(partials(1::3))
      scene%work_external = sum(partials(2::3))
      scene%impulse = sum(partials(3::3))
    else
      scene%work_internal = 0.0_dp
      scene%work_external = 0.0_dp
      scene%impulse = 0.0_dp
    end if
  end subroutine restore_scene_ranks

end module wellposed_mpm_restart
