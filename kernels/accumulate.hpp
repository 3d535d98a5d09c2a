#pragma once
/// Deterministic accumulation: contact forces are computed per contact, then each particle gathers
/// its contacts' forces through a particle -> contact list in a fixed (sorted) order. No floating-point
/// atomics, so a run is bit-for-bit the same for any thread count.
#include "contact_list.hpp"
#include "particles.hpp"
#include "walls.hpp"

namespace dem {

/// Particle -> contact adjacency (CSR). entry = 2 * contact + role, role 0: particle 1, role 1: particle 2.
struct Adjacency {
  IndexView offset;   ///< n + 1
  IndexView entry;
};

/// Builds the adjacency of n particles from a contact list (roles 0 and 1 for ball-ball lists).
Adjacency build_adjacency(int n, const ContactList& c, bool two_sided);

/// f = sum of contact forces, m = sum of contact moments, over ball-ball and ball-wall contacts.
void gather_forces(Particles& p, const ContactList& balls, const Adjacency& adj_balls, const ContactList& walls,
                   const Adjacency& adj_walls);

/// Offsets of each wall object's contacts in the (key-sorted) ball-wall list: nobj + 1 entries.
IndexView object_offsets(const ContactList& walls, int nobj);

/// Force on each wall object (N), the reaction of its contacts, summed in key order.
void wall_forces_into(const ContactList& walls, const IndexView& offsets, Vec3View& out);

}  // namespace dem
