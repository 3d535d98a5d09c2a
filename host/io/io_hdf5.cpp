#include "host/io/io_hdf5.hpp"

#include "host/io/h5_file.hpp"
#include "host/io/xdmf.hpp"
#include "host/util/ranks.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace dem::io {

using namespace h5;

namespace {

namespace fs = std::filesystem;

static_assert(sizeof(int) == 4, "specimen and triangle datasets are written as 32-bit integers");


std::string in_folder(const std::string& folder, const std::string& name) {
  return (fs::path(folder) / name).string();
}

std::string join(const std::vector<std::string>& parts, char sep) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? std::string(1, sep) : "") + parts[i];
  return out;
}

/// HDF5 reads '/' as a group separator, so it cannot appear in a dataset name.
std::string dataset_name(std::string name) {
  std::replace(name.begin(), name.end(), '/', '_');
  return name;
}

/// Names become dataset names, CSV header fields and comma-joined attributes: reject the ones that would
/// collide or make those ambiguous now, rather than leave a file that reads back wrong.
void check_names(const std::vector<std::string>& names, std::set<std::string> taken, const std::string& context) {
  for (const std::string& name : names) {
    const std::string ds = dataset_name(name);
    if (name.empty() || ds == "." || name.find_first_of(",\"\r\n") != std::string::npos)
      throw std::invalid_argument(context + ": name '" + name + "' is empty, '.', or has a comma, quote or newline");
    if (!taken.insert(ds).second)
      throw std::invalid_argument(context + ": name '" + name + "' clashes with another or a reserved name");
  }
}



/// series.h5 written at `tmp` (errors name `path`).
void write_series_h5(const std::string& tmp, const std::string& path, const std::vector<std::string>& columns,
                     const std::vector<double>& rows) {
  {
    H5Writer f(tmp, path);
    const hsize_t ncol = columns.size(), nrow = ncol ? rows.size() / ncol : 0;
    f.dataset(f.root(), "table", H5T_NATIVE_DOUBLE, rows.data(), {nrow, ncol});
    f.string_attribute("table", "columns", join(columns, ','));
    std::vector<double> column(nrow);
    for (hsize_t c = 0; c < ncol; ++c) {
      for (hsize_t r = 0; r < nrow; ++r) column[r] = rows[r * ncol + c];
      const std::string name = dataset_name(columns[c]);
      f.dataset(f.root(), name, H5T_NATIVE_DOUBLE, column.data(), {nrow});
      f.string_attribute(name, "name", columns[c]);
    }
    f.close();
  }
}

std::string series_csv(const std::vector<std::string>& columns, const std::vector<double>& rows) {
  std::string text = join(columns, ',') + '\n';
  char value[32];
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::snprintf(value, sizeof value, "%.10g", rows[i]);
    text += value;
    text += (i + 1) % columns.size() == 0 ? '\n' : ',';
  }
  return text;
}

/// A mismatch found here would otherwise be a read past a vector's end, or a file ParaView cannot load.
void check_snapshot(const Snapshot& s, const SurfaceSnapshot* surface) {
  const std::string context = "write_snapshot(step " + std::to_string(s.step) + ")";
  const std::size_t n = s.radius.size();
  std::vector<std::tuple<std::string, std::size_t, std::size_t>> sizes{
      {"x", s.x.size(), 3 * n}, {"v", s.v.size(), 3 * n}, {"w", s.w.size(), 3 * n},
      {"gid", s.gid.size(), n}, {"specimen", s.specimen.size(), n}};
  std::vector<std::string> names;
  for (const auto& [name, values] : s.scalars) sizes.emplace_back(name, values.size(), n), names.push_back(name);
  for (const auto& [what, got, want] : sizes)
    if (got != want)
      throw std::invalid_argument(context + ": '" + what + "' has " + std::to_string(got) + " values, expected " +
                                  std::to_string(want) + " (radius has " + std::to_string(n) + ")");
  check_names(names, {"x", "v", "w", "radius", "gid", "specimen", "cells", "surface"}, context);
  if (!surface) return;
  const long nodes = long(surface->nodes.size() / 3);
  const auto outside = [&](int node) { return node < 0 || node >= nodes; };
  if (surface->nodes.size() % 3 || surface->triangles.size() % 3 ||
      std::any_of(surface->triangles.begin(), surface->triangles.end(), outside))
    throw std::invalid_argument(context + ": surface needs node and triangle triples, with node indices below " +
                                std::to_string(nodes));
}

void write_surface(H5Writer& f, const SurfaceSnapshot& surface) {
  Handle group(f.check(H5Gcreate2(f.root(), "surface", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "create /surface"),
               H5Gclose);
  f.dataset(group.get(), "nodes", H5T_NATIVE_DOUBLE, surface.nodes.data(), {surface.nodes.size() / 3, 3});
  f.dataset(group.get(), "triangles", H5T_NATIVE_INT, surface.triangles.data(), {surface.triangles.size() / 3, 3});
}

void write_contacts(H5Writer& f, const ContactTable& c) {
  const std::size_t n = c.a.size();
  if (c.b.size() != n || c.boundary.size() != n || c.fn.size() != n || c.normal.size() != 3 * n ||
      c.point.size() != 3 * n || c.branch.size() != 3 * n || c.ft.size() != 3 * n)
    throw std::invalid_argument("write_snapshot: contact table columns of unequal length");
  Handle group(f.check(H5Gcreate2(f.root(), "contacts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "create /contacts"),
               H5Gclose);
  f.dataset(group.get(), "a", H5T_NATIVE_INT, c.a.data(), {n});
  f.dataset(group.get(), "b", H5T_NATIVE_INT, c.b.data(), {n});
  f.dataset(group.get(), "boundary", H5T_NATIVE_INT, c.boundary.data(), {n});
  f.dataset(group.get(), "fn", H5T_NATIVE_DOUBLE, c.fn.data(), {n});
  for (const auto& [name, v] : {std::pair<const char*, const std::vector<double>*>{"normal", &c.normal},
                                {"point", &c.point}, {"branch", &c.branch}, {"ft", &c.ft}})
    f.dataset(group.get(), name, H5T_NATIVE_DOUBLE, v->data(), {n, 3});
}

void write_snapshot_h5(const std::string& path, const Snapshot& s, const SurfaceSnapshot* surface,
                       const ContactTable* contacts) {
  replace_atomically(path, [&](const std::string& tmp) {
    H5Writer f(tmp, path);
    const hsize_t n = s.radius.size();
    f.dataset(f.root(), "x", H5T_NATIVE_DOUBLE, s.x.data(), {n, 3});
    f.dataset(f.root(), "v", H5T_NATIVE_DOUBLE, s.v.data(), {n, 3});
    f.dataset(f.root(), "w", H5T_NATIVE_DOUBLE, s.w.data(), {n, 3});
    f.dataset(f.root(), "radius", H5T_NATIVE_DOUBLE, s.radius.data(), {n});
    f.dataset(f.root(), "gid", H5T_NATIVE_UINT32, s.gid.data(), {n});
    f.dataset(f.root(), "specimen", H5T_NATIVE_INT, s.specimen.data(), {n});
    // One vertex cell per particle. Without this the Xdmf3 readers of ParaView make points but no cells,
    // which the default representations do not draw.
    std::vector<int> cells(n);
    std::iota(cells.begin(), cells.end(), 0);
    f.dataset(f.root(), "cells", H5T_NATIVE_INT, cells.data(), {n});
    for (const auto& [name, values] : s.scalars) {
      f.dataset(f.root(), dataset_name(name), H5T_NATIVE_DOUBLE, values.data(), {n});
      f.string_attribute(dataset_name(name), "name", name);
    }
    const std::int64_t step = s.step;
    f.attribute(".", "step", H5T_NATIVE_INT64, &step);
    f.attribute(".", "time", H5T_NATIVE_DOUBLE, &s.time);
    f.string_attribute(".", "label", s.label);
    if (surface) write_surface(f, *surface);
    if (contacts) write_contacts(f, *contacts);
    f.close();
  });
}

}  // namespace

namespace {
constexpr const char* kSeriesMarker = ".series_commit";

bool is_series_file(const std::string& name) { return name == "series.h5" || name == "series.csv"; }

/// Text written at `tmp` (errors name `path`).
void write_text_file(const std::string& tmp, const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  bool ok = f && std::fwrite(text.data(), 1, text.size(), f) == text.size();
  int err = errno;
  // fclose flushes the buffer, so it can be the call that fails (e.g. disk full).
  if (f && std::fclose(f) != 0 && ok) ok = false, err = errno;
  if (!ok) fail(path, "write '" + tmp + "': " + std::strerror(err));
}

/// Finishes a series commit that a crash interrupted (flush_series): each file the marker names that is still
/// there is renamed to its final name (the name before ".tmp."), then the marker goes. Only series.h5 and
/// series.csv of this folder are ever replaced (the folder compared as a file, so "out/" is "out").
void recover_series(const std::string& folder) {
  const std::string marker = in_folder(folder, kSeriesMarker);
  std::ifstream in(marker);
  if (!in) return;
  std::error_code ec;
  for (std::string tmp; std::getline(in, tmp);) {
    const std::size_t at = tmp.rfind(".tmp.");
    const std::string final_name = at == std::string::npos ? "" : tmp.substr(0, at);
    const fs::path target(final_name);
    if (!is_series_file(target.filename().string()) || !fs::equivalent(target.parent_path(), folder, ec) ||
        !fs::exists(tmp))
      continue;
    fs::rename(tmp, final_name, ec);
  }
  in.close();
  fs::remove(marker, ec);
}
}  // namespace

Output::Output(std::string folder) : folder_(std::move(folder)) {
  const auto refuse = [&](const std::string& reason) {
    throw std::runtime_error("output folder '" + folder_ + "' is not writable: " + reason);
  };
  std::error_code ec;
  fs::create_directories(folder_, ec);
  if (ec) refuse(ec.message());
  // Found out now rather than at the first snapshot, possibly hours into a run.
  const std::string probe = in_folder(folder_, ".write_probe.tmp");
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (!f) refuse(std::strerror(errno));
  std::fclose(f);
  if (!fs::remove(probe, ec)) refuse("cannot remove probe file: " + ec.message());
  recover_series(folder_);
}

void Output::set_series_columns(std::vector<std::string> names) {
  if (!rows_.empty())
    throw std::invalid_argument("set_series_columns: the series already has rows; set the columns before the first");
  check_names(names, {"table"}, "set_series_columns");
  columns_ = std::move(names);
}

void Output::append_series(const std::vector<double>& row) {
  if (row.size() != columns_.size() || columns_.empty())
    throw std::invalid_argument("append_series: row has " + std::to_string(row.size()) + " values but the series has " +
                                std::to_string(columns_.size()) + " columns");
  rows_.insert(rows_.end(), row.begin(), row.end());
}

// The pair is committed as one step: both files are written and flushed under temporary names, a marker names
// them, then both are renamed and the marker goes. A crash between the renames leaves the marker, and the next
// Output of the folder finishes the renames (recover_series), so a crash never leaves series.h5 and series.csv
// disagreeing. A rename that fails is an error that stops the run; the pair is then rewritten by the next flush.
void Output::flush_series() {
  const std::string h5 = in_folder(folder_, "series.h5"), csv = in_folder(folder_, "series.csv");
  h5::Staged a(h5, [&](const std::string& tmp) { write_series_h5(tmp, h5, columns_, rows_); });
  h5::Staged b(csv, [&](const std::string& tmp) { write_text_file(tmp, csv, series_csv(columns_, rows_)); });
  const std::string marker = in_folder(folder_, kSeriesMarker);
  write_text_atomic(marker, a.tmp() + "\n" + b.tmp() + "\n");
  a.commit();
  b.commit();
  std::error_code ec;
  fs::remove(marker, ec);
}

void Output::write_snapshot(const Snapshot& s, const SurfaceSnapshot* surface, const ContactTable* contacts) {
  check_snapshot(s, surface);
  char file[48];
  std::snprintf(file, sizeof file, "snap_%09ld.h5", s.step);
  write_snapshot_h5(in_folder(folder_, file), s, surface, contacts);
  Entry e{s.step, s.time, file, long(s.radius.size()), 0, 0, {}};
  if (surface) e.nsurf_nodes = long(surface->nodes.size() / 3), e.nsurf_tris = long(surface->triangles.size() / 3);
  for (const auto& scalar : s.scalars) e.scalars.push_back(scalar.first);
  // A step written again (e.g. after a restart) replaces its entry instead of adding a second one.
  const auto same = std::find_if(snaps_.begin(), snaps_.end(), [&](const Entry& o) { return o.step == s.step; });
  if (same != snaps_.end()) *same = std::move(e);
  else snaps_.push_back(std::move(e));
  write_xdmf();
}

/// Particles and surface are two temporal collections: a surface that exists only at some steps then just has
/// fewer time steps in ParaView, rather than a block that appears and vanishes.
std::string Output::snapshot_index() const {
  // One line per snapshot: step, time (round trip), file, balls, surface nodes and triangles, scalar names.
  std::string text;
  char line[160];
  for (const Entry& e : snaps_) {
    std::snprintf(line, sizeof line, "%ld %.17g %s %ld %ld %ld", e.step, e.time, e.file.c_str(), e.n, e.nsurf_nodes,
                  e.nsurf_tris);
    text += line;
    for (const std::string& name : e.scalars) text += " " + name;
    text += "\n";
  }
  return text;
}

void Output::resume(const std::vector<double>& rows, const std::string& snapshot_index) {
  if (columns_.empty() || rows.size() % columns_.size() != 0)
    throw std::runtime_error("output '" + folder_ + "': the checkpoint's series does not fit the " +
                             std::to_string(columns_.size()) + " columns of this run");
  rows_ = rows;
  snaps_.clear();
  std::istringstream in(snapshot_index);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    Entry e;
    if (!(words >> e.step >> e.time >> e.file >> e.n >> e.nsurf_nodes >> e.nsurf_tris))
      throw std::runtime_error("output '" + folder_ + "': the checkpoint's snapshot index has a bad line: " + line);
    for (std::string name; words >> name;) e.scalars.push_back(name);
    snaps_.push_back(std::move(e));
  }
}

void Output::write_xdmf() const {
  std::vector<XdmfStep> steps;
  for (const Entry& e : snaps_) {
    XdmfStep x{e.file, e.step, e.time, e.n, e.nsurf_nodes, e.nsurf_tris, {}};
    for (const std::string& name : e.scalars) x.scalars.emplace_back(name, dataset_name(name));
    steps.push_back(std::move(x));
  }
  write_text_atomic(in_folder(folder_, "snapshots.xdmf"), xdmf_document(steps));
}

FolderLock claim_output_folder(const std::string& folder, bool resume, bool overwrite) {
  FolderLock lock(folder);
  if (resume) return lock;
  // What marks a folder as a run's (every run writes these), and what else a run leaves there: the triaxial
  // job's tables and micro files, and a crashed writer's temporaries and series marker, which the next Output
  // of the folder would otherwise roll forward into the new run's series.
  const auto starts = [](const std::string& name, const char* prefix) { return name.rfind(prefix, 0) == 0; };
  std::vector<fs::path> outputs, leftovers;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string(), ext = e.path().extension().string();
    if (name == "checkpoint.h5" || name == "blowup_state.h5" || is_series_file(name) || name == "snapshots.xdmf" ||
        (starts(name, "snap_") && ext == ".h5"))
      outputs.push_back(e.path());
    else if (name == kSeriesMarker || name.find(".tmp.") != std::string::npos || name == "summary.csv" ||
             name == "layers.csv" || name == "specimen.csv" || name == "porosity_profile.csv" ||
             (starts(name, "micro_") && ext == ".csv") || (starts(name, "force_chains_") && ext == ".vtk"))
      leftovers.push_back(e.path());
  }
  if (outputs.empty()) return lock;
  if (!overwrite) {
    std::sort(outputs.begin(), outputs.end());
    throw std::runtime_error("output folder '" + folder + "' holds another run's outputs (" +
                             outputs.front().filename().string() +
                             (outputs.size() > 1 ? " and " + std::to_string(outputs.size() - 1) + " more" : "") +
                             "): continue that run with --resume, replace it with --overwrite, or choose "
                             "another folder with -o");
  }
  for (const fs::path& p : outputs) fs::remove(p);
  for (const fs::path& p : leftovers) fs::remove(p);
  return lock;
}

void write_text_atomic(const std::string& path, const std::string& text) {
  if (!ranks::leader()) return;  // a shadow rank computes what the leader writes
  replace_atomically(path, [&](const std::string& tmp) { write_text_file(tmp, path, text); });
}


}  // namespace dem::io
