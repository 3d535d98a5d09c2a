/// Snapshots whose HDF5 structure is well formed and whose content is the fuzzer's: each array's length (the
/// balls', the contacts', the surface's, each a little off or not), gids, contact ends and boundaries, triangle
/// nodes and every value. What is fuzzed is triaxdem's reading of a snapshot and what `triaxdem micro` does with
/// it (read_snapshot, contact_set, the micro measures, the surface's enclosed volume).
#include <fuzzer/FuzzedDataProvider.h>

#include "fuzz_file.hpp"
#include "host/io/h5_file.hpp"
#include "host/engine/micro.hpp"
#include "host/triax/micro_report.hpp"

namespace {
namespace h5 = dem::io::h5;

/// A length near `n`: mostly n, sometimes one off or zero, so that disagreeing lengths get tried.
std::size_t near(FuzzedDataProvider& in, std::size_t n) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: return n + 1;
    case 1: return n > 0 ? n - 1 : 0;
    case 2: return 0;
    default: return n;
  }
}
void doubles(h5::H5Writer& f, hid_t loc, const char* name, FuzzedDataProvider& in, std::size_t rows, std::size_t cols) {
  std::vector<double> v(rows * cols);
  for (double& x : v) x = in.ConsumeBool() ? in.ConsumeFloatingPoint<double>() : in.ConsumeFloatingPointInRange(-1e-2, 1e-2);
  if (cols == 1) f.dataset(loc, name, H5T_NATIVE_DOUBLE, v.data(), {rows});
  else f.dataset(loc, name, H5T_NATIVE_DOUBLE, v.data(), {rows, cols});
}
template <class T>
void integers(h5::H5Writer& f, hid_t loc, const char* name, hid_t type, FuzzedDataProvider& in, std::size_t rows,
              std::size_t cols, T lo, T hi) {
  std::vector<T> v(rows * cols);
  for (T& x : v) x = in.ConsumeBool() ? in.ConsumeIntegral<T>() : in.ConsumeIntegralInRange<T>(lo, hi);
  if (cols == 1) f.dataset(loc, name, type, v.data(), {rows});
  else f.dataset(loc, name, type, v.data(), {rows, cols});
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  return dem::fuzz::read_bytes(nullptr, 0, ".snap.h5", [&](const std::string& path) {
    {
      h5::H5Writer f(path, path);
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(1, 8);
      const int balls = static_cast<int>(n);
      doubles(f, f.root(), "x", in, near(in, n), 3);
      doubles(f, f.root(), "radius", in, n, 1);
      integers<std::uint32_t>(f, f.root(), "gid", H5T_NATIVE_UINT32, in, near(in, n), 1, 0, n);
      f.string_attribute(".", "label", "fuzz");
      if (in.ConsumeBool()) {
        h5::Handle g(f.check(H5Gcreate2(f.root(), "surface", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "group"), H5Gclose);
        const std::size_t nodes = in.ConsumeIntegralInRange<std::size_t>(0, 6);
        doubles(f, g.get(), "nodes", in, nodes, 3);
        integers<int>(f, g.get(), "triangles", H5T_NATIVE_INT, in, in.ConsumeIntegralInRange<std::size_t>(0, 4), 3, -1,
                      static_cast<int>(nodes));
      }
      if (in.ConsumeBool()) {
        h5::Handle g(f.check(H5Gcreate2(f.root(), "contacts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "group"), H5Gclose);
        const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, 10);
        integers<int>(f, g.get(), "a", H5T_NATIVE_INT, in, k, 1, -1, balls);
        integers<int>(f, g.get(), "b", H5T_NATIVE_INT, in, near(in, k), 1, -1, balls);
        integers<int>(f, g.get(), "boundary", H5T_NATIVE_INT, in, near(in, k), 1, -1, 3);
        doubles(f, g.get(), "fn", in, near(in, k), 1);
        for (const char* name : {"normal", "point", "branch", "ft"}) doubles(f, g.get(), name, in, near(in, k), 3);
      }
      f.close();
    }
    const dem::io::SnapshotFile s = dem::io::read_snapshot(path);
    if (s.has_surface) dem::surface_volume(s.surface);
    if (s.has_contacts) dem::micro_row(dem::contact_set(s, path), 1e-6);
  });
}
