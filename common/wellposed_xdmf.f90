!> XDMF (version 2) descriptions of the particle snapshots in run.h5, so
!> that ParaView (File > Open, "Xdmf Reader") shows a run's particles as a
!> point cloud over time: a temporal collection of Polyvertex grids, one
!> per snapshot, whose heavy data stay in run.h5 (the XDMF file only names
!> the datasets). Both MPM programs write one beside run.h5.
module wellposed_xdmf
  use wellposed_kinds, only: dp
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_text, only: int_text, real_text
  use wellposed_checked_io, only: out_file_t
  implicit none
  private
  public :: write_particle_xdmf

contains

  !> Write `path`, describing `size(groups)` snapshots of `n` particles:
  !> snapshot j is the group `groups(j)` (ending in '/') of the HDF5 file
  !> `h5_name` (as seen from the XDMF file's folder), at time `times(j)` (s).
  !> Positions are the group's dataset `geometry`: an (n, 2) array when
  !> `ndim` = 2; n abscissae when `ndim` = 1, drawn on the x axis (the
  !> reader computes y = 0 * x, nothing more is stored). Every name in
  !> `fields` is a dataset of n values in each group, shown as a point
  !> attribute. A failed write (wellposed_checked_io) is an error naming it.
  subroutine write_particle_xdmf(path, h5_name, grid_name, groups, times, n, ndim, geometry, &
                                 fields, err)
    character(len=*), intent(in) :: path, h5_name, grid_name, geometry
    character(len=*), intent(in) :: groups(:), fields(:)
    real(dp), intent(in) :: times(:)
    integer, intent(in) :: n, ndim
    type(error_t), allocatable, intent(out) :: err
    type(out_file_t) :: out
    integer :: j, f
    character(len=:), allocatable :: g, item, nn

    if (size(times) /= size(groups) .or. .not. (ndim == 1 .or. ndim == 2)) then
      call new_error(err, status_invalid, 'xdmf', path//': '//int_text(size(groups))// &
        ' snapshot groups, '//int_text(size(times))//' times, ndim = '//int_text(ndim)// &
        ' (1 or 2)')
      return
    end if
    call out%open(path, err)
    if (allocated(err)) return
    nn = int_text(n)
    item = '<DataItem Dimensions="'//nn//'" Format="HDF" NumberType="Float" Precision="8">'
    call put('<?xml version="1.0" ?>')
    call put('<Xdmf Version="2.0">')
    call put(' <Domain>')
    call put('  <Grid Name="'//grid_name//'" GridType="Collection" CollectionType="Temporal">')
    do j = 1, size(groups)
      g = h5_name//':/'//trim(groups(j))
      call put('   <Grid Name="'//grid_name//'_'//int_text(j)//'" GridType="Uniform">')
      call put('    <Time Value="'//real_text(times(j))//'"/>')
      call put('    <Topology TopologyType="Polyvertex" NumberOfElements="'//nn//'"/>')
      if (ndim == 2) then
        call put('    <Geometry GeometryType="XY">')
        call put('     <DataItem Dimensions="'//nn//' 2" Format="HDF" NumberType="Float" '// &
                 'Precision="8">'//g//geometry//'</DataItem>')
      else
        call put('    <Geometry GeometryType="X_Y">')
        call put('     '//item//g//geometry//'</DataItem>')
        call put('     <DataItem ItemType="Function" Function="0*$0" Dimensions="'//nn//'">')
        call put('      '//item//g//geometry//'</DataItem>')
        call put('     </DataItem>')
      end if
      call put('    </Geometry>')
      do f = 1, size(fields)
        call put('    <Attribute Name="'//trim(fields(f))//'" Center="Node">')
        call put('     '//item//g//trim(fields(f))//'</DataItem>')
        call put('    </Attribute>')
      end do
      call put('   </Grid>')
    end do
    call put('  </Grid>')
    call put(' </Domain>')
    call put('</Xdmf>')
    call out%close(err)

  contains

    subroutine put(line)
      character(len=*), intent(in) :: line
      call out%put(line)
    end subroutine put

  end subroutine write_particle_xdmf

end module wellposed_xdmf
