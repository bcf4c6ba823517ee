!> The state of a running plate (wellposed_mpm_plane_strain) in a
!> checkpoint (wellposed_checkpoint) and back (--restart), on any number of
!> ranks: time, step, time step, top displacement, the run totals of
!> Algorithm 1 and every particle (all fields but the connectivity, rebuilt
!> each step, with its viscous pressure and material) in every rank's
!> order. The grid is rebuilt every step, so this is all the next step
!> reads. Entries are named `ps/<field>`.
module wellposed_mpm_plate_restart
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_mpi, only: gatherv_real, allreduce_sum
  use wellposed_mpm_particles, only: particle_record_length, pack_particle, unpack_particle, &
                                     ensure_capacity
  use wellposed_mpm_decomposition, only: owner_of_position
  use wellposed_mpm_plane_strain, only: ps_scene_t, ps_max_substeps, ps_size_workspace
  implicit none
  private
  public :: ps_save, ps_restore

  !> Version of the checkpoint entries of ps_save; ps_restore refuses others.
  integer, parameter :: ps_layout_version = 1

contains

  !> Put the state of a running scene into `ckpt` (collective; `ckpt` is
  !> filled on rank 0 only): time, step, time step, top displacement, the
  !> run totals of Algorithm 1, and every particle (all fields but the
  !> connectivity, rebuilt each step, with its viscous pressure and
  !> material) in every rank's order, with the count each rank held. The
  !> grid is rebuilt every step, so this is all the next step reads.
  subroutine ps_save(self, ckpt)
    type(ps_scene_t), intent(in) :: self
    type(checkpoint_t), intent(inout) :: ckpt
    real(dp), allocatable :: rec(:), recs(:)
    integer, allocatable :: counts(:)
    integer :: plen, reclen, p, nsub, moved
    plen = particle_record_length(self%parts)
    reclen = plen + 2
    allocate (rec(reclen*self%parts%n))
    do p = 1, self%parts%n
      call pack_particle(self%parts, p, rec((p - 1)*reclen + 1:(p - 1)*reclen + plen))
      rec((p - 1)*reclen + plen + 1) = self%q(p)
      rec(p*reclen) = real(self%mat(p), dp)
    end do
    call gatherv_real(self%comm, rec, recs, 0, counts)
    nsub = ps_max_substeps(self)
    moved = self%moved
    if (self%dec%nranks > 1) call allreduce_sum(self%comm, moved)
    if (self%comm%rank /= 0) return
    call ckpt%put('ps/layout', [ps_layout_version, self%parts%ndim, self%parts%nsup, &
                                self%parts%nstatv, self%ntotal, self%comm%size, reclen])
    call ckpt%put('ps/counts', counts/reclen)
    call ckpt%put('ps/particles', recs)
    call ckpt%put('ps/scalars', [self%t, self%dt, self%top_disp, self%cfg%dx])
    call ckpt%put('ps/steps', [self%nstep, nsub, moved])
    call ckpt%put('ps/nonlocal', [self%nl%steps_iterated, self%nl%iterations_total, &
                                  self%nl%iterations_max, merge(1, 0, self%nl%warned_sharp), &
                                  merge(1, 0, self%nl%warned_printed)])
  end subroutine ps_save

  !> Continue `self`, freshly built by new_ps_scene from the deck of the run
  !> that wrote `ckpt` (every rank holds the whole checkpoint). Saved on as
  !> many ranks as now: every rank takes back its particles in their order,
  !> and the run continues bit for bit. Saved on another number: every rank
  !> takes the particles of its cell rows in global-id order (the
  !> continuation then differs by the order of nodal additions only). A
  !> checkpoint of another layout, cell size or time step is refused.
  subroutine ps_restore(self, ckpt, err)
    type(ps_scene_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ckpt
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: layout(:), counts(:), steps(:), nl(:), order(:)
    real(dp), allocatable :: recs(:), sc(:)
    integer :: plen, reclen, nsaved, first, p, m, g, k
    call ckpt%get('ps/layout', layout, err)
    if (allocated(err)) return
    plen = particle_record_length(self%parts)
    if (size(layout) /= 7) then
      call bad('its plane-strain layout entry is garbled'); return
    end if
    if (layout(1) /= ps_layout_version) then
      call bad('plane-strain checkpoint layout '//int_text(layout(1))//', this program '// &
               'reads '//int_text(ps_layout_version)); return
    end if
    if (layout(2) /= self%parts%ndim .or. layout(3) /= self%parts%nsup .or. &
        layout(4) /= self%parts%nstatv .or. layout(5) /= self%ntotal .or. &
        layout(7) /= plen + 2) then
      call bad('it holds '//int_text(layout(5))//' particles with nsup, nstatv = '// &
               int_text(layout(3))//', '//int_text(layout(4))//'; this deck gives '// &
               int_text(self%ntotal)//', '//int_text(self%parts%nsup)//', '// &
               int_text(self%parts%nstatv)//' (another deck?)'); return
    end if
    reclen = layout(7)
    nsaved = layout(6)
    call ckpt%get('ps/scalars', sc, err); if (allocated(err)) return
    if (size(sc) /= 4) then
      call bad('its scalars entry is garbled'); return
    end if
    if (sc(4) /= self%cfg%dx .or. sc(2) /= self%dt) then
      call bad('it was written with dx = '//real_text(sc(4))//' m and dt = '// &
               real_text(sc(2))//' s; this deck gives '//real_text(self%cfg%dx)//' m and '// &
               real_text(self%dt)//' s: restart with the deck (and overrides) of the '// &
               'interrupted run'); return
    end if
    call ckpt%get('ps/counts', counts, err); if (allocated(err)) return
    call ckpt%get('ps/particles', recs, err); if (allocated(err)) return
    call ckpt%get('ps/steps', steps, err); if (allocated(err)) return
    call ckpt%get('ps/nonlocal', nl, err); if (allocated(err)) return
    if (size(counts) /= nsaved .or. sum(counts) /= self%ntotal .or. &
        size(recs) /= reclen*self%ntotal .or. size(steps) /= 3 .or. size(nl) /= 5) then
      call bad('its particle entries do not match its layout'); return
    end if
    ! which saved records this rank takes, in which order
    if (nsaved == self%comm%size) then
      first = sum(counts(1:self%comm%rank))
      order = [(first + p, p=1, counts(self%comm%rank + 1))]
    else
      allocate (order(self%ntotal))
      order = 0
      do p = 1, self%ntotal
        g = nint(recs((p - 1)*reclen + 1))
        if (g < 1 .or. g > self%ntotal) then
          call bad('its particle ids are not 1 .. '//int_text(self%ntotal)); return
        end if
        order(g) = p
      end do
      m = 0
      do k = 1, self%ntotal
        p = order(k)
        if (p == 0) then
          call bad('its particle ids are not 1 .. '//int_text(self%ntotal)); return
        end if
        if (owner_of_position(self%dec, recs((p - 1)*reclen + 1 + self%parts%ndim + self%dec%axis)) &
            /= self%dec%rank) cycle
        m = m + 1
        order(m) = p
      end do
      order = order(1:m)
    end if
    m = size(order)
    self%parts%n = 0
    call ensure_capacity(self%parts, m)
    call ps_size_workspace(self)
    do k = 1, m
      p = order(k)
      call unpack_particle(self%parts, k, recs((p - 1)*reclen + 1:(p - 1)*reclen + plen))
      self%q(k) = recs((p - 1)*reclen + plen + 1)
      self%mat(k) = nint(recs(p*reclen))
    end do
    self%parts%n = m
    self%t = sc(1)
    self%top_disp = sc(3)
    self%nstep = steps(1)
    self%max_substeps = steps(2)
    self%moved = 0
    if (self%comm%rank == 0) self%moved = steps(3)
    self%nl%steps_iterated = nl(1)
    self%nl%iterations_total = nl(2)
    self%nl%iterations_max = nl(3)
    self%nl%warned_sharp = nl(4) == 1
    self%nl%warned_printed = nl(5) == 1
  contains
    subroutine bad(why)
      character(len=*), intent(in) :: why
      call new_error(err, status_invalid, 'checkpoint', 'the checkpoint cannot continue this '// &
                     'scene: '//why)
    end subroutine bad
  end subroutine ps_restore
end module wellposed_mpm_plate_restart
