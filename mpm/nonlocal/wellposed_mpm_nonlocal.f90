!> The MPM's nonlocal package in one `use`: the &nonlocal settings
!> (wellposed_mpm_nonlocal_settings), the state Algorithm 1 keeps between
!> steps (wellposed_mpm_nonlocal_state), the grid-based average
!> (wellposed_mpm_nonlocal_grid), Algorithm 1 (wellposed_mpm_algorithm1)
!> and its sweep order (wellposed_mpm_sweep_order). The dissertation's
!> eq. 4.46-4.50; docs/guide/mpm.md, docs/research/theory.md.
module wellposed_mpm_nonlocal
  use wellposed_mpm_nonlocal_settings, only: nonlocal_settings_t, nl_fixed_point, nl_anderson, &
                                             nl_scheme_names, nl_scheme_id, ours_bounds, &
                                             nl_sweep_auto, nl_gauss_seidel, nl_jacobi, &
                                             nl_coloured, nl_sweep_names
  use wellposed_mpm_nonlocal_state, only: nonlocal_t, nonlocal_step_stats_t, new_nonlocal, &
                                          nonlocal_ghost_nodes
  use wellposed_mpm_nonlocal_grid, only: nonlocal_project, nonlocal_average
  use wellposed_mpm_algorithm1, only: nonlocal_host_t, nonlocal_solve
  use wellposed_mpm_nonlocal_ranks, only: nonlocal_ranks_t
  use wellposed_mpm_sweep_order, only: sweep_key
  implicit none
  private
  public :: nonlocal_settings_t, nonlocal_t, nonlocal_host_t, nonlocal_step_stats_t
  public :: new_nonlocal, nonlocal_solve, nonlocal_project, nonlocal_average
  public :: nl_fixed_point, nl_anderson, nl_scheme_names, nl_scheme_id, ours_bounds
  public :: nonlocal_ranks_t, nonlocal_ghost_nodes, sweep_key
  public :: nl_sweep_auto, nl_gauss_seidel, nl_jacobi, nl_coloured, nl_sweep_names
end module wellposed_mpm_nonlocal
