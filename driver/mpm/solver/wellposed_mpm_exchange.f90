!> What a domain-decomposed run exchanges between ranks, behind two calls
!> the solver makes every step (issue 7 fills them with Open MPI):
!>  - sum_ghosts: add the ghost nodes' mass, momentum and forces into their
!>    owners and copy the sums back (serial: one patch, nothing to do);
!>  - hand_off: send particles whose support left this rank's patch to the
!>    rank that owns it (serial: there is none, so a particle whose support
!>    leaves the grid is an error naming it).
module wellposed_mpm_exchange
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_mpm_grid, only: grid_t
  use wellposed_mpm_particles, only: particles_t
  implicit none
  private
  public :: sum_ghosts, hand_off

contains

  !> Sum ghost-node contributions across patches (serial: no-op).
  subroutine sum_ghosts(grid)
    type(grid_t), intent(inout) :: grid
    ! Serial: the only patch owns every node, so there are no ghosts to sum.
    ! (This file is compiled with -Wno-unused-dummy-argument for that reason.)
  end subroutine sum_ghosts

  !> Particles whose support nodes lie outside [glo, ghi] after the
  !> connectivity was rebuilt. Serial: an error naming the first of them.
  subroutine hand_off(parts, grid, err)
    type(particles_t), intent(inout) :: parts
    type(grid_t), intent(in) :: grid
    type(error_t), allocatable, intent(out) :: err
    integer :: p
    character(len=160) :: buf
    if (minval(parts%node(:, 1:parts%n)) >= grid%glo .and. &
        maxval(parts%node(:, 1:parts%n)) <= grid%ghi) return
    do p = 1, parts%n
      if (minval(parts%node(:, p)) < grid%glo .or. maxval(parts%node(:, p)) > grid%ghi) exit
    end do
    write (buf, '(a,i0,a,es12.5,a,es12.5,a,es12.5,a)') 'particle ', parts%gid(p), &
      ' at x = ', parts%x(1, p), ' m left the grid [', &
      grid%origin + grid%glo*grid%dx, ', ', grid%origin + grid%ghi*grid%dx, '] m'
    call new_error(err, status_invalid, 'grid', trim(buf)//'; enlarge the grid '// &
      '(grid%pad_cells) or shorten the run')
  end subroutine hand_off

end module wellposed_mpm_exchange
