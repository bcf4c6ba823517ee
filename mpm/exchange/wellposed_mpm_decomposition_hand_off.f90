!> Particles between the ranks of the decomposition (wellposed_mpm_decomposition):
!> each to the rank owning its cell, in a deterministic order (stayers in
!> theirs, arrivals in the order of the sending ranks), with any data a
!> host keeps beside them; and particle values gathered in global-id order.
module wellposed_mpm_decomposition_hand_off
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpi, only: comm_t, alltoall_counts, alltoallv_real, allreduce_any, gatherv_real, &
                           gatherv_int, allreduce_sum
  use wellposed_mpm_particles, only: particles_t, copy_particle, particle_record_length, &
                                     pack_particle, unpack_particle, ensure_capacity
  use wellposed_mpm_decomposition_layout, only: decomposition_t, owner_of_position, &
                                                particle_left_grid
  implicit none
  private
  public :: hand_off_particles, hand_off_particles_with, gather_by_gid

contains

  !> Send every particle whose cell another rank owns to that rank, and take
  !> in the particles other ranks send here (collective). Stayers keep their
  !> order; arrivals are appended in the order of the sending ranks. A
  !> particle that left the grid is an error on every rank (the first rank
  !> to see one names it). `moved` counts the particles this rank sent.
  subroutine hand_off_particles(self, comm, parts, err, moved)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(inout) :: parts
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: moved
    real(dp), allocatable :: none(:, :)
    ! the same hand-off with no data beside particles_t (zero rows travel)
    allocate (none(0, size(parts%gid)))
    call hand_off_particles_with(self, comm, parts, none, err, moved)
  end subroutine hand_off_particles

  !> hand_off_particles for a host that keeps more per-particle data beside
  !> particles_t: extra(:, p) (any number of reals per particle, columns
  !> 1 .. parts%n in use) travels with particle p and ends in the same slot;
  !> it grows with the particles' capacity. Collective; same order rules.
  subroutine hand_off_particles_with(self, comm, parts, extra, err, moved)
    type(decomposition_t), intent(in) :: self
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(inout) :: parts
    real(dp), allocatable, intent(inout) :: extra(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: moved
    integer :: owner(parts%n), scount(0:comm%size - 1), rcount(0:comm%size - 1)
    integer :: sdispl(0:comm%size - 1), rdispl(0:comm%size - 1), fill(0:comm%size - 1)
    integer :: p, q, m, reclen, plen, ne, nin, bad
    real(dp), allocatable :: sbuf(:), rbuf(:), grown(:, :)
    plen = particle_record_length(parts)
    ne = size(extra, 1)
    reclen = plen + ne
    bad = 0
    scount = 0
    do p = 1, parts%n
      owner(p) = owner_of_position(self, parts%x(self%axis, p))
      if (owner(p) < 0) then
        if (bad == 0) bad = p
        owner(p) = self%rank
      end if
      if (owner(p) /= self%rank) scount(owner(p)) = scount(owner(p)) + 1
    end do
    if (allreduce_any(comm, bad > 0)) then
      if (bad > 0) then
        call particle_left_grid(self, parts, bad, err)
      else
        call new_error(err, status_invalid, 'grid', 'a particle on another rank left the grid')
      end if
      return
    end if
    if (present(moved)) moved = sum(scount)
    call alltoall_counts(comm, scount, rcount)
    scount = scount*reclen
    rcount = rcount*reclen
    sdispl(0) = 0
    rdispl(0) = 0
    do q = 1, comm%size - 1
      sdispl(q) = sdispl(q - 1) + scount(q - 1)
      rdispl(q) = rdispl(q - 1) + rcount(q - 1)
    end do
    allocate (sbuf(max(1, sum(scount))), rbuf(max(1, sum(rcount))))
    fill = sdispl
    m = 0
    do p = 1, parts%n
      q = owner(p)
      if (q /= self%rank) then
        call pack_particle(parts, p, sbuf(fill(q) + 1:fill(q) + plen))
        sbuf(fill(q) + plen + 1:fill(q) + reclen) = extra(:, p)
        fill(q) = fill(q) + reclen
      else
        m = m + 1
        if (m /= p) then
          call copy_particle(parts, p, m)
          extra(:, m) = extra(:, p)
        end if
      end if
    end do
    call alltoallv_real(comm, sbuf, scount, sdispl, rbuf, rcount, rdispl)
    nin = sum(rcount)/reclen
    parts%n = m
    call ensure_capacity(parts, m + nin)
    if (size(extra, 2) < size(parts%gid)) then
      allocate (grown(ne, size(parts%gid)))
      grown(:, 1:m) = extra(:, 1:m)
      call move_alloc(grown, extra)
    end if
    do p = 1, nin
      call unpack_particle(parts, m + p, rbuf((p - 1)*reclen + 1:(p - 1)*reclen + plen))
      extra(:, m + p) = rbuf((p - 1)*reclen + plen + 1:p*reclen)
    end do
    parts%n = m + nin
  end subroutine hand_off_particles_with

  !> Gather values(:, 1:n) of the local particles (ids gid(1:n)) onto
  !> `root` as all(:, 1:ntotal) in global-id order, the layout of a serial
  !> run. ntotal is the largest id; every id 1..ntotal must occur once.
  subroutine gather_by_gid(comm, gid, values, root, all)
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: gid(:)
    real(dp), intent(in) :: values(:, :)
    integer, intent(in) :: root
    real(dp), allocatable, intent(out) :: all(:, :)
    integer, allocatable :: ids(:)
    real(dp), allocatable :: flat(:)
    integer :: nc, p, ntot
    nc = size(values, 1)
    call gatherv_int(comm, gid, ids, root)
    call gatherv_real(comm, reshape(values, [nc*size(gid)]), flat, root)
    ntot = size(gid)
    call allreduce_sum(comm, ntot)
    if (comm%rank == root) then
      allocate (all(nc, ntot))
      all = 0.0_dp
      do p = 1, size(ids)
        all(:, ids(p)) = flat((p - 1)*nc + 1:p*nc)
      end do
    else
      allocate (all(nc, 0))
    end if
  end subroutine gather_by_gid

end module wellposed_mpm_decomposition_hand_off
