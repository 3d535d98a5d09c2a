// A batch's servos on the device (CellBatch::set_cell_servo): their slots, their launches before a step, and the
// host's reads of the cells they changed.
#include "host/engine/cell_batch.hpp"
#include "kernels/contact/contact_sums.hpp"

namespace dem {

const Domain& CellBatch::domain(int s) const {
  const Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  if (sp.stale) read_cells();
  return sp.prm.domain;
}

Real CellBatch::axis_length(int s, int d) const {
  const Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  if (sp.stale && sp.servo.on && sp.servo.spec.servo[d]) read_cells();
  return sp.prm.domain.length(d);
}

void CellBatch::read_cells() const {
  bool any = false;
  for (const Specimen& sp : spec_) any = any || sp.stale;
  if (!any) return;
  Kokkos::deep_copy(host_spec_, dev_spec_);
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    Specimen& sp = spec_[s];
    if (!sp.stale) continue;
    sp.prm.domain = host_spec_(s).dom;
    sp.stale = false;
  }
}

void CellBatch::upload_slots() {
  for (std::size_t s = 0; s < spec_.size(); ++s) host_slots_(s) = spec_[s].servo;
  Kokkos::deep_copy(servo_slots_, host_slots_);
}

void CellBatch::set_cell_servo(int s, const CellServoSpec& spec) {
  Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  if (!sp.running) return;
  read_cells();
  sp.servo.spec = spec;
  sp.servo.reach = 2 * sp.rmax + sp.prm.skin;
  sp.servo.calls = 0;
  sp.servo.on = 1;
  take_fixed_rates(sp.prm.domain, spec);
  upload_slots();
}

void CellBatch::servo_step() {
  bool any = false, fresh = false;
  for (Specimen& sp : spec_) {
    if (!sp.running || !sp.servo.on) continue;
    any = true;
    if (sp.servo.calls++ % sp.servo.spec.stiffness_every == 0) fresh = true;  // every one's calls counted
    sp.stale = true;
  }
  if (!any) return;
  const SpecimenImages images{p_.specimen, dev_spec_};
  Real* sums = servo_sums_.data();  // device memory: the host passes it on, never reads it
  const int stride = CellServoSums::kCount;
  if (fresh_) {
    Kokkos::deep_copy(servo_sums_, Real(0));  // no contacts yet: no sums (per_volume's zeros)
  } else {
    if (fresh) {
      const StiffnessTerms<SpecimenImages> terms{p_.x, p_.radius, images};
      segmented_reduce_lanes_to<3, 0, 1>("dem::batch::servo_stiffness", owner_tree_,
                                         OwnerSums<3, StiffnessTerms<SpecimenImages>>{owners(), terms},
                                         sums + CellServoSums::kStiffnessSums, stride);
    }
    segmented_reduce_lanes_to<3, 0, 1>("dem::batch::servo_stress", owner_tree_,
                                       OwnerSums<3, LoveWeberTerms<3, SpecimenImages>>{owners(), {p_.x, images}},
                                       sums + CellServoSums::kStressSums, stride);
  }
  cell_servo_rates(dev_spec_, servo_slots_, servo_sums_);
}

}  // namespace dem
