#pragma once
/// The calibration simulator: periodic-cell triaxial runs (host/triax/periodic_triaxial.hpp) on an ensemble of
/// specimens, each prepared once from the base config with its own packing seed and reused at every parameter
/// point (common random numbers: the difference between two points is then the parameters' effect, not the
/// specimens'). Member k packs with seed first_seed + k; data made for tests draw their specimens from seeds
/// outside that set (kForeignSeedOffset), as real data come from specimens the simulator never saw.
#include <array>
#include <chrono>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "host/config/config.hpp"
#include "host/data/compression_data.hpp"
#include "host/engine/builder.hpp"
#include "host/data/measured.hpp"
#include "host/lab/packing_store.hpp"
#include "host/lab/state_match.hpp"

namespace dem {

/// A model to simulate: contact law (with extensions) and the membrane extension (Pa, E_m t / R0).
struct Model {
  ContactParams law;
  Real membrane = 0;
};

/// The model of a config: its ball law and the periodic cell's membrane.
Model model_of(const Config& cfg);
/// Whether two models are the same, bit for bit (their Reals: the run store names a run by the same bytes).
bool same_model(const Model& a, const Model& b);

/// Simulated tests of an ensemble: [test][member], each summarised like measured curves.
using Ensemble = std::vector<std::vector<TriaxialTest>>;

/// Packing seeds of synthetic data start this far above the config's seed: never a member of an ensemble
/// (at most 64 members, config.cpp).
constexpr unsigned kForeignSeedOffset = 100000;

/// The base config with `factor` times the balls in a box as many times larger (same packing density).
Config larger_cell(const Config& base, int factor);

class PeriodicLab {
 public:
  /// `specimens` specimens with packing seeds first_seed, first_seed + 1, ..., of which the first `members`
  /// (at most all) form the ensemble that run_ensemble runs. They are packed up to `workers` at once (set_workers).
  PeriodicLab(const Config& base, bool verbose, int members, unsigned first_seed, int specimens = 0, int workers = 1);
  /// The config's ensemble ([calibrate] ensemble, scatter_specimens), cell ([calibrate] cell_factor) and seed
  /// ([run] seed); an "auto" ensemble starts as all the scatter specimens and an "auto" cell as the config's,
  /// until measure_misfit chooses.
  PeriodicLab(const Config& base, bool verbose, int workers = 1);
  /// One simulated test (curves, summarised; its void ratio at the start of shear) of one member at sigma3 (Pa).
  TriaxialTest run(const Model& m, Real sigma3, const std::string& material = "sim", int member = 0);
  /// Every test of `like` (its materials and pressures) on every member (on every specimen with `all`); up to
  /// workers() runs at once.
  Ensemble run_ensemble(const Model& m, const std::vector<TriaxialTest>& like, bool all = false);
  /// Part of the ensemble of `members` members: its cases [from, to) in member-major order (case c: test c % T of
  /// `like` on member c / T), each test's runs in member order (a search's screening runs the first member's tests,
  /// and as many more as fill the workers, before the rest).
  Ensemble run_part(const Model& m, const std::vector<TriaxialTest>& like, std::size_t members, std::size_t from,
                    std::size_t to);
  /// Test j of `like` (its material and pressure) on member j % members(): data made on a specimen per test.
  std::vector<TriaxialTest> run_each(const Model& m, const std::vector<TriaxialTest>& like);
  /// A compression test as `like` (its path, seating stress and increments) on member's specimen, at model m: the strain
  /// and K0 at each increment (host/triax/compression_test.hpp); a run that blew up or did not come to rest gives NaN
  /// (missing data), counted in failed_runs().
  CompressionTest run_compression(const Model& m, const CompressionTest& like, int member);
  /// Every test of `like` on every member (every specimen with `all`), [test][member], up to workers() at once.
  std::vector<std::vector<CompressionTest>> run_compressions(const Model& m, const std::vector<CompressionTest>& like,
                                                             bool all = false);
  /// Runs at once: each in a child process (fork) with the same specimens; the results are the same as one at a
  /// time, bit for bit. Only where that is safe: a host backend on one thread (OMP_NUM_THREADS=1); otherwise
  /// the runs go one at a time with all threads. Returns the value in effect.
  int set_workers(int workers);
  int workers() const { return workers_; }
  /// Runs stepped side by side in this process, at most `batch` at once ([calibrate] batch; kAutoBatch: all of a
  /// call on a GPU build, 1 on a CPU); 1 runs them one at a time or forked (set_workers). A cell between walls is
  /// never batched. Returns the value in effect.
  int set_batch(long batch);
  int batch() const { return batch_; }
  int members() const { return members_; }
  /// Makes the first k specimens the ensemble (1 <= k <= specimens()).
  void set_members(int k);
  /// Packs every specimen again (same seeds) in a cell of `factor` times the balls (larger_cell), workers() at once.
  /// Where `state` holds a match to the data's void ratio, the preparation friction is matched again, on the larger
  /// cell's first specimens (prep_friction_for). Returns the match on the larger cell (`state` where it holds none).
  StateMatch grow_cell(int factor, const StateMatch& state);
  /// The cell's balls as a multiple of the config's.
  int cell_factor() const { return cell_factor_; }
  /// Whether the lab reports its own work (packings, the state match of a grown cell) as it goes.
  bool verbose() const { return verbose_; }
  int specimens() const { return static_cast<int>(specimens_.size()); }
  const Config& config() const { return cfg_; }
  /// Keeps every run's curves in `folder` (one file each, named by a hash of the model, the pressure, the
  /// specimen's balls, the config and the program's version) as it ends, and reads a run found there instead of
  /// running it again: a calibration writes what it has as it goes, and one resumed in its folder replays its
  /// search from the stored runs, bit for bit. "" keeps nothing.
  void set_run_store(std::string folder);
  const std::string& run_store() const { return store_; }
  /// Which deviator the lab's tests carry as q: the cell's own (area_corrected: over the current cross-section, the
  /// default) or over the cross-section at the start of shear (fixed_area), as the data name theirs.
  void set_q_measure(QMeasure m);
  QMeasure q_measure() const { return q_measure_; }
  /// Of runs(), those read from the store instead of run.
  long stored_runs_read() const { return stored_read_; }
  /// Names the runs that follow in a progress line with ETA (each batch of runs counts them); "" for none: a
  /// calibration's search reports its own progress, the scatter measurement and the state match this way.
  void set_progress(std::string label) { progress_label_ = std::move(label); }
  long runs() const { return runs_; }
  /// Of runs(), those a blow-up stopped (their data count as missing), and the highest pressure of one (Pa).
  long failed_runs() const { return failed_; }
  Real highest_failed_sigma3() const { return failed_sigma3_; }
  /// More than half of the runs stopped at a blow-up: a result would rest on the few that ended (a calibration of
  /// sigma3 typed in Pa under a kPa header once reported mu_s = 0.05 from 126 blown-up runs).
  bool mostly_failed() const { return 2 * failed_ > runs_; }
  double seconds() const { return seconds_; }
  std::size_t balls() const { return specimens_.front().balls.size(); }
  /// Void ratio of member k's specimen after its preparation (at the preparation pressure).
  Real prepared_void_ratio(int k) const { return specimen(k).void_ratio; }
  /// Member k's specimen as packed and prepared.
  const PackedCell& specimen(int k) const { return specimens_[static_cast<std::size_t>(k)]; }

 private:
  Config cfg_;
  std::vector<PackedCell> specimens_;
  long runs_ = 0;
  long failed_ = 0;
  Real failed_sigma3_ = 0;
  double seconds_ = 0;
  std::string progress_label_;
  std::string store_;
  QMeasure q_measure_ = QMeasure::kAreaCorrected;
  long stored_read_ = 0;
  int workers_ = 1;
  int batch_ = 1;
  int members_ = 1;
  int cell_factor_ = 1;
  unsigned first_seed_ = 0;
  bool verbose_ = false;
  /// Packs `count` specimens (seeds first_seed_ on), reading those the packing store holds (Config::packing_store)
  /// and keeping those it packs; `verbose`: a progress line with ETA, and the first one's preparation where the
  /// specimens are packed one at a time.
  void pack(int count, bool verbose);
  /// One run to make: a test's material and pressure on one member's specimen.
  struct Case {
    std::string material;
    Real sigma3;
    int member;
  };
  /// run_or_read, then the blown-up runs among them counted (failed_runs), whichever way each test came.
  std::vector<TriaxialTest> run_cases(const Model& m, const std::vector<Case>& cases);
  /// The cases in order, up to workers() at once; those in the run store are read.
  std::vector<TriaxialTest> run_or_read(const Model& m, const std::vector<Case>& cases);
  /// The cases side by side in one batch (run_periodic_batch), each as run() gives it.
  std::vector<TriaxialTest> run_batch(const Model& m, const std::vector<Case>& cases);
  /// n runs made since t0: counted in runs() and seconds(), and in the process's lab_time().
  void count_runs(std::size_t n, std::chrono::steady_clock::time_point t0);
  /// The test parameters of a run at sigma3 (Pa) of model m.
  PeriodicTriaxialParams test_params(const Model& m, Real sigma3) const;
  /// The run store's file of a case ("" without a store).
  std::string stored_path(const Model& m, const Case& c) const;
};

/// Where this process's labs spent their time (every lab's: the state match's and the cell check's too), for a
/// job's account of its time: wall seconds running the simulator, the runs made (not read from a store), and wall
/// seconds packing specimens.
struct LabTime {
  double runs = 0;
  long ran = 0;
  double packing = 0;
};
LabTime lab_time();

/// Runs at once that `workers` asks for, where that is safe (PeriodicLab::set_workers); otherwise 1.
int runs_at_once(int workers);

/// Before Kokkos starts, in a program that will run `workers` > 1 simulator runs at once: sets OpenMP to one
/// thread (its runtime read OMP_NUM_THREADS when it was loaded, before main, so through its API), as
/// PeriodicLab::set_workers requires.
void prepare_parallel_runs(int workers);

}  // namespace dem
