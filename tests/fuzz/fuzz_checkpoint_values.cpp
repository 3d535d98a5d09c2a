/// Checkpoints whose HDF5 structure is well formed (written by write_checkpoint, sealed) and whose content is the
/// fuzzer's: counts, gids, materials, contact keys and indices, every value. libhdf5 then parses only valid files,
/// and what is fuzzed is triaxdem's reading and checking of what the file holds (read_checkpoint, check_state):
/// a state must be refused with a runtime_error or be one a simulation can take.
#include <fuzzer/FuzzedDataProvider.h>

#include "fuzz_file.hpp"
#include "host/engine/checkpoint.hpp"

namespace {
std::vector<double> values(FuzzedDataProvider& in, std::size_t n) {
  std::vector<double> v(n);
  for (double& x : v) x = in.ConsumeBool() ? in.ConsumeFloatingPoint<double>() : in.ConsumeFloatingPointInRange(-1.0, 1.0);
  return v;
}
template <class T>
std::vector<T> indices(FuzzedDataProvider& in, std::size_t n, T most) {
  std::vector<T> v(n);
  for (T& x : v) x = in.ConsumeBool() ? in.ConsumeIntegral<T>() : in.ConsumeIntegralInRange<T>(0, most);
  return v;
}
dem::SavedContacts contacts(FuzzedDataProvider& in, int balls) {
  dem::SavedContacts c;
  const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 12);
  c.key = indices<std::uint64_t>(in, n, (std::uint64_t(balls) << 32) | std::uint64_t(balls));
  c.i = indices<int>(in, n, balls);
  c.j = indices<int>(in, n, balls);
  c.fs = values(in, 3 * n), c.mr = values(in, 3 * n), c.fc = values(in, 3 * n), c.mt = values(in, 3 * n);
  for (auto& s : c.slot) s = values(in, n);
  c.fn = values(in, n);
  c.flags = indices<std::uint8_t>(in, n, 255);
  return c;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  dem::Checkpoint c;
  c.job = "run";
  dem::SimState& s = c.sim;
  const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(1, 12);
  s.step = in.ConsumeIntegral<long>();
  s.time = in.ConsumeFloatingPoint<double>();
  s.dt = in.ConsumeFloatingPoint<double>();
  for (int d = 0; d < 3; ++d) {
    s.domain.lo[d] = in.ConsumeFloatingPoint<double>();
    s.domain.hi[d] = in.ConsumeFloatingPoint<double>();
    s.domain.strain_rate[d] = in.ConsumeFloatingPoint<double>();
    s.domain.periodic[d] = in.ConsumeBool();
  }
  for (auto* v : {&s.x, &s.v, &s.w, &s.f, &s.m, &s.x_ref}) *v = values(in, 3 * n);
  s.radius = values(in, n), s.mass = values(in, n), s.inertia = values(in, n);
  s.gid = indices<std::uint32_t>(in, n, static_cast<std::uint32_t>(n));
  s.specimen = indices<int>(in, n, 2);
  s.material = indices<int>(in, n, 2);
  s.balls = contacts(in, static_cast<int>(n));
  s.walls = contacts(in, static_cast<int>(n));
  s.wall_point = values(in, 3 * in.ConsumeIntegralInRange<std::size_t>(0, 3));
  s.wall_velocity = values(in, s.wall_point.size());
  s.node_x = values(in, 3 * in.ConsumeIntegralInRange<std::size_t>(0, 4));
  s.node_v = values(in, s.node_x.size());
  s.cell_pressure = in.ConsumeFloatingPoint<double>();
  s.wall_disp = in.ConsumeFloatingPoint<double>();
  s.fresh = in.ConsumeBool();
  return dem::fuzz::read_bytes(nullptr, 0, ".ckpt.h5", [&](const std::string& path) {
    dem::write_checkpoint(path, c);
    const dem::Checkpoint back = dem::read_checkpoint(path);
    dem::check_state(back.sim, back.sim.wall_point.size() / 3, 2, 2);
  });
}
