#pragma once
/// A shear record's host work, from the state copied at the record (host/engine/state_copy.hpp): the balls' envelope
/// volume, and with [micro] enabled the contact set, the rows of the specimen and of its central cube, and the states
/// written at the paper's points and at a new peak. Where the steps run on a device it is done on a thread of its own
/// while the device steps on towards the next record: the host's cores would otherwise wait with the device idle
/// (docs/performance.md, "The records beside the steps"). A record worked out beside the steps gives the bits of one
/// worked out at once: the same functions on the same copy.
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/micro.hpp"
#include "host/engine/state_copy.hpp"
#include "host/triax/micro_report.hpp"

namespace dem {

/// Whether a config's records are worked out beside the steps: [micro] overlap, "auto" where the steps run on a device.
bool overlaps_records(const MicroConfig& mc);

/// One record's work: its state, the top platen's height (m; the central cube sits on the axis at half of it), the
/// specimen's volume (m^3), and the labels of the micromechanics' states to write ("A" to "D", "peak").
struct RecordJob {
  std::shared_ptr<const ContactCopy> state;
  Real top = 0;
  Real volume = 0;
  std::vector<std::string> states;
};

/// What it gives: the envelope's volume (m^3); with [micro] enabled the specimen's row and the values of the series'
/// micro columns (the specimen's, then the cube's).
struct RecordWorked {
  Real envelope_volume = 0;
  MicroRow micro;
  std::vector<double> values;
};

class RecordWork {
 public:
  /// What a record's caller does with its work, on the caller's thread.
  using Done = std::function<void(const RecordWorked&)>;

  /// The envelope of `slabs` slabs, each hull grown by `mean_radius` (m); `folder`: where the states are written
  /// (empty: nowhere).
  RecordWork(const MicroConfig& mc, Real mean_radius, int slabs, std::string folder);
  RecordWork(const RecordWork&) = delete;
  RecordWork& operator=(const RecordWork&) = delete;
  /// Waits for a record still being worked out, without its `done`: a run ending in an error keeps what it had.
  ~RecordWork();

  /// Works out `job`, at once or beside the next steps, after the record before it is finished; `done` runs at the
  /// latest in the next add() or finish().
  void add(RecordJob job, Done done);
  /// Finishes the record being worked out, if any: its `done` runs now. A failure on the other thread (a file not
  /// written) is thrown here.
  void finish();

 private:
  RecordWorked work(const RecordJob& job) const;

  MicroConfig mc_;
  Real mean_radius_;
  int slabs_;
  std::string folder_;
  bool overlap_;
  std::future<RecordWorked> pending_;
  Done done_;
};

}  // namespace dem
