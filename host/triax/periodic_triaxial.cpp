#include "host/triax/periodic_triaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "host/engine/cell_batch.hpp"
#include "host/triax/cell_boundary.hpp"
#include "host/triax/cell_control.hpp"
#include "host/data/measured.hpp"
#include "kernels/contact/contact_sums.hpp"
#include "kernels/core/reduce.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/stage_loop.hpp"
#include "host/util/progress.hpp"

namespace dem {

namespace {

constexpr Real kPi = 3.14159265358979323846;

/// Mean diameter (m), effective density (kg/m^3, x mass_scale) and solid volume (m^3) of the balls.
struct GrainScales {
  Real d = 0, rho_eff = 0, v_solid = 0;
};

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

/// The strain-rate servo of the cell: each call measures the contact stress and sets the next step's rates.
class CellServo {
 public:
  CellServo(const PeriodicTriaxialParams& prm, Real max_rate) : prm_(prm), max_rate_(max_rate) {}

  /// servo[d]: axis d is servoed to target[d] (Pa); otherwise its rate is fixed[d] (1/s, extension positive).
  void update(CellControl& cell, const bool servo[3], const Real fixed[3], const Real target[3]) {
    if (calls_++ % prm_.stiffness_every == 0) k_ = cell.stiffness();
    stress_ = cell.stress();
    const Real dt = cell.dt();
    Real rate[3];
    for (int d = 0; d < 3; ++d) {
      if (!servo[d]) { rate[d] = fixed[d]; continue; }
      const Real err = stress_[d] - target[d];
      // gain = alpha sigma3 / (K dt); with no contacts (K = 0) the clamp decides.
      const Real r = k_[d] > 0 ? prm_.servo_alpha * err / (k_[d] * dt)
                               : (err > 0 ? max_rate_ : (err < 0 ? -max_rate_ : Real(0)));
      rate[d] = std::clamp(r, -max_rate_, max_rate_);
    }
    cell.set_rates(Vec3(rate[0], rate[1], rate[2]));
  }

 private:
  PeriodicTriaxialParams prm_;
  Real max_rate_;
  long calls_ = 0;
  std::array<Real, 3> k_{};
  std::array<Real, 3> stress_{};
};

/// Lateral confinement per axis: sigma3 plus the membrane's, from the cell's lateral strains since L0.
std::array<Real, 3> lateral_targets(const std::array<Real, 3>& lengths, const PeriodicTriaxialParams& prm,
                                    const std::array<Real, 3>& L0) {
  std::array<Real, 3> t{};
  for (int d = 0; d < 3; ++d)
    t[d] = prm.sigma3 + membrane_confinement(prm.membrane_stiffness, lengths[d] / L0[d] - 1);
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
  r.p = (r.sigma1 + r.sigma2 + r.sigma3) / 3;
  const Real sum = r.sigma1 + lateral;
  r.phi_mob_deg = sum > 0 ? std::asin(std::clamp(r.q / sum, Real(-1), Real(1))) * 180 / kPi : 0;
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

}  // namespace

std::array<Real, 3> cell_stiffness(Simulation& sim) {
  const ContactList c = sim.ball_contacts();
  Particles& p = sim.particles();
  auto x = p.x;
  auto r = p.radius;
  const Domain dom = sim.domain();
  const MinImage image(dom);
  Real k[3];
  deterministic_reduce<3, 0>("dem::periodic::cell_stiffness", c.n, KOKKOS_LAMBDA(const int s, Real* v) {
    stiffness_terms(c, s, x, r, image, v);
  }, k);
  const Real V = dom.volume();
  return {k[0] / V, k[1] / V, k[2] / V};
}

PeriodicTriaxialParams resolve_periodic_params(Simulation& sim, PeriodicTriaxialParams prm) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("periodic triaxial: " + what); };
  const Domain& dom = sim.domain();
  const bool periodic = dom.periodic[0] && dom.periodic[1] && dom.periodic[2];
  if (!periodic && !walled(sim)) bad("the cell must be periodic along x, y and z, or lie between six walls");
  if ((periodic && sim.num_walls() > 0) || sim.membrane().ntri > 0)
    bad("a periodic cell must have no walls, facets or membrane");
  if (norm2(sim.params().integ.gravity) != 0) bad("gravity must be zero in a fully periodic cell");
  if (sim.params().integ.dt <= 0) bad("the time step is not set");
  if (!(prm.sigma3 > 0)) bad("sigma3 must be > 0");
  if (!(prm.target_strain > 0 && prm.target_strain < 0.9)) bad("target axial strain must be in (0, 0.9)");
  if (!(prm.servo_alpha > 0 && prm.servo_alpha <= 1)) bad("servo alpha must be in (0, 1]");
  if (!(prm.stress_tolerance > 0 && prm.unbalanced_tolerance > 0)) bad("tolerances must be > 0");
  if (!(prm.record_strain > 0)) bad("record strain interval must be > 0");
  if (prm.axial_rate < 0 || prm.max_lateral_rate < 0 || prm.consolidation_rate < 0) bad("rates must be >= 0");
  if (prm.check_every < 1 || prm.stiffness_every < 1 || prm.max_consolidation_steps < 1)
    bad("check_every, stiffness_every and max_consolidation_steps must be >= 1");
  const GrainScales g = grain_scales(sim);
  const Real scale = g.d * std::sqrt(g.rho_eff / prm.sigma3);  // I = rate * scale at p = sigma3
  if (prm.axial_rate == 0) {
    if (!(prm.target_inertial > 0)) bad("target inertial number must be > 0 when the axial rate is automatic");
    prm.axial_rate = prm.target_inertial / scale;
  }
  const Real inertial = prm.axial_rate * scale;
  if (inertial > prm.max_inertial && !prm.allow_high_inertial) {
    std::ostringstream s;
    s << "axial strain rate " << prm.axial_rate << " /s gives an inertial number I = " << inertial
      << " at p = sigma3, above the quasi-static limit " << prm.max_inertial << " (d = " << g.d
      << " m, rho_eff = " << g.rho_eff << " kg/m^3); lower the rate to at most " << prm.max_inertial / scale
      << " /s or set allow_high_inertial";
    bad(s.str());
  }
  if (prm.max_lateral_rate == 0) prm.max_lateral_rate = 5 * prm.axial_rate;
  if (prm.consolidation_rate == 0) prm.consolidation_rate = prm.max_lateral_rate;
  return prm;
}

namespace {

/// Stage (a), isotropic consolidation, on a cell: its servo, its progress line, and the state it reached.
class Consolidation {
 public:
  Consolidation(CellControl& cell, const PeriodicTriaxialParams& prm)
      : cell_(cell), prm_(prm), servo_(prm, prm.consolidation_rate),
        progress_(prm.name + " consolidation (ETA to the step cap)", prm.max_consolidation_steps) {}

  StageSteps steps() {
    StageSteps stage;
    stage.last = prm_.max_consolidation_steps;
    stage.before = [this](long n) {
      const bool all[3] = {true, true, true};
      const Real none[3] = {0, 0, 0};
      const Real target[3] = {prm_.sigma3, prm_.sigma3, prm_.sigma3};
      servo_.update(cell_, all, none, target);
      return StepPlan{false, n % prm_.check_every == 0};
    };
    stage.after = [this](long n, bool measured) {
      if (!measured) return false;
      s_ = cell_.stress();
      err_ = 0;
      for (int d = 0; d < 3; ++d) err_ = std::max(err_, std::fabs(s_[d] - prm_.sigma3) / prm_.sigma3);
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

  /// After the stage: the cell's rates zeroed; "" where it converged, else why not (the error's message).
  std::string end(StageEnd& e) {
    cell_.set_rates(Vec3());
    if (e.done) {
      if (prm_.verbose) progress_.finish("(converged after " + std::to_string(e.step) + " steps)");
      e.timing.name = "consolidation";
      return "";
    }
    std::ostringstream msg;
    msg << "periodic triaxial: isotropic consolidation to sigma3 = " << 1e-3 * prm_.sigma3
        << " kPa did not converge in " << prm_.max_consolidation_steps << " steps: stresses (xx, yy, zz) = ("
        << 1e-3 * s_[0] << ", " << 1e-3 * s_[1] << ", " << 1e-3 * s_[2] << ") kPa, largest error " << err_
        << " (tolerance " << prm_.stress_tolerance << "), unbalanced-force ratio " << ratio_ << " (tolerance "
        << prm_.unbalanced_tolerance << "). Raise max_consolidation_steps, or loosen unbalanced_tolerance if the "
        << "ratio is still falling";
    return msg.str();
  }

 private:
  CellControl& cell_;
  PeriodicTriaxialParams prm_;
  CellServo servo_;
  Progress progress_;
  Real err_ = 0, ratio_ = 1;
  std::array<Real, 3> s_{};
};

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

/// Snapshots at the configured axial strains within the test, each written once, when the strain first reaches it
/// (several passed in one step give one snapshot, labelled with the largest). None without an output.
class SnapshotSchedule {
 public:
  SnapshotSchedule(const PeriodicTriaxialParams& prm, Simulation* sim, io::Output* out) : sim_(sim), out_(out) {
    for (Real e : prm.snapshot_strains)
      if (e >= 0 && e <= prm.target_strain + 1e-12) strains_.push_back(e);
    std::sort(strains_.begin(), strains_.end());
  }
  /// The cell is at axial strain eps.
  void at(Real eps) {
    Real nominal = -1;
    while (next_ < strains_.size() && eps >= strains_[next_] - 1e-9) nominal = strains_[next_++];
    if (nominal >= 0 && out_ && sim_) {
      out_->flush_series();
      out_->write_snapshot(take_snapshot(*sim_, pct_label(nominal)));
    }
  }

 private:
  Simulation* sim_;
  io::Output* out_;
  std::vector<Real> strains_;
  std::size_t next_ = 0;
};

/// Stage (b), drained shear, on a consolidated cell: the servo of the lateral axes, the records, the snapshots.
/// Constructed at the stage's start: records the first row.
class Shear {
 public:
  Shear(CellControl& cell, PeriodicTriaxialResult& res, const GrainScales& g, io::Output* out, Simulation* sim)
      : cell_(cell), res_(res), prm_(res.params), g_(g), out_(out), snapshots_(prm_, sim, out),
        servo_(prm_, prm_.max_lateral_rate),
        total_(static_cast<long>(std::ceil(-std::log(1 - prm_.target_strain) / (prm_.axial_rate * cell.dt())))),
        progress_(prm_.name + " shear", total_), next_record_(prm_.record_strain) {
    L0_ = cell_.lengths();
    res_.h0 = L0_[2];
    res_.V0 = cell_.volume();
    res_.void_ratio0 = res_.V0 / g_.v_solid - 1;
    if (out_) out_->set_series_columns(kSeriesColumns);
    record();
    snapshots_.at(0);
  }

  StageSteps steps() {
    StageSteps stage;
    stage.last = std::numeric_limits<long>::max();  // until the target strain
    stage.before = [this](long) {
      const bool lateral[3] = {true, true, false};
      const Real axial[3] = {0, 0, -prm_.axial_rate};
      const std::array<Real, 3> lengths = cell_.lengths();
      const std::array<Real, 3> target = lateral_targets(lengths, prm_, L0_);
      servo_.update(cell_, lateral, axial, target.data());
      const Real h = lengths[2];
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
      snapshots_.at((res_.h0 - cell_.lengths()[2]) / res_.h0);
      return last_;
    };
    return stage;
  }

  /// After the stage: its timing named, the cell's rates zeroed, the series flushed, the result summarised.
  void end(StageTiming timing, double wall_seconds) {
    timing.name = "shear";
    res_.stages.push_back(timing);
    cell_.set_rates(Vec3());
    if (out_) out_->flush_series();
    finish_result(cell_, res_, progress_, wall_seconds);
  }

 private:
  CellControl& cell_;
  PeriodicTriaxialResult& res_;
  const PeriodicTriaxialParams& prm_;
  GrainScales g_;
  io::Output* out_;
  SnapshotSchedule snapshots_;
  CellServo servo_;
  long total_;
  Progress progress_;
  Real next_record_;
  bool last_ = false;  // the step ends the test
  std::array<Real, 3> L0_{};

  void record() {
    res_.series.push_back(measure_row(cell_, prm_, g_, res_.h0, res_.V0, L0_));
    if (out_) out_->append_series(series_row(res_.series.back()));
  }
};

/// The result's parameters and grain figures before the test, and its first line when verbose.
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

}  // namespace

StageEnd consolidate_isotropic(Simulation& sim, const PeriodicTriaxialParams& prm_in) {
  const PeriodicTriaxialParams prm = resolve_periodic_params(sim, prm_in);  // idempotent
  const auto cell = cell_of(sim);
  Consolidation stage(*cell, prm);
  StageEnd end = run_stage(sim, stage.steps(), nullptr);
  const std::string failure = stage.end(end);
  if (!failure.empty()) throw std::runtime_error(failure);
  return end;
}

PeriodicTriaxialResult run_periodic_triaxial(Simulation& sim, const PeriodicTriaxialParams& prm_in, io::Output* out) {
  const auto t0 = std::chrono::steady_clock::now();
  GrainScales g;
  PeriodicTriaxialResult res = start_result(sim, prm_in, g);
  const StageEnd consolidated = consolidate_isotropic(sim, res.params);
  res.consolidation_steps = consolidated.step;
  res.stages.push_back(consolidated.timing);
  const auto cell = cell_of(sim);
  Shear shear(*cell, res, g, out, &sim);
  const StageTiming sheared = run_stage(sim, shear.steps(), nullptr).timing;
  shear.end(sheared, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return res;
}

std::vector<BatchedTest> run_periodic_batch(const std::vector<Simulation*>& sims,
                                            const std::vector<PeriodicTriaxialParams>& prms, bool consolidate_only,
                                            std::array<long, 2>* steps) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t S = sims.size();
  if (prms.size() != S) throw std::invalid_argument("run_periodic_batch: a parameter set per specimen");
  std::vector<BatchedTest> out(S);
  std::vector<GrainScales> g(S);
  for (std::size_t s = 0; s < S; ++s) out[s].result = start_result(*sims[s], prms[s], g[s]);
  CellBatch batch(std::vector<const Simulation*>(sims.begin(), sims.end()));
  // Each specimen's program: consolidation, then (unless consolidate_only) shear; a stage's steps numbered from 1.
  struct Member {
    std::unique_ptr<CellControl> cell;
    std::unique_ptr<Consolidation> consolidation;
    std::unique_ptr<Shear> shear;
    StageSteps stage;
    long n = 1;
    long first_step = 0;  ///< the specimen's step count at the stage's start
  };
  std::vector<Member> m(S);
  for (std::size_t s = 0; s < S; ++s) {
    m[s].cell = cell_of(batch, static_cast<int>(s));
    m[s].consolidation = std::make_unique<Consolidation>(*m[s].cell, out[s].result.params);
    m[s].stage = m[s].consolidation->steps();
  }
  const auto seconds = [&]() { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  // The stage of specimen s ended (run_stage's StageEnd): on to its next stage, or stopped.
  const auto end_stage = [&](std::size_t s, StageEnd e) {
    Member& me = m[s];
    BatchedTest& t = out[s];
    e.timing.balls = batch.balls(static_cast<int>(s));
    e.timing.steps = batch.step_count(static_cast<int>(s)) - me.first_step;
    me.first_step = batch.step_count(static_cast<int>(s));
    if (!me.shear) {
      t.failure = me.consolidation->end(e);
      t.consolidation = e;
      t.result.consolidation_steps = e.step;
      t.result.stages.push_back(e.timing);
      if (!t.failure.empty() || consolidate_only) {
        if (consolidate_only && t.failure.empty()) {
          t.balls = batch.balls_of(static_cast<int>(s));
          t.domain = batch.domain(static_cast<int>(s));
        }
        batch.stop(static_cast<int>(s));
        return;
      }
      me.shear = std::make_unique<Shear>(*me.cell, t.result, g[s], nullptr, nullptr);
      me.stage = me.shear->steps();
      me.n = 1;
      return;
    }
    me.shear->end(e.timing, seconds());
    batch.stop(static_cast<int>(s));
  };
  std::vector<char> measure(S, 0), stepping(S, 0);
  while (batch.running_count() > 0) {
    for (std::size_t s = 0; s < S; ++s) {
      stepping[s] = 0;
      if (!batch.running(static_cast<int>(s))) continue;
      StepPlan plan = m[s].stage.before(m[s].n);
      while (plan.done && batch.running(static_cast<int>(s))) {
        end_stage(s, {m[s].n - 1, true, {}});
        if (batch.running(static_cast<int>(s))) plan = m[s].stage.before(m[s].n);
      }
      measure[s] = plan.measure;
      stepping[s] = batch.running(static_cast<int>(s));
    }
    if (batch.running_count() == 0) break;
    batch.step(measure);
    for (std::size_t s = 0; s < S; ++s) {
      if (!stepping[s]) continue;
      if (!batch.running(static_cast<int>(s))) {  // blown up
        out[s].blowup = batch.blowup(static_cast<int>(s));
        continue;
      }
      Member& me = m[s];
      if (me.stage.after(me.n, measure[s] != 0)) end_stage(s, {me.n, true, {}});
      else if (++me.n > me.stage.last) end_stage(s, {me.n - 1, false, {}});
    }
  }
  if (steps) *steps = {batch.steps(), batch.rebuild_steps()};
  return out;
}

Real membrane_confinement(Real stiffness, Real eps) { return stiffness * std::max(eps, Real(0)); }

}  // namespace dem
