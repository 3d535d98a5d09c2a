// A batch's servos on the device (CellBatch::set_cell_servo): their slots, their launches before a step, and the
// host's reads of the cells they changed.
#include <type_traits>

#include "host/engine/cell_batch.hpp"
#include "host/engine/cell_services.hpp"

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
  if (fresh_) {
    Kokkos::deep_copy(servo_sums_, Real(0));  // no contacts yet: no sums (per_volume's zeros)
  } else {
    // Device memory, a row per specimen: the host passes it on, never reads it.
    cell_servo_sums([&](const char* label, const auto& terms, Real* root) {
          using Terms = std::decay_t<decltype(terms)>;
          segmented_reduce_lanes_to<3, 0, 1>(label, owner_tree_, OwnerSums<3, Terms>{owners(), terms}, root,
                                             CellServoSums::kCount);
        }, p_.x, p_.radius, SpecimenImages{p_.specimen, dev_spec_}, fresh, servo_sums_.data());
  }
  cell_servo_rates(dev_spec_, servo_slots_, servo_sums_);
}

}  // namespace dem
