#pragma once
/// The micromechanics of a shear stage's records. A record's contacts are copied at its state; the rest (the contact
/// set, the rows of the specimen and of its central cube, the states written at the paper's points and at a new
/// peak) is host work, which where the steps run on a device is done on a thread of its own while the device steps
/// on towards the next record: the host's cores would otherwise wait with the device idle (docs/performance.md,
/// "The records beside the steps"). A record worked out beside the steps gives the bits of one worked out at once:
/// the same functions on the same copy.
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/micro.hpp"
#include "host/triax/micro_report.hpp"

namespace dem {

/// Whether a config's records are worked out beside the steps: [micro] overlap, "auto" where the steps run on a device.
bool overlaps_records(const MicroConfig& mc);

/// One record's micromechanics: its contacts, the specimen's volume (m^3) and the central cube's centre, and the labels
/// of the states to write ("A" to "D", "peak").
struct MicroJob {
  std::shared_ptr<const ContactCopy> contacts;
  Real volume = 0;
  Vec3 centre;
  std::vector<std::string> states;
};

class MicroRecords {
 public:
  /// What a record's caller does with its micromechanics, on the caller's thread: the specimen's row and the values
  /// of its series columns (the specimen's, then the cube's).
  using Done = std::function<void(const MicroRow& row, const std::vector<double>& values)>;

  /// `folder`: where the states are written (empty: nowhere).
  MicroRecords(const MicroConfig& mc, std::string folder);
  MicroRecords(const MicroRecords&) = delete;
  MicroRecords& operator=(const MicroRecords&) = delete;
  /// Waits for a record still being worked out, without its `done`: a run ending in an error keeps what it had.
  ~MicroRecords();

  /// Works out `job`, at once or beside the next steps, after the record before it is finished; `done` runs at the
  /// latest in the next add() or finish().
  void add(MicroJob job, Done done);
  /// Finishes the record being worked out, if any: its `done` runs now. A failure on the other thread (a file not
  /// written) is thrown here.
  void finish();

 private:
  struct Result {
    MicroRow row;
    std::vector<double> values;
  };
  Result work(const MicroJob& job) const;

  MicroConfig mc_;
  std::string folder_;
  bool overlap_;
  std::future<Result> pending_;
  Done done_;
};

}  // namespace dem
