#pragma once
/// Output of a run: HDF5 files that ParaView opens through an XDMF index, and CSV time series.
/// Every file is written to "<name>.tmp" and renamed into place, so a crash never leaves a half-written
/// file under a final name and nothing already written is lost.
///
/// Layout of an output folder:
///   series.h5 / series.csv    one row per record: columns named by the caller (SI units, names carry units)
///   snap_<step>.h5            one particle snapshot: /x (n x 3, m), /v (n x 3, m/s), /w (n x 3, rad/s),
///                             /radius (n, m), /gid (n), /specimen (n), extra per-particle fields
///   snapshots.xdmf            temporal collection over all snapshots (ParaView: open this file)
#include <cstdint>
#include <string>
#include <vector>

#include "host/util/folder_lock.hpp"

namespace dem::io {

/// One particle snapshot on the host, structure of arrays; vectors are interleaved (x0,y0,z0,x1,...).
struct Snapshot {
  long step = 0;
  double time = 0;           ///< s
  std::string label;         ///< free text, e.g. "shear eps_a=5%"
  std::vector<double> x, v, w;              ///< n*3 each
  std::vector<double> radius;               ///< n
  std::vector<std::uint32_t> gid;           ///< n
  std::vector<int> specimen;                ///< n
  /// Extra named per-particle scalars (e.g. "coordination"), each of length n.
  std::vector<std::pair<std::string, std::vector<double>>> scalars;
};

/// Triangle surface (membrane) snapshot: nodes n*3 (m) and triangles m*3 (node indices).
struct SurfaceSnapshot {
  std::vector<double> nodes;
  std::vector<int> triangles;
};

/// Touching contacts of a snapshot (group /contacts), structure of arrays: a and b are gids (b = -1 at a
/// boundary), boundary 0 = none, 1 = platen, 2 = membrane; normal, point, branch and ft are n x 3 (m, N), fn
/// is n (N). The force a exerts on b (or on the boundary) is fn normal + ft.
struct ContactTable {
  std::vector<int> a, b, boundary;
  std::vector<double> normal, point, branch, fn, ft;
};

/// A snapshot file read back.
struct SnapshotFile {
  Snapshot particles;             ///< x and radius by row; v, w, scalars not read
  bool has_surface = false;
  SurfaceSnapshot surface;
  bool has_contacts = false;
  ContactTable contacts;
};
/// Reads a snap_<step>.h5 written by Output. Throws std::runtime_error naming the file and what is missing.
SnapshotFile read_snapshot(const std::string& path);

/// Writes a run's output folder. Not thread-safe; one per run.
class Output {
 public:
  /// Creates the folder if needed; refuses (throws std::runtime_error naming the folder) if it is not writable.
  explicit Output(std::string folder);
  const std::string& folder() const { return folder_; }

  /// Sets the column names of the time series (once, before the first row).
  void set_series_columns(std::vector<std::string> names);
  /// Appends a row (same length as the columns). Rows are kept in memory and written by flush_series().
  void append_series(const std::vector<double>& row);
  /// Rewrites series.h5 and series.csv atomically from all rows so far.
  void flush_series();

  /// Writes snap_<step>.h5 (with the optional surface in /surface and contacts in /contacts) and rewrites
  /// snapshots.xdmf.
  void write_snapshot(const Snapshot& s, const SurfaceSnapshot* surface = nullptr,
                      const ContactTable* contacts = nullptr);

  /// What a checkpoint keeps of the output, to resume it: the series rows and the snapshot index (text).
  const std::vector<double>& series_rows() const { return rows_; }
  std::string snapshot_index() const;
  /// Continues an output from a checkpoint: the rows and index it kept (later rows and snapshots, written
  /// by the run after its checkpoint, are replaced as the resumed run reaches them). Columns must be set.
  /// Throws std::runtime_error on a row length or index line that does not fit.
  void resume(const std::vector<double>& rows, const std::string& snapshot_index);

 private:
  std::string folder_;
  std::vector<std::string> columns_;
  std::vector<double> rows_;  // row-major
  struct Entry { long step; double time; std::string file; long n; long nsurf_nodes; long nsurf_tris; std::vector<std::string> scalars; };
  std::vector<Entry> snaps_;
  void write_xdmf() const;
};

/// Makes `folder` the output of a new run (resume: the continuation of the run there), locked for as long as the
/// returned lock lives (FolderLock: a second run into it is refused). A folder that holds another run's outputs
/// (checkpoint, series, snapshots) is refused, so that a later --resume cannot mix two runs, unless `overwrite`:
/// then those files are removed first. Throws std::runtime_error naming the folder and what holds it.
[[nodiscard]] FolderLock claim_output_folder(const std::string& folder, bool resume, bool overwrite);

/// Writes text to path atomically (a temporary file of this process, flushed, then renamed). Throws
/// std::runtime_error naming the path.
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace dem::io
