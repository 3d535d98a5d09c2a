#include "checkpoint.hpp"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <cstdint>
#include <sstream>

#include "h5_file.hpp"

namespace dem {

using io::h5::H5Reader;
using io::h5::H5Writer;

namespace {

constexpr const char* kFormat = "triaxdem checkpoint 1";

template <class T>
void put(H5Writer& f, const std::string& name, hid_t type, const std::vector<T>& v, std::size_t columns = 1) {
  const hsize_t rows = v.size() / columns;
  if (columns == 1)
    f.dataset(f.root(), name, type, v.data(), {rows});
  else
    f.dataset(f.root(), name, type, v.data(), {rows, hsize_t(columns)});
}

void put_history(H5Writer& f, const std::string& prefix, const SavedContacts& h) {
  put(f, prefix + "key", H5T_NATIVE_UINT64, h.key);
  put(f, prefix + "i", H5T_NATIVE_INT, h.i);
  put(f, prefix + "j", H5T_NATIVE_INT, h.j);
  put(f, prefix + "fs", H5T_NATIVE_DOUBLE, h.fs, 3);
  put(f, prefix + "mr", H5T_NATIVE_DOUBLE, h.mr, 3);
  put(f, prefix + "slip", H5T_NATIVE_DOUBLE, h.slip);
  put(f, prefix + "flags", H5T_NATIVE_UINT8, h.flags);
  put(f, prefix + "fc", H5T_NATIVE_DOUBLE, h.fc, 3);
  put(f, prefix + "mt", H5T_NATIVE_DOUBLE, h.mt, 3);
  put(f, prefix + "fn", H5T_NATIVE_DOUBLE, h.fn);
}

SavedContacts get_history(const H5Reader& f, const std::string& prefix) {
  SavedContacts h;
  h.key = f.read<std::uint64_t>("/" + prefix + "key", H5T_NATIVE_UINT64, 1);
  h.i = f.read<int>("/" + prefix + "i", H5T_NATIVE_INT, 1);
  h.j = f.read<int>("/" + prefix + "j", H5T_NATIVE_INT, 1);
  h.fs = f.read<double>("/" + prefix + "fs", H5T_NATIVE_DOUBLE, 3);
  h.mr = f.read<double>("/" + prefix + "mr", H5T_NATIVE_DOUBLE, 3);
  h.slip = f.read<double>("/" + prefix + "slip", H5T_NATIVE_DOUBLE, 1);
  h.flags = f.read<std::uint8_t>("/" + prefix + "flags", H5T_NATIVE_UINT8, 1);
  h.fc = f.read<double>("/" + prefix + "fc", H5T_NATIVE_DOUBLE, 3);
  h.mt = f.read<double>("/" + prefix + "mt", H5T_NATIVE_DOUBLE, 3);
  h.fn = f.read<double>("/" + prefix + "fn", H5T_NATIVE_DOUBLE, 1);
  return h;
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

std::vector<std::string> split_names(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string n; std::getline(in, n, ',');)
    if (!n.empty()) out.push_back(n);
  return out;
}

/// One value of a one-value dataset.
template <class T>
T get_one(const H5Reader& f, const std::string& path, const std::string& name, hid_t type, std::size_t count = 1,
          std::size_t at = 0) {
  const std::vector<T> v = f.read<T>("/" + name, type, 1);
  if (v.size() != count) throw std::runtime_error(path + ": dataset '" + name + "' has the wrong length");
  return v[at];
}

}  // namespace

void write_checkpoint(const std::string& path, const Checkpoint& c) {
  const SimState& s = c.sim;
  io::h5::replace_atomically(path, [&](const std::string& tmp) {
    H5Writer f(tmp, path);
    f.string_attribute(".", "format", kFormat);
    f.string_attribute(".", "job", c.job);
    put(f, "step", H5T_NATIVE_INT64, std::vector<std::int64_t>{s.step});
    put(f, "time_s", H5T_NATIVE_DOUBLE, std::vector<double>{s.time});
    put(f, "dt_s", H5T_NATIVE_DOUBLE, std::vector<double>{s.dt});
    put(f, "cell_pressure_Pa", H5T_NATIVE_DOUBLE, std::vector<double>{s.cell_pressure});
    put(f, "wall_disp_m", H5T_NATIVE_DOUBLE, std::vector<double>{s.wall_disp});
    put(f, "stats", H5T_NATIVE_DOUBLE, std::vector<double>{s.stats.unbalanced, s.stats.kinetic, s.stats.max_disp2,
                                                          s.stats.max_move2});
    put(f, "flags", H5T_NATIVE_INT, std::vector<int>{s.fresh ? 1 : 0, s.stats.bad});
    const Domain& d = s.domain;
    put(f, "domain", H5T_NATIVE_DOUBLE,
        std::vector<double>{d.lo[0], d.lo[1], d.lo[2], d.hi[0], d.hi[1], d.hi[2], d.strain_rate[0],
                            d.strain_rate[1], d.strain_rate[2]}, 3);
    put(f, "periodic", H5T_NATIVE_INT, std::vector<int>{d.periodic[0], d.periodic[1], d.periodic[2]});
    for (const auto& [name, v] : {std::make_pair("x", &s.x), std::make_pair("v", &s.v), std::make_pair("w", &s.w),
                                  std::make_pair("f", &s.f), std::make_pair("m", &s.m), std::make_pair("x_ref", &s.x_ref),
                                  std::make_pair("wall_point", &s.wall_point),
                                  std::make_pair("wall_velocity", &s.wall_velocity),
                                  std::make_pair("node_x", &s.node_x), std::make_pair("node_v", &s.node_v)})
      put(f, name, H5T_NATIVE_DOUBLE, *v, 3);
    put(f, "radius", H5T_NATIVE_DOUBLE, s.radius);
    put(f, "mass", H5T_NATIVE_DOUBLE, s.mass);
    put(f, "inertia", H5T_NATIVE_DOUBLE, s.inertia);
    put(f, "gid", H5T_NATIVE_UINT32, s.gid);
    put(f, "specimen", H5T_NATIVE_INT, s.specimen);
    put(f, "material", H5T_NATIVE_INT, s.material);
    put_history(f, "balls_", s.balls);
    put_history(f, "walls_", s.walls);
    std::vector<std::string> numbers, texts;
    for (const auto& [name, v] : c.numbers) {
      put(f, "number_" + name, H5T_NATIVE_DOUBLE, v);
      numbers.push_back(name);
    }
    for (const auto& [name, text] : c.texts) {
      put(f, "text_" + name, H5T_NATIVE_CHAR, std::vector<char>(text.begin(), text.end()));
      texts.push_back(name);
    }
    f.string_attribute(".", "numbers", join_names(numbers));
    f.string_attribute(".", "texts", join_names(texts));
    f.close();
  });
}

Checkpoint read_checkpoint(const std::string& path) {
  const H5Reader f(path);
  if (f.string_attribute("/", "format") != kFormat)
    throw std::runtime_error(path + ": not a triaxdem checkpoint (root attribute 'format' is not '" + kFormat + "')");
  Checkpoint c;
  c.job = f.string_attribute("/", "job");
  SimState& s = c.sim;
  s.step = get_one<std::int64_t>(f, path, "step", H5T_NATIVE_INT64);
  s.time = get_one<double>(f, path, "time_s", H5T_NATIVE_DOUBLE);
  s.dt = get_one<double>(f, path, "dt_s", H5T_NATIVE_DOUBLE);
  s.cell_pressure = get_one<double>(f, path, "cell_pressure_Pa", H5T_NATIVE_DOUBLE);
  s.wall_disp = get_one<double>(f, path, "wall_disp_m", H5T_NATIVE_DOUBLE);
  const std::vector<double> stats = f.read<double>("/stats", H5T_NATIVE_DOUBLE, 1);
  const std::vector<int> flags = f.read<int>("/flags", H5T_NATIVE_INT, 1);
  const std::vector<double> dom = f.read<double>("/domain", H5T_NATIVE_DOUBLE, 3);
  const std::vector<int> periodic = f.read<int>("/periodic", H5T_NATIVE_INT, 1);
  if (stats.size() != 4 || flags.size() != 2 || dom.size() != 9 || periodic.size() != 3)
    throw std::runtime_error(path + ": stats, flags, domain or periodic has the wrong length");
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
    *v = f.read<double>(std::string("/") + name, H5T_NATIVE_DOUBLE, 3);
  s.radius = f.read<double>("/radius", H5T_NATIVE_DOUBLE, 1);
  s.mass = f.read<double>("/mass", H5T_NATIVE_DOUBLE, 1);
  s.inertia = f.read<double>("/inertia", H5T_NATIVE_DOUBLE, 1);
  s.gid = f.read<std::uint32_t>("/gid", H5T_NATIVE_UINT32, 1);
  s.specimen = f.read<int>("/specimen", H5T_NATIVE_INT, 1);
  s.material = f.read<int>("/material", H5T_NATIVE_INT, 1);
  s.balls = get_history(f, "balls_");
  s.walls = get_history(f, "walls_");
  for (const std::string& name : split_names(f.string_attribute("/", "numbers")))
    c.numbers[name] = f.read<double>("/number_" + name, H5T_NATIVE_DOUBLE, 1);
  for (const std::string& name : split_names(f.string_attribute("/", "texts"))) {
    const std::vector<char> bytes = f.read<char>("/text_" + name, H5T_NATIVE_CHAR, 1);
    c.texts[name] = std::string(bytes.begin(), bytes.end());
  }
  return c;
}

Checkpoint checkpoint_of(const std::string& job, const Simulation& sim, const io::Output* out) {
  Checkpoint c;
  c.job = job;
  c.sim = sim.state();
  const StageTimes& t = sim.times();
  c.numbers["stage_times_s"] = {t.rebuild, t.forces, t.integrate, t.boundaries, t.membrane,
                                static_cast<double>(t.rebuilds)};
  if (out) {
    c.numbers["series"] = out->series_rows();
    c.texts["snapshots"] = out->snapshot_index();
  }
  return c;
}

Checkpoint resume_checkpoint(const std::string& path, const std::string& job) {
  if (!std::filesystem::exists(path))
    throw std::runtime_error("--resume: no checkpoint " + path + " (run without --resume to start afresh)");
  Checkpoint c = read_checkpoint(path);
  if (c.job != job) throw std::runtime_error(path + ": written by the '" + c.job + "' job, not by '" + job + "'");
  return c;
}

void resume_from(const Checkpoint& c, Simulation& sim, io::Output* out) {
  sim.restore(c.sim);
  const auto times = c.numbers.find("stage_times_s");
  if (times != c.numbers.end() && times->second.size() == 6) {
    const std::vector<double>& t = times->second;
    sim.set_times(StageTimes{t[0], t[1], t[2], t[3], t[4], static_cast<long>(t[5])});
  }
  if (!out) return;
  const auto rows = c.numbers.find("series");
  const auto index = c.texts.find("snapshots");
  out->resume(rows == c.numbers.end() ? std::vector<double>{} : rows->second,
              index == c.texts.end() ? "" : index->second);
}

std::string checkpoint_path(const std::string& folder) { return folder + "/checkpoint.h5"; }
std::string blowup_path(const std::string& folder) { return folder + "/blowup_state.h5"; }

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
