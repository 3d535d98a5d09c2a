#include "packing.hpp"

#include <cmath>
#include <random>
#include <string>
#include <unordered_map>

namespace dem {

namespace {

std::vector<BallSpec> random_insertion(const Config& cfg, std::mt19937_64& rng) {
  const auto& pc = cfg.particles;
  const Real dmax = 2 * pc.diameter * pc.diameter_ratio / (1 + pc.diameter_ratio);
  const Real dmin = dmax / pc.diameter_ratio;
  std::uniform_real_distribution<Real> u01(0, 1);
  // Hash grid of cell size dmax: a new ball only checks the 27 cells around it.
  const Real h = dmax;
  auto cell_key = [&](const Vec3& x) {
    const long cx = static_cast<long>(std::floor(x.x / h)), cy = static_cast<long>(std::floor(x.y / h)),
               cz = static_cast<long>(std::floor(x.z / h));
    return (cx * 73856093L) ^ (cy * 19349663L) ^ (cz * 83492791L);
  };
  std::unordered_multimap<long, int> grid;
  std::vector<BallSpec> balls;
  balls.reserve(pc.count);
  const long max_tries = 200 * pc.count + 10000;
  long tries = 0;
  while (static_cast<long>(balls.size()) < pc.count) {
    if (++tries > max_tries) {
      const Real vbox = cfg.box.size[0] * cfg.box.size[1] * cfg.box.size[2];
      const Real vsolid = pc.count * M_PI / 6 * pc.diameter * pc.diameter * pc.diameter;
      throw ConfigError(cfg.path + ": [particles] count: could place only " + std::to_string(balls.size()) + " of " +
                        std::to_string(pc.count) + " balls by random insertion (solid fraction " +
                        std::to_string(vsolid / vbox) +
                        "; random insertion reaches about 0.3): enlarge [box] size_mm or use fill = \"lattice\"");
    }
    const Real d = dmin + (dmax - dmin) * u01(rng);
    const Real r = d / 2;
    Vec3 x;
    Real c[3];
    for (int k = 0; k < 3; ++k) {
      const Real margin = cfg.box.periodic[k] ? 0 : r;
      c[k] = margin + (cfg.box.size[k] - 2 * margin) * u01(rng);
    }
    x = Vec3(c[0], c[1], c[2]);
    bool free = true;
    const long base[3] = {static_cast<long>(std::floor(x.x / h)), static_cast<long>(std::floor(x.y / h)),
                          static_cast<long>(std::floor(x.z / h))};
    for (int dz = -1; dz <= 1 && free; ++dz)
      for (int dy = -1; dy <= 1 && free; ++dy)
        for (int dx = -1; dx <= 1 && free; ++dx) {
          const Vec3 probe((base[0] + dx + 0.5) * h, (base[1] + dy + 0.5) * h, (base[2] + dz + 0.5) * h);
          auto range = grid.equal_range(cell_key(probe));
          for (auto it = range.first; it != range.second && free; ++it) {
            const BallSpec& o = balls[it->second];
            Vec3 sep = o.x - x;
            Real s[3] = {sep.x, sep.y, sep.z};
            for (int k = 0; k < 3; ++k)
              if (cfg.box.periodic[k]) s[k] -= cfg.box.size[k] * std::round(s[k] / cfg.box.size[k]);
            if (norm2(Vec3(s[0], s[1], s[2])) < (r + o.radius) * (r + o.radius)) free = false;
          }
        }
    // Periodic images across the box faces are only checked through the wrapped distance of
    // neighbours found in the hash grid, so keep balls off the periodic seams by one diameter.
    for (int k = 0; k < 3 && free; ++k)
      if (cfg.box.periodic[k] && (c[k] < dmax || c[k] > cfg.box.size[k] - dmax)) free = false;
    if (!free) continue;
    BallSpec b;
    b.x = x;
    b.radius = r;
    b.density = pc.density;
    grid.emplace(cell_key(x), static_cast<int>(balls.size()));
    balls.push_back(b);
  }
  return balls;
}

std::vector<BallSpec> jittered_lattice(const Config& cfg, std::mt19937_64& rng) {
  const auto& pc = cfg.particles;
  const Real pitch = cfg.box.lattice_spacing * pc.diameter;
  int n[3];
  long capacity = 1;
  for (int k = 0; k < 3; ++k) {
    const Real usable = cfg.box.periodic[k] ? cfg.box.size[k] : cfg.box.size[k] - pc.diameter;
    n[k] = static_cast<int>(std::floor(usable / pitch + 1e-9)) + (cfg.box.periodic[k] ? 0 : 1);
    capacity *= n[k];
  }
  if (capacity < pc.count)
    throw ConfigError(cfg.path + ": [particles] count: a lattice of pitch " + std::to_string(pitch * 1e3) +
                      " mm holds only " + std::to_string(capacity) + " balls in this box");
  std::uniform_real_distribution<Real> jit(-0.005 * pc.diameter, 0.005 * pc.diameter);
  std::vector<BallSpec> balls;
  balls.reserve(pc.count);
  for (int iz = 0; iz < n[2] && static_cast<long>(balls.size()) < pc.count; ++iz)
    for (int iy = 0; iy < n[1] && static_cast<long>(balls.size()) < pc.count; ++iy)
      for (int ix = 0; ix < n[0] && static_cast<long>(balls.size()) < pc.count; ++ix) {
        const int idx[3] = {ix, iy, iz};
        Real c[3];
        for (int k = 0; k < 3; ++k)
          c[k] = (cfg.box.periodic[k] ? 0.5 * pitch : 0.5 * pc.diameter) + idx[k] * pitch + jit(rng);
        BallSpec b;
        b.x = Vec3(c[0], c[1], c[2]);
        b.radius = pc.diameter / 2;
        b.density = pc.density;
        balls.push_back(b);
      }
  return balls;
}

}  // namespace

std::vector<BallSpec> make_packing(const Config& cfg) {
  std::mt19937_64 rng(cfg.run.seed);
  return cfg.box.fill == "lattice" ? jittered_lattice(cfg, rng) : random_insertion(cfg, rng);
}

std::vector<WallSpec> box_walls(const Config& cfg) {
  std::vector<WallSpec> walls;
  if (!cfg.box.walls) return walls;
  for (int k = 0; k < 3; ++k) {
    if (cfg.box.periodic[k]) continue;
    for (int side = 0; side < 2; ++side) {
      WallSpec w;
      w.kind = kPlane;
      Real p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
      p[k] = side == 0 ? 0 : cfg.box.size[k];
      n[k] = side == 0 ? 1 : -1;
      w.point = Vec3(p[0], p[1], p[2]);
      w.normal = Vec3(n[0], n[1], n[2]);
      w.material = 1;
      walls.push_back(w);
    }
  }
  return walls;
}

}  // namespace dem
