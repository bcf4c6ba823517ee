!> wellposed_h5_mpio for serial HDF5 (Debian's libhdf5-dev): the same
!> module, h5_mpio_available = .false.; every call fails (hdferr = -1), and
!> wellposed_h5_parallel never makes them, gathering to rank 0 instead.
module wellposed_h5_mpio
  use hdf5, only: hid_t
  implicit none
  private
  public :: h5_mpio_available, h5_fapl_mpio, h5_dxpl_collective, h5_dxpl_was_collective

  !> False: this HDF5 has no MPI-IO driver.
  logical, parameter :: h5_mpio_available = .false.

contains

  !> Not available: hdferr = -1.
  subroutine h5_fapl_mpio(comm_f, info_f, fapl, hdferr)
    integer, intent(in) :: comm_f, info_f
    integer(hid_t), intent(out) :: fapl
    integer, intent(out) :: hdferr
    fapl = -1
    hdferr = -1
  end subroutine h5_fapl_mpio

  !> Not available: hdferr = -1.
  subroutine h5_dxpl_collective(dxpl, hdferr)
    integer(hid_t), intent(out) :: dxpl
    integer, intent(out) :: hdferr
    dxpl = -1
    hdferr = -1
  end subroutine h5_dxpl_collective

  !> Never collective.
  logical function h5_dxpl_was_collective(dxpl) result(collective)
    integer(hid_t), intent(in) :: dxpl
    collective = .false.
  end function h5_dxpl_was_collective

end module wellposed_h5_mpio
