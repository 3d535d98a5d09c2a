#include "triaxial_state.hpp"

#include <stdexcept>

#include "micro_report.hpp"

namespace dem {

namespace {

std::vector<double> stage_numbers(const Stage& s) {
  return {s.shear, s.step, s.h0, s.v0, s.v0_envelope, s.void_ratio, s.consolidation_steps, s.q_max, s.next_snap,
          s.next_record};
}
Stage stage_of(const std::vector<double>& v, const std::string& path) {
  if (v.size() != 10)
    throw std::runtime_error(path + ": the triaxial stage has " + std::to_string(v.size()) + " values, not 10");
  return Stage{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]};
}

constexpr int kRecordValues = 9;
std::vector<double> record_numbers(const std::vector<TriaxialRecord>& rs) {
  std::vector<double> v;
  for (const TriaxialRecord& r : rs)
    v.insert(v.end(), {r.eps_a, r.eps_v, r.sigma1, r.sigma1_bottom, r.q, r.sigma3_balls, r.eps_v_envelope,
                       r.unbalanced, r.kinetic});
  return v;
}
std::vector<TriaxialRecord> records_of(const std::vector<double>& v) {
  std::vector<TriaxialRecord> rs(v.size() / kRecordValues);
  for (std::size_t i = 0; i < rs.size(); ++i) {
    const double* x = &v[kRecordValues * i];
    rs[i] = TriaxialRecord{x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8]};
  }
  return rs;
}
}  // namespace

void save_triaxial(const std::string& path, const Simulation& sim, const io::Output* out, const Stage& st,
                   const TriaxialResult& res) {
  Checkpoint c = checkpoint_of("triaxial", sim, out);
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
  resume_from(c, sim, out);
  st = stage_of(c.numbers.at("stage"), path);
  res.records = records_of(c.numbers.at("records"));
  if (c.numbers.count("wall_s") && c.numbers.at("wall_s").size() == 1) res.wall_seconds = c.numbers.at("wall_s")[0];
  if (c.numbers.count("micro"))
    for (std::size_t at = 0; at < c.numbers.at("micro").size();)
      res.micro.push_back(micro_row_from(c.numbers.at("micro"), at));
}

}  // namespace dem
