#include "host/triax/periodic_stages.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "host/data/measured.hpp"
#include "host/engine/micro.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/stress.hpp"

namespace dem {

namespace {

constexpr Real kPi = 3.14159265358979323846;

/// The servo of stage (b): the lateral axes to sigma3 plus the membrane's confinement from their strains since L0,
/// clamped to max_lateral_rate; the axial axis shortened at axial_rate.
CellServoSpec shear_servo(const PeriodicTriaxialParams& prm, const std::array<Real, 3>& L0) {
  CellServoSpec s = consolidation_servo(prm);
  s.servo[2] = false;
  s.fixed[2] = -prm.axial_rate;
  s.membrane_stiffness = prm.membrane_stiffness;
  for (int d = 0; d < 3; ++d) s.L0[d] = L0[static_cast<std::size_t>(d)];
  s.max_rate = prm.max_lateral_rate;
  s.gas_rate = 0;  // a sheared packing is no gas, however it dilates
  return s;
}

/// Lateral confinement per axis: sigma3 plus the membrane's, from the cell's lateral strains since L0.
std::array<Real, 3> lateral_targets(const std::array<Real, 3>& lengths, const PeriodicTriaxialParams& prm,
                                    const std::array<Real, 3>& L0) {
  const CellServoSpec s = shear_servo(prm, L0);
  std::array<Real, 3> t{};
  for (int d = 0; d < 3; ++d) t[static_cast<std::size_t>(d)] = servo_target(s, d, lengths[static_cast<std::size_t>(d)]);
  return t;
}

PeriodicTriaxialRecord measure_row(CellControl& cell, const PeriodicTriaxialParams& prm, const GrainScales& g,
                                   Real h0, Real V0, const std::array<Real, 3>& L0) {
  PeriodicTriaxialRecord r;
  const std::array<Real, 3> lengths = cell.lengths();
  const Real V = cell.volume();
  const std::array<Real, 3> s = cell.stress();
  r.step = cell.step_count();
  r.time = cell.time();
  r.eps_a = (h0 - lengths[2]) / h0;
  r.eps_v = -(V - V0) / V0;
  r.sigma1 = s[2];
  r.sigma2 = s[0];
  r.sigma3 = s[1];
  const Real lateral = 0.5 * (r.sigma2 + r.sigma3);
  const std::array<Real, 3> target = lateral_targets(lengths, prm, L0);
  r.membrane = 0.5 * (target[0] + target[1]) - prm.sigma3;
  r.q = r.sigma1 - (lateral - r.membrane);
  r.q_fixed_area = r.q * (lengths[0] * lengths[1]) / (L0[0] * L0[1]);
  r.p = mean_stress(s);
  // The lab's angle of q against the confinement it is measured from: the lateral stress less the membrane's share.
  const Real confinement = lateral - r.membrane;
  r.phi_mob_deg = confinement > 0 && r.q > -confinement ? friction_angle_deg(r.q, confinement) : 0;
  r.void_ratio = V / g.v_solid - 1;
  const int n = cell.balls();
  r.coordination = n > 0 ? 2.0 * static_cast<Real>(cell.touching()) / n : 0;
  r.unbalanced = cell.unbalanced_ratio();
  r.kinetic = cell.kinetic();
  r.inertial = r.p > 0 ? prm.axial_rate * g.d * std::sqrt(g.rho_eff / r.p) : std::numeric_limits<Real>::infinity();
  const Vec3 rates = cell.rates();
  r.rate_x = rates.x;
  r.rate_y = rates.y;
  return r;
}

const std::vector<std::string> kSeriesColumns = {
    "step", "time_s", "eps_a_pct", "eps_v_pct", "sigma1_kPa", "sigma2_kPa", "sigma3_kPa", "q_kPa", "p_kPa",
    "phi_mob_deg", "void_ratio", "coordination", "unbalanced_ratio", "kinetic_energy_J", "inertial_number",
    "rate_x_per_s", "rate_y_per_s", "membrane_kPa"};

std::vector<double> series_row(const PeriodicTriaxialRecord& r) {
  return {static_cast<double>(r.step), r.time, 100 * r.eps_a, 100 * r.eps_v, 1e-3 * r.sigma1, 1e-3 * r.sigma2,
          1e-3 * r.sigma3, 1e-3 * r.q, 1e-3 * r.p, r.phi_mob_deg, r.void_ratio, r.coordination, r.unbalanced,
          r.kinetic, r.inertial, r.rate_x, r.rate_y, 1e-3 * r.membrane};
}

std::string pct_label(Real eps) {
  char b[48];
  std::snprintf(b, sizeof b, "shear eps_a=%g%%", 100 * eps);
  return b;
}

/// The result's curve values and checks (the lateral stress's largest error, the largest kinetic energy), and the
/// closing lines when verbose; `wall_seconds` is set.
void finish_result(CellControl& cell, PeriodicTriaxialResult& res, Progress& progress, double wall_seconds) {
  const PeriodicTriaxialParams& prm = res.params;
  take_curve_values(res, summarised(res.series, prm.sigma3));
  for (const PeriodicTriaxialRecord& r : res.series) {
    // The membrane's share is the same on both axes to rounding (they stretch alike on average); its
    // mean is recorded.
    const Real target = prm.sigma3 + r.membrane;
    res.max_lateral_error = std::max({res.max_lateral_error, std::fabs(r.sigma2 - target) / target,
                                      std::fabs(r.sigma3 - target) / target});
    res.max_kinetic = std::max(res.max_kinetic, r.kinetic);
  }
  res.wall_seconds = wall_seconds;
  if (prm.verbose) {
    const PeriodicTriaxialRecord& f = res.series.back();
    progress.finish("");
    std::printf("periodic triaxial: consolidated in %ld steps to void ratio %.4f (Z = %.2f); sheared to eps_a = %.2f%% "
                "in %ld steps\n", res.consolidation_steps, res.void_ratio0, res.series.front().coordination,
                100 * f.eps_a, cell.step_count() - res.series.front().step);
    std::printf("peak q = %.2f kPa at eps_a = %.2f%% (moving mean over +-%.2f%% strain); peak friction angle "
                "phi = asin((s1-s3)/(s1+s3)) = %.2f deg\n",
                1e-3 * res.q_peak, 100 * res.eps_a_peak, 100 * kSmoothHalfWidth, res.phi_peak_deg);
    std::printf("end: q = %.2f kPa, eps_v = %.2f%%, void ratio %.4f; lateral stress within %.2f%% of sigma3; "
                "wall time %s\n", 1e-3 * f.q, 100 * f.eps_v, f.void_ratio, 100 * res.max_lateral_error,
                format_duration(res.wall_seconds).c_str());
  }
}

/// The test's first line: pressure, rate, inertial number (flagged above the quasi-static limit), step, servo.
void announce(const PeriodicTriaxialParams& prm, Real inertial, Real dt) {
  std::printf("periodic triaxial: sigma3 %.1f kPa, axial rate %.4g /s (I = %.2e at p = sigma3%s), dt %.3e s, "
              "servo alpha %.2f, lateral rate clamp %.4g /s\n",
              1e-3 * prm.sigma3, prm.axial_rate, inertial,
              inertial > prm.max_inertial ? ", ABOVE the quasi-static limit: allowed by the config" : "", dt,
              prm.servo_alpha, prm.max_lateral_rate);
}

}  // namespace

CellServoSpec consolidation_servo(const PeriodicTriaxialParams& prm) {
  CellServoSpec s;
  for (bool& on : s.servo) on = true;
  s.sigma3 = prm.sigma3;
  s.alpha = prm.servo_alpha;
  s.max_rate = prm.consolidation_rate;
  s.gas_rate = prm.gas_rate;
  s.gas_volume = prm.gas_volume;
  s.stiffness_every = prm.stiffness_every;
  return s;
}

GrainScales grain_scales(Simulation& sim) {
  Particles& p = sim.particles();
  auto r = Kokkos::create_mirror_view_and_copy(HostSpace(), p.radius);
  auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), p.mass);
  GrainScales g;
  Real mass = 0;
  for (int i = 0; i < p.n; ++i) {
    g.d += 2 * r(i);
    g.v_solid += 4.0 / 3.0 * kPi * r(i) * r(i) * r(i);
    mass += m(i);
  }
  if (p.n > 0) g.d /= p.n;
  g.rho_eff = g.v_solid > 0 ? mass / g.v_solid * sim.params().integ.mass_scale : 0;
  return g;
}

PeriodicTriaxialResult start_result(Simulation& sim, const PeriodicTriaxialParams& prm_in, GrainScales& g) {
  PeriodicTriaxialResult res;
  res.params = resolve_periodic_params(sim, prm_in);
  const PeriodicTriaxialParams& prm = res.params;
  g = grain_scales(sim);
  res.mean_diameter = g.d;
  res.density_eff = g.rho_eff;
  res.inertial = prm.axial_rate * g.d * std::sqrt(g.rho_eff / prm.sigma3);
  if (prm.verbose) announce(prm, res.inertial, sim.params().integ.dt);
  return res;
}

void CellServo::update(CellControl& cell) {
  if (on_device_) return;
  if (calls_ == 0 && cell.servo_on_device(spec_)) {
    on_device_ = true;
    return;
  }
  if (calls_++ % spec_.stiffness_every == 0) k_ = cell.stiffness();
  const std::array<Real, 3> stress = cell.stress();
  const std::array<Real, 3> lengths = cell.lengths();
  const Real volume = cell.volume();
  Real rate[3];
  for (std::size_t d = 0; d < 3; ++d) {
    const int a = static_cast<int>(d);
    rate[d] = spec_.servo[d]
                  ? servo_rate(spec_, stress[d] - servo_target(spec_, a, lengths[d]), k_[d], cell.dt(), volume)
                  : spec_.fixed[d];
  }
  cell.set_rates(Vec3(rate[0], rate[1], rate[2]));
}

Consolidation::Consolidation(CellControl& cell, const PeriodicTriaxialParams& prm)
    : Consolidation(cell, prm, consolidation_servo(prm), "consolidation") {}

Consolidation::Consolidation(CellControl& cell, const PeriodicTriaxialParams& prm, const CellServoSpec& spec,
                             const std::string& what)
    : cell_(cell), prm_(prm), spec_(spec), what_(what), servo_(spec),
      progress_(prm.name + " " + what + " (ETA to the step cap)", prm.max_consolidation_steps) {}

StageSteps Consolidation::steps() {
  StageSteps stage;
  stage.last = prm_.max_consolidation_steps;
  stage.before = [this](long n) {
    servo_.update(cell_);
    return StepPlan{false, n % prm_.check_every == 0};
  };
  stage.after = [this](long n, bool measured) {
    if (!measured) return false;
    s_ = cell_.stress();
    err_ = 0;
    for (int d = 0; d < 3; ++d)
      if (spec_.servo[d]) err_ = std::max(err_, std::fabs(s_[d] - spec_.sigma3) / spec_.sigma3);
    ratio_ = cell_.unbalanced_ratio();
    if (prm_.verbose) {
      char extra[128];
      std::snprintf(extra, sizeof extra, "p %.1f kPa, stress error %.2e, unbalanced %.2e",
                    1e-3 * (s_[0] + s_[1] + s_[2]) / 3, err_, ratio_);
      progress_.update(n, extra);
    }
    return err_ < prm_.stress_tolerance && ratio_ < prm_.unbalanced_tolerance;
  };
  return stage;
}

std::string Consolidation::end(StageEnd& e) {
  cell_.set_rates(Vec3());
  if (e.done) {
    if (prm_.verbose) progress_.finish("(converged after " + std::to_string(e.step) + " steps)");
    e.timing.name = what_;
    return "";
  }
  std::ostringstream msg;
  msg << prm_.name << ": " << what_ << " (target " << 1e-3 * spec_.sigma3 << " kPa on the servoed axes) did not converge in " << prm_.max_consolidation_steps << " steps: stresses (xx, yy, zz) = ("
      << 1e-3 * s_[0] << ", " << 1e-3 * s_[1] << ", " << 1e-3 * s_[2] << ") kPa, largest error " << err_
      << " (tolerance " << prm_.stress_tolerance << "), unbalanced-force ratio " << ratio_ << " (tolerance "
      << prm_.unbalanced_tolerance << "). Raise max_consolidation_steps, or loosen unbalanced_tolerance if the "
      << "ratio is still falling";
  return msg.str();
}

SnapshotSchedule::SnapshotSchedule(const PeriodicTriaxialParams& prm, Simulation* sim, io::Output* out)
    : sim_(sim), out_(out) {
  for (Real e : prm.snapshot_strains)
    if (e >= 0 && e <= prm.target_strain + 1e-12) strains_.push_back(e);
  std::sort(strains_.begin(), strains_.end());
}

void SnapshotSchedule::at(Real eps) {
  Real nominal = -1;
  while (next_ < strains_.size() && eps >= strains_[next_] - 1e-9) nominal = strains_[next_++];
  if (nominal >= 0 && out_ && sim_) {
    out_->flush_series();
    // With its contacts, for `triaxdem micro` (the fabric of the packing at each snapshot).
    const io::ContactTable contacts = contact_table(contact_set(*sim_));
    out_->write_snapshot(take_snapshot(*sim_, pct_label(nominal)), nullptr, &contacts);
  }
}

Shear::Shear(CellControl& cell, PeriodicTriaxialResult& res, const GrainScales& g, io::Output* out, Simulation* sim)
    : cell_(cell), res_(res), prm_(res.params), g_(g), out_(out), snapshots_(prm_, sim, out),
      servo_(shear_servo(prm_, cell.lengths())),
      total_(shear_step_count(prm_.target_strain, prm_.axial_rate, cell.dt())),
      progress_(prm_.name + " shear", total_), next_record_(prm_.record_strain) {
  L0_ = cell_.lengths();
  res_.h0 = L0_[2];
  res_.V0 = cell_.volume();
  res_.void_ratio0 = res_.V0 / g_.v_solid - 1;
  if (out_) out_->set_series_columns(kSeriesColumns);
  record();
  snapshots_.at(0);
}

StageSteps Shear::steps() {
  StageSteps stage;
  stage.last = std::numeric_limits<long>::max();  // until the target strain
  stage.before = [this](long) {
    servo_.update(cell_);
    const Real h = cell_.length(2);
    const Real eps_next = (res_.h0 - h * (1 - prm_.axial_rate * cell_.dt())) / res_.h0;
    last_ = eps_next >= prm_.target_strain;
    return StepPlan{false, last_ || eps_next >= next_record_ - 1e-12};  // a recorded step measures
  };
  stage.after = [this](long n, bool recorded) {
    if (recorded) {
      record();
      while (next_record_ <= res_.series.back().eps_a + 1e-12) next_record_ += prm_.record_strain;
      const PeriodicTriaxialRecord& r = res_.series.back();
      if (prm_.verbose) {
        char extra[160];
        std::snprintf(extra, sizeof extra, "eps_a %.2f%%, q %.1f kPa, eps_v %.2f%%, lateral %.1f/%.1f kPa",
                      100 * r.eps_a, 1e-3 * r.q, 100 * r.eps_v, 1e-3 * r.sigma2, 1e-3 * r.sigma3);
        progress_.update(std::min(n, total_), extra);
      }
      if (out_ && res_.series.size() % 50 == 0) out_->flush_series();
    }
    snapshots_.at((res_.h0 - cell_.length(2)) / res_.h0);
    return last_;
  };
  return stage;
}

void Shear::end(StageTiming timing, double wall_seconds) {
  timing.name = "shear";
  res_.stages.push_back(timing);
  cell_.set_rates(Vec3());
  if (out_) out_->flush_series();
  finish_result(cell_, res_, progress_, wall_seconds);
}

void Shear::record() {
  res_.series.push_back(measure_row(cell_, prm_, g_, res_.h0, res_.V0, L0_));
  if (out_) out_->append_series(series_row(res_.series.back()));
}

}  // namespace dem
