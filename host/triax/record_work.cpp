#include "host/triax/record_work.hpp"

#include <utility>

#include "host/triax/triaxial_measure.hpp"
#include "kernels/core/types.hpp"

namespace dem {

bool overlaps_records(const MicroConfig& mc) {
  // On a CPU build the threads that would work out a record are the ones that step: nothing is gained by a thread
  // more, so "auto" overlaps only where a device steps.
  return mc.overlap == "on" || (mc.overlap == "auto" && kOnDevice);
}

RecordWork::RecordWork(const MicroConfig& mc, Real mean_radius, int slabs, std::string folder)
    : mc_(mc), mean_radius_(mean_radius), slabs_(slabs), folder_(std::move(folder)), overlap_(overlaps_records(mc)) {}

RecordWork::~RecordWork() {
  if (pending_.valid()) pending_.wait();
}

RecordWorked RecordWork::work(const RecordJob& job) const {
  RecordWorked r;
  r.envelope_volume = envelope_volume(centres_by_gid(*job.state), job.top, mean_radius_, slabs_);
  if (!mc_.enabled) return r;
  const ContactSet cs = contact_set(*job.state);
  const ContactSet rve = restrict_to_cube(cs, Vec3(0, 0, job.top / 2), mc_.rve_edge);
  r.micro = micro_row(cs, job.volume);
  for (const MicroRow& x : {r.micro, micro_row(rve, mc_.rve_edge * mc_.rve_edge * mc_.rve_edge)})
    for (double v : micro_values(x)) r.values.push_back(v);
  if (!folder_.empty())
    for (const std::string& label : job.states) write_micro_state(folder_, label, cs, rve, mc_.rose_bins);
  return r;
}

void RecordWork::add(RecordJob job, Done done) {
  finish();
  done_ = std::move(done);
  if (!overlap_) {
    done_(work(job));
    return;
  }
  // The job holds its copy (shared, read only; StateCopies reuses it once released), so the thread reads nothing
  // the steps change.
  pending_ = std::async(std::launch::async, [this, job = std::move(job)] { return work(job); });
}

void RecordWork::finish() {
  if (!pending_.valid()) return;
  const RecordWorked r = pending_.get();
  done_(r);
}

}  // namespace dem
