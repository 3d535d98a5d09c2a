#include "host/triax/compression_test.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "host/engine/stress.hpp"
#include "host/triax/periodic_stages.hpp"

namespace dem {

namespace {

/// An increment's servo: the consolidation's gain and clamp without its gas phase (the cell is packed), the axial
/// axis alone servoed with the lateral ones held (oedometer), or all three (isotropic).
CellServoSpec increment_servo(const PeriodicTriaxialParams& prm, CompressionPath path, Real target) {
  CellServoSpec s = consolidation_servo(prm);
  s.sigma3 = target;
  s.gas_rate = 0;
  if (path == CompressionPath::oedometer) s.servo[0] = s.servo[1] = false;  // fixed at rate 0: lengths held
  return s;
}

CompressionRecord measure(CellControl& cell, Real target, Real h0, Real V0, Real v_solid) {
  CompressionRecord r;
  const std::array<Real, 3> s = cell.stress();
  const Real V = cell.volume();
  r.step = cell.step_count();
  r.target = target;
  r.eps_a = (h0 - cell.length(2)) / h0;
  r.eps_v = -(V - V0) / V0;
  r.sigma_v = s[2];
  r.sigma_h = (s[0] + s[1]) / 2;
  r.p = mean_stress(s);
  r.q = axial_deviator(s);
  r.k0 = r.sigma_v > 0 ? r.sigma_h / r.sigma_v : 0;
  r.void_ratio = V / v_solid - 1;
  r.coordination = cell.balls() > 0 ? 2.0 * static_cast<Real>(cell.touching()) / cell.balls() : 0;
  r.unbalanced = cell.unbalanced_ratio();
  return r;
}

}  // namespace

CompressionTest compression_data_of(const CompressionResult& r, const std::string& material, Real sigma3) {
  CompressionTest t{material, r.path, sigma3, {}, {}, {}, {}, {}};
  for (std::size_t k = 1; k < r.series.size(); ++k) {
    const CompressionRecord& x = r.series[k];
    t.stress.push_back(x.target);
    t.strain.push_back(r.path == CompressionPath::oedometer ? x.eps_a : x.eps_v);
    if (r.path == CompressionPath::oedometer) t.k0.push_back(x.k0);
  }
  return t;
}

const std::vector<std::string>& compression_columns() {
  static const std::vector<std::string> names = {
      "step", "target_kPa", "eps_a_pct", "eps_v_pct", "sigma_v_kPa", "sigma_h_kPa", "p_kPa", "q_kPa", "K0",
      "void_ratio", "coordination", "unbalanced_ratio"};
  return names;
}

std::vector<double> compression_row(const CompressionRecord& r) {
  return {static_cast<double>(r.step), 1e-3 * r.target, 100 * r.eps_a, 100 * r.eps_v, 1e-3 * r.sigma_v,
          1e-3 * r.sigma_h, 1e-3 * r.p, 1e-3 * r.q, r.k0, r.void_ratio, r.coordination, r.unbalanced};
}

CompressionResult run_compression_test(Simulation& sim, const PeriodicTriaxialParams& prm_in, CompressionPath path,
                                       const std::vector<Real>& targets, io::Output* out) {
  for (Real t : targets)
    if (!(t > 0) || !std::isfinite(t))
      throw std::invalid_argument(std::string(path_name(path)) + ": every target stress must be positive and finite");
  const PeriodicTriaxialParams prm = resolve_periodic_params(sim, prm_in);
  CompressionResult res;
  res.path = path;
  res.stages.push_back(consolidate_isotropic(sim, prm).timing);
  const GrainScales g = grain_scales(sim);
  const auto cell = cell_of(sim);
  const Real h0 = cell->length(2), V0 = cell->volume();
  if (out) out->set_series_columns(compression_columns());
  auto record = [&](Real target) {
    res.series.push_back(measure(*cell, target, h0, V0, g.v_solid));
    if (out) {
      out->append_series(compression_row(res.series.back()));
      out->flush_series();
    }
  };
  record(prm.sigma3);
  for (std::size_t k = 0; k < targets.size(); ++k) {
    char what[96];
    std::snprintf(what, sizeof what, "%s %zu/%zu to %.4g kPa", path_name(path), k + 1, targets.size(),
                  1e-3 * targets[k]);
    Consolidation hold(*cell, prm, increment_servo(prm, path, targets[k]), what);
    StageEnd end = run_stage(sim, hold.steps(), nullptr);
    const std::string failure = hold.end(end);
    if (!failure.empty()) throw std::runtime_error(failure);
    res.stages.push_back(end.timing);
    record(targets[k]);
  }
  return res;
}

}  // namespace dem
