#include "host/triax/triaxial_state.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "host/triax/micro_report.hpp"

namespace dem {

namespace {

std::vector<double> stage_numbers(const Stage& s) {
  return {s.shear ? 1.0 : 0.0,
          static_cast<double>(s.step),
          s.h0,
          s.v0,
          s.v0_envelope,
          s.void_ratio,
          static_cast<double>(s.consolidation_steps),
          s.q_max,
          static_cast<double>(s.next_snap),
          s.next_record};
}
/// The stage as the file gives it, each value checked against what the loops do with it: the stage and the
/// snapshot index select, the step starts a loop, the volumes divide.
Stage stage_of(const std::vector<double>& v, const std::string& path) {
  if (v.size() != 10)
    throw std::runtime_error(path + ": the triaxial stage has " + std::to_string(v.size()) + " values, not 10");
  const char* names[10] = {"shear", "step", "h0", "v0", "v0_envelope", "void_ratio", "consolidation_steps",
                           "q_max", "next_snap", "next_record"};
  auto refuse = [&](int k, const std::string& allowed) {
    throw std::runtime_error(path + ": number_stage, row " + std::to_string(k) + " (" + names[k] + ") = " +
                             std::to_string(v[k]) + " (allowed: " + allowed + ")");
  };
  auto whole = [&](int k, double most) {
    if (!(v[k] >= 0 && v[k] <= most && v[k] == std::floor(v[k]))) refuse(k, "a whole number from 0 to " + std::to_string(most));
  };
  whole(0, 1);
  whole(1, kMaxStageSteps);
  // The shear divides by the heights and volumes taken at its start; consolidation has none yet (zeros).
  for (int k : {2, 3, 4, 5})
    if (!(std::isfinite(v[k]) && (v[0] == 0 ? v[k] >= 0 : v[k] > 0)))
      refuse(k, v[0] == 0 ? "a finite number of 0 or more" : "a finite positive number (in shear)");
  whole(6, kMaxStageSteps);
  if (std::isnan(v[7]) || v[7] == INFINITY) refuse(7, "a finite number, or -inf before the first record");
  whole(8, kSnapshotStrains);
  if (!(std::isfinite(v[9]) && v[9] >= 0)) refuse(9, "a finite strain of 0 or more");
  return Stage{v[0] != 0, static_cast<long>(v[1]), v[2], v[3], v[4], v[5], static_cast<long>(v[6]), v[7],
               static_cast<int>(v[8]), v[9]};
}

/// A record's fields in the file's order: one list for the writer (const records) and the reader.
constexpr int kRecordValues = 19;
template <class Record>
std::array<decltype(&std::declval<Record&>().eps_a), kRecordValues> record_fields(Record& r) {
  return {&r.eps_a,        &r.eps_v,      &r.sigma1,      &r.sigma1_bottom, &r.q,           &r.sigma3_balls,
          &r.eps_v_envelope, &r.unbalanced, &r.kinetic,   &r.q_area,        &r.q_parabolic, &r.q_membrane,
          &r.sigma3_hoop,  &r.q_lw,       &r.p_lw,        &r.q_boundary,    &r.p_boundary,  &r.q_net,
          &r.p_net};
}
std::vector<double> record_numbers(const std::vector<TriaxialRecord>& rs) {
  std::vector<double> v;
  for (const TriaxialRecord& r : rs)
    for (const Real* x : record_fields(r)) v.push_back(*x);
  return v;
}
std::vector<TriaxialRecord> records_of(const std::vector<double>& v, const std::string& path) {
  if (v.size() % kRecordValues != 0)
    throw std::runtime_error(path + ": number_records has " + std::to_string(v.size()) + " values (allowed: " +
                             std::to_string(kRecordValues) + " per record)");
  for (std::size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      throw std::runtime_error(path + ": number_records, value " + std::to_string(k) + " is not a finite number");
  std::vector<TriaxialRecord> rs(v.size() / kRecordValues);
  std::size_t at = 0;
  for (TriaxialRecord& r : rs)
    for (Real* x : record_fields(r)) *x = v[at++];
  return rs;
}
}  // namespace

void save_triaxial(const std::string& path, const Simulation& sim, const io::Output* out, const Stage& st,
                   const TriaxialResult& res, const std::string& config) {
  Checkpoint c = checkpoint_of("triaxial", sim, out, config);
  c.numbers["stage"] = stage_numbers(st);
  c.numbers["records"] = record_numbers(res.records);
  c.numbers["wall_s"] = {res.wall_seconds};
  std::vector<double>& micro = c.numbers["micro"];
  for (const MicroRow& m : res.micro) append_micro_state(m, micro);
  write_checkpoint(path, c);
}

void restore_triaxial(const Checkpoint& c, const std::string& path, Simulation& sim, io::Output* out, Stage& st,
                      TriaxialResult& res) {
  if (c.job != "triaxial") throw std::runtime_error(path + ": written by the '" + c.job + "' job, not 'triaxial'");
  for (const char* key : {"stage", "records"})
    if (!c.numbers.count(key)) throw std::runtime_error(path + ": the triaxial '" + std::string(key) + "' is missing");
  // Everything the file gives is checked before anything of the run changes.
  const Stage checked = stage_of(c.numbers.at("stage"), path);
  std::vector<TriaxialRecord> records = records_of(c.numbers.at("records"), path);
  std::vector<MicroRow> micro;
  if (c.numbers.count("micro"))
    for (std::size_t at = 0; at < c.numbers.at("micro").size();)
      micro.push_back(micro_row_from(c.numbers.at("micro"), at));
  resume_from(c, sim, out);
  st = checked;
  res.records = std::move(records);
  res.micro = std::move(micro);
  if (c.numbers.count("wall_s") && c.numbers.at("wall_s").size() == 1) res.wall_seconds = c.numbers.at("wall_s")[0];
}

}  // namespace dem
