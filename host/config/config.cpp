#include "host/config/config.hpp"
#include "host/config/size_distribution.hpp"
#include "host/config/config_checks.hpp"
#include "host/config/model_keys.hpp"
#include "host/util/fnv1a.hpp"
#include "host/config/noise_model.hpp"
#include "host/config/toml_reader.hpp"

#include <algorithm>
#include <iterator>
#include <set>
#include <cmath>
#include <map>
#include <sstream>

namespace dem {

namespace {

/// A material's law ([material] law, kContactLawNames) and the keys of that law and of every law; a key of another
/// law is refused, naming the keys this one takes. A law's needed keys (hertz_mindlin's constants) have no default: they
/// are given, or taken from `from` (the balls' material, for the walls) where it has that law.
void read_contact(TableReader& r, ContactParams& c, const ContactParams* from = nullptr) {
  std::string law = kContactLawNames[static_cast<int>(c.law)];
  r.string("law", law, std::set<std::string>(std::begin(kContactLawNames), std::end(kContactLawNames)));
  c.law = static_cast<ContactLawId>(std::find(std::begin(kContactLawNames), std::end(kContactLawNames), law) -
                                    std::begin(kContactLawNames));
  for (const ModelKey& k : model_keys()) {
    if (!k.field) continue;
    Real other = 0;  // a key of another law: read (and listed by config_keys) only to be refused
    const bool mine = law_takes(k.law, law);
    r.number(k.key, mine ? c.*k.field : other, k.lo, k.hi, k.scale, k.open_lo);
    if (!mine && r.has(k.key)) {
      try {
        require_law_of(k, c.law);
      } catch (const std::invalid_argument& e) {
        r.fail(k.key, e.what());
      }
    }
  }
  // The keys a law's material must give (needed in model_keys: no default), unless `from` has that law and gives them.
  if (!(from && from->law == c.law)) {
    std::string needed;
    for (const ModelKey& k : model_keys())
      if (k.required && own_key_of(k, law))
        needed += (needed.empty() ? "" : ", ") + std::string(k.key) + " (allowed: " + allowed_range(k) + ")";
    for (const ModelKey& k : model_keys())
      if (k.required && own_key_of(k, law) && !r.has(k.key))
        r.fail(k.key, "law = \"" + law + "\" needs its keys, which have no default: " + needed);
  }
  r.finish();
}


/// Refuses a ball count whose run cannot fit in memory, before anything is allocated.
void check_memory(TableReader& t, const std::string& key, long balls) {
  const double need = run_memory_bytes(balls), have = available_memory();
  if (have > 0 && need > 0.8 * have) {
    std::ostringstream m;
    m << balls << " balls need about " << need / 1e9 << " GB (" << kBytesPerBall
      << " bytes per ball), more than 80% of the " << have / 1e9 << " GB available (allowed: up to "
      << static_cast<long>(0.8 * have / kBytesPerBall) << " balls on this machine)";
    t.fail(key, m.str());
  }
}
}  // namespace

Config load_config(const std::string& path) { return parse_config(file_text(path), path); }

namespace {

/// The config's tables by name, each read through a TableReader that names the file and table in its errors.
struct Tables {
  const std::string& path;
  toml::table& root;
  TableReader operator()(const char* name) const { return TableReader(path, name, root[name].as_table()); }
  bool present(const char* name) const { return root[name].as_table() != nullptr; }
};

/// [run]: names, steps, outputs, seed, checkpoints.
void read_run(const Tables& read, Config& c) {
  TableReader run = read("run");
  run.string("name", c.run.name);
  run.string("material", c.run.material);
  run.integer("steps", c.run.steps, 0, 1000000000L);
  run.string("output", c.run.output);
  run.integer("series_every", c.run.series_every, 1, 1000000000L);
  run.integer("snapshot_every", c.run.snapshot_every, 0, 1000000000L);
  long seed = c.run.seed;
  run.integer("seed", seed, 0, 4294967295L);
  run.number("stop_ratio", c.run.stop_ratio, 0, 1);
  run.integer("checkpoint_every", c.run.checkpoint_every, 0, 1000000000L);
  run.number("checkpoint_minutes", c.run.checkpoint_minutes, 0, 1e6);
  c.run.seed = static_cast<unsigned>(seed);
  run.finish();
}

/// [particles], with the memory the count needs.
void read_particles(const Tables& read, Config& c) {
  TableReader pt = read("particles");
  pt.integer("count", c.particles.count, 1, 2000000000L);
  check_memory(pt, "count", c.particles.count);
  pt.number("diameter_mm", c.particles.diameter, 1e-6, 1e6, 1e-3, true);
  pt.number("diameter_ratio", c.particles.diameter_ratio, 1, 10);
  pt.number("density_kg_m3", c.particles.density, 0, 1e6, 1, true);
  read_size_distribution(pt, c.particles);
  pt.finish();
}

/// [box].
void read_box(const Tables& read, Config& c) {
  TableReader box = read("box");
  // Up to a kilometre: cell and lattice counts are cast to int, and the memory check bounds the balls.
  box.number_triple("size_mm", c.box.size, 0, 1e6, 1e-3, true);
  box.boolean_triple("periodic", c.box.periodic);
  box.boolean("walls", c.box.walls);
  box.string("fill", c.box.fill, {"random", "lattice"});
  box.number("lattice_spacing", c.box.lattice_spacing, 0.9, 2.0);
  box.finish();
}

/// [material] and [wall_material] (the walls follow the balls unless it says otherwise).
void read_materials(const Tables& read, Config& c) {
  TableReader mat = read("material");
  read_contact(mat, c.ball);
  c.wall = c.ball;
  TableReader wmat = read("wall_material");
  read_contact(wmat, c.wall, &c.ball);
}

/// [solver].
void read_solver(const Tables& read, Config& c) {
  TableReader sv = read("solver");
  sv.number("damping", c.solver.damping, 0, 0.99);
  sv.number_triple("gravity", c.solver.gravity, -1e4, 1e4);
  sv.number("dt_safety", c.solver.dt_safety, kMinDtFraction, 1);
  sv.number("dt_s", c.solver.dt, 0, 1);
  sv.number("mass_scale", c.solver.mass_scale, 1, 1e12);
  sv.number("skin", c.solver.skin, 0, 2, 1, true);
  sv.number("overlap_limit", c.solver.overlap_limit, 0, 1, 1, true);
  sv.integer("stats_every", c.solver.stats_every, 0, kMaxStatsEvery);
  sv.finish();
}

/// [specimen], with what its count or void ratio implies (a packing denser than random close packing, the memory, the width in diameters).
void read_specimen(const Tables& read, Config& c) {
  TableReader sp = read("specimen");
  c.has_specimen = read.present("specimen");
  sp.number("diameter_mm", c.specimen.diameter, 0, 1e6, 1e-3, true);
  sp.number("height_mm", c.specimen.height, 0, 1e6, 1e-3, true);
  // Monodisperse spheres pack no denser than random close packing (solid fraction 0.64, e = 0.5625).
  sp.number("void_ratio", c.specimen.void_ratio, 0.5625, 3);
  sp.integer("ball_count", c.specimen.ball_count, 0, 2000000000L);
  sp.integer("layers", c.specimen.layers, 1, 100);
  sp.number("compaction_mu_s", c.specimen.compaction_mu_s, 0, 10);
  sp.number("settle_mu_s", c.specimen.settle_mu_s, 0, 10);
  sp.number("platen_speed_mm_s", c.specimen.platen_speed, 0, 1e4, 1e-3, true);
  sp.number("stop_ratio", c.specimen.stop_ratio, 0, 1, 1, true);
  sp.number("layer_stop_ratio", c.specimen.layer_stop_ratio, 0, 1);
  sp.integer("max_steps_per_layer", c.specimen.max_steps_per_layer, 1, 1000000000L);
  sp.boolean("accept_unsettled", c.specimen.accept_unsettled);
  sp.finish();
  if (c.specimen.ball_count > 0) {
    // The count decides; the target e is the one it gives in the nominal cylinder.
    const Real d = c.particles.diameter;
    const Real cylinder = M_PI / 4 * c.specimen.diameter * c.specimen.diameter * c.specimen.height;
    c.specimen.void_ratio = cylinder / (c.specimen.ball_count * M_PI / 6 * d * d * d) - 1;
    if (c.specimen.void_ratio < 0.5625) {
      std::ostringstream r;
      r << "value " << c.specimen.ball_count << " gives e = " << c.specimen.void_ratio
        << " in the cylinder, denser than random close packing (allowed: e >= 0.5625, at most "
        << std::floor(cylinder / (1.5625 * M_PI / 6 * d * d * d)) << " balls)";
      sp.fail("ball_count", r.str());
    }
  }
  if (c.has_specimen) {
    const Real d = c.particles.diameter;
    const Real cylinder = M_PI / 4 * c.specimen.diameter * c.specimen.diameter * c.specimen.height;
    const double balls = cylinder / ((1 + c.specimen.void_ratio) * M_PI / 6 * d * d * d);
    check_memory(sp, c.specimen.ball_count > 0 ? "ball_count" : "void_ratio",
                 static_cast<long>(std::min(balls, 4e18)));
  }
  if (c.has_specimen && c.specimen.diameter < 4 * c.particles.diameter)
    throw ConfigError(c.path + ": [specimen] diameter_mm: must be at least 4 particle diameters (" +
                      std::to_string(4e3 * c.particles.diameter) + " mm)");
}

/// [triaxial], with the membrane's memory and the record interval against the strain.
void read_triaxial(const Tables& read, Config& c) {
  TableReader tx = read("triaxial");
  tx.number("sigma3_kPa", c.triaxial.sigma3, 0, 1e6, 1e3, true);
  tx.number("axial_strain_end_pct", c.triaxial.axial_strain_end, 0, 50, 1e-2, true);
  tx.number("inertial_number", c.triaxial.inertial_number, 0, 1e-1, 1, true);
  tx.number("record_every_pct", c.triaxial.record_every, 0, 10, 1e-2, true);
  tx.number("consolidation_tol", c.triaxial.consolidation_tol, 0, 0.5, 1, true);
  tx.number("stop_ratio", c.triaxial.stop_ratio, 0, 1, 1, true);
  tx.integer("max_consolidation_steps", c.triaxial.max_consolidation_steps, 1, 1000000000L);
  long around = c.triaxial.membrane_around, segs = c.triaxial.membrane_segments;
  tx.integer("membrane_nodes_around", around, 8, 10000);
  tx.integer("membrane_segments", segs, 1, 10000);
  {
    // A node holds position, velocity, force and mass (about 80 bytes), and owns two triangles of three indices,
    // rest geometry and facet contacts: 1 kB per node bounds it from above.
    const double nodes = static_cast<double>(around) * static_cast<double>(segs + 1), have = available_memory();
    if (have > 0 && nodes * kBytesPerMembraneNode > 0.5 * have) {
      std::ostringstream m;
      m << around << " x " << segs + 1 << " nodes need up to " << nodes * kBytesPerMembraneNode / 1e9
        << " GB, more than half the " << have / 1e9 << " GB available (allowed: nodes_around x (segments + 1) up to "
        << static_cast<long>(0.5 * have / kBytesPerMembraneNode) << ")";
      tx.fail("membrane_nodes_around", m.str());
    }
  }
  c.triaxial.membrane_around = static_cast<int>(around);
  c.triaxial.membrane_segments = static_cast<int>(segs);
  tx.number("membrane_modulus_MPa", c.triaxial.membrane_modulus, 0, 1e5, 1e6, true);
  tx.number("membrane_poisson", c.triaxial.membrane_poisson, -0.99, 0.499);
  tx.number("membrane_thickness_mm", c.triaxial.membrane_thickness, 0, 100, 1e-3, true);
  tx.number("membrane_density_kg_m3", c.triaxial.membrane_density, 0, 1e5, 1, true);
  tx.boolean("damping_about_flow", c.triaxial.damping_about_flow);
  tx.finish();
  check_records(c.path, "triaxial", "record_every_pct", c.triaxial.record_every, "axial_strain_end_pct",
                c.triaxial.axial_strain_end);
}

/// [micro], with the cube inside the specimen.
void read_micro(const Tables& read, Config& c) {
  TableReader mi = read("micro");
  mi.boolean("enabled", c.micro.enabled);
  mi.number("rve_edge_mm", c.micro.rve_edge, 0, 1e6, 1e-3, true);
  mi.string("overlap", c.micro.overlap, {"auto", "on", "off"});
  long bins = c.micro.rose_bins;
  mi.integer("rose_bins", bins, 2, 3600);
  c.micro.rose_bins = static_cast<int>(bins);
  mi.finish();
  if (c.has_specimen && c.micro.enabled) {
    // The cube must lie inside the cylinder: half its diagonal within the radius, its edge within the height.
    const Real fit = std::min(c.specimen.diameter / std::sqrt(2.0), c.specimen.height);
    if (c.micro.rve_edge > fit) {
      std::ostringstream r;
      r << "value " << c.micro.rve_edge * 1e3 << " does not fit in the " << c.specimen.diameter * 1e3 << " x "
        << c.specimen.height * 1e3 << " mm specimen (allowed: (0, " << fit * 1e3 << "])";
      mi.fail("rve_edge_mm", r.str());
    }
  }
}

/// [periodic], with the record interval against the strain.
void read_periodic(const Tables& read, Config& c) {
  TableReader pr = read("periodic");
  c.has_periodic = read.present("periodic");
  PeriodicTriaxialParams& t = c.periodic.triax;
  pr.number("sigma3_kPa", t.sigma3, 0, 1e7, 1e3, true);
  pr.number("axial_rate_per_s", t.axial_rate, 0, 1e6);
  pr.number("target_inertial", t.target_inertial, 0, 1, 1, true);
  pr.number("max_inertial", t.max_inertial, 0, 1, 1, true);
  pr.boolean("allow_high_inertial", t.allow_high_inertial);
  pr.number("target_axial_strain_pct", t.target_strain, 0, 90, 1e-2, true);
  pr.number("servo_alpha", t.servo_alpha, 0, 1, 1, true);
  pr.number("max_lateral_rate_per_s", t.max_lateral_rate, 0, 1e6);
  pr.number("consolidation_rate_per_s", t.consolidation_rate, 0, 1e6);
  pr.number("gas_rate_per_s", t.gas_rate, 0, 1e6);
  pr.number("gas_solid_fraction", t.gas_solid_fraction, 0, kGasSolidFractionMax, 1, true);
  pr.number("stress_tolerance", t.stress_tolerance, 0, 1, 1, true);
  pr.number("unbalanced_tolerance", t.unbalanced_tolerance, 0, 1, 1, true);
  pr.integer("max_consolidation_steps", t.max_consolidation_steps, 1, 1000000000L);
  pr.integer("check_every", t.check_every, 1, 1000000L);
  pr.integer("stiffness_every", t.stiffness_every, 1, 1000000L);
  pr.number("record_strain_pct", t.record_strain, 0, 90, 1e-2, true);
  const ModelKey& membrane = model_key("membrane_kPa");
  pr.number(membrane.key, t.membrane_stiffness, membrane.lo, membrane.hi, membrane.scale, membrane.open_lo);
  pr.numbers("snapshot_strains_pct", t.snapshot_strains, 0, 90, 1e-2);
  pr.number("prep_mu_s", c.periodic.prep_mu_s, 0, 10);
  pr.number("prep_mu_r", c.periodic.prep_mu_r, 0, 10);
  pr.number("prep_unbalanced_tolerance", c.periodic.prep_unbalanced_tolerance, 0, 1, 1, true);
  std::string boundary = "periodic";
  pr.string("boundary", boundary, {"periodic", "walls"});
  c.periodic.boundary = boundary == "walls" ? CellBoundary::walls : CellBoundary::periodic;
  pr.finish();
  check_records(c.path, "periodic", "record_strain_pct", t.record_strain, "target_axial_strain_pct", t.target_strain);
}

/// [calibrate].
void read_calibrate(const Tables& read, Config& c) {
  TableReader cal = read("calibrate");
  cal.strings("free", c.calibrate.free);  // names checked against the registry by the calibration job
  if (!cal.word("ensemble", "auto", c.calibrate.ensemble, kAutoEnsemble))
    cal.integer("ensemble", c.calibrate.ensemble, 1, 64);
  cal.integer("scatter_specimens", c.calibrate.scatter_specimens, 1, 64);
  if (!cal.word("cell_factor", "auto", c.calibrate.cell_factor, kAutoCell))
    cal.integer("cell_factor", c.calibrate.cell_factor, 1, 16);
  if (!cal.word("batch", "auto", c.calibrate.batch, kAutoBatch)) cal.integer("batch", c.calibrate.batch, 1, 4096);
  cal.string("predict", c.calibrate.predict);
  cal.integer("predict_specimens", c.calibrate.predict_specimens, 1, 16);
  cal.string("reference_test", c.calibrate.reference_test, {"periodic", "walls", "two_fidelity"});
  cal.string("walled_match", c.calibrate.walled_match, {"interior", "whole"});
  cal.string("method", c.calibrate.method, {"ensemble", "one_specimen"});
  cal.finish();
  if (c.calibrate.one_specimen() && c.calibrate.reference_test == "two_fidelity")
    throw ConfigError(read.path + ": [calibrate] method: \"one_specimen\" fits one cell; with reference_test = "
                      "\"two_fidelity\" the allowed value is \"ensemble\"");
}

}  // namespace

Config parse_config(const std::string& text, const std::string& path) {
  Config c;
  c.path = path;
  toml::table root = parse_tables(text, path, {"run", "particles", "box", "material", "wall_material", "solver",
                                                "specimen", "triaxial", "micro", "periodic", "calibrate"});
  const Tables read{path, root};
  {
    toml::table settings = root;
    if (toml::table* run = settings["run"].as_table())
      for (const char* free : {"steps", "name", "output", "stop_ratio", "checkpoint_every", "checkpoint_minutes"})
        run->erase(free);
    std::string text;
    canonical_text(settings, text);
    c.fingerprint = hex16(fnv1a(text.data(), text.size()));
  }

  read_run(read, c);
  read_particles(read, c);
  read_box(read, c);
  read_materials(read, c);
  read_solver(read, c);
  read_specimen(read, c);
  read_triaxial(read, c);
  read_micro(read, c);
  read_periodic(read, c);
  read_calibrate(read, c);
  for (int d = 0; d < 3; ++d)
    if (c.box.size[d] < 3 * c.particles.diameter)
      throw ConfigError(path + ": [box] size_mm: every side must be at least 3 diameters (" +
                        std::to_string(3e3 * c.particles.diameter) + " mm)");
  if (c.box.fill == "lattice" && c.particles.psd != SizeLaw::uniform)
    throw ConfigError(path + ": [box] fill: \"lattice\" places balls of one size; a size distribution ([particles] "
                      "psd) needs fill = \"random\"");
  check_cell_physics(c);
  return c;
}

std::map<std::string, std::string> config_keys() {
  std::map<std::string, std::string> keys;
  TableReader::log_keys(&keys);
  try {
    // Every table present (empty), so that the keys read only with a table (the specimen's) are asked for too.
    parse_config("[run]\n[particles]\n[box]\n[material]\n[wall_material]\n[solver]\n[specimen]\n[triaxial]\n"
                 "[micro]\n[periodic]\n[calibrate]\n",
                 "<keys>");
  } catch (...) {
    TableReader::log_keys(nullptr);
    throw;
  }
  TableReader::log_keys(nullptr);
  return keys;
}

LabNoise read_lab_noise(const std::string& path) {
  const toml::table root = parse_tables(file_text(path), path, {"curve", "summary"});
  LabNoise n;
  TableReader curve(path, "curve", root["curve"].as_table());
  // q's scatter is positive: a lab with none would make every curve datum exact.
  curve.number("q_rel", n.curve.q_rel, 0, 1, 1, true);
  curve.number("q_shared", n.curve.q_shared, 0, 1);
  if (n.curve.q_shared > n.curve.q_rel)
    curve.fail("q_shared", "the shared factor is part of q's scatter (allowed: up to q_rel = " +
                               std::to_string(n.curve.q_rel) + ")");
  curve.number("eps_v_rel", n.curve.ev_rel, 0, 1);
  curve.number("eps_v_abs_pct", n.curve.ev_abs, 0, 5, 1e-2, true);
  curve.number("length", n.curve.length, 0.05, 20);
  curve.finish();
  TableReader summary(path, "summary", root["summary"].as_table());
  summary.number("specimen", n.summary.specimen, 0, 1);
  for (int q = 0; q < kQuantities; ++q) {
    const std::string name = quantity_name(q);
    if (q == kStrainAtPeak) {
      summary.number(name + "_pct", n.summary.abs[q], 0, 20, 1e-2, true);
      continue;
    }
    summary.number(name, n.summary.rel[q], 0, 1, 1, q != kDilatancy);
    if (q == kDilatancy) summary.number(name + "_abs", n.summary.abs[q], 0, 5);
  }
  for (int q = 0; q < kQuantities; ++q)
    if (NoiseModel::is_stress(q) && n.summary.specimen > n.summary.rel[q])
      summary.fail("specimen", "the shared factor is part of each stress's scatter (allowed: up to " +
                                   std::string(quantity_name(q)) + " = " + std::to_string(n.summary.rel[q]) + ")");
  if (n.summary.rel[kDilatancy] == 0 && n.summary.abs[kDilatancy] == 0)
    summary.fail("max_dilatancy", "max_dilatancy and max_dilatancy_abs are both 0 (allowed: one of them above 0)");
  summary.finish();
  return n;
}

}  // namespace dem
