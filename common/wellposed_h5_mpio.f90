!> The HDF5 calls that exist only in a parallel HDF5 build (Debian's
!> libhdf5-openmpi-dev): MPI-IO file access and collective transfers.
!> wellposed_h5_parallel reaches them only through this module; a build on
!> serial HDF5 compiles wellposed_h5_mpio_serial.f90 instead (the same
!> module, h5_mpio_available = .false.). Communicators arrive as integer
!> handles of the older MPI Fortran binding, which is what HDF5 1.10 takes.
module wellposed_h5_mpio
  use hdf5
  implicit none
  private
  public :: h5_mpio_available, h5_fapl_mpio, h5_dxpl_collective, h5_dxpl_was_collective

  !> True: this HDF5 can open a file on a communicator.
  logical, parameter :: h5_mpio_available = .true.

contains

  !> A new file access property list `fapl` for the MPI-IO driver on
  !> communicator `comm_f` (with info `info_f`), with metadata reads and
  !> writes collective (every rank makes the same metadata calls; one
  !> aggregated write instead of one per rank). hdferr /= 0 on failure.
  subroutine h5_fapl_mpio(comm_f, info_f, fapl, hdferr)
    integer, intent(in) :: comm_f, info_f
    integer(hid_t), intent(out) :: fapl
    integer, intent(out) :: hdferr
    call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, hdferr)
    if (hdferr == 0) call h5pset_fapl_mpio_f(fapl, comm_f, info_f, hdferr)
    if (hdferr == 0) call h5pset_all_coll_metadata_ops_f(fapl, .true., hdferr)
    if (hdferr == 0) call h5pset_coll_metadata_write_f(fapl, .true., hdferr)
  end subroutine h5_fapl_mpio

  !> A new data transfer property list `dxpl` with H5FD_MPIO_COLLECTIVE.
  subroutine h5_dxpl_collective(dxpl, hdferr)
    integer(hid_t), intent(out) :: dxpl
    integer, intent(out) :: hdferr
    call h5pcreate_f(H5P_DATASET_XFER_F, dxpl, hdferr)
    if (hdferr == 0) call h5pset_dxpl_mpio_f(dxpl, H5FD_MPIO_COLLECTIVE_F, hdferr)
  end subroutine h5_dxpl_collective

  !> After a transfer through `dxpl`: did HDF5 really do it collectively
  !> (it falls back to independent I/O for some selections)?
  logical function h5_dxpl_was_collective(dxpl) result(collective)
    integer(hid_t), intent(in) :: dxpl
    integer :: mode, hdferr
    call h5pget_mpio_actual_io_mode_f(dxpl, mode, hdferr)
    collective = hdferr == 0 .and. mode /= H5D_MPIO_NO_COLLECTIVE_F
  end function h5_dxpl_was_collective

end module wellposed_h5_mpio
