!> What the station histories need from a scene spread over ranks, so they
!> keep the serial values: gather_particles (every particle on rank 0, in
!> global-id order), gather_reference_positions (their x0 alone, to place
!> stations); station proxies, a small particle set refreshed every sample
!> by one exact reduction (the holder gives the value, the others zeros);
!> put_stations / get_stations, a stations_t in a checkpoint.
!> Particle snapshots go from every rank: wellposed_mpm_snapshots.
module wellposed_mpm_parallel_io
  use, intrinsic :: iso_fortran_env, only: int64
  use wellposed_kinds, only: dp
  use wellposed_out_of_memory, only: out_of_memory
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpi, only: comm_t, gatherv_real, broadcast, allreduce_sum
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_mpm_particles, only: particles_t, particle_record_length, pack_particle, &
                                     unpack_particle, ensure_capacity
  use wellposed_mpm_stations, only: stations_t, nfields, start_stations
  implicit none
  private
  public :: gather_particles, gather_reference_positions, station_proxy_t, &
            make_station_proxy, fill_station_proxy, start_proxied_stations, put_stations, &
            get_stations

  !> The particles the stations read, by global id, and their copies.
  type :: station_proxy_t
    integer, allocatable :: gids(:)     !< global ids, in proxy order
    integer, allocatable :: slot(:)     !< (global id) -> proxy index, 0 if none
    type(particles_t) :: parts          !< the copies (on every rank)
  end type station_proxy_t

contains

  !> Every rank's particles on `root` as `all`, in global-id order (ids
  !> 1..N, each once), connectivity zeroed; elsewhere `all` is empty.
  subroutine gather_particles(comm, parts, root, all)
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(in) :: parts
    integer, intent(in) :: root
    type(particles_t), intent(out) :: all
    real(dp), allocatable :: rec(:), recs(:)
    integer :: reclen, p, n, g, st
    reclen = particle_record_length(parts)
    allocate (rec(reclen*parts%n), stat=st)
    if (st /= 0) call out_of_memory('particle records', int(reclen, int64)*parts%n, st)
    do p = 1, parts%n
      call pack_particle(parts, p, rec((p - 1)*reclen + 1:p*reclen))
    end do
    call gatherv_real(comm, rec, recs, root)
    all%ndim = parts%ndim
    all%nsup = parts%nsup
    all%nstatv = parts%nstatv
    n = 0
    if (comm%rank == root) n = size(recs)/reclen
    call ensure_capacity(all, max(n, 1))
    do p = 1, n
      g = nint(recs((p - 1)*reclen + 1))
      call unpack_particle(all, g, recs((p - 1)*reclen + 1:p*reclen))
    end do
    all%n = n
  end subroutine gather_particles

  !> Re-point stations `st`, set up on rank 0 over the particles in
  !> global-id order (so st%pa, st%pb are global ids there), at a proxy of
  !> just the particles they read; every rank gets the same `st` indices
  !> and proxy. `ntotal` is the number of particles of the scene.
  subroutine make_station_proxy(st, comm, ntotal, like, proxy)
    type(stations_t), intent(inout) :: st
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: ntotal
    type(particles_t), intent(in) :: like      !< any particle set of the scene (extents)
    type(station_proxy_t), intent(out) :: proxy
    integer :: s, nst, k
    integer, allocatable :: ids(:)
    nst = st%n
    call broadcast(comm, nst, 0)
    allocate (ids(2*nst))
    if (comm%rank == 0) ids = [(st%pa(s), st%pb(s), s=1, nst)]
    call broadcast(comm, ids, 0)
    allocate (proxy%slot(ntotal))
    proxy%slot = 0
    allocate (proxy%gids(0))
    do k = 1, size(ids)
      if (proxy%slot(ids(k)) == 0) then
        proxy%gids = [proxy%gids, ids(k)]
        proxy%slot(ids(k)) = size(proxy%gids)
      end if
    end do
    if (comm%rank == 0) then
      do s = 1, st%n
        st%pa(s) = proxy%slot(st%pa(s))
        st%pb(s) = proxy%slot(st%pb(s))
      end do
    end if
    proxy%parts%ndim = like%ndim
    proxy%parts%nsup = like%nsup
    proxy%parts%nstatv = like%nstatv
    call ensure_capacity(proxy%parts, max(1, size(proxy%gids)))
    proxy%parts%n = size(proxy%gids)
  end subroutine make_station_proxy

  !> The reference positions x0(1:ndim, id) of every rank's particles on
  !> `root`, in global-id order (ids 1..N, each once); elsewhere x0(ndim, 0).
  subroutine gather_reference_positions(comm, parts, root, x0)
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(in) :: parts
    integer, intent(in) :: root
    real(dp), allocatable, intent(out) :: x0(:, :)
    real(dp), allocatable :: rec(:), recs(:)
    integer :: p, k, nd, n
    nd = parts%ndim
    allocate (rec((nd + 1)*parts%n))
    do p = 1, parts%n
      k = (p - 1)*(nd + 1)
      rec(k + 1) = real(parts%gid(p), dp)
      rec(k + 2:k + 1 + nd) = parts%x0(1:nd, p)
    end do
    call gatherv_real(comm, rec, recs, root)
    n = 0
    if (comm%rank == root) n = size(recs)/(nd + 1)
    allocate (x0(nd, n))
    do p = 1, n
      k = (p - 1)*(nd + 1)
      x0(:, nint(recs(k + 1))) = recs(k + 2:k + 1 + nd)
    end do
  end subroutine gather_reference_positions

  !> Stations `st` placed on rank 0 (global ids in pa, pb) start on the
  !> scene's particles `parts` spread over the ranks (collective): their
  !> proxy, filled, gives the first sample, as start_stations on every
  !> particle would; pa, pb become proxy slots.
  subroutine start_proxied_stations(st, comm, ntotal, parts, sample_dt, t_end, proxy)
    type(stations_t), intent(inout) :: st
    type(comm_t), intent(in) :: comm
    integer, intent(in) :: ntotal
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: sample_dt, t_end
    type(station_proxy_t), intent(out) :: proxy
    call make_station_proxy(st, comm, ntotal, parts, proxy)
    call fill_station_proxy(proxy, comm, parts)
    if (comm%rank == 0) call start_stations(st, proxy%parts, sample_dt, t_end)
  end subroutine start_proxied_stations

  !> Copy the proxied particles from whichever rank holds them into
  !> proxy%parts on every rank (collective; exact).
  subroutine fill_station_proxy(proxy, comm, parts)
    type(station_proxy_t), intent(inout) :: proxy
    type(comm_t), intent(in) :: comm
    type(particles_t), intent(in) :: parts
    real(dp), allocatable :: buf(:)
    integer :: reclen, p, k
    reclen = particle_record_length(parts)
    allocate (buf(reclen*size(proxy%gids)))
    buf = 0.0_dp
    do p = 1, parts%n
      if (parts%gid(p) > size(proxy%slot)) cycle
      k = proxy%slot(parts%gid(p))
      if (k > 0) call pack_particle(parts, p, buf((k - 1)*reclen + 1:k*reclen))
    end do
    call allreduce_sum(comm, buf)
    do k = 1, size(proxy%gids)
      call unpack_particle(proxy%parts, k, buf((k - 1)*reclen + 1:k*reclen))
    end do
  end subroutine fill_station_proxy

  !> The state of stations `st` under `prefix` (e.g. 'stations/').
  subroutine put_stations(ckpt, prefix, st)
    type(checkpoint_t), intent(inout) :: ckpt
    character(len=*), intent(in) :: prefix
    type(stations_t), intent(in) :: st
    call ckpt%put(prefix//'counts', [st%n, st%ns, size(st%time), nfields])
    call ckpt%put(prefix//'pa', st%pa)
    call ckpt%put(prefix//'pb', st%pb)
    call ckpt%put(prefix//'x', st%x)
    call ckpt%put(prefix//'wb', st%wb)
    call ckpt%put(prefix//'scalars', [st%sample_dt, st%t_prev])
    call ckpt%put(prefix//'time', st%time(1:st%ns))
    call ckpt%put(prefix//'hist', reshape(st%hist(:, :, 1:st%ns), [nfields*st%n*st%ns]))
    call ckpt%put(prefix//'prev', reshape(st%prev, [nfields*st%n]))
  end subroutine put_stations

  !> Stations `st` (built by new_stations for the same deck) back from
  !> `ckpt`; a checkpoint of another station layout is refused.
  subroutine get_stations(ckpt, prefix, st, err)
    type(checkpoint_t), intent(in) :: ckpt
    character(len=*), intent(in) :: prefix
    type(stations_t), intent(inout) :: st
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: counts(:), ia(:)
    real(dp), allocatable :: a(:)
    integer :: n, ns
    call ckpt%get(prefix//'counts', counts, err)
    if (allocated(err)) return
    if (size(counts) /= 4) then
      call bad('the station counts are garbled'); return
    end if
    n = counts(1)
    ns = counts(2)
    if (n /= st%n .or. counts(4) /= nfields .or. counts(3) /= size(st%time) .or. &
        ns > size(st%time) .or. ns < 0) then
      call bad('the checkpoint has another station layout (another deck?)'); return
    end if
    call ckpt%get(prefix//'pa', ia, err); if (allocated(err)) return
    if (size(ia) /= n) then
      call bad('pa'); return
    end if
    st%pa = ia
    call ckpt%get(prefix//'pb', ia, err); if (allocated(err)) return
    if (size(ia) /= n) then
      call bad('pb'); return
    end if
    st%pb = ia
    call ckpt%get(prefix//'x', a, err); if (allocated(err)) return
    if (size(a) /= n) then
      call bad('x'); return
    end if
    st%x = a
    call ckpt%get(prefix//'wb', a, err); if (allocated(err)) return
    if (size(a) /= n) then
      call bad('wb'); return
    end if
    st%wb = a
    call ckpt%get(prefix//'scalars', a, err); if (allocated(err)) return
    if (size(a) /= 2) then
      call bad('scalars'); return
    end if
    st%sample_dt = a(1)
    st%t_prev = a(2)
    call ckpt%get(prefix//'time', a, err); if (allocated(err)) return
    if (size(a) /= ns) then
      call bad('time'); return
    end if
    st%time(1:ns) = a
    call ckpt%get(prefix//'hist', a, err); if (allocated(err)) return
    if (size(a) /= nfields*n*ns) then
      call bad('hist'); return
    end if
    st%hist(:, :, 1:ns) = reshape(a, [nfields, n, ns])
    call ckpt%get(prefix//'prev', a, err); if (allocated(err)) return
    if (size(a) /= nfields*n) then
      call bad('prev'); return
    end if
    st%prev = reshape(a, [nfields, n])
    st%ns = ns
  contains
    subroutine bad(what)
      character(len=*), intent(in) :: what
      call new_error(err, status_invalid, 'checkpoint', 'station entry of the checkpoint '// &
        'refused: '//what)
    end subroutine bad
  end subroutine get_stations

end module wellposed_mpm_parallel_io
