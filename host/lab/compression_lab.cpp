/// The lab's compression tests: an oedometer or an isotropic compression on the ensemble's specimens, as a calibration
/// fits them beside the triaxial tests (host/fit/compression_misfit.hpp).
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "host/lab/periodic_lab.hpp"
#include "host/triax/compression_test.hpp"
#include "host/util/forked_runs.hpp"

namespace dem {

namespace {

/// The simulated test at `like`'s increments from a run's series, NaN where the run gave none.
CompressionTest simulated(const CompressionTest& like, const CompressionResult* r) {
  CompressionTest t = r ? compression_data_of(*r, like.material, like.sigma3) : CompressionTest{};
  t.material = like.material, t.path = like.path, t.sigma3 = like.sigma3, t.stress = like.stress;
  t.strain.resize(like.stress.size(), std::numeric_limits<Real>::quiet_NaN());
  t.k0.resize(like.stress.size(), std::numeric_limits<Real>::quiet_NaN());
  return t;
}

}  // namespace

CompressionTest PeriodicLab::run_compression(const Model& m, const CompressionTest& like, int member) {
  const auto t0 = std::chrono::steady_clock::now();
  const PackedCell& sp = specimens_.at(static_cast<std::size_t>(member));
  CompressionTest t;
  try {
    auto sim = make_periodic_simulation(sp.balls, sp.cell, m.law, cfg_.solver, cfg_.periodic.boundary);
    const CompressionResult r = run_compression_test(*sim, test_params(m, like.sigma3), like.path, like.stress);
    t = simulated(like, &r);
  } catch (const std::runtime_error&) {  // a blow-up, or an increment that did not come to rest within its steps
    t = simulated(like, nullptr);
  }
  count_runs(1, t0);
  return t;
}

std::vector<std::vector<CompressionTest>> PeriodicLab::run_compressions(const Model& m,
                                                                        const std::vector<CompressionTest>& like,
                                                                        bool all) {
  const std::size_t T = like.size(), M = all ? specimens_.size() : static_cast<std::size_t>(members_);
  std::vector<std::vector<CompressionTest>> out(T, std::vector<CompressionTest>(M));
  auto place = [&](std::size_t j, CompressionTest t) {
    if (!std::isfinite(t.strain.empty() ? 0 : t.strain.back())) {
      ++failed_;
      failed_sigma3_ = std::max(failed_sigma3_, t.sigma3);
    }
    out[j % T][j / T] = std::move(t);
  };
  const std::size_t n = T * M;
  if (workers_ <= 1) {
    for (std::size_t j = 0; j < n; ++j) place(j, run_compression(m, like[j % T], static_cast<int>(j / T)));
    return out;
  }
  // Each child writes its test's strains and K0s; the parent counts the runs (a child's counts end with it).
  const auto t0 = std::chrono::steady_clock::now();
  forked_runs(n, workers_, [&](std::size_t j, int fd) {
    const CompressionTest t = run_compression(m, like[j % T], static_cast<int>(j / T));
    put_bytes(fd, t.strain.data(), t.strain.size() * sizeof(Real));
    put_bytes(fd, t.k0.data(), t.k0.size() * sizeof(Real));
  }, [&](std::size_t j, int fd) {
    const CompressionTest& l = like[j % T];
    CompressionTest t{l.material, l.path, l.sigma3, l.stress, std::vector<Real>(l.stress.size()),
                      std::vector<Real>(l.stress.size()), {}, {}};
    if (!get_bytes(fd, t.strain.data(), t.strain.size() * sizeof(Real)) ||
        !get_bytes(fd, t.k0.data(), t.k0.size() * sizeof(Real)))
      return false;
    place(j, std::move(t));
    return true;
  }, "compression tests");
  count_runs(n, t0);
  return out;
}

}  // namespace dem
