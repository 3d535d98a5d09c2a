#pragma once
/// A running simulation's state as a record reads it: its balls and, for the micromechanics, its contacts, walls and
/// membrane, copied at one state into kept host buffers, so that the rest (the balls put in gid order, the contact
/// set, the envelope's hulls) is worked out on another thread while the device steps on. On a device the buffers
/// are pinned host memory; they are allocated by the first records and grow with the counts, so that a record then
/// costs the steps one copy an array and no allocation (docs/performance.md, "The records beside the steps").
#include <memory>
#include <vector>

#include "kernels/core/domain.hpp"
#include "kernels/core/types.hpp"
#include "kernels/core/vec3.hpp"

namespace dem {

class Simulation;

struct ContactCopy {
  /// A contact list's first n entries: local ball index, partner (a ball's local index, or a wall object: a wall
  /// below the walls' count, else a facet), the total force on the ball (N) and the normal force (N, > 0 where
  /// touching).
  struct List {
    HostCopyView<IndexView> i, j;
    HostCopyView<Vec3View> fc;
    HostCopyView<ScalarView> fn;
    int n = 0;
  };
  int n = 0;                         ///< balls
  HostCopyView<GidView> gid;         ///< of each local index
  HostCopyView<Vec3View> x;          ///< ball centres (m), by local index
  /// The facet walls (the membrane's where there is one): the nodes (m) at each copy; the facets and the membrane's
  /// fixed nodes (1: tied to a platen), which a simulation never changes, where the buffer has none of the count yet.
  HostCopyView<Vec3View> node_x;
  HostCopyView<Index3View> tri;
  HostCopyView<FlagView> fixed;
  int ntri = 0;
  bool contacts = false;             ///< whether what follows was copied (copy_state's `contacts`)
  HostCopyView<ScalarView> radius;   ///< m, by local index
  List balls, walls;
  int nwalls = 0;
  HostCopyView<IndexView> wall_kind;
  HostCopyView<Vec3View> wall_point, wall_normal;
  HostCopyView<ScalarView> wall_radius;
  Domain domain;
};

/// Copies the simulation's balls (and, with `contacts`, what contact_set needs) into `into`'s buffers, growing them
/// where they are short.
void copy_state(Simulation& sim, bool contacts, ContactCopy& into);

/// The copy's ball centres in gid order (m).
std::vector<Vec3> centres_by_gid(const ContactCopy& c);

/// Kept copies for a run's records: a copy is taken into a buffer no record's work still holds, so that after the
/// first records (two where they are worked out beside the steps) none is allocated.
class StateCopies {
 public:
  std::shared_ptr<const ContactCopy> take(Simulation& sim, bool contacts);

 private:
  std::vector<std::shared_ptr<ContactCopy>> kept_;
};

}  // namespace dem
