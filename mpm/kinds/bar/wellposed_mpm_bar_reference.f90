!> The reference run of a bar deck (&output reference, reference_label):
!> another deck of the same folder, named by its file stem, which is its
!> &scene name. stations.png draws that deck's run ROOT/<reference>/run.h5
!> dashed on the same axes (the dissertation's convention in figs. 2.6,
!> 2.9 and 2.10 right); when the run has not been made yet the plot says so
!> and prints the command that makes it (mpm/plots/mpm_stations.py).
module wellposed_mpm_bar_reference
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: path_exists, shell_quote
  implicit none
  private
  public :: check_reference, reference_plot_args

  character(len=*), parameter :: stem_chars = &
    'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-'

contains

  !> The deck file of `reference`: REFERENCE.nml beside the deck `path`.
  pure function reference_deck(path, reference) result(deck)
    character(len=*), intent(in) :: path, reference
    character(len=:), allocatable :: deck
    deck = path(1:index(path, '/', back=.true.))//reference//'.nml'
  end function reference_deck

  !> Refuse a reference ('' = none) that is this deck itself (its &scene
  !> `name` or its own file) or that names no deck beside `path`.
  subroutine check_reference(path, name, reference, err)
    character(len=*), intent(in) :: path, name, reference
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: what
    if (len(reference) == 0) return
    what = path//": &output: reference = '"//reference//"' "
    if (reference == name .or. reference_deck(path, reference) == path) then
      call new_error(err, status_invalid, 'reference', what//'names this deck itself: '// &
        'the reference is another run, drawn dashed beside this one')
    else if (verify(reference, stem_chars) /= 0) then
      call new_error(err, status_invalid, 'reference', what//'must be the file stem of a '// &
        'deck in the same folder (letters, digits, "_", "." or "-")')
    else if (.not. path_exists(reference_deck(path, reference))) then
      call new_error(err, status_invalid, 'reference', what//'names no deck: '// &
        reference_deck(path, reference)//" does not exist (output.reference='' runs "// &
        'without a reference)')
    end if
  end subroutine check_reference

  !> The station plot's arguments for the reference ('' = none): the run
  !> ROOT/<reference>/run.h5, its label (default: the reference's name) and
  !> the command that makes it (this program on the reference deck).
  function reference_plot_args(root, path, reference, label) result(args)
    character(len=*), intent(in) :: root, path, reference, label
    character(len=:), allocatable :: args, program, make, show
    integer :: n
    args = ''
    if (len(reference) == 0) return
    call get_command_argument(0, length=n)
    allocate (character(len=n) :: program)
    call get_command_argument(0, program)
    make = program//' '
    if (root /= 'out') make = make//'--out '//shell_quote(root)//' '
    make = make//shell_quote(reference_deck(path, reference))
    show = reference
    if (len(label) > 0) show = label
    args = ' --reference '//shell_quote(root//'/'//reference//'/run.h5')//' '// &
           shell_quote(show)//' --make '//shell_quote(make)
  end function reference_plot_args

end module wellposed_mpm_bar_reference
