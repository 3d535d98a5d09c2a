#include "host/config/size_distribution.hpp"
#include "host/triax/specimen.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <tuple>

#include "host/config/model_keys.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/engine/packing.hpp"
#include "host/util/fnv1a.hpp"
#include "host/util/progress.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/simulation.hpp"
#include "host/engine/stage_loop.hpp"

namespace dem {

namespace {

constexpr int kProfileBins = 24;

/// Volume of a spherical cap of height h (0 <= h <= 2r).
Real cap_volume(Real r, Real h) { return M_PI * h * h * (3 * r - h) / 3; }

enum WallIndex { kBottom = 0, kMould = 1, kTop = 2 };

/// Rigid mould: bottom platen, cylinder, top platen at z_top.
std::vector<WallSpec> mould(Real radius, Real z_top) {
  std::vector<WallSpec> w(3);
  w[kBottom].kind = kPlane;
  w[kBottom].normal = Vec3(0, 0, 1);
  w[kMould].kind = kCylinder;
  w[kMould].normal = Vec3(0, 0, 1);
  w[kMould].radius = radius;
  w[kTop].kind = kPlane;
  w[kTop].point = Vec3(0, 0, z_top);
  w[kTop].normal = Vec3(0, 0, -1);
  for (auto& x : w) x.material = 1;
  return w;
}

/// Presses the top platen down to z_target, then settles. The platen slows down in proportion to the mean
/// force of its contacts and stops where that force would squeeze them by 1% of the radius (f_limit): the
/// layer is then looser than asked, and pressing on would only overlap the balls. The proportional approach
/// avoids the stop-and-go of an on/off limit, which keeps a packing agitated and the unbalanced ratio
/// high. Returns how the layer's stage ended (its steps and cost) and its ratio; `progress` (may be null) is told
/// the platen's travel in micrometres.
std::pair<StageEnd, Real> compact(Simulation& sim, Real z_target, const SpecimenConfig& sc, Real stop_ratio,
                                  Real f_limit, Progress* progress, const std::vector<ContactParams>* settle) {
  const long check_every = 200;
  const Real z_start = sim.wall_point(kTop).z;
  Real ratio = 1, load = 0;  // load: mean platen contact force / f_limit
  Real z = z_start;          // the platen's height before the step
  StageSteps layer;
  layer.last = sc.max_steps_per_layer;
  layer.before = [&](long n) {
    z = sim.wall_point(kTop).z;
    const Real dt = sim.params().integ.dt;
    if ((n - 1) % 5 == 0) {
      const Simulation::WallLoads walls = sim.wall_loads(false);
      const int touching = walls.touching[kTop];
      load = touching > 0 ? std::fabs(walls.force[kTop].z) / (touching * f_limit) : 0;
    }
    const Real v = std::min(sc.platen_speed * std::clamp(1 - load, Real(0), Real(1)), (z - z_target) / dt);
    sim.set_wall_velocity(kTop, Vec3(0, 0, -std::max(v, Real(0))));
    return StepPlan{false, n % check_every == 0};
  };
  layer.after = [&](long n, bool measured) {
    if (!measured) return false;
    // A stop asked for here has no checkpoint to write: a half-built specimen is no state to resume.
    if (StopSignals::requested())
      throw RunStopped(std::string(StopSignals::name()) + " during the specimen build: nothing was stored, and "
                       "the next run builds the specimen again", 128 + StopSignals::signal());
    ratio = sim.unbalanced_ratio();
    if (progress) {
      // At its height the platen has no travel left to report, and the unbalanced ratio does not fall steadily
      // enough to extrapolate: the line says what the layer waits for and the step cap that bounds it.
      char extra[160];
      if (z - z_target < 1e-9) {
        std::snprintf(extra, sizeof extra, "platen at its height, settling until the unbalanced ratio is below "
                      "%.0e (now %.1e), at most %ld steps more (the layer's step cap)", stop_ratio, ratio,
                      sc.max_steps_per_layer - n);
        progress->settling(extra);
      } else {
        std::snprintf(extra, sizeof extra, "(um of platen travel), unbalanced ratio %.1e (stop at %.0e)", ratio,
                      stop_ratio);
        progress->update(std::lround((z_start - z) * 1e6), extra);
      }
    }
    const bool blocked = load > 0.9;
    // Pressed to its height (or as far as it goes, nearly at rest): friction now only helps the layer come
    // to rest; switched on earlier, it would lock the packing before the platen gets there.
    if (settle && (z - z_target < 1e-9 || (blocked && ratio < 10 * stop_ratio))) {
      sim.set_contact_params(*settle);
      settle = nullptr;
    }
    return (z - z_target < 1e-9 || blocked) && ratio < stop_ratio;
  };
  const StageEnd end = run_stage(sim, layer, nullptr);
  sim.set_wall_velocity(kTop, Vec3());
  return {end, ratio};
}

}  // namespace

Real sphere_slab_volume(Real zc, Real r, Real z0, Real z1) {
  const Real a = std::clamp(z0 - (zc - r), Real(0), 2 * r);  // height of the part below z0
  const Real b = std::clamp(z1 - (zc - r), Real(0), 2 * r);  // height of the part below z1
  return cap_volume(r, b) - cap_volume(r, a);
}

Real slab_void_ratio(const std::vector<BallSpec>& balls, Real radius, Real z0, Real z1) {
  Real solid = 0;
  for (const BallSpec& b : balls) solid += sphere_slab_volume(b.x.z, b.radius, z0, z1);
  const Real total = M_PI * radius * radius * (z1 - z0);
  return solid > 0 ? (total - solid) / solid : INFINITY;
}

long specimen_ball_count(const Config& cfg) {
  const SpecimenConfig& sc = cfg.specimen;
  if (sc.ball_count > 0) return sc.ball_count;
  const Real v = M_PI * sc.diameter * sc.diameter / 4 * sc.height;
  return std::lround(v / ((1 + sc.void_ratio) * M_PI / 6 * SizeDistribution(cfg.particles).mean_cube()));
}

Specimen build_specimen(const Config& cfg, bool verbose, const LayerBlowUp& on_blowup) {
  const SpecimenConfig& sc = cfg.specimen;
  const Real R = sc.diameter / 2, h_layer = sc.height / sc.layers;
  const long total = specimen_ball_count(cfg);
  std::mt19937_64 rng(cfg.run.seed);
  Specimen out;
  ContactParams ball_law = cfg.ball.base(), wall_law = cfg.wall.base();
  ball_law.mu_s = sc.compaction_mu_s;
  ball_law.mu_r = 0;  // rolling resistance off too: the specimen does not depend on the test's friction
  wall_law.mu_s = 0;  // a smooth mould, so that walls do not hold the layers up
  wall_law.mu_r = 0;
  for (long k = 0; k < sc.layers; ++k) {
    ParticleConfig pc = cfg.particles;
    pc.count = total / sc.layers + (k == sc.layers - 1 ? total % sc.layers : 0);
    const Real z0 = k * h_layer, z1 = (k + 1) * h_layer;
    // Pour into a loose column about 2.2 times the layer's final height (solid fraction about 0.28, close
    // to what random insertion reaches, ~0.3); a taller column only lengthens the platen's travel.
    Real h_loose = 2.2 * h_layer;
    std::vector<BallSpec> fresh;
    for (int attempt = 0; attempt < 6; ++attempt, h_loose *= 1.4) {
      InsertRegion reg;
      reg.lo = Vec3(-R, -R, z0);
      reg.hi = Vec3(R, R, z0 + h_loose);
      reg.radius = R;
      fresh = insert_random(pc, reg, out.balls, rng);
      if (static_cast<long>(fresh.size()) == pc.count) break;
    }
    if (static_cast<long>(fresh.size()) < pc.count)
      throw ConfigError(cfg.path + ": [specimen]: could not pour layer " + std::to_string(k + 1) + " (" +
                        std::to_string(pc.count) + " balls) into the mould");
    std::vector<BallSpec> all = out.balls;
    all.insert(all.end(), fresh.begin(), fresh.end());
    const SimParams prm = solver_params(cfg);
    Simulation sim(make_particles(all), make_walls(mould(R, z0 + h_loose)), FacetMesh(),
                   {ball_law, wall_law, wall_law, wall_law}, 2, prm);
    sim.set_dt(time_step(cfg.solver, sim.critical_dt(), cfg.path));
    const Real f_limit = 0.01 * cfg.particles.diameter / 2 *
                         ContactLaws::servo_stiffness(wall_law, cfg.particles.diameter / 2, 0);
    Progress progress("specimen layer " + std::to_string(k + 1) + "/" + std::to_string(sc.layers),
                      std::lround((z0 + h_loose - z1) * 1e6));
    ContactParams settle_law = ball_law;
    settle_law.mu_s = sc.settle_mu_s;
    const std::vector<ContactParams> settle_table{settle_law, wall_law, wall_law, wall_law};
    StageEnd end;
    Real ratio = 0;
    try {
      std::tie(end, ratio) = compact(sim, z1, sc, layer_stop_ratio(sc, k), f_limit, verbose ? &progress : nullptr,
                                     sc.settle_mu_s >= 0 ? &settle_table : nullptr);
    } catch (const BlowUp&) {
      if (on_blowup) on_blowup(sim);
      throw;
    }
    const long steps = end.step;
    out.stages.push_back(end.timing);
    out.stages.back().name = "specimen layer " + std::to_string(k + 1);
    const HostParticles h = to_host_by_gid(sim.particles());
    for (std::size_t q = 0; q < all.size(); ++q) {
      all[q].x = h.x[q];
      all[q].v = Vec3();
      all[q].w = Vec3();
    }
    out.balls = all;
    LayerReport rep{z0, z1, sim.wall_point(kTop).z, slab_void_ratio(out.balls, R, z0, z1), steps, ratio};
    out.layers.push_back(rep);
    if (verbose)
      std::printf("specimen: layer %ld/%ld: %ld balls, platen at %.3f mm (target %.3f), unbalanced ratio %.1e; time "
                  "loop: %s\n", k + 1, sc.layers, pc.count, rep.z_platen * 1e3, z1 * 1e3, ratio,
                  describe(sim.times(), static_cast<long>(all.size()), steps).c_str());
  }
  // Later layers press on the earlier ones: report every layer as it is in the finished specimen.
  for (LayerReport& l : out.layers) l.void_ratio = slab_void_ratio(out.balls, R, l.z_bottom, l.z_top);
  out.height = std::max(out.layers.back().z_platen, sc.height);
  out.void_ratio = slab_void_ratio(out.balls, R, 0, out.height);
  for (int b = 0; b < kProfileBins; ++b) {
    const Real e = slab_void_ratio(out.balls, R, b * sc.height / kProfileBins, (b + 1) * sc.height / kProfileBins);
    out.porosity_profile.push_back(e / (1 + e));
  }
  return out;
}

Real layer_stop_ratio(const SpecimenConfig& sc, long k) {
  return sc.layer_stop_ratio > 0 && k + 1 < sc.layers ? sc.layer_stop_ratio : sc.stop_ratio;
}

std::string specimen_key(const Config& cfg) {
  const SpecimenConfig& sc = cfg.specimen;
  const ParticleConfig& pc = cfg.particles;
  const SolverConfig& sv = cfg.solver;
  std::ostringstream k;
  k.precision(17);
  k << "v3 d " << pc.diameter << " ratio " << pc.diameter_ratio << size_key(pc) << " rho " << pc.density << " D " << sc.diameter
    << " H " << sc.height << " n " << specimen_ball_count(cfg) << " layers " << sc.layers << " mu " << sc.compaction_mu_s
    << " settle " << sc.settle_mu_s
    << " v " << sc.platen_speed << " stop " << sc.stop_ratio << " max " << sc.max_steps_per_layer << " seed "
    << cfg.run.seed << " damp " << sv.damping << " g "
    << sv.gravity[0] << " " << sv.gravity[1] << " " << sv.gravity[2] << " dts " << sv.dt_safety << " dt " << sv.dt
    << " ms " << sv.mass_scale << " skin " << sv.skin;
  if (sc.layer_stop_ratio > 0) k << " lstop " << sc.layer_stop_ratio;  // absent: the keys of earlier specimens hold
  // The balls' and the walls' law with its own keys (model_keys) and the damping ratio: what the preparation's contacts
  // follow. The friction (the compaction's own) and the extensions (preparation runs the law's base()) stay out.
  for (const ContactParams* p : {&cfg.ball, &cfg.wall}) {
    const std::string law = kContactLawNames[static_cast<int>(p->law)];
    k << (p == &cfg.ball ? " ball " : " wall ") << law;
    for (const ModelKey& m : model_keys())
      if (m.field && !*m.extension && own_key_of(m, law)) k << " " << m.key << " " << p->*m.field;
    k << " beta_n " << p->beta_n;
  }
  return k.str();
}

void save_specimen(const std::string& path, const Specimen& sp, const std::string& key) {
  std::ostringstream o;
  o.precision(17);
  o << "# triaxdem specimen\n# key " << key << "\n# height_m " << sp.height << " void_ratio " << sp.void_ratio << "\n";
  for (const LayerReport& l : sp.layers)
    o << "# layer " << l.z_bottom << " " << l.z_top << " " << l.z_platen << " " << l.void_ratio << " " << l.steps
      << " " << l.unbalanced << "\n";
  o << "# profile";
  for (Real p : sp.porosity_profile) o << " " << p;
  o << "\nx_m,y_m,z_m,radius_m,density_kg_m3\n";
  for (const BallSpec& b : sp.balls)
    o << b.x.x << "," << b.x.y << "," << b.x.z << "," << b.radius << "," << b.density << "\n";
  const std::string text = o.str();
  io::write_text_atomic(path, text + "# checksum " + hex16(fnv1a(text.data(), text.size())) + "\n");
}

bool load_specimen(const std::string& path, const std::string& key, Specimen& sp) {
  std::ifstream f(path);
  if (!f) return false;
  std::string line;
  long n = 0;
  auto damaged = [&](const std::string& why) {
    throw std::runtime_error(path + ":" + std::to_string(n) + ": damaged specimen file (" + why +
                             "); delete it to rebuild the specimen");
  };
  Specimen out;
  bool key_ok = false;
  std::uint64_t sum = kFnv1aOffset;  // of every line above the checksum's
  std::string sealed;
  while (std::getline(f, line)) {
    ++n;
    if (!sealed.empty()) damaged("a line below its checksum line");
    std::istringstream s(line);
    std::string tag, word;
    if (line.rfind("# checksum ", 0) == 0) {
      sealed = line.substr(11);
      if (sealed != hex16(sum))
        damaged("its checksum says " + sealed + ", its lines " + hex16(sum) + ": edited or damaged after triaxdem "
                "wrote it");
      continue;
    }
    sum = fnv1a("\n", 1, fnv1a(line.data(), line.size(), sum));
    if (line.rfind("# key ", 0) == 0) {
      if (line.substr(6) != key) return false;
      key_ok = true;
    } else if (line.rfind("# height_m ", 0) == 0) {
      s >> tag >> word >> out.height >> word >> out.void_ratio;
    } else if (line.rfind("# layer ", 0) == 0) {
      LayerReport l;
      if (!(s >> tag >> word >> l.z_bottom >> l.z_top >> l.z_platen >> l.void_ratio >> l.steps >> l.unbalanced))
        damaged("a layer line needs 6 numbers");
      out.layers.push_back(l);
    } else if (line.rfind("# profile", 0) == 0) {
      s >> tag >> word;
      for (Real p; s >> p;) out.porosity_profile.push_back(p);
    } else if (!line.empty() && line[0] != '#' && line[0] != 'x') {
      BallSpec b;
      char c1, c2, c3, c4;
      if (!(s >> b.x.x >> c1 >> b.x.y >> c2 >> b.x.z >> c3 >> b.radius >> c4 >> b.density) || c1 != ',' || c2 != ',' ||
          c3 != ',' || c4 != ',' || !(b.radius > 0) || !std::isfinite(b.x.x) || !std::isfinite(b.x.y) ||
          !std::isfinite(b.x.z) || !std::isfinite(b.radius) || !(b.density > 0) || !std::isfinite(b.density))
        damaged("expected x_m,y_m,z_m,radius_m,density_kg_m3, finite, radius and density positive");
      out.balls.push_back(b);
    }
  }
  if (!key_ok) return false;
  if (out.balls.empty() || !(out.height > 0)) damaged("no balls or no height");
  if (sealed.empty()) {  // cut short above its last line, or written before specimens were sealed: never used
    std::fprintf(stderr, "specimen: %s has no checksum line (cut short, or written by an earlier triaxdem): built "
                 "again\n", path.c_str());
    return false;
  }
  // A file cut at a line's end (a full disk, a copy stopped) parses whole: its key says how many balls it holds.
  if (const std::string::size_type at = key.find(" n "); at != std::string::npos) {
    const long want = std::strtol(key.c_str() + at + 3, nullptr, 10);
    if (static_cast<long>(out.balls.size()) != want)
      damaged(std::to_string(out.balls.size()) + " balls where its key says " + std::to_string(want));
  }
  sp = std::move(out);
  return true;
}

Specimen cached_specimen(const Config& cfg, const std::string& cache, bool verbose, const std::string& own,
                         const LayerBlowUp& on_blowup) {
  const std::string key = specimen_key(cfg);
  char name[32];
  std::snprintf(name, sizeof name, "%016zx.csv", std::hash<std::string>{}(key));
  const std::string path = (std::filesystem::path(cache) / name).string();
  Specimen sp;
  const bool from_own = !own.empty() && load_specimen(own, key, sp);
  if (from_own) {
    if (verbose) std::printf("specimen: the run's own, %s (%zu balls, e = %.4f)\n", own.c_str(), sp.balls.size(),
                             sp.void_ratio);
  } else if (load_specimen(path, key, sp)) {
    if (verbose)
      std::printf("specimen: reusing %s (%zu balls, e = %.4f; same beads, mould, seed and compaction)\n", path.c_str(),
                  sp.balls.size(), sp.void_ratio);
  } else {
    sp = build_specimen(cfg, verbose, on_blowup);
    std::filesystem::create_directories(cache);
    save_specimen(path, sp, key);
    if (verbose) std::printf("specimen: stored in %s for later runs\n", path.c_str());
  }
  if (!own.empty() && !from_own) save_specimen(own, sp, key);
  require_settled(cfg, sp);
  return sp;
}

void require_settled(const Config& cfg, const Specimen& sp) {
  const SpecimenConfig& sc = cfg.specimen;
  if (sc.accept_unsettled) return;
  for (std::size_t k = 0; k < sp.layers.size(); ++k) {
    const LayerReport& l = sp.layers[k];
    const Real stop = layer_stop_ratio(sc, static_cast<long>(k));
    if (l.steps < sc.max_steps_per_layer || l.unbalanced < stop) continue;
    char msg[400];
    std::snprintf(msg, sizeof msg, "[specimen] layer %zu/%zu stopped at max_steps_per_layer = %ld with the unbalanced "
                  "ratio at %.1e, above its stop ratio %.0e: it is not at rest. Raise max_steps_per_layer, or set "
                  "accept_unsettled = true to go on with it (the specimen is kept: a rerun does not build it again)",
                  k + 1, sp.layers.size(), sc.max_steps_per_layer, l.unbalanced, stop);
    throw ConfigError(cfg.path + ": " + msg);
  }
}

void write_specimen_report(const std::string& folder, const Config& cfg, const Specimen& sp) {
  std::string layers = "layer,z_bottom_mm,z_top_mm,z_platen_mm,void_ratio,steps,unbalanced_ratio\n";
  for (std::size_t k = 0; k < sp.layers.size(); ++k) {
    const LayerReport& l = sp.layers[k];
    char row[160];
    std::snprintf(row, sizeof row, "%zu,%.4f,%.4f,%.4f,%.5f,%ld,%.3e\n", k + 1, l.z_bottom * 1e3, l.z_top * 1e3,
                  l.z_platen * 1e3, l.void_ratio, l.steps, l.unbalanced);
    layers += row;
  }
  io::write_text_atomic(folder + "/layers.csv", layers);
  std::string profile = "z_mm,porosity\n";
  const std::size_t nb = sp.porosity_profile.size();
  for (std::size_t b = 0; b < nb; ++b) {
    char row[64];
    std::snprintf(row, sizeof row, "%.4f,%.5f\n", (b + 0.5) * cfg.specimen.height / nb * 1e3, sp.porosity_profile[b]);
    profile += row;
  }
  io::write_text_atomic(folder + "/porosity_profile.csv", profile);
}

}  // namespace dem
