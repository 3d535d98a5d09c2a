#pragma once
/// Deterministic accumulation, no floating-point atomics, so a run is bit-for-bit the same for any
/// thread count:
///  - a ball-ball contact is evaluated once and stores both sides: the force and moment on its owner, particle 1
///    (the lower gid), and the reaction moment on particle 2;
///  - every particle then sums, inside integration (Gather), the owner's side of the contacts it owns in key
///    order, the reactions of the contacts it does not own and its wall contacts, through particle -> contact
///    lists sorted by contact index.
#include "kernels/neighbor/contact_list.hpp"
#include "kernels/core/particles.hpp"
#include "kernels/core/vec3.hpp"

namespace dem {

/// Particle -> contact list (CSR), entries in ascending contact order.
struct Adjacency {
  IndexView offset;   ///< n + 1
  IndexView entry;    ///< contact index
  IndexView entry_buf, cursor;  ///< scratch kept for the next build (kernels/core/buffers.hpp)
};

/// Adjacency of n particles to the contacts whose gathering side is `side(k)` (c.j for ball-ball
/// reactions, c.i for ball-wall contacts).
Adjacency build_adjacency(int n, const ContactList& c, const IndexView& side);
/// The same into `a`, whose Views are reused where they are large enough.
void build_adjacency(int n, const ContactList& c, const IndexView& side, Adjacency& a);

/// Contacts owned by each particle: [own(i,0), own(i,1)) in the key-sorted ball-ball list. Contiguous
/// because keys start with the owner's gid.
Index2View owner_ranges(const Particles& p, const ContactList& balls);
/// The same into `own`, reused where it has p.n rows.
void owner_ranges(const Particles& p, const ContactList& balls, Index2View& own);

/// A particle's force and moment: the owner's side of the ball-ball contacts it owns (contiguous, in key order),
/// minus the reactions of those it is particle 2 of, plus its wall contacts.
struct Gather {
  ConstVec3View bfc, bmo, bmt, wfc, wmt;
  Index2View own;
  ConstIndexView boff, bent, woff, went;

  KOKKOS_INLINE_FUNCTION void operator()(const int i, Vec3& f, Vec3& m) const {
    f = Vec3();
    m = Vec3();
    for (int s = own(i, 0); s < own(i, 1); ++s) {
      f += load(bfc, s);
      m += load(bmo, s);
    }
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

Gather make_gather(const ContactList& balls, const Index2View& own, const Adjacency& adj_balls,
                   const ContactList& walls, const Adjacency& adj_walls);

/// Offsets of each wall object's contacts in the (key-sorted) ball-wall list: nobj + 1 entries.
IndexView object_offsets(const ContactList& walls, int nobj);
/// The same into `off`, reused where it has nobj + 1 entries.
void object_offsets(const ContactList& walls, int nobj, IndexView& off);

/// Load of each of the first `nobj` wall objects: the force (N), the reaction of its contacts summed in key order,
/// and its touching contacts; `loads` is (re)allocated only where it is too short.
void wall_loads_into(const ContactList& walls, const IndexView& offsets, int nobj, WallLoadView& loads);

}  // namespace dem
