#pragma once
/// The membrane test's cell: two platens, the membrane and the specimen's balls in one simulation, with what the
/// test's stages and records ask of it (host/triax/triaxial.cpp).
#include <memory>
#include <utility>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/membrane_mesh.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/specimen.hpp"

namespace dem {

enum Platen { kBottomPlaten = 0, kTopPlaten = 1 };

/// The test cell: two platens, the membrane (sides tangent to the mould, so no ball starts inside a
/// facet) and the specimen's balls.
struct Cell {
  std::unique_ptr<Simulation> sim;
  Membrane membrane;
  Real radius = 0, area = 0;  ///< m, m^2: mould radius and platen area
  Real kn_wall = 0;           ///< N/m, platen contact stiffness of a mean ball
  Real solid_volume = 0;      ///< m^3
  Real mean_radius = 0;       ///< m
};

Cell make_cell(const Config& cfg, const Specimen& sp);
/// Moves the top platen and the membrane's top ring together (the ring is tied to the platen).
void set_top_velocity(Cell& c, Real vz);
/// Axial stresses on the two platens (Pa, compression positive) from the wall forces `f`.
std::pair<Real, Real> platen_stresses(const Cell& c, const std::vector<Vec3>& f);
/// The volume the membrane and the platens enclose (m^3).
Real specimen_volume(const Cell& c);

}  // namespace dem
