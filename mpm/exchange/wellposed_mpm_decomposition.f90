!> Domain decomposition of the MPM grid over ranks in one `use`: the
!> layout of strips and patches, owners and the cut of a serial run's grid
!> and particles (wellposed_mpm_decomposition_layout); sums and copies at
!> the nodes patches share (wellposed_mpm_decomposition_ghosts); particles
!> handed between ranks and gathered by id (wellposed_mpm_decomposition_hand_off).
!> Design: docs/guide/parallel.md.
module wellposed_mpm_decomposition
  use wellposed_mpm_decomposition_layout, only: decomposition_t, new_decomposition, &
                                                owner_of_layer, owner_of_position, &
                                                layer_of_position, restrict_grid, &
                                                restrict_particles, ghost_layers, patch_nodes
  use wellposed_mpm_decomposition_ghosts, only: sum_ghost_values, sum_ghost_grid, &
                                                copy_owned_to_ghosts
  use wellposed_mpm_decomposition_hand_off, only: hand_off_particles, hand_off_particles_with, &
                                                  gather_by_gid
  implicit none
  private
  public :: decomposition_t, new_decomposition, owner_of_layer, owner_of_position, &
            layer_of_position, restrict_grid, restrict_particles, hand_off_particles, &
            sum_ghost_values, sum_ghost_grid, copy_owned_to_ghosts, gather_by_gid, ghost_layers
  public :: patch_nodes, hand_off_particles_with
end module wellposed_mpm_decomposition
