!> An output of an MPM run as a component of the one run loop
!> (wellposed_mpm_run_loop): it starts with its case, samples the scene
!> after every step, finishes after the last, puts its lines into the
!> summary and its datasets into run.h5, and puts and gets its own state in
!> a checkpoint under its own name. The loop asks every output of a list in
!> the list's order. How to add one: docs/guide/mpm.md.
module wellposed_mpm_output
  use wellposed_error, only: error_t
  use wellposed_mpi, only: comm_t
  use wellposed_mpm_scene, only: mpm_scene_t
  use wellposed_checkpoint, only: checkpoint_t
  use wellposed_summary, only: summary_t
  use wellposed_h5_parallel, only: h5_parallel_file_t
  implicit none
  private
  public :: mpm_output_t, output_list_t, stage_start, stage_sample, stage_finish

  !> The moments the loop asks every output of a list (output_list_t%ask).
  integer, parameter :: stage_start = 1, stage_sample = 2, stage_finish = 3

  !> One output; `name` prefixes its checkpoint entries ('<name>/...').
  !> Every procedure but summarise is collective (called on every rank).
  type, abstract :: mpm_output_t
    character(len=:), allocatable :: name
  contains
    procedure :: start => output_nothing       !< a fresh case, before its first step
    procedure :: sample => output_nothing      !< after every step
    procedure :: finish => output_nothing      !< after the last step
    procedure :: summarise => output_no_lines  !< rank 0: its summary lines
    procedure :: write_h5 => output_no_h5      !< its datasets, at the end
    procedure(put_i), deferred :: put
    procedure(get_i), deferred :: get
  end type mpm_output_t

  abstract interface
    !> Into `ck` (on rank 0, which writes it; the others may take part).
    subroutine put_i(self, ck, comm)
      import :: mpm_output_t, checkpoint_t, comm_t
      class(mpm_output_t), intent(inout) :: self
      type(checkpoint_t), intent(inout) :: ck
      type(comm_t), intent(inout) :: comm
    end subroutine put_i
    !> Back from `ck` (every rank holds the whole checkpoint).
    subroutine get_i(self, ck, comm, err)
      import :: mpm_output_t, checkpoint_t, comm_t, error_t
      class(mpm_output_t), intent(inout) :: self
      type(checkpoint_t), intent(in) :: ck
      type(comm_t), intent(inout) :: comm
      type(error_t), allocatable, intent(out) :: err
    end subroutine get_i
  end interface

  type :: output_ref_t
    class(mpm_output_t), pointer :: o => null()
  end type output_ref_t

  !> The outputs of a case, in the order they are asked (the owner keeps
  !> the outputs themselves, as targets).
  type :: output_list_t
    type(output_ref_t), allocatable :: items(:)
  contains
    procedure :: add => list_add
    procedure :: ask => list_ask
    procedure :: summarise => list_summarise
    procedure :: write_h5 => list_write_h5
    procedure :: put => list_put
    procedure :: get => list_get
  end type output_list_t

contains

  subroutine output_nothing(self, sc, comm, err)
    class(mpm_output_t), intent(inout) :: self
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
  end subroutine output_nothing

  subroutine output_no_lines(self, sm)
    class(mpm_output_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
  end subroutine output_no_lines

  subroutine output_no_h5(self, h5)
    class(mpm_output_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
  end subroutine output_no_h5

  !> Append output `o` (a target its owner keeps).
  subroutine list_add(self, o)
    class(output_list_t), intent(inout) :: self
    class(mpm_output_t), target, intent(inout) :: o
    type(output_ref_t) :: r
    if (.not. allocated(self%items)) allocate (self%items(0))
    r%o => o
    self%items = [self%items, r]
  end subroutine list_add

  !> Every output's start, sample or finish (`stage`), in the list's
  !> order; the first error stops the round.
  subroutine list_ask(self, stage, sc, comm, err)
    class(output_list_t), intent(inout) :: self
    integer, intent(in) :: stage
    type(mpm_scene_t), intent(in) :: sc
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    do k = 1, size(self%items)
      select case (stage)
      case (stage_start)
        call self%items(k)%o%start(sc, comm, err)
      case (stage_sample)
        call self%items(k)%o%sample(sc, comm, err)
      case default
        call self%items(k)%o%finish(sc, comm, err)
      end select
      if (allocated(err)) return
    end do
  end subroutine list_ask

  subroutine list_summarise(self, sm)
    class(output_list_t), intent(inout) :: self
    type(summary_t), intent(inout) :: sm
    integer :: k
    do k = 1, size(self%items)
      call self%items(k)%o%summarise(sm)
    end do
  end subroutine list_summarise

  subroutine list_write_h5(self, h5)
    class(output_list_t), intent(inout) :: self
    type(h5_parallel_file_t), intent(inout) :: h5
    integer :: k
    do k = 1, size(self%items)
      call self%items(k)%o%write_h5(h5)
    end do
  end subroutine list_write_h5

  subroutine list_put(self, ck, comm)
    class(output_list_t), intent(inout) :: self
    type(checkpoint_t), intent(inout) :: ck
    type(comm_t), intent(inout) :: comm
    integer :: k
    do k = 1, size(self%items)
      call self%items(k)%o%put(ck, comm)
    end do
  end subroutine list_put

  !> Every output back from `ck`; an error names the output.
  subroutine list_get(self, ck, comm, err)
    class(output_list_t), intent(inout) :: self
    type(checkpoint_t), intent(in) :: ck
    type(comm_t), intent(inout) :: comm
    type(error_t), allocatable, intent(out) :: err
    integer :: k
    do k = 1, size(self%items)
      call self%items(k)%o%get(ck, comm, err)
      if (allocated(err)) then
        err%message = 'output '//self%items(k)%o%name//': '//err%message
        return
      end if
    end do
  end subroutine list_get

end module wellposed_mpm_output
