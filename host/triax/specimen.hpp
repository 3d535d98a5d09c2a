#pragma once
/// Cylindrical specimen by multilayer compaction (Tang et al. 2025, Sec. 3.3): the specimen height is
/// split into equal layers; each layer's share of balls (count from the target void ratio) is poured at
/// random above the previous layers inside a rigid cylinder and pressed by the top platen to the layer's
/// target height, then left to settle until the unbalanced-force ratio is below the threshold.
#include <functional>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/builder.hpp"
#include "host/engine/stage_loop.hpp"

namespace dem {

struct LayerReport {
  Real z_bottom = 0, z_top = 0;  ///< m, the layer's target slab
  Real z_platen = 0;             ///< m, where the top platen stopped (above z_top if it could not get there)
  Real void_ratio = 0;           ///< of the slab in the finished specimen (exact sphere-slab volumes)
  long steps = 0;
  Real unbalanced = 0;           ///< ratio when the layer ended
};

struct Specimen {
  std::vector<BallSpec> balls;
  std::vector<LayerReport> layers;
  Real void_ratio = 0;           ///< whole specimen, up to where the last platen stopped
  Real height = 0;               ///< m, where the last platen stopped
  /// Porosity in `profile_bins` equal slices from bottom to top.
  std::vector<Real> porosity_profile;
  /// What each layer's compaction cost, where this process built it (not kept in the specimen's file).
  std::vector<StageTiming> stages;
};

/// The unbalanced ratio that ends layer k (from 0): layer_stop_ratio below the top layer where it is set, else
/// stop_ratio.
Real layer_stop_ratio(const SpecimenConfig& sc, long k);

/// Balls needed for the target void ratio: V / ((1 + e) V_ball), V_ball of the mean diameter.
long specimen_ball_count(const Config& cfg);

/// What a caller does with a layer's simulation that blew up, before the BlowUp goes on (save its state).
using LayerBlowUp = std::function<void(Simulation&)>;

/// Builds the specimen of cfg.specimen with cfg.particles sizes and the cfg.ball / cfg.wall laws.
/// Throws ConfigError when a layer cannot be placed or compacted, BlowUp (after `on_blowup`) when one blows up.
Specimen build_specimen(const Config& cfg, bool verbose, const LayerBlowUp& on_blowup = {});

/// Text key of everything that decides the specimen (particles, [specimen], seed, compaction laws, solver):
/// equal keys build identical specimens, so a study's cases can share one.
std::string specimen_key(const Config& cfg);

/// Writes / reads a specimen as CSV (x_m, y_m, z_m, radius_m, density_kg_m3 per ball; the layer reports,
/// height, key and a checksum of the lines above it in '#' lines). The write is atomic; load_specimen returns false
/// when the file is missing, was built for another key or has no checksum (a note says so), and throws
/// std::runtime_error naming the file and line when it is damaged or edited.
void save_specimen(const std::string& path, const Specimen& sp, const std::string& key);
bool load_specimen(const std::string& path, const std::string& key, Specimen& sp);

/// build_specimen through a cache folder: reuses cache/<hash of the key>.csv when it holds this key,
/// otherwise builds the specimen and stores it there. With `own` (a run folder's specimen.csv), that file is
/// looked at first and written when it does not hold the specimen: a run resumed elsewhere, or after the cache
/// was cleared, does not build it again. Then require_settled: an unsettled specimen is kept and refused.
Specimen cached_specimen(const Config& cfg, const std::string& cache, bool verbose, const std::string& own = "",
                         const LayerBlowUp& on_blowup = {});

/// Throws ConfigError naming the first layer that max_steps_per_layer stopped above stop_ratio, the keys to
/// change, and accept_unsettled, unless [specimen] accept_unsettled.
void require_settled(const Config& cfg, const Specimen& sp);

/// Exact volume of the part of a sphere (centre height zc, radius r) between the planes z0 < z1 (m^3).
Real sphere_slab_volume(Real zc, Real r, Real z0, Real z1);

/// Void ratio of the cylinder slab of radius R between z0 and z1 (balls assumed inside the cylinder).
Real slab_void_ratio(const std::vector<BallSpec>& balls, Real radius, Real z0, Real z1);

/// Writes layers.csv (each layer's void ratio in the finished specimen) and porosity_profile.csv.
void write_specimen_report(const std::string& folder, const Config& cfg, const Specimen& sp);

}  // namespace dem
