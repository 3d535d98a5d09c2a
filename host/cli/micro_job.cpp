/// The `micro` command: the micromechanics of a saved state, from a run folder and a strain or a snapshot.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "host/cli/job.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/triax/micro_report.hpp"

#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// The nominal axial strain (%) in a snapshot label "shear eps_a=5%"; NaN when the label has none.
double label_strain(const std::string& label) {
  const auto k = label.find("eps_a=");
  return k == std::string::npos ? NAN : std::atof(label.c_str() + k + 6);
}

/// The snapshot file `source` names: itself, or in a run's folder the one saved at axial strain at_pct (%). Throws
/// std::runtime_error naming the strains the run saved and the keys that set them.
std::string snapshot_at(const std::string& source, double at_pct) {
  namespace fs = std::filesystem;
  std::string path = source;
  if (fs::is_directory(source)) {
    std::vector<std::pair<double, std::string>> found;
    for (const auto& e : fs::directory_iterator(source)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("snap_", 0) != 0 || e.path().extension() != ".h5") continue;
      found.emplace_back(label_strain(io::read_snapshot(e.path().string()).particles.label), e.path().string());
    }
    std::sort(found.begin(), found.end());
    path.clear();
    std::string have;
    for (const auto& [eps, file] : found) {
      char level[32];
      std::snprintf(level, sizeof level, "%s%.1f%%", have.empty() ? "" : ", ", eps);
      if (std::isfinite(eps)) have += level;
      if (std::isfinite(eps) && std::fabs(eps - at_pct) < 1e-6) path = file;
    }
    if (found.empty())
      throw std::runtime_error(source + ": not a triaxial run's folder (no snap_*.h5 in it); give the -o folder of a "
                               "'triaxdem triaxial' run, or one snapshot file");
    if (path.empty())
      throw std::runtime_error(source + ": no snapshot at axial strain " + std::to_string(at_pct) +
                               "% (the run saved states at: " +
                               (have.empty() ? std::string("none in the shear") : have) +
                               "; [run] snapshot_every sets them in a membrane test, [periodic] snapshot_strains_pct "
                               "in a periodic cell)");
  } else if (!fs::is_regular_file(source)) {
    throw std::runtime_error(source + ": no such run folder or snapshot file");
  }
  return path;
}

}  // namespace

int micro_job(const std::string& source, double at_pct, double rve_edge_mm, int rose_bins, const std::string& output,
              bool overwrite) {
  namespace fs = std::filesystem;
  const std::string path = snapshot_at(source, at_pct);
  const std::string label = fs::path(path).stem().string();
  // An earlier micro of this state (another --rve or --bins, perhaps) is a result: replaced only when asked.
  for (const std::string& name : {"micro_" + label + ".csv", "micro_coordination_" + label + ".csv",
                                   "micro_rose_" + label + ".csv", "force_chains_" + label + ".vtk"})
    if (!overwrite && fs::exists(fs::path(output) / name))
      throw std::runtime_error(output + "/" + name + ": an earlier micro of this state wrote it: --overwrite replaces "
                               "its files, or -o names another folder");
  const io::SnapshotFile f = io::read_snapshot(path);
  const ContactSet cs = contact_set(f, path);
  if (cs.contacts.empty()) throw std::runtime_error(path + ": the snapshot's contact list is empty");
  if (!f.has_surface) throw std::runtime_error(path + ": no membrane surface in the snapshot: the specimen volume is unknown");
  const Real volume = surface_volume(f.surface);
  Real zmax = -INFINITY, zmin = INFINITY, rmax = 0;
  for (std::size_t k = 0; k < f.surface.nodes.size(); k += 3) {
    zmin = std::min(zmin, f.surface.nodes[k + 2]);
    zmax = std::max(zmax, f.surface.nodes[k + 2]);
  }
  for (std::size_t q = 0; q < cs.x.size(); ++q) rmax = std::max(rmax, std::hypot(cs.x[q].x, cs.x[q].y));
  const Real edge = rve_edge_mm * 1e-3;
  if (!(edge > 0) || edge / std::sqrt(2.0) > rmax || edge > zmax - zmin)
    throw std::runtime_error("--rve " + fmt("%g", rve_edge_mm) + ": a cube of that edge (mm) does not fit in this "
                             "specimen (ball centres within a radius of " + fmt("%.3g", rmax * 1e3) + " mm, height " +
                             fmt("%.3g", (zmax - zmin) * 1e3) + " mm; allowed: above 0, at most " +
                             fmt("%.3g", std::min(std::sqrt(2.0) * rmax, zmax - zmin) * 1e3) + " mm)");
  const ContactSet rve = restrict_to_cube(cs, Vec3(0, 0, 0.5 * (zmin + zmax)), edge);
  const MicroRow all = micro_row(cs, volume), cube = micro_row(rve, edge * edge * edge);
  fs::create_directories(output);
  std::string text;
  for (const std::string& c : micro_columns()) text += c + ",";
  for (const std::string& c : micro_columns("rve_")) text += c + (c == micro_columns("rve_").back() ? "\n" : ",");
  std::vector<double> v = micro_values(all);
  for (double x : micro_values(cube)) v.push_back(x);
  char cell[32];
  for (std::size_t k = 0; k < v.size(); ++k) {
    std::snprintf(cell, sizeof cell, "%.6g%s", v[k], k + 1 == v.size() ? "\n" : ",");
    text += cell;
  }
  io::write_text_atomic(output + "/micro_" + label + ".csv", text);
  write_micro_state(output, label, cs, rve, rose_bins);
  std::printf("%s (%s): %zu balls, %zu contacts, volume %.1f cm^3\n", path.c_str(), f.particles.label.c_str(),
              cs.x.size(), cs.contacts.size(), volume * 1e6);
  std::printf("  Z %.3f (with membrane contacts), Z_mech %.3f; mean fn %.3f N, strong/weak fn ratio %.2f\n",
              all.z.z, all.z.z_mech, all.net.all.mean_fn, all.net.fn_ratio);
  std::printf("  a_c %.3f, a_n %.3f, a_t %.3f; q/p from the contacts %.3f, stress-force-fabric %.3f\n", all.all.a_c,
              all.all.a_n, all.all.a_t, all.q_over_p, all.q_over_p_sff);
  std::printf("  central %.0f mm cube: %zu contacts, mean fn %.3f N, a_c %.3f, a_n %.3f\n", rve_edge_mm,
              rve.contacts.size(), cube.net.all.mean_fn, cube.all.a_c, cube.all.a_n);
  std::printf("  written: %s/micro_%s.csv, micro_coordination_%s.csv, micro_rose_%s.csv, force_chains_%s.vtk\n",
              output.c_str(), label.c_str(), label.c_str(), label.c_str(), label.c_str());
  return 0;
}

}  // namespace dem
