#include "host/lab/packing_store.hpp"

#include <cstdint>
#include <type_traits>

#include "host/lab/run_store.hpp"
#include "host/util/fnv1a.hpp"
#include "host/util/forked_runs.hpp"

namespace dem {

static_assert(std::is_trivially_copyable<BallSpec>::value, "a specimen's balls are stored and piped as bytes");

std::string packing_path(const Config& cfg) {
  if (cfg.packing_store.empty() || cfg.fingerprint.empty()) return "";
  std::uint64_t h = store_hash(cfg);
  const Real v[] = {cfg.box.size[0], cfg.box.size[1], cfg.box.size[2], cfg.periodic.prep_mu_s,
                    cfg.periodic.prep_mu_r, cfg.periodic.prep_unbalanced_tolerance};
  h = fnv1a(v, sizeof v, h);
  const long n[] = {cfg.particles.count, static_cast<long>(cfg.run.seed), static_cast<long>(cfg.periodic.boundary),
                    cfg.box.periodic[0], cfg.box.periodic[1], cfg.box.periodic[2]};
  h = fnv1a(n, sizeof n, h);
  const ContactParams law = cfg.ball.base();  // a preparation never runs the extensions
  h = fnv1a(&law, sizeof law, h);             // Reals only: no padding
  return cfg.packing_store + "/cell_" + hex16(h) + ".pack";
}

namespace {
std::uint64_t checksum(const PackedCell& s) {
  std::uint64_t h = fnv1a(s.balls.data(), s.balls.size() * sizeof(BallSpec));
  h = fnv1a(s.cell.data(), sizeof s.cell, h);
  return fnv1a(&s.void_ratio, sizeof s.void_ratio, h);
}
}  // namespace

std::string packed_bytes(const PackedCell& s) {
  std::string b;
  const auto put = [&](const void* p, std::size_t n) { b.append(static_cast<const char*>(p), n); };
  const std::size_t n = s.balls.size();
  const std::uint64_t sum = checksum(s);
  put(&n, sizeof n);
  put(s.balls.data(), n * sizeof(BallSpec));
  put(s.cell.data(), sizeof s.cell);
  put(&s.void_ratio, sizeof s.void_ratio);
  put(&sum, sizeof sum);
  return b;
}

bool get_packed(int fd, PackedCell& s, std::size_t balls) {
  std::size_t n = 0;
  std::uint64_t sum = 0;
  if (!get_bytes(fd, &n, sizeof n) || n != balls) return false;
  s.balls.resize(n);
  return get_bytes(fd, s.balls.data(), n * sizeof(BallSpec)) && get_bytes(fd, s.cell.data(), sizeof s.cell) &&
         get_bytes(fd, &s.void_ratio, sizeof s.void_ratio) && get_bytes(fd, &sum, sizeof sum) && sum == checksum(s);
}

bool read_packing(const Config& cfg, PackedCell& s) {
  PackedCell read;
  if (!read_stored(packing_path(cfg), [&](int fd) {
        return get_packed(fd, read, static_cast<std::size_t>(cfg.particles.count));
      }))
    return false;
  s = std::move(read);
  return true;
}

void write_packing(const Config& cfg, const PackedCell& s) {
  const std::string path = packing_path(cfg);
  if (!path.empty()) write_stored(path, packed_bytes(s));
}

}  // namespace dem
