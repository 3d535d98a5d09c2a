#include "host/engine/checkpoint.hpp"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <cstdint>
#include <sstream>

#include "host/engine/setup.hpp"
#include "host/util/fnv1a.hpp"
#include "host/io/h5_file.hpp"
#include "host/util/text_format.hpp"

namespace dem {

using io::h5::H5Reader;
using io::h5::H5Writer;

namespace {

constexpr const char* kFormatName = "triaxdem checkpoint ";
constexpr int kFormatVersion = 2;

/// A checksum of everything a checkpoint holds: the sum (mod 2^64) of each dataset's FNV-1a hash over its name
/// and bytes, and of the job and config attributes. A sum, so that the order of reading does not matter; a hash
/// per dataset, so that a value moved from one dataset to another does not cancel.
struct Seal {
  std::uint64_t sum = 0;
  void add(const std::string& name, const void* data, std::size_t bytes) {
    sum += fnv1a(data, bytes, fnv1a(name.c_str(), name.size() + 1));
  }
  std::string hex() const { return hex16(sum); }
};

/// Writes datasets and seals them.
struct SealedWriter {
  H5Writer& f;
  Seal seal;
  template <class T>
  void put(const std::string& name, hid_t type, const std::vector<T>& v, std::size_t columns = 1) {
    const hsize_t rows = v.size() / columns;
    if (columns == 1)
      f.dataset(f.root(), name, type, v.data(), {rows});
    else
      f.dataset(f.root(), name, type, v.data(), {rows, hsize_t(columns)});
    seal.add(name, v.data(), v.size() * sizeof(T));
  }
  void attribute(const std::string& name, const std::string& value) {
    f.string_attribute(".", name, value);
    seal.add("@" + name, value.data(), value.size());
  }
};

/// Reads datasets and adds them to the seal, to be compared with the stored checksum at the end.
struct SealedReader {
  const H5Reader& f;
  Seal seal;
  template <class T>
  std::vector<T> read(const std::string& name, hid_t type, std::size_t columns = 1) {
    std::vector<T> v = f.read<T>("/" + name, type, columns);
    seal.add(name, v.data(), v.size() * sizeof(T));
    return v;
  }
  std::string attribute(const std::string& name) {
    const std::string v = f.string_attribute("/", name);
    seal.add("@" + name, v.data(), v.size());
    return v;
  }
};

void put_history(SealedWriter& f, const std::string& prefix, const SavedContacts& h) {
  f.put(prefix + "key", H5T_NATIVE_UINT64, h.key);
  f.put(prefix + "i", H5T_NATIVE_INT, h.i);
  f.put(prefix + "j", H5T_NATIVE_INT, h.j);
  f.put(prefix + "fs", H5T_NATIVE_DOUBLE, h.fs, 3);
  f.put(prefix + "mr", H5T_NATIVE_DOUBLE, h.mr, 3);
  for (int s = 0; s < kHistorySlots; ++s) f.put(prefix + kHistorySlotNames[s], H5T_NATIVE_DOUBLE, h.slot[s]);
  f.put(prefix + "flags", H5T_NATIVE_UINT8, h.flags);
  f.put(prefix + "fc", H5T_NATIVE_DOUBLE, h.fc, 3);
  f.put(prefix + "mt", H5T_NATIVE_DOUBLE, h.mt, 3);
  f.put(prefix + "fn", H5T_NATIVE_DOUBLE, h.fn);
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

std::vector<std::string> split_names(const std::string& s) {
  std::vector<std::string> out;
  for (const std::string& n : split_fields(s))
    if (!n.empty()) out.push_back(n);
  return out;
}

SavedContacts get_history(SealedReader& f, const std::string& prefix) {
  SavedContacts h;
  h.key = f.read<std::uint64_t>(prefix + "key", H5T_NATIVE_UINT64);
  h.i = f.read<int>(prefix + "i", H5T_NATIVE_INT);
  h.j = f.read<int>(prefix + "j", H5T_NATIVE_INT);
  h.fs = f.read<double>(prefix + "fs", H5T_NATIVE_DOUBLE, 3);
  h.mr = f.read<double>(prefix + "mr", H5T_NATIVE_DOUBLE, 3);
  for (int s = 0; s < kHistorySlots; ++s) h.slot[s] = f.read<double>(prefix + kHistorySlotNames[s], H5T_NATIVE_DOUBLE);
  h.flags = f.read<std::uint8_t>(prefix + "flags", H5T_NATIVE_UINT8);
  h.fc = f.read<double>(prefix + "fc", H5T_NATIVE_DOUBLE, 3);
  h.mt = f.read<double>(prefix + "mt", H5T_NATIVE_DOUBLE, 3);
  h.fn = f.read<double>(prefix + "fn", H5T_NATIVE_DOUBLE);
  return h;
}

/// The values a dataset of exactly `count` values holds.
template <class T>
std::vector<T> exactly(SealedReader& f, const std::string& path, const std::string& name, hid_t type,
                       std::size_t count, std::size_t columns = 1) {
  std::vector<T> v = f.read<T>(name, type, columns);
  if (v.size() != count)
    throw std::runtime_error(path + ": dataset '/" + name + "' has " + std::to_string(v.size()) + " values (allowed: " +
                             std::to_string(count) + ")");
  return v;
}

/// The counts a checkpoint declares (balls, ball-ball and ball-wall contacts, walls, mesh nodes), against which
/// every array's rows are checked: a truncated or spliced file disagrees with them.
std::vector<std::int64_t> counts_of(const SimState& s) {
  return {static_cast<std::int64_t>(s.radius.size()), static_cast<std::int64_t>(s.balls.key.size()),
          static_cast<std::int64_t>(s.walls.key.size()), static_cast<std::int64_t>(s.wall_point.size() / 3),
          static_cast<std::int64_t>(s.node_x.size() / 3)};
}

}  // namespace

void write_checkpoint(const std::string& path, const Checkpoint& c) {
  const SimState& s = c.sim;
  io::h5::replace_atomically(path, [&](const std::string& tmp) {
    H5Writer h5(tmp, path);
    SealedWriter f{h5, {}};
    h5.string_attribute(".", "format", kFormatName + std::to_string(kFormatVersion));
    f.attribute("job", c.job);
    f.attribute("config", c.config);
    f.put("counts", H5T_NATIVE_INT64, counts_of(s));
    f.put("step", H5T_NATIVE_INT64, std::vector<std::int64_t>{s.step});
    f.put("time_s", H5T_NATIVE_DOUBLE, std::vector<double>{s.time});
    f.put("dt_s", H5T_NATIVE_DOUBLE, std::vector<double>{s.dt});
    f.put("cell_pressure_Pa", H5T_NATIVE_DOUBLE, std::vector<double>{s.cell_pressure});
    f.put("wall_disp_m", H5T_NATIVE_DOUBLE, std::vector<double>{s.wall_disp});
    f.put("stats", H5T_NATIVE_DOUBLE, std::vector<double>{s.stats.unbalanced, s.stats.kinetic, s.stats.max_disp2,
                                                          s.stats.max_move2});
    f.put("flags", H5T_NATIVE_INT, std::vector<int>{s.fresh ? 1 : 0, s.stats.bad});
    const Domain& d = s.domain;
    f.put("domain", H5T_NATIVE_DOUBLE,
          std::vector<double>{d.lo[0], d.lo[1], d.lo[2], d.hi[0], d.hi[1], d.hi[2], d.strain_rate[0],
                              d.strain_rate[1], d.strain_rate[2]}, 3);
    f.put("periodic", H5T_NATIVE_INT, std::vector<int>{d.periodic[0], d.periodic[1], d.periodic[2]});
    for (const auto& [name, v] : {std::make_pair("x", &s.x), std::make_pair("v", &s.v), std::make_pair("w", &s.w),
                                  std::make_pair("f", &s.f), std::make_pair("m", &s.m), std::make_pair("x_ref", &s.x_ref),
                                  std::make_pair("wall_point", &s.wall_point),
                                  std::make_pair("wall_velocity", &s.wall_velocity),
                                  std::make_pair("node_x", &s.node_x), std::make_pair("node_v", &s.node_v)})
      f.put(name, H5T_NATIVE_DOUBLE, *v, 3);
    f.put("radius", H5T_NATIVE_DOUBLE, s.radius);
    f.put("mass", H5T_NATIVE_DOUBLE, s.mass);
    f.put("inertia", H5T_NATIVE_DOUBLE, s.inertia);
    f.put("gid", H5T_NATIVE_UINT32, s.gid);
    f.put("specimen", H5T_NATIVE_INT, s.specimen);
    f.put("material", H5T_NATIVE_INT, s.material);
    put_history(f, "balls_", s.balls);
    put_history(f, "walls_", s.walls);
    std::vector<std::string> numbers, texts;
    for (const auto& [name, v] : c.numbers) {
      f.put("number_" + name, H5T_NATIVE_DOUBLE, v);
      numbers.push_back(name);
    }
    for (const auto& [name, text] : c.texts) {
      f.put("text_" + name, H5T_NATIVE_CHAR, std::vector<char>(text.begin(), text.end()));
      texts.push_back(name);
    }
    f.attribute("numbers", join_names(numbers));
    f.attribute("texts", join_names(texts));
    h5.string_attribute(".", "checksum", f.seal.hex());
    h5.close();
  });
}

Checkpoint read_checkpoint(const std::string& path) {
  const H5Reader h5(path);
  const std::string format = h5.string_attribute("/", "format");
  const std::string version = kFormatName + std::to_string(kFormatVersion);
  if (format.rfind(kFormatName, 0) == 0 && format != version)
    throw std::runtime_error(path + ": checkpoint format '" + format + "', this triaxdem reads '" + version +
                             "' (written by another version: run afresh without --resume)");
  if (format != version)
    throw std::runtime_error(path + ": not a triaxdem checkpoint (root attribute 'format' is not '" + version + "')");
  SealedReader f{h5, {}};
  Checkpoint c;
  c.job = f.attribute("job");
  c.config = f.attribute("config");
  const std::vector<std::int64_t> counts = exactly<std::int64_t>(f, path, "counts", H5T_NATIVE_INT64, 5);
  SimState& s = c.sim;
  s.step = exactly<std::int64_t>(f, path, "step", H5T_NATIVE_INT64, 1)[0];
  s.time = exactly<double>(f, path, "time_s", H5T_NATIVE_DOUBLE, 1)[0];
  s.dt = exactly<double>(f, path, "dt_s", H5T_NATIVE_DOUBLE, 1)[0];
  s.cell_pressure = exactly<double>(f, path, "cell_pressure_Pa", H5T_NATIVE_DOUBLE, 1)[0];
  s.wall_disp = exactly<double>(f, path, "wall_disp_m", H5T_NATIVE_DOUBLE, 1)[0];
  const std::vector<double> stats = exactly<double>(f, path, "stats", H5T_NATIVE_DOUBLE, 4);
  const std::vector<int> flags = exactly<int>(f, path, "flags", H5T_NATIVE_INT, 2);
  const std::vector<double> dom = exactly<double>(f, path, "domain", H5T_NATIVE_DOUBLE, 9, 3);
  const std::vector<int> periodic = exactly<int>(f, path, "periodic", H5T_NATIVE_INT, 3);
  s.stats.unbalanced = stats[0];
  s.stats.kinetic = stats[1];
  s.stats.max_disp2 = stats[2];
  s.stats.max_move2 = stats[3];
  s.fresh = flags[0] != 0;
  s.stats.bad = flags[1];
  for (int k = 0; k < 3; ++k) {
    s.domain.lo[k] = dom[k];
    s.domain.hi[k] = dom[3 + k];
    s.domain.strain_rate[k] = dom[6 + k];
    s.domain.periodic[k] = periodic[k] != 0;
  }
  for (const auto& [name, v] : {std::make_pair("x", &s.x), std::make_pair("v", &s.v), std::make_pair("w", &s.w),
                                std::make_pair("f", &s.f), std::make_pair("m", &s.m), std::make_pair("x_ref", &s.x_ref),
                                std::make_pair("wall_point", &s.wall_point),
                                std::make_pair("wall_velocity", &s.wall_velocity),
                                std::make_pair("node_x", &s.node_x), std::make_pair("node_v", &s.node_v)})
    *v = f.read<double>(name, H5T_NATIVE_DOUBLE, 3);
  s.radius = f.read<double>("radius", H5T_NATIVE_DOUBLE);
  s.mass = f.read<double>("mass", H5T_NATIVE_DOUBLE);
  s.inertia = f.read<double>("inertia", H5T_NATIVE_DOUBLE);
  s.gid = f.read<std::uint32_t>("gid", H5T_NATIVE_UINT32);
  s.specimen = f.read<int>("specimen", H5T_NATIVE_INT);
  s.material = f.read<int>("material", H5T_NATIVE_INT);
  s.balls = get_history(f, "balls_");
  s.walls = get_history(f, "walls_");
  for (const std::string& name : split_names(f.attribute("numbers")))
    c.numbers[name] = f.read<double>("number_" + name, H5T_NATIVE_DOUBLE);
  for (const std::string& name : split_names(f.attribute("texts"))) {
    const std::vector<char> bytes = f.read<char>("text_" + name, H5T_NATIVE_CHAR);
    c.texts[name] = std::string(bytes.begin(), bytes.end());
  }
  const std::string stored = h5.string_attribute("/", "checksum");
  if (stored != f.seal.hex())
    throw std::runtime_error(path + ": checksum " + f.seal.hex() + " where the file says " + stored +
                             ": the checkpoint was edited or damaged after triaxdem wrote it");
  const std::vector<std::int64_t> have = counts_of(s);
  const char* what[5] = {"balls", "ball-ball contacts", "ball-wall contacts", "walls", "mesh nodes"};
  for (int k = 0; k < 5; ++k)
    if (have[k] != counts[k])
      throw std::runtime_error(path + ": the file declares " + std::to_string(counts[k]) + " " + what[k] + " and holds " +
                               std::to_string(have[k]));
  return c;
}

Checkpoint checkpoint_of(const std::string& job, const Simulation& sim, const io::Output* out,
                         const std::string& config) {
  Checkpoint c;
  c.job = job;
  c.config = config;
  c.sim = sim.state();
  const StageTimes& t = sim.times();
  c.numbers["stage_times_s"] = {t.rebuild, t.forces, t.integrate, t.boundaries, t.membrane,
                                static_cast<double>(t.rebuilds), t.walls};
  if (out) {
    c.numbers["series"] = out->series_rows();
    c.texts["snapshots"] = out->snapshot_index();
  }
  return c;
}

Checkpoint resume_checkpoint(const std::string& path, const std::string& job, const std::string& config) {
  if (!std::filesystem::exists(path))
    throw std::runtime_error("--resume: no checkpoint " + path + " (run without --resume to start afresh)");
  Checkpoint c = read_checkpoint(path);
  if (c.job != job) throw std::runtime_error(path + ": written by the '" + c.job + "' job, not by '" + job + "'");
  if (!c.config.empty() && !config.empty() && c.config != config)
    throw std::runtime_error(path + ": written with another config (fingerprint " + c.config + ", this config " +
                             config + "): resume with the config that ran it, or start afresh without --resume");
  return c;
}

void resume_from(const Checkpoint& c, Simulation& sim, io::Output* out) {
  sim.restore(c.sim);
  const auto times = c.numbers.find("stage_times_s");
  // Six numbers: a checkpoint from before the ball-wall share was timed on its own (it is in the forces).
  if (times != c.numbers.end() && (times->second.size() == 6 || times->second.size() == 7)) {
    const std::vector<double>& t = times->second;
    sim.set_times(StageTimes{t[0], t[1], t[2], t[3], t[4], static_cast<long>(t[5]), t.size() == 7 ? t[6] : 0});
  }
  if (!out) return;
  const auto rows = c.numbers.find("series");
  const auto index = c.texts.find("snapshots");
  out->resume(rows == c.numbers.end() ? std::vector<double>{} : rows->second,
              index == c.texts.end() ? "" : index->second);
}

std::string checkpoint_path(const std::string& folder) { return folder + "/checkpoint.h5"; }
std::string blowup_path(const std::string& folder) { return folder + "/blowup_state.h5"; }

void save_blowup_state(io::Output& out, Simulation& sim, const std::string& job, const std::string& config) {
  out.flush_series();
  out.write_snapshot(take_snapshot(sim, "blow-up"));
  write_checkpoint(blowup_path(out.folder()), checkpoint_of(job, sim, &out, config));
}

// ---------------------------------------------------------------------------------------------------

namespace {
double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

CheckpointClock::CheckpointClock(long every_steps, double minutes)
    : every_(every_steps), seconds_(60 * minutes), last_(now_seconds()) {}

bool CheckpointClock::due(long step) const {
  return (every_ > 0 && step % every_ == 0) || (seconds_ > 0 && now_seconds() - last_ >= seconds_);
}

void CheckpointClock::written() { last_ = now_seconds(); }

bool CheckpointPlan::due(long step) const {
  return !path.empty() && (clock.due(step) || stop(step));
}

bool CheckpointPlan::stop(long step) const { return StopSignals::requested() || step == stop_at_step; }

RunStopped run_stopped(const CheckpointPlan& plan, long step) {
  const bool signal = StopSignals::requested();
  return RunStopped(std::string(signal ? StopSignals::name() : "stop_at_step") + " at step " + std::to_string(step) +
                        ": checkpoint " + plan.path + " written; continue with --resume",
                    signal ? 128 + StopSignals::signal() : 3);
}

namespace {
volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_stop_signal(int sig) { g_signal = sig; }
using Handler = void (*)(int);
Handler g_old_int = SIG_DFL, g_old_term = SIG_DFL;
}  // namespace

StopSignals::StopSignals() {
  g_signal = 0;
  g_old_int = std::signal(SIGINT, on_stop_signal);
  g_old_term = std::signal(SIGTERM, on_stop_signal);
}

StopSignals::~StopSignals() {
  std::signal(SIGINT, g_old_int);
  std::signal(SIGTERM, g_old_term);
}

bool StopSignals::requested() { return g_signal != 0; }
int StopSignals::signal() { return g_signal; }
const char* StopSignals::name() { return g_signal == SIGINT ? "SIGINT" : g_signal == SIGTERM ? "SIGTERM" : ""; }

}  // namespace dem
