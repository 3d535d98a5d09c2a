#pragma once
/// Contact force kernels: geometry and kinematics of each candidate contact, then the contact law.
/// Candidates that do not touch get zero force and lose their history (the contact opened).
#include "kernels/contact/accumulate.hpp"
#include "kernels/contact/contact_law.hpp"
#include "kernels/core/domain.hpp"
#include "kernels/core/specimen.hpp"
#include "kernels/core/walls.hpp"

namespace dem {

/// Ball-ball forces with each pair's law (ContactLaws), kContactLanes contacts per work item (simd.hpp): writes each
/// contact's force and moments on both sides (fc, mo, mt) for the gather (accumulate.hpp), and the largest overlap
/// ratio to `worst`, in device memory: the host does not wait.
void compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const Domain& dom, Real dt,
                         const OverlapResultView& worst);
/// The same for the one specimen of `one` (SpecimenTable: its cell by value or in device memory, its time step).
void compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const SpecimenTable& one,
                         const OverlapResultView& worst);

/// A batch's ball-ball contacts cut into work items of kContactLanes that stay within one specimen: specimen s's
/// contacts [contact_first(s), contact_first(s + 1)) are items [item_first(s), item_first(s + 1)) (S + 1 entries
/// each, on the device).
struct ContactItems {
  IndexView contact_first, item_first;
  int specimens = 0;
  int items = 0;
  /// Every contact whose overlap passed its specimen's limit this step, `exceeded_count()` of them: each specimen's
  /// largest (ties to the later contact, as the one-specimen reduction) is its blow-up, whatever the others'.
  Kokkos::View<OverlapStat*, MemSpace> exceeded;
  Kokkos::View<int, MemSpace> exceeded_count;
};
/// The same forces for the specimens of a batch at once: each contact with its specimen's cell, time step and
/// row of the material-pair table (SpecimenParams), bit for bit what the specimen gets alone.
void compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params,
                         const SpecimenParamsView& specimens, const ContactItems& items,
                         const OverlapResultView& worst);
/// The same, returning the largest overlap ratio to the host.
OverlapStat compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const Domain& dom,
                                Real dt);

/// Ball-wall forces (analytic walls and facets). A ball touching several facets at a shared edge or
/// vertex gets one contact: an edge/vertex hit yields to a face hit, or an equal hit of a lower facet
/// number, on any touching facet that holds the same edge or vertex.
void compute_wall_forces(const Particles& p, ContactList& c, const Adjacency& adj, const WallSet& walls,
                         const FacetMesh& mesh, const ParamTableView& params, Real dt, const OverlapResultView& worst);
OverlapStat compute_wall_forces(const Particles& p, ContactList& c, const Adjacency& adj, const WallSet& walls,
                                const FacetMesh& mesh, const ParamTableView& params, Real dt);

/// Stores a touching contact's updated history and the law's output (force on particle 1, elastic normal force)
/// at `at`; both kernels. Of the history slots only those in `slots` (ContactLaw::slots): no other can change.
template <class T, class At>
KOKKOS_INLINE_FUNCTION void store_law(const ContactList& c, At at, const ContactHistoryT<T>& h,
                                      const ContactOutputT<T>& out, unsigned slots) {
  put(c.fs, at, h.fs);
  put(c.mr, at, h.mr);
  put_scalar(c.flags, at, h.flags);
  for (int s = 0; s < kHistorySlots; ++s)
    if (slots & (1u << s)) put_scalar(c.slot[s], at, h.slot[s]);
  put(c.fc, at, out.force);
  put_scalar(c.fn, at, out.fn);
}

/// Applies the law to kinematics k of contact slot `s`, stores its history and output, and returns the output.
KOKKOS_FORCEINLINE_FUNCTION ContactOutput apply_law(const ContactList& c, int s, const ContactParams& prm,
                                               const ContactKinematics& k) {
  ContactHistory h{load(c.fs, s), load(c.mr, s), c.flags(s)};
  const unsigned slots = ContactLaws::slots(prm);
  for (int q = 0; q < kHistorySlots; ++q)
    if (slots & (1u << q)) h.slot[q] = c.slot[q](s);
  const ContactOutput out = ContactLaws::eval(prm, k, h);
  store_law(c, LaneRow{s, 0}, h, out, slots);
  return out;
}

/// Zeroes the results and history of a candidate that does not touch. One already open is left as it is: it
/// holds zeros (a new candidate starts at zero, and every evaluation sets kTouching, so flags of 0 mean the
/// contact was opened since), and rewriting them every step only costs memory traffic.
KOKKOS_INLINE_FUNCTION void open_contact(const ContactList& c, int s) {
  if (c.flags(s) == 0) return;
  store(c.fs, s, Vec3());
  store(c.mr, s, Vec3());
  c.flags(s) = 0;
  for (int q = 0; q < kHistorySlots; ++q) c.slot[q](s) = 0;
  store(c.fc, s, Vec3());
  store(c.mo, s, Vec3());
  store(c.mt, s, Vec3());
  c.fn(s) = 0;
}

}  // namespace dem
