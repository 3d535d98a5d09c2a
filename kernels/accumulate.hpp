#pragma once
/// Deterministic accumulation, no floating-point atomics, so a run is bit-for-bit the same for any
/// thread count:
///  - a ball-ball contact is evaluated by its owner, particle 1 (the lower gid): the owner sums its own
///    side in key order while the kernel runs, and stores the reaction for particle 2;
///  - every particle then gathers the reactions of the contacts it does not own, and its wall contacts,
///    through a particle -> contact list sorted by contact index (Gather, called inside integration).
#include "contact_list.hpp"
#include "particles.hpp"
#include "vec3.hpp"

namespace dem {

/// Particle -> contact list (CSR), entries in ascending contact order.
struct Adjacency {
  IndexView offset;   ///< n + 1
  IndexView entry;    ///< contact index
};

/// Adjacency of n particles to the contacts whose gathering side is `side(k)` (c.j for ball-ball
/// reactions, c.i for ball-wall contacts).
Adjacency build_adjacency(int n, const ContactList& c, const IndexView& side);

/// Contacts owned by each particle: [own(i,0), own(i,1)) in the key-sorted ball-ball list. Contiguous
/// because keys start with the owner's gid.
Index2View owner_ranges(const Particles& p, const ContactList& balls);

/// Completes a particle's force and moment: its own side (already in p.f, p.m), minus the reactions of
/// ball-ball contacts it is particle 2 of, plus its wall contacts.
struct Gather {
  ConstVec3View own_f, own_m;
  ConstVec3View bfc, bmt, wfc, wmt;
  ConstIndexView boff, bent, woff, went;

  KOKKOS_INLINE_FUNCTION void operator()(const int i, Vec3& f, Vec3& m) const {
    f = load(own_f, i);
    m = load(own_m, i);
    for (int a = boff(i); a < boff(i + 1); ++a) {
      f -= load(bfc, bent(a));
      m += load(bmt, bent(a));
    }
    for (int a = woff(i); a < woff(i + 1); ++a) {
      f += load(wfc, went(a));
      m += load(wmt, went(a));
    }
  }
};

Gather make_gather(const Particles& p, const ContactList& balls, const Adjacency& adj_balls, const ContactList& walls,
                   const Adjacency& adj_walls);

/// Offsets of each wall object's contacts in the (key-sorted) ball-wall list: nobj + 1 entries.
IndexView object_offsets(const ContactList& walls, int nobj);

/// Force on each wall object (N), the reaction of its contacts, summed in key order.
void wall_forces_into(const ContactList& walls, const IndexView& offsets, Vec3View& out);

}  // namespace dem
