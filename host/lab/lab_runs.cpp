/// How the lab's runs are made: one at a time in the process, forked into one-thread children, side by side in one
/// batch (CellBatch), or read back from the run store; and what a run gives the lab.
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include <Kokkos_Core.hpp>
#if defined(KOKKOS_ENABLE_OPENMP)
#include <omp.h>
#endif

#include "host/lab/periodic_lab.hpp"
#include "host/lab/run_store.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/util/fnv1a.hpp"
#include "host/util/forked_runs.hpp"
#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"

namespace dem {

namespace {

/// A run that produced no test (a blow-up): every quantity NaN, counted as missing by residuals().
void mark_failed(TriaxialTest& t) {
  t.q_peak = t.eps_a_peak = t.q_end = t.max_dilatancy = t.e_ini = t.q_1pct = t.q_3pct =
      std::numeric_limits<Real>::quiet_NaN();
}

/// A run's test as the lab reports it: its curves summarised, q as `measure` (PeriodicLab::set_q_measure), or, for a
/// run that blew up (null), a missing test.
TriaxialTest lab_test(const PeriodicTriaxialResult* r, Real sigma3, const std::string& material, QMeasure measure) {
  TriaxialTest t;
  if (r) {
    if (measure == QMeasure::kFixedArea) {
      std::vector<PeriodicTriaxialRecord> rows = r->series;
      for (PeriodicTriaxialRecord& row : rows) row.q = row.q_fixed_area;
      t = summarised(rows, sigma3);
    } else {
      t = summarised(r->series, sigma3);
    }
    t.void_ratio = r->void_ratio0;
  } else {
    t.sigma3 = sigma3;
    mark_failed(t);
  }
  t.material = material;
  return t;
}

}  // namespace

TriaxialTest PeriodicLab::run(const Model& m, Real sigma3, const std::string& material, int member) {
  const auto t0 = std::chrono::steady_clock::now();
  const PackedCell& sp = specimens_.at(static_cast<std::size_t>(member));
  TriaxialTest t;
  try {
    auto sim = make_periodic_simulation(sp.balls, sp.cell, m.law, cfg_.solver, cfg_.periodic.boundary);
    const PeriodicTriaxialResult r = run_periodic_triaxial(*sim, test_params(m, sigma3));
    t = lab_test(&r, sigma3, material, q_measure_);
  } catch (const BlowUp&) {
    t = lab_test(nullptr, sigma3, material, q_measure_);
  }
  count_runs(1, t0);
  return t;
}

void prepare_parallel_runs(int workers) {
#if defined(KOKKOS_ENABLE_OPENMP)
  if (workers > 1) omp_set_num_threads(1);
#else
  (void)workers;
#endif
}

int runs_at_once(int workers) {
  // Spread over ranks, the pools' pieces go to the other ranks, one at a time each (ranks.hpp), in child processes:
  // a GPU build cannot fork once its device has started, so there every rank runs every piece itself.
  if (ranks::spread()) return kOnDevice ? 1 : std::max(2, ranks::size() - 1);
  return !kOnDevice && ExecSpace().concurrency() == 1 ? std::max(workers, 1) : 1;
}

int PeriodicLab::set_workers(int workers) { return workers_ = runs_at_once(workers); }

namespace {

/// The curves of a test as bytes to `put(pointer, count)`: row count, void ratio, then eps_a, q, eps_v (a count of
/// -1: the run blew up). Through a child's pipe (send_curves) and into the run store.
template <class Put>
void put_curves(const TriaxialTest& t, Put put) {
  const long n = std::isfinite(t.q_peak) ? static_cast<long>(t.q.size()) : -1;
  put(&n, sizeof n);
  put(&t.void_ratio, sizeof t.void_ratio);
  for (const std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v})
    if (n > 0) put(v->data(), sizeof(Real) * v->size());
}

}  // namespace

void send_curves(int fd, const TriaxialTest& t) {
  put_curves(t, [fd](const void* p, std::size_t n) { put_bytes(fd, p, n); });
}

bool receive_curves(int fd, TriaxialTest& t) {
  long n = 0;
  if (!get_bytes(fd, &n, sizeof n) || !get_bytes(fd, &t.void_ratio, sizeof t.void_ratio)) return false;
  if (n < 0) {
    mark_failed(t);
    return true;
  }
  for (std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v}) {
    v->resize(static_cast<std::size_t>(n));
    if (n > 0 && !get_bytes(fd, v->data(), sizeof(Real) * v->size())) return false;
  }
  summarise(t);
  return true;
}

bool same_model(const Model& a, const Model& b) {
  return std::memcmp(&a.law, &b.law, sizeof a.law) == 0 && std::memcmp(&a.membrane, &b.membrane, sizeof a.membrane) == 0;
}

void PeriodicLab::set_run_store(std::string folder) { store_ = std::move(folder); }

void PeriodicLab::set_q_measure(QMeasure m) {
  if (m != QMeasure::kAreaCorrected && m != QMeasure::kFixedArea)
    throw std::invalid_argument(std::string("PeriodicLab: a cell gives q as area_corrected or fixed_area, not ") +
                                name_of(m));
  q_measure_ = m;
}

std::string PeriodicLab::stored_path(const Model& m, const Case& c) const {
  if (store_.empty()) return "";
  std::uint64_t h = store_hash(cfg_);
  h = fnv1a(&m.law, sizeof m.law, h);  // Reals only: no padding
  h = fnv1a(&m.membrane, sizeof m.membrane, h);
  h = fnv1a(&c.sigma3, sizeof c.sigma3, h);
  if (q_measure_ != QMeasure::kAreaCorrected) h = fnv1a(&q_measure_, sizeof q_measure_, h);  // earlier runs' names kept
  const PackedCell& sp = specimens_.at(static_cast<std::size_t>(c.member));
  for (const BallSpec& b : sp.balls) {
    const Real v[] = {b.x.x, b.x.y, b.x.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z, b.radius, b.density};
    h = fnv1a(v, sizeof v, h);
    h = fnv1a(&b.material, sizeof b.material, h);
  }
  h = fnv1a(sp.cell.data(), sizeof(Real) * sp.cell.size(), h);
  return store_ + "/" + hex16(h) + ".run";
}

namespace {
/// A run's curves into the store (put_curves' bytes, as through a pipe).
void store_run(const std::string& path, const TriaxialTest& t) {
  if (path.empty()) return;
  std::string bytes;
  put_curves(t, [&](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); });
  write_stored(path, bytes);
}
}  // namespace

std::vector<TriaxialTest> PeriodicLab::run_cases(const Model& m, const std::vector<Case>& cases) {
  std::vector<TriaxialTest> out = run_or_read(m, cases);
  for (const TriaxialTest& t : out)
    if (!std::isfinite(t.q_peak)) ++failed_, failed_sigma3_ = std::max(failed_sigma3_, t.sigma3);
  return out;
}

std::vector<TriaxialTest> PeriodicLab::run_or_read(const Model& m, const std::vector<Case>& cases) {
  std::vector<TriaxialTest> out(cases.size());
  std::optional<Progress> progress;
  if (!progress_label_.empty()) progress.emplace(progress_label_, static_cast<long>(cases.size()));
  long done = 0;
  const auto one_done = [&]() {
    if (progress) progress->update(++done, "runs");
  };
  std::vector<std::string> paths(cases.size());
  std::vector<std::size_t> todo;  // the cases not in the store
  for (std::size_t j = 0; j < cases.size(); ++j) {
    paths[j] = stored_path(m, cases[j]);
    out[j].material = cases[j].material;
    out[j].sigma3 = cases[j].sigma3;
    if (read_stored(paths[j], [&](int fd) { return receive_curves(fd, out[j]); })) {
      ++stored_read_;
      ++runs_;  // a run of the search, read: the counts a resumed search reports are those it reported
      one_done();
    } else {
      out[j] = TriaxialTest{};
      todo.push_back(j);
    }
  }
  if (batch_ > 1 && todo.size() > 1) {
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t first = 0; first < todo.size(); first += static_cast<std::size_t>(batch_)) {
      std::vector<Case> chunk;
      for (std::size_t k = first; k < std::min(todo.size(), first + static_cast<std::size_t>(batch_)); ++k)
        chunk.push_back(cases[todo[k]]);
      const std::vector<TriaxialTest> done = run_batch(m, chunk);
      for (std::size_t k = 0; k < done.size(); ++k) {
        const std::size_t j = todo[first + k];
        out[j] = done[k];
        store_run(paths[j], out[j]);
        one_done();
      }
    }
    count_runs(todo.size(), t0);
    return out;
  }
  if (workers_ <= 1 || todo.size() <= 1) {
    for (const std::size_t j : todo) {
      out[j] = run(m, cases[j].sigma3, cases[j].material, cases[j].member);
      store_run(paths[j], out[j]);
      one_done();
    }
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  forked_runs(
      todo.size(), workers_,
      [&](std::size_t k, int fd) {
        const Case& c = cases[todo[k]];
        send_curves(fd, run(m, c.sigma3, c.material, c.member));
      },
      [&](std::size_t k, int fd) {
        const std::size_t j = todo[k];
        out[j].material = cases[j].material;
        out[j].sigma3 = cases[j].sigma3;
        const bool received = receive_curves(fd, out[j]);
        if (received) store_run(paths[j], out[j]);
        one_done();
        return received;
      },
      "calibration");
  count_runs(todo.size(), t0);
  return out;
}

std::vector<TriaxialTest> PeriodicLab::run_batch(const Model& m, const std::vector<Case>& cases) {
  std::vector<std::unique_ptr<Simulation>> made;
  std::vector<Simulation*> sims;
  std::vector<PeriodicTriaxialParams> prms;
  for (const Case& c : cases) {
    const PackedCell& sp = specimens_.at(static_cast<std::size_t>(c.member));
    made.push_back(make_periodic_simulation(sp.balls, sp.cell, m.law, cfg_.solver, cfg_.periodic.boundary));
    sims.push_back(made.back().get());
    prms.push_back(test_params(m, c.sigma3));
  }
  const std::vector<BatchedTest> runs = run_periodic_batch(sims, prms);
  std::vector<TriaxialTest> out(cases.size());
  for (std::size_t j = 0; j < cases.size(); ++j) {
    // As run() meets them: a consolidation that does not converge is the job's error, a blow-up a missing test.
    if (!runs[j].failure.empty()) throw std::runtime_error(runs[j].failure);
    out[j] = lab_test(runs[j].blowup.empty() ? &runs[j].result : nullptr, cases[j].sigma3, cases[j].material,
                      q_measure_);
  }
  return out;
}

}  // namespace dem
