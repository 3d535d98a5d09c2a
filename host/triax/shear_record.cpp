#include "host/triax/shear_record.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>

#include "host/engine/setup.hpp"
#include "host/engine/simulation.hpp"
#include "host/engine/stress.hpp"
#include "host/triax/micro_report.hpp"
#include "host/triax/triaxial_measure.hpp"

namespace dem {

namespace {

/// series.csv's columns before the micro ones, and a record's values in them (series_row): one order for both.
const std::vector<std::string> kSeriesColumns = {
    "eps_a_pct",        "eps_v_pct",          "q_kPa",            "sigma1_kPa",      "sigma1_bottom_kPa",
    "sigma3_kPa",       "sigma3_balls_kPa",   "eps_v_envelope_pct", "unbalanced_ratio", "kinetic_energy_J",
    "q_area_kPa",       "q_parabolic_kPa",    "q_membrane_kPa",   "sigma3_hoop_kPa", "q_lw_kPa",
    "p_lw_kPa",         "q_boundary_kPa",     "p_boundary_kPa",   "q_net_kPa",       "p_net_kPa",
    "p_kPa",            "void_ratio",         "phi_mob_deg"};

/// `e0`: the void ratio after consolidation, from which eps_v counts. p and phi_mob are the lab's, of the q the
/// paper reports (q_kPa) and the cell pressure: p = sigma3 + q / 3, as the periodic series has them.
std::vector<double> series_row(const TriaxialRecord& r, Real sigma3, Real e0) {
  return {100 * r.eps_a,         100 * r.eps_v,        r.q / 1e3,           r.sigma1 / 1e3,     r.sigma1_bottom / 1e3,
          sigma3 / 1e3,          r.sigma3_balls / 1e3, 100 * r.eps_v_envelope, r.unbalanced,     r.kinetic,
          r.q_area / 1e3,        r.q_parabolic / 1e3,  r.q_membrane / 1e3,  r.sigma3_hoop / 1e3, r.q_lw / 1e3,
          r.p_lw / 1e3,          r.q_boundary / 1e3,   r.p_boundary / 1e3,  r.q_net / 1e3,      r.p_net / 1e3,
          triaxial_mean_stress(sigma3, r.q) / 1e3, (1 + e0) * (1 - r.eps_v) - 1, friction_angle_deg(r.q, sigma3)};
}

/// The record's deviators as labs report them and the specimen's stresses over the enclosed `volume` (its contacts'
/// on the device, specimen_stress), from the platen force (r.sigma1, r.sigma3_balls and the strains set). `a0`: the
/// cross-section after consolidation, V0 / h0.
void measure_stresses(const Cell& c, const TriaxialConfig& tc, Real volume, Real a0, TriaxialRecord& r) {
  const Real force = r.sigma1 * c.area;
  r.q_area = force / right_cylinder_area(a0, r.eps_a, r.eps_v) - tc.sigma3;
  r.q_parabolic = force / parabolic_mid_area(a0, r.eps_a, r.eps_v) - tc.sigma3;
  r.q_membrane = r.q_area + tc.sigma3 - r.sigma3_balls;
  r.sigma3_hoop = tc.sigma3 + membrane_hoop_stress(tc.membrane_modulus, tc.membrane_thickness,
                                                   std::sqrt(4 * a0 / M_PI), r.eps_a, r.eps_v);
  const SpecimenStress s = specimen_stress(*c.sim, volume);
  r.q_lw = axial_deviator(s.love_weber);
  r.p_lw = mean_stress(s.love_weber);
  r.q_boundary = axial_deviator(s.boundary);
  r.p_boundary = mean_stress(s.boundary);
  r.q_net = axial_deviator(s.net_force);
  r.p_net = mean_stress(s.net_force);
}

/// The state of the current step, copied to the host at most once a step, for the record and the snapshot alike.
class LazyCopy {
 public:
  LazyCopy(StateCopies& copies, Simulation& sim, bool contacts) : copies_(copies), sim_(sim), contacts_(contacts) {}
  std::shared_ptr<const ContactCopy> copy() {
    if (!copy_) copy_ = copies_.take(sim_, contacts_);
    return copy_;
  }
  ContactSet set() { return contact_set(*copy()); }

 private:
  StateCopies& copies_;
  Simulation& sim_;
  bool contacts_;
  std::shared_ptr<const ContactCopy> copy_;
};

/// What follows a record's work, on the stepping thread: the envelope's strain and the micromechanics into the record
/// just taken, and its series row out (a crash keeps the curve so far: the series is flushed every 25 rows).
RecordWork::Done record_done(const ShearRecorder& sh) {
  return [&res = sh.res, out = sh.out, index = sh.res.records.size() - 1, v0 = sh.v0_envelope,
          micro = sh.cfg.micro.enabled, sigma3 = sh.cfg.triaxial.sigma3, e0 = sh.st.void_ratio](const RecordWorked& w) {
    TriaxialRecord& r = res.records[index];
    r.eps_v_envelope = (v0 - w.envelope_volume) / v0;
    if (micro) res.micro.push_back(w.micro);
    std::vector<double> row = series_row(r, sigma3, e0);
    row.insert(row.end(), w.values.begin(), w.values.end());
    if (!out) return;
    out->append_series(row);
    if ((index + 1) % 25 == 0) out->flush_series();
  };
}

/// One record of the shear stage at axial strain eps_a, step k: boundary stresses and strains and the stress measures
/// here; the envelope and the micromechanics where enabled (with their states at the snapshot strains and the peak)
/// from the copy of the state, then the series row (record_done).
void take_record(const ShearRecorder& sh, Real eps_a, long k, LazyCopy& state) {
  const TriaxialConfig& tc = sh.cfg.triaxial;
  const Cell& cell = sh.cell;
  Simulation& sim = *cell.sim;
  const char* snap_labels[] = {"A", "B", "C", "D"};  // the paper's points A-D (Figure 8)
  TriaxialRecord r;
  const std::vector<Vec3> wall_f = sim.wall_forces();
  const auto [top, bottom] = platen_stresses(cell, wall_f);
  const Real top_z = sim.wall_point(kTopPlaten).z, volume = specimen_volume(cell);
  r.eps_a = eps_a;
  r.eps_v = (sh.v0 - volume) / sh.v0;
  r.sigma1 = top;
  r.sigma1_bottom = bottom;
  r.q = top - tc.sigma3;
  r.sigma3_balls = lateral_stress(*state.copy(), sim.num_walls(), wall_f);
  r.unbalanced = sim.unbalanced_ratio();
  r.kinetic = sim.stats().kinetic;
  measure_stresses(cell, tc, volume, sh.v0 / sh.h0, r);
  sh.res.records.push_back(r);
  RecordJob job{state.copy(), top_z, volume, {}};
  if (sh.cfg.micro.enabled) {
    const int snap = sh.st.next_snap;
    if (snap < kSnapshotStrains && eps_a >= sh.snaps[snap] - 1e-12) job.states.push_back(snap_labels[snap]);
    if (r.q > sh.st.q_max) job.states.push_back("peak");
  }
  sh.work.add(std::move(job), record_done(sh));
  sh.st.q_max = std::max(sh.st.q_max, r.q);
  sh.st.next_record += tc.record_every;
  if (sh.verbose) {
    char extra[64];
    std::snprintf(extra, sizeof extra, "eps_a %.2f%%, q %.1f kPa", 100 * eps_a, r.q / 1e3);
    sh.progress.update(k, extra);
  }
}

}  // namespace

/// The state step k of the shear left: its record where one is due (or `last`), and a snapshot where one is.
void observe_shear(const ShearRecorder& sh, long k, bool last) {
  Simulation& sim = *sh.cell.sim;
  const bool micro = sh.cfg.micro.enabled;
  const Real eps_a = (sh.h0 - sim.wall_point(kTopPlaten).z) / sh.h0;
  LazyCopy state{sh.copies, sim, micro};
  if (eps_a >= sh.st.next_record - 1e-12 || last) take_record(sh, eps_a, k, state);
  const int next_snap = sh.st.next_snap;
  if (sh.out && next_snap < kSnapshotStrains && eps_a >= sh.snaps[next_snap] - 1e-12) {
    char label[48];
    std::snprintf(label, sizeof label, "shear eps_a=%.0f%%", 100 * sh.snaps[next_snap]);
    const io::SurfaceSnapshot surface = membrane_surface(sh.cell.membrane);
    const io::ContactTable table = micro ? contact_table(state.set()) : io::ContactTable();
    sh.out->write_snapshot(take_snapshot(sim, label), &surface, micro ? &table : nullptr);
    sh.st.next_snap += 1;
  }
}

/// The series' columns: the boundary's, then the micromechanics' of the specimen and of its central cube where enabled.
std::vector<std::string> series_columns(const MicroConfig& mc) {
  std::vector<std::string> columns = kSeriesColumns;
  if (mc.enabled)
    for (const std::string& prefix : {std::string(), std::string("rve_")})
      for (const std::string& c : micro_columns(prefix)) columns.push_back(c);
  return columns;
}

}  // namespace dem
