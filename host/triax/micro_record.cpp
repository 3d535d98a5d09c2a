#include "host/triax/micro_record.hpp"

#include <utility>

#include "kernels/core/types.hpp"

namespace dem {

bool overlaps_records(const MicroConfig& mc) {
  // On a CPU build the threads that would work out a record are the ones that step: nothing is gained by a thread
  // more, so "auto" overlaps only where a device steps.
  return mc.overlap == "on" || (mc.overlap == "auto" && kOnDevice);
}

MicroRecords::MicroRecords(const MicroConfig& mc, std::string folder)
    : mc_(mc), folder_(std::move(folder)), overlap_(overlaps_records(mc)) {}

MicroRecords::~MicroRecords() {
  if (pending_.valid()) pending_.wait();
}

MicroRecords::Result MicroRecords::work(const MicroJob& job) const {
  const ContactSet cs = contact_set(*job.contacts);
  const ContactSet rve = restrict_to_cube(cs, job.centre, mc_.rve_edge);
  Result r;
  r.row = micro_row(cs, job.volume);
  for (const MicroRow& x : {r.row, micro_row(rve, mc_.rve_edge * mc_.rve_edge * mc_.rve_edge)})
    for (double v : micro_values(x)) r.values.push_back(v);
  if (!folder_.empty())
    for (const std::string& label : job.states) write_micro_state(folder_, label, cs, rve, mc_.rose_bins);
  return r;
}

void MicroRecords::add(MicroJob job, Done done) {
  finish();
  done_ = std::move(done);
  if (!overlap_) {
    const Result r = work(job);
    done_(r.row, r.values);
    return;
  }
  // The job owns its copy (shared, read only), so the thread reads nothing the steps change.
  pending_ = std::async(std::launch::async, [this, job = std::move(job)] { return work(job); });
}

void MicroRecords::finish() {
  if (!pending_.valid()) return;
  const Result r = pending_.get();
  done_(r.row, r.values);
}

}  // namespace dem
