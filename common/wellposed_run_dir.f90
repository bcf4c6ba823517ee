!> One run's output folder, written so that an interrupted run never leaves
!> a folder that looks finished: everything goes into `<root>/<name>.partial/`,
!> and `commit` renames it to `<root>/<name>/` (rename(2), atomic on one file
!> system) only when the run has succeeded. An older finished `<name>/` is
!> replaced; a stale `<name>.partial/` from a crashed run is removed first.
module wellposed_run_dir
  use wellposed_error, only: error_t, new_error, status_invalid
  use wellposed_fs, only: make_dirs, make_dir, remove_tree, rename_path, path_exists, &
                          process_id, int_text
  use wellposed_deck, only: read_text_file
  use wellposed_checked_io, only: out_file_t
  implicit none
  private
  public :: run_dir_t

  !> A run folder being written (create ... commit).
  type :: run_dir_t
    character(len=:), allocatable :: root     !< parent folder of the run folder
    character(len=:), allocatable :: name     !< the finished folder's name
    character(len=:), allocatable :: partial  !< <root>/<name>.partial
    character(len=:), allocatable :: final    !< <root>/<name>
    logical :: committed = .false.
  contains
    procedure :: create => run_dir_create
    procedure :: path => run_dir_path
    procedure :: commit => run_dir_commit
  end type run_dir_t

contains

  !> Make `<root>/<name>.partial/` (removing a stale one; creating `root`
  !> when missing) and copy the deck file `deck_path` into it under its
  !> own base name.
  subroutine run_dir_create(self, root, name, deck_path, err)
    class(run_dir_t), intent(inout) :: self
    character(len=*), intent(in) :: root, name, deck_path
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: text
    type(out_file_t) :: copy
    integer :: slash
    if (len_trim(name) == 0 .or. index(name, '/') > 0) then
      call new_error(err, status_invalid, 'name', 'run name "'//name// &
        '" must be non-empty and contain no "/"')
      return
    end if
    self%root = trim(root)
    if (len(self%root) == 0) self%root = '.'
    self%name = trim(name)
    self%final = self%root//'/'//self%name
    self%partial = self%final//'.partial'
    self%committed = .false.
    call make_dirs(self%root, err)
    if (allocated(err)) return
    call remove_tree(self%partial, err)
    if (allocated(err)) return
    call make_dir(self%partial, err)
    if (allocated(err)) return
    call read_text_file(deck_path, text, err)
    if (allocated(err)) return
    slash = index(deck_path, '/', back=.true.)
    call copy%open(self%path(deck_path(slash + 1:)), err)
    if (allocated(err)) return
    call copy%put_bytes(text)
    call copy%close(err)
  end subroutine run_dir_create

  !> Full path of `filename` inside the folder being written.
  function run_dir_path(self, filename) result(full)
    class(run_dir_t), intent(in) :: self
    character(len=*), intent(in) :: filename
    character(len=:), allocatable :: full
    full = self%partial//'/'//filename
  end function run_dir_path

  !> Rename `<name>.partial` to `<name>`, replacing an older finished one.
  subroutine run_dir_commit(self, err)
    class(run_dir_t), intent(inout) :: self
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: old
    if (.not. allocated(self%partial)) then
      call new_error(err, status_invalid, 'run_dir', 'commit before create')
      return
    end if
    if (path_exists(self%final)) then
      ! rename(2) does not replace a non-empty folder: move the old one aside.
      old = self%final//'.old.'//int_text(process_id())
      call rename_path(self%final, old, err)
      if (allocated(err)) return
      call rename_path(self%partial, self%final, err)
      if (allocated(err)) return
      call remove_tree(old, err)
    else
      call rename_path(self%partial, self%final, err)
    end if
    if (.not. allocated(err)) self%committed = .true.
  end subroutine run_dir_commit

end module wellposed_run_dir
