#pragma once
/// The cell test's boundary (host/triax/periodic_triaxial.hpp): the periodic cell itself, or a cuboid between six rigid,
/// frictionless plane walls (the set-up of YADE's TriaxialStressController and of most walled DEM studies).
/// The servo and the records see the same few quantities of either:
///   lengths L_d      periodic: the cell's sides; walls: the distance between the two walls normal to d
///   stress sigma_dd  periodic: Love-Weber of the ball-ball contacts over the cell's volume (the specimen's
///                    interior); walls: the mean normal force on the two walls over the face area L_e L_f, as a
///                    walled test measures it at its boundary
///   stiffness K_dd   periodic: (1/V) sum_c kn l_d^2 (Simulation::cell_stiffness); walls: k_d L_d / (2 A_d), k_d
///                    the mean over the two walls of sum kn of their contacts: moving each wall in by L_d deps / 2
///                    loads it by at most k_d L_d deps / 2 (the balls behind it held still), so K_dd bounds
///                    d sigma_dd / d eps_dd from above, as the periodic one does, and the servo's alpha <= 1 keeps its
///                    loop stable
///   rates            periodic: the cell's homogeneous strain rate; walls: each wall moves at rate_d L_d / 2,
///                    away from the centre for a positive (extension) rate
/// Walls are numbered x-, x+, y-, y+, z-, z+ (cell_walls); a walled cell has no periodic axis.
#include <array>
#include <memory>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/builder.hpp"

namespace dem {

class Simulation;

/// True for a cell between six walls (cell_walls), false for a periodic cell.
bool walled(const Simulation& sim);

/// The six plane walls of a cuboid [0, cell) (box_walls): x-, x+, y-, y+, z-, z+, normals into the box, material 1.
std::vector<WallSpec> cell_walls(const std::array<Real, 3>& cell);

/// The lower corner (m): the periodic cell's domain.lo, the walled cell's x-, y- and z- walls.
Vec3 cell_corner(const Simulation& sim);
/// L_d (m).
std::array<Real, 3> cell_lengths(const Simulation& sim);
/// L_x L_y L_z (m^3).
Real cell_volume(const Simulation& sim);
/// sigma_dd (Pa, compression positive) on the boundary's definition above.
std::array<Real, 3> cell_stress(Simulation& sim);
/// K_dd (Pa) on the boundary's definition above.
std::array<Real, 3> boundary_stiffness(Simulation& sim);
/// Sets the strain rates (1/s, extension positive) of the next steps.
void set_cell_rates(Simulation& sim, const Vec3& rate);
/// The strain rates set last (1/s).
Vec3 cell_rates(const Simulation& sim);

}  // namespace dem
