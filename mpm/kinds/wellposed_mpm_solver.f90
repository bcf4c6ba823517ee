!> The MPM's public entry: a scene of any kind (new_scene: a bar from its
!> bar_config_t, a plate from its plate_config_t), one explicit step
!> (wellposed_mpm_step's advance: section 4.3, no branch on the kind) and
!> the sums a run reports. It sits above the kinds: the engine below it
!> knows no kind (mpm/kinds/; docs/guide/mpm.md, "Scene kinds").
module wellposed_mpm_solver
  use wellposed_mpm_scene, only: mpm_scene_t, max_substeps, timer_transfer, timer_grid, &
                                 timer_umat, ntimers
  use wellposed_mpm_scene_sums, only: kinetic_energy, total_momentum, plastic_strain, &
                                      plastic_count
  use wellposed_mpm_step, only: advance
  use wellposed_mpm_bar_build, only: new_bar_scene, probe_moduli
  use wellposed_mpm_plate_build, only: new_plate_scene
  use wellposed_mpm_plate_kind, only: applied_stress
  implicit none
  private
  public :: mpm_scene_t, new_scene, advance, kinetic_energy, total_momentum, applied_stress, &
            plastic_strain, max_substeps, plastic_count, probe_moduli, timer_umat, &
            timer_transfer, timer_grid, ntimers

  !> A scene of a bar (bar_config_t) or a plate (plate_config_t).
  interface new_scene
    module procedure new_bar_scene, new_plate_scene
  end interface new_scene

end module wellposed_mpm_solver
