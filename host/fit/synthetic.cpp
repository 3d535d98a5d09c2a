/// Synthetic measured data (host/fit/diagnose.hpp): the simulator's curves with a hidden extension and lab-like
/// noise, written as a measured-data file, for the hidden-effect tests, the sweep and `triaxdem synth`.
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

#include "host/fit/diagnose.hpp"
#include "host/io/io_hdf5.hpp"

namespace dem {

Real draw_strength(const Extension& e, unsigned seed) {
  std::mt19937_64 rng(seed * 7919u + 17u);
  std::uniform_real_distribution<Real> u(0, 1);
  return e.levels.front() * std::pow(e.levels.back() / e.levels.front(), u(rng));
}

std::vector<TriaxialTest> synthetic_tests(PeriodicLab& lab, const Model& truth, const std::vector<Real>& sigma3,
                                          const std::string& material, unsigned seed, Real noise) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<Real> gauss(0, 1);
  std::vector<TriaxialTest> like(sigma3.size());
  for (std::size_t j = 0; j < sigma3.size(); ++j) like[j].sigma3 = sigma3[j], like[j].material = material;
  std::vector<TriaxialTest> out = lab.run_each(truth, like);
  for (std::size_t j = 0; j < sigma3.size(); ++j) {
    const Real s3 = sigma3[j];
    TriaxialTest& t = out[j];
    t.specimen_balls = static_cast<Real>(lab.balls());
    const Real factor = 1 + noise * 0.02 * gauss(rng);
    for (std::size_t i = 0; i < t.q.size(); ++i) {
      t.q[i] = factor * t.q[i] + noise * 0.005 * s3 * gauss(rng);
      t.eps_v[i] += noise * 2e-4 * gauss(rng);
    }
    summarise(t);
  }
  return out;
}

void write_measured_curves(const std::string& path, const std::vector<TriaxialTest>& tests,
                           const std::string& comment, const std::string& q_measure) {
  const bool volume = std::all_of(tests.begin(), tests.end(), [](const TriaxialTest& t) { return !t.eps_v.empty(); });
  auto all = [&](Real TriaxialTest::*m) {
    return std::all_of(tests.begin(), tests.end(), [&](const TriaxialTest& t) { return std::isfinite(t.*m); });
  };
  const bool state = all(&TriaxialTest::void_ratio), size = all(&TriaxialTest::specimen_balls);
  // The HDF5 form's table holds numbers: labels are written where each is one (member numbers, seeds).
  std::vector<double> label(tests.size());
  bool labels = !tests.empty();
  for (std::size_t k = 0; k < tests.size() && labels; ++k) {
    char* end = nullptr;
    label[k] = std::strtod(tests[k].replicate.c_str(), &end);
    labels = !tests[k].replicate.empty() && *end == '\0';
  }
  std::vector<std::string> columns{"sigma3_kPa"};
  if (labels) columns.push_back("test");
  for (const char* c : {"eps_a_pct", "q_kPa"}) columns.push_back(c);
  if (volume) columns.push_back("eps_v_pct");
  if (state) columns.push_back("void_ratio");
  if (size) columns.push_back("specimen_balls");
  std::map<std::string, std::vector<std::vector<double>>> rows;  // by material
  std::vector<std::string> order;                                 // materials in file order
  for (std::size_t k = 0; k < tests.size(); ++k) {
    const TriaxialTest& t = tests[k];
    if (!rows.count(t.material)) order.push_back(t.material);
    for (std::size_t i = 0; i < t.q.size(); ++i) {
      rows[t.material].push_back({1e-3 * t.sigma3});
      if (labels) rows[t.material].back().push_back(label[k]);
      for (double v : {100 * t.eps_a[i], 1e-3 * t.q[i]}) rows[t.material].back().push_back(v);
      if (volume) rows[t.material].back().push_back(100 * t.eps_v[i]);
      if (state) rows[t.material].back().push_back(t.void_ratio);
      if (size) rows[t.material].back().push_back(t.specimen_balls);
    }
  }
  if (is_hdf5_path(path)) return write_measured_h5(path, columns, rows, comment, q_measure);
  std::ostringstream f;
  f << "# " << comment << "\n# triaxdem measured-data format (curves): see host/data/measured.hpp and docs/calibration.md.\n";
  f << "material";
  for (const std::string& c : columns) f << "," << c;
  f << (q_measure.empty() ? "" : ",q_measure") << "\n";
  char cell[32];
  for (const std::string& m : order)
    for (const std::vector<double>& r : rows[m]) {
      f << m;
      for (double v : r) {
        std::snprintf(cell, sizeof cell, ",%.6g", v);
        f << cell;
      }
      f << (q_measure.empty() ? "" : "," + q_measure) << "\n";
    }
  io::write_text_atomic(path, f.str());
}

}  // namespace dem
